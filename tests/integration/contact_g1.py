#!/usr/bin/env python3
"""G1 (formulation.md §6): frictionless indentation of the block by the rigid capstan,
augmented Lagrangian (inputs/seed/g1.xml).

  * it converges, summary.json conforms, effects are exactly brick and contact:capstan,
    mesh.contact_faces = 14 x 6 candidate faces;
  * equilibrium at every step: the capstan's force (body on capstan) equals the base's
    reaction (on the body), 1e-8 relative; both point up (+y) and grow with the steps;
  * contact is exact: max_penetration <= the default tolerance 1e-4 h (h = 0.5);
  * symmetry about x = 3.5: mirrored nodal displacements (u_x changes sign) agree to
    1e-8 x max |u|; element stresses of mirrored elements agree (xy and xz change sign)
    to 1e-8 x max |sigma|, and so do the stress extrema of the mirrored components;
    the capstan's x and z forces vanish (1e-8 x |F|);
  * fields.h5 contact faces: the contact traction integrated over the faces equals the
    force on the body, -force (1e-8), and faces clear of the capstan carry no pressure;
  * nip.csv: s is measured from the line of centres, on a box the perpendicular from
    the capstan's axis to the face it presses (interface.md): at every step the rows'
    s span -a..a symmetrically (1e-8 x a), with a the half of the step's contact_width.
"""
import os
import sys

sys.dont_write_bytecode = True
sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from capstan_test import Test, read_fields  # noqa: E402

T = Test("contact_g1", __doc__)
scene = T.input("seed/g1.xml")
p, s, out = T.run_scene(scene, "g1")
if s is None:
    T.fatal("no summary.json")
T.check(s["converged"] is True, f"converged = {s['converged']} ({s['failure']!r})")
T.conforms(out, scene)
T.check(sorted(s["effects"]) == ["brick", "contact:capstan"], f"effects that ran: {sorted(s['effects'])}")
T.check(s["mesh"]["contact_faces"] == 84, f"mesh.contact_faces = {s['mesh']['contact_faces']} (84)")
T.check(len(s["steps"]) == 5, f"{len(s['steps'])} steps (5)")

TOL_PEN = 1e-4 * 0.5
previous = 0.0
for st in s["steps"]:
    c = st["capstans"]["capstan"]
    F, B = c["force"], st["supports"]["base"]["force"]
    scale = max(abs(x) for x in B)
    worst = max(abs(a - b) for a, b in zip(F, B)) / scale
    T.check(worst <= 1e-8, f"step {st['step']}: capstan force {F[1]:.10g}, base reaction {B[1]:.10g}: "
            f"max diff / |F| = {worst:.2e}")
    T.check(F[1] > previous, f"step {st['step']}: capstan force y {F[1]:.6g} > previous step's {previous:.6g}")
    previous = F[1]
    T.check(max(abs(F[0]), abs(F[2])) <= 1e-8 * abs(F[1]),
            f"step {st['step']}: capstan force x, z = {F[0]:.2e}, {F[2]:.2e} (symmetry: 0)")
    T.check(c["max_penetration"] <= TOL_PEN,
            f"step {st['step']}: max_penetration {c['max_penetration']:.2e} <= {TOL_PEN:.1e}")
    T.check(c["contact_points"] > 0, f"step {st['step']}: {c['contact_points']} contact points")

# --- symmetry about x = 3.5 in fields.h5 --------------------------------------
import numpy as np  # noqa: E402

f = read_fields(os.path.join(out, "fields.h5"))
last = f[max(f)]
X, u = last["X"], last["u"]
key = {tuple(np.round(x, 9)): i for i, x in enumerate(X)}
umax = np.abs(u).max()
worst, missing = 0.0, 0
for i, x in enumerate(X):
    j = key.get(tuple(np.round([7.0 - x[0], x[1], x[2]], 9)))
    if j is None:
        missing += 1
        continue
    mirrored = u[j] * np.array([-1, 1, 1])
    worst = max(worst, np.abs(u[i] - mirrored).max())
T.check(missing == 0, f"every node has a mirror image ({missing} missing)")
T.check(worst <= 1e-8 * umax, f"mirrored nodal displacements: max |u| = {umax:.4g}, worst diff / max |u| = {worst / umax:.2e}")

centroids = X[last["hexahedra"]].mean(axis=1)
ckey = {tuple(np.round(c, 9)): e for e, c in enumerate(centroids)}
sig = last["stress"]
smax = np.abs(sig).max()
flip = np.array([1, 1, 1, -1, 1, -1])  # xx yy zz xy yz xz under x -> -x
worst = 0.0
for e, c in enumerate(centroids):
    m = ckey.get(tuple(np.round([7.0 - c[0], c[1], c[2]], 9)))
    worst = max(worst, np.abs(sig[e] - flip * sig[m]).max()) if m is not None else np.inf
T.check(worst <= 1e-8 * smax, f"mirrored element stresses: max |sigma| = {smax:.4g}, worst diff / max = {worst / smax:.2e}")
fin = s["final"]["stress"]
for comp in ("xy", "xz"):
    lo, hi = fin[comp]["min"], fin[comp]["max"]
    T.check(abs(lo + hi) <= 1e-8 * smax, f"final stress {comp}: min {lo:.10g} = -max {hi:.10g}")

# --- contact fields -----------------------------------------------------------
quads = last["quads"]
T.check(quads is not None and len(quads) == 84, f"fields.h5 holds the {0 if quads is None else len(quads)} contact faces (84)")
if quads is not None:
    P = X[quads]
    area = np.linalg.norm(np.cross(P[:, 1] - P[:, 0], P[:, 3] - P[:, 0]), axis=1)  # rectangles
    faces = last["faces"]
    total = (faces["contact_traction"] * area[:, None]).sum(axis=0)
    F = np.array(s["steps"][-1]["capstans"]["capstan"]["force"])
    diff = np.abs(total + F).max() / np.abs(F).max()
    T.check(diff <= 1e-8, f"integral of contact_traction {total.round(8).tolist()} = -force: rel. diff {diff:.2e}")
    clear = faces["gap"] < -1e-3
    T.check(clear.any() and np.all(faces["contact_pressure"][clear] == 0),
            f"{clear.sum()} faces clear of the capstan (gap < -1e-3) carry no pressure")
    T.check(faces["contact_pressure"].max() > 0, f"peak face pressure {faces['contact_pressure'].max():.4g} > 0")
import csv  # noqa: E402

with open(os.path.join(out, "nip.csv")) as fh:
    rows = list(csv.DictReader(fh))
for k, st in enumerate(s["steps"], start=1):
    sv = [float(r["s"]) for r in rows if int(r["step"]) == k]
    half = 0.5 * st["capstans"]["capstan"]["contact_width"]
    T.check(len(sv) > 0 and abs(min(sv) + max(sv)) <= 1e-8 * max(half, 1e-12) and abs(max(sv) - half) <= 1e-8 * half,
            f"step {k}: nip.csv's s spans {min(sv, default=0):.9g}..{max(sv, default=0):.9g}, "
            f"symmetric about the line of centres (half width {half:.9g})")

T.finish()
