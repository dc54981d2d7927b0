#!/usr/bin/python3
"""What accuracy costs in time: sweep knobs of a base scene, run capstan for every
value, and report each quantity of interest's error against the sweep's reference
together with the run's wall time.

    scripts/study.py SCENE.xml --out DIR --sweep KNOB=V1,V2,... [--sweep ...]
                     [--set PATH=VALUE ...] [--reference-set PATH=VALUE ...] [--face NAME ...]
                     [--columns q1,q2,...] [--capstan build/capstan] [--ranks N]

KNOB is a parameter path of the scene (as for `capstan run --set`), or one of the
shorthands
    mesh=1,2,4          refine Mesh/Cells by these factors (every direction)
    steps=1,2,4         Time/Steps x f, Time/Step Size / f (same end time)
    penalty=...         Contact/Penalty of every capstan
    regularization=...  Friction/Regularization of every capstan
    quadrature=...      Contact/Quadrature of every capstan ("Gauss 2x2", "Nodal", ...)
List a sweep's values from cheapest to most accurate: the last one is its reference,
unless --reference-set gives a reference run (the base scene with those settings, e.g.
"Capstans/capstan/Contact/Method=Augmented Lagrangian" for a penalty sweep). For mesh
sweeps with three or more factors the reference is the Richardson extrapolation of the
three finest, and the observed order of convergence is reported.

Writes DIR/study.csv (one row per run), DIR/study.md (tables per sweep) and
DIR/study.png (error against wall time, log-log, one panel per quantity, one line per
sweep: the Pareto front at a glance). Runs whose summary.json exists in
DIR/runs/<sweep>-<i>/ are reused, so a study can be extended.
"""
import argparse
import csv
import json
import math
import os
import subprocess
import sys
import xml.etree.ElementTree as ET

# Quantities of interest: name -> function(summary) -> float (None if absent).
def _capstan(s, key, index=None):
    caps = s["steps"][-1].get("capstans", {}) if s["steps"] else {}
    if not caps:
        return None
    c = next(iter(caps.values()))
    v = c.get(key)
    if v is None:
        return None
    return v[index] if index is not None else v


def _force_magnitude(s):
    f = _capstan(s, "force")
    return None if f is None else math.sqrt(sum(x * x for x in f))


QUANTITIES = {
    "capstan_force": _force_magnitude,
    "peak_pressure": lambda s: _capstan(s, "peak_pressure"),
    "contact_width": lambda s: _capstan(s, "contact_width"),
    "von_mises_max": lambda s: s["final"]["von_mises"]["max"],
    "sigma_yy_min": lambda s: s["final"]["stress"]["yy"]["min"],
    "max_penetration": lambda s: _capstan(s, "max_penetration"),
    "stick_points": lambda s: _capstan(s, "stick_points"),
    "slip_points": lambda s: _capstan(s, "slip_points"),
    "max_ux": lambda s: s["final"]["max_displacement"][0],
    "max_uy": lambda s: s["final"]["max_displacement"][1],
    "ymax_mean_uy": lambda s: s["final"]["node_displacement_mean"].get("ymax", [None, None])[1],
    "xmin_mean_ux": lambda s: s["final"]["node_displacement_mean"].get("xmin", [None])[0],
}
# Quantities whose error is measured as an absolute value (their exact value is 0).
ABSOLUTE = {"max_penetration"}


def scene_values(scene, overrides):
    """Base values the shorthands need: cells, steps, step size, capstan names (the
    scene's, or the --set overrides')."""
    root = ET.parse(scene).getroot()

    def sub(node, name):
        return next((c for c in node if c.tag == "ParameterList" and c.get("name") == name), None)

    def param(node, name, default=None):
        if node is None:
            return default
        p = next((c for c in node if c.tag == "Parameter" and c.get("name") == name), None)
        return default if p is None else p.get("value")

    cells = [int(x) for x in param(sub(root, "Mesh"), "Cells", "{1,1,1}").strip("{} ").split(",")]
    time = sub(root, "Time")
    caps = sub(root, "Capstans")
    names = [c.get("name") for c in caps if c.tag == "ParameterList"] if caps is not None else []
    steps, dt = int(param(time, "Steps", "1")), float(param(time, "Step Size", "1"))
    for o in overrides:
        path, value = o.split("=", 1)
        if path == "Mesh/Cells":
            cells = [int(x) for x in value.strip("{} ").split(",")]
        elif path == "Time/Steps":
            steps = int(value)
        elif path == "Time/Step Size":
            dt = float(value)
    return cells, steps, dt, names


def settings_for(knob, value, base):
    cells, steps, dt, capstans = base
    if knob == "mesh":
        f = int(value)
        return ["Mesh/Cells={%s}" % ",".join(str(c * f) for c in cells)]
    if knob == "steps":
        f = int(value)
        return [f"Time/Steps={steps * f}", f"Time/Step Size={dt / f!r}"]
    if knob in ("penalty", "regularization", "quadrature"):
        path = {"penalty": "Contact/Penalty", "regularization": "Friction/Regularization",
                "quadrature": "Contact/Quadrature"}[knob]
        return [f"Capstans/{c}/{path}={value}" for c in capstans]
    return [f"{knob}={value}"]


def run(args, tag, sets):
    out = os.path.join(args.out, "runs", tag)
    summary = os.path.join(out, "summary.json")
    if not os.path.isfile(summary):
        cmd = [args.capstan, "run", args.scene, "--output", out, "--quiet"]
        for s in list(args.set) + sets:
            cmd += ["--set", s]
        if args.ranks > 1:
            cmd = ["mpiexec", "--allow-run-as-root", "--oversubscribe", "-n", str(args.ranks)] + cmd
        print(f"  {tag}: {' '.join(sets)}", flush=True)
        p = subprocess.run(cmd, capture_output=True, text=True)
        if p.returncode not in (0, 2):
            sys.exit(f"study: {tag} failed (exit {p.returncode}):\n{p.stderr[-2000:]}")
    with open(summary) as f:
        return json.load(f)


def richardson(q, f):
    """Extrapolated value and observed order p from three values q on meshes refined by
    the factors f (h ~ 1/f): q_i = q* + C f_i^-p. None for p if the differences change sign."""
    d1, d2 = q[1] - q[0], q[2] - q[1]
    if d1 == 0 or d2 == 0 or d1 * d2 < 0:
        return q[2], None
    h = [1.0 / x for x in f]
    ratio = abs(d1 / d2)

    def g(p):  # (h0^p - h1^p) / (h1^p - h2^p) - ratio, increasing in p
        return (h[0] ** p - h[1] ** p) / (h[1] ** p - h[2] ** p) - ratio

    lo, hi = 1e-3, 20.0
    if g(lo) > 0 or g(hi) < 0:
        return q[2], None
    for _ in range(200):
        mid = 0.5 * (lo + hi)
        lo, hi = (mid, hi) if g(mid) < 0 else (lo, mid)
    p = 0.5 * (lo + hi)
    return q[2] + d2 * h[2] ** p / (h[1] ** p - h[2] ** p), p


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("scene")
    ap.add_argument("--out", required=True)
    ap.add_argument("--sweep", action="append", required=True, help="KNOB=V1,V2,...")
    ap.add_argument("--set", action="append", default=[], help="PATH=VALUE for every run")
    ap.add_argument("--reference-set", action="append", default=[],
                    help="PATH=VALUE of a reference run for the sweeps that are not mesh sweeps")
    ap.add_argument("--capstan", default=os.path.join(os.path.dirname(__file__), "..", "build", "capstan"))
    ap.add_argument("--ranks", type=int, default=1)
    ap.add_argument("--no-plot", action="store_true")
    ap.add_argument("--face", action="append", default=[],
                    help="a face whose mean displacement (node_displacement_mean) is a quantity: "
                         "adds <face>_mean_ux, _uy, _uz")
    ap.add_argument("--columns", default="",
                    help="comma-separated quantities for study.md and study.png (default: all that apply)")
    args = ap.parse_args()
    os.makedirs(args.out, exist_ok=True)
    base = scene_values(args.scene, args.set)
    for face in args.face:
        for i, comp in enumerate("xyz"):
            QUANTITIES[f"{face}_mean_u{comp}"] = (
                lambda s, face=face, i=i: s["final"]["node_displacement_mean"].get(face, [None] * 3)[i])
    shown = [c for c in args.columns.split(",") if c]
    for c in shown:
        if c not in QUANTITIES:
            sys.exit(f"study: unknown quantity '{c}' (known: {', '.join(QUANTITIES)})")

    rows, report = [], ["# Study of " + args.scene, ""]
    reference_run = run(args, "reference", args.reference_set) if args.reference_set else None
    for sweep in args.sweep:
        knob, values = sweep.split("=", 1)
        values = [v.strip() for v in values.split(",")]
        name = knob.replace("/", "_").replace(" ", "_")
        runs = [run(args, f"{name}-{i}", settings_for(knob, v, base)) for i, v in enumerate(values)]
        # Reference per quantity: the last run, or Richardson for mesh sweeps.
        ref, order = {}, {}
        for qn, fn in QUANTITIES.items():
            qs = [fn(s) if s["converged"] else None for s in runs]
            if qn in ABSOLUTE:
                ref[qn] = 0.0
            elif reference_run is not None and knob != "mesh":
                ref[qn] = fn(reference_run) if reference_run["converged"] else None
            else:  # the most accurate run that converged
                ref[qn] = next((q for q in reversed(qs) if q is not None), None)
            if ref[qn] is None:
                del ref[qn]
                continue
            if knob == "mesh" and len(qs) >= 3 and None not in qs[-3:] and qn not in ABSOLUTE:
                ref[qn], order[qn] = richardson(qs[-3:], [float(x) for x in values[-3:]])
        report += [f"## Sweep `{knob}` over {', '.join(values)}", "",
                   "reference: " + ("Richardson extrapolation of the three finest meshes" if order
                                    else "the finest mesh" if knob == "mesh"
                                    else "a run with " + ", ".join(args.reference_set) if reference_run
                                    else "the last run"), ""]
        if order:
            report += ["observed order of convergence: " +
                       ", ".join(f"{q} {p:.2f}" for q, p in order.items() if p is not None), ""]
        cols = [q for q in QUANTITIES if q in ref and (not shown or q in shown)]
        report += ["| value | wall s | converged | " + " | ".join(f"{q} (error)" for q in cols) + " |",
                   "|---|---|---|" + "---|" * len(cols)]
        for v, s in zip(values, runs):
            row = {"sweep": knob, "value": v, "wall_seconds": s["timing"]["total"], "converged": s["converged"]}
            cells = []
            for q in cols:
                x = QUANTITIES[q](s) if s["converged"] else None
                err = None
                if x is not None:
                    err = abs(x) if q in ABSOLUTE else abs(x - ref[q]) / max(abs(ref[q]), 1e-300)
                row[q], row[q + "_error"] = x, err
                cells.append("-" if x is None else f"{x:.6g} ({err:.1e})")
            rows.append(row)
            report.append(f"| {v} | {row['wall_seconds']:.2f} | {s['converged']} | " + " | ".join(cells) + " |")
        report.append("")

    fields = ["sweep", "value", "wall_seconds", "converged"]
    for q in QUANTITIES:
        fields += [q, q + "_error"]
    with open(os.path.join(args.out, "study.csv"), "w", newline="") as f:
        w = csv.DictWriter(f, fieldnames=fields)
        w.writeheader()
        for r in rows:
            w.writerow({k: r.get(k) for k in fields})
    with open(os.path.join(args.out, "study.md"), "w") as f:
        f.write("\n".join(report) + "\n")
    print("\n".join(report))
    if not args.no_plot:
        plot(rows, os.path.join(args.out, "study.png"), args.scene, shown)


def plot(rows, path, title, shown=()):
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    qs = [q for q in QUANTITIES if any((r.get(q + "_error") or 0) > 0 for r in rows) and (not shown or q in shown)]
    if not qs:
        return
    n = len(qs)
    cols = min(3, n)
    fig, axes = plt.subplots((n + cols - 1) // cols, cols, figsize=(5 * cols, 4 * ((n + cols - 1) // cols)),
                             squeeze=False)
    for ax, q in zip(axes.flat, qs):
        for sweep in dict.fromkeys(r["sweep"] for r in rows):
            pts = [(r["wall_seconds"], r[q + "_error"], r["value"]) for r in rows
                   if r["sweep"] == sweep and (r.get(q + "_error") or 0) > 0]
            if not pts:
                continue
            ax.loglog([p[0] for p in pts], [p[1] for p in pts], "o-", label=sweep)
            for t, e, v in pts:
                ax.annotate(v, (t, e), fontsize=7, xytext=(3, 3), textcoords="offset points")
        ax.set_title(q)
        ax.set_xlabel("wall time [s]")
        ax.set_ylabel("absolute value" if q in ABSOLUTE else "relative error")
        ax.grid(True, which="both", alpha=0.3)
        ax.legend(fontsize=8)
    for ax in list(axes.flat)[n:]:
        ax.axis("off")
    fig.suptitle(f"Error against wall time: {os.path.basename(title)}")
    fig.tight_layout()
    fig.savefig(path, dpi=110)


if __name__ == "__main__":
    main()
