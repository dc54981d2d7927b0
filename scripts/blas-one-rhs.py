#!/usr/bin/env python3
"""MUMPS' one-right-hand-side GEMM and TRSM by GEMV and TRSV (src/blas_one_rhs.cpp), on
and off (CAPSTAN_BLAS_ONE_RHS=off), alternating in rounds of back-to-back runs of one
build (docs/performance.md, "Defaults and why").

Prints per run the wall time, the run's own total, Newton and Krylov iterations and peak
memory; per case the medians and the off/on ratio of every round.

  scripts/blas-one-rhs.py [--cases g1x2,g1,hertz,drive,steady,g1x2-2] [--rounds 5]
                          [--capstan build/capstan] [--out out/blas-one-rhs]
"""
import argparse
import os
import statistics

from capstan_runs import ROOT, run_scene

# name: (scene, --set strings, ranks)
CASES = {
    "g1": ("seed/g1.xml", [], 1),
    "g1x2": ("seed/g1.xml", ["Mesh/Cells={28, 8, 12}"], 1),
    "g1x2-2": ("seed/g1.xml", ["Mesh/Cells={28, 8, 12}"], 2),
    "hertz": ("hertz-roller.xml", [], 1),
    "drive": ("pinch-roller.xml", ["Time/Steps=3"], 1),
    "steady": ("pinch-roller-steady.xml", [], 1),
}


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--cases", default="g1x2,g1,hertz,drive,steady")
    ap.add_argument("--rounds", type=int, default=5)
    ap.add_argument("--capstan", default=os.path.join(ROOT, "build", "capstan"))
    ap.add_argument("--out", default=os.path.join(ROOT, "out", "blas-one-rhs"))
    a = ap.parse_args()
    names = a.cases.split(",")
    unknown = [n for n in names if n not in CASES]
    if unknown:
        ap.error(f"unknown case(s) {unknown}; known: {', '.join(CASES)}")
    runs = {}
    for r in range(1, a.rounds + 1):
        for name in names:
            scene, sets, ranks = CASES[name]
            for mode in ("on", "off"):
                out = os.path.join(a.out, f"{name}-{mode}")
                rc, wall, s = run_scene(a.capstan, scene, out, sets, ranks, env={"CAPSTAN_BLAS_ONE_RHS": mode})
                if rc != 0 or s is None:
                    raise SystemExit(f"{name} ({mode}): exit {rc}")
                newton = sum(st["newton_iterations"] for st in s["steps"])
                krylov = sum(st["linear_iterations"] for st in s["steps"])
                peak = s["memory"]["peak_rss_mib_max"]
                runs.setdefault((name, mode), []).append((wall, s["timing"]["total"]))
                print(f"round {r} {name:7s} {mode:3s} wall {wall:6.3f} s  run {s['timing']['total']:6.3f} s  "
                      f"Newton {newton}  Krylov {krylov}  peak {peak:.0f} MiB", flush=True)
    print()
    for name in names:
        on, off = runs[(name, "on")], runs[(name, "off")]
        med = lambda rs, i: statistics.median(x[i] for x in rs)
        print(f"{name}: wall {med(on, 0):.3f} s on, {med(off, 0):.3f} s off ({med(off, 0) / med(on, 0):.2f}x); "
              f"run {med(on, 1):.3f} / {med(off, 1):.3f} s ({med(off, 1) / med(on, 1):.2f}x); off/on by round: "
              + ", ".join(f"{b[0] / a_[0]:.2f}" for a_, b in zip(on, off)))


if __name__ == "__main__":
    main()
