#!/usr/bin/python3
"""A steady scene's figures over mesh phases: its mean and spread where one steady solve
depends on where the mesh's nodes sit against the nip (docs/accuracy.md, "The
pinch-roller nip").

    scripts/steady-phases.py SCENE.xml [--phases 4] [--set PATH=VALUE ...]
        [--out out/steady-phases] [--capstan build/capstan]

The scene must be a steady one on an annulus with a `Mesh/Fine Sector` (its nip cells):
phase j of K turns the mesh by j/K of one fine cell (the sector's centre moved by that
much; phase 0 is the scene's own mesh; an `Accuracy` preset's refined cells counted). The runs go to OUT/pJ. For every step, and every free core and capstan, the mean, least and
largest value over the phases of the speed ratio, the core's angular velocity, the
capstan's force magnitude and torque and its slip power are written to OUT/phases.csv
and as a table to OUT/phases.md. The mean over the phases is what the quasi-static
analysis' time mean averages over as it rolls the mesh through the nip; the spread is
one solve's uncertainty from the mesh alone.
"""
import argparse
import csv
import math
import os
import sys
import xml.etree.ElementTree as ET

from capstan_runs import ROOT, run_scene, turned_sector, write_report


def scene_value(scene, sets, path):
    """A parameter's text: the last --set of `path`, else the scene's, else None."""
    for s in reversed(sets):
        key, _, value = s.partition("=")
        if key.strip() == path:
            return value.strip()
    node = ET.parse(scene).getroot()
    for name in path.split("/")[:-1]:
        node = next((c for c in node.findall("ParameterList") if c.get("name") == name), None)
        if node is None:
            return None
    p = next((c for c in node.findall("Parameter") if c.get("name") == path.split("/")[-1]), None)
    return None if p is None else p.get("value")


def numbers(text):
    return [float(x) for x in text.strip().strip("{}").split(",")]


def phase_sets(scene, sets, phases):
    """The --set strings that turn the mesh to each phase."""
    sector, cells = scene_value(scene, sets, "Mesh/Fine Sector"), scene_value(scene, sets, "Mesh/Cells")
    if sector is None or cells is None or numbers(sector)[1] <= 0:
        sys.exit(f"steady-phases.py: {scene}: needs Mesh/Cells and a Mesh/Fine Sector of positive width")
    centre, width, fraction = numbers(sector)
    # Accuracy = Standard / Fine refine the scene's cells 2x / 4x (src/scene.cpp).
    refine = {"Standard": 2, "Fine": 4}.get(scene_value(scene, sets, "Accuracy") or "Scene", 1)
    nt = refine * int(numbers(cells)[1])
    return [turned_sector(nt, j / phases, (centre, width, fraction))[1] for j in range(phases)]


def figures(step):
    """name -> value of one step's figures that a phase can move."""
    out = {}
    for name, core in step.get("supports", {}).items():
        for key in ("speed_ratio", "angular_velocity"):
            if core.get(key) is not None:
                out[f"{name} {key}"] = core[key]
    for name, cap in step.get("capstans", {}).items():
        out[f"{name} force"] = math.sqrt(sum(f * f for f in cap["force"]))
        for key in ("torque", "slip_power"):
            if cap.get(key) is not None:
                out[f"{name} {key}"] = cap[key]
    return out


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("scene")
    ap.add_argument("--phases", type=int, default=4)
    ap.add_argument("--set", action="append", default=[], help="PATH=VALUE for every run")
    ap.add_argument("--out", default=os.path.join(ROOT, "out", "steady-phases"))
    ap.add_argument("--capstan", default=os.path.join(ROOT, "build", "capstan"))
    a = ap.parse_args()
    scene = os.path.abspath(a.scene)
    runs = []
    for j, turn in enumerate(phase_sets(scene, a.set, a.phases)):
        out = os.path.join(a.out, f"p{j}")
        path = os.path.join(out, "summary.json")
        if os.path.isfile(path):
            os.remove(path)  # the settings may have changed: run again
        print(f"phase {j}/{a.phases}: {turn}", flush=True)
        rc, _, s = run_scene(a.capstan, scene, out, a.set + [turn])
        if rc != 0 or s is None:
            sys.exit(f"steady-phases.py: phase {j} ended with exit {rc}" +
                     ("" if s is None else f": {s.get('failure')}") + f" (outputs in {out})")
        runs.append(s)
    steps = min(len(s["steps"]) for s in runs)
    rows = []
    for k in range(steps):
        per_phase = [figures(s["steps"][k]) for s in runs]
        for name in per_phase[0]:
            v = [f[name] for f in per_phase]
            rows.append(dict(step=k + 1, figure=name, mean=sum(v) / len(v), least=min(v), largest=max(v),
                             spread=max(v) - min(v), **{f"phase{j}": x for j, x in enumerate(v)}))
    os.makedirs(a.out, exist_ok=True)
    with open(os.path.join(a.out, "phases.csv"), "w", newline="") as fh:
        w = csv.DictWriter(fh, fieldnames=list(rows[0]))
        w.writeheader()
        w.writerows(rows)
    lines = [f"{os.path.basename(scene)} over {a.phases} mesh phases" + (f" ({', '.join(a.set)})" if a.set else ""),
             "", "| step | figure | mean | least | largest | spread |", "|---|---|---|---|---|---|"]
    lines += [f"| {r['step']} | {r['figure']} | {r['mean']:.6g} | {r['least']:.6g} | {r['largest']:.6g} | "
              f"{r['spread']:.2e} |" for r in rows]
    write_report(os.path.join(a.out, "phases.md"), lines)
    return 0


if __name__ == "__main__":
    sys.exit(main())
