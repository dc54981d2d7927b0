#!/usr/bin/env python3
"""Coulomb friction with a sticking region (inputs/seed/stick-slip.xml): H1's block on a
stiff foundation (k = 10), the capstan turning slowly (1 rad/s), mu = 0.5, augmented
Lagrangian contact.

  * it converges and conforms; every step is in equilibrium (capstan x force = the
    foundation's reaction, 1e-8);
  * while the friction force builds up, the contact has both sticking and slipping
    points (at least one step with both), the stick zone shrinks as the force grows
    (stick counts never increase after the first step with slip), and the friction
    traction never exceeds mu t_n (1e-8);
  * refining the tangential penalty 10x (default: the contact's solve penalty) changes
    the final capstan force by less than 1%.
"""
import os
import sys

sys.dont_write_bytecode = True
sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from capstan_test import Test  # noqa: E402

T = Test("friction_stick_slip", __doc__)
scene = T.input("seed/stick-slip.xml")
F = "Capstans/capstan/Friction/"
finals = {}
for tag, sets in (("default", []), ("refined", [f"{F}Tangential Penalty=1.75e-4"])):
    p, s, out = T.run_scene(scene, tag, sets=sets)
    if s is None or not s["converged"]:
        T.check(False, f"{tag}: converged ({None if s is None else s['failure']!r})")
        continue
    T.conforms(out, scene)
    rows = [(st["capstans"]["capstan"], st["supports"]["foundation"]["force"][0], st) for st in s["steps"]]
    print(f"    {tag}: " + ", ".join(f"[{c['force'][0]:.5f} stick {c['stick_points']} slip {c['slip_points']} "
                                      f"cut {st['cutbacks']}]" for c, _, st in rows))
    for c, fx, st in rows:
        T.check(abs(c["force"][0] - fx) <= 1e-8 * max(abs(fx), 1e-3),
                f"{tag} step {st['step']}: capstan x force {c['force'][0]:.10g} = foundation {fx:.10g}")
        T.check(c["friction"]["max_traction_ratio"] <= 1 + 1e-8,
                f"{tag} step {st['step']}: |t_f| / (mu t_n) = {c['friction']['max_traction_ratio']:.12f} <= 1")
    if tag == "default":
        both = [st["step"] for c, _, st in rows if c["stick_points"] > 0 and c["slip_points"] > 0]
        T.check(len(both) >= 1, f"steps with both stick and slip points: {both}")
        sticks = [c["stick_points"] for c, _, _ in rows]
        first = next((i for i, (c, _, _) in enumerate(rows) if c["slip_points"] > 0 and i > 0), len(rows))
        T.check(all(b <= a for a, b in zip(sticks[first:], sticks[first + 1:])),
                f"stick points shrink while the force grows: {sticks}")
    finals[tag] = rows[-1][0]["force"][0]
if len(finals) == 2:
    d = abs(finals["refined"] - finals["default"]) / abs(finals["refined"])
    T.check(d < 0.01, f"final force x: default {finals['default']:.6g}, tangential penalty 10x finer "
            f"{finals['refined']:.6g}: rel. change {d:.2%} < 1%")
T.finish()
