#!/usr/bin/env python3
"""inputs/default.xml (the README's scene) and inputs/squeeze.xml (supports only: fixed,
displacement, foundation) run and their summaries conform.

Exit 0, check_summary.py --scene passes, the run converged with every step of the
scene reported, the volume constraint holds (max |v_e/V_e - 1| <= 1e-10), and the
body is in equilibrium: with no capstan, the supports' forces on the body sum to
zero in every step (interface.md: "the sum of the supports' forces (on the body)
equals the sum of the capstans' forces"), to 1e-8 of the largest support force.
Each run also writes scene.xml, its scene as resolved; run again from it (into
another directory) it gives the same summary figures to the last digit.
"""
import os
import sys

sys.dont_write_bytecode = True  # nothing written into the source tree
sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from capstan_test import SceneInfo, Test, has_nan  # noqa: E402

T = Test("default_scene", __doc__)
for name in ("default.xml", "squeeze.xml"):
    scene = T.input(name)
    info = SceneInfo(scene)
    steps = int(info.number("Time/Steps", 1))

    p, s, out = T.run_scene(scene, name[:-4])
    if s is None:
        T.check(False, f"{name}: no summary.json")
        continue
    T.conforms(out, scene)
    T.check(s["converged"] is True and s["failure"] is None, f"converged = {s['converged']}, failure = {s['failure']!r}")
    T.check(len(s["steps"]) == steps, f"{len(s['steps'])} steps reported ({steps})")
    T.check(not has_nan(s), "no NaN or infinity in summary.json")
    for fname in ("summary.json", "history.csv", "fields.h5", "fields.xmf", "scene.xml"):
        T.check(os.path.isfile(os.path.join(out, fname)), f"{name}: {fname} written")
    _, again, _ = T.run_scene(os.path.join(out, "scene.xml"), name[:-4] + "-again")

    def figures(steps):  # every per-step figure but the wall time
        return [{k: v for k, v in st.items() if "wall" not in k} for st in steps]

    T.check(again is not None and figures(again["steps"]) == figures(s["steps"]) and again["final"] == s["final"],
            f"{name}: run again from its scene.xml, the same steps and final figures")
    dv = s["final"]["max_abs_volume_change"]
    T.check(dv <= 1e-10, f"final.max_abs_volume_change = {dv:.2e} (<= 1e-10)")
    for st in s["steps"]:
        supports = [f["force"] for f in st["supports"].values()]
        capstans = [c["force"] for c in st.get("capstans", {}).values()]
        scale = max(abs(x) for f in supports + capstans for x in f)
        total = [sum(f[i] for f in supports) - sum(c[i] for c in capstans) for i in range(3)]
        worst = max(abs(x) for x in total) / scale
        T.check(worst <= 1e-8, f"step {st['step']}: supports - capstans {['%.2e' % x for x in total]}, "
                f"/ max |force| ({scale:.4g}) = {worst:.2e} (<= 1e-8); newton {st['newton_iterations']}, "
                f"cutbacks {st['cutbacks']}")
    print(f"  total run time {s['timing']['total']:.2f} s")

T.finish()
