#!/usr/bin/env python3
"""An annulus mesh (the pinch roller's coating) pressed by a capstan, core held
(inputs/roller-held.xml), on 1 and 2 ranks:

  * the summary conforms to interface.md;
  * equilibrium at every step: the capstan force (body on capstan) equals the core's
    reaction (support on body) to 1e-8 relative;
  * the scene is symmetric about x = 0: the x components of the forces vanish
    (1e-8 of the y force), and the stress extrema of xy are opposite (1e-6);
  * contact is exact (augmented Lagrangian): max_penetration <= 1e-4 x the cell size;
  * the contact grows with the indentation (points, width, force increase each step);
  * 1 and 2 ranks agree to 1e-8 on every step's forces.
"""
import os
import sys

sys.dont_write_bytecode = True
sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from capstan_test import Test, has_nan, rel_diff  # noqa: E402

T = Test("annulus_roller", __doc__)
scene = T.input("roller-held.xml")
runs = {}
for ranks in (1, 2):
    p, s, out = T.run_scene(scene, f"r{ranks}", ranks=ranks)
    if s is None:
        T.fatal(f"{ranks} rank(s): no summary.json")
    T.conforms(out, scene)
    T.check(s["converged"] and not has_nan(s), f"{ranks} rank(s): converged, no NaN")
    runs[ranks] = s

s = runs[1]
prev = None
for st in s["steps"]:
    c = st["capstans"]["capstan"]
    core = st["supports"]["core"]["force"]
    fy = c["force"][1]
    T.check(rel_diff(c["force"][1], core[1]) < 1e-8 and abs(c["force"][0] - core[0]) < 1e-8 * abs(fy),
            f"step {st['step']}: capstan force {c['force'][1]:.12g} = core force {core[1]:.12g} (1e-8)")
    T.check(abs(c["force"][0]) < 1e-8 * abs(fy), f"step {st['step']}: capstan force x {c['force'][0]:.1e} ~ 0 (symmetry)")
    T.check(c["max_penetration"] <= 1e-4 * 0.5, f"step {st['step']}: max_penetration {c['max_penetration']:.1e} <= 5e-5")
    if prev is not None:
        T.check(abs(fy) > abs(prev["force"][1]) and c["contact_width"] > prev["contact_width"]
                and c["contact_points"] >= prev["contact_points"],
                f"step {st['step']}: force {abs(fy):.4f}, width {c['contact_width']:.4f}, points "
                f"{c['contact_points']} grow from the previous step")
    prev = c
xy = s["final"]["stress"]["xy"]
T.check(abs(xy["min"] + xy["max"]) < 1e-6 * abs(xy["max"]),
        f"symmetry: sigma_xy min {xy['min']:.10g} = -max {xy['max']:.10g}")
for a, b in zip(runs[1]["steps"], runs[2]["steps"]):
    f1, f2 = a["capstans"]["capstan"]["force"][1], b["capstans"]["capstan"]["force"][1]
    T.check(rel_diff(f2, f1) < 1e-8, f"step {a['step']}: 1 vs 2 ranks force {f1:.12g} vs {f2:.12g}")
T.finish()
