#!/usr/bin/env python3
"""Steady rolling against the quasi-static rolling run, back to back (docs/steady-rolling.md).

Runs, one after the other on this machine:
  * the 3D drive's steady state (inputs/pinch-roller-steady.xml, one step; the median wall
    time of three runs);
  * a 10-torque brake sweep of the 3D drive in one steady run (1.8 .. 18 N mm, 90% of
    mu F R = 20 N mm);
  * the slice's brake sweep (inputs/pinch-roller-braked-steady.xml, 11 torques);
  * with --transient, the quasi-static drive (inputs/pinch-roller.xml, its first STEPS
    steps, default 20: about 15 minutes on one core), for the time ratio.
and prints, per run, the wall time, Newton iterations per step, cuts, speed ratios, and the
ratio of the transient wall time to the steady one. --cells NR,NT,NZ runs the 3D drive's
three runs on another mesh (the scenes' own fine sector), e.g. 3,160,8: twice the shipped
mesh's circumferential and axial cells.

  scripts/steady-bench.py [--capstan build/capstan] [--transient] [--steps 20] [--cells NR,NT,NZ]
                          [--out out/steady-bench]
"""
import argparse
import os
import sys

from capstan_runs import ROOT, run_scene


def describe(label, rc, wall, s):
    steps = s["steps"]
    newton = [st["newton_iterations"] for st in steps]
    cuts = sum(st["cutbacks"] for st in steps)
    ratios = [st["supports"]["core"].get("speed_ratio", float("nan")) for st in steps]
    print(f"{label}: exit {rc}, {wall:.1f} s wall, {len(steps)} steps, cuts {cuts}")
    print(f"    Newton per step: {newton}")
    d = s["timing"].get("direct_solver")
    if d:
        print(f"    MUMPS: {d['analyses']} analyses, {d['factorizations']} factorisations, {d['solves']} solves")
    print("    speed ratio: " + ", ".join(f"{r:.5f}" for r in ratios))
    if len(ratios) > 2:
        half = ratios[len(ratios) // 2:]
        print(f"    mean speed ratio over the second half: {sum(half) / len(half):.5f}")


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--capstan", default=os.path.join(ROOT, "build", "capstan"))
    ap.add_argument("--transient", action="store_true", help="also run the quasi-static drive (minutes)")
    ap.add_argument("--steps", type=int, default=20, help="quasi-static steps (default 20)")
    ap.add_argument("--out", default=os.path.join(ROOT, "out", "steady-bench"))
    ap.add_argument("--cells", help="NR,NT,NZ: the 3D drive's mesh (default the scenes' own)")
    a = ap.parse_args()
    os.makedirs(a.out, exist_ok=True)
    mesh = [f"Mesh/Cells={{{a.cells}}}"] if a.cells else []
    # The steady state a second long: the median of three runs (the first also
    # loads the program and its libraries into the page cache after a build).
    walls = []
    for _ in range(3):
        rc, wall, s = run_scene(a.capstan, "pinch-roller-steady.xml", os.path.join(a.out, "drive-steady"), mesh)
        walls.append(wall)
    steady_wall = sorted(walls)[1]
    describe("3D drive, steady state (median of 3: " + ", ".join(f"{w:.2f}" for w in walls) + " s)",
             rc, steady_wall, s)
    rc, wall, s = run_scene(a.capstan, "pinch-roller-steady.xml", os.path.join(a.out, "drive-sweep"),
                      ["Supports/core/Torque=18", "Supports/core/Torque Ramp Time=0.010", "Time/Steps=10"] + mesh)
    describe("3D drive, 10-torque brake sweep", rc, wall, s)
    rc, wall, s = run_scene(a.capstan, "pinch-roller-braked-steady.xml", os.path.join(a.out, "slice-sweep"))
    describe("slice, 11-torque brake sweep", rc, wall, s)
    if a.transient:
        rc, wall, s = run_scene(a.capstan, "pinch-roller.xml", os.path.join(a.out, "drive-transient"),
                          [f"Time/Steps={a.steps}"] + mesh)
        describe(f"3D drive, quasi-static, {a.steps} steps", rc, wall, s)
        print(f"transient / steady wall time: {wall / steady_wall:.1f}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
