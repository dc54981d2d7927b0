#!/usr/bin/env python3
"""MUMPS (Solver/Linear Solver = Direct) on 1 and 2 ranks gives the Newton iterations and
the answers of Amesos2's KLU2 on 1 rank, the direct solver it replaced.

G1 (inputs/seed/g1.xml), H5 (Coulomb friction), hertz-roller.xml (a graded ring with a
spring-pressed free rigid core) and the rolling slice (pinch-roller-slice.xml, a free core
turned by friction; its first 4 steps) are run with KLU2 on 1 rank (the scene with
Solver/Stratimikos/Linear Solver Type = Amesos2) and with MUMPS on 1 and 2 ranks:
  * the Newton iterations of every step are the same, as are the cuts and augmentations;
    in a step that is cut (the slice's steps 3 and 4: Newton fails on stick/slip
    chattering, issue 33), the failed attempts end where round-off tips the line search,
    so there the Newton iterations agree to 20%;
  * the final stress, pressure and von Mises extrema, the face means of the displacement
    and every support and capstan force of every step agree to 1e-10 relative to the
    largest magnitude of their kind, and the cores' rotations to 1e-10 of the largest.
summary.json's timing.direct_solver counts MUMPS' work: at least one analysis, a factorisation
for each Newton iteration at least (Direct factors every Newton matrix), a solve for each
factorisation at least, and the same factorisations and solves on 1 and 2 ranks.
Both solvers run the saddle-point steps on a factorisation of their own
(Solver/Pressure Step Factorisation = New): with MUMPS the default reuses Newton's last
one, which KLU2 cannot, and takes the slice along another path within Newton's tolerance
(stress 3.6e-9 apart).
"""
import os
import sys
import xml.etree.ElementTree as ET

sys.dont_write_bytecode = True  # nothing written into the source tree
sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from capstan_test import Test, summary_figures, worst_difference  # noqa: E402

TOL = 1e-10
T = Test("direct_solvers", __doc__)


def klu2_copy(scene, name):
    """The scene with Solver/Stratimikos/Linear Solver Type = Amesos2 (KLU2)."""
    tree = ET.parse(scene)
    root = tree.getroot()
    solver = next((p for p in root.findall("ParameterList") if p.get("name") == "Solver"), None)
    if solver is None:
        solver = ET.SubElement(root, "ParameterList", name="Solver")
    strat = ET.SubElement(solver, "ParameterList", name="Stratimikos")
    ET.SubElement(strat, "Parameter", name="Linear Solver Type", type="string", value="Amesos2")
    path = T.path(name + "-klu2.xml")
    tree.write(path)
    return path


def rotations(s):
    return {f"step {st['step']} {name}.rotation": sup["rotation"]
            for st in s["steps"] for name, sup in st["supports"].items() if "rotation" in sup}


for name, scene, sets in (("g1", "seed/g1.xml", []), ("h5", "seed/h5.xml", []),
                          ("hertz", "hertz-roller.xml", []), ("slice", "pinch-roller-slice.xml", ["Time/Steps=4"])):
    path = T.input(scene)
    sets = sets + ["Solver/Linear Solver=Direct", "Solver/Pressure Step Factorisation=New",
                   "Output/Write Fields=false"]
    _, ref, _ = T.run_scene(klu2_copy(path, name), f"{name}-klu2", sets=sets)
    if ref is None:
        T.check(False, f"{name}: KLU2 on 1 rank wrote no summary.json")
        continue
    newton_ref = [st["newton_iterations"] for st in ref["steps"]]
    route_ref = [(st["cutbacks"], st["augmentations"]) for st in ref["steps"]]
    work = {}  # ranks: MUMPS' (factorisations, solves)
    for ranks in (1, 2):
        _, s, out = T.run_scene(path, f"{name}-mumps-{ranks}", sets=sets, ranks=ranks)
        label = f"{name}, MUMPS on {ranks} rank(s)"
        if s is None:
            T.check(False, f"{label}: no summary.json")
            continue
        T.check(s["converged"] is True, f"{label}: converged = {s['converged']} ({s['failure']!r})")
        T.conforms(out, path)
        newton = [st["newton_iterations"] for st in s["steps"]]
        d = s["timing"]["direct_solver"]
        T.check(d["analyses"] >= 1 and d["factorizations"] >= sum(newton) and d["solves"] >= d["factorizations"],
                f"{label}: timing.direct_solver {d}: an analysis, a factorisation a Newton iteration "
                f"({sum(newton)}) and a solve a factorisation at least")
        work[ranks] = (d["factorizations"], d["solves"])
        route = [(st["cutbacks"], st["augmentations"]) for st in s["steps"]]
        T.check(route == route_ref, f"{label}: (cuts, augmentations) per step {route} as KLU2's {route_ref}")
        same = all(n == m or (c > 0 and abs(n - m) <= 0.2 * m)
                   for n, m, (c, _) in zip(newton, newton_ref, route_ref)) and len(newton) == len(newton_ref)
        T.check(same, f"{label}: Newton iterations per step {newton} as KLU2's {newton_ref} (20% in cut steps)")
        groups = summary_figures(ref)
        groups["rotation"] = rotations(ref)
        other = summary_figures(s) | {"rotation": rotations(s)}
        for group, figures in groups.items():
            if not figures or max(abs(v) for v in figures.values()) == 0:  # a held core: zero rotations
                T.check(all(other[group].get(k) == 0 for k in figures), f"{label}: {group}: zero as KLU2's")
                continue
            worst, k, scale = worst_difference(figures, other[group])
            T.check(worst <= TOL, f"{label}: {group} as KLU2's: worst {worst:.2e} ({k}) (<= {TOL:g})")
    if len(work) == 2:
        T.check(work[1] == work[2], f"{name}: MUMPS' (factorisations, solves) {work[2]} on 2 ranks as on 1 {work[1]}")

T.finish()
