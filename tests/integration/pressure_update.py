#!/usr/bin/env python3
"""The pressure updates reach the same converged state.

Solver/Pressure Update = Saddle Point (positions, pressure anchors, exact
contact's multipliers and Coulomb's stick tractions from one block Krylov solve
per pass; Auto's choice without friction and for quasi-static rolling with
friction) and Anderson (pbar <- p(x), Anderson-accelerated; Auto's choice for
other friction scenes) are two routes to the same fixed point,
v_e = V_e with the contact and friction multipliers converged. Without friction
a third: Monolithic (Auto's choice there), the saddle-point step alone in every
pass from the predictor on, i.e. Newton's method on positions, anchors and
contact multipliers together; it must also take fewer Newton iterations (each
of its steps counts as one) than the nested Saddle Point loop. On

  * seed/g1.xml refined 2x (frictionless indentation, augmented contact),
    GMRES + MueLu,
  * seed/h1.xml (rolling with tanh friction on a soft foundation), and
  * seed/stick-slip.xml (Coulomb friction with exact stick, whose sticking
    points are rows of the saddle-point step),

both runs must converge with max |v_e/V_e - 1| <= 1e-10, conform to
interface.md, and agree on every step's support and capstan forces, the final
stress and pressure extrema and the face means of the displacement, to 1e-6
relative to the largest magnitude of their kind (the contact is converged to
its penetration tolerance, not further, in either run). Also printed: the
passes and Krylov iterations of each route.
"""
import os
import sys

sys.dont_write_bytecode = True  # nothing written into the source tree
sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from capstan_test import Test, has_nan, summary_figures, worst_difference  # noqa: E402

TOL = 1e-6
T = Test("pressure_update", __doc__)

CASES = [
    ("g1 2x", "seed/g1.xml", ["Mesh/Cells={28,8,12}", "Time/Steps=2", "Solver/Linear Solver=GMRES",
                              "Solver/Preconditioner=MueLu"], ("Monolithic", "Saddle Point", "Anderson")),
    ("g1 1x", "seed/g1.xml", [], ("Monolithic", "Saddle Point")),
    ("h1", "seed/h1.xml", [], ("Saddle Point", "Anderson")),
    ("stick-slip", "seed/stick-slip.xml", [], ("Saddle Point", "Anderson")),
]

for label, scene_name, sets, methods in CASES:
    scene = T.input(scene_name)
    runs, newtons = {}, {}
    for method in methods:
        tag = f"{label.replace(' ', '-')}-{method.split()[0].lower()}"
        p, s, out = T.run_scene(scene, tag, sets=sets + [f"Solver/Pressure Update={method}"])
        if s is None:
            T.check(False, f"{label} {method}: no summary.json")
            continue
        T.check(s["converged"] is True, f"{label} {method}: converged = {s['converged']} ({s['failure']!r})")
        T.check(not has_nan(s), f"{label} {method}: no NaN in summary.json")
        dv = s["final"]["max_abs_volume_change"]
        T.check(dv <= 1e-10, f"{label} {method}: final.max_abs_volume_change = {dv:.2e} (<= 1e-10)")
        T.conforms(out, scene)
        passes = sum(st["augmentations"] for st in s["steps"])
        linear = sum(st["linear_iterations"] for st in s["steps"])
        newton = sum(st["newton_iterations"] for st in s["steps"])
        print(f"  {label} {method}: {passes} passes, {newton} Newton iterations, {linear} Krylov iterations, "
              f"{s['timing']['total']:.2f} s")
        if s["converged"] is True:
            runs[method] = summary_figures(s)
            newtons[method] = newton
    if len(runs) < len(methods):
        continue
    a = runs["Saddle Point"]
    for method in methods:
        if method == "Saddle Point":
            continue
        for group in ("force", "stress", "displacement"):
            worst, where, scale = worst_difference(runs[method][group], a[group])
            T.check(worst <= TOL, f"{label}: {method} against Saddle Point: {group} figures agree: worst "
                    f"{worst:.2e} of the largest {scale:.4g} ({where}) (<= {TOL:g})")
    if "Monolithic" in newtons:
        T.check(newtons["Monolithic"] < newtons["Saddle Point"],
                f"{label}: Monolithic takes fewer Newton iterations: {newtons['Monolithic']} "
                f"(< {newtons['Saddle Point']})")

T.finish()
