#!/usr/bin/env python3
"""The converged state does not depend on the pressure penalty eps1.

Material/Pressure Penalty (eps1) only conditions the condensed Newton step; the
pressure loop drives v_e = V_e, so the converged state must be the same for every
eps1 (interface.md, scene.cpp doc string). Sweep eps1 = 1e-13 ... 1e-1 on

  * inputs/uniaxial.xml (homogeneous): final stress xx/yy extrema and the face
    means of the displacement agree with the eps1 = 1e-3 run to 1e-8 relative
    (absolute 1e-8 for values below 1 in magnitude, i.e. near 0);
  * inputs/shear.xml (simple shear, non-homogeneous): the face means of the
    displacement and all stress/pressure extrema agree with the eps1 = 1e-3 run
    to 1e-8 relative to the largest magnitude of their kind.

Every run must converge with max |v_e/V_e - 1| <= Solver/Volume Tolerance (1e-10).
"""
import os
import sys

sys.dont_write_bytecode = True  # nothing written into the source tree
sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from capstan_test import STRESS, Test, has_nan  # noqa: E402

EPS = ["1e-13", "1e-8", "1e-5", "1e-3", "1e-1"]
REF = "1e-3"
TOL = 1e-8

T = Test("eps1_independence", __doc__)


def sweep(name):
    scene = T.input(name)
    runs = {}
    for eps in EPS:
        p, s, out = T.run_scene(scene, f"{name[:-4]}-{eps}", sets=[f"Material/Pressure Penalty={eps}"])
        if s is None:
            T.check(False, f"{name} eps1={eps}: no summary.json")
            continue
        ok = s["converged"] is True
        T.check(ok, f"{name} eps1={eps}: converged = {s['converged']} ({s['failure']!r})")
        T.check(not has_nan(s), f"{name} eps1={eps}: no NaN in summary.json")
        dv = s["final"]["max_abs_volume_change"]
        T.check(dv <= 1e-10, f"{name} eps1={eps}: final.max_abs_volume_change = {dv:.2e} (<= 1e-10)")
        # Equilibrium: with no capstan, the supports' forces on the body sum to 0.
        worst = 0.0
        for st in s["steps"]:
            forces = [f["force"] for f in st["supports"].values()]
            scale = max(abs(x) for f in forces for x in f)
            total = max(abs(sum(f[i] for f in forces)) for i in range(3))
            worst = max(worst, total / scale)
        last = s["steps"][-1] if s["steps"] else {}
        T.check(worst <= TOL, f"{name} eps1={eps}: supports' forces sum to 0: worst |sum| / max |force| = "
                f"{worst:.2e} (<= {TOL:g}); last step residual_norm {last.get('residual_norm', float('nan')):.2e}")
        if ok:
            runs[eps] = s
    if REF not in runs:
        T.fatal(f"{name}: the reference run (eps1 = {REF}) failed")
    return runs


def values_uniaxial(s):
    f = s["final"]
    v = {}
    for comp in ("xx", "yy"):
        for m in ("min", "max"):
            v[f"stress.{comp}.{m}"] = f["stress"][comp][m]
    for face, d in f["node_displacement_mean"].items():
        for i in range(3):
            v[f"node_displacement_mean.{face}[{'xyz'[i]}]"] = d[i]
    return v


# -- uniaxial: 1e-8 relative, absolute 1e-8 near 0 -----------------------------
runs = sweep("uniaxial.xml")
ref = values_uniaxial(runs[REF])
for eps, s in runs.items():
    if eps == REF:
        continue
    got = values_uniaxial(s)
    worst, worst_key = 0.0, None
    bad = []
    for k, r in ref.items():
        tol = TOL * max(abs(r), 1.0)
        d = abs(got[k] - r)
        if d / max(abs(r), 1.0) > worst:
            worst, worst_key = d / max(abs(r), 1.0), k
        if d > tol:
            bad.append(f"{k} = {got[k]!r} vs {r!r} (diff {d:.2e} > {tol:.1e})")
    T.check(not bad, f"uniaxial eps1={eps} vs {REF}: {len(ref)} figures, worst {worst:.2e} ({worst_key})"
            + ("" if not bad else ": " + "; ".join(bad)))


# -- shear: 1e-8 relative to the largest magnitude of each kind ---------------
def groups_shear(s):
    f = s["final"]
    stress = {}
    for comp in STRESS:
        for m in ("min", "max"):
            stress[f"stress.{comp}.{m}"] = f["stress"][comp][m]
    for m in ("min", "max"):
        stress[f"pressure.{m}"] = f["pressure"][m]
    disp = {f"node_displacement_mean.{face}[{'xyz'[i]}]": d[i]
            for face, d in f["node_displacement_mean"].items() for i in range(3)}
    return {"stress": stress, "displacement": disp}


runs = sweep("shear.xml")
ref = groups_shear(runs[REF])
for eps, s in runs.items():
    if eps == REF:
        continue
    got = groups_shear(s)
    for group, rv in ref.items():
        scale = max(abs(x) for x in rv.values())
        diffs = {k: abs(got[group][k] - r) / scale for k, r in rv.items()}
        k = max(diffs, key=diffs.get)
        T.check(diffs[k] <= TOL,
                f"shear eps1={eps} vs {REF}: {group} ({len(rv)} figures, scale {scale:.3g}): worst {diffs[k]:.2e} "
                f"({k} = {got[group][k]!r} vs {rv[k]!r})")

T.finish()
