#!/usr/bin/env python3
"""The performance study scripts run and report what the runs' summaries say.

scripts/scaling.py on G1 1x (1 and 2 ranks) and scripts/speedup.py on G1 1x for
one load step, two rounds (1 rank, 2 ranks with METIS, 2 ranks with Slabs):

  * every run's summary.json conforms to interface.md (check_summary.py --scene);
  * scaling.csv holds the runs' DOFs, Newton and Krylov iterations and total times
    as their summaries give them;
  * speedup.csv has one row per run, each round's 2-rank runs carry their
    partition, and speedup.md states each round's speed-up (1 rank's time over 2
    ranks') and their mean, to the printed 2 decimals;
  * a second call with the same --out reuses the runs (no summary.json rewritten)
    and may add rounds;
  * the PNGs are written.

scripts/nip-accuracy.py on the slice (steady 4x64 and 8x128 at 2 mesh phases, a
12-step quasi-static run):

  * phase 0 is the shipped mesh: its speed ratio is a plain steady run's;
  * the quasi-static figure is the mean over the run's second half, and every error
    in the CSV is |speed ratio - reference| with the reference (two meshes: the finer
    phase mean) stated in the report.

scripts/steady-phases.py on the steady slice (2 phases): phase 0 is the scene's own
mesh, phase 1 another, and phases.csv's mean is the two runs' mean; a scene without a
fine sector is refused.

scripts/stick-shear.py on the steady slice at 8x256: one row in each table, stick faces counted, the
shear's alternation a fraction of mu p_max (rms at most the largest); at the sticking nodes the
shear's alternation follows the jump of the outer elements' pressure across each node (Q1P0's
checkerboard: correlation below -0.95).
"""
import csv
import json
import os
import re
import statistics
import subprocess
import sys

sys.dont_write_bytecode = True
sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from capstan_test import Test  # noqa: E402

T = Test("study_scripts", __doc__)
scripts = os.path.normpath(os.path.join(T.inputs, "..", "scripts"))
g1 = T.input("seed/g1.xml")


def script(name, *args):
    cmd = [sys.executable, os.path.join(scripts, name), "--capstan", T.capstan] + list(args)
    print("  $ " + " ".join(cmd))
    p = subprocess.run(cmd, capture_output=True, text=True, timeout=600,
                       env=dict(os.environ, OMPI_MCA_rmaps_base_oversubscribe="1"))
    T.check(p.returncode == 0, f"{name}: exit status {p.returncode}" +
            ("" if p.returncode == 0 else ": " + (p.stdout[-1500:] + p.stderr[-1500:]).replace("\n", " | ")))
    return p


def summaries(out):
    runs = {}
    for d in sorted(os.listdir(out)):
        path = os.path.join(out, d, "summary.json")
        if os.path.isfile(path):
            with open(path) as fh:
                runs[d] = json.load(fh)
            T.conforms(os.path.join(out, d), g1)
    return runs


# --- scaling.py --------------------------------------------------------------
out = T.path("scaling")
script("scaling.py", "--out", out, "--g1", "1", "--h1", "")
runs = summaries(out)
T.check(sorted(runs) == ["g1-1x-1r", "g1-1x-2r"], f"scaling.py ran {sorted(runs)}")
with open(os.path.join(out, "scaling.csv")) as fh:
    rows = list(csv.DictReader(fh))
for r in rows:
    s = runs.get(f"g1-1x-{r['ranks']}r")
    if s is None:
        continue
    want = (s["mesh"]["dofs"], sum(st["newton_iterations"] for st in s["steps"]),
            sum(st["linear_iterations"] for st in s["steps"]), round(s["timing"]["total"], 2))
    got = (int(r["dofs"]), int(r["newton"]), int(r["linear"]), float(r["total_s"]))
    T.check(got == want, f"scaling.csv, {r['ranks']} rank(s): dofs, Newton, Krylov, total s {got} (summary: {want})")
T.check(os.path.getsize(os.path.join(out, "scaling.png")) > 10000, "scaling.png written")

# --- speedup.py --------------------------------------------------------------
out = T.path("speedup")
args = ["--out", out, "--factor", "1", "--steps", "1"]
script("speedup.py", *args, "--rounds", "1")
first = {d: os.path.getmtime(os.path.join(out, d, "summary.json")) for d in ("a-1r", "a-metis", "a-slabs")
         if os.path.isfile(os.path.join(out, d, "summary.json"))}
p = script("speedup.py", *args, "--rounds", "2")
runs = summaries(out)
names = ["a-1r", "a-metis", "a-slabs", "b-1r", "b-metis", "b-slabs"]
T.check(sorted(runs) == names, f"speedup.py, 2 rounds: runs {sorted(runs)}")
again = {d: os.path.getmtime(os.path.join(out, d, "summary.json")) for d in first}
T.check(len(first) == 3 and first == again, f"round a's {len(first)} runs reused by the second call, not rerun")
for d, s in runs.items():
    want = {"1r": (1, None), "metis": (2, "METIS"), "slabs": (2, "Slabs")}[d[2:]]
    got = (s["ranks"], s["mesh"]["partition"] if s["ranks"] > 1 else None)
    T.check(got == want and len(s["steps"]) == 1, f"{d}: ranks, partition {got}, {len(s['steps'])} step")
with open(os.path.join(out, "speedup.csv")) as fh:
    rows = list(csv.DictReader(fh))
T.check(len(rows) == 6, f"speedup.csv: {len(rows)} rows (6)")
with open(os.path.join(out, "speedup.md")) as fh:
    md = fh.read()
if len(runs) == 6:
    for part in ("metis", "slabs"):
        ratios = [runs[f"{k}-1r"]["timing"]["total"] / runs[f"{k}-{part}"]["timing"]["total"] for k in "ab"]
        line = next((ln for ln in md.splitlines() if ln.startswith(f"- {part}:")), "")
        m = re.search(r"speed-ups ([\d.]+)x, ([\d.]+)x; mean ([\d.]+)x", line)
        stated = [float(x) for x in m.groups()] if m else []
        want = ratios + [statistics.mean(ratios)]
        T.check(len(stated) == 3 and all(abs(a - b) <= 0.006 for a, b in zip(stated, want)),
                f"speedup.md, {part}: speed-ups and mean {stated} (from the summaries: "
                f"{[round(x, 3) for x in want]})")
T.check(os.path.getsize(os.path.join(out, "speedup.png")) > 10000, "speedup.png written")

# --- nip-accuracy.py ---------------------------------------------------------
out = T.path("nip-accuracy")
script("nip-accuracy.py", "--out", out, "--steady", "4x64,8x128", "--phases", "2", "--quasi-static", "4x64:1",
       "--window", "6", "--png", os.path.join(out, "nip.png"))
with open(os.path.join(out, "nip-accuracy.csv")) as fh:
    rows = list(csv.DictReader(fh))
T.check([(r["analysis"], r["mesh"]) for r in rows] ==
        [("steady", "4x64")] * 2 + [("steady", "8x128")] * 2 + [("quasi-static", "4x64")],
        f"nip-accuracy.csv rows {[(r['analysis'], r['mesh'], r['phase']) for r in rows]}")
_, plain, _ = T.run_scene(T.input("pinch-roller-braked-steady.xml"), "nip-plain",
                          sets=["Supports/core/Torque=0", "Supports/core/Torque Ramp Time=0.002", "Time/Steps=2",
                                "Output/Write Fields=false"])
want = plain["steps"][-1]["supports"]["core"]["speed_ratio"] if plain else float("nan")
if len(rows) == 5:
    T.check(abs(float(rows[0]["speed_ratio"]) - want) < 1e-12,
            f"phase 0 is the shipped mesh: {float(rows[0]['speed_ratio']):.9f} against a plain run's {want:.9f}")
    T.check(abs(float(rows[1]["speed_ratio"]) - want) > 1e-5, "phase 1 is another mesh: another speed ratio")
    with open(os.path.join(out, "quasi-static", "4x64-dt1", "summary.json")) as fh:
        steps = json.load(fh)["steps"]
    late = [st["supports"]["core"]["speed_ratio"] for st in steps[6:]]
    T.check(len(steps) == 12 and abs(float(rows[4]["speed_ratio"]) - sum(late) / 6) < 1e-12,
            f"quasi-static: {len(steps)} steps, mean of the last 6 {float(rows[4]['speed_ratio']):.6f}")
    ref = (float(rows[2]["speed_ratio"]) + float(rows[3]["speed_ratio"])) / 2
    T.check(all(abs(float(r["error"]) - abs(float(r["speed_ratio"]) - ref)) < 1e-12 for r in rows),
            f"errors against the finer phase mean {ref:.6f}")
    with open(os.path.join(out, "nip-accuracy.md")) as fh:
        T.check(f"Reference speed ratio {ref:.6f}: the finest phase mean" in fh.read(), "the report states the reference")
T.check(os.path.getsize(os.path.join(out, "nip.png")) > 10000, "nip-accuracy's PNG written")

# --- steady-phases.py ---------------------------------------------------------
out = T.path("steady-phases")
script("steady-phases.py", T.input("pinch-roller-slice-steady.xml"), "--phases", "2", "--out", out)
with open(os.path.join(out, "phases.csv")) as fh:
    ratio = next((r for r in csv.DictReader(fh) if r["step"] == "1" and r["figure"] == "core speed_ratio"), None)
runs = []
for j in range(2):
    with open(os.path.join(out, f"p{j}", "summary.json")) as fh:
        runs.append(json.load(fh)["steps"][0]["supports"]["core"]["speed_ratio"])
_, own, _ = T.run_scene(T.input("pinch-roller-slice-steady.xml"), "phases-own", sets=["Output/Write Fields=false"])
if ratio and own:
    mine = own["steps"][0]["supports"]["core"]["speed_ratio"]
    T.check(abs(runs[0] - mine) < 1e-12 and abs(runs[1] - mine) > 1e-5,
            f"phase 0 is the scene's mesh ({runs[0]:.9f} against {mine:.9f}), phase 1 another ({runs[1]:.9f})")
    T.check(abs(float(ratio["mean"]) - sum(runs) / 2) < 1e-12 and abs(float(ratio["spread"]) - abs(runs[1] - runs[0])) < 1e-12,
            f"phases.csv: speed ratio mean {float(ratio['mean']):.9f}, spread {float(ratio['spread']):.2e}")
else:
    T.check(False, "phases.csv has the core's speed ratio, and the scene's own run a summary")
p = subprocess.run([sys.executable, os.path.join(scripts, "steady-phases.py"), T.input("pinch-roller-slice-steady.xml"),
                    "--capstan", T.capstan, "--out", T.path("phases-uniform"), "--set", "Mesh/Fine Sector={0, 0, 0}"],
                   capture_output=True, text=True, timeout=60)
T.check(p.returncode != 0 and "Fine Sector of positive width" in p.stderr,
        f"a uniform mesh is refused: exit {p.returncode}, {p.stderr.strip()[-120:]}")

# --- stick-shear.py -------------------------------------------------------------
T.run_scene(T.input("pinch-roller-slice-steady.xml"), "stick-shear", sets=["Mesh/Cells={8, 256, 1}"])
p = subprocess.run([sys.executable, os.path.join(scripts, "stick-shear.py"), T.path("stick-shear")],
                   capture_output=True, text=True, timeout=60)
row = [line.split("|")[1:-1] for line in p.stdout.splitlines() if line.startswith("| " + T.path("stick-shear"))]
if p.returncode == 0 and len(row) == 2 and " - " not in row[0] + row[1]:
    faces, rms, largest = int(row[0][1]), float(row[0][2]), float(row[0][3])
    T.check(faces > 0 and 0 < rms <= largest < 1, f"stick-shear.py: {faces} stick faces, rms {rms}, largest {largest}")
    nodes, corr, ratio = int(row[1][1]), float(row[1][4]), float(row[1][5])
    T.check(nodes >= 10 and corr < -0.95 and 0.5 < abs(ratio) < 3,
            f"stick-shear.py: the shear's alternation over {nodes} sticking nodes follows the pressure "
            f"jump across them (correlation {corr:+.3f}, below -0.95; shear / jump {ratio})")
else:
    T.check(False, f"stick-shear.py: exit {p.returncode}, {p.stdout[-300:]} {p.stderr[-300:]}")

T.finish()
