#!/usr/bin/python3
"""How capstan's cost grows with the mesh and the ranks.

Runs G1 (inputs/seed/g1.xml, 14x4x6 cells x factor in every direction, 5 steps)
and H1 (inputs/seed/h1.xml, 20x2x1 cells x factor, rolling with tanh friction,
4 steps) on 1 and 2 ranks, all with GMRES + MueLu so that every size and rank
count runs the same method, and writes

    OUT/scaling.csv   one row per run
    OUT/scaling.md    the same as a markdown table, plus the 2-rank speed-ups, each
                      split into time per Krylov iteration and Krylov iterations
    OUT/scaling.png   time per Newton iteration and per step vs DOFs (log-log),
                      with the ideal slope (time proportional to DOFs) drawn

    scripts/scaling.py [--out out/scaling] [--g1 1,2,4] [--h1 2,4,8] [--ranks 1,2]
                       [--steps N] [--capstan build/capstan] [--set PATH=VALUE]...

Runs whose summary.json exists are reused (delete OUT/<run>/ to redo one); a
run made by hand with --log newton leaves OUT/<run>/log.jsonl, from which the
pressure steps' iterations are read if its summary lacks them.
--steps N runs only the first N steps of each scene (the per-step and
per-Newton figures stay comparable; the totals do not). The 8x G1 (550k
DOFs, --g1 8) takes 4-13 minutes on 2 ranks and 6-20 on 1, by machine (docs/performance.md).
"linear" counts every Krylov iteration: Newton's solves and the saddle-point
pressure steps (split out in their own columns).
"""
import argparse
import csv
import os

from capstan_runs import CAPSTAN, CASES, command, pyplot, summary, totals, write_report

ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
ap.add_argument("--out", default="out/scaling")
ap.add_argument("--capstan", default=CAPSTAN)
ap.add_argument("--g1", default="1,2,4", help="G1 refinement factors ('' for none)")
ap.add_argument("--h1", default="2,4,8", help="H1 refinement factors ('' for none)")
ap.add_argument("--ranks", default="1,2")
ap.add_argument("--steps", type=int, default=0, help="run only this many steps (0: the scene's)")
ap.add_argument("--set", action="append", default=[], metavar="PATH=VALUE",
                help="an extra scene parameter for every run (capstan run --set), e.g. "
                     "'Solver/Pressure Step Schur=Diagonal'; repeatable")
args = ap.parse_args()


def factors(text):
    return [int(x) for x in text.split(",") if x.strip()]


plan = [("G1", f) for f in factors(args.g1)] + [("H1", f) for f in factors(args.h1)]
rows = []
for case, f in plan:
    scene, base = CASES[case]
    cells = [n * f for n in base]
    for ranks in factors(args.ranks):
        tag = f"{case.lower()}-{f}x-{ranks}r" + (f"-{args.steps}steps" if args.steps else "")
        out = os.path.join(args.out, tag)
        s = summary(out, command(args.capstan, scene, out, cells, ranks, args.set, args.steps), tag, "scaling.py")
        steps = s["steps"]
        newton, linear, pstep = totals(s)
        log = os.path.join(out, "log.jsonl")  # a run made by hand with --log newton
        if pstep is None and os.path.isfile(log):
            with open(log) as fh:
                pstep = sum(e.get("iterations", 0) for e in map(json.loads, fh) if e.get("event") == "pressure_step")
        t = s["timing"]
        rows.append({
            "case": case, "factor": f, "cells": "x".join(map(str, cells)), "ranks": ranks,
            "dofs": s["mesh"]["dofs"], "steps": len(steps), "converged": s["converged"],
            "newton": newton, "linear": linear, "linear_per_newton": round(linear / max(newton, 1), 1),
            "pressure_step_linear": pstep,
            "newton_linear_per_newton": None if pstep is None else round((linear - pstep) / max(newton, 1), 1),
            "augmentations": sum(st["augmentations"] for st in steps),
            "total_s": round(t["total"], 2), "per_step_s": round(t["total"] / max(len(steps), 1), 3),
            "per_newton_s": round(t["total"] / max(newton, 1), 4),
            "assembly_s": round(t["assembly"], 2), "preconditioner_setup_s": round(t.get("preconditioner_setup", 0), 2),
            "linear_solve_s": round(t["linear_solve"], 2),
            "peak_mib_per_rank": round(s.get("memory", {}).get("peak_rss_mib_max", float("nan")), 1),
        })

os.makedirs(args.out, exist_ok=True)
with open(os.path.join(args.out, "scaling.csv"), "w", newline="") as fh:
    w = csv.DictWriter(fh, fieldnames=list(rows[0].keys()))
    w.writeheader()
    w.writerows(rows)

head = ["case", "cells", "ranks", "dofs", "Newton", "linear", "linear/Newton", "of it: pressure steps",
        "Newton's linear/Newton", "pressure passes",
        "s/Newton", "s/step", "total s", "assembly s", "prec. set-up s", "linear solve s", "peak MiB/rank"]
lines = ["| " + " | ".join(head) + " |", "|" + "---|" * len(head)]
for r in rows:
    lines.append("| " + " | ".join(str(x) for x in [
        r["case"], r["cells"], r["ranks"], r["dofs"], r["newton"], r["linear"], r["linear_per_newton"],
        "n/a" if r["pressure_step_linear"] is None else r["pressure_step_linear"],
        "n/a" if r["newton_linear_per_newton"] is None else r["newton_linear_per_newton"], r["augmentations"], r["per_newton_s"], r["per_step_s"], r["total_s"], r["assembly_s"],
        r["preconditioner_setup_s"], r["linear_solve_s"], r["peak_mib_per_rank"]]) +
        ("" if r["converged"] else " (did not converge)") + " |")
lines += ["", "2 ranks against 1 (total wall time, same run set):", ""]
for r in rows:
    if r["ranks"] != 1:
        continue
    for q in rows:
        if q["case"] == r["case"] and q["factor"] == r["factor"] and q["ranks"] == 2:
            # Split the speed-up: time per Krylov iteration (what the second rank
            # buys) against the iterations (what the 2-rank preconditioner costs).
            per_it = (r["total_s"] / max(r["linear"], 1)) / (q["total_s"] / max(q["linear"], 1))
            lines.append(f"- {r['case']} {r['cells']} ({r['dofs']} DOFs): {r['total_s'] / q['total_s']:.2f}x "
                         f"({r['total_s']} s vs {q['total_s']} s; Newton {r['newton']} vs {q['newton']}, "
                         f"linear/Newton {r['linear_per_newton']} vs {q['linear_per_newton']}; "
                         f"per Krylov iteration {per_it:.2f}x, Krylov iterations {q['linear'] / max(r['linear'], 1):.2f}x)")
write_report(os.path.join(args.out, "scaling.md"), lines)
plt = pyplot()

fig, axes = plt.subplots(1, 2, figsize=(11, 4.5))
for ax, key, label in [(axes[0], "per_newton_s", "wall time per Newton iteration (s)"),
                       (axes[1], "per_step_s", "wall time per load step (s)")]:
    for case in CASES:
        for ranks in factors(args.ranks):
            pts = sorted((r["dofs"], r[key]) for r in rows if r["case"] == case and r["ranks"] == ranks)
            if not pts:
                continue
            x, y = zip(*pts)
            ax.loglog(x, y, "o-" if ranks == 1 else "s--", label=f"{case}, {ranks} rank{'s' if ranks > 1 else ''}")
            if ranks == 1 and len(pts) > 1:  # ideal: time proportional to DOFs, from the smallest run
                ax.loglog([x[0], x[-1]], [y[0], y[0] * x[-1] / x[0]], ":", color="gray")
    ax.set_xlabel("DOFs")
    ax.set_ylabel(label)
    ax.grid(True, which="both", alpha=0.3)
    ax.legend(fontsize=8)
axes[0].set_title("dotted: ideal slope 1 (time ~ DOFs)")
fig.tight_layout()
fig.savefig(os.path.join(args.out, "scaling.png"), dpi=120)
print(f"wrote {args.out}/scaling.csv, scaling.md, scaling.png")
