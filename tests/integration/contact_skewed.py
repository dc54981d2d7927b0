#!/usr/bin/env python3
"""G2 and G3 (formulation.md §6): the capstan's axis skewed in x-z (G2) and tilted
towards the block (G3), inputs/seed/g2.xml and g3.xml.

  * both run all 5 steps, converge, conform to interface.md;
  * equilibrium at every step: capstan force = base reaction (1e-8 relative);
  * contact is exact: max_penetration <= 1e-4 h (h = 0.5);
  * G3 starts in contact only near z = 4: the axis rises 0.2 per unit of depth from
    z = 4, so after 0.1 of indentation the undeformed top surface meets the cylinder
    only for z > 4 - 0.70 = 3.30, and after 0.5 for z > 1.30. At step 1 every face that
    carries contact pressure lies in the two rows of faces nearest z = 4 (centres
    z >= 3.0, nodes z >= 2.67); the contact point count grows with the steps, and at
    step 5 the contact reaches faces with centres below z = 2;
  * G2's axis is skewed in x: the capstan force has an x component that is small
    against y, and the contact is not symmetric about x = 3.5 (G1's is).
"""
import os
import sys

sys.dont_write_bytecode = True
sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from capstan_test import Test, read_fields  # noqa: E402

T = Test("contact_skewed", __doc__)
import numpy as np  # noqa: E402

runs = {}
for g in ("g2", "g3"):
    scene = T.input(f"seed/{g}.xml")
    p, s, out = T.run_scene(scene, g)
    if s is None:
        T.check(False, f"{g}: no summary.json")
        continue
    T.check(s["converged"] is True and len(s["steps"]) == 5,
            f"{g}: converged = {s['converged']} ({s['failure']!r}), {len(s['steps'])} steps (5)")
    T.conforms(out, scene)
    for st in s["steps"]:
        c = st["capstans"]["capstan"]
        F, B = c["force"], st["supports"]["base"]["force"]
        worst = max(abs(a - b) for a, b in zip(F, B)) / max(abs(x) for x in B)
        T.check(worst <= 1e-8, f"{g} step {st['step']}: capstan force {np.round(F, 6).tolist()} = base reaction, "
                f"rel. diff {worst:.2e}")
        T.check(c["max_penetration"] <= 5e-5, f"{g} step {st['step']}: max_penetration {c['max_penetration']:.2e} <= 5e-5")
    runs[g] = (s, out)

if "g3" in runs:
    s, out = runs["g3"]
    counts = [st["capstans"]["capstan"]["contact_points"] for st in s["steps"]]
    T.check(all(b >= a for a, b in zip(counts, counts[1:])) and counts[-1] > counts[0],
            f"G3 contact points grow with the steps: {counts}")
    f = read_fields(os.path.join(out, "fields.h5"))
    X = f[1]["X"]
    zc = X[f[1]["quads"]][:, :, 2].mean(axis=1)
    for step in (1, 5):
        loaded = f[step]["faces"]["contact_pressure"] > 0
        zmin = zc[loaded].min() if loaded.any() else None
        print(f"    G3 step {step}: {loaded.sum()} faces in contact, centres from z = {zmin}")
        if step == 1:
            T.check(loaded.any() and zmin > 3.0 - 1e-9, f"G3 step 1: faces in contact only near z = 4 (centres z >= {zmin})")
        else:
            T.check(loaded.any() and zmin < 2.0, f"G3 step 5: contact has spread to face centres below z = 2 (z >= {zmin})")

if "g2" in runs:
    s, out = runs["g2"]
    F = s["steps"][-1]["capstans"]["capstan"]["force"]
    T.check(0 < abs(F[0]) < 0.2 * abs(F[1]), f"G2 final force x {F[0]:.4g} non-zero and small against y {F[1]:.4g}")
    f = read_fields(os.path.join(out, "fields.h5"))
    last = f[max(f)]
    xc = last["X"][last["quads"]][:, :, 0].mean(axis=1)
    p = last["faces"]["contact_pressure"]
    left, right = p[xc < 3.5].sum(), p[xc > 3.5].sum()
    T.check(abs(left - right) > 1e-3 * (left + right), f"G2 contact pressure left/right of x = 3.5: {left:.4g} vs {right:.4g} (not mirrored)")
T.finish()
