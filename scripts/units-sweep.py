#!/usr/bin/env python3
"""Every shipped scene in other units against its own (docs/numerics.md, "Penalties in any units").

Writes each scene of inputs/ and inputs/seed/ in three other systems of units (lengths x L,
stresses x S, times x T; forces x S L^2): metres and pascals (1e-3, 1e6, 1), time x 10, and an
odd set (37, 3e-4, 0.02). Runs the scene and its three copies, and prints per copy the Newton
iterations (the scene's / the copy's) and the largest difference of the scaled figures: the
capstans' forces, the cores' translations and speed ratios. A missing Material/c (default 1) is
written out first, so that it is scaled too. About 8 minutes on one core.

    /usr/bin/python3 scripts/units-sweep.py [--capstan build/capstan] [--out out/units] [SCENE ...]
"""
import argparse
import glob
import json
import os
import subprocess
import xml.etree.ElementTree as ET

HERE = os.path.dirname(os.path.abspath(__file__))
INPUTS = os.path.join(HERE, "..", "inputs")
SYSTEMS = [("si", 1e-3, 1e6, 1.0), ("time", 1.0, 1.0, 10.0), ("odd", 37.0, 3e-4, 0.02)]


def convert(src, dst, L, S, T, drop=()):
    """SRC written in other units to DST; DROP: parameter names left out (to their defaults)."""
    F = S * L * L
    by_name = {"Min": L, "Max": L, "Center": L, "Inner Radius": L, "Outer Radius": L, "Length": L,
               "c": S, "Pressure Penalty": 1 / S, "Body Force": S / L, "Stiffness": S / L, "Axis Point": L,
               "Force": F, "Torque": F * L, "Radius": L, "Penetration Tolerance": L, "Tangential Penalty": L / S,
               "Regularization": L / T, "Velocity": L / T, "Angular Velocity": 1 / T, "Step Size": T,
               "Force Ramp Time": T, "Torque Ramp Time": T}
    in_contact = {"Penalty": L / S, "Smoothing": S, "Minimum Solve Penalty": L / S}
    tree = ET.parse(src)
    root = tree.getroot()
    material = [pl for pl in root.iter("ParameterList") if pl.get("name") == "Material"]
    if not material:
        material = [ET.SubElement(root, "ParameterList", {"name": "Material"})]
    if not any(p.get("name") == "c" for p in material[0]):
        ET.SubElement(material[0], "Parameter", {"name": "c", "type": "double", "value": "1"})

    def walk(node, parent):
        for child in list(node):
            if child.tag == "ParameterList":
                walk(child, child.get("name"))
                continue
            name = child.get("name")
            if name in drop:
                node.remove(child)
                continue
            factor = in_contact.get(name) if parent == "Contact" else by_name.get(name)
            if factor is None or child.get("type") not in ("double", "Array(double)"):
                continue
            value = child.get("value")
            if child.get("type") == "double":
                child.set("value", repr(float(value) * factor))
            else:
                child.set("value", "{" + ", ".join(repr(float(v) * factor) for v in value.strip("{} ").split(",")) + "}")

    walk(root, "")
    tree.write(dst)


def run(capstan, scene, out):
    p = subprocess.run([capstan, "run", scene, "--output", out, "--quiet", "--set", "Output/Write Fields=false"],
                       capture_output=True, text=True, timeout=1800)
    try:
        with open(os.path.join(out, "summary.json")) as f:
            return p, json.load(f)
    except (OSError, ValueError):
        return p, None


def worst_difference(base, other, L, S):
    """The largest difference of the scaled figures at the last step, and which."""
    F = S * L * L
    worst, what = 0.0, ""
    a, b = base["steps"][-1], other["steps"][-1]
    for name, c in a["capstans"].items():
        scale = max(abs(v) for v in c["force"]) or 1.0
        d = max(abs(x * F - y) for x, y in zip(c["force"], b["capstans"][name]["force"])) / (scale * F)
        if d > worst:
            worst, what = d, f"{name} force"
    for name, s in a["supports"].items():
        t = b["supports"][name]
        if "speed_ratio" in s and abs(s["speed_ratio"] - t["speed_ratio"]) > worst:
            worst, what = abs(s["speed_ratio"] - t["speed_ratio"]), f"{name} speed ratio"
        if "translation" in s and max(abs(x) for x in s["translation"]) > 0:
            scale = max(abs(x) for x in s["translation"])
            d = max(abs(x * L - y) for x, y in zip(s["translation"], t["translation"])) / (scale * L)
            if d > worst:
                worst, what = d, f"{name} translation"
    return worst, what


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--capstan", default=os.path.join(HERE, "..", "build", "capstan"))
    ap.add_argument("--out", default="out/units")
    ap.add_argument("scenes", nargs="*", help="scene names (file names without .xml); default: all")
    args = ap.parse_args()
    os.makedirs(args.out, exist_ok=True)
    scenes = sorted(glob.glob(os.path.join(INPUTS, "*.xml")) + glob.glob(os.path.join(INPUTS, "seed", "*.xml")))
    for scene in scenes:
        name = os.path.basename(scene)[:-4]
        if args.scenes and name not in args.scenes:
            continue
        _, base = run(args.capstan, scene, os.path.join(args.out, f"{name}-own"))
        for tag, L, S, T in SYSTEMS:
            copy = os.path.join(args.out, f"{name}-{tag}.xml")
            convert(scene, copy, L, S, T)
            p, other = run(args.capstan, copy, os.path.join(args.out, f"{name}-{tag}"))
            if not (base and other and base["steps"] and other["steps"]):
                print(f"{name:28s} {tag:5s} exit {p.returncode}: {(other or {}).get('failure')}", flush=True)
                continue
            n0 = [s["newton_iterations"] for s in base["steps"]]
            n1 = [s["newton_iterations"] for s in other["steps"]]
            worst, what = worst_difference(base, other, L, S)
            print(f"{name:28s} {tag:5s} exit {p.returncode}, Newton {sum(n0)}/{sum(n1)}"
                  f"{'' if n0 == n1 else ' (differ)'}, largest difference {worst:.1e} {what}", flush=True)


if __name__ == "__main__":
    main()
