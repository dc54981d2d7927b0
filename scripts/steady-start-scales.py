#!/usr/bin/env python3
"""The steady start's Tanh stages (Analysis/Start Slip Scales): Newton iterations from rest
over a set of scenes, one column per set of scales (docs/steady-rolling.md, "Start from rest").

Newton's count depends on the scales irregularly, scene by scene, so a default is chosen by
totals over many scenes. Scenes: the eight of the steady benchmarks (the drive, its 10-torque
brake sweep, the slice and the braked slice at 4x64 and 8x256, the Carter coating, the drive
at mu = 2), twelve variants of the drive (friction 0.5-1.5, force 2 and 8 N, twice the speed,
a brake, finer meshes and nips, Tanh 0.01) and, with --hard, fourteen hard cases (4x-9x the
force, mu 1.1-1.3, Tanh and Arctan 1e-4, tangential penalties 1e-6 and 1); with --more,
seventeen further variants (3x, 5x and 10x the force, mu 0.9-1.7, tangential penalties 1e-5,
1e-4 and 0.3, a brake, the slices at high friction and force, Arctan 1e-3). About 2 minutes a
set (4 with --hard, 8 with both) on one core.

  scripts/steady-start-scales.py [--capstan build/capstan] [--sets "0.06,0.015,0.004;0.02,0.004"]
                                 [--hard] [--more] [--out out/steady-start-scales]
"""
import argparse
import os
import sys

from capstan_runs import ROOT, run_scene

DRIVE, SLICE, BRAKED, CARTER = ("pinch-roller-steady.xml", "pinch-roller-slice-steady.xml",
                                "pinch-roller-braked-steady.xml", "carter-roller-steady.xml")
NIP = "Mesh/Fine Sector={-90, 20, 0.6}"
SCENES = [
    ("drive", DRIVE, []),
    ("drive, brake sweep", DRIVE, ["Supports/core/Torque=18", "Supports/core/Torque Ramp Time=0.010", "Time/Steps=10"]),
    ("slice 4x64", SLICE, []),
    ("slice 8x256", SLICE, ["Mesh/Cells={8, 256, 1}"]),
    ("braked slice 4x64", BRAKED, []),
    ("braked slice 8x256", BRAKED, ["Mesh/Cells={8, 256, 1}"]),
    ("Carter coating", CARTER, ["Mesh/Cells={12, 250, 1}"]),
    ("drive, mu 2", DRIVE, ["Capstans/capstan/Friction/Coefficient=2"]),
    ("drive, mu 0.5", DRIVE, ["Capstans/capstan/Friction/Coefficient=0.5"]),
    ("drive, mu 1", DRIVE, ["Capstans/capstan/Friction/Coefficient=1.0"]),
    ("drive, mu 1.5", DRIVE, ["Capstans/capstan/Friction/Coefficient=1.5"]),
    ("drive, 2 N", DRIVE, ["Supports/core/Force={0, -2, 0}"]),
    ("drive, 8 N", DRIVE, ["Supports/core/Force={0, -8, 0}"]),
    ("drive, twice the speed", DRIVE, ["Capstans/capstan/Angular Velocity=38.1"]),
    ("drive, brake 9 N mm", DRIVE, ["Supports/core/Torque=9"]),
    ("drive 3x100x8, nip sector", DRIVE, ["Mesh/Cells={3, 100, 8}", NIP]),
    ("drive 3x120x8, nip sector", DRIVE, ["Mesh/Cells={3, 120, 8}", NIP]),
    ("drive 4x80x8", DRIVE, ["Mesh/Cells={4, 80, 8}"]),
    ("drive 3x160x8", DRIVE, ["Mesh/Cells={3, 160, 8}"]),
    ("drive, Tanh 0.01", DRIVE, ["Capstans/capstan/Friction/Law=Tanh", "Capstans/capstan/Friction/Regularization=0.01"]),
]
HARD = [(f"drive, {f} N", DRIVE, [f"Supports/core/Force={{0, -{f}, 0}}"]) for f in (16, 24, 28, 32, 36)] + [
    (f"drive, mu {m}", DRIVE, [f"Capstans/capstan/Friction/Coefficient={m}"]) for m in (1.1, 1.2, 1.3)] + [
    ("drive, Tanh 1e-4", DRIVE, ["Capstans/capstan/Friction/Law=Tanh", "Capstans/capstan/Friction/Regularization=1e-4"]),
    ("drive, Tanh 1e-3", DRIVE, ["Capstans/capstan/Friction/Law=Tanh", "Capstans/capstan/Friction/Regularization=1e-3"]),
    ("drive, Arctan 1e-4", DRIVE, ["Capstans/capstan/Friction/Law=Arctan", "Capstans/capstan/Friction/Regularization=1e-4"]),
    ("slice, Tanh 1e-4", SLICE, ["Capstans/capstan/Friction/Law=Tanh", "Capstans/capstan/Friction/Regularization=1e-4"]),
    ("drive, tangential penalty 1e-6", DRIVE, ["Capstans/capstan/Friction/Tangential Penalty=1e-6"]),
    ("drive, tangential penalty 1", DRIVE, ["Capstans/capstan/Friction/Tangential Penalty=1"]),
]


F = "Capstans/capstan/Friction/"
# --more: seventeen further variants, a check on defaults chosen over the groups above
# (docs/steady-rolling.md, "Failed tries in the start").
MORE = [(f"drive, {f} N", DRIVE, [f"Supports/core/Force={{0, -{f}, 0}}"]) for f in (12, 20, 40)] + [
    (f"drive, mu {m}", DRIVE, [f"{F}Coefficient={m}"]) for m in (0.9, 1.05, 1.15, 1.4, 1.7)] + [
    (f"drive, tangential penalty {e}", DRIVE, [f"{F}Tangential Penalty={e}"]) for e in ("1e-5", "1e-4", "0.3")] + [
    ("drive, 16 N, mu 1.2", DRIVE, ["Supports/core/Force={0, -16, 0}", f"{F}Coefficient=1.2"]),
    ("drive, brake 15 N mm", DRIVE, ["Supports/core/Torque=15"]),
    ("slice, mu 1.5", SLICE, [f"{F}Coefficient=1.5"]),
    ("slice, twice the force", SLICE, ["Supports/core/Force={0, -0.5, 0}"]),
    ("braked slice, 4x the force, brake 4.4", BRAKED, ["Supports/core/Force={0, -1.0, 0}", "Supports/core/Torque=4.4"]),
    ("drive, Arctan 1e-3", DRIVE, [f"{F}Law=Arctan", f"{F}Regularization=1e-3"]),
]


def newton(capstan, out, scene, sets):
    """Newton iterations of a run ('-' where it failed), with ' (N cuts)' where it was cut."""
    rc, _, s = run_scene(capstan, scene, out, sets)
    if s is None or rc != 0:
        return None, "-"
    n = sum(st["newton_iterations"] for st in s["steps"])
    cuts = sum(st["cutbacks"] for st in s["steps"])
    return n, f"{n}" + (f" ({cuts} cuts)" if cuts else "")


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--capstan", default=os.path.join(ROOT, "build", "capstan"))
    ap.add_argument("--sets", default="0.06,0.015,0.004;0.02,0.004",
                    help="sets of scales, ';' between sets (default: today's and the one before)")
    ap.add_argument("--hard", action="store_true", help="also the fourteen hard cases")
    ap.add_argument("--more", action="store_true", help="also seventeen further variants")
    ap.add_argument("--out", default=os.path.join(ROOT, "out", "steady-start-scales"))
    a = ap.parse_args()
    sets = [s.strip() for s in a.sets.split(";") if s.strip()]
    groups = [("scenes", SCENES)] + ([("hard cases", HARD)] if a.hard else []) + ([("more", MORE)] if a.more else [])
    table = {}
    for k, scales in enumerate(sets):
        for group, scenes in groups:
            for j, (name, scene, extra) in enumerate(scenes):
                out = os.path.join(a.out, f"set{k}", group.replace(" ", "-"), str(j))
                table[(scales, name)] = newton(a.capstan, out, scene,
                                               extra + [f"Analysis/Start Slip Scales={{{scales}}}"])
                print(f"  {{{scales}}} {name}: {table[(scales, name)][1]}", flush=True)
    print("\n| scene | " + " | ".join("{" + s + "}" for s in sets) + " |")
    print("|---|" + "---|" * len(sets))
    for group, scenes in groups:
        for name, _, _ in scenes:
            print(f"| {name} | " + " | ".join(table[(s, name)][1] for s in sets) + " |")
        totals = []
        for s in sets:
            ns = [table[(s, name)][0] for name, _, _ in scenes]
            totals.append(f"**{sum(n for n in ns if n is not None)}**" + ("" if None not in ns else " (failures left out)"))
        print(f"| total, {len(scenes)} {group} | " + " | ".join(totals) + " |")
    return 0


if __name__ == "__main__":
    sys.exit(main())
