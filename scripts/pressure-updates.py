#!/usr/bin/python3
"""The pressure loop's two frictionless updates side by side: Monolithic (a
saddle-point step alone in every pass, Newton's method on positions, anchors and
contact multipliers together; Auto's choice with exact linear solves) against
Saddle Point (the step after each Newton solve on the positions).

Runs each scene with both, alternating, ROUNDS times, and prints per scene and
update: the median run time (summary.json timing.total), the Newton iterations
(a monolithic step counts as one), the Krylov iterations, and the largest
relative difference of the capstan forces between the two. Writes
OUT/pressure-updates.csv and OUT/pressure-updates.png (run times, bars).

Usage: scripts/pressure-updates.py [--out out/pressure-updates] [--rounds 3]
       [--capstan build/capstan] [--cases g1,g2,g3,two,hertz]
       (also "g1x2 LU" and "g1x2 MueLu": G1 2x with each preconditioner)
"""
import argparse
import csv
import os
import statistics
import sys

sys.dont_write_bytecode = True
sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from capstan_runs import CAPSTAN, run_scene  # noqa: E402

CASES = {  # name: (scene under inputs/, extra --set)
    "g1": ("seed/g1.xml", []),
    "g2": ("seed/g2.xml", []),
    "g3": ("seed/g3.xml", []),
    "two": ("two-capstans.xml", []),
    "hertz": ("hertz-roller.xml", []),
    # 10,179 unknowns: above Auto's direct size on a box, so the LU
    # preconditioner is asked for, and MueLu shown both ways.
    "g1x2 LU": ("seed/g1.xml", ["Mesh/Cells={28,8,12}", "Solver/Linear Solver=GMRES", "Solver/Preconditioner=LU"]),
    "g1x2 MueLu": ("seed/g1.xml", ["Mesh/Cells={28,8,12}", "Solver/Linear Solver=GMRES",
                                   "Solver/Preconditioner=MueLu"]),
}
UPDATES = ("Monolithic", "Saddle Point")


def forces(s):
    return [x for st in s["steps"] for c in st.get("capstans", {}).values() for x in c["force"]]


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--out", default="out/pressure-updates")
    ap.add_argument("--rounds", type=int, default=3)
    ap.add_argument("--capstan", default=CAPSTAN)
    ap.add_argument("--cases", default="g1,g2,g3,two,hertz")
    a = ap.parse_args()
    names = a.cases.split(",")
    for n in names:
        if n not in CASES:
            sys.exit(f"pressure-updates.py: unknown case {n!r} (one of {', '.join(CASES)})")
    os.makedirs(a.out, exist_ok=True)
    runs = {}
    for r in range(a.rounds):
        for n in names:
            scene, sets = CASES[n]
            for u in UPDATES:
                out = os.path.join(a.out, f"{n.replace(' ', '-')}-{u.split()[0].lower()}")
                rc, _, s = run_scene(a.capstan, scene, out, sets + [f"Solver/Pressure Update={u}"])
                if s is None or not s["converged"]:
                    sys.exit(f"pressure-updates.py: {n} {u}: exit {rc}, not converged")
                runs.setdefault((n, u), []).append(s)
                print(f"  round {r + 1} {n} {u}: {s['timing']['total']:.3f} s", flush=True)
    rows = []
    for n in names:
        mono, nested = runs[(n, UPDATES[0])][0], runs[(n, UPDATES[1])][0]
        fm, fn = forces(mono), forces(nested)
        scale = max(abs(x) for x in fn) or 1.0
        diff = max(abs(x - y) for x, y in zip(fm, fn)) / scale
        for u in UPDATES:
            ss = runs[(n, u)]
            t = [s["timing"]["total"] for s in ss]
            rows.append({"case": n, "update": u, "median_s": statistics.median(t), "min_s": min(t), "max_s": max(t),
                         "newton": sum(st["newton_iterations"] for st in ss[0]["steps"]),
                         "krylov": sum(st["linear_iterations"] for st in ss[0]["steps"]),
                         "force_difference": diff})
    print(f"\n{'case':12s} {'update':13s} {'median s':>9s} {'range':>15s} {'Newton':>7s} {'Krylov':>7s}  forces differ")
    for row in rows:
        print(f"{row['case']:12s} {row['update']:13s} {row['median_s']:9.3f} "
              f"{row['min_s']:7.3f}-{row['max_s']:<7.3f} {row['newton']:7d} {row['krylov']:7d}  "
              f"{row['force_difference']:.1e}")
    for n in names:
        m = next(r for r in rows if r["case"] == n and r["update"] == UPDATES[0])["median_s"]
        s = next(r for r in rows if r["case"] == n and r["update"] == UPDATES[1])["median_s"]
        print(f"{n}: Monolithic {s / m:.2f}x as fast as Saddle Point")
    with open(os.path.join(a.out, "pressure-updates.csv"), "w", newline="") as f:
        w = csv.DictWriter(f, fieldnames=list(rows[0]))
        w.writeheader()
        w.writerows(rows)
    try:
        import matplotlib
        matplotlib.use("Agg")
        import matplotlib.pyplot as plt
    except ImportError:
        print("matplotlib missing: no PNG")
        return
    fig, ax = plt.subplots(figsize=(8, 4))
    width = 0.38
    for k, u in enumerate(UPDATES):
        ys = [next(r for r in rows if r["case"] == n and r["update"] == u)["median_s"] for n in names]
        ax.bar([i + (k - 0.5) * width for i in range(len(names))], ys, width, label=u)
    ax.set_xticks(range(len(names)))
    ax.set_xticklabels(names)
    ax.set_ylabel("run time, median of %d (s)" % a.rounds)
    ax.set_yscale("log")
    ax.set_title("Pressure Update: Monolithic against Saddle Point (no friction, 1 rank)")
    ax.legend()
    fig.tight_layout()
    fig.savefig(os.path.join(a.out, "pressure-updates.png"), dpi=110)
    print("wrote", os.path.join(a.out, "pressure-updates.png"))


if __name__ == "__main__":
    main()
