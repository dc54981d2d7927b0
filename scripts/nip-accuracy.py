#!/usr/bin/python3
"""What the pinch roller's speed ratio costs: its error against wall time, steady and
quasi-static, on the 1 mm slice (docs/accuracy.md, "The pinch-roller nip").

    scripts/nip-accuracy.py [--capstan build/capstan] [--out out/nip-accuracy] [--torque 0]
        [--steady 4x64,8x128,16x256,32x512] [--phases 8]
        [--quasi-static 4x64:1,4x64:0.5,4x64:0.25,8x128:1,8x128:0.5,16x256:1] [--window 24]
        [--sector -65,60,0.6] [--set PATH=VALUE ...] [--png docs/img/accuracy-nip.png]

Steady (inputs/pinch-roller-braked-steady.xml at brake torque --torque, 0 = the free
roller): each mesh at --phases mesh phases, the mesh turned by j/phases of one fine cell
(phase 0: the shipped mesh, as scripts/steady-phase.py does). A single steady solve's
answer depends on where the nodes sit against the nip; the mean over the phases is the
quasi-static analysis' time mean, which rolls every phase through the nip.

Quasi-static (inputs/pinch-roller-braked.xml at the same torque): MESH:DT (DT in ms) runs
for twice --window ms of rolling (48 ms: the capstan's surface travels 2.3 mm) and
averages the speed ratio over the last --window ms (the first half starts from rest).

Reference: the Richardson extrapolation of the steady phase means on the three finest
meshes (each refined 2x in both directions), or the finest mean where the three do not
converge monotonically (said in the report). Errors are |speed ratio - reference|; a
steady mesh's "worst phase" is the largest error over its phases, what one solve on an
unluckily placed mesh gives. Wall times are the runs' own (summary.json timing.total);
a phase mean costs the sum of its phases.

--sector sets the steady meshes' fine sector (the quasi-static runs keep the scene's,
which must cover the nip as the mesh rolls). --set adds a scene setting to every run (e.g. the upwind order or a Tanh law, steady only
with --quasi-static ""). Writes OUT/nip-accuracy.csv (one row per run), OUT/nip-accuracy.md and the PNG. Runs
of the same scene and settings whose summary.json exists under OUT are reused.
"""
import argparse
import csv
import json
import math
import os
import sys

from capstan_runs import ROOT, SECTOR, pyplot, run_scene, save_png, turned_sector, write_report

STEADY_SCENE, QS_SCENE = "pinch-roller-braked-steady.xml", "pinch-roller-braked.xml"


def cells_of(mesh):
    radial, circumferential = (int(c) for c in mesh.split("x"))
    return radial, circumferential


def reuse_or_run(capstan, scene, out, sets):
    """(exit status, summary or None): the summary a run of the same scene and settings
    left under `out` (its settings.json says which), else a new run."""
    path, settings = os.path.join(out, "summary.json"), os.path.join(out, "settings.json")
    want = {"scene": scene, "sets": list(sets)}
    if os.path.isfile(path) and os.path.isfile(settings):
        with open(settings) as fh:
            same = json.load(fh) == want
        if same:
            with open(path) as fh:
                return 0, json.load(fh)
    rc, _, s = run_scene(capstan, scene, out, sets)
    if s is not None:
        with open(settings, "w") as fh:
            json.dump(want, fh)
    return rc, s


def steady_runs(a, mesh):
    """Rows of the steady runs of one mesh, one per phase."""
    nr, nt = cells_of(mesh)
    rows = []
    for j in range(a.phases):
        sets = [f"Mesh/Cells={{{nr}, {nt}, 1}}", turned_sector(nt, j / a.phases, a.sector)[1],
                f"Supports/core/Torque={a.torque:g}", "Supports/core/Torque Ramp Time=0.002", "Time/Steps=2"] + a.set
        rc, s = reuse_or_run(a.capstan, STEADY_SCENE, os.path.join(a.out, "steady", mesh, f"p{j}"), sets)
        ok = rc == 0 and s is not None and s["converged"]
        rows.append(dict(analysis="steady", mesh=mesh, dt_ms="", phase=j,
                         speed_ratio=s["steps"][-1]["supports"]["core"]["speed_ratio"] if ok else math.nan,
                         wall_s=s["timing"]["total"] if s else math.nan,
                         newton=sum(st["newton_iterations"] for st in s["steps"]) if s else 0))
    return rows


def quasi_static_run(a, mesh, dt_ms):
    """The row of one quasi-static run: the speed ratio's mean over the last --window ms."""
    nr, nt = cells_of(mesh)
    steps = int(round(2 * a.window / dt_ms))
    sets = [f"Mesh/Cells={{{nr}, {nt}, 1}}", f"Supports/core/Torque={a.torque:g}", f"Time/Steps={steps}",
            f"Time/Step Size={dt_ms * 1e-3:g}"] + a.set
    rc, s = reuse_or_run(a.capstan, QS_SCENE, os.path.join(a.out, "quasi-static", f"{mesh}-dt{dt_ms:g}"), sets)
    ok = rc == 0 and s is not None and s["converged"] and len(s["steps"]) == steps
    late = s["steps"][steps // 2:] if ok else []
    return dict(analysis="quasi-static", mesh=mesh, dt_ms=dt_ms, phase="",
                speed_ratio=sum(st["supports"]["core"]["speed_ratio"] for st in late) / len(late) if ok else math.nan,
                wall_s=s["timing"]["total"] if s else math.nan,
                newton=sum(st["newton_iterations"] for st in s["steps"]) if s else 0)


def reference(means):
    """(reference, how): Richardson on the last three phase means (refinement ratio 2)."""
    if len(means) < 3:
        return means[-1], "the finest phase mean (fewer than three meshes)"
    m1, m2, m3 = means[-3:]
    if (m1 - m2) * (m2 - m3) <= 0 or abs(m1 - m2) <= abs(m2 - m3):
        return m3, "the finest phase mean (the last three do not converge monotonically)"
    order = math.log2((m1 - m2) / (m2 - m3))
    return m3 + (m3 - m2) / (2 ** order - 1), f"Richardson on the three finest phase means (observed order {order:.1f})"


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--capstan", default=os.path.join(ROOT, "build", "capstan"))
    ap.add_argument("--out", default=os.path.join(ROOT, "out", "nip-accuracy"))
    ap.add_argument("--torque", type=float, default=0.0, help="brake torque, N mm per mm (0: free roller)")
    ap.add_argument("--steady", default="4x64,8x128,16x256,32x512")
    ap.add_argument("--phases", type=int, default=8)
    ap.add_argument("--quasi-static", dest="qs", default="4x64:1,4x64:0.5,4x64:0.25,8x128:1,8x128:0.5,16x256:1")
    ap.add_argument("--window", type=float, default=24.0, help="ms of rolling averaged (after as many from rest)")
    ap.add_argument("--sector", default=",".join(f"{x:g}" for x in SECTOR),
                    help="the steady meshes' Mesh/Fine Sector: centre, width (deg), fraction of the cells")
    ap.add_argument("--set", action="append", default=[], help="PATH=VALUE for every run")
    ap.add_argument("--png", default=os.path.join(ROOT, "docs", "img", "accuracy-nip.png"))
    a = ap.parse_args()
    a.sector = tuple(float(x) for x in a.sector.split(","))
    meshes = [m.strip() for m in a.steady.split(",") if m.strip()]
    qs_cases = [(c.split(":")[0], float(c.split(":")[1])) for c in a.qs.split(",") if c.strip()]

    rows = []
    for mesh in meshes:
        print(f"steady {mesh}x1, {a.phases} phases ...", flush=True)
        rows += steady_runs(a, mesh)
    for mesh, dt in qs_cases:
        print(f"quasi-static {mesh}x1, dt {dt:g} ms ...", flush=True)
        rows.append(quasi_static_run(a, mesh, dt))
    failed = [r for r in rows if math.isnan(r["speed_ratio"])]

    def steady_of(mesh):
        return [r for r in rows if r["analysis"] == "steady" and r["mesh"] == mesh]

    means = [sum(r["speed_ratio"] for r in steady_of(m)) / a.phases for m in meshes]
    ref, how = reference(means)
    for r in rows:
        r["error"] = abs(r["speed_ratio"] - ref)
    os.makedirs(a.out, exist_ok=True)
    with open(os.path.join(a.out, "nip-accuracy.csv"), "w", newline="") as fh:
        w = csv.DictWriter(fh, fieldnames=list(rows[0]))
        w.writeheader()
        w.writerows(rows)

    brake = "free roller" if a.torque == 0 else f"brake {a.torque:g} N mm/mm"
    lines = [f"Slice, {brake}. Reference speed ratio {ref:.6f}: {how}.", "",
             "| analysis | mesh | speed ratio | error | worst phase | phase spread | wall s (one solve) | Newton |",
             "|---|---|---|---|---|---|---|---|"]
    steady_points = []
    for mesh, mean in zip(meshes, means):
        rs = steady_of(mesh)
        v = [r["speed_ratio"] for r in rs]
        wall = sorted(r["wall_s"] for r in rs)[len(rs) // 2]
        worst = max(r["error"] for r in rs)
        newton = sorted(r["newton"] for r in rs)[len(rs) // 2]
        lines.append(f"| steady, shipped phase | {mesh}x1 | {v[0]:.5f} | {abs(v[0] - ref):.1e} | {worst:.1e} | "
                     f"{max(v) - min(v):.1e} | {wall:.2f} | {newton} |")
        lines.append(f"| steady, mean of {a.phases} phases | {mesh}x1 | {mean:.5f} | {abs(mean - ref):.1e} | | | "
                     f"{sum(r['wall_s'] for r in rs):.2f} ({a.phases} solves) | |")
        steady_points.append((mesh, wall, abs(v[0] - ref), worst, sum(r["wall_s"] for r in rs), abs(mean - ref)))
    for r in (r for r in rows if r["analysis"] == "quasi-static"):
        lines.append(f"| quasi-static, dt {r['dt_ms']:g} ms | {r['mesh']}x1 | {r['speed_ratio']:.5f} | "
                     f"{r['error']:.1e} | | | {r['wall_s']:.2f} | {r['newton']} |")
    lines += ["", "runs that failed: " + (", ".join(f"{r['analysis']} {r['mesh']} {r['phase']}{r['dt_ms']}"
                                                       for r in failed) if failed else "none")]
    write_report(os.path.join(a.out, "nip-accuracy.md"), lines)

    # Below the last two phase means' difference the reference cannot tell errors apart.
    floor = abs(means[-1] - means[-2]) if len(means) > 1 else 0.0
    plt = pyplot()
    fig, ax = plt.subplots(figsize=(7.5, 5.2))
    ax.loglog([p[1] for p in steady_points], [p[3] for p in steady_points], "o-", color="C0",
              label="steady, one solve: worst of the mesh phases")
    ax.loglog([p[1] for p in steady_points], [p[2] for p in steady_points], "o", color="C0", mfc="none",
              label="steady, one solve: the shipped mesh")
    resolved = [p for p in steady_points if p[5] > 0]  # the reference's own mean is left out
    ax.loglog([p[4] for p in resolved], [p[5] for p in resolved], "s-", color="C2",
              label=f"steady, mean of {a.phases} mesh phases")
    for p in steady_points:
        ax.annotate(p[0], (p[1], p[3]), textcoords="offset points", xytext=(4, 4), fontsize=8, color="C0")
    for p in resolved:
        ax.annotate(p[0], (p[4], p[5]), textcoords="offset points", xytext=(4, -10), fontsize=8, color="C2")
    qs = [r for r in rows if r["analysis"] == "quasi-static" and not math.isnan(r["speed_ratio"])]
    ax.loglog([r["wall_s"] for r in qs], [r["error"] for r in qs], "^", color="C3",
              label=f"quasi-static, mean over {a.window:g} ms")
    for k, r in enumerate(qs):
        ax.annotate(f"{r['mesh']} {r['dt_ms']:g} ms", (r["wall_s"], r["error"]), textcoords="offset points",
                    xytext=(4, 4 if k % 2 == 0 else -10), fontsize=8, color="C3")
    if floor > 0:
        low = ax.get_ylim()[0]
        ax.axhspan(low / 10, floor, color="0.85", zorder=0,
                   label="not resolved: the two finest phase means differ by this")
        ax.set_ylim(bottom=low)
    ax.set_xlabel("wall time (s, 1 rank)")
    ax.set_ylabel(f"|speed ratio - {ref:.5f}|")
    ax.set_title(f"Pinch-roller slice, {brake}: speed ratio error against wall time")
    ax.grid(alpha=0.3, which="both")
    ax.legend(fontsize=8)
    fig.tight_layout()
    save_png(fig, a.png)
    return 1 if failed else 0


if __name__ == "__main__":
    sys.exit(main())
