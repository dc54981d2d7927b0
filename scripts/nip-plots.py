#!/usr/bin/python3
"""Pictures of a roller's nip from a run's fields.h5 (last step, or --step):

    scripts/nip-plots.py OUTDIR --capstan-axis X,Y --capstan-radius R [--hertz E*,R_roller,LENGTH]
                         [--png nip.png]

Left: the deformed section near the nip (nodes at z = zmin), the contact faces coloured
by their contact pressure, the capstan's circle, and the faces where every contact point
sticks (S) or some slip (s). Right: contact pressure against the arc length on the
capstan from the contact's centre, with Hertz's p0 sqrt(1 - s^2/a^2) when --hertz is
given (a, p0 from the measured force per length of summary.json).
"""
import argparse
import json
import math
import os

import h5py
import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402
from matplotlib.collections import LineCollection  # noqa: E402

ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
ap.add_argument("outdir")
ap.add_argument("--capstan-axis", required=True, help="x,y of the capstan's axis (parallel to z)")
ap.add_argument("--capstan-radius", type=float, required=True)
ap.add_argument("--hertz", help="E*,R_roller,length: overlay Hertz's line-contact profile")
ap.add_argument("--step", type=int, default=-1)
ap.add_argument("--png", default=None)
ap.add_argument("--title", default="")
args = ap.parse_args()

cx, cy = (float(v) for v in args.capstan_axis.split(","))
Rc = args.capstan_radius
with h5py.File(os.path.join(args.outdir, "fields.h5"), "r") as f:
    steps = sorted(f["steps"].keys())
    key = steps[args.step]
    g = f["steps"][key]
    xyz = g["coordinates"][()]
    quads = f["mesh/quads"][()]
    hexes = f["mesh/hexahedra"][()]
    p = g["faces/contact_pressure"][()][:, 0]
    stick = g["faces/stick_points"][()][:, 0] if "faces/stick_points" in g else np.zeros(len(quads))
    slip = g["faces/slip_points"][()][:, 0] if "faces/slip_points" in g else np.zeros(len(quads))
with open(os.path.join(args.outdir, "summary.json")) as fs:
    summary = json.load(fs)
last = summary["steps"][args.step]
force = last["capstans"]["capstan"]["force"]

# Contact direction: from the capstan's axis towards the body (along -force).
nf = math.hypot(force[0], force[1])
ex, ey = -force[0] / nf, -force[1] / nf
zmin = xyz[:, 2].min()
front = np.abs(xyz[:, 2] - zmin) < 1e-9

fig, (ax, bx) = plt.subplots(1, 2, figsize=(11, 4.6))
# Element edges of the front face near the nip.
centre = np.array([cx + Rc * ex, cy + Rc * ey])
segs = []
for h in hexes:
    for a, b in ((0, 1), (1, 2), (2, 3), (3, 0)):
        i, j = h[a], h[b]
        if front[i] and front[j]:
            segs.append([xyz[i, :2], xyz[j, :2]])
segs = np.array(segs)
near = np.linalg.norm(segs.mean(axis=1) - centre, axis=1) < 12 * max(1e-12, last["capstans"]["capstan"]["contact_width"] / 2 + 0.05)
ax.add_collection(LineCollection(segs[near], colors="0.75", linewidths=0.5))
# Contact faces: their front edge, coloured by pressure.
fsegs, fp, marks = [], [], []
arc, parc = [], []
for q, (pp, st, sl) in enumerate(zip(p, stick, slip)):
    nodes = [n for n in quads[q] if front[n]]
    c = xyz[quads[q]].mean(axis=0)
    ang = math.atan2((c[0] - cx) * (-ey) + (c[1] - cy) * ex, (c[0] - cx) * ex + (c[1] - cy) * ey)
    if len(nodes) == 2:
        fsegs.append([xyz[nodes[0], :2], xyz[nodes[1], :2]])
        fp.append(pp)
        if pp > 0 and st + sl > 0:
            marks.append((c[0], c[1], "S" if sl == 0 else "s"))
    if abs(ang) < 0.5:
        arc.append(Rc * ang)
        parc.append(pp)
lc = LineCollection(np.array(fsegs), array=np.array(fp), cmap="viridis", linewidths=4)
ax.add_collection(lc)
fig.colorbar(lc, ax=ax, label="contact pressure (face mean)")
t = np.linspace(0, 2 * math.pi, 400)
ax.plot(cx + Rc * np.cos(t), cy + Rc * np.sin(t), "k-", lw=1)
for x, y, m in marks:
    ax.text(x + 0.04 * ex, y + 0.04 * ey, m, fontsize=6, ha="center", va="center",
            color="C3" if m == "s" else "C2")
w = max(0.6, 3 * last["capstans"]["capstan"]["contact_width"])
ax.set_xlim(centre[0] - w, centre[0] + w)
ax.set_ylim(centre[1] - w, centre[1] + w)
ax.set_aspect("equal")
ax.set_title("deformed nip (S: all points stick, s: some slip)")

order = np.argsort(arc)
bx.plot(np.array(arc)[order], np.array(parc)[order], "o-", ms=3, label="capstan (face means)")
if args.hertz:
    E, Rr, L = (float(v) for v in args.hertz.split(","))
    R = 1 / (1 / Rc + 1 / Rr)
    P = nf / L
    a = math.sqrt(4 * P * R / (math.pi * E))
    p0 = 2 * P / (math.pi * a)
    s = np.linspace(-a, a, 200)
    bx.plot(s, p0 * np.sqrt(1 - (s / a) ** 2), "k--", label=f"Hertz: p0 = {p0:.4g}, a = {a:.4g}")
bx.set_xlim(-w, w)
bx.set_xlabel("arc length on the capstan from the contact's centre")
bx.set_ylabel("contact pressure")
bx.legend(fontsize=8)
bx.set_title("pressure across the nip")
fig.suptitle(args.title or f"{args.outdir}, step {last['step']}")
fig.tight_layout()
png = args.png or os.path.join(args.outdir, "nip.png")
fig.savefig(png, dpi=120)
print("wrote " + png)
