#!/usr/bin/env python3
"""A brake sweep of the 3D drive in one steady run (issue 31: each continuation step at
most 20 Newton iterations, no cuts): inputs/pinch-roller-steady.xml with the brake torque
ramped to 18 N mm (90% of mu F R) over 10 steps, as scripts/steady-bench.py runs it.

  * 10 steps, no cut; every step after the first (the steady state from rest) at most 20
    Newton iterations;
  * the speed ratio falls with each torque step (more brake, more creep);
  * from rest, the starting guesses (the frictionless footprint and the Tanh stages, one
    pass each) are solved only to 1e-7 c L^2 (src/augmentation.cpp, kGuessTolerance):
    at most 18 Newton residuals together (15 today; 21 with each solved to the step's
    tolerance);
  * a progress line for each stage of the start from rest (their Newton iterations add up
    to the step's), none for the continuation steps;
  * the saddle-point step was shortened at least once (the merit test that keeps a step
    from pushing points across stick, slip and free: src/augmentation.cpp), and every
    shortening was called for (the longer step left |R| above the step's start);
  * a braked slice on a capstan of radius 1 whose first step needs the force eased: a cut
    halves the span to the first load still ramping (the force), so it converges, at the
    speed ratio of the same brake put on at once (2e-5), the ratios falling step by step.
"""
import os
import sys

sys.dont_write_bytecode = True
sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from capstan_test import Test  # noqa: E402

T = Test("steady_sweep", __doc__)
scene = T.input("pinch-roller-steady.xml")
sets = ["Supports/core/Torque=18", "Supports/core/Torque Ramp Time=0.010", "Time/Steps=10",
        "Output/Write Fields=false"]
_, s, out = T.run_scene(scene, "sweep", sets=sets, extra=["--log", "newton"])
if s:
    T.conforms(out, scene)
    st = s["steps"]
    newton = [x["newton_iterations"] for x in st]
    cuts = [x["cutbacks"] for x in st]
    ratio = [x["supports"]["core"]["speed_ratio"] for x in st]
    print(f"    Newton per step {newton}, cuts {cuts}")
    print("    speed ratio " + ", ".join(f"{r:.5f}" for r in ratio))
    T.check(len(st) == 10, f"10 steps ({len(st)})")
    T.check(sum(cuts) == 0, f"no step cut ({cuts})")
    T.check(max(newton[1:]) <= 20, f"steps 2-10: at most 20 Newton iterations each ({max(newton[1:])})")
    T.check(all(b < a for a, b in zip(ratio, ratio[1:])), "the speed ratio falls with the brake torque")
    stage, guesses = None, 0
    for e in T.log_events(out):
        if e.get("step") != 1:
            continue
        if e.get("event") == "steady stage":
            stage = e["stage"]
        elif e.get("event") == "newton" and stage and not stage.startswith("steady state"):
            guesses += len(e["residuals"])
    T.check(0 < guesses <= 18, f"the starting guesses: {guesses} Newton residuals (<= 18)")
    # Progress: a line for each stage of the start from rest, none for a continuation step.
    progress = [e for e in T.log_events(out) if e.get("topic") == "progress"]
    stages = [e for e in T.log_events(out, "steady stage") if e.get("step") == 1]
    stage_lines = [e["text"] for e in progress if ": done, newton=" in e["text"] or ": failed, newton=" in e["text"]]
    T.check(len(stage_lines) == len(stages) > 0 and all(e.get("step") == 1 for e in progress
                                                         if e["text"] in stage_lines),
            f"a progress line for each of step 1's {len(stages)} stages ({len(stage_lines)}), none after")
    T.check(sum(int(t.split("newton=")[1].split(",")[0]) for t in stage_lines) == newton[0],
            "the stages' Newton iterations add up to step 1's")
    halved = T.log_events(out, "pressure_step_halved")
    T.check(len(halved) > 0, f"the saddle-point step was shortened ({len(halved)} times)")
    T.check(all(e["residual"] > e["start"] for e in halved), "each shortening: the longer step left |R| above the start")
else:
    T.check(False, "the sweep converges")

# A footprint that needs the force eased: the braked slice on a capstan of radius 1 just
# touching it, the brake ramped over the sweep's 4 steps. Its first step fails at the full
# force; a cut halves the span to the first load still ramping (the force's 1e-6), so the
# force eases. Before, cuts halved the brake's ramp, left the force whole, and the run
# ended in exit 2; without the brake's ramp the same first step converged.
SMALL = ["Capstans/capstan/Radius=0.9955", "Capstans/capstan/Axis Point={0, -7.2455, 0}"]
braked = T.input("pinch-roller-braked-steady.xml")
_, b, _ = T.run_scene(braked, "small-capstan-sweep", sets=SMALL + [
    "Supports/core/Torque=0.4", "Supports/core/Torque Ramp Time=0.004", "Time/Steps=4", "Output/Write Fields=false"])
_, one, _ = T.run_scene(braked, "small-capstan-unramped", sets=SMALL + [
    "Supports/core/Torque=0.1", "Supports/core/Torque Ramp Time=1e-6", "Time/Steps=1", "Output/Write Fields=false"])
if b is not None and b["converged"] and one is not None and one["converged"]:
    ratios = [st["supports"]["core"]["speed_ratio"] for st in b["steps"]]
    T.check(b["steps"][0]["cutbacks"] > 0 and all(st["cutbacks"] == 0 for st in b["steps"][1:]),
            f"small capstan sweep: its first step cut, the others not ({[st['cutbacks'] for st in b['steps']]})")
    T.check(all(r1 < r0 for r0, r1 in zip(ratios, ratios[1:])), f"small capstan sweep: speed ratios fall {ratios}")
    r_one = one["steps"][0]["supports"]["core"]["speed_ratio"]
    T.check(abs(ratios[0] - r_one) < 2e-5,
            f"small capstan sweep: first step {ratios[0]:.6f} against the unramped brake's {r_one:.6f} (2e-5)")
else:
    T.check(False, "small capstan sweep and its unramped first step converged")
T.finish()
