#!/usr/bin/env python3
"""A scene may pick MueLu's smoother (Solver/Stratimikos/Preconditioner Types/MueLu).

capstan's MueLu defaults include a Chebyshev degree; it is set only with its own
Chebyshev smoother, so that a scene choosing another smoother gets that smoother's
defaults (MueLu rejects a Chebyshev degree for, e.g., Gauss-Seidel: before, such a
scene stopped with an internal error). seed/g1.xml (1575 dofs), GMRES + MueLu:

  * the default smoother, and
  * smoother: type = RELAXATION, relaxation: type = Symmetric Gauss-Seidel,

both converge, conform to interface.md, and agree on every step's support and
capstan forces to 1e-8 (the same converged state, whatever the preconditioner);
their Krylov iteration counts differ (the scene's choice took effect).
"""
import os
import sys

sys.dont_write_bytecode = True  # nothing written into the source tree
sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from capstan_test import Test, summary_figures, worst_difference  # noqa: E402

TOL = 1e-8
T = Test("muelu_smoother", __doc__)
base = T.input("seed/g1.xml")
SGS = ('<ParameterList name="Solver"><ParameterList name="Stratimikos"><ParameterList name="Preconditioner Types">'
       '<ParameterList name="MueLu"><Parameter name="smoother: type" type="string" value="RELAXATION"/>'
       '<ParameterList name="smoother: params"><Parameter name="relaxation: type" type="string" '
       'value="Symmetric Gauss-Seidel"/></ParameterList></ParameterList></ParameterList></ParameterList>'
       '</ParameterList>')
sgs = T.scene_with(base, "g1-sgs.xml", SGS)

sets = ["Solver/Linear Solver=GMRES", "Solver/Preconditioner=MueLu", "Output/Write Fields=false"]
runs = {}
for label, scene in (("Chebyshev (default)", base), ("symmetric Gauss-Seidel", sgs)):
    s = T.converged_run(scene, label.split()[0].lower(), label, sets=sets)
    if s is None:
        continue
    runs[label] = s
    print(f"  {label}: {sum(st['linear_iterations'] for st in s['steps'])} Krylov iterations")

if len(runs) == 2:
    a, b = (runs[k] for k in ("Chebyshev (default)", "symmetric Gauss-Seidel"))
    worst, where, scale = worst_difference(summary_figures(a)["force"], summary_figures(b)["force"])
    T.check(worst <= TOL, f"forces agree: worst {worst:.2e} of the largest {scale:.4g} ({where}) (<= {TOL:g})")
    la = [st["linear_iterations"] for st in a["steps"]]
    lb = [st["linear_iterations"] for st in b["steps"]]
    T.check(la != lb, f"the smoother took effect: Krylov iterations per step {la} vs {lb}")

T.finish()
