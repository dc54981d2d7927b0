#!/usr/bin/env python3
"""A state with the body through a capstan is no answer (AugmentationLoop::bodyThroughCapstan).

Contact holds the contact faces' points only. A body pushed through a capstan, its faces
closed behind it, balances with every point clear; so does a capstan that fits between
the points of faces much longer than its diameter. Both converged before with exit 0:

  * the steady slice (inputs/pinch-roller-slice-steady.xml) on 8x128 cells with a capstan
    of radius 1 just touching it (Axis Point y = -7.2455): the frictionless footprint's
    pseudo-time carried the roller 12.6 down, through the capstan, and the run reported
    a speed ratio of -1.064 with max_penetration 0. Such a try now fails ("passed through
    the capstan", a node inside it), and the run converges to the physical state: the
    core's translation below 0.5 (0.066 today; it was 12.6) and the speed ratio within
    1e-3 of the same capstan on the shipped 4x64 mesh (0.988). Since the footprint's
    pseudo-time fails on its own stall (src/steady_rolling.cpp) no try gets that far: the
    same answer in at most 400 Newton iterations (250; 1,148 while the tries went through);
  * the 3D drive (inputs/pinch-roller-steady.xml) on 4 cells round: faces 12.3 long
    against the capstan's diameter of 5, the capstan sat 1.75 deep between two nodes and
    the speed ratio was -0.67. Such a try now fails ("cuts ... into a contact face"), and
    the run converges with the capstan on the outside (speed ratio 0.9-1.1), in at most
    300 Newton iterations (177 today, with the footprint's pseudo-time stall; 666 while
    its tries went between the nodes). The run warns of contact faces near the capstan
    longer than its diameter. (The check's geometry, kernels::faceCut, is tested in
    tests/test_contact_kernel.cpp.)

A free roller whose surface runs against the capstan's (a negative speed ratio) is no
steady state either: the drive on 4 cells round with the capstan reversed converged with
-13.8; now each try is refused and the run ends with exit 2, the reason on the progress
lines (SteadyRolling::rollerTurningBackwards).

Soft penalties (20x and 640x softer than formulation.md's range) sink the contact points
themselves into the capstan, and still converge: the bound counts from their penetration.

Every shipped scene takes the same Newton iterations with the check (docs/contact.md).
"""
import os
import sys

sys.dont_write_bytecode = True
sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from capstan_test import Test, has_nan  # noqa: E402

T = Test("through_capstan", __doc__)
SLICE = T.input("pinch-roller-slice-steady.xml")
SMALL = ["Capstans/capstan/Radius=0.9955", "Capstans/capstan/Axis Point={0, -7.2455, 0}"]


def core(s):
    c = s["steps"][-1]["supports"]["core"]
    return c["speed_ratio"], c["translation"]


p, fine, out = T.run_scene(SLICE, "small-capstan-8x128", sets=SMALL + ["Mesh/Cells={8, 128, 1}"], quiet=False)
_, coarse, _ = T.run_scene(SLICE, "small-capstan-4x64", sets=SMALL)
if fine is not None and coarse is not None and fine["converged"] and coarse["converged"]:
    T.conforms(out, SLICE)
    T.check(not has_nan(fine), "small capstan: no NaN in summary.json")
    n = sum(st["newton_iterations"] for st in fine["steps"])
    T.check(n <= 400, f"small capstan: {n} Newton iterations (<= 400; 250 today, 1,148 before the footprint's "
            f"pseudo-time stall)")
    (ratio, t), (ratio_ref, _) = core(fine), core(coarse)
    T.check(abs(t[1]) < 0.5, f"small capstan: the core's translation {t[1]:.4g} (|.| < 0.5, a quarter of the coating: "
            f"not through it; 4x64: {core(coarse)[1][1]:.4g})")
    T.check(abs(ratio - ratio_ref) < 1e-3,
            f"small capstan: speed ratio {ratio:.6f} against 4x64's {ratio_ref:.6f} (within 1e-3)")
else:
    T.check(False, "small capstan: both meshes converged")

DRIVE = T.input("pinch-roller-steady.xml")
p, four, out = T.run_scene(DRIVE, "four-cells-round", sets=["Mesh/Cells={5, 4, 8}", "Output/Write Fields=false"],
                           quiet=False)
if four is not None and four["converged"]:
    ratio, t = core(four)
    n = sum(st["newton_iterations"] for st in four["steps"])
    T.check(n <= 300, f"four cells round: {n} Newton iterations (<= 300; 177 today, 666 before the footprint's "
            f"pseudo-time stall)")
    T.check("contact faces near the capstan are up to 12.3 long" in p.stderr,
            "four cells round: warned of faces longer than the capstan's diameter")
    T.check(0.9 < ratio < 1.1, f"four cells round: speed ratio {ratio:.4f} (0.9-1.1: the capstan outside)")
else:
    T.check(False, "four cells round: converged")

# The same mesh with the capstan reversed converged to a roller turning against it, 14x fast
# (speed ratio -13.8; randomized sweep 12): no nip carries that, so the step fails and the run
# ends with exit 2, saying why (8 cells round converge: 0.967).
p, back, out = T.run_scene(DRIVE, "four-cells-reversed", expect_rc=2, quiet=False,
                           sets=["Mesh/Cells={4, 4, 6}", "Capstans/capstan/Angular Velocity=-19.05",
                                 "Output/Write Fields=false"])
T.check("running against the capstan's" in p.stdout, "four cells round, capstan reversed: the roller turning "
        "backwards is refused, said on the progress lines")
if back is not None:
    T.conforms(out, DRIVE)
    T.check(back["converged"] is False and not back["steps"], f"four cells round, capstan reversed: no step "
            f"converged ({len(back['steps'])} written)")

# Soft penalties sink the contact points themselves into the capstan: that is the penalty's
# model, not a body through the capstan (the earlier sweeps' runs, which converged before
# the check and must still; without the points' penetration in the bound both failed).
SOFT = [
    ("H5 study on a foundation of 3e-10, tilted, mu 1.34", "seed/h5-study.xml",
     ["Time/Steps=4", "Supports/foundation/Stiffness=3.34e-10",
      "Capstans/capstan/Axis Direction={-0.118142, -0.306853, 0.944396}", "Capstans/capstan/Friction/Law=Coulomb",
      "Capstans/capstan/Friction/Coefficient=1.338"]),
    ("the braked roller at a penalty of 6.41", "pinch-roller-braked.xml",
     ["Time/Steps=3", "Capstans/capstan/Contact/Penalty=6.41", "Capstans/capstan/Contact/Method=Penalty",
      "Capstans/capstan/Friction/Coefficient=1.5283"]),
]
for i, (label, scene, sets) in enumerate(SOFT):
    p, s, out = T.run_scene(T.input(scene), f"soft{i}", sets=sets + ["Output/Write Fields=false"], quiet=False)
    if s is not None and s["converged"]:
        pen = max(st["capstans"]["capstan"]["max_penetration"] for st in s["steps"])
        T.check("through the capstan" not in p.stdout and pen > 0.1,
                f"{label}: converged, its contact points {pen:.3g} deep (the soft penalty's), no try failed as "
                f"through the capstan")
    else:
        T.check(False, f"{label}: converged")
T.finish()
