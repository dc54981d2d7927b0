#!/usr/bin/python3
"""How much a steady run's friction shear alternates from face to face in its stick zone
(docs/steady-rolling.md, "Open"):

    scripts/stick-shear.py RUN_DIR [RUN_DIR ...] [--mu 0.8]

For each run (its fields.h5, last step): along every ring of contact faces (the faces at
one z, ordered by angle about the mesh's z axis), each face whose two ring neighbours and
itself stick at all their points gives the second difference of its shear (the friction
traction along the ring's direction), t_f - (t_f-1 + t_f+1) / 2, and of the pressure of the
element under it. Printed per run: the stick faces counted, the shear's rms and largest
second difference over mu p_max (p_max the largest contact pressure), the element
pressures' rms, and the correlation of the two.
"""
import argparse
import os

import h5py
import numpy as np

ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
ap.add_argument("runs", nargs="+")
ap.add_argument("--mu", type=float, default=0.8, help="the friction coefficient (scales the figures)")
args = ap.parse_args()


def alternation(run):
    with h5py.File(os.path.join(run, "fields.h5"), "r") as f:
        step = f["steps"][sorted(f["steps"].keys())[-1]]
        x = step["coordinates"][:]
        hexes, quads = f["mesh/hexahedra"][:], f["mesh/quads"][:]
        p = step["elements/pressure"][:, 0]
        traction = step["faces/friction_traction"][:]
        pc = step["faces/contact_pressure"][:, 0]
        stick = step["faces/stick_points"][:, 0]
    centre = x[quads].mean(axis=1)
    angle, z = np.arctan2(centre[:, 1], centre[:, 0]), centre[:, 2]
    shear = traction[:, 0] * -np.sin(angle) + traction[:, 1] * np.cos(angle)
    # The element under a face: the hexahedron holding its four nodes.
    holding = {}
    for e, h in enumerate(hexes):
        for n in h:
            holding.setdefault(int(n), set()).add(e)
    dt, dp = [], []
    for level in np.unique(np.round(z, 4)):
        ring = np.where((np.abs(z - level) < 1e-3) & (pc > 0))[0]
        ring = ring[np.argsort(angle[ring])]
        under = [min(set.intersection(*(holding[int(n)] for n in quads[f]))) for f in ring]
        corners = quads.shape[1]
        for i in range(1, len(ring) - 1):
            if all(stick[ring[j]] == corners for j in (i - 1, i, i + 1)):
                dt.append(shear[ring[i]] - 0.5 * (shear[ring[i - 1]] + shear[ring[i + 1]]))
                dp.append(p[under[i]] - 0.5 * (p[under[i - 1]] + p[under[i + 1]]))
    return np.array(dt), np.array(dp), pc.max()


print("| run | stick faces | shear 2nd difference rms / mu p_max | largest | element pressure 2nd difference rms [MPa] | correlation |")
print("|---|---|---|---|---|---|")
for run in args.runs:
    dt, dp, pmax = alternation(run)
    if len(dt) < 2:
        print(f"| {run} | {len(dt)} | - | - | - | - |")
        continue
    scale = args.mu * pmax
    corr = np.corrcoef(dt, dp)[0, 1] if dp.std() > 0 and dt.std() > 0 else float("nan")
    print(f"| {run} | {len(dt)} | {np.sqrt(np.mean(dt**2)) / scale:.3f} | {np.abs(dt).max() / scale:.3f} | "
          f"{np.sqrt(np.mean(dp**2)):.4f} | {corr:+.2f} |")
