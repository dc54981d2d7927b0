#!/usr/bin/python3
"""Speed ratio and capstan torque against the brake torque on the pinch roller
(inputs/pinch-roller-braked.xml, the 1 mm plane-strain slice), and a table of a
finished pinch-roller run's figures per step.

    scripts/pinch-roller-study.py [--out out/pinch-study] [--torques 0,0.15,...] [--steps 48]
    scripts/pinch-roller-study.py --figures out/pinch-roller/summary.json

The brake study runs one scene per torque (runs whose summary.json exists are reused),
averages the speed ratio over the second half of the steps (the first ones start the
roller from rest), and writes brake.csv, brake.md and brake.png into --out. The nip
can carry at most mu F R = 0.8 x 0.25 x 6.25 = 1.25 N mm per mm: a larger torque ends
with exit 2 and is listed as such.
"""
import argparse
import json
import os
import subprocess
import sys

root = os.path.join(os.path.dirname(os.path.abspath(__file__)), "..")
ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
ap.add_argument("--out", default="out/pinch-study")
ap.add_argument("--torques", default="0,0.15,0.3,0.45,0.6,0.8,1.0,1.5")
ap.add_argument("--steps", type=int, default=48)
ap.add_argument("--capstan", default=os.path.join(root, "build", "capstan"))
ap.add_argument("--figures", help="print the per-step table of this summary.json and stop")
args = ap.parse_args()


def per_step_table(summary):
    print("| step | t | nip width | peak pressure | contact area | speed ratio | stick / slip | core torque | "
          "Newton | linear | cuts | wall s |")
    print("|---|---|---|---|---|---|---|---|---|---|---|---|")
    for st in summary["steps"]:
        cap, core = st["capstans"]["capstan"], st["supports"]["core"]
        print(f"| {st['step']} | {st['time']:.4g} | {cap['contact_width']:.4f} | {cap['peak_pressure']:.4f} | "
              f"{cap['contact_area']:.4f} | {core.get('speed_ratio', float('nan')):.5f} | "
              f"{cap['stick_points']} / {cap['slip_points']} | {core['torque']:.2e} | {st['newton_iterations']} | "
              f"{st['linear_iterations']} | {st['cutbacks']} | {st['wall_seconds']:.1f} |")


if args.figures:
    with open(args.figures) as f:
        per_step_table(json.load(f))
    sys.exit(0)

scene = os.path.join(root, "inputs", "pinch-roller-braked.xml")
os.makedirs(args.out, exist_ok=True)
rows = []
for M in [float(x) for x in args.torques.split(",")]:
    out = os.path.join(args.out, f"torque-{M:g}")
    path = os.path.join(out, "summary.json")
    if not os.path.isfile(path):
        cmd = [args.capstan, "run", scene, "--output", out, "--quiet", "--set", f"Supports/core/Torque={M:g}",
               "--set", f"Time/Steps={args.steps}"]
        print("$ " + " ".join(cmd), flush=True)
        subprocess.run(cmd)
    with open(path) as f:
        s = json.load(f)
    steps = s["steps"]
    if not s["converged"] or len(steps) < args.steps:
        rows.append((M, None, None, None, None, s["failure"]))
        continue
    late = steps[len(steps) // 2:]
    ratio = sum(st["supports"]["core"]["speed_ratio"] for st in late) / len(late)
    torque = sum(st["capstans"]["capstan"]["torque"] for st in late) / len(late)
    slip = sum(st["capstans"]["capstan"]["slip_points"] for st in late) / len(late)
    stick = sum(st["capstans"]["capstan"]["stick_points"] for st in late) / len(late)
    rows.append((M, ratio, torque, stick, slip, None))

with open(os.path.join(args.out, "brake.csv"), "w") as f:
    f.write("brake_torque,speed_ratio,capstan_torque,stick_points,slip_points,failure\n")
    for M, r, t, st, sl, fail in rows:
        f.write(f"{M},{'' if r is None else r},{'' if t is None else t},{'' if st is None else st},"
                f"{'' if sl is None else sl},{fail or ''}\n")
lines = ["| brake torque (N mm/mm) | speed ratio | capstan torque (N mm/mm) | stick / slip points |", "|---|---|---|---|"]
for M, r, t, st, sl, fail in rows:
    lines.append(f"| {M:g} | no equilibrium (exit 2) | | |" if r is None else
                 f"| {M:g} | {r:.5f} | {t:.5f} | {st:.0f} / {sl:.0f} |")
text = "\n".join(lines)
print(text)
with open(os.path.join(args.out, "brake.md"), "w") as f:
    f.write(text + "\n")

try:
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
except ImportError:
    sys.exit("matplotlib missing: no brake.png (use /usr/bin/python3)")
ok = [x for x in rows if x[1] is not None]
fig, ax = plt.subplots(figsize=(6, 4))
ax.plot([x[0] for x in ok], [x[1] for x in ok], "o-", color="C0", label="speed ratio")
ax.set_xlabel("brake torque on the core (N mm per mm of roller)")
ax.set_ylabel("speed ratio (roller / capstan surface)", color="C0")
ax.axvline(0.8 * 0.25 * 6.25, color="gray", ls=":", label="mu F R: no equilibrium beyond")
ax2 = ax.twinx()
ax2.plot([x[0] for x in ok], [-x[2] for x in ok], "s--", color="C1", label="capstan torque (drive)")
ax2.set_ylabel("torque the capstan must supply (N mm per mm)", color="C1")
ax.set_title("Pinch roller slice: speed ratio and capstan torque vs brake")
h1, l1 = ax.get_legend_handles_labels()
h2, l2 = ax2.get_legend_handles_labels()
ax.legend(h1 + h2, l1 + l2, loc="center left", fontsize=8)
fig.tight_layout()
fig.savefig(os.path.join(args.out, "brake.png"), dpi=120)
print("wrote " + os.path.join(args.out, "brake.png"))
