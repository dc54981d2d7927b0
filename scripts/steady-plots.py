#!/usr/bin/python3
"""Plots and a table of a steady-rolling run (interface.md "Steady rolling", formulation.md §8):

    scripts/steady-plots.py RUN_DIR [--scene SCENE.xml] [--step N] [--capstan NAME] [--out DIR]

Reads RUN_DIR/summary.json and RUN_DIR/nip.csv and writes into --out (default RUN_DIR):

- nip.png: contact pressure, friction shear (traction on the body along the rolling
  direction) and slip rate against s, the arc length on the capstan from the line of
  centres (positive along the capstan's surface motion: material enters at s < 0), for
  one step (--step, default the last); stick and slip points marked apart, the Coulomb
  bound +-mu p, and the thick-coating references where the scene gives what they need:
  Hertz's p0 sqrt(1 - (s/a)^2) (E* = 4G = 8c, 1/R = 1/R_capstan + 1/R_roller,
  P = |Force| / Length) and, for a braked step, Carter's traction (full slip mu p minus
  the stick zone's correction over a stick zone of half-width c = a sqrt(1 - Q/(mu P))
  at the leading edge, Q = |brake torque| / (R_roller Length)).
- brake.png (runs whose steps have different core torques): speed ratio, capstan torque
  and slip power against the brake torque, one point per step, with Carter's creep and
  the rigid-radius torque balance as references.
- steady.md: a table per step (also printed).

The scene is --scene, else RUN_DIR/scene.xml (the scene as the run resolved it, --set
overrides included), else summary.json's "scene" looked up near RUN_DIR, the current
directory and the repository's inputs/ (a run from before scene.xml).
Without a scene the references are skipped. nip.csv rows at the same (s, z) (a node's
points on two faces) are averaged; for a 3D run the row nearest mid-length is drawn and
the other z rows in light colour.
"""
import argparse
import csv
import json
import math
import os
import sys
import xml.etree.ElementTree as ET

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402

ROOT = os.path.normpath(os.path.join(os.path.dirname(os.path.abspath(__file__)), ".."))
PERMM = "N mm per mm"


def fail(msg):
    print("steady-plots: " + msg, file=sys.stderr)
    sys.exit(1)


# ---------------------------------------------------------------- scene (Teuchos XML)
def parse_value(typ, text):
    typ = (typ or "string").strip()
    if typ.startswith("Array("):
        inner = text.strip().strip("{}").strip()
        items = [t.strip() for t in inner.split(",")] if inner else []
        base = typ[6:-1]
        return [parse_value(base, t) for t in items]
    if typ in ("double", "float"):
        return float(text)
    if typ in ("int", "long long", "long"):
        return int(text)
    if typ == "bool":
        return text.strip().lower() in ("true", "1", "yes")
    return text


def read_plist(elem):
    d = {}
    for ch in elem:
        if ch.tag == "ParameterList":
            d[ch.get("name")] = read_plist(ch)
        elif ch.tag == "Parameter":
            try:
                d[ch.get("name")] = parse_value(ch.get("type"), ch.get("value", ""))
            except ValueError:
                d[ch.get("name")] = ch.get("value")
    return d


def get(d, *path, default=None):
    for k in path:
        if not isinstance(d, dict) or k not in d:
            return default
        d = d[k]
    return d


def find_scene(run_dir, summary):
    own = os.path.join(run_dir, "scene.xml")  # the run's resolved scene, --set overrides included
    if os.path.isfile(own):
        return own
    ref = summary.get("scene")
    if not ref:
        return None
    cands = [ref] if os.path.isabs(ref) else [
        os.path.join(run_dir, ref), os.path.join(run_dir, "..", ref), ref,
        os.path.join(ROOT, ref), os.path.join(ROOT, "build", ref)]
    cands.append(os.path.join(ROOT, "inputs", os.path.basename(ref)))
    for c in cands:
        if os.path.isfile(c):
            return os.path.normpath(c)
    return None


# ---------------------------------------------------------------- run data
def read_nip(path):
    rows = []
    with open(path, newline="") as f:
        rd = csv.DictReader(f)
        need = {"step", "capstan", "s", "z", "pressure", "shear", "slip_rate", "state"}
        if not rd.fieldnames or not need <= set(rd.fieldnames):
            fail(f"{path}: expected columns {','.join(sorted(need))}, got {rd.fieldnames}")
        for r in rd:
            rows.append((int(r["step"]), r["capstan"], float(r["s"]), float(r["z"]), float(r["pressure"]),
                         float(r["shear"]), float(r["slip_rate"]), r["state"].strip()))
    return rows


def collapse(rows, tol=1e-7):
    """Average rows at the same (s, z); state by majority (a tie counts as slip)."""
    groups = {}
    for (_, _, s, z, p, q, v, st) in rows:
        key = (round(s / tol), round(z / tol))
        groups.setdefault(key, []).append((s, z, p, q, v, st))
    out, mixed = [], 0
    for g in groups.values():
        a = np.array([x[:5] for x in g]).mean(axis=0)
        nslip = sum(1 for x in g if x[5] == "slip")
        if 0 < nslip < len(g):
            mixed += 1
        out.append((*a, nslip * 2 >= len(g)))
    out.sort(key=lambda x: (x[1], x[0]))
    arr = np.array([x[:5] for x in out]) if out else np.zeros((0, 5))
    slip = np.array([x[5] for x in out], dtype=bool)
    return arr, slip, mixed


def core_name(summary, scene):
    sup = get(scene, "Supports", default={}) or {}
    for n, v in sup.items():
        if isinstance(v, dict) and v.get("Type") == "Rigid Core":
            return n
    for st in summary.get("steps", []):
        for n, v in st.get("supports", {}).items():
            if "angular_velocity" in v or "speed_ratio" in v:
                return n
    return None


def ramp(t, t_ramp, t_first):
    tr = t_ramp if t_ramp is not None else t_first
    return 1.0 if not tr or tr <= 0 else min(1.0, t / tr)


# ---------------------------------------------------------------- references
def hertz(P, R, Estar):
    a = math.sqrt(4 * P * R / (math.pi * Estar))
    return a, 2 * P / (math.pi * a)


def carter(s, a, p0, mu, c, sign):
    """Traction on the body: mu p minus the stick zone's correction, stick zone [-a, -a + 2c]."""
    q = mu * p0 * np.sqrt(np.clip(1 - (s / a) ** 2, 0, None))
    s0 = -a + c
    if c > 0:
        inside = np.abs(s - s0) < c
        q = q - np.where(inside, mu * p0 * (c / a) * np.sqrt(np.clip(1 - ((s - s0) / c) ** 2, 0, None)), 0)
    return sign * q


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("run_dir")
    ap.add_argument("--scene", help="the run's scene XML (default: summary.json's 'scene', looked up)")
    ap.add_argument("--step", type=int, default=None, help="step number for the nip plot (default: last)")
    ap.add_argument("--capstan", default=None, help="capstan name (default: the first in summary.json)")
    ap.add_argument("--out", default=None, help="output folder (default: RUN_DIR)")
    args = ap.parse_args()

    run = args.run_dir
    if not os.path.isdir(run):
        fail(f"{run} is not a directory")
    sj, nc = os.path.join(run, "summary.json"), os.path.join(run, "nip.csv")
    missing = [os.path.basename(p) for p in (sj, nc) if not os.path.isfile(p)]
    if missing:
        fail(f"{run} lacks {' and '.join(missing)} (not a steady-rolling output directory?)")
    try:
        with open(sj) as f:
            summary = json.load(f)
    except (OSError, ValueError) as e:
        fail(f"{sj}: cannot read: {e}")
    steps = summary.get("steps") or []
    if not steps:
        fail(f"{sj} has no steps")
    rows = read_nip(nc)
    out = args.out or run
    notes = []

    # Scene.
    scene, scene_path = {}, args.scene
    if scene_path is None:
        scene_path = find_scene(run, summary)
        if scene_path and os.path.basename(scene_path) == "scene.xml" and os.path.dirname(scene_path) == run:
            notes.append(f"scene {scene_path} (the run's own, as it resolved it)")
        elif scene_path:
            notes.append(f"scene {scene_path} (found from summary.json's \"scene\"; --set overrides not seen)")
        else:
            notes.append(f"no scene found (summary.json scene: {summary.get('scene')!r}); pass --scene: "
                         "references (Hertz, Carter, mu) skipped")
    if scene_path:
        if not os.path.isfile(scene_path):
            notes.append(f"scene {scene_path} not found: references skipped")
            scene_path = None
        else:
            scene_path = os.path.abspath(scene_path)
            try:
                scene = read_plist(ET.parse(scene_path).getroot())
                if args.scene:
                    notes.append(f"scene {scene_path}")
            except ET.ParseError as e:
                notes.append(f"scene {scene_path} unreadable ({e}): references skipped")
                scene, scene_path = {}, None
    if scene and summary.get("title") and scene.get("Title") and scene["Title"] != summary["title"]:
        notes.append("warning: the scene's Title differs from summary.json's: is it the run's scene?")

    caps = list(steps[-1].get("capstans", {}).keys())
    cap = args.capstan or (caps[0] if caps else (rows[0][1] if rows else None))
    if cap is None:
        fail("no capstan in summary.json or nip.csv")
    core = core_name(summary, scene)
    capsc = get(scene, "Capstans", cap, default={}) or {}
    mu = get(capsc, "Friction", "Coefficient")
    if scene and mu is None:
        notes.append(f"scene has no Capstans/{cap}/Friction/Coefficient: frictionless, no shear bound")
    Rc = get(capsc, "Radius")
    omc = get(capsc, "Angular Velocity")
    mesh = get(scene, "Mesh", default={}) or {}
    Rr, L = mesh.get("Outer Radius"), mesh.get("Length")
    cmat = get(scene, "Material", "c")
    zs_all = sorted({r[3] for r in rows})
    if L is None:
        if len(zs_all) > 1:
            L = zs_all[-1] - zs_all[0]
            notes.append(f"Length {L:g} mm taken from nip.csv's z range (no scene)")
        else:
            L = 1.0
            notes.append("Length unknown: figures per mm assume Length = 1")
    coresc = get(scene, "Supports", core, default={}) or {}
    Fvec = coresc.get("Force")
    t_first = steps[0].get("time")
    Estar = 8 * cmat if cmat else None
    Rred = 1 / (1 / Rc + 1 / Rr) if (Rc and Rr) else None

    # Per-step figures.
    tab = []
    for st in steps:
        sc = st.get("supports", {}).get(core, {}) if core else {}
        cp = st.get("capstans", {}).get(cap, {})
        T = sc.get("torque")
        if T is not None and abs(T) < 1e-10 * L:
            T = 0.0   # round-off of a free-turning core
        om = sc.get("angular_velocity")
        rec = {"step": st["step"], "time": st.get("time", 0.0), "T": T, "om": om,
               "sr": sc.get("speed_ratio"), "Tc": cp.get("torque"), "D": cp.get("slip_power"),
               "w": cp.get("contact_width"), "pk": cp.get("peak_pressure"),
               "nstick": cp.get("stick_points"), "nslip": cp.get("slip_points")}
        srows = [r for r in rows if r[0] == st["step"] and r[1] == cap]
        arr, slip, _ = collapse(srows)
        if len(arr):
            zz = np.unique(np.round(arr[:, 1], 9))
            zsel = zz[np.argmin(np.abs(zz - 0.5 * (zz[0] + zz[-1])) + 1e-12 * zz)]
            slip = slip[np.abs(arr[:, 1] - zsel) < 1e-7]
        rec["node_stick"], rec["node_slip"] = int((~slip).sum()), int(slip.sum())
        rec["P"] = (math.sqrt(sum(x * x for x in Fvec)) * ramp(rec["time"], coresc.get("Force Ramp Time"), t_first) / L
                    if Fvec else None)
        rec["Q"] = abs(T) / (Rr * L) if (T is not None and Rr) else None
        rec["Q_muP"] = rec["Q"] / (mu * rec["P"]) if (rec["Q"] is not None and mu and rec["P"]) else None
        # power balance: capstan's power in - brake's power out = friction dissipation (§8)
        rec["Dbal"] = (-rec["Tc"] * omc - abs(T * om)) / L if None not in (rec["Tc"], omc, T, om) else None
        tab.append(rec)

    # ------------------------------------------------------------ table
    def f(x, fmt):
        return "-" if x is None else format(x, fmt)

    hdr = ["step", f"brake torque [{PERMM}]", "Q/(mu P)", "speed ratio", f"capstan torque [{PERMM}]",
           "slip power [mW per mm]", "power balance [mW per mm]", "nip width [mm]", "peak p [MPa]",
           "stick/slip points", "stick/slip nodes"]
    lines = []
    for r in tab:
        lines.append([str(r["step"]), f(None if r["T"] is None else r["T"] / L, ".4g"), f(r["Q_muP"], ".3f"),
                      f(r["sr"], ".5f"), f(None if r["Tc"] is None else r["Tc"] / L, ".4g"),
                      f(None if r["D"] is None else r["D"] / L, ".3g"), f(r["Dbal"], ".3g"),
                      f(r["w"], ".4f"), f(r["pk"], ".4f"),
                      f"{f(r['nstick'], 'd')}/{f(r['nslip'], 'd')}", f"{r['node_stick']}/{r['node_slip']}"])
    widths = [max(len(h), *(len(l[i]) for l in lines)) for i, h in enumerate(hdr)]
    md = ["| " + " | ".join(h.ljust(w) for h, w in zip(hdr, widths)) + " |",
          "|" + "|".join("-" * (w + 2) for w in widths) + "|"]
    md += ["| " + " | ".join(c.rjust(w) for c, w in zip(l, widths)) + " |" for l in lines]
    legend = ("brake torque: the core's torque on the body (supports.%s.torque) per mm of length; "
              "Q = |brake torque| / R_roller; power balance = (-capstan torque x capstan omega - "
              "|brake torque x core omega|) per mm, which should equal the slip power in a steady state; "
              "points: contact points in summary.json (a node's points on two faces and at both ends "
              "of a slice count apart); nodes: distinct (s, z) in nip.csv at the plotted z.") % core

    # ------------------------------------------------------------ nip plot
    steps_in_csv = sorted({r[0] for r in rows if r[1] == cap})
    want = args.step if args.step is not None else steps[-1]["step"]
    if want < 0 and steps_in_csv:
        want = steps_in_csv[want] if -want <= len(steps_in_csv) else steps_in_csv[0]
    srec = next((r for r in tab if r["step"] == want), None)
    if srec is None:
        fail(f"step {want} not in summary.json (steps {steps[0]['step']}..{steps[-1]['step']})")
    os.makedirs(out, exist_ok=True)
    nip_png = None
    srows = [r for r in rows if r[0] == want and r[1] == cap]
    if not srows:
        notes.append(f"nip.csv has no contact rows for step {want}, capstan {cap}: no nip plot"
                     + (f" (steps with rows: {steps_in_csv})" if steps_in_csv else ""))
    else:
        arr, slip, mixed = collapse(srows)
        if mixed:
            notes.append(f"step {want}: {mixed} (s, z) points with both stick and slip rows (majority shown)")
        zs = np.unique(np.round(arr[:, 1], 9))
        zmid = 0.5 * (zs[0] + zs[-1])
        zsel = zs[np.argmin(np.abs(zs - zmid) + 1e-12 * zs)]
        main_m = np.abs(arr[:, 1] - zsel) < 1e-7
        others = ~main_m
        if len(zs) == 2:
            # a slice: its two ends should agree
            a0, a1 = arr[arr[:, 1] == zs[0]], arr[arr[:, 1] == zs[1]]
            if len(a0) == len(a1):
                dev = np.abs(a0[np.argsort(a0[:, 0])][:, 2:4] - a1[np.argsort(a1[:, 0])][:, 2:4]).max()
                notes.append(f"z = {zsel:g} shown; the other end z = {zs[zs != zsel][0]:g} differs by "
                             f"at most {dev:.2g} MPa")
            others[:] = False
        m = arr[main_m]
        sl = slip[main_m]
        order = np.argsort(m[:, 0])
        m, sl = m[order], sl[order]
        has_shear = (mu is not None and mu > 0) or (not scene and np.any(np.abs(arr[:, 3]) > 0))
        if scene and mu is None and np.any(np.abs(arr[:, 3]) > 0):
            has_shear = True
            notes.append("nip.csv has shear though the scene names no friction coefficient")

        P, Q = srec["P"], srec["Q"]
        href = None
        if P and Rred and Estar:
            a, p0 = hertz(P, Rred, Estar)
            href = (a, p0)
        elif scene:
            miss = [n for n, v in (("Material/c", cmat), ("Mesh/Outer Radius", Rr),
                                   (f"Capstans/{cap}/Radius", Rc), (f"Supports/{core}/Force", Fvec)) if not v]
            notes.append("no Hertz overlay: scene lacks " + ", ".join(miss))
        braked = Q is not None and mu and P and Q > 1e-9 * mu * P
        sign = 1.0
        if braked and srec["T"] is not None and srec["om"]:
            sign = 1.0 if srec["T"] * srec["om"] < 0 else -1.0   # a brake: the capstan drives (+s)

        npan = 3 if has_shear else 1
        fig, axs = plt.subplots(npan, 1, figsize=(11.5, 3.0 + 2.6 * (npan - 1)), sharex=True,
                                gridspec_kw={"height_ratios": [3, 3, 1.6][:npan]})
        axs = np.atleast_1d(axs)
        ax = axs[0]
        st_kw = dict(marker="o", ls="none", ms=6, color="tab:blue",
                     label=f"stick ({int((~sl).sum())} nodes)" if has_shear else f"contact nodes ({len(sl)})")
        sl_kw = dict(marker="^", ls="none", ms=7, mfc="none", mew=1.5, color="tab:red",
                     label=f"slip ({int(sl.sum())} nodes)")
        light = dict(marker=".", ls="none", ms=3, color="0.75")
        span = max(m[:, 0].max() - m[:, 0].min(), 2 * href[0] if href else 0, 1e-3)
        xs = np.linspace(-0.5 * span - 0.25 * span, 0.5 * span + 0.25 * span, 600)
        if href:
            a, p0 = href
            xs = np.linspace(-1.25 * max(a, np.abs(m[:, 0]).max()), 1.25 * max(a, np.abs(m[:, 0]).max()), 801)
        # pressure
        if others.any():
            ax.plot(arr[others, 0], arr[others, 2], label="other z", **light)
        ax.plot(m[:, 0], m[:, 2], "-", color="0.6", lw=0.8, zorder=1)
        ax.plot(m[~sl, 0], m[~sl, 2], **st_kw)
        if has_shear or sl.any():
            ax.plot(m[sl, 0], m[sl, 2], **sl_kw)
        if href:
            a, p0 = href
            ax.plot(xs, p0 * np.sqrt(np.clip(1 - (xs / a) ** 2, 0, None)), "k--", lw=1.2,
                    label=f"Hertz, thick-coating reference\n(a = {a:.3f} mm, p0 = {p0:.3f} MPa)")
        ax.set_ylabel("contact pressure p [MPa]")
        ax.set_ylim(bottom=0)
        ax.legend(fontsize=8, loc="upper left", bbox_to_anchor=(1.01, 1.0))
        ax.grid(alpha=0.3)
        # shear
        if has_shear:
            bx = axs[1]
            if others.any():
                bx.plot(arr[others, 0], arr[others, 3], **light)
            if mu:
                # the Coulomb bound |q| <= mu p, drawn on the side(s) the shear uses
                ref = 0.1 * mu * m[:, 2].max()
                sides = [sg for sg in (1, -1) if (sg * arr[:, 3]).max() > ref] or [1, -1]
                for i, sg in enumerate(sides):
                    bx.plot(m[:, 0], sg * mu * m[:, 2], ":", color="tab:gray", lw=1.3,
                            label=None if i else ("±" if len(sides) == 2 else ("" if sg > 0 else "-"))
                            + f"mu p, the Coulomb bound (FE p, mu = {mu:g})")
            bx.plot(m[:, 0], m[:, 3], "-", color="0.6", lw=0.8, zorder=1)
            bx.plot(m[~sl, 0], m[~sl, 3], **st_kw)
            bx.plot(m[sl, 0], m[sl, 3], **sl_kw)
            # The stick zone's shear less its node-to-node alternation (the outer elements'
            # Q1P0 pressure checkerboard, held by the sticking nodes: docs/steady-rolling.md).
            fs, ft = [], []
            for i in range(1, len(m) - 1):
                if not (sl[i - 1] or sl[i] or sl[i + 1]):
                    fs.append(m[i, 0]), ft.append(0.25 * (m[i - 1, 3] + 2 * m[i, 3] + m[i + 1, 3]))
            if len(fs) > 1:
                bx.plot(fs, ft, "-", color="tab:blue", lw=1.8, alpha=0.8,
                        label="stick shear, node-to-node alternation\nfiltered out (1/4, 1/2, 1/4)")
            if href and mu:
                a, p0 = href
                if braked:
                    qm = min(Q / (mu * P), 1.0)
                    c = a * math.sqrt(1 - qm)
                    bx.plot(xs, sign * mu * p0 * np.sqrt(np.clip(1 - (xs / a) ** 2, 0, None)), "k:", lw=1,
                            label="Hertz mu p0 sqrt(1-(s/a)^2) (full slip)")
                    bx.plot(xs, carter(xs, a, p0, mu, c, sign), "k--", lw=1.4,
                            label=f"Carter, thick-coating reference\n(Q/(mu P) = {Q / (mu * P):.3f}, c/a = {c / a:.3f})")
                    if c > 0:
                        bx.axvspan(-a, -a + 2 * c, color="tab:green", alpha=0.12,
                                   label="Carter stick zone (leading edge)")
                    if Q > mu * P:
                        notes.append(f"step {want}: Q > mu P: no steady state by Carter")
                else:
                    bx.axhline(0, color="k", ls="--", lw=1.2,
                               label="Carter, thick-coating reference: no shear in free rolling")
            bx.axhline(0, color="0.3", lw=0.5)
            bx.set_ylabel("shear on the body along +s [MPa]")
            bx.legend(fontsize=8, loc="upper left", bbox_to_anchor=(1.01, 1.0))
            bx.grid(alpha=0.3)
            # slip rate
            cx = axs[2]
            if others.any():
                cx.plot(arr[others, 0], arr[others, 4], **light)
            cx.plot(m[:, 0], m[:, 4], "-", color="0.6", lw=0.8, zorder=1)
            cx.plot(m[~sl, 0], m[~sl, 4], **st_kw)
            cx.plot(m[sl, 0], m[sl, 4], **sl_kw)
            cx.axhline(0, color="0.3", lw=0.5)
            cx.set_ylabel("slip rate [mm/s]")
            cx.grid(alpha=0.3)
        last_ax = axs[-1]
        last_ax.set_xlabel("s: arc length on the capstan from the line of centres [mm]  "
                           "(+ along the capstan's surface motion)")
        lo, hi = axs[0].get_xlim()
        for axx in axs:
            axx.axvline(0, color="0.5", lw=0.5, ls="-.")
        axs[0].text(0.01, 0.97, "← leading edge\n(material enters)", transform=axs[0].transAxes,
                    fontsize=8, va="top", ha="left", color="0.3")
        if has_shear:
            axs[2].text(1.01, 0.5, "body's slip on the capstan\n(v_body - v_capstan) along +s",
                        transform=axs[2].transAxes, fontsize=8, va="center", ha="left", color="0.3")
        axs[0].text(0.99, 0.03, "trailing edge →", transform=axs[0].transAxes, fontsize=8, va="bottom",
                    ha="right", color="0.3")
        Ttxt = "" if srec["T"] is None else f", brake torque {srec['T'] / L:.3g} {PERMM}"
        srtxt = "" if srec["sr"] is None else f", speed ratio {srec['sr']:.4f}"
        ztxt = f", z = {zsel:g} mm" if len(zs) > 1 else ""
        fig.suptitle(f"{summary.get('title', run)}\nstep {want}{Ttxt}{srtxt}{ztxt}  —  "
                     f"{int((~sl).sum())} stick, {int(sl.sum())} slip nodes", fontsize=9.5)
        fig.tight_layout()
        nip_png = os.path.join(out, "nip.png")
        fig.savefig(nip_png, dpi=130)
        plt.close(fig)

    # ------------------------------------------------------------ brake plot
    brake_png = None
    Ts = [r["T"] for r in tab if r["T"] is not None]
    if len(Ts) > 1 and (max(Ts) - min(Ts)) > 1e-12 * max(1.0, max(abs(t) for t in Ts)):
        tb = np.array([abs(r["T"]) / L for r in tab if r["T"] is not None])
        sr = np.array([np.nan if r["sr"] is None else r["sr"] for r in tab if r["T"] is not None])
        tc = np.array([np.nan if r["Tc"] is None else r["Tc"] / L for r in tab if r["T"] is not None])
        dd = np.array([np.nan if r["D"] is None else r["D"] / L for r in tab if r["T"] is not None])
        db = np.array([np.nan if r["Dbal"] is None else r["Dbal"] for r in tab if r["T"] is not None])
        sub = [r for r in tab if r["T"] is not None]
        fig, (ax, bx, cx) = plt.subplots(3, 1, figsize=(7.5, 9.0), sharex=True,
                                         gridspec_kw={"height_ratios": [3, 3, 2]})
        ax.plot(tb, sr, "o-", color="tab:blue", label="capstan (steady state per step)")
        for r, x, y in zip(sub, tb, sr):
            ax.annotate(str(r["step"]), (x, y), textcoords="offset points", xytext=(4, 4), fontsize=7, color="0.4")
        P0 = sub[-1]["P"]
        if mu and P0 and Rred and Estar and Rr and np.isfinite(sr[0]):
            a, _ = hertz(P0, Rred, Estar)
            Qs = tb / Rr
            x = np.clip(Qs / (mu * P0), 0, 1)
            xi = mu * a / Rred * (1 - np.sqrt(1 - x))
            free = sr[0] + xi[0]   # anchored at the first step
            tt = np.linspace(0, min(tb.max() * 1.05, mu * P0 * Rr), 200)
            xt = np.clip(tt / Rr / (mu * P0), 0, 1)
            ax.plot(tt, free - mu * a / Rred * (1 - np.sqrt(1 - xt)), "k--", lw=1.2,
                    label=f"Carter creep, thick-coating reference,\nanchored at step {sub[0]['step']} "
                          f"(free-rolling ratio {free:.4f})")
            lim = mu * P0 * Rr
            for axx in (ax, bx, cx):
                axx.axvline(lim, color="tab:red", ls=":", lw=1)
            ax.text(lim, ax.get_ylim()[0], " mu P R_roller", color="tab:red", fontsize=8, rotation=90,
                    va="bottom", ha="right")
        ax.set_ylabel("speed ratio (roller / capstan surface speed)")
        ax.legend(fontsize=8)
        ax.grid(alpha=0.3)
        bx.plot(tb, tc, "s-", color="tab:orange", label="capstan torque (of the body on the capstan)")
        if Rc and Rr:
            tt = np.linspace(0, tb.max() * 1.05, 50)
            sgn = -1.0 if np.nanmedian(tc) < 0 else 1.0
            bx.plot(tt, sgn * tt * Rc / Rr, "k--", lw=1,
                    label=("-" if sgn < 0 else "") + "brake torque x R_capstan / R_roller (rigid radii)")
        bx.set_ylabel(f"capstan torque [{PERMM}]")
        bx.legend(fontsize=8)
        bx.grid(alpha=0.3)
        cx.plot(tb, dd, "o-", color="tab:purple", label="slip power (summary.json)")
        if np.isfinite(db).any():
            cx.plot(tb, db, "x--", color="0.4", label="power balance: -T_capstan ω_capstan - |T_brake ω_core|")
        cx.axhline(0, color="0.3", lw=0.5)
        cx.set_ylabel("friction power [mW per mm]")
        cx.set_xlabel(f"brake torque |T| on the core [{PERMM}]")
        cx.legend(fontsize=8)
        cx.grid(alpha=0.3)
        fig.suptitle(f"{summary.get('title', run)}\nbrake sweep, {len(sub)} steady steps", fontsize=9.5)
        fig.tight_layout()
        brake_png = os.path.join(out, "brake.png")
        fig.savefig(brake_png, dpi=130)
        plt.close(fig)

    # ------------------------------------------------------------ report
    ref_lines = []
    if Rred and Estar and tab[-1]["P"]:
        a, p0 = hertz(tab[-1]["P"], Rred, Estar)
        ref_lines.append(f"thick-coating references (last step): E* = 8c = {Estar:g} MPa, R = {Rred:.4g} mm, "
                         f"P = {tab[-1]['P']:.4g} N per mm, Hertz a = {a:.4g} mm (2a = {2 * a:.4g}), "
                         f"p0 = {p0:.4g} MPa" + (f", mu = {mu:g}, mu P R_roller = {mu * tab[-1]['P'] * Rr:.4g} "
                                                 f"{PERMM}" if mu else ""))
    text = [f"# Steady rolling: {summary.get('title', run)}", "",
            f"run: {os.path.abspath(run)}, capstan {cap}, core {core}", ""] + md + ["", legend, ""]
    text += ["- " + n for n in ref_lines + notes]
    for p in (nip_png, brake_png):
        if p:
            text.append(f"- wrote {p}")
    body = "\n".join(text) + "\n"
    print(body, end="")
    with open(os.path.join(out, "steady.md"), "w") as fmd:
        fmd.write(body)


if __name__ == "__main__":
    main()
