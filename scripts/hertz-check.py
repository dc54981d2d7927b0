#!/usr/bin/python3
"""Hertz line contact check of inputs/hertz-roller-held.xml on several meshes:
peak contact pressure and contact width against Hertz's p0 = 2P/(pi a) and
2a = 2 sqrt(4 P R / (pi E*)), from the measured force per length P, with
E* = 4G = 8c and 1/R = 1/R_capstan + 1/R_roller.

    scripts/hertz-check.py [--out out/hertz] [--cells 10,60,1 --cells 20,120,1 ...]

Runs whose summary.json exists are reused. Prints a markdown table.
"""
import argparse
import json
import math
import os
import subprocess

ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
ap.add_argument("--out", default="out/hertz")
ap.add_argument("--cells", action="append", default=[])
ap.add_argument("--capstan", default=os.path.join(os.path.dirname(__file__), "..", "build", "capstan"))
args = ap.parse_args()
cells = args.cells or ["10,60,1", "20,120,1"]
scene = os.path.join(os.path.dirname(__file__), "..", "inputs", "hertz-roller-held.xml")
c, length, r_capstan, r_roller = 1.0, 0.1, 5.0, 6.25
E = 8 * c
R = 1 / (1 / r_capstan + 1 / r_roller)
print("| mesh | dofs | step | P (per length) | peak pressure | Hertz p0 | error | contact width | Hertz 2a | error | wall s |")
print("|---|---|---|---|---|---|---|---|---|---|---|")
for cl in cells:
    out = os.path.join(args.out, cl.replace(",", "x"))
    if not os.path.isfile(os.path.join(out, "summary.json")):
        subprocess.run([args.capstan, "run", scene, "--output", out, "--quiet", "--set", f"Mesh/Cells={{{cl}}}"],
                       check=True)
    with open(os.path.join(out, "summary.json")) as f:
        s = json.load(f)
    for st in s["steps"]:
        cap = st["capstans"]["capstan"]
        P = abs(cap["force"][1]) / length
        a = math.sqrt(4 * P * R / (math.pi * E))
        p0 = 2 * P / (math.pi * a)
        print(f"| {cl.replace(',', 'x')} | {s['mesh']['dofs']} | {st['step']} | {P:.5f} | {cap['peak_pressure']:.5f} | {p0:.5f} | "
              f"{abs(cap['peak_pressure'] - p0) / p0:.2%} | {cap['contact_width']:.4f} | {2 * a:.4f} | "
              f"{abs(cap['contact_width'] - 2 * a) / (2 * a):.1%} | {s['timing']['total']:.0f} |")
