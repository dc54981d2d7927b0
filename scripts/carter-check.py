#!/usr/bin/python3
"""Carter's 2D rolling-contact check of steady rolling (formulation.md §8, "Analytical
checks") on inputs/carter-roller-steady.xml: a thick coating at small strain, braked at
Q/(mu P) = 0, 0.25, 0.5, 0.75.

    scripts/carter-check.py [--capstan build/capstan] [--scene inputs/carter-roller-steady.xml]
                            [--out out/carter-check] [--ratios 0,0.25,0.5,0.75]
                            [--set PATH=VALUE ...] [--reuse]

Two runs: the free roller (Torque 0), and one brake sweep over the other ratios (evenly
spaced: Torque ramps to the largest at Torque Ramp Time = the last step's time; otherwise
one run per ratio). The brake torque for a ratio q is T = q mu P R_outer (P = |Force|, the
force on the slice; the nominal Q = T / R_outer); the Q reported and used in Carter's
formula is the one measured: |capstan torque| / R_capstan.

Checks (exit 1 if any fails, 2 if a run fails):
 (a) free-rolling creep 1 - speed_ratio(0) below 10% of the largest braked creep;
 (b) braked creep xi = speed_ratio(0) - speed_ratio(Q) within 10% of Carter's
     (mu a / R)(1 - sqrt(1 - Q/(mu P))), a the Hertz half-width sqrt(4 P R / (pi E*)),
     E* = 4G = 8c, 1/R = 1/R_capstan + 1/R_roller;
 (c) a stick zone at the leading edge (s < 0 in nip.csv, where the material enters) whose
     half-width is within 10% of Carter's a sqrt(1 - Q/(mu P)), give or take half a node
     spacing of the nip (the stick/slip boundary is only known to lie between two nodes).
     Measured: from the leading contact edge (a fit of p^2 = quadratic in s over the
     contact nodes, Hertz's ellipse) to the midpoint between the last sticking node of the
     run that starts at the leading edge and the first slipping one, halved.
The measured contact half-width (the p^2 fit, and half the nodes' extent) is reported
beside Hertz's. Writes carter.md (the table), carter.png (creep vs Q/(mu P) with Carter's
curve, and the shear traction against Carter's) and carter.json to --out.
"""
import argparse
import csv
import json
import math
import os
import subprocess
import sys
import time
import xml.etree.ElementTree as ET

import numpy as np

REPO = os.path.abspath(os.path.join(os.path.dirname(os.path.abspath(__file__)), ".."))
TOL_CREEP = 0.10       # (b): relative error of the braked creep
TOL_FREE = 0.10        # (a): free creep over the largest braked creep
TOL_STICK = 0.10       # (c): relative error of the stick half-width (plus half a node spacing)

ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
ap.add_argument("--capstan", default=os.path.join(REPO, "build", "capstan"))
ap.add_argument("--scene", default=os.path.join(REPO, "inputs", "carter-roller-steady.xml"))
ap.add_argument("--out", default="out/carter-check")
ap.add_argument("--ratios", default="0,0.25,0.5,0.75", help="Q/(mu P) values; must include 0")
ap.add_argument("--set", action="append", default=[], metavar="PATH=VALUE",
                help="extra scene overrides passed to every run (e.g. Mesh/Cells={48,1000,1})")
ap.add_argument("--reuse", action="store_true", help="reuse runs whose summary.json exists")
args = ap.parse_args()

ratios = sorted(float(r) for r in args.ratios.split(","))
if ratios[0] != 0:
    sys.exit("--ratios must include 0 (the free-rolling reference)")
braked = ratios[1:]

# ------------------------------------------------------------------ scene parameters
overrides = {}
for s in args.set:
    path, _, value = s.partition("=")
    overrides[path.strip()] = value.strip()


def param(path, default=None):
    """A parameter of the scene by its path of sublist names, --set overrides first."""
    if path in overrides:
        text = overrides[path]
    else:
        node = ET.parse(args.scene).getroot()
        *lists, name = path.split("/")
        for sub in lists:
            node = next((n for n in node.findall("ParameterList") if n.get("name") == sub), None)
            if node is None:
                break
        p = None if node is None else next((n for n in node.findall("Parameter") if n.get("name") == name), None)
        if p is None:
            if default is None:
                sys.exit(f"{args.scene}: no parameter {path}")
            return default
        text = p.get("value")
    text = text.strip()
    if text.startswith("{"):
        return [float(v) for v in text.strip("{}").split(",")]
    return float(text)


c = param("Material/c")
G = 2 * c
E_star = 4 * G
r_outer = param("Mesh/Outer Radius")
r_inner = param("Mesh/Inner Radius")
length = param("Mesh/Length")
cells = [int(v) for v in param("Mesh/Cells")]
r_capstan = param("Capstans/capstan/Radius")
mu = param("Capstans/capstan/Friction/Coefficient")
force = param("Supports/core/Force")
step_size = param("Time/Step Size")
F = math.sqrt(sum(f * f for f in force))       # on the slice
P = F / length                                   # per unit length
R = 1 / (1 / r_capstan + 1 / r_outer)
a = math.sqrt(4 * P * R / (math.pi * E_star))
p0 = 2 * P / (math.pi * a)
creep_scale = mu * a / R


def carter_creep(q):
    return creep_scale * (1 - math.sqrt(max(0.0, 1 - q)))


# ------------------------------------------------------------------ runs
os.makedirs(args.out, exist_ok=True)
walls = {}


def run(name, sets):
    out = os.path.join(args.out, "runs", name)
    summary = os.path.join(out, "summary.json")
    if not (args.reuse and os.path.isfile(summary)):
        cmd = [args.capstan, "run", args.scene, "--output", out, "--quiet"]
        for s in list(sets) + args.set:
            cmd += ["--set", s]
        print("$ " + " ".join(f'"{c}"' if " " in c else c for c in cmd), flush=True)
        t = time.time()
        rc = subprocess.run(cmd).returncode
        walls[name] = time.time() - t
        if rc != 0:
            print(f"run {name} failed (exit {rc})")
            sys.exit(2)
    with open(summary) as f:
        s = json.load(f)
    walls.setdefault(name, s["timing"]["total"])
    rows = []
    with open(os.path.join(out, "nip.csv")) as f:
        for r in csv.DictReader(f):
            rows.append(r)
    return s, rows


def torque(q):
    return q * mu * F * r_outer


results = {}   # q -> (step record, nip rows of that step, run name)
s, rows = run("free", ["Supports/core/Torque=0", "Time/Steps=1"])
results[0.0] = (s["steps"][0], [r for r in rows if int(r["step"]) == 1], "free")
n = len(braked)
even = n > 0 and all(abs(q - (i + 1) * braked[0]) < 1e-9 for i, q in enumerate(braked))
if even:
    s, rows = run("sweep", [f"Supports/core/Torque={torque(braked[-1]):.9g}",
                            f"Supports/core/Torque Ramp Time={n * step_size:.9g}", f"Time/Steps={n}"])
    for i, q in enumerate(braked):
        results[q] = (s["steps"][i], [r for r in rows if int(r["step"]) == i + 1], "sweep")
else:
    for q in braked:
        s, rows = run(f"q{q:g}", [f"Supports/core/Torque={torque(q):.9g}", "Time/Steps=1"])
        results[q] = (s["steps"][0], [r for r in rows if int(r["step"]) == 1], f"q{q:g}")


# ------------------------------------------------------------------ nip analysis
def nip(rows):
    """Contact nodes of one z (the first), deduplicated, sorted by s: s, p, shear, stick."""
    zs = sorted({float(r["z"]) for r in rows})
    pts = {}
    for r in rows:
        if float(r["z"]) != zs[0]:
            continue
        k = round(float(r["s"]), 9)
        pts.setdefault(k, []).append(r)
    s = np.array(sorted(pts))
    p = np.array([float(pts[k][0]["pressure"]) for k in sorted(pts)])
    t = np.array([float(pts[k][0]["shear"]) for k in sorted(pts)])
    stick = np.array([all(r["state"] == "stick" for r in pts[k]) for k in sorted(pts)])
    return s, p, t, stick


def measure(rows):
    s, p, t, stick = nip(rows)
    h = float(np.median(np.diff(s)))
    # Hertz's ellipse: p^2 = c0 + c1 s + c2 s^2, c2 < 0.
    c2, c1, c0 = np.polyfit(s, p * p, 2)
    centre = -c1 / (2 * c2)
    half = math.sqrt(max(0.0, centre * centre - c0 / c2))
    lead = centre - half
    # The stick run that starts at the leading edge (allow the first node to slip: p -> 0 there).
    i0 = 0 if stick[0] else (1 if len(stick) > 1 and stick[1] else None)
    if i0 is None:
        stick_half, at_lead, i1 = 0.0, False, -1
    else:
        i1 = i0
        while i1 + 1 < len(s) and stick[i1 + 1]:
            i1 += 1
        boundary = s[i1] + h / 2 if i1 + 1 == len(s) else (s[i1] + s[i1 + 1]) / 2
        stick_half = (boundary - lead) / 2
        at_lead = True
    others = int(stick.sum()) - (i1 - i0 + 1 if i0 is not None else 0)   # stick nodes elsewhere
    return dict(h=h, a_fit=half, centre=centre, a_extent=(s[-1] - s[0]) / 2, stick_half=stick_half,
                at_lead=at_lead, stray_stick=others, nodes=len(s), stick_nodes=int(stick.sum()),
                s=s, p=p, t=t, stick=stick)


sr0 = results[0.0][0]["supports"]["core"]["speed_ratio"]
table = []
for q in ratios:
    st, rows, name = results[q]
    core, cap = st["supports"]["core"], st["capstans"]["capstan"]
    Q = abs(cap["torque"]) / r_capstan / length
    qm = Q / (mu * P)
    m = measure(rows)
    xi = sr0 - core["speed_ratio"]
    xc = carter_creep(qm)
    c_carter = a * math.sqrt(max(0.0, 1 - qm))
    table.append(dict(q=q, q_measured=qm, speed_ratio=core["speed_ratio"], omega=core["angular_velocity"],
                      brake=core["torque"], xi=xi, xi_carter=xc, xi_error=(xi - xc) / xc if q > 0 else None,
                      stick_half=m["stick_half"], stick_carter=c_carter,
                      stick_error=(m["stick_half"] - c_carter) / c_carter if c_carter > 0 else None,
                      stick_at_lead=m["at_lead"], stray_stick=m["stray_stick"], h=m["h"],
                      a_fit=m["a_fit"], a_extent=m["a_extent"], width=cap["contact_width"],
                      peak=cap["peak_pressure"], nodes=m["nodes"], stick_nodes=m["stick_nodes"],
                      slip_power=cap["slip_power"], run=name, _m=m))

free_creep = 1 - sr0
max_xi = max((r["xi"] for r in table if r["q"] > 0), default=0.0)
checks = []
checks.append(("(a) free creep 1 - SR(0) < 10% of the largest braked creep",
               abs(free_creep) < TOL_FREE * max_xi, f"{free_creep:.3e} vs {TOL_FREE * max_xi:.3e}"))
for r in table:
    if r["q"] > 0:
        checks.append((f"(b) creep at Q/(mu P) = {r['q']:g} within 10% of Carter",
                       abs(r["xi_error"]) <= TOL_CREEP, f"{r['xi_error']:+.1%}"))
for r in table:
    ok = (r["stick_at_lead"] and r["stray_stick"] == 0 and
          abs(r["stick_half"] - r["stick_carter"]) <= TOL_STICK * r["stick_carter"] + r["h"] / 2)
    checks.append((f"(c) stick zone at Q/(mu P) = {r['q']:g}: at the leading edge, half-width within "
                   f"10% (+ h/2) of Carter", ok,
                   f"{r['stick_half']:.4f} vs {r['stick_carter']:.4f} ({r['stick_error']:+.1%}), h/2 = {r['h'] / 2:.4f}"
                   + ("" if r["stick_at_lead"] else ", not at the leading edge")
                   + (f", {r['stray_stick']} stick nodes elsewhere" if r["stray_stick"] else "")))

# ------------------------------------------------------------------ report
head = (f"Scene {os.path.relpath(args.scene, REPO) if args.scene.startswith(REPO) else args.scene}"
        + (f" with {' '.join(args.set)}" if args.set else "") + "\n\n"
        f"G = {G:g}, R_roller = {r_outer:g} (coating {r_outer - r_inner:g} = {(r_outer - r_inner) / a:.1f} a), "
        f"R_capstan = {r_capstan:g}, R = {R:.4g}, P = {P:.6g}, mu = {mu:g}; Hertz a = {a:.5g}, "
        f"p0 = {p0:.4g} = {p0 / G:.3f} G, mu a / R = {creep_scale:.5g}; mesh {cells[0]}x{cells[1]}x{cells[2]}, "
        f"nip node spacing h = {table[0]['h']:.4g} = a/{a / table[0]['h']:.1f}\n")
lines = ["| Q/(mu P) nominal | Q/(mu P) measured | speed ratio | creep xi | Carter xi | error | "
         "stick half-width | Carter a sqrt(1-Q/muP) | error | contact half-width (p^2 fit) | half nodes' extent | "
         "Hertz a | peak p / p0 |",
         "|---|---|---|---|---|---|---|---|---|---|---|---|---|"]
for r in table:
    xi_err = f"{r['xi_error']:+.1%}" if r["xi_error"] is not None else "-"
    lines.append(f"| {r['q']:g} | {r['q_measured']:.4f} | {r['speed_ratio']:.6f} | {r['xi']:.5f} | "
                 f"{r['xi_carter']:.5f} | {xi_err} | {r['stick_half']:.4f} | {r['stick_carter']:.4f} | "
                 f"{r['stick_error']:+.1%} | {r['a_fit']:.4f} | {r['a_extent']:.4f} | {a:.4f} | {r['peak'] / p0:.4f} |")
check_lines = [f"- {'PASS' if ok else 'FAIL'} {name}: {detail}" for name, ok, detail in checks]
wall_lines = [f"- run {k}: {v:.1f} s" for k, v in walls.items()]
report = (head + "\n" + "\n".join(lines) + "\n\nFree-rolling creep 1 - SR(0) = "
          f"{free_creep:.3e}\n\n" + "\n".join(check_lines) + "\n\nWall times:\n" + "\n".join(wall_lines) + "\n")
print()
print(report)
with open(os.path.join(args.out, "carter.md"), "w") as f:
    f.write(report)
with open(os.path.join(args.out, "carter.json"), "w") as f:
    json.dump(dict(a_hertz=a, R=R, P=P, mu=mu, G=G, p0=p0, free_creep=free_creep, walls=walls,
                   rows=[{k: v for k, v in r.items() if not k.startswith("_")} for r in table],
                   checks=[dict(name=n, ok=bool(ok), detail=d) for n, ok, d in checks]), f, indent=1)

try:
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    fig, (ax1, ax2) = plt.subplots(1, 2, figsize=(12, 4.5))
    qq = np.linspace(0, 1, 201)
    ax1.plot(qq, [carter_creep(v) for v in qq], "k-", label="Carter, Hertz a")
    ax1.plot([r["q_measured"] for r in table], [r["xi"] for r in table], "ro", label="capstan steady rolling")
    ax1.set_xlabel("Q / (mu P)")
    ax1.set_ylabel("creep xi = SR(0) - SR(Q)")
    ax1.set_title("Braked creep")
    ax1.legend()
    ax1.grid(alpha=0.3)
    for i, r in enumerate(table):
        m, qm = r["_m"], r["q_measured"]
        col = f"C{i}"
        ax2.plot(m["s"] / a, m["t"] / (mu * p0), "o", ms=3, color=col, label=f"Q/muP = {qm:.2f}")
        x = np.linspace(-1, 1, 401)
        cc = math.sqrt(max(0.0, 1 - qm))
        tc = np.sqrt(np.clip(1 - x * x, 0, None)) - cc * np.sqrt(np.clip(1 - ((x + 1 - cc) / cc) ** 2, 0, None)) \
            if cc > 0 else np.sqrt(np.clip(1 - x * x, 0, None))
        ax2.plot(x, tc, "-", color=col, lw=1)
    ax2.set_xlabel("s / a (material enters at s < 0)")
    ax2.set_ylabel("shear / (mu p0)")
    ax2.set_title("Shear traction: nodes vs Carter (lines)")
    ax2.legend(fontsize=8)
    ax2.grid(alpha=0.3)
    fig.tight_layout()
    fig.savefig(os.path.join(args.out, "carter.png"), dpi=120)
except ImportError:
    print("matplotlib missing: no carter.png")

sys.exit(0 if all(ok for _, ok, _ in checks) else 1)
