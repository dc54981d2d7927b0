#!/usr/bin/env python3
"""inputs/uniaxial.xml against the exact homogeneous solution.

A 2 x 1 x 1 block on symmetry rollers (xmin, ymin, zmin), xmax pulled along x to
lambda = 1.5 in 5 steps, c = 1. Incompressible neo-Hookean, uniaxial stress:
    sigma_xx = 2c (lambda^2 - 1/lambda), every other stress component 0,
    lateral stretch 1/sqrt(lambda), det F = 1,
    pull force = sigma_xx x current cross-section (A0 / lambda), xsym = -pull.
Q1P0 bricks reproduce this homogeneous state exactly, so the tolerances are 1e-8.
"""
import math
import os
import sys

sys.dont_write_bytecode = True  # nothing written into the source tree
sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from capstan_test import STRESS, SceneInfo, Test, has_nan, read_fields, rel_diff  # noqa: E402

T = Test("uniaxial", __doc__)
scene = T.input("uniaxial.xml")
info = SceneInfo(scene)

lo, hi = info.vector("Mesh/Min"), info.vector("Mesh/Max")
L = [h - l for h, l in zip(hi, lo)]
c = info.number("Material/c")
steps = int(info.number("Time/Steps"))
dt = info.number("Time/Step Size")
v = info.vector("Supports/pull/Velocity")[0]
lam_final = 1 + v * steps * dt / L[0]
print(f"  scene: box {L}, c = {c}, {steps} steps of {dt}, pull velocity {v} -> lambda = {lam_final}")
T.check(abs(lam_final - 1.5) < 1e-14 and c == 1.0 and steps == 5,
        f"scene is the documented one: lambda = {lam_final} (1.5), c = {c} (1), steps = {steps} (5)")


def sigma(lam):
    return 2 * c * (lam * lam - 1 / lam)


p, s, out = T.run_scene(scene, "run")
if s is None:
    T.fatal("no summary.json")
T.conforms(out, scene)
T.check(s["converged"] is True and s["failure"] is None, f"converged = {s['converged']}, failure = {s['failure']!r}")
T.check(s["ranks"] == 1, f"ranks = {s['ranks']} (1)")
T.check(len(s["steps"]) == steps, f"{len(s['steps'])} steps reported ({steps})")
T.check(not has_nan(s), "no NaN or infinity in summary.json")

lam = lam_final
sxx = sigma(lam)
fin = s["final"]
print(f"  exact: sigma_xx = 2c(lambda^2 - 1/lambda) = {sxx!r}")
for m in ("min", "max"):
    got = fin["stress"]["xx"][m]
    T.check(rel_diff(got, sxx) <= 1e-8,
            f"final.stress.xx.{m} = {got!r}, exact {sxx!r}, rel. error {rel_diff(got, sxx):.2e} (<= 1e-8)")
for comp in STRESS[1:]:
    for m in ("min", "max"):
        got = fin["stress"][comp][m]
        T.check(abs(got) < 1e-8 * sxx, f"final.stress.{comp}.{m} = {got:.3e}, |.| < 1e-8 sigma_xx = {1e-8 * sxx:.3e}")
# Pressure: sigma_yy = -p + 2c(1/lambda - 1) = 0.
p_exact = 2 * c * (1 / lam - 1)
for m in ("min", "max"):
    got = fin["pressure"][m]
    T.check(abs(got - p_exact) <= 1e-8 * sxx,
            f"final.pressure.{m} = {got!r}, exact 2c(1/lambda - 1) = {p_exact!r}, diff {abs(got - p_exact):.2e}")
for m in ("min", "max"):
    got = fin["von_mises"][m]
    T.check(rel_diff(got, sxx) <= 1e-8, f"final.von_mises.{m} = {got!r} = sigma_xx (rel. {rel_diff(got, sxx):.2e})")
T.check(fin["max_abs_volume_change"] < 1e-10,
        f"final.max_abs_volume_change = {fin['max_abs_volume_change']:.3e} (< 1e-10)")

# Face means of the displacement.
means = fin["node_displacement_mean"]
ux = (lam - 1) * L[0]
lat = 1 / math.sqrt(lam) - 1
T.check(abs(means["xmax"][0] - ux) <= 1e-12, f"xmax mean u_x = {means['xmax'][0]!r} (exact {ux!r})")
T.check(abs(means["xmin"][0]) <= 1e-12, f"xmin mean u_x = {means['xmin'][0]!r} (0)")
for face, i in (("ymax", 1), ("zmax", 2)):
    exact = lat * L[i]
    got = means[face][i]
    T.check(rel_diff(got, exact) <= 1e-8,
            f"{face} mean u_{'xyz'[i]} = {got!r}, exact (1/sqrt(lambda) - 1) L = {exact!r}, rel. {rel_diff(got, exact):.2e}")
md = fin["max_displacement"]
for i, exact in enumerate((ux, abs(lat) * L[1], abs(lat) * L[2])):
    T.check(rel_diff(md[i], exact) <= 1e-8, f"final.max_displacement[{i}] = {md[i]!r} (exact {exact!r})")

# Reactions, every step: lambda_n = 1 + v t_n / Lx.
A0 = L[1] * L[2]
for st in s["steps"]:
    ln = 1 + v * st["time"] / L[0]
    F = sigma(ln) * A0 / ln
    sup = st["supports"]
    pull, xsym = sup["pull"]["force"], sup["xsym"]["force"]
    T.check(rel_diff(pull[0], F) <= 1e-8,
            f"step {st['step']} (lambda {ln:.3f}): pull force x = {pull[0]!r}, sigma_xx A0/lambda = {F!r}, "
            f"rel. {rel_diff(pull[0], F):.2e}")
    T.check(rel_diff(xsym[0], -pull[0], abs(F)) <= 1e-8,
            f"step {st['step']}: xsym force x = {xsym[0]!r} = -pull (rel. {rel_diff(xsym[0], -pull[0], abs(F)):.2e})")
    others = [pull[1], pull[2], xsym[1], xsym[2], sup["ysym"]["force"][0], sup["ysym"]["force"][1],
              sup["ysym"]["force"][2], sup["zsym"]["force"][0], sup["zsym"]["force"][1], sup["zsym"]["force"][2]]
    worst = max(abs(x) for x in others)
    T.check(worst <= 1e-8 * abs(F), f"step {st['step']}: other reaction components max |.| = {worst:.2e} (<= 1e-8 F)")

# The displacement field is the homogeneous one at every node.
try:
    import numpy as np
    fields = read_fields(os.path.join(out, "fields.h5"))
except Exception as e:  # noqa: BLE001
    T.fatal(f"cannot read fields.h5: {e}")
last = fields[max(fields)]
X, u = last["X"] - np.array(lo), last["u"]
exact = np.stack([(lam - 1) * X[:, 0], lat * X[:, 1], lat * X[:, 2]], axis=1)
err = np.abs(u - exact).max() / np.abs(exact).max()
T.check(err <= 1e-8, f"fields.h5 step {max(fields)}: nodal displacement vs homogeneous field, max rel. error {err:.2e}")
st = last["stress"]
err = max(np.abs(st[:, 0] - sxx).max(), np.abs(st[:, 1:]).max()) / sxx
T.check(err <= 1e-8, f"fields.h5 step {max(fields)}: element stresses vs exact, max rel. error {err:.2e}")

T.finish()
