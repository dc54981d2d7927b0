#!/usr/bin/python3
"""The linear solvers side by side: MUMPS (Solver/Linear Solver = Direct), Amesos2's
KLU2 (one rank only: it solves distributed matrices wrongly in Trilinos 13.2), and
GMRES with MueLu or ILU, on 1 and 2 ranks, in rounds of back-to-back runs.

    scripts/direct-solvers.py [--out out/direct] [--rounds 2] [--cases drive,g1,g1x2]
                              [--solvers MUMPS,KLU2,MueLu] [--ranks 1,2]
                              [--capstan build/capstan]

Per case and solver: the run's time (summary.json timing.total) per Newton iteration,
its linear-solve time per Newton iteration, Newton and Krylov iterations, peak memory
of the largest rank; then each solver's time per Newton iteration against MUMPS on one
rank, within each round (the machines are noisy: only ratios of one round compare).
Writes OUT/direct-solvers.csv (a row per run), OUT/direct-solvers.md (the tables) and
OUT/direct-solvers.png (time per Newton iteration per case, solver and ranks). Runs
are reused when their summary.json exists (delete the folder to redo one).
"""
import argparse
import csv
import os
import statistics
import subprocess
import sys
import tempfile
import time
import xml.etree.ElementTree as ET

from capstan_runs import CAPSTAN, ENV, ROOT, pyplot, summary, write_report

# name: (scene, extra --set strings). Steps are capped to keep a round short.
CASES = {
    "drive": ("inputs/pinch-roller.xml", ["Time/Steps=3"]),                 # 3D drive, 4,800 dofs
    "slice": ("inputs/pinch-roller-slice.xml", ["Time/Steps=5"]),           # rolling slice, 1,920 dofs
    "hertz": ("inputs/hertz-roller.xml", []),                               # graded ring, 7,200 dofs
    "g1": ("inputs/seed/g1.xml", []),                                       # 1,575 dofs
    "g1x2": ("inputs/seed/g1.xml", ["Mesh/Cells={28,8,12}"]),              # 9,801 dofs
    "g1x4": ("inputs/seed/g1.xml", ["Mesh/Cells={56,16,24}", "Time/Steps=2"]),  # 65,025 dofs
    "h5": ("inputs/seed/h5.xml", []),
}
SOLVERS = {
    "MUMPS": ["Solver/Linear Solver=Direct"],
    "KLU2": ["Solver/Linear Solver=Direct"],  # plus Stratimikos/Linear Solver Type = Amesos2 (scene copy)
    "LU": ["Solver/Linear Solver=GMRES", "Solver/Preconditioner=LU"],
    "MueLu": ["Solver/Linear Solver=GMRES", "Solver/Preconditioner=MueLu"],
    "ILU": ["Solver/Linear Solver=GMRES", "Solver/Preconditioner=ILU"],
}


def klu2_scene(scene, tmp):
    """A copy of the scene whose Solver/Stratimikos names Amesos2 (KLU2, its default)."""
    tree = ET.parse(os.path.join(ROOT, scene))
    root = tree.getroot()
    solver = next((p for p in root.findall("ParameterList") if p.get("name") == "Solver"), None)
    if solver is None:
        solver = ET.SubElement(root, "ParameterList", name="Solver")
    strat = ET.SubElement(solver, "ParameterList", name="Stratimikos")
    ET.SubElement(strat, "Parameter", name="Linear Solver Type", type="string", value="Amesos2")
    path = os.path.join(tmp, os.path.basename(scene).replace(".xml", "-klu2.xml"))
    tree.write(path)
    return path


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--out", default="out/direct")
    ap.add_argument("--capstan", default=CAPSTAN)
    ap.add_argument("--rounds", type=int, default=2)
    ap.add_argument("--cases", default="drive,g1,g1x2")
    ap.add_argument("--solvers", default="MUMPS,KLU2,MueLu")
    ap.add_argument("--ranks", default="1,2")
    a = ap.parse_args()
    cases, solvers = a.cases.split(","), a.solvers.split(",")
    ranks = [int(r) for r in a.ranks.split(",")]
    os.makedirs(a.out, exist_ok=True)
    tmp = tempfile.mkdtemp(prefix="capstan-direct-")
    rows = []
    for rnd in range(a.rounds):
        tag = chr(ord("a") + rnd)
        for case in cases:
            scene, sets = CASES[case]
            variants = [(s, r) for s in solvers for r in ranks if not (s == "KLU2" and r > 1)]
            variants = variants[rnd % len(variants):] + variants[:rnd % len(variants)]  # rotate the order
            for solver, nr in variants:
                out = os.path.join(a.out, f"{tag}-{case}-{solver}-{nr}r")
                path = klu2_scene(scene, tmp) if solver == "KLU2" else os.path.join(ROOT, scene)
                cmd = [a.capstan, "run", path, "--output", out, "--quiet", "--set", "Output/Write Fields=false"]
                for s in SOLVERS[solver] + sets:
                    cmd += ["--set", s]
                if nr > 1:
                    cmd = ["mpiexec", "--oversubscribe", "-n", str(nr)] + cmd
                start = time.perf_counter()
                s = summary(out, cmd, f"round {tag}: {case} {solver} {nr} rank(s)", "direct-solvers.py")
                wall = time.perf_counter() - start
                steps = s["steps"]
                newton = sum(st["newton_iterations"] for st in steps)
                rows.append(dict(round=tag, case=case, solver=solver, ranks=nr, dofs=s["mesh"]["dofs"],
                                 converged=s["converged"], steps=len(steps), newton=newton,
                                 krylov=sum(st["linear_iterations"] for st in steps),
                                 cuts=sum(st["cutbacks"] for st in steps), total=s["timing"]["total"],
                                 linear=s["timing"]["linear_solve"], wall=wall,
                                 per_newton=s["timing"]["total"] / max(newton, 1),
                                 linear_per_newton=s["timing"]["linear_solve"] / max(newton, 1),
                                 peak_mib=s["memory"]["peak_rss_mib_max"]))
    with open(os.path.join(a.out, "direct-solvers.csv"), "w", newline="") as fh:
        w = csv.DictWriter(fh, fieldnames=list(rows[0]))
        w.writeheader()
        w.writerows(rows)
    lines = ["# Linear solvers side by side", "",
             f"`scripts/direct-solvers.py --out {a.out} --rounds {a.rounds} --cases {a.cases} "
             f"--solvers {a.solvers} --ranks {a.ranks}`", "",
             "| round | case | dofs | solver | ranks | converged | Newton | Krylov | cuts | run s | s / Newton "
             "| linear s / Newton | peak MiB/rank | MUMPS 1 rank's s/Newton over this |",
             "|---|---|---|---|---|---|---|---|---|---|---|---|---|---|"]
    base = {(r["round"], r["case"]): r["per_newton"] for r in rows if r["solver"] == "MUMPS" and r["ranks"] == 1}
    for r in rows:
        b = base.get((r["round"], r["case"]))
        up = "" if b is None else f"{b / r['per_newton']:.2f}x"
        lines.append(f"| {r['round']} | {r['case']} | {r['dofs']} | {r['solver']} | {r['ranks']} | {r['converged']} "
                     f"| {r['newton']} | {r['krylov']} | {r['cuts']} | {r['total']:.2f} | {r['per_newton'] * 1e3:.1f} ms "
                     f"| {r['linear_per_newton'] * 1e3:.1f} ms | {r['peak_mib']:.0f} "
                     f"| {up} |")
    lines += ["", "Mean over the rounds of the per-round speed-up against MUMPS on 1 rank (time per Newton iteration):", "",
              "| case | solver | ranks | speed-up (mean, range) |", "|---|---|---|---|"]
    for case in cases:
        for solver in solvers:
            for nr in ranks:
                ups = [base[(r["round"], case)] / r["per_newton"] for r in rows
                       if r["case"] == case and r["solver"] == solver and r["ranks"] == nr and (r["round"], case) in base]
                if ups:
                    lines.append(f"| {case} | {solver} | {nr} | {statistics.mean(ups):.2f}x "
                                 f"({min(ups):.2f}-{max(ups):.2f}) |")
    write_report(os.path.join(a.out, "direct-solvers.md"), lines)
    plt = pyplot()
    fig, ax = plt.subplots(figsize=(8, 4.5))
    labels = []
    for i, case in enumerate(cases):
        for j, (solver, nr) in enumerate((s, r) for s in solvers for r in ranks if not (s == "KLU2" and r > 1)):
            vals = [r["per_newton"] * 1e3 for r in rows if r["case"] == case and r["solver"] == solver and r["ranks"] == nr]
            if vals:
                ax.bar(len(labels), statistics.mean(vals), color=f"C{j}")
                labels.append(f"{case}\n{solver} {nr}r")
    ax.set_xticks(range(len(labels)))
    ax.set_xticklabels(labels, fontsize=6, rotation=60)
    ax.set_ylabel("run time per Newton iteration [ms]")
    ax.set_yscale("log")
    ax.set_title("Linear solvers (mean over rounds)")
    fig.tight_layout()
    fig.savefig(os.path.join(a.out, "direct-solvers.png"), dpi=120)


if __name__ == "__main__":
    main()
