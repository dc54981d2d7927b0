#!/usr/bin/env python3
"""Contact penalty eps2 on G1 (inputs/seed/g1.xml), final capstan force:

  * augmented Lagrangian: Penalty 1e-2 and 1e-4 (100x apart; Minimum Solve Penalty = 0,
    so the Newton solves really use these penalties) give forces within 1e-4 relative,
    each with max_penetration below the tolerance (1e-4 h = 5e-5);
  * penalty method, nodal rule (the augmented Lagrangian's points): eps2 = 1e-2 ... 1e-5
    converges to the augmented Lagrangian's force at first order: the error falls
    monotonically, by 5x to 20x per decade, to below 1e-3 relative; max_penetration
    falls with eps2 (about eps2 x peak pressure);
  * penalty method, Gauss 2x2 (the default rule): eps2 = 1e-2, 1e-3, 1e-4 converges
    (successive changes shrink by more than 5x).
Prints the sequences.
"""
import os
import sys

sys.dont_write_bytecode = True
sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from capstan_test import Test  # noqa: E402

T = Test("contact_penalty", __doc__)
scene = T.input("seed/g1.xml")
C = "Capstans/capstan/Contact/"


def final(tag, sets):
    p, s, out = T.run_scene(scene, tag, sets=sets)
    if s is None or not s["converged"]:
        T.check(False, f"{tag}: converged ({None if s is None else s['failure']!r})")
        return None
    c = s["steps"][-1]["capstans"]["capstan"]
    newton = sum(st["newton_iterations"] for st in s["steps"])
    print(f"    {tag:28s} force_y = {c['force'][1]:.12g}  max_penetration = {c['max_penetration']:.3e}  "
          f"newton = {newton}  wall = {s['timing']['total']:.2f} s")
    return c


print("  augmented Lagrangian:")
al = {}
for eps in ("1e-2", "1e-4"):
    c = final(f"al-{eps}", [f"{C}Penalty={eps}", f"{C}Minimum Solve Penalty=0"])
    if c:
        al[eps] = c["force"][1]
        T.check(c["max_penetration"] <= 5e-5, f"AL eps2 = {eps}: max_penetration {c['max_penetration']:.2e} <= 5e-5")
if len(al) == 2:
    d = abs(al["1e-2"] - al["1e-4"]) / abs(al["1e-4"])
    T.check(d < 1e-4, f"AL force, eps2 1e-2 vs 1e-4: {al['1e-2']:.12g} vs {al['1e-4']:.12g}, rel. diff {d:.2e} < 1e-4")

print("  penalty, nodal rule:")
ref = al.get("1e-4")
errors, pens = [], []
for eps in ("1e-2", "1e-3", "1e-4", "1e-5"):
    c = final(f"penalty-nodal-{eps}", [f"{C}Method=Penalty", f"{C}Quadrature=Nodal", f"{C}Penalty={eps}"])
    if c and ref:
        errors.append(abs(c["force"][1] - ref) / abs(ref))
        pens.append(c["max_penetration"])
if len(errors) == 4:
    print("    relative error against the augmented Lagrangian: " + ", ".join(f"{e:.3e}" for e in errors))
    ratios = [errors[i] / errors[i + 1] for i in range(3)]
    T.check(all(5 < r < 20 for r in ratios), f"error falls by {', '.join(f'{r:.2f}' for r in ratios)} per decade (5..20)")
    T.check(errors[-1] < 1e-3, f"eps2 = 1e-5: error {errors[-1]:.2e} < 1e-3")
    T.check(all(pens[i] > 5 * pens[i + 1] for i in range(3)), f"max_penetration falls with eps2: {pens}")

print("  penalty, Gauss 2x2:")
forces = []
for eps in ("1e-2", "1e-3", "1e-4"):
    c = final(f"penalty-gauss-{eps}", [f"{C}Method=Penalty", f"{C}Quadrature=Gauss 2x2", f"{C}Penalty={eps}"])
    if c:
        forces.append(c["force"][1])
if len(forces) == 3:
    d1, d2 = abs(forces[1] - forces[0]), abs(forces[2] - forces[1])
    T.check(d1 > 5 * d2, f"successive changes {d1:.4g}, {d2:.4g}: shrink by {d1 / d2:.2f} (> 5)")
T.finish()
