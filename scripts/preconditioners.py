#!/usr/bin/python3
"""Linear solvers compared on G1 (inputs/seed/g1.xml, 5 load steps), refined
1x, 2x, 4x (cells multiplied in every direction), GMRES with each
preconditioner; then the pressure penalty eps1 swept from 1e-13 to 1e-1 with
the default solver, and the solver's two cost savers (Eisenstat-Walker
tolerances, a reused preconditioner) switched off one at a time.

    scripts/preconditioners.py [--out out/preconditioners] [--factors 1,2,4]
                               [--ranks 1] [--quick] [--steps 5]

--pressure-update: Solver/Pressure Update of every run (default Anderson,
with the solve penalty it had then, 1e-2: the pressure loop of the figures in
docs/performance.md; Auto runs today's default, the saddle-point step: see
"Defaults and why" there).

--steps: load steps of every run (Time/Steps; default 5, the whole G1); the
eps1 and cost-saver runs only where the factors include 1.

--quick: the 1x and 2x meshes only. Runs whose summary.json exists are
reused. Writes OUT/preconditioners.md and .csv (one row per run) and prints
the table: Newton and linear iterations, linear iterations per Newton
iteration, set-up and solve seconds, the capstan force (every run must give
the same answer).
"""
import argparse
import csv
import json
import os
import re
import subprocess
import sys

ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
root = os.path.join(os.path.dirname(os.path.abspath(__file__)), "..")
ap.add_argument("--out", default="out/preconditioners")
ap.add_argument("--capstan", default=os.path.join(root, "build", "capstan"))
ap.add_argument("--factors", default="1,2,4")
ap.add_argument("--ranks", type=int, default=1)
ap.add_argument("--quick", action="store_true")
ap.add_argument("--steps", type=int, default=5)
ap.add_argument("--pressure-update", default="Anderson", choices=["Anderson", "Saddle Point", "Auto"])
args = ap.parse_args()
factors = [1, 2] if args.quick else [int(x) for x in args.factors.split(",")]
env = dict(os.environ, OMPI_ALLOW_RUN_AS_ROOT="1", OMPI_ALLOW_RUN_AS_ROOT_CONFIRM="1")


def ifpack2(prec_type, settings):
    """A Solver/Stratimikos sublist that sets Ifpack2's type and settings."""
    items = "".join(f'<Parameter name="{k}" type="{t}" value="{v}"/>' for k, t, v in settings)
    return ('<ParameterList name="Preconditioner Types"><ParameterList name="Ifpack2">'
            f'<Parameter name="Prec Type" type="string" value="{prec_type}"/>'
            f'<ParameterList name="Ifpack2 Settings">{items}</ParameterList></ParameterList></ParameterList>')


# name: (capstan Solver parameters, extra Solver/Stratimikos XML)
PRECONDITIONERS = {
    "MueLu SA": ({"Preconditioner": "MueLu"}, ""),
    "ILU(1)": ({"Preconditioner": "ILU", "ILU Level": "1"}, ""),
    "ILU(0)": ({"Preconditioner": "ILU", "ILU Level": "0"}, ""),
    "Chebyshev(3)": ({"Preconditioner": "Jacobi"},
                     ifpack2("CHEBYSHEV", [("chebyshev: degree", "int", 3)])),
    "SGS x2": ({"Preconditioner": "Jacobi"},
               ifpack2("RELAXATION", [("relaxation: type", "string", "Symmetric Gauss-Seidel"),
                                      ("relaxation: sweeps", "int", 2)])),
    "Jacobi": ({"Preconditioner": "Jacobi"}, ""),
}


def scene_with(path, solver, stratimikos):
    """G1 with a Solver sublist written into it (a copy under OUT/scenes)."""
    params = "".join(f'<Parameter name="{k}" type="{"int" if k == "ILU Level" else "string"}" value="{v}"/>'
                     for k, v in solver.items())
    strat = f'<ParameterList name="Stratimikos">{stratimikos}</ParameterList>' if stratimikos else ""
    text = open(os.path.join(root, "inputs/seed/g1.xml")).read()
    text = text.replace('<ParameterList name="Output">',
                        f'<ParameterList name="Solver">{params}{strat}</ParameterList>\n  <ParameterList name="Output">')
    os.makedirs(os.path.dirname(path), exist_ok=True)
    with open(path, "w") as fh:
        fh.write(text)
    return path


runs = []  # (group, label, tag, solver, stratimikos, sets)
for f in factors:
    cells = f"Mesh/Cells={{{14 * f},{4 * f},{6 * f}}}"
    for name, (solver, strat) in PRECONDITIONERS.items():
        # ILU(0) and Jacobi need 177 and 67 iterations per Newton step already
        # on 1x (4-10x MueLu's time): not run on the finer meshes.
        if f > 1 and name in ("Jacobi", "ILU(0)"):
            continue
        # ILU(1) on 2x: 3.3x MueLu's time, its set-up alone 7x; not run on 4x.
        if f > 2 and name == "ILU(1)":
            continue
        runs.append(("preconditioner", f"{f}x {name}", f"g1-{f}x-" + re.sub(r"[^A-Za-z0-9]+", "", name),
                     dict(solver, **{"Linear Solver": "GMRES"}), strat, [cells]))
extras = 1 in factors  # the eps1 sweep and the cost savers (1x, 2x) go with the 1x mesh
for eps in ("1e-13", "1e-8", "1e-3", "1e-1") if extras else ():
    runs.append(("eps1", f"1x eps1 = {eps}", f"g1-1x-eps1-{eps}", {"Linear Solver": "GMRES", "Preconditioner": "MueLu"},
                 "", [f"Material/Pressure Penalty={eps}"]))
for f in [x for x in factors if x <= 2 and extras]:
    for label, extra in (("fixed tolerance", {"Linear Tolerance Method": "Fixed"}),
                         ("new preconditioner every Newton iteration", {"Preconditioner Reuse": "None"}),
                         ("both", {"Linear Tolerance Method": "Fixed", "Preconditioner Reuse": "None"})):
        runs.append(("savers", f"{f}x MueLu, {label}", f"g1-{f}x-savers-" + re.sub(r"[^A-Za-z]+", "", label),
                     dict({"Linear Solver": "GMRES", "Preconditioner": "MueLu"}, **extra), "",
                     [f"Mesh/Cells={{{14 * f},{4 * f},{6 * f}}}"]))

rows = []
for group, label, tag, solver, strat, sets in runs:
    out = os.path.join(args.out, f"{tag}-r{args.ranks}")
    summary = os.path.join(out, "summary.json")
    if not os.path.isfile(summary):
        scene = scene_with(os.path.join(args.out, "scenes", tag + ".xml"), solver, strat)
        cmd = [args.capstan, "run", scene, "--output", out, "--quiet", "--set", "Output/Write Fields=false",
               "--set", f"Time/Steps={args.steps}"]
        for s in sets:
            cmd += ["--set", s]
        cmd += ["--set", f"Solver/Pressure Update={args.pressure_update}"]
        if args.pressure_update == "Anderson" and not any(s.startswith("Solver/Minimum Solve Penalty") for s in sets):
            cmd += ["--set", "Solver/Minimum Solve Penalty=1e-2"]
        if args.ranks > 1:
            cmd = ["mpiexec", "--oversubscribe", "-n", str(args.ranks)] + cmd
        print("  " + label, flush=True)
        run = subprocess.run(cmd, env=env, capture_output=True, text=True)
        if not os.path.isfile(summary):
            sys.exit(f"preconditioners.py: {label} wrote no summary.json (exit {run.returncode}):\n{run.stderr}")
    with open(summary) as fh:
        s = json.load(fh)
    newton = sum(st["newton_iterations"] for st in s["steps"])
    linear = sum(st["linear_iterations"] for st in s["steps"])
    t = s["timing"]
    rows.append({"group": group, "run": label, "ranks": args.ranks, "dofs": s["mesh"]["dofs"], "newton": newton,
                 "linear": linear, "linear_per_newton": round(linear / max(newton, 1), 1),
                 "setup_s": round(t.get("preconditioner_setup", 0), 2),
                 "krylov_s": round(t["linear_solve"] - t.get("preconditioner_setup", 0), 2),
                 "total_s": round(t["total"], 2),
                 "force_y": s["steps"][-1]["capstans"]["capstan"]["force"][1] if s["steps"] else float("nan"),
                 "converged": s["converged"]})

os.makedirs(args.out, exist_ok=True)
with open(os.path.join(args.out, "preconditioners.csv"), "w", newline="") as fh:
    w = csv.DictWriter(fh, fieldnames=list(rows[0].keys()))
    w.writeheader()
    w.writerows(rows)
lines = []
for group, title in (("preconditioner", "GMRES with each preconditioner"),
                     ("eps1", "The pressure penalty eps1 (1x mesh, GMRES + MueLu)"),
                     ("savers", "Without the cost savers (GMRES + MueLu)")):
    sel = [r for r in rows if r["group"] == group]
    if not sel:
        continue
    lines += [f"### {title}", "",
              "| run | dofs | Newton its | linear its | linear its / Newton | prec. set-up s | Krylov s | total s | capstan force y |",
              "|---|---|---|---|---|---|---|---|---|"]
    for r in sel:
        lines.append(f"| {r['run']} | {r['dofs']} | {r['newton']} | {r['linear']} | {r['linear_per_newton']} | "
                     f"{r['setup_s']} | {r['krylov_s']} | {r['total_s']} | {r['force_y']:.10f}"
                     f"{'' if r['converged'] else ' (did not converge)'} |")
    lines.append("")
text = "\n".join(lines)
with open(os.path.join(args.out, "preconditioners.md"), "w") as fh:
    fh.write(text)
print(text)
