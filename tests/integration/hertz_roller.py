#!/usr/bin/env python3
"""Hertz line contact: a thick rubber coating (17 contact half-widths) in plane
strain, pressed by a frictionless capstan: on a held core pushed into by the capstan
(inputs/hertz-roller-held.xml), and on a rigid core free along y, pushed onto the
capstan by a spring Force (inputs/hertz-roller.xml). From the measured force per length P, Hertz gives the half-width
a = sqrt(4 P R / (pi E*)) and peak pressure p0 = 2 P / (pi a), with E* = 4G = 8c and
1/R = 1/R_capstan + 1/R_roller. On the graded 20x120x1 mesh the last step's peak
pressure must agree within 5% and the contact width within 10%, and both errors must
be smaller than on the coarsest mesh (10x60x1; 5x30x1 for the free core). The capstan force equals the core's reaction
(1e-8) at every step; with the free core both equal the ramped Force (1e-8).
The free core once more with Krylov solves (GMRES + MueLu, the saddle-point step with
the Laplacian Schur term), and once with Predictor = Previous (Newton from rest in step 1):
each must converge to the direct run's state (forces and peak pressure to 1e-6) in as many
steps, without a cut. The Krylov run's pressure loop once stalled just above the volume tolerance
(docs/numerics.md, "The pressure loop"); the Previous run's monolithic loop crawled through
every cut of step 1 (a plain contact update from rest, before any Newton solve).
"""
import math
import os
import sys

sys.dont_write_bytecode = True
sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from capstan_test import Test, rel_diff  # noqa: E402

T = Test("hertz_roller", __doc__)
c, length, R = 1.0, 0.1, 1 / (1 / 5.0 + 1 / 6.25)
E = 8 * c
direct = None  # the free core's direct run on the scene's own mesh
for name in ("hertz-roller-held.xml", "hertz-roller.xml"):
    scene = T.input(name)
    free = name == "hertz-roller.xml"
    errors = []
    meshes = ("5,30,1", "10,60,1", "20,120,1") if free else ("10,60,1", "20,120,1")
    for cells in meshes:
        # A direct solve: smoothed aggregation needs ~500 GMRES iterations per Newton
        # step on this strongly graded ring (docs/pinch-roller.md).
        p, s, out = T.run_scene(scene, name[:-4] + "-" + cells.replace(",", "x"),
                                sets=[f"Mesh/Cells={{{cells}}}", "Solver/Linear Solver=Direct"])
        if s is None or not s["converged"]:
            T.fatal(f"{name} {cells}: did not converge")
        T.conforms(out, scene)
        for st in s["steps"]:
            f, core = st["capstans"]["capstan"]["force"][1], st["supports"]["core"]["force"][1]
            T.check(rel_diff(f, core) < 1e-8, f"{name} {cells} step {st['step']}: capstan force {f:.12g} = core force {core:.12g}")
            if free:
                # The spring's Force, ramped linearly to t = 2.
                applied = -0.005 * min(st["time"] / 2, 1)
                T.check(rel_diff(core, applied) < 1e-8, f"{name} {cells} step {st['step']}: core force {core:.12g} = Force {applied:.12g}")
        cap = s["steps"][-1]["capstans"]["capstan"]
        P = abs(cap["force"][1]) / length
        a = math.sqrt(4 * P * R / (math.pi * E))
        p0 = 2 * P / (math.pi * a)
        ep = abs(cap["peak_pressure"] - p0) / p0
        ew = abs(cap["contact_width"] - 2 * a) / (2 * a)
        print(f"    {name} {cells}: P = {P:.6f}, peak {cap['peak_pressure']:.6f} vs Hertz {p0:.6f} ({ep:.2%}), "
              f"width {cap['contact_width']:.5f} vs 2a = {2 * a:.5f} ({ew:.2%}), half-width / thickness "
              f"{a / 5.25:.3f}")
        errors.append((ep, ew))
        if free and cells == meshes[-1]:
            direct = s
    if len(errors) == len(meshes):
        # The width is measured between contact nodes (known to one node spacing):
        # against the coarsest mesh, so that a lucky node position does not decide.
        (ep1, ew1), (ep2, ew2) = errors[0], errors[-1]
        T.check(ep2 < 0.05, f"{name} fine mesh: peak pressure error {ep2:.2%} < 5%")
        T.check(ew2 < 0.10, f"{name} fine mesh: contact width error {ew2:.2%} < 10%")
        T.check(ep2 < ep1 and ew2 < ew1, f"{name}: errors shrink under refinement: pressure {ep1:.2%} -> {ep2:.2%}, "
                                         f"width {ew1:.2%} -> {ew2:.2%}")
# The free core again: with Krylov solves, and starting Newton from the last converged state
# (from rest in step 1; its monolithic pressure loop once crawled through every cut there).
VARIANTS = (("GMRES", "hertz-roller-gmres", ["Solver/Linear Solver=GMRES", "Solver/Preconditioner=MueLu",
                                             "Solver/Pressure Step Schur=Laplacian"]),
            ("Predictor=Previous", "hertz-roller-previous", ["Solver/Predictor=Previous"]))
for label, run, sets in VARIANTS if direct is not None else ():
    scene = T.input("hertz-roller.xml")
    p, s, out = T.run_scene(scene, run, sets=sets)
    if s is None or not s["converged"]:
        T.fatal(f"hertz-roller.xml with {label}: did not converge")
    T.conforms(out, scene)
    for a, b in zip(direct["steps"], s["steps"]):
        fa, fb = a["capstans"]["capstan"]["force"][1], b["capstans"]["capstan"]["force"][1]
        T.check(rel_diff(fa, fb) < 1e-6, f"{label} step {b['step']}: capstan force {fb:.12g} = direct {fa:.12g}")
        pa, pb = a["capstans"]["capstan"]["peak_pressure"], b["capstans"]["capstan"]["peak_pressure"]
        T.check(rel_diff(pa, pb) < 1e-6, f"{label} step {b['step']}: peak pressure {pb:.12g} = direct {pa:.12g}")
    T.check(len(s["steps"]) == len(direct["steps"]), f"{label}: {len(s['steps'])} steps as the direct run's {len(direct['steps'])}")
    cuts = sum(st["cutbacks"] for st in s["steps"])
    T.check(cuts == 0, f"{label}: {cuts} step cuts (none)")
T.finish()
