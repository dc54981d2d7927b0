#!/usr/bin/python3
"""Mesh phase of the steady brake slice: how the steady speed ratio depends on where the
mesh's nodes sit relative to the nip (docs/steady-rolling.md).

The steady scene inputs/pinch-roller-braked-steady.xml puts a fine sector of the annulus
(Mesh/Fine Sector = {-65, 60, 0.6}) over the nip at -90 degrees. The generator (src/mesh.cpp)
puts m = lround(0.6 nt) of the nt circumferential cells in the sector, each 60/m degrees wide,
and every node angle follows the sector's centre: moving the centre by d rotates the whole
mesh by d. Phase j/K moves the centre by -j/K of one fine cell (j = 0 .. K-1), so the nodes
in the nip take K positions between two neighbours; phase 0 is the shipped mesh. For each
mesh and brake torque M (M = 0: the free roller) the script runs the steady state at every
phase and prints, per mesh, the phase spread of the speed ratio against the quasi-static
reference (whose time average is over all phases as the mesh rolls through the nip), and
plots speed ratio against phase, one panel per mesh.

  scripts/steady-phase.py [--capstan build/capstan] [--out out/steady-phase] [--phases 8]
      [--meshes 4x64,8x128] [--torques 0,0.15,0.3,0.6,1.0] [--png docs/img/steady-phase.png]
"""
import argparse
import csv
import math
import os
import sys

from capstan_runs import ROOT, SECTOR, fine_cell, pyplot, run_scene, save_png, turned_sector

SCENE = "pinch-roller-braked-steady.xml"
# Quasi-static reference: the mean speed ratio over the second half of a transient run of the
# slice (the mesh rolls through the nip, so the mean is over all phases). 4x64x1: the brake
# table of docs/pinch-roller.md (free: its refinement table); 8x128x1: the free roller from
# the refinement table of docs/pinch-roller.md, the brakes from the quasi-static column of
# the steady-against-quasi-static table in docs/steady-rolling.md.
QS = {"4x64": {0.0: 0.98961, 0.15: 0.98357, 0.3: 0.97809, 0.6: 0.96714, 1.0: 0.93633},
      "8x128": {0.0: 0.99125, 0.15: 0.98493, 0.3: 0.97713, 0.6: 0.96048, 1.0: 0.93190}}


def steady(capstan, out, cells, torque, sector):
    """One steady run at `torque` (two steps, the torque ramped over them): (exit status,
    speed ratio of the last step or nan, Newton iterations per step)."""
    sets = ["Mesh/Cells={%d, %d, 1}" % cells,
            sector,
            f"Supports/core/Torque={torque:g}", "Supports/core/Torque Ramp Time=0.002",
            "Time/Steps=2"]
    stale = os.path.join(out, "summary.json")
    if os.path.isfile(stale):  # run_scene would read it back if this run writes none
        os.remove(stale)
    rc, _, s = run_scene(capstan, SCENE, out, sets)
    if s is None or not s["steps"]:
        return rc, float("nan"), []
    ratio = s["steps"][-1]["supports"]["core"].get("speed_ratio", float("nan"))
    return rc, ratio, [st["newton_iterations"] for st in s["steps"]]


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--capstan", default=os.path.join(ROOT, "build", "capstan"))
    ap.add_argument("--out", default=os.path.join(ROOT, "out", "steady-phase"))
    ap.add_argument("--phases", type=int, default=8, help="phases per fine cell (default 8)")
    ap.add_argument("--meshes", default="4x64,8x128", help="radial x circumferential cells")
    ap.add_argument("--torques", default="0,0.15,0.3,0.6,1.0", help="brake torques, N mm/mm")
    ap.add_argument("--png", default=os.path.join(ROOT, "docs", "img", "steady-phase.png"))
    a = ap.parse_args()
    meshes = [m.strip() for m in a.meshes.split(",")]
    torques = [float(t) for t in a.torques.split(",")]
    phases = [j / a.phases for j in range(a.phases)]
    os.makedirs(a.out, exist_ok=True)
    rows, failed = [], []
    for mesh in meshes:
        cells = tuple(int(c) for c in mesh.split("x"))
        m, dtheta = fine_cell(cells[1])
        print(f"{mesh}x1: {m} of {cells[1]} cells in the sector, fine cell {dtheta:.6f} deg, "
              f"coarse cell {(360 - SECTOR[1]) / (cells[1] - m):.6f} deg", flush=True)
        for torque in torques:
            for j, ph in enumerate(phases):
                centre, sector = turned_sector(cells[1], ph)
                out = os.path.join(a.out, mesh, f"M{torque:g}", f"p{j}")
                rc, ratio, newton = steady(a.capstan, out, cells, torque, sector)
                rows.append(dict(mesh=mesh, torque=torque, phase=ph, centre=centre,
                                 exit=rc, speed_ratio=ratio, newton=newton))
                if rc != 0:
                    failed.append(f"{mesh} M={torque:g} phase {ph:g} (centre {centre:.5f}): exit {rc}")
    with open(os.path.join(a.out, "phase.csv"), "w", newline="") as fh:
        w = csv.DictWriter(fh, fieldnames=list(rows[0]))
        w.writeheader()
        w.writerows(rows)

    fmt = lambda x: "n/a" if x is None or math.isnan(x) else f"{x:.5f}"
    dif = lambda x, y: "n/a" if y is None or math.isnan(x) else f"{x - y:+.5f}"
    for mesh in meshes:
        print(f"\n{mesh}x1, {a.phases} phases (speed ratio of the last step; Newton = iterations per run)")
        print("| M | min | max | spread | mean | shipped | QS | shipped-QS | mean-QS | Newton |")
        print("|---|---|---|---|---|---|---|---|---|---|")
        for torque in torques:
            rs = [r for r in rows if r["mesh"] == mesh and r["torque"] == torque]
            v = [r["speed_ratio"] for r in rs if r["exit"] == 0 and not math.isnan(r["speed_ratio"])]
            its = [sum(r["newton"]) for r in rs]
            lo, hi = (min(v), max(v)) if v else (float("nan"),) * 2
            mean = sum(v) / len(v) if v else float("nan")
            ship, qs = rs[0]["speed_ratio"], QS.get(mesh, {}).get(torque)
            print(f"| {torque:g} | {fmt(lo)} | {fmt(hi)} | {hi - lo:.5f} | {fmt(mean)} | {fmt(ship)} | "
                  f"{fmt(qs)} | {dif(ship, qs)} | {dif(mean, qs)} | {min(its)}-{max(its)} |")
    print("\nnon-zero exits: " + ("; ".join(failed) if failed else "none"))

    plt = pyplot()
    fig, axes = plt.subplots(1, len(meshes), figsize=(5.5 * len(meshes), 4.5), squeeze=False)
    for ax, mesh in zip(axes[0], meshes):
        for k, torque in enumerate(torques):
            colour = f"C{k}"
            rs = [r for r in rows if r["mesh"] == mesh and r["torque"] == torque]
            ax.plot([r["phase"] for r in rs], [r["speed_ratio"] for r in rs], "o-", color=colour,
                    label=f"M = {torque:g}")
            if torque in QS.get(mesh, {}):
                ax.axhline(QS[mesh][torque], color=colour, ls="--", lw=1)
        ax.set_title(f"{mesh}x1 steady (dashed: quasi-static)")
        ax.set_xlabel("phase: sector centre moved by -phase fine cells")
        ax.set_ylabel("speed ratio")
        ax.grid(alpha=0.3)
    fig.legend(*axes[0][0].get_legend_handles_labels(), loc="center right", fontsize=9)
    fig.tight_layout(rect=(0, 0, 1 - 0.9 / fig.get_figwidth(), 1))
    save_png(fig, a.png, dpi=150)
    return 1 if failed else 0


if __name__ == "__main__":
    sys.exit(main())
