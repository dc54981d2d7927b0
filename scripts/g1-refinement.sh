#!/usr/bin/env bash
# G1 (inputs/seed/g1.xml) on the original 14x4x6 mesh and refined 2x and 4x (cells
# multiplied in every direction): the figures after the last step, as a markdown table.
#   scripts/g1-refinement.sh [FACTORS...]      (default: 1 2 4; 4x takes ~15 min)
# Outputs in out/g1-refine-<factor>/; a factor whose summary.json exists is not rerun.
set -euo pipefail
cd "$(dirname "$0")/.."
if [ $# -eq 0 ]; then factors=(1 2 4); else factors=("$@"); fi
for r in "${factors[@]}"; do
  out=out/g1-refine-$r
  if [ ! -f "$out/summary.json" ]; then
    build/capstan run inputs/seed/g1.xml --output "$out" \
      --set "Mesh/Cells={$((14 * r)),$((4 * r)),$((6 * r))}"
  fi
done
/usr/bin/python3 - "${factors[@]}" <<'PY'
import json, sys
print("| mesh | dofs | capstan force y | von Mises min / max | sigma_yy min / max | sigma_xz min / max "
      "| max penetration | Newton its per step | wall time |")
print("|---|---|---|---|---|---|---|---|---|")
for r in sys.argv[1:]:
    s = json.load(open(f"out/g1-refine-{r}/summary.json"))
    f, st = s["final"], s["steps"]
    c = st[-1]["capstans"]["capstan"]
    cells = "x".join(str(int(n) * int(r)) for n in (14, 4, 6))
    print(f"| {cells} | {s['mesh']['dofs']} | {c['force'][1]:.6f} | {f['von_mises']['min']:.4f} / {f['von_mises']['max']:.4f} "
          f"| {f['stress']['yy']['min']:.4f} / {f['stress']['yy']['max']:.4f} "
          f"| {f['stress']['xz']['min']:.4f} / {f['stress']['xz']['max']:.4f} | {c['max_penetration']:.1e} "
          f"| {' '.join(str(x['newton_iterations']) for x in st)} | {s['timing']['total']:.1f} s |")
PY
