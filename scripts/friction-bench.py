#!/usr/bin/env python3
"""Frictional contact's Newton cost, scene by scene (issue 33; docs/friction.md).

Runs, one after the other on this machine, and prints per run the exit status, Newton
iterations per step (mean and largest), step cuts and wall time:
  * the study's H1-H5 (inputs/seed/) with each law, Tanh, Arctan and Coulomb, and exact
    contact (the augmented Lagrangian);
  * the rolling slice, inputs/pinch-roller-slice.xml (20 steps), with the streamline shift
    (the default Solver/Rolling Predictor) and with the rigid roll;
  * fast free rollers: inputs/free-roller-fast.xml (one nip cell per step) and with twice
    its Step Size (two cells), for mu 0.3, 0.6, 0.9 and spring forces 0.125, 0.25, 0.5 N
    (--steps steps each, default 8); --rolling-predictor "Rigid Roll" runs them with the roll;
  * with --drive, the 3D drive inputs/pinch-roller.xml, its first --drive-steps steps
    (default 5; minutes).
Writes OUT/friction-bench.csv, OUT/friction-bench.md and OUT/friction-bench.png (Newton
iterations per step against the case, failed runs marked).

  scripts/friction-bench.py [--capstan build/capstan] [--out out/friction-bench]
                            [--only seed,slice,fast] [--steps 8] [--drive] [--drive-steps 5]
  scripts/friction-bench.py --replot --out DIR    (the picture again from DIR's CSV)
Run it with /usr/bin/python3 (Debian's, which has matplotlib).
"""
import argparse
import csv
import os

from capstan_runs import ROOT, run_scene

AL = "Capstans/capstan/Contact/Method=Augmented Lagrangian"
F = "Capstans/capstan/Friction/"


def run(capstan, scene, out, sets):
    rc, wall, summary = run_scene(capstan, scene, out, sets)
    steps = summary["steps"] if summary else []
    newton = [s["newton_iterations"] for s in steps]
    return {"rc": rc, "wall": wall, "steps": len(steps),
            "newton_mean": sum(newton) / len(newton) if newton else 0.0,
            "newton_max": max(newton) if newton else 0, "cuts": sum(s["cutbacks"] for s in steps)}


def cases(a):
    if "seed" in a.only:
        for name in ("h1", "h2", "h3", "h4", "h5"):
            for law in ("Tanh", "Arctan", "Coulomb"):
                yield f"{name.upper()} {law}", f"seed/{name}.xml", [AL, F + "Law=" + law]
    if "slice" in a.only:
        yield "slice", "pinch-roller-slice.xml", []
        yield "slice, rigid roll", "pinch-roller-slice.xml", ["Solver/Rolling Predictor=Rigid Roll"]
    if "fast" in a.only:
        for cells, size in ((1, 0.004), (2, 0.008)):
            for mu in (0.3, 0.6, 0.9):
                for force in (0.125, 0.25, 0.5):
                    yield (f"fast roller, {cells} cell/step, mu {mu}, {force} N", "free-roller-fast.xml",
                           [f"Time/Step Size={size}", f"Time/Steps={a.steps}", F + f"Coefficient={mu}",
                            "Supports/core/Force={0, %g, 0}" % -force] + a.predictor)
    if a.drive:
        yield "3D drive", "pinch-roller.xml", [f"Time/Steps={a.drive_steps}"]


def plot(rows, out):
    try:
        import matplotlib
        matplotlib.use("Agg")
        import matplotlib.pyplot as plt
    except ImportError:
        print("matplotlib not found (run with /usr/bin/python3): no picture")
        return
    fig, ax = plt.subplots(figsize=(10, 0.28 * len(rows) + 1.5))
    y = list(range(len(rows)))
    ax.barh(y, [r["newton_mean"] for r in rows],
            color=["tab:blue" if r["rc"] == 0 else "tab:red" for r in rows])
    for i, r in enumerate(rows):
        ax.text(r["newton_mean"], i, f"  {r['cuts']} cuts" + ("" if r["rc"] == 0 else f", exit {r['rc']}"),
                va="center", fontsize=7)
    ax.set_yticks(y)
    ax.set_yticklabels([r["case"] for r in rows], fontsize=7)
    ax.invert_yaxis()
    ax.set_xscale("log")
    ax.axvline(25, color="gray", ls="--", lw=0.8)
    ax.set_xlabel("Newton iterations per converged step (mean, log scale; dashed: 25); red: did not finish")
    ax.set_title("Frictional contact: Newton cost per scene (scripts/friction-bench.py)")
    fig.tight_layout()
    fig.savefig(os.path.join(out, "friction-bench.png"), dpi=120)


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--capstan", default=os.path.join(ROOT, "build", "capstan"))
    ap.add_argument("--out", default=os.path.join(ROOT, "out", "friction-bench"))
    ap.add_argument("--only", default="seed,slice,fast", help="comma-separated: seed, slice, fast")
    ap.add_argument("--steps", type=int, default=8, help="steps of each fast roller (default 8)")
    ap.add_argument("--drive", action="store_true", help="also the 3D drive (minutes)")
    ap.add_argument("--drive-steps", type=int, default=5)
    ap.add_argument("--replot", action="store_true", help="only draw the picture from OUT's CSV")
    ap.add_argument("--rolling-predictor", default="", help='the fast rollers\' Solver/Rolling Predictor')
    ap.add_argument("--set", action="append", default=[], metavar="PATH=VALUE",
                    help="a scene parameter for every run (repeatable), e.g. 'Solver/Multiplier Acceleration=Pressure'")
    a = ap.parse_args()
    a.only = a.only.split(",")
    a.predictor = [f"Solver/Rolling Predictor={a.rolling_predictor}"] if a.rolling_predictor else []
    os.makedirs(a.out, exist_ok=True)
    if a.replot:
        with open(os.path.join(a.out, "friction-bench.csv")) as f:
            rows = [dict(r, rc=int(r["rc"]), newton_mean=float(r["newton_mean"]), cuts=int(r["cuts"]))
                    for r in csv.DictReader(f)]
        plot(rows, a.out)
        return
    rows = []
    print("| case | exit | steps | Newton per step (mean, max) | cuts | wall |\n|---|---|---|---|---|---|")
    for k, (label, scene, sets) in enumerate(cases(a)):
        r = run(a.capstan, scene, os.path.join(a.out, f"run{k:02d}"), sets + a.set)
        r["case"] = label
        rows.append(r)
        print(f"| {label} | {r['rc']} | {r['steps']} | {r['newton_mean']:.1f}, {r['newton_max']} | {r['cuts']} | "
              f"{r['wall']:.1f} s |", flush=True)
    keys = ["case", "rc", "steps", "newton_mean", "newton_max", "cuts", "wall"]
    with open(os.path.join(a.out, "friction-bench.csv"), "w", newline="") as f:
        w = csv.DictWriter(f, fieldnames=keys)
        w.writeheader()
        for r in rows:
            w.writerow({k: r[k] for k in keys})
    with open(os.path.join(a.out, "friction-bench.md"), "w") as f:
        f.write("| case | exit | steps | Newton per step (mean, max) | cuts | wall |\n|---|---|---|---|---|---|\n")
        for r in rows:
            f.write(f"| {r['case']} | {r['rc']} | {r['steps']} | {r['newton_mean']:.1f}, {r['newton_max']} | "
                    f"{r['cuts']} | {r['wall']:.1f} s |\n")
    plot(rows, a.out)
    print(f"wrote {a.out}/friction-bench.csv, .md, .png")


if __name__ == "__main__":
    main()
