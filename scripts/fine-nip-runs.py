#!/usr/bin/env python3
"""Repeats the steady 3D drive on a fine nip, where Coulomb's stick and slip cycle and
points are held in slip (docs/steady-rolling.md, "Stick and slip that cycle"), and prints
one line per run: exit status, Newton iterations, cuts, points held, speed ratio, seconds.
On 2 ranks the round-off, and so which points cycle, moves from run to run.

  /usr/bin/python3 scripts/fine-nip-runs.py --runs 8 --ranks 2
  /usr/bin/python3 scripts/fine-nip-runs.py --uniform --coretype Nehalem --runs 1
"""
import argparse
import json
import os
import subprocess
import sys
import tempfile

from capstan_runs import ROOT, run_scene


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--runs", type=int, default=4)
    ap.add_argument("--ranks", type=int, default=1)
    ap.add_argument("--uniform", action="store_true", help="3x160x8 with Outer Cell Ratio = 1 (else 3x120x8)")
    ap.add_argument("--coretype", help="OPENBLAS_CORETYPE for the runs (OpenBLAS' kernels)")
    ap.add_argument("--capstan", default=os.path.join(ROOT, "build", "capstan"))
    ap.add_argument("--timeout", type=float, default=1800, help="seconds a run may take")
    args = ap.parse_args()
    sets = ["Mesh/Fine Sector={-90, 20, 0.6}"]
    sets += ["Mesh/Cells={3, 160, 8}", "Mesh/Outer Cell Ratio=1"] if args.uniform else ["Mesh/Cells={3, 120, 8}"]
    env = {"OPENBLAS_CORETYPE": args.coretype} if args.coretype else None
    print(f"{'run':>3} {'exit':>4} {'newton':>6} {'cuts':>4} {'held':>4} {'speed ratio':>11} {'seconds':>8}")
    with tempfile.TemporaryDirectory(prefix="capstan-fine-nip-") as scratch:
        for k in range(args.runs):
            out = os.path.join(scratch, f"run{k}")
            try:
                rc, _, s = run_scene(args.capstan, "pinch-roller-steady.xml", out, sets, ranks=args.ranks,
                                     extra=["--log", "newton"], env=env, timeout=args.timeout)
            except subprocess.TimeoutExpired:
                print(f"{k:>3} not ended within {args.timeout:.0f} s")
                continue
            if s is None or not s["steps"]:
                print(f"{k:>3} {rc:>4} no steady step in its summary", flush=True)
                continue
            st = s["steps"][-1]
            held = 0
            with open(os.path.join(out, "log.jsonl")) as fh:
                for line in fh:
                    e = json.loads(line)
                    if e.get("event") == "held_slips":
                        held = max(held, int(e["points"]))
            print(f"{k:>3} {rc:>4} {st['newton_iterations']:>6} {st['cutbacks']:>4} {held:>4} "
                  f"{st['supports']['core']['speed_ratio']:>11.8f} {s['timing']['total']:>8.1f}", flush=True)
    return 0


if __name__ == "__main__":
    sys.exit(main())
