#!/usr/bin/env python3
"""A capstan that overlaps a free core's body deeply at t = 0: the body seated (src/seating.hpp).

The Hertz ring (inputs/hertz-roller.xml: a free core pressed by 0.005 onto a capstan that
overlaps it by 0.01 at t = 0) with the capstan's axis tilted to (-0.068, 0.261, 0.963). The
tilt turns the overlap into 0.21 at one end of the slice, 5.8 shortest contact face edges
(0.036): the first Newton solve had to squeeze it out of the thin cells at the surface,
failed at every cut (a cut does not lessen an overlap present at t = 0) and ran minutes to
exit 2. Now the body moves clear with its core first (the first guess only):

  * exit 0, with the seating said on the progress lines and logged once per try
    (translation 0.2078, the overlap down to a quarter of that edge), at most 4 Newton
    iterations a step (3 today), max_penetration <= 1e-4 h, volumes within 1e-10;
  * the answer is the problem's own: against the same tilt with the capstan moved 0.2
    away (Axis Point y = -11.44, an overlap of about 0.01, not seated), the capstan force
    within 1e-8 (relative) and the core's translation 0.2 apart to 1e-8;
  * 2 ranks give 1 rank's force and translation to 1e-8;
  * a body between two capstans is not seated: the fast roller (inputs/free-roller-fast.xml)
    overlapped 0.3 by its capstan, with a second capstan across it. Seated, it moved 4.9,
    through the second capstan, and converged with that capstan inside its coating; now
    it converges where both capstans touch the body;
  * designed preloads are not seated: the shipped Hertz ring (overlap 0.01, 0.28 of its
    edge) and the 3D drive's step 1 (0.06, 0.66 of its edge).
"""
import os
import sys

sys.dont_write_bytecode = True
sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from capstan_test import Test, has_nan  # noqa: E402

T = Test("seating", __doc__)
SCENE = T.input("hertz-roller.xml")
TILT = ["Capstans/capstan/Axis Direction={-0.068286, 0.261145, 0.962881}", "Time/Steps=3"]
AWAY = TILT + ["Capstans/capstan/Axis Point={0, -11.44, 0}"]


def final(s):
    st = s["steps"][-1]
    return st["capstans"]["capstan"]["force"], st["supports"]["core"]["translation"]


def rel(a, b):
    return max(abs(x - y) for x, y in zip(a, b)) / max(abs(x) for x in b)


p, tilted, out = T.run_scene(SCENE, "tilted", sets=TILT, quiet=False, extra=["--log", "newton"])
if tilted is not None and tilted["converged"]:
    T.conforms(out, SCENE)
    T.check("moved 0.2078 clear with its core" in p.stdout, "tilted: the seating is on the progress lines")
    seatings = T.log_events(out, "seating")
    T.check(len(seatings) == 1 and abs(seatings[0]["translation"] - 0.2078) < 1e-3 and seatings[0]["kept"] is True,
            f"tilted: one seating logged, translation 0.2078 ({[e.get('translation') for e in seatings]})")
    newton = [st["newton_iterations"] for st in tilted["steps"]]
    T.check(max(newton) <= 4, f"tilted: Newton iterations per step {newton} (at most 4)")
    T.check(not has_nan(tilted), "tilted: no NaN in summary.json")
    pen = max(st["capstans"]["capstan"]["max_penetration"] for st in tilted["steps"])
    dv = max(st["max_abs_volume_change"] for st in tilted["steps"])
    T.check(pen <= 3.6e-6 and dv <= 1e-10, f"tilted: max_penetration {pen:.1e} (<= 3.6e-6), volume change {dv:.1e}")
else:
    T.check(False, f"tilted: converged ({None if tilted is None else tilted['failure']!r})")

_, away, out = T.run_scene(SCENE, "away", sets=AWAY, extra=["--log", "newton"])
T.check(not T.log_events(out, "seating"), "capstan moved away (overlap 0.01): not seated")
_, two, _ = T.run_scene(SCENE, "tilted-2ranks", sets=TILT, ranks=2)
if tilted and away and two and tilted["converged"] and away["converged"] and two["converged"]:
    (F, q), (Fa, qa), (F2, q2) = final(tilted), final(away), final(two)
    print(f"    tilted: force {F}, core translation {q[1]:.10f}; moved away: {Fa}, {qa[1]:.10f}")
    T.check(rel(F, Fa) <= 1e-8, f"tilted against the capstan moved away: force within {rel(F, Fa):.1e} (1e-8)")
    T.check(abs(q[1] - qa[1] - 0.2) <= 1e-8, f"core translations {q[1] - qa[1]:.10f} apart (0.2, to 1e-8)")
    T.check(rel(F2, F) <= 1e-8 and abs(q2[1] - q[1]) <= 1e-8,
            f"2 ranks against 1: force {rel(F2, F):.1e}, translation {abs(q2[1] - q[1]):.1e} (1e-8)")

_, shipped, out = T.run_scene(SCENE, "shipped", extra=["--log", "newton"])
T.check(shipped is not None and shipped["converged"] and not T.log_events(out, "seating"),
        "the shipped Hertz ring (overlap 0.28 of the edge): converged, not seated")
C2 = "Capstans/c2/"
TWO = ["Time/Steps=1", "Capstans/capstan/Axis Point={0, -8.39, 0}", C2 + "Radius=2.5", C2 + "Axis Point={0, 8.69, 0}",
       C2 + "Contact Faces=outer", C2 + "Contact/Method=Augmented Lagrangian"]
_, two, out = T.run_scene(T.input("free-roller-fast.xml"), "two-capstans", sets=TWO, extra=["--log", "newton"])
if two is not None and two["converged"]:
    points = {k: v["contact_points"] for k, v in two["steps"][-1]["capstans"].items()}
    q = two["steps"][-1]["supports"]["core"]["translation"]
    T.check(not T.log_events(out, "seating") and all(n > 0 for n in points.values()) and abs(q[1]) < 1,
            f"between two capstans: not seated, both capstans touch the body {points}, core moved {q[1]:.3f}")
else:
    T.check(False, f"between two capstans: converged ({None if two is None else two['failure']!r})")

_, drive, out = T.run_scene(T.input("pinch-roller.xml"), "drive", sets=["Time/Steps=1", "Output/Write Fields=false"],
                            extra=["--log", "newton"])
T.check(drive is not None and drive["converged"] and not T.log_events(out, "seating"),
        "the 3D drive's step 1 (overlap 0.66 of its edge): converged, not seated")
T.finish()
