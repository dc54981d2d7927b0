#!/usr/bin/python3
"""The steady 3D drive pressed harder than shipped (docs/steady-rolling.md, "Large indentation").

Runs inputs/pinch-roller-steady.xml with the core's force at each multiple of the shipped 4 N:
from rest (the force on within the one step), and ramped over two steps (the second step a
continuation from the first's steady state). Prints per force the Newton iterations, the
step cuts, the speed ratio and the contact width, writes OUT/large-indentation.csv, and plots
Newton iterations and speed ratio against the force (PNG).

  scripts/large-indentation.py [--capstan build/capstan] [--out out/large-indentation]
      [--factors 4,6,7,8,9,10,11,12,14,16,20,25] [--ramped 7,8,9,10]
      [--png docs/img/large-indentation.png]

About a minute on one core with the defaults (16x-25x take 7-10 s each from rest).
"""
import argparse
import csv
import os
import sys

from capstan_runs import ROOT, pyplot, run_scene, save_png

SCENE = "pinch-roller-steady.xml"
SHIPPED_FORCE = 4.0  # N, the scene's Supports/core/Force


def run(capstan, out, factor, ramped):
    """One run at `factor` x the shipped force: (exit status, Newton per step, cuts, speed ratio,
    contact width); the speed ratio and width of the last step (None where it wrote none)."""
    sets = [f"Supports/core/Force={{0, -{factor * SHIPPED_FORCE:g}, 0}}"]
    if ramped:
        sets += ["Time/Steps=2", "Supports/core/Force Ramp Time=0.002"]
    stale = os.path.join(out, "summary.json")
    if os.path.isfile(stale):  # run_scene would read it back if this run writes none
        os.remove(stale)
    rc, _, s = run_scene(capstan, SCENE, out, sets)
    if s is None or not s["steps"]:
        return rc, [], 0, None, None
    last = s["steps"][-1]
    return (rc, [st["newton_iterations"] for st in s["steps"]], sum(st["cutbacks"] for st in s["steps"]),
            last["supports"]["core"].get("speed_ratio"), last["capstans"]["capstan"].get("contact_width"))


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--capstan", default=os.path.join(ROOT, "build", "capstan"))
    ap.add_argument("--out", default=os.path.join(ROOT, "out", "large-indentation"))
    ap.add_argument("--factors", default="4,6,7,8,9,10,11,12,14,16,20,25", help="multiples of the shipped force, from rest")
    ap.add_argument("--ramped", default="7,8,9,10", help="multiples also ramped over two steps")
    ap.add_argument("--png", default=os.path.join(ROOT, "docs", "img", "large-indentation.png"))
    a = ap.parse_args()
    factors = [float(f) for f in a.factors.split(",") if f.strip()]
    ramped = [float(f) for f in a.ramped.split(",") if f.strip()]
    os.makedirs(a.out, exist_ok=True)
    rows = []
    for factor in sorted(set(factors) | set(ramped)):
        for ramp in ([False] if factor in factors else []) + ([True] if factor in ramped else []):
            out = os.path.join(a.out, f"x{factor:g}" + ("-ramped" if ramp else ""))
            rc, newton, cuts, ratio, width = run(a.capstan, out, factor, ramp)
            rows.append(dict(factor=factor, force=factor * SHIPPED_FORCE, ramped=ramp, exit=rc,
                             newton="+".join(str(n) for n in newton), newton_total=sum(newton), cuts=cuts,
                             speed_ratio=ratio, contact_width=width))
            print(f"  {factor:g}x ({factor * SHIPPED_FORCE:g} N){' ramped' if ramp else ''}: exit {rc}, "
                  f"Newton {rows[-1]['newton']}, cuts {cuts}, speed ratio {ratio}", flush=True)
    with open(os.path.join(a.out, "large-indentation.csv"), "w", newline="") as fh:
        w = csv.DictWriter(fh, fieldnames=list(rows[0]))
        w.writeheader()
        w.writerows(rows)

    fmt = lambda x, f: "-" if x is None else format(x, f)
    print("\n| force | from rest: Newton (cuts) | speed ratio | contact width (mm) | ramped over two steps |")
    print("|---|---|---|---|---|")
    for factor in sorted(set(factors) | set(ramped)):
        rest = next((r for r in rows if r["factor"] == factor and not r["ramped"]), None)
        ramp = next((r for r in rows if r["factor"] == factor and r["ramped"]), None)
        cell = lambda r: "-" if r is None else (f"{r['newton']}" + (f" ({r['cuts']} cut{'s' if r['cuts'] > 1 else ''})" if r["cuts"] else "") +
                                                ("" if r["exit"] == 0 else f", exit {r['exit']}"))
        print(f"| {factor:g}x ({factor * SHIPPED_FORCE:g} N) | {cell(rest)} | "
              f"{fmt(rest and rest['speed_ratio'], '.5f')} | {fmt(rest and rest['contact_width'], '.3f')} | "
              f"{cell(ramp)} |")

    plt = pyplot()
    fig, (left, right) = plt.subplots(1, 2, figsize=(11, 4.2))
    for ramp, style, label in ((False, "o-", "from rest"), (True, "s--", "ramped over two steps")):
        rs = [r for r in rows if r["ramped"] == ramp]
        if not rs:
            continue
        left.plot([r["force"] for r in rs], [r["newton_total"] for r in rs], style, label=label)
        for r in rs:
            if r["cuts"]:
                left.annotate(f"{r['cuts']} cut" + ("s" if r["cuts"] > 1 else ""), (r["force"], r["newton_total"]),
                              textcoords="offset points", xytext=(4, 4), fontsize=8)
    rest = [r for r in rows if not r["ramped"] and r["speed_ratio"] is not None]
    right.plot([r["force"] for r in rest], [r["speed_ratio"] for r in rest], "o-")
    left.set_xlabel("core force (N)")
    left.set_ylabel("Newton iterations (all steps)")
    left.set_title("steady 3D drive, pressed harder")
    left.legend(fontsize=9)
    right.set_xlabel("core force (N)")
    right.set_ylabel("speed ratio")
    right.set_title("free roller, mu = 0.8")
    for ax in (left, right):
        ax.grid(alpha=0.3)
    fig.tight_layout()
    save_png(fig, a.png, dpi=130)
    return 1 if any(r["exit"] != 0 for r in rows) else 0


if __name__ == "__main__":
    sys.exit(main())
