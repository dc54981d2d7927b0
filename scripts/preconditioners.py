#!/usr/bin/python3
"""Preconditioners compared on G1 (inputs/seed/g1.xml), refined 1x and 2x, and the
pressure penalty eps1 swept on the 1x mesh: Newton and linear iterations, linear
iterations per Newton iteration, preconditioner set-up and linear-solve seconds.

    scripts/preconditioners.py [--out out/preconditioners] [--ranks 1] [--factors 1,2]

Runs whose summary.json exists are reused. Prints a markdown table (also
written to OUT/preconditioners.md).
"""
import argparse
import json
import os
import subprocess

ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
ap.add_argument("--out", default="out/preconditioners")
ap.add_argument("--capstan", default=os.path.join(os.path.dirname(__file__), "..", "build", "capstan"))
ap.add_argument("--factors", default="1,2")
ap.add_argument("--ranks", type=int, default=1)
args = ap.parse_args()

runs = []
for f in [int(x) for x in args.factors.split(",")]:
    cells = f"{{{14 * f},{4 * f},{6 * f}}}"
    precs = [("ILU", ["Solver/ILU Level=1"]), ("MueLu", [])]
    if f == 1:  # far slower on the 1x mesh already (453 and 196 linear its per Newton)
        precs += [("ILU(0)", ["Solver/Preconditioner=ILU", "Solver/ILU Level=0"]), ("Jacobi", [])]
    for name, extra in precs:
        sets = [f"Mesh/Cells={cells}", "Solver/Linear Solver=GMRES"]
        if not name.startswith("ILU("):
            sets.append(f"Solver/Preconditioner={name}")
        runs.append((f"{f}x {name}", f"g1-{f}x-{name}".replace("(", "").replace(")", ""), sets + extra))
for eps in ("1e-13", "1e-8", "1e-3", "1e-1"):
    runs.append((f"1x MueLu eps1={eps}", f"g1-1x-MueLu-eps1-{eps}",
                 ["Solver/Linear Solver=GMRES", "Solver/Preconditioner=MueLu", f"Material/Pressure Penalty={eps}"]))

lines = ["| run | ranks | dofs | Newton its | linear its | linear its / Newton | precond. set-up s | linear solve s | total s | converged |",
         "|---|---|---|---|---|---|---|---|---|---|"]
for label, tag, sets in runs:
    out = os.path.join(args.out, f"{tag}-r{args.ranks}")
    if not os.path.isfile(os.path.join(out, "summary.json")):
        cmd = [args.capstan, "run", "inputs/seed/g1.xml", "--output", out, "--quiet"]
        for s in sets:
            cmd += ["--set", s]
        if args.ranks > 1:
            cmd = ["mpiexec", "--allow-run-as-root", "--oversubscribe", "-n", str(args.ranks)] + cmd
        print("  " + label, flush=True)
        subprocess.run(cmd, capture_output=True)
    with open(os.path.join(out, "summary.json")) as fh:
        s = json.load(fh)
    newton = sum(st["newton_iterations"] for st in s["steps"])
    linear = sum(st["linear_iterations"] for st in s["steps"])
    t = s["timing"]
    lines.append(f"| {label} | {args.ranks} | {s['mesh']['dofs']} | {newton} | {linear} | {linear / max(newton, 1):.1f} | "
                 f"{t.get('preconditioner_setup', 0):.1f} | {t['linear_solve']:.1f} | {t['total']:.1f} | {s['converged']} |")
text = "\n".join(lines)
os.makedirs(args.out, exist_ok=True)
with open(os.path.join(args.out, "preconditioners.md"), "w") as fh:
    fh.write(text + "\n")
print(text)
