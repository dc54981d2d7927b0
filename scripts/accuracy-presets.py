#!/usr/bin/python3
"""Error and cost of the accuracy presets (Accuracy = Draft | Standard | Fine) on a scene.

    scripts/accuracy-presets.py SCENE.xml --out DIR [--capstan build/capstan] [--reuse PRESET=RUNDIR]

Runs the scene with each preset (outputs in DIR/<preset>/; a run whose summary.json
exists is reused, and --reuse takes an existing run for a preset, e.g. the 4x refined
G1 of scripts/g1-refinement.sh for Fine). Draft keeps the scene's mesh, Standard and
Fine refine it 2x and 4x, so the three runs are a mesh sequence: each quantity's
reference is their Richardson extrapolation (scripts/study.py). Prints a markdown
table: preset, mesh, wall time, and value and relative error of each quantity.
"""
import argparse
import json
import os
import shutil
import subprocess
import sys

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import study  # noqa: E402

PRESETS = [("Draft", 1), ("Standard", 2), ("Fine", 4)]
SHOWN = ["capstan_force", "peak_pressure", "contact_width", "max_ux", "von_mises_max"]


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("scene")
    ap.add_argument("--out", required=True)
    ap.add_argument("--capstan", default=os.path.join(os.path.dirname(__file__), "..", "build", "capstan"))
    ap.add_argument("--reuse", action="append", default=[], help="PRESET=RUNDIR")
    args = ap.parse_args()
    reuse = dict(r.split("=", 1) for r in args.reuse)
    runs = []
    for preset, _ in PRESETS:
        out = os.path.join(args.out, preset)
        if preset in reuse and not os.path.isfile(os.path.join(out, "summary.json")):
            shutil.copytree(reuse[preset], out, dirs_exist_ok=True)
        if not os.path.isfile(os.path.join(out, "summary.json")):
            print(f"  {preset} ...", flush=True)
            subprocess.run([args.capstan, "run", args.scene, "--output", out, "--quiet",
                            "--set", f"Accuracy={preset}"], check=True)
        with open(os.path.join(out, "summary.json")) as f:
            runs.append(json.load(f))
    cols = [q for q in SHOWN if all(study.QUANTITIES[q](s) is not None for s in runs)]
    ref = {q: study.richardson([study.QUANTITIES[q](s) for s in runs], [1, 2, 4])[0] for q in cols}
    lines = ["| preset | bricks | dofs | wall s | " + " | ".join(f"{q} (rel. error)" for q in cols) + " |",
             "|---|---|---|---|" + "---|" * len(cols)]
    for (preset, _), s in zip(PRESETS, runs):
        vals = []
        for q in cols:
            x = study.QUANTITIES[q](s)
            vals.append(f"{x:.6g} ({abs(x - ref[q]) / abs(ref[q]):.1e})")
        lines.append(f"| {preset} | {s['mesh']['elements']} | {s['mesh']['dofs']} | {s['timing']['total']:.1f} | " + " | ".join(vals) + " |")
    lines.append("| reference (Richardson) | | | | " + " | ".join(f"{ref[q]:.6g}" for q in cols) + " |")
    text = "\n".join(lines)
    with open(os.path.join(args.out, "presets.md"), "w") as f:
        f.write(text + "\n")
    print(text)


if __name__ == "__main__":
    main()
