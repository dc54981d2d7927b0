#!/usr/bin/env python3
"""A soft stick: Auto's Anderson loop fails, the saddle-point step finishes (ctest label `hard`).

seed/stick-slip.xml under Coulomb with mu = 0.108 and Tangential Penalty = 0.098 (a sweep
run): `Solver/Pressure Update = Auto` gives this friction scene without rolling the
Anderson loop, whose passes stall on step 1 through every cut (the volume change stays
above its tolerance after 100 passes). The step is then solved again from its start with
the saddle-point pressure step, which the run keeps (src/load_stepper.cpp).

Checks:
- Auto: exit 0, the switch reported once on the progress lines and listed at step 1 in
  summary.json's `solver_switches` (empty with Saddle Point named), and every step's capstan
  force equal to the run with `Pressure Update = Saddle Point` from the start (1e-8 of
  the largest force); the same on 2 ranks, its forces those of 1 rank (1e-8).
- `Pressure Update = Anderson` named: exit 2 at step 1 (nothing switches a named update),
  so the fallback is what rescues the run.
- A checkpoint after the switch (3 steps, Checkpoint Every = 2) restarts with the
  saddle-point step and its carried stop-rule state: step 3 as the uninterrupted run's,
  the same Newton iterations and forces to 1e-10, and the switch still listed.
"""
import json
import os
import sys

sys.dont_write_bytecode = True
sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from capstan_test import Test  # noqa: E402

T = Test("anderson_fallback", __doc__)
SCENE = T.input("seed/stick-slip.xml")
SOFT = ["Capstans/capstan/Friction/Coefficient=0.108", "Capstans/capstan/Friction/Tangential Penalty=0.098"]
SWITCH = "the step again with the saddle-point pressure step"


def forces(s):
    return [st["capstans"]["capstan"]["force"] for st in s["steps"]]


p, s, out = T.run_scene(SCENE, "auto", sets=SOFT, quiet=False)
T.conforms(out, os.path.join(out, "scene.xml"))
p2, s2, _ = T.run_scene(SCENE, "saddle-point", sets=SOFT + ["Solver/Pressure Update=Saddle Point"])
if T.check(s is not None and s["converged"] and s2 is not None and s2["converged"], "Auto and Saddle Point converge"):
    T.check(p.stdout.count(SWITCH) == 1, f"Auto: the switch reported once ({p.stdout.count(SWITCH)})")
    sw = s["solver_switches"]
    T.check(len(sw) == 1 and sw[0]["step"] == 1 and "saddle-point pressure step" in sw[0]["what"],
            f"Auto: summary.json's solver_switches lists it at step 1 ({sw})")
    T.check(s2["solver_switches"] == [], f"Saddle Point named: no switch listed ({s2['solver_switches']})")
    T.check(len(s["steps"]) == len(s2["steps"]) == 6, "six steps each")
    scale = max(abs(v) for f in forces(s2) for v in f)
    worst = max(abs(a - b) for fa, fb in zip(forces(s), forces(s2)) for a, b in zip(fa, fb)) / scale
    T.check(worst <= 1e-8, f"Auto's forces against Saddle Point's from the start: {worst:.1e} of the largest (1e-8)")

p4, s4, _ = T.run_scene(SCENE, "auto-2ranks", sets=SOFT, ranks=2, quiet=False)
if s is not None and s["converged"] and T.check(s4 is not None and s4["converged"], "Auto on 2 ranks converges"):
    T.check(p4.stdout.count(SWITCH) == 1, "2 ranks: the switch reported once")
    scale = max(abs(v) for f in forces(s) for v in f)
    worst = max(abs(a - b) for fa, fb in zip(forces(s), forces(s4)) for a, b in zip(fa, fb)) / scale
    T.check(worst <= 1e-8, f"1 and 2 ranks' forces: {worst:.1e} of the largest (1e-8)")

p3, s3, _ = T.run_scene(SCENE, "anderson", sets=SOFT + ["Solver/Pressure Update=Anderson"], expect_rc=2)
if s3 is not None:
    T.check(s3["failure"].startswith("step 1 failed"), f"Anderson named: {s3['failure'][:90]!r}...")
    T.check(SWITCH not in p3.stdout + p3.stderr, "Anderson named: no switch")

# Restart after the switch.
THREE = SOFT + ["Time/Steps=3"]
_, whole, _ = T.run_scene(SCENE, "whole", sets=THREE)
ck = T.path("checkpointed")
T.run_scene(SCENE, "checkpointed", sets=THREE + ["Output/Checkpoint Every=2"])
pr = T.capstan_run(["run", SCENE, "--output", ck, "--restart", ck, "--quiet"] +
                   sum((["--set", x] for x in THREE + ["Output/Checkpoint Every=2"]), []))
T.check(pr.returncode == 0, f"restart from step 2: exit {pr.returncode} {pr.stderr.strip()[:200]}")
if pr.returncode == 0 and whole is not None:
    with open(os.path.join(ck, "summary.json")) as fh:
        again = json.load(fh)
    a, b = again["steps"][2], whole["steps"][2]
    T.check(a["newton_iterations"] == b["newton_iterations"],
            f"restarted step 3: {a['newton_iterations']} Newton iterations, uninterrupted {b['newton_iterations']}")
    fa, fb = a["capstans"]["capstan"]["force"], b["capstans"]["capstan"]["force"]
    d = max(abs(x - y) for x, y in zip(fa, fb)) / max(abs(y) for y in fb)
    T.check(d <= 1e-10, f"restarted step 3's capstan force against the uninterrupted run's: {d:.1e} (1e-10)")
    T.check(again["solver_switches"] == whole["solver_switches"] and len(again["solver_switches"]) == 1,
            f"the restarted run's solver_switches, carried by the checkpoint: {again['solver_switches']}")
T.finish()
