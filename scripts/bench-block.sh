#!/usr/bin/env bash
# Issue 3's figures: brick kernel throughput, then the 40^3 block (206k dofs) on 1 and
# 2 ranks: Newton and linear iterations, assembly and linear-solve time per step.
#   scripts/bench-block.sh [CELLS]      (default 40; e.g. 20 for a quick look)
set -euo pipefail
cd "$(dirname "$0")/.."
n=${1:-40}
export OMPI_ALLOW_RUN_AS_ROOT=1 OMPI_ALLOW_RUN_AS_ROOT_CONFIRM=1
build/capstan_bench 20
for ranks in 1 2; do
  out=out/bench-block$n-${ranks}r
  mpiexec -n $ranks build/capstan run inputs/block40.xml --set "Mesh/Cells={$n,$n,$n}" --output $out --quiet
  /usr/bin/python3 - "$out/summary.json" <<'PY'
import json, sys
d = json.load(open(sys.argv[1]))
s = d["steps"][0]; t = d["timing"]
print(f"ranks={d['ranks']} dofs={d['mesh']['dofs']} newton={s['newton_iterations']} "
      f"linear={s['linear_iterations']} augmentations={s['augmentations']} "
      f"step={s['wall_seconds']:.1f}s assembly={t['assembly']:.1f}s linear_solve={t['linear_solve']:.1f}s "
      f"assembly/newton={t['assembly']/max(1,s['newton_iterations']):.3f}s")
PY
done
