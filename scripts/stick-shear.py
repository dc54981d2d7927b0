#!/usr/bin/python3
"""How much a steady run's friction shear alternates from face to face in its stick zone
(docs/steady-rolling.md, "In the stick zone the shear alternates from node to node"):

    scripts/stick-shear.py RUN_DIR [RUN_DIR ...] [--mu 0.8]

For each run (its fields.h5, last step): along every ring of contact faces (the faces at
one z, ordered by angle about the mesh's z axis), each face whose two ring neighbours and
itself stick at all their points gives the second difference of its shear (the friction
traction along the ring's direction), t_f - (t_f-1 + t_f+1) / 2, and of the pressure of the
element under it. Printed per run: the stick faces counted, the shear's rms and largest
second difference over mu p_max (p_max the largest contact pressure), the element
pressures' rms, and the correlation of the two.

Then, per run, the nodes (nip.csv's rows of the last step, matched to the mesh's surface
nodes by s and z): a sticking node's friction shear against the jump of pressure across it,
p(element behind) - p(element ahead) of the two outer-layer elements that share it. Under
Q1P0 a pressure jump pushes the node along the ring (by the jump times half the outer
element's thickness per unit length), and in the stick zone the shear is what holds the
node: the table gives the correlation of the two's alternating parts (each less its
1/4, 1/2, 1/4 average over the node and its ring neighbours) and their ratio. The capstan's
axis, radius and turning sense come from the run's scene: its scene.xml (the scene as the
run resolved it, --set overrides included), or --scene.
"""
import argparse
import csv
import json
import os
import xml.etree.ElementTree as ET

import h5py
import numpy as np

ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
ap.add_argument("runs", nargs="+")
ap.add_argument("--mu", type=float, default=0.8, help="the friction coefficient (scales the figures)")
ap.add_argument("--scene", help="the runs' scene (default: each run's scene.xml)")
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


def capstan_of(scene_path):
    """(axis point, axis direction, radius, sense) of the scene's first capstan."""
    root = ET.parse(scene_path).getroot()
    mesh = {e.get("name"): e.get("value") for e in [m for m in root if m.get("name") == "Mesh"][0] if e.tag == "Parameter"}
    caps = [e for e in root if e.get("name") == "Capstans"][0][0]
    val = {e.get("name"): e.get("value") for e in caps if e.tag == "Parameter"}
    vec = lambda t: np.array([float(v) for v in t.strip("{} ").split(",")])
    b = vec(val["Axis Direction"])
    return vec(val["Axis Point"]), b / np.linalg.norm(b), float(val["Radius"]), \
        1.0 if float(val.get("Angular Velocity", "1")) >= 0 else -1.0, vec(mesh.get("Center", "{0, 0, 0}"))


def node_jumps(run):
    """Per sticking node with two sticking ring neighbours: the alternating parts of
    (shear, pressure jump)."""
    scene = args.scene or os.path.join(run, "scene.xml")  # the run's resolved scene (capstan writes it)
    if not os.path.exists(scene):  # a run from before scene.xml
        with open(os.path.join(run, "summary.json")) as f:
            scene = json.load(f)["scene"]
    a, b, radius, sense, roller = capstan_of(scene)
    with h5py.File(os.path.join(run, "fields.h5"), "r") as f:
        step = f["steps"][sorted(f["steps"].keys())[-1]]
        x = step["coordinates"][:]
        X = x - step["nodes/displacement"][:]
        hexes = f["mesh/hexahedra"][:]
        p = step["elements/pressure"][:, 0]
    with open(os.path.join(run, "nip.csv")) as f:
        rows = list(csv.DictReader(f))
    last = max(int(r["step"]) for r in rows)
    nodes = {}
    for r in rows:
        if int(r["step"]) == last:
            nodes[(round(float(r["s"]), 7), round(float(r["z"]), 7))] = (float(r["shear"]), r["state"])
    # The mesh's surface nodes (outer radius about its z axis), their s and z as nip.csv's.
    rc = np.round(np.hypot(*X[hexes].mean(axis=1)[:, :2].T), 6)
    centre = x[hexes].mean(axis=1)  # where the elements are now
    outer = np.where(rc == rc.max())[0]
    rn = np.hypot(X[:, 0], X[:, 1])
    surface = np.unique(hexes[outer])
    surface = surface[np.abs(rn[surface] - rn[surface].max()) < 1e-9]
    n0 = roller - a  # the mesh's centre, not the core's moved axis (nip.csv's): 1e-3 mm of s apart
    n0 = n0 - b * (n0 @ b)
    n0 /= np.linalg.norm(n0)
    d = x[surface] - a
    e = d - np.outer(d @ b, b)
    e /= np.linalg.norm(e, axis=1)[:, None]
    phi = np.arctan2(np.cross(n0, e) @ b, e @ n0)
    s_n, z_n = sense * radius * phi, d @ b
    owner = {}
    for k in outer:
        for n in hexes[k]:
            owner.setdefault(int(n), []).append(int(k))
    out = []
    zs = sorted({z for _, z in nodes})
    for z in zs:
        ring = sorted((s_, v) for (s_, z_), v in nodes.items() if z_ == z)
        pts = []
        for s_, (shear, state) in ring:
            k = int(np.argmin((s_n - s_) ** 2 + (z_n - z) ** 2))
            n = int(surface[k])
            els = owner.get(n, [])
            # the outer elements holding the node, nearest in z first: two behind it and two
            # ahead where it sits between axial layers, one each on a face of the body
            els = sorted(els, key=lambda el: abs(((centre[el] - a) @ b) - z))[:4]
            ang = {el: np.arctan2(np.cross(n0, centre[el] - a) @ b, (centre[el] - a) @ n0) for el in els}
            behind = [el for el in els if sense * ang[el] < sense * phi[k]]
            ahead = [el for el in els if sense * ang[el] > sense * phi[k]]
            jump = np.mean(p[behind]) - np.mean(p[ahead]) if behind and ahead else np.nan
            pts.append((shear, jump, state))
        for i in range(1, len(pts) - 1):
            if all(pts[j][2] == "stick" for j in (i - 1, i, i + 1)) and not np.isnan(
                    [pts[j][1] for j in (i - 1, i, i + 1)]).any():
                alt = lambda j: pts[i][j] - 0.25 * (pts[i - 1][j] + 2 * pts[i][j] + pts[i + 1][j])
                out.append((alt(0), alt(1)))
    return np.array(out)


print()
print("| run | sticking nodes | shear alternation rms [MPa] | pressure-jump alternation rms [MPa] | correlation | shear / jump |")
print("|---|---|---|---|---|---|")
for run in args.runs:
    a_ = node_jumps(run)
    if len(a_) < 3:
        print(f"| {run} | {len(a_)} | - | - | - | - |")
        continue
    t, j = a_[:, 0], a_[:, 1]
    corr = np.corrcoef(t, j)[0, 1]
    print(f"| {run} | {len(a_)} | {np.sqrt(np.mean(t**2)):.4f} | {np.sqrt(np.mean(j**2)):.4f} | {corr:+.3f} | "
          f"{np.polyfit(j, t, 1)[0]:.2f} |")
