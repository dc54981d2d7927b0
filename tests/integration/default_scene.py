#!/usr/bin/env python3
"""inputs/default.xml (the README's scene) runs and its summary conforms.

Exit 0, check_summary.py --scene passes, the run converged with every step of the
scene reported, the volume constraint holds (max |v_e/V_e - 1| <= 1e-10), and the
body is in equilibrium: with no capstan, the supports' forces on the body sum to
zero in every step (interface.md: "the sum of the supports' forces (on the body)
equals the sum of the capstans' forces"), to 1e-8 of the largest support force.
"""
import os
import sys

sys.dont_write_bytecode = True  # nothing written into the source tree
sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from capstan_test import SceneInfo, Test, has_nan  # noqa: E402

T = Test("default_scene", __doc__)
scene = T.input("default.xml")
info = SceneInfo(scene)
steps = int(info.number("Time/Steps", 1))

p, s, out = T.run_scene(scene, "default")
if s is None:
    T.fatal("no summary.json")
T.conforms(out, scene)
T.check(s["converged"] is True and s["failure"] is None, f"converged = {s['converged']}, failure = {s['failure']!r}")
T.check(len(s["steps"]) == steps, f"{len(s['steps'])} steps reported ({steps})")
T.check(not has_nan(s), "no NaN or infinity in summary.json")
for name in ("summary.json", "history.csv", "fields.h5", "fields.xmf"):
    T.check(os.path.isfile(os.path.join(out, name)), f"{name} written")
dv = s["final"]["max_abs_volume_change"]
T.check(dv <= 1e-10, f"final.max_abs_volume_change = {dv:.2e} (<= 1e-10)")
for st in s["steps"]:
    forces = {n: f["force"] for n, f in st["supports"].items()}
    scale = max(abs(x) for f in forces.values() for x in f)
    total = [sum(f[i] for f in forces.values()) for i in range(3)]
    worst = max(abs(x) for x in total) / scale
    T.check(worst <= 1e-8, f"step {st['step']}: sum of support forces {['%.2e' % x for x in total]}, "
            f"|sum| / max |force| ({scale:.4g}) = {worst:.2e} (<= 1e-8); newton {st['newton_iterations']}, "
            f"cutbacks {st['cutbacks']}")
print(f"  total run time {s['timing']['total']:.2f} s")

T.finish()
