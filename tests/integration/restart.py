#!/usr/bin/env python3
"""Checkpoint/restart gives the results of an uninterrupted run (ctest labels
integration, hard).

The scene is inputs/seed/stick-slip.xml (augmented Lagrangian contact, Coulomb
friction: pressure anchors, contact and tangential multipliers, stick states and
the friction history all carry over between steps; every step does Newton work).

  1 rank:  run it uninterrupted; run it again with Output/Checkpoint Every = 1,
           kill it (SIGKILL) once the checkpoint of step 3 or later exists, check
           that the killed run left a readable fields.h5 and fields.xmf, then
           `capstan run --restart` into the same directory.
  2 ranks: the same on a 20 x 2 x 1 mesh; and a finished run with Checkpoint
           Every = 4 restarted from step 4 (its fields.h5 steps 5 and 6 must be
           replaced, not duplicated).

Each restarted run must list every step, and every per-step figure of
summary.json (all numbers but wall_seconds), the rows of history.csv, and the
displacement and pressure of every step in fields.h5 must equal the
uninterrupted run's to 1e-10 relative.

The free roller slice (inputs/pinch-roller-slice.xml, 2 ranks) finished with a
checkpoint at step 4 and restarted there: its rolling predictors extrapolate the
last increment, which the checkpoint carries, so steps 5 and 6 equal the
uninterrupted run's to 1e-10 too; the same for the steady braked slice (its
friction entities include the core's angular velocity), restarted in place and into
another directory (--output elsewhere: fields.h5 and nip.csv continue the earlier
run's); nip.csv's rows equal the uninterrupted run's.

Bad restarts exit 1, name the scene file and what does not fit, and leave the
output directory as it was: another mesh (Mesh/Cells; the annulus' Outer Cell
Ratio, its Fine Sector), another analysis (Analysis/Type), another step size
(Time/Step Size), another rank count, a directory without a checkpoint, a
damaged checkpoint (one byte flipped: its checksum), an incomplete one (a rank's
file removed).
"""
import csv
import glob
import math
import os
import signal
import subprocess
import sys
import time
import xml.etree.ElementTree as ET

sys.dont_write_bytecode = True
sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from capstan_test import Test, _quote  # noqa: E402

T = Test("restart", __doc__)
SCENE = T.input("seed/stick-slip.xml")
STEPS = 6
RTOL = 1e-10
SMALL = ["Mesh/Cells={20,2,1}"]  # the 2-rank variant (GMRES on 2 ranks is slower)


def checkpoints(out):
    """Step numbers of the complete checkpoints in OUT."""
    steps = []
    for d in glob.glob(os.path.join(out, "checkpoint", "step-*")):
        name = os.path.basename(d)
        if name[5:].isdigit() and os.path.isfile(os.path.join(d, "rank-00000.bin")):
            steps.append(int(name[5:]))
    return sorted(steps)


def descendants(pid):
    """Process ids of PID's children, grandchildren, ... (from /proc)."""
    children = {}
    for entry in os.listdir("/proc"):
        if not entry.isdigit():
            continue
        try:
            with open(f"/proc/{entry}/stat") as f:
                stat = f.read()
        except OSError:
            continue
        ppid = int(stat[stat.rindex(")") + 2:].split()[1])
        children.setdefault(ppid, []).append(int(entry))
    out, todo = [], [pid]
    while todo:
        for c in children.get(todo.pop(), []):
            out.append(c)
            todo.append(c)
    return out


def kill_job(p):
    """SIGKILL to the driver and every process it started (mpiexec's ranks may sit
    in process groups of their own), leaves first; waits until all are gone."""
    pids = descendants(p.pid)
    for pid in reversed(pids):
        try:
            os.kill(pid, signal.SIGKILL)
        except ProcessLookupError:
            pass
    p.kill()
    p.wait()
    deadline = time.time() + 30
    while time.time() < deadline and any(os.path.exists(f"/proc/{pid}") and not _zombie(pid) for pid in pids):
        time.sleep(0.01)


def _zombie(pid):
    try:
        with open(f"/proc/{pid}/stat") as f:
            stat = f.read()
        return stat[stat.rindex(")") + 2] == "Z"
    except OSError:
        return True


def run_and_kill(tag, sets, ranks, after_step):
    """Starts the scene with Checkpoint Every = 1 and kills it (SIGKILL to mpiexec
    and its ranks) once a checkpoint of AFTER_STEP or later exists. Returns the
    output directory and the step of its checkpoint."""
    out = T.path(tag)
    args = ["run", SCENE, "--output", out, "--quiet", "--set", "Output/Checkpoint Every=1"]
    for s in sets:
        args += ["--set", s]
    cmd = T.command(args, ranks)
    env = dict(os.environ, OMPI_ALLOW_RUN_AS_ROOT="1", OMPI_ALLOW_RUN_AS_ROOT_CONFIRM="1",
               OMPI_MCA_rmaps_base_oversubscribe="1")
    print("  $ " + " ".join(_quote(c) for c in cmd) + "   (killed later)")
    p = subprocess.Popen(cmd, cwd=T.dir, env=env, stdout=subprocess.DEVNULL, stderr=subprocess.PIPE)
    deadline = time.time() + 120
    while time.time() < deadline and p.poll() is None:
        if any(k >= after_step for k in checkpoints(out)):
            break
        time.sleep(0.005)
    running = p.poll() is None
    if running:
        kill_job(p)
    else:
        p.wait()
    err = p.stderr.read().decode(errors="replace")
    if not T.check(running, f"{tag}: still running when the checkpoint of step >= {after_step} appeared "
                            f"(exit {p.returncode}) {err[-300:]}"):
        T.finish()
    found = checkpoints(out)
    T.check(len(found) == 1 and after_step <= found[-1] < STEPS,
            f"{tag}: killed with checkpoint {found} (one, of a step in [{after_step}, {STEPS - 1}])")
    time.sleep(1)
    T.check(checkpoints(out) == found, f"{tag}: nothing runs on after the kill (checkpoints {checkpoints(out)})")
    return out, found[-1] if found else None


def killed_outputs_readable(tag, out, k):
    """What a killed run leaves: fields.h5 opens and holds steps 0..k at least;
    fields.xmf parses and indexes only steps fields.h5 holds; history.csv rows >= k;
    summary.json lists the converged steps (>= k) and says the run stopped."""
    import h5py
    try:
        with h5py.File(os.path.join(out, "fields.h5"), "r") as f:
            steps = sorted(int(s) for s in f["steps"].keys())
            for s in steps:
                f["steps"][f"{s:06d}"]["nodes"]["displacement"][()]
        ok = steps[: k + 1] == list(range(k + 1))
        T.check(ok, f"{tag}: killed run's fields.h5 readable, steps {steps} (0..{k} at least)")
    except Exception as e:  # noqa: BLE001 - any failure to read is the finding
        T.check(False, f"{tag}: killed run's fields.h5 readable: {e}")
        steps = []
    try:
        grids = ET.parse(os.path.join(out, "fields.xmf")).getroot().iter("Time")
        n = sum(1 for _ in grids)
        T.check(k + 1 <= n <= len(steps), f"{tag}: killed run's fields.xmf parses, {n} steps indexed")
    except ET.ParseError as e:
        T.check(False, f"{tag}: killed run's fields.xmf parses: {e}")
    with open(os.path.join(out, "history.csv")) as f:
        rows = list(csv.DictReader(f))
    T.check(len(rows) >= k, f"{tag}: killed run's history.csv has {len(rows)} rows (>= {k})")
    # summary.json is rewritten after every step: the killed run's lists its converged steps.
    import json
    try:
        with open(os.path.join(out, "summary.json")) as f:
            summary = json.load(f)
        listed = [st["step"] for st in summary["steps"]]
        T.check(summary["converged"] is False and "stopped after step" in (summary["failure"] or "")
                and listed == list(range(1, len(listed) + 1)) and len(listed) >= k,
                f"{tag}: killed run's summary.json lists steps 1..{len(listed)} (>= {k}), not converged: "
                f"{summary['failure']!r}")
    except (OSError, ValueError, KeyError) as e:
        T.check(False, f"{tag}: killed run's summary.json readable: {e}")


def restart(tag, out, sets, ranks, k, scene=None, into=None):
    args = ["run", scene or SCENE, "--output", into or out, "--restart", out]
    for s in sets:
        args += ["--set", s]
    p = T.capstan_run(args, ranks=ranks)
    T.check(p.returncode == 0, f"{tag}: restart exit status {p.returncode} (0) {p.stderr[-300:]}")
    lines = [ln for ln in p.stdout.splitlines() if ln.startswith("step ")]
    T.check(p.stdout.startswith("restart from") and f"step-{k:06d}" in p.stdout.splitlines()[0],
            f"{tag}: restarted from step {k}: {p.stdout.splitlines()[0] if p.stdout else '(no output)'}")
    T.check(len(lines) == STEPS - k and lines[0].startswith(f"step {k + 1}/"),
            f"{tag}: ran steps {k + 1}..{STEPS} only ({len(lines)} progress lines)")


def per_step_figures(summary):
    """{'step 3 capstans.capstan.force[1]': value, ...}: every number of every step
    but wall_seconds."""
    out = {}

    def walk(prefix, v):
        if isinstance(v, dict):
            for k, x in v.items():
                if k != "wall_seconds":
                    walk(f"{prefix}.{k}" if prefix else k, x)
        elif isinstance(v, list):
            for i, x in enumerate(v):
                walk(f"{prefix}[{i}]", x)
        elif isinstance(v, (int, float)) and not isinstance(v, bool):
            out[prefix] = float(v)
        else:
            out[prefix] = v

    for st in summary["steps"]:
        walk(f"step {st['step']}", st)
    return out


def close(a, b):
    if a == b:
        return True
    if not (isinstance(a, float) and isinstance(b, float)):
        return False
    return abs(a - b) <= RTOL * max(abs(a), abs(b))


def compare(tag, ref_out, out, scene=None):
    import json

    import numpy as np
    from capstan_test import read_fields
    with open(os.path.join(ref_out, "summary.json")) as f:
        ref = json.load(f)
    with open(os.path.join(out, "summary.json")) as f:
        got = json.load(f)
    T.check(got["converged"] is True and [s["step"] for s in got["steps"]] == list(range(1, STEPS + 1)),
            f"{tag}: summary.json converged, lists steps {[s['step'] for s in got['steps']]}")
    a, b = per_step_figures(ref), per_step_figures(got)
    bad = [k for k in a if k not in b or not close(a[k], b[k])]
    worst = max((abs(a[k] - b[k]) / max(abs(a[k]), abs(b[k])) for k in a
                 if k in b and isinstance(a[k], float) and isinstance(b[k], float) and a[k] != b[k]), default=0.0)
    T.check(not bad and set(a) == set(b),
            f"{tag}: all {len(a)} per-step figures of summary.json agree (largest relative difference "
            f"{worst:.1e}; differing: {bad[:4]})")
    T.conforms(out, scene or SCENE)
    # The checkpoint carries the direct solver's counts so far: with the same arithmetic, the
    # same factorisations and solves (a new process analyses the pattern again).
    wa, wb = ref["timing"]["direct_solver"], got["timing"]["direct_solver"]
    T.check((wa["factorizations"], wa["solves"]) == (wb["factorizations"], wb["solves"]),
            f"{tag}: timing.direct_solver {wb}: the uninterrupted run's factorisations and solves {wa}")

    def rows(d):
        with open(os.path.join(d, "history.csv")) as f:
            return [{k: v for k, v in r.items() if k != "wall_seconds"} for r in csv.DictReader(f)]
    ra, rb = rows(ref_out), rows(out)
    same = len(ra) == len(rb) == STEPS and all(
        set(x) == set(y) and all(close(float(x[k]), float(y[k])) for k in x) for x, y in zip(ra, rb))
    T.check(same, f"{tag}: history.csv: {len(rb)} rows, equal to the uninterrupted run's ({len(ra)})")

    fa, fb = read_fields(os.path.join(ref_out, "fields.h5")), read_fields(os.path.join(out, "fields.h5"))
    T.check(sorted(fb) == list(range(STEPS + 1)), f"{tag}: fields.h5 holds steps {sorted(fb)} (0..{STEPS})")
    worst_u = worst_p = 0.0
    for s in fa:
        if s not in fb:
            continue
        for key, name in (("u", "displacement"), ("pressure", "pressure")):
            x, y = fa[s][key], fb[s][key]
            if x.shape != y.shape:
                T.check(False, f"{tag}: step {s} {name} shape {y.shape} (expected {x.shape})")
                continue
            scale = float(np.abs(x).max())
            d = float(np.abs(x - y).max())
            rel = 0.0 if d == 0 else (d / scale if scale > 0 else math.inf)
            if key == "u":
                worst_u = max(worst_u, rel)
            else:
                worst_p = max(worst_p, rel)
    T.check(worst_u <= RTOL and worst_p <= RTOL,
            f"{tag}: fields.h5 displacement and pressure of every step agree (largest relative "
            f"difference {worst_u:.1e}, {worst_p:.1e}; <= {RTOL:.0e})")
    with open(os.path.join(out, "fields.xmf")) as f:
        n = sum(1 for _ in ET.parse(f).getroot().iter("Time"))
    T.check(n == STEPS + 1, f"{tag}: fields.xmf indexes {n} steps ({STEPS + 1})")

    if os.path.exists(os.path.join(ref_out, "nip.csv")):
        def nip(d):
            with open(os.path.join(d, "nip.csv")) as f:
                return list(csv.DictReader(f))
        na, nb = nip(ref_out), nip(out)
        same = len(na) == len(nb) and all(
            x["step"] == y["step"] and x["capstan"] == y["capstan"] and x["state"] == y["state"] and
            all(close(float(x[k]), float(y[k])) for k in ("s", "z", "pressure", "shear", "slip_rate"))
            for x, y in zip(na, nb))
        T.check(same, f"{tag}: nip.csv: {len(nb)} rows of steps {sorted({int(r['step']) for r in nb})}, equal to the "
                f"uninterrupted run's ({len(na)})")


def snapshot(d):
    out = {}
    for root, dirs, files in os.walk(d):
        for n in dirs + files:
            p = os.path.join(root, n)
            st = os.stat(p)
            out[os.path.relpath(p, d)] = (st.st_size, st.st_mtime_ns)
    return out


def bad_restart(label, out, args, ranks, needles, scene=None):
    before = snapshot(out)
    p = T.capstan_run(["run", scene or SCENE, "--output", out, "--restart", out] + args, ranks=ranks)
    T.check(p.returncode == 1, f"{label}: exit status {p.returncode} (1)")
    err = p.stderr.strip()
    for n in needles:
        T.check(n in err, f"{label}: stderr names {n!r}: {err.splitlines()[0][:300] if err else '(empty)'}")
    after = snapshot(out)
    changed = sorted(k for k in set(before) | set(after) if before.get(k) != after.get(k))
    T.check(not changed, f"{label}: output directory unchanged (changed: {changed[:5]})")


# --- 1 rank ----------------------------------------------------------------
t0 = time.time()
_, s, ref1 = T.run_scene(SCENE, "uninterrupted-1")
out1, k1 = run_and_kill("killed-1", [], 1, 3)
if k1 is not None:
    killed_outputs_readable("1 rank", out1, k1)
    restart("1 rank", out1, [], 1, k1)
    compare("1 rank", ref1, out1)
print(f"    1 rank: {time.time() - t0:.1f} s")

# --- 2 ranks ---------------------------------------------------------------
t0 = time.time()
_, s, ref2 = T.run_scene(SCENE, "uninterrupted-2", sets=SMALL, ranks=2)
out2, k2 = run_and_kill("killed-2", SMALL, 2, 3)
if k2 is not None:
    killed_outputs_readable("2 ranks", out2, k2)
    restart("2 ranks", out2, SMALL, 2, k2)
    compare("2 ranks", ref2, out2)
# A finished run restarted from its step-4 checkpoint: steps 5 and 6 are redone.
_, s, out3 = T.run_scene(SCENE, "finished-2", sets=SMALL + ["Output/Checkpoint Every=4"], ranks=2)
T.check(checkpoints(out3) == [4], f"Checkpoint Every = 4: checkpoints {checkpoints(out3)} ([4], only the newest)")
restart("2 ranks, from a finished run", out3, SMALL, 2, 4)
compare("2 ranks, from a finished run", ref2, out3)
print(f"    2 ranks: {time.time() - t0:.1f} s")

# --- rolling, 2 ranks: the predictors' last increment carries over ---------------
# The free roller slice (6 steps): from step 3 on its first guess extrapolates
# the last increment, which the checkpoint holds (without it step 5 took 7
# Newton iterations against 9 and its speed ratio moved by 3.4e-5).
t0 = time.time()
SLICE = T.input("pinch-roller-slice.xml")
_, s, ref4 = T.run_scene(SLICE, "slice-uninterrupted-2", sets=[f"Time/Steps={STEPS}"], ranks=2)
_, s, out4 = T.run_scene(SLICE, "slice-finished-2", sets=[f"Time/Steps={STEPS}", "Output/Checkpoint Every=4"], ranks=2)
restart("rolling slice, 2 ranks, from a finished run", out4, [f"Time/Steps={STEPS}"], 2, 4, scene=SLICE)
compare("rolling slice, 2 ranks, from a finished run", ref4, out4, scene=SLICE)
print(f"    rolling slice: {time.time() - t0:.1f} s")
# Steady rolling (the braked slice's sweep, 2 ranks): steady friction's entities
# hold the core's angular velocity (a block past the mesh's nodes), keyed apart
# from the nodes (a restart read past the node ids and refused its own checkpoint).
t0 = time.time()
STEADY = T.input("pinch-roller-braked-steady.xml")
_, s, ref5 = T.run_scene(STEADY, "steady-uninterrupted-2", sets=[f"Time/Steps={STEPS}"], ranks=2)
_, s, out5 = T.run_scene(STEADY, "steady-finished-2", sets=[f"Time/Steps={STEPS}", "Output/Checkpoint Every=4"],
                         ranks=2)
restart("steady braked slice, 2 ranks, from a finished run", out5, [f"Time/Steps={STEPS}"], 2, 4, scene=STEADY)
compare("steady braked slice, 2 ranks, from a finished run", ref5, out5, scene=STEADY)
# Into another directory: the earlier run's fields.h5 copied there and continued, its
# nip.csv rows kept (before, the new nip.csv held only the steps after the checkpoint).
into = T.path("steady-elsewhere")
restart("steady braked slice, restarted into another directory", out5, [f"Time/Steps={STEPS}"], 2, 4, scene=STEADY,
        into=into)
compare("steady braked slice, restarted into another directory", ref5, into, scene=STEADY)
print(f"    steady slice: {time.time() - t0:.1f} s")

# --- bad restarts ------------------------------------------------------------
bad_restart("another mesh", out1, ["--set", "Mesh/Cells={40,4,2}"], 1, [SCENE, "Mesh/Cells"])
bad_restart("another step size", out1, ["--set", "Time/Step Size=0.01"], 1, [SCENE, "Time/Step Size"])
bad_restart("2-rank checkpoint on 1 rank", out2, ["--set", SMALL[0]], 1, [SCENE, "2 rank(s)"])
# The steady slice's checkpoint: the same cells graded otherwise, or the other analysis.
bad_restart("another radial grading", out5, ["--set", f"Time/Steps={STEPS}", "--set", "Mesh/Outer Cell Ratio=0.5"], 2,
            [STEADY, "Mesh/Outer Cell Ratio"], scene=STEADY)
bad_restart("another fine sector", out5, ["--set", f"Time/Steps={STEPS}", "--set", "Mesh/Fine Sector={-60, 60, 0.6}"],
            2, [STEADY, "Mesh/Fine Sector"], scene=STEADY)
bad_restart("another analysis", out5, ["--set", f"Time/Steps={STEPS}", "--set", "Analysis/Type=Quasi-Static"], 2,
            [STEADY, "Analysis/Type"], scene=STEADY)
bad_restart("no checkpoint", ref1, [], 1, [SCENE, "no checkpoint"])
# A damaged checkpoint (one byte flipped, a copy of the slice's): its checksum says so.
import shutil  # noqa: E402

damaged = T.path("slice-damaged")
shutil.copytree(out4, damaged)
(rank0,) = glob.glob(os.path.join(damaged, "checkpoint", "step-*", "rank-00000.bin"))
with open(rank0, "r+b") as fh:
    fh.seek(os.path.getsize(rank0) * 3 // 4)
    byte = fh.read(1)
    fh.seek(-1, os.SEEK_CUR)
    fh.write(bytes([byte[0] ^ 0xFF]))
bad_restart("a damaged checkpoint", damaged, ["--set", f"Time/Steps={STEPS}"], 2, [SLICE, "checksum"], scene=SLICE)
# A checkpoint that lost a rank's file: incomplete, not one of fewer ranks.
partial = T.path("slice-partial")
shutil.copytree(out4, partial)
for f in glob.glob(os.path.join(partial, "checkpoint", "step-*", "rank-00001.bin")):
    os.remove(f)
bad_restart("a checkpoint without rank 1's file", partial, ["--set", f"Time/Steps={STEPS}"], 2,
            [SLICE, "incomplete", "written on 2 rank(s)"], scene=SLICE)
T.finish()
