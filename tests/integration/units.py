#!/usr/bin/env python3
"""Units: a scene in metres and pascals gives the answer of the same scene in millimetres
and megapascals, with its penalties scaled or left at their automatic defaults
(docs/contact.md and docs/numerics.md, "Penalties in any units").

Every length is scaled by L = 1e-3 and every stress by S = 1e6, so forces (S L^2) keep their
values. The study's penalties (1e-3) suit c ~ 1 and faces ~ 1; in metres and pascals they
are 1e9 and 1e12 times too soft. Their converged answers do not depend on them (the pressure
loop, exact contact), and the solves hold them within bounds scaled by h / c: the runs must
take the same Newton iterations and give the same forces. A plain penalty has its own
answer: its automatic default scales with h / c, and a soft one written into the scene warns.
A brake sweep balances the core's torque among forces: its row is a force (the torque over a
length of the core), so Newton's line search takes the same steps in both units.
"""
import importlib.util
import os

import capstan_test

T = capstan_test.Test("units", __doc__)
L, S = 1e-3, 1e6
# The scenes are rewritten by scripts/units-sweep.py's converter (each parameter's dimension by its name).
_spec = importlib.util.spec_from_file_location("units_sweep", os.path.join(T.inputs, "..", "scripts", "units-sweep.py"))
units_sweep = importlib.util.module_from_spec(_spec)
_spec.loader.exec_module(units_sweep)


def to_si(src, dst, drop=()):
    """Writes SRC in metres and pascals to DST; DROP: parameter names left to their defaults."""
    units_sweep.convert(src, dst, L, S, 1.0, drop)
    return dst


def rel(a, b):
    return abs(a - b) / max(abs(a), abs(b), 1e-300)


def vec_rel(a, b):
    return max(abs(x - y) for x, y in zip(a, b)) / max(max(abs(x) for x in a), 1e-300)


# --- G1: the default scene, exact contact (augmented Lagrangian) --------------------------
G1 = T.input("seed/g1.xml")
_, mm, _ = T.run_scene(G1, "g1-mm")
for label, drop in (("the scene's penalties, scaled", ()), ("the penalties' defaults", ("Penalty", "Pressure Penalty"))):
    si_file = to_si(G1, os.path.join(T.dir, f"g1-si-{len(drop)}.xml"), drop)
    p, si, out = T.run_scene(si_file, f"g1-si-{len(drop)}", quiet=False)
    T.conforms(out, si_file)
    if mm is None or si is None or not si["converged"]:
        T.check(False, f"G1 in metres and pascals, {label}: converged ({p.stderr.strip()[-300:]!r})")
        continue
    f_mm, f_si = mm["steps"][-1]["capstans"]["capstan"]["force"], si["steps"][-1]["capstans"]["capstan"]["force"]
    n_mm, n_si = [s["newton_iterations"] for s in mm["steps"]], [s["newton_iterations"] for s in si["steps"]]
    w_mm = mm["steps"][-1]["capstans"]["capstan"]["contact_width"]
    w_si = si["steps"][-1]["capstans"]["capstan"]["contact_width"]
    T.check(vec_rel(f_mm, f_si) < 1e-8, f"G1, {label}: force {f_si[1]:.10g} N against {f_mm[1]:.10g} "
                                          f"({vec_rel(f_mm, f_si):.1e} apart, 1e-8)")
    T.check(rel(w_si / L, w_mm) < 1e-8, f"G1, {label}: contact width {w_si:.6g} m against {w_mm:.6g} mm")
    T.check(n_si == n_mm, f"G1, {label}: Newton iterations {n_si} against {n_mm}")
    T.check("WARNING" not in p.stderr, f"G1, {label}: no warning ({p.stderr.strip()[:200]!r})")

# --- a plain penalty: its automatic default gives the same answer in both units; one of 1e-3 --
# --- written into a scene in metres (as formulation.md's G1 has it) warns --------------------
plain_sets = ["Capstans/capstan/Contact/Method=Penalty", "Time/Steps=1"]
_, mm_plain, _ = T.run_scene(G1, "g1-mm-plain", sets=plain_sets + ["Capstans/capstan/Contact/Penalty=0"])
plain = to_si(G1, os.path.join(T.dir, "g1-si-plain.xml"), ("Penalty",))
p, si_plain, _ = T.run_scene(plain, "g1-si-plain", sets=plain_sets, quiet=False)
if mm_plain is not None and si_plain is not None:
    f_mm, f_si = (x["steps"][-1]["capstans"]["capstan"]["force"] for x in (mm_plain, si_plain))
    pen_mm, pen_si = (x["steps"][-1]["capstans"]["capstan"]["max_penetration"] for x in (mm_plain, si_plain))
    T.check(vec_rel(f_mm, f_si) < 1e-8 and rel(pen_si / L, pen_mm) < 1e-6,
            f"plain penalty, automatic: force {f_si[1]:.10g} N against {f_mm[1]:.10g}, penetration {pen_si:.4g} m "
            f"against {pen_mm:.4g} mm")
    T.check("WARNING" not in p.stderr, f"plain penalty, automatic, in metres: no warning ({p.stderr.strip()[:200]!r})")
p = T.capstan_run(["run", plain, "--output", os.path.join(T.dir, "plain-1e-3"), "--quiet", "--set", "Time/Steps=1",
                   "--set", "Capstans/capstan/Contact/Method=Penalty", "--set", "Capstans/capstan/Contact/Penalty=1e-3"],
                  cwd=T.dir, timeout=300)
T.check("Capstans/capstan/Contact/Penalty" in p.stderr and "sinks into the capstan" in p.stderr
        and "2e+06 h at a pressure of c" in p.stderr,
        f"plain penalty 1e-3 in metres: warned, exit {p.returncode} ({p.stderr.strip()[:300]!r})")

# G1's own units: a plain penalty above 2e-2 h / c (1e-2 there, formulation.md's softest) warns.
for penalty, warned in (("1e-2", False), ("0.014", True)):
    p = T.capstan_run(["run", G1, "--output", os.path.join(T.dir, f"plain-{penalty}"), "--quiet", "--set", "Time/Steps=1",
                       "--set", "Capstans/capstan/Contact/Method=Penalty", "--set",
                       f"Capstans/capstan/Contact/Penalty={penalty}"], cwd=T.dir)
    T.check(("WARNING" in p.stderr and "Capstans/capstan/Contact/Penalty" in p.stderr and G1 in p.stderr) == warned
            and p.returncode == 0, f"G1, plain penalty {penalty}: {'a' if warned else 'no'} warning, exit {p.returncode} "
            f"({p.stderr.strip()[:200]!r})")

def mm_and_si(scene_name, tag):
    """Runs a shipped scene as written and in metres and pascals: (mm summary, SI summary,
    the SI run's process), the SI output checked against interface.md."""
    scene = T.input(scene_name)
    _, mm, _ = T.run_scene(scene, f"{tag}-mm")
    si_file = to_si(scene, os.path.join(T.dir, f"{tag}-si.xml"))
    p, si, out = T.run_scene(si_file, f"{tag}-si", quiet=False)
    T.conforms(out, si_file)
    return mm, si, p


# --- steady rolling: the pinch-roller slice, a rigid core with a force ------------------------
mm, si, p = mm_and_si("pinch-roller-slice-steady.xml", "slice")
if mm is not None and si is not None and si["converged"]:
    r_mm, r_si = (x["steps"][-1]["supports"]["core"]["speed_ratio"] for x in (mm, si))
    T.check(abs(r_mm - r_si) < 1e-8, f"steady slice: speed ratio {r_si:.10f} against {r_mm:.10f}")
    f_mm, f_si = mm["steps"][-1]["capstans"]["capstan"]["force"], si["steps"][-1]["capstans"]["capstan"]["force"]
    T.check(vec_rel(f_mm, f_si) < 1e-8, f"steady slice: capstan force {f_si} N against {f_mm} ({vec_rel(f_mm, f_si):.1e})")
    t_mm, t_si = (x["steps"][-1]["supports"]["core"]["translation"][1] for x in (mm, si))
    T.check(rel(t_si / L, t_mm) < 1e-6, f"steady slice: core translation {t_si:.6g} m against {t_mm:.6g} mm")
    n_mm, n_si = mm["steps"][-1]["newton_iterations"], si["steps"][-1]["newton_iterations"]
    T.check(n_si == n_mm, f"steady slice: {n_si} Newton iterations against {n_mm}")
    T.check("WARNING" not in p.stderr, f"steady slice: no warning ({p.stderr.strip()[:200]!r})")
else:
    T.check(False, f"steady slice in metres and pascals: converged ({p.stderr.strip()[-300:]!r})")

# --- a brake sweep: the core's torque balance among the forces ---------------------------------
# The residual holds the torque over the core's radius (a force), so the line
# search weighs it alike in both units. Before, as a torque, it weighed 1e-3 as much in metres:
# 170 Newton iterations against 62.
mm, si, p = mm_and_si("pinch-roller-braked-steady.xml", "braked")
if mm is not None and si is not None and si["converged"]:
    n_mm, n_si = ([s["newton_iterations"] for s in x["steps"]] for x in (mm, si))
    T.check(n_si == n_mm, f"brake sweep: Newton iterations {n_si} ({sum(n_si)}) against {n_mm} ({sum(n_mm)})")
    r_mm, r_si = ([s["supports"]["core"]["speed_ratio"] for s in x["steps"]] for x in (mm, si))
    worst = max(abs(a - b) for a, b in zip(r_mm, r_si))
    T.check(len(r_si) == len(r_mm) and worst < 1e-8, f"brake sweep: speed ratios {worst:.1e} apart (1e-8)")
else:
    T.check(False, f"brake sweep in metres and pascals: converged ({p.stderr.strip()[-300:]!r})")
T.finish()
