#!/usr/bin/env python3
"""A body held by soft supports: a nearly singular tangent (ctest label `hard`).

block40.xml on 10x10x4 cells with its base on an elastic Foundation of Stiffness
1.3749e-4 in x, y and z (c = 1): the top face is pushed down 0.05 and the block, nearly
rigid against so soft a bed, sinks with it. The tangent's soft modes (the rigid motions
the springs barely hold) make it nearly singular, and the LU preconditioner's
single-precision factors erred by 8% there: GMRES on them gave Newton directions no line
search could use, and the run ended with exit 2 after 41 cuts at 31% of its step. The
factorisation's probe (src/mumps_solve_factory.cpp) now switches to double precision.

Checks: exit 0 with no cut and few Newton iterations; the switch is reported (stderr, and
summary.json's `solver_switches` at step 1); the base's
reaction equals the springs' k A 0.05 (the block hardly deforms: within 1e-3); and the
same scene with Precision = Double named gives the same forces (1e-8).
"""
import os
import sys

sys.dont_write_bytecode = True
sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from capstan_test import Test  # noqa: E402

T = Test("soft_support", __doc__)

SOFT = ["Supports/base/Type=Foundation", "Supports/base/Components=xyz", "Supports/base/Stiffness=1.3749e-4",
        "Mesh/Cells={10,10,4}"]
p, s, out = T.run_scene(T.input("block40.xml"), "soft", sets=SOFT)
T.conforms(out, os.path.join(out, "scene.xml"))
ok = s is not None and s["converged"]
T.check(ok, f"soft foundation: converged ({None if s is None else s['failure']!r})")
if ok:
    st = s["steps"][-1]
    newton = sum(x["newton_iterations"] for x in s["steps"])
    cuts = sum(x["cutbacks"] for x in s["steps"])
    T.check(cuts == 0 and newton <= 10, f"soft foundation: {newton} Newton iterations (<= 10), {cuts} cuts (0)")
    T.check("double precision from here on" in p.stderr, "soft foundation: the switch to double factors is reported")
    sw = s["solver_switches"]
    T.check(len(sw) == 1 and sw[0]["step"] == 1 and "double precision" in sw[0]["what"],
            f"soft foundation: summary.json's solver_switches lists it at step 1 ({sw})")
    fy, expected = st["supports"]["base"]["force"][1], 1.3749e-4 * 1.0 * 0.05
    T.check(abs(fy - expected) <= 1e-3 * expected, f"soft foundation: base reaction {fy:.6e} = k A 0.05 = {expected:.6e}")
    p2, s2, out2 = T.run_scene(T.input("block40.xml"), "soft-double",
                               sets=SOFT + ["Solver/Stratimikos/Preconditioner Types/MUMPS/Precision=Double"])
    if T.check(s2 is not None and s2["converged"], "soft foundation, Precision = Double: converged"):
        f1, f2 = st["supports"]["top"]["force"][1], s2["steps"][-1]["supports"]["top"]["force"][1]
        T.check(abs(f1 - f2) <= 1e-8 * abs(f2), f"soft foundation: top force {f1:.10e} against Double's {f2:.10e}")
        T.check("double precision from here on" not in p2.stderr and s2["solver_switches"] == [],
                "Precision = Double named: nothing to report")
T.finish()
