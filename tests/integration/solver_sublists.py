#!/usr/bin/env python3
"""Solver/Belos and Solver/Ifpack2 are passed through to Trilinos (interface.md:
"Trilinos sublists (NOX, Belos, Ifpack2 / Stratimikos) are passed through unchanged").

seed/g1.xml (1575 dofs), GMRES + ILU(1), 2 steps:

  * capstan's defaults;
  * Solver/Belos/Num Blocks = 4 in the scene (GMRES restarted every 4 iterations);
  * Solver/Ifpack2/fact: iluk level-of-fill = 0 by --set (ILU(0) for ILU(1));

each converges, conforms to interface.md and agrees with the defaults on every
step's support and capstan forces to 1e-8 (the same converged state), while its
Krylov iteration count differs (the sublist took effect). An int given where
Ifpack2 takes a double (a damping factor of 1) is read as a double. Misspelt names
and values Belos refuses are bad input: tests/integration/bad_input.py. NOX ignores
names it does not read: a Solver/NOX name that NOX did not read in the run's first
Newton solve is a warning naming its path, once, on 1 and 2 ranks (a name it read
gives none); on G1, whose monolithic pressure loop does without NOX, every one is.
"""
import os
import sys

sys.dont_write_bytecode = True  # nothing written into the source tree
sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from capstan_test import Test, summary_figures, worst_difference  # noqa: E402

TOL = 1e-8
T = Test("solver_sublists", __doc__)
base = T.input("seed/g1.xml")
belos = T.scene_with(base, "g1-belos.xml", '<ParameterList name="Solver"><ParameterList name="Belos">'
                                           '<Parameter name="Num Blocks" type="int" value="4"/></ParameterList>'
                                           '</ParameterList>')

sets = ["Solver/Linear Solver=GMRES", "Solver/Preconditioner=ILU", "Time/Steps=2", "Output/Write Fields=false"]
runs = {}
for label, scene, extra in (("defaults", base, []), ("Belos' Num Blocks = 4", belos, []),
                            ("Ifpack2's level of fill 0", base, ["Solver/Ifpack2/fact: iluk level-of-fill=0"])):
    s = T.converged_run(scene, label.split()[0].lower().strip("'"), label, sets=sets + extra)
    if s is None:
        continue
    runs[label] = s
    print(f"  {label}: Krylov iterations per step {[st['linear_iterations'] for st in s['steps']]}")

# An int where Ifpack2 takes a double, as a user writes it on the command line.
p, s, out = T.run_scene(base, "jacobi-damping", sets=["Solver/Linear Solver=GMRES", "Solver/Preconditioner=Jacobi",
                                                      "Time/Steps=1", "Output/Write Fields=false",
                                                      "Solver/Ifpack2/relaxation: damping factor=1"])
T.check(s is not None and s["converged"] is True, "Jacobi with --set 'Solver/Ifpack2/relaxation: damping factor=1' "
                                                  "(an int where Ifpack2 takes a double) runs and converges")

# NOX ignores names it does not read: a name NOX read in the first Newton solve runs silently, one
# it did not (misspelt, or for a line search the run does not use) is a warning naming its path; on
# G1, whose monolithic pressure loop takes its Newton steps without NOX, every NOX name is.
slice_scene = T.input("pinch-roller-slice.xml")
nox = ["Time/Steps=1", "Output/Write Fields=false"]
read, unread = "Solver/NOX/Line Search/Backtrack/Max Iters", ("Solver/NOX/Foo", "Solver/NOX/Line Search/Polynomial/Max Iters")
for ranks in (1, 2):
    p, s, out = T.run_scene(slice_scene, f"nox-{ranks}", sets=nox + [f"{read}=12"] + [f"{u}=5" for u in unread],
                            ranks=ranks, quiet=False)
    T.check(f"'{read}'" not in p.stderr, f"{ranks} rank(s): {read} (read by NOX): no warning")
    for path in unread:
        T.check(p.stderr.count(f"parameter '{path}': NOX did not read it") == 1,
                f"{ranks} rank(s): {path} (not read by NOX): one warning naming it")
    T.check(s is not None and s["converged"] is True, f"{ranks} rank(s): the run with unread NOX names converges")
p, s, out = T.run_scene(base, "nox-g1", sets=nox + [f"{read}=12"], quiet=False)
T.check(p.stderr.count(f"parameter '{read}': no Newton iteration of this run went through NOX") == 1,
        f"G1 (monolithic, no NOX solve): {read} is a warning")

if len(runs) == 3:
    a = runs["defaults"]
    for label in ("Belos' Num Blocks = 4", "Ifpack2's level of fill 0"):
        b = runs[label]
        worst, where, scale = worst_difference(summary_figures(a)["force"], summary_figures(b)["force"])
        T.check(worst <= TOL, f"{label}: forces agree with the defaults' to {worst:.2e} of {scale:.4g} ({where}) "
                              f"(<= {TOL:g})")
        la = [st["linear_iterations"] for st in a["steps"]]
        lb = [st["linear_iterations"] for st in b["steps"]]
        T.check(la != lb, f"{label}: took effect, Krylov iterations per step {la} vs {lb}")

T.finish()
