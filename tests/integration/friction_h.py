#!/usr/bin/env python3
"""Rolling contact with friction, the study's H cases (formulation.md §6,
inputs/seed/h1.xml ... h5.xml).

  * every scene converges with no step cut and conforms; effects are brick, the foundation, contact and
    friction (each capstan's friction is its own effect); every step of every run is in
    equilibrium: the capstan's force equals the sum of the supports' forces (1e-8 of
    the largest);
  * H1 full-slip balance at every step: the capstan's x force equals the foundation's
    reaction (1e-8 relative), and the integral of the friction traction equals mu times
    the integral of the normal traction (1e-6: friction fully mobilised), every contact
    point slipping;
  * H1 with exact contact, Tanh and Coulomb: contact met to 1e-6 of
    the capstan's radius, friction = mu x normal traction to 1e-8 in steps 2-4 (full slip);
  * H1 (tanh) and H2 (arctan) agree within 1% on the final capstan force and the xmin
    mean displacement;
  * H3: Regularization 1e-15, 1e-9, 1e-3, 1: every run converges, and the final capstan
    force and xmin mean displacement vary by less than 1%;
  * H4 (k = 0.1) and H5 (mu = 0.9), capstan's method (augmented Lagrangian, Coulomb):
    converge with max_penetration below 1e-3 at every step, the friction traction never
    above mu t_n (ratio <= 1 + 1e-8), no NaN; the study's loosened penalties
    (h4-study.xml, h5-study.xml) are run and their penetrations printed beside them;
  * power (summary.json slip_power, the friction dissipation; interface.md "Steady
    rolling"): >= 0 at every step, at most the power the capstan delivers (-torque x
    omega: the rest goes into the body), and equal to it (1e-8) in the steps of steady
    full slip, where the body stands still (H1 steps 2-4 with tanh, H5 steps 3-4 with
    Coulomb); summary.json names its analysis, Quasi-Static.
"""
import os
import sys

sys.dont_write_bytecode = True
sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from capstan_test import Test, has_nan  # noqa: E402

T = Test("friction_h", __doc__)
F = "Capstans/capstan/Friction/"


def run(name, sets=(), tag=None):
    scene = T.input(f"seed/{name}.xml")
    p, s, out = T.run_scene(scene, tag or name, sets=sets)
    if s is None or not s["converged"]:
        T.check(False, f"{tag or name}: converged ({None if s is None else s['failure']!r})")
        return None
    T.conforms(out, scene)
    T.check(not has_nan(s), f"{tag or name}: no NaN in summary.json")
    cuts = sum(st["cutbacks"] for st in s["steps"])
    T.check(cuts == 0, f"{tag or name}: no step cut ({cuts})")
    worst = 0.0
    for st in s["steps"]:
        cap = st["capstans"]["capstan"]["force"]
        sup = [sum(f["force"][i] for f in st["supports"].values()) for i in range(3)]
        scale = max(max(abs(x) for x in cap), max(abs(x) for f in st["supports"].values() for x in f["force"]))
        worst = max(worst, max(abs(a - b) for a, b in zip(cap, sup)) / scale)
    T.check(worst <= 1e-8, f"{tag or name}: capstan force = sum of support forces at every step (worst rel. {worst:.1e})")
    c = s["steps"][-1]["capstans"]["capstan"]
    print(f"    {tag or name:14s} force = [{c['force'][0]:.8f}, {c['force'][1]:.8f}]  "
          f"xmin u_x = {s['final']['node_displacement_mean']['xmin'][0]:.8f}  "
          f"max_penetration = {max(st['capstans']['capstan']['max_penetration'] for st in s['steps']):.3e}  "
          f"stick/slip = {c['stick_points']}/{c['slip_points']}  "
          f"newton = {[st['newton_iterations'] for st in s['steps']]}  wall = {s['timing']['total']:.2f} s")
    return s


OMEGA = 12.5  # the capstan's angular velocity in h1.xml and h5.xml


def check_power(name, s, steady_steps):
    """slip_power against the capstan's power -torque x omega (see the docstring)."""
    T.check(s.get("analysis") == "Quasi-Static", f"{name}: summary.json analysis {s.get('analysis')!r}")
    for st in s["steps"]:
        c = st["capstans"]["capstan"]
        sp, delivered = c["slip_power"], -c["torque"] * OMEGA
        T.check(-1e-12 <= sp <= delivered * (1 + 1e-10),
                f"{name} step {st['step']}: 0 <= slip_power {sp:.10g} <= capstan power {delivered:.10g}")
        if st["step"] in steady_steps:
            T.check(abs(sp - delivered) <= 1e-8 * delivered,
                    f"{name} step {st['step']} (steady full slip): slip_power {sp:.12g} = capstan power {delivered:.12g}")


def final(s):
    return (s["steps"][-1]["capstans"]["capstan"]["force"][0], s["final"]["node_displacement_mean"]["xmin"][0])


h1 = run("h1")
if h1:
    T.check(sorted(h1["effects"]) == ["brick", "contact:capstan", "foundation:foundation", "friction:capstan"],
            f"H1 effects: {sorted(h1['effects'])}")
    for st in h1["steps"]:
        c = st["capstans"]["capstan"]
        fx, rx = c["force"][0], st["supports"]["foundation"]["force"][0]
        T.check(abs(fx - rx) <= 1e-8 * abs(rx), f"H1 step {st['step']}: capstan x force {fx:.12g} = foundation {rx:.12g}")
        fr = c["friction"]
        ratio = fr["traction_integral"] / (0.1 * fr["normal_traction_integral"])
        T.check(abs(ratio - 1) <= 1e-6, f"H1 step {st['step']}: friction integral / (mu x normal integral) = {ratio:.9f}")
        T.check(c["slip_points"] == c["contact_points"] > 0 and c["stick_points"] == 0,
                f"H1 step {st['step']}: all {c['contact_points']} contact points slip ({c['slip_points']})")

if h1:
    check_power("H1", h1, (2, 3, 4))

# H1 with exact contact (augmented Lagrangian), the study's Tanh and Coulomb: no cut,
# contact met to 1e-6 of the capstan's radius, and in full slip friction = mu x normal
# traction to 1e-8. (Arctan saturates only as 1 - 2 eps / (pi v): 2.5e-5 below here.)
for law in ("Tanh", "Coulomb"):
    s = run("h1", ["Capstans/capstan/Contact/Method=Augmented Lagrangian", f"{F}Law={law}"], tag=f"h1 exact {law}")
    if not s:
        continue
    pen = max(st["capstans"]["capstan"]["max_penetration"] for st in s["steps"])
    T.check(pen <= 1e-6 * 2.0, f"H1 exact {law}: max_penetration {pen:.1e} <= 1e-6 R")
    worst = max(abs(st["capstans"]["capstan"]["friction"]["traction_integral"] /
                    (0.1 * st["capstans"]["capstan"]["friction"]["normal_traction_integral"]) - 1)
                for st in s["steps"][1:])
    T.check(worst <= 1e-8, f"H1 exact {law}: friction / (mu x normal) - 1 = {worst:.1e} (<= 1e-8), steps 2-4")

h2 = run("h2")
if h1 and h2:
    (f1, u1), (f2, u2) = final(h1), final(h2)
    T.check(abs(f2 - f1) <= 0.01 * abs(f1) and abs(u2 - u1) <= 0.01 * abs(u1),
            f"H1 vs H2: force x {f1:.6g} vs {f2:.6g}, xmin u_x {u1:.6g} vs {u2:.6g} (1%)")

h3 = {}
for reg in ("1e-15", "1e-9", "1e-3", "1"):
    s = run("h3", [f"{F}Regularization={reg}"], tag=f"h3 reg={reg}")
    if s:
        h3[reg] = final(s)
if len(h3) == 4:
    fs, us = [v[0] for v in h3.values()], [v[1] for v in h3.values()]
    T.check((max(fs) - min(fs)) <= 0.01 * max(abs(x) for x in fs) and (max(us) - min(us)) <= 0.01 * max(abs(x) for x in us),
            f"H3: force x in [{min(fs):.8g}, {max(fs):.8g}], xmin u_x in [{min(us):.8g}, {max(us):.8g}] (1%)")

for name in ("h4", "h5"):
    s = run(name)
    study = run(f"{name}-study")
    if s:
        worst = max(st["capstans"]["capstan"]["max_penetration"] for st in s["steps"])
        ratio = max(st["capstans"]["capstan"]["friction"]["max_traction_ratio"] for st in s["steps"])
        T.check(worst < 1e-3, f"{name}: max_penetration {worst:.2e} < 1e-3 at every step")
        T.check(ratio <= 1 + 1e-8, f"{name}: |t_f| / (mu t_n) <= {ratio:.12f} (<= 1 + 1e-8)")
        if name == "h5":
            check_power("H5", s, (3, 4))
    if study:
        pen = max(st["capstans"]["capstan"]["max_penetration"] for st in study["steps"])
        print(f"    {name}-study: the study's loosened penalty lets the capstan in by {pen:.4f} "
              f"({100 * pen / 0.175:.0f}% of the 0.175 indentation)")
T.finish()
