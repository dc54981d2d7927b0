#!/usr/bin/env python3
"""Behaviour-preservation check for refactors: every scene gives the same figures.

What it checks
--------------
Runs every scene `inputs/*.xml` and `inputs/seed/*.xml` (sorted) with a capstan
binary, and compares the outputs of two such sets of runs, scene by scene:

- `summary.json`, recursively: the same keys, the same list lengths, strings,
  booleans and nulls equal, every number equal to within 1e-12 relative:
  |a - b| <= 1e-12 * max(|a|, |b|), or both |a|, |b| < 1e-300 (NaN equals NaN);
- `history.csv`, cell by cell with the same rule, columns matched by name (the
  second side may add columns, not drop any; same rows);
- the exit status of the run (`exit_status.txt`, written by this script).

Ignored, because they are not figures of the solution and change from run to
run or from build to build: every key whose path (any key on the way down)
contains `timing`, `memory`, `wall_seconds`, `seconds` (the effects' kernel
seconds), `version` (the build's version string) or `scene` (the scene file's
path, which differs between checkouts); in history.csv the columns whose names
contain the same words (`wall_seconds`). (The words are matched in key names,
so an object named e.g. "scene" would be skipped too; no scene has one.)
`effects/*/launches` (kernel launch counts) are compared unless
`--ignore-launches` is given: a refactor that batches kernels differently
changes them without changing any answer, so that flag lets such a change
through while keeping every other figure.
`fields.h5` is not compared (HDF5 needs more than the standard library).

How to use it
-------------
1. Before the change, build and keep the old binary, and make the baseline
   (one run at a time; on a 2-core machine this takes about 4 minutes):

       mkdir -p /work/baseline/bin && cp build/capstan /work/baseline/bin/capstan
       /usr/bin/python3 scripts/compare-scenes.py --capstan /work/baseline/bin/capstan \\
           --out /work/baseline/out

2. After the change, rebuild, run the same scenes and compare in one go:

       /usr/bin/python3 scripts/compare-scenes.py --capstan build/capstan \\
           --out out/after --baseline /work/baseline/out

   or compare two existing sets of runs without running anything:

       /usr/bin/python3 scripts/compare-scenes.py --compare /work/baseline/out out/after

   Options: `--only default,seed/g1,h1` runs or compares a subset (the name is the
   scene's path below inputs/ without `.xml`, or just its file name);
   `--ranks N` runs under `mpiexec -n N`; `--steps-cap N` (default 3) caps the
   long scenes of CAPPED (below) at N load steps; `--jobs N` runs N scenes at a
   time (default 1: timings are not compared, but a loaded 2-core machine is
   slow); `--timeout S` kills a run after S seconds (exit status `timeout`);
   `--list` lists the scenes and their caps.

One line per scene is printed: `OK name` or `DIFF name: path a b (rel ...)` with
the first 5 differences; then the counts. Exit status 1 if any scene differs
(or is missing from either side), else 0. Both sides must have been run with
the same `--steps-cap` and `--ranks` (each run's `run.json` records them; a
mismatch is reported as a difference).

Each run goes to OUT/<name>/ (the scene's old directory there is removed first)
with `summary.json`, `history.csv`, `fields.*` as capstan writes them, plus
`exit_status.txt`, `stdout.txt`, `stderr.txt` and `run.json` (command line,
wall seconds, exit status) written by this script.

Determinism and the tolerance: two runs of the same binary (1 rank, and 2 ranks)
were measured bit-identical in every compared figure (`--rtol 0` passes), so
1e-12 is achievable; `OK name (max rel ...)` says when figures passed without
being identical. Note that some figures are round-off noise (force components
that should be 0, ~1e-14; residual norms ~1e-13; volume changes ~1e-11;
penetrations ~1e-12 under augmented Lagrangian): a change that reorders
floating-point operations moves those by far more than 1e-12 relative, so in
practice this check asks for bit-identical arithmetic. (A 1-rank vs 2-rank run,
for scale: displacements agree to 1.6e-10, volume changes differ by 30%.)
`--rtol X` sets another tolerance (0: bit-identical).
"""
import argparse
import concurrent.futures
import csv
import json
import math
import os
import shutil
import subprocess
import sys
import time
import xml.etree.ElementTree as ET

ROOT = os.path.normpath(os.path.join(os.path.dirname(os.path.abspath(__file__)), ".."))
INPUTS = os.path.join(ROOT, "inputs")

RTOL = 1e-12
TINY = 1e-300
# Keys (anywhere on the path) and history.csv columns containing one of these are
# not compared: timings, memory, build version and the scene file's path.
IGNORED_WORDS = ("timing", "memory", "wall_seconds", "seconds", "version", "scene")
MAX_SHOWN = 5

# Scenes run with `--set Time/Steps=N` (N = --steps-cap, default 3) when their
# Time/Steps exceed N. Time/Step Size is fixed per scene, so a capped run is the
# first N steps of the full run: the same code paths (contact, Coulomb friction,
# rigid core, step cutting: its step 2 cuts 5 times) are exercised, only fewer
# times. Wall times measured with the pre-refactor Release build (commit
# eae508f) on the 2-core machine, one run at a time while the other core
# compiled (first figure: alone; second: in the full baseline run):
#   pinch-roller         40 steps: 56-77 s for the first 3 (steps 1-3 took
#                        5, 37 (5 cuts) and 13 s; the README gives about a
#                        minute a step, some 40 minutes in full)        -> capped
#   block40               1 step:  32-35 s (nothing to cap)
#   hertz-roller          2 steps: 24-28 s; hertz-roller-held 2 steps: 20-22 s
#   pinch-roller-slice   20 steps: 18-22 s; pinch-roller-braked 20 steps: 18-23 s
#                        (cheap enough to run in full)
#   every other scene    under 5 s
# so only pinch-roller is capped, and the whole suite (24 scenes) takes about
# 4 minutes (241 s measured) with the default cap.
CAPPED = ("pinch-roller",)


def scenes():
    """(name, path) of every scene, sorted by path; name = path below inputs/
    without .xml (`default`, `seed/g1`)."""
    out = []
    for sub in ("", "seed"):
        folder = os.path.join(INPUTS, sub)
        for f in sorted(os.listdir(folder)):
            if f.endswith(".xml"):
                out.append((os.path.join(sub, f[:-4]) if sub else f[:-4], os.path.join(folder, f)))
    return out


def select(all_scenes, only):
    """The scenes named in `only` (comma-separated full names or file names)."""
    if not only:
        return all_scenes
    wanted = [w.strip() for w in only.split(",") if w.strip()]
    picked = []
    for w in wanted:
        w = w[:-4] if w.endswith(".xml") else w
        hits = [s for s in all_scenes if s[0] == w or os.path.basename(s[0]) == w]
        if not hits:
            sys.exit(f"compare-scenes: no scene named {w!r} (names: {', '.join(n for n, _ in all_scenes)})")
        if len(hits) > 1:
            sys.exit(f"compare-scenes: {w!r} is ambiguous: {', '.join(n for n, _ in hits)}")
        if hits[0] not in picked:
            picked.append(hits[0])
    return sorted(picked, key=lambda s: s[1])


def scene_steps(path):
    """Time/Steps of a scene file (None if it does not say)."""
    try:
        root = ET.parse(path).getroot()
    except ET.ParseError:
        return None
    for plist in root.iter("ParameterList"):
        if plist.get("name") == "Time":
            for p in plist.findall("Parameter"):
                if p.get("name") == "Steps":
                    try:
                        return int(p.get("value"))
                    except (TypeError, ValueError):
                        return None
    return None


def command(capstan, name, path, outdir, ranks, steps_cap):
    """The command line of one run and the steps cap applied (0: none)."""
    cmd = [capstan, "run", path, "--output", outdir, "--quiet"]
    cap = 0
    steps = scene_steps(path)
    if steps_cap > 0 and name in CAPPED and steps is not None and steps > steps_cap:
        cmd += ["--set", f"Time/Steps={steps_cap}"]
        cap = steps_cap
    if ranks > 1:
        mpi = ["mpiexec", "-n", str(ranks)]
        if os.geteuid() == 0:
            mpi += ["--allow-run-as-root", "--oversubscribe"]
        cmd = mpi + cmd
    return cmd, cap


def run_one(capstan, name, path, out, ranks, steps_cap, timeout):
    """Runs one scene into OUT/<name>; returns (name, exit status, seconds, cap)."""
    outdir = os.path.join(out, name)
    if os.path.isdir(outdir):
        shutil.rmtree(outdir)
    os.makedirs(outdir)
    cmd, cap = command(capstan, name, path, outdir, ranks, steps_cap)
    env = dict(os.environ, OMPI_ALLOW_RUN_AS_ROOT="1", OMPI_ALLOW_RUN_AS_ROOT_CONFIRM="1")
    t0 = time.monotonic()
    try:
        proc = subprocess.run(cmd, cwd=ROOT, env=env, capture_output=True, text=True,
                              timeout=timeout if timeout > 0 else None)
        status, stdout, stderr = str(proc.returncode), proc.stdout, proc.stderr
    except subprocess.TimeoutExpired as e:
        status = "timeout"
        stdout = e.stdout.decode(errors="replace") if isinstance(e.stdout, bytes) else (e.stdout or "")
        stderr = e.stderr.decode(errors="replace") if isinstance(e.stderr, bytes) else (e.stderr or "")
    seconds = time.monotonic() - t0
    for fname, text in (("exit_status.txt", status + "\n"), ("stdout.txt", stdout),
                        ("stderr.txt", stderr)):
        with open(os.path.join(outdir, fname), "w") as fh:
            fh.write(text)
    info = {"scene": os.path.relpath(path, ROOT), "command": cmd, "ranks": ranks,
            "steps_cap": cap, "full_steps": scene_steps(path), "exit_status": status,
            "wall_seconds": round(seconds, 3)}
    with open(os.path.join(outdir, "run.json"), "w") as fh:
        json.dump(info, fh, indent=1)
        fh.write("\n")
    return name, status, seconds, cap


def run_all(args, selected):
    capstan = os.path.abspath(args.capstan) if os.sep in args.capstan else args.capstan
    if not (os.path.isfile(capstan) and os.access(capstan, os.X_OK)):
        sys.exit(f"compare-scenes: no capstan binary at {capstan}")
    out = os.path.abspath(args.out)
    os.makedirs(out, exist_ok=True)
    print(f"running {len(selected)} scene(s) with {capstan} into {out}"
          f" (ranks {args.ranks}, steps cap {args.steps_cap}, jobs {args.jobs})", flush=True)
    results = []
    t0 = time.monotonic()
    with concurrent.futures.ThreadPoolExecutor(max_workers=max(1, args.jobs)) as pool:
        futures = [pool.submit(run_one, capstan, name, path, out, args.ranks, args.steps_cap,
                               args.timeout) for name, path in selected]
        for fut in concurrent.futures.as_completed(futures):
            name, status, seconds, cap = fut.result()
            capped = f"  (capped at {cap} steps)" if cap else ""
            print(f"  ran {name:24s} exit {status:7s} {seconds:8.1f} s{capped}", flush=True)
            results.append((name, status, seconds, cap))
    print(f"ran {len(results)} scene(s) in {time.monotonic() - t0:.1f} s", flush=True)
    return results


# ---------------------------------------------------------------- comparison

def ignored(key):
    k = str(key).lower()
    return any(w in k for w in IGNORED_WORDS)


def is_number(x):
    return isinstance(x, (int, float)) and not isinstance(x, bool)


class Diffs(list):
    """The differences found, (path, a, b, rel or None); `worst_ok` is the largest
    relative difference of the numbers that passed (0: all bit-identical)."""
    worst_ok = 0.0


def numbers_differ(a, b, diffs):
    """None if a and b agree to RTOL relative, else the relative difference
    (inf where one is NaN or infinite and the other is not)."""
    a, b = float(a), float(b)
    if math.isnan(a) or math.isnan(b):
        return None if (math.isnan(a) and math.isnan(b)) else float("inf")
    if a == b:
        return None
    if abs(a) < TINY and abs(b) < TINY:
        return None
    if math.isinf(a) or math.isinf(b):
        return float("inf")
    scale = max(abs(a), abs(b))
    rel = abs(a - b) / scale
    if abs(a - b) <= RTOL * scale:
        diffs.worst_ok = max(diffs.worst_ok, rel)
        return None
    return rel


def compare_json(a, b, path, diffs, ignore_launches):
    """Appends (path, a, b, rel) for every difference between a and b."""
    if isinstance(a, dict) and isinstance(b, dict):
        for k in sorted(set(a) | set(b), key=str):
            if ignored(k):
                continue
            if ignore_launches and k == "launches" and path.startswith("effects/"):
                continue
            p = f"{path}/{k}" if path else str(k)
            if k not in a:
                diffs.append((p, "<missing>", _short(b[k]), None))
            elif k not in b:
                diffs.append((p, _short(a[k]), "<missing>", None))
            else:
                compare_json(a[k], b[k], p, diffs, ignore_launches)
    elif isinstance(a, list) and isinstance(b, list):
        if len(a) != len(b):
            diffs.append((f"{path}/len", len(a), len(b), None))
        for i, (x, y) in enumerate(zip(a, b)):
            compare_json(x, y, f"{path}[{i}]", diffs, ignore_launches)
    elif is_number(a) and is_number(b):
        rel = numbers_differ(a, b, diffs)
        if rel is not None:
            diffs.append((path, a, b, rel))
    elif type(a) is not type(b) or a != b:
        diffs.append((path, _short(a), _short(b), None))


def _short(x):
    s = json.dumps(x) if not isinstance(x, str) else repr(x)
    return s if len(s) <= 60 else s[:57] + "..."


def _cell(s):
    """A history.csv cell as a number if it reads as one, else the string."""
    try:
        return float(s)
    except ValueError:
        return s.strip()


def compare_csv(fa, fb, diffs):
    with open(fa, newline="") as fh:
        ra = list(csv.reader(fh))
    with open(fb, newline="") as fh:
        rb = list(csv.reader(fh))
    if not ra or not rb:
        if ra != rb:
            diffs.append(("history.csv", f"{len(ra)} lines", f"{len(rb)} lines", None))
        return
    ha, hb = [h.strip() for h in ra[0]], [h.strip() for h in rb[0]]
    # Columns are matched by name: the second run may add columns (history.csv
    # lists every figure of summary.json's steps), never drop one.
    missing = [h for h in ha if h not in hb]
    if missing:
        diffs.append(("history.csv/header", _short(",".join(missing)), "<missing>", None))
    if len(ra) != len(rb):
        diffs.append(("history.csv/rows", len(ra) - 1, len(rb) - 1, None))
    keep = [h for h in ha if h in hb and not ignored(h)]
    ia = {h: i for i, h in enumerate(ha)}
    ib = {h: i for i, h in enumerate(hb)}
    for r, (row_a, row_b) in enumerate(zip(ra[1:], rb[1:]), start=1):
        for h in keep:
            x = row_a[ia[h]] if ia[h] < len(row_a) else "<missing>"
            y = row_b[ib[h]] if ib[h] < len(row_b) else "<missing>"
            cx, cy = _cell(x), _cell(y)
            p = f"history.csv[{r}]/{h}"
            if isinstance(cx, float) and isinstance(cy, float):
                rel = numbers_differ(cx, cy, diffs)
                if rel is not None:
                    diffs.append((p, x, y, rel))
            elif cx != cy:
                diffs.append((p, x, y, None))


def _read(path):
    try:
        with open(path) as fh:
            return fh.read().strip()
    except OSError:
        return None


def compare_scene(da, db, ignore_launches):
    """The differences between two run directories of one scene."""
    diffs = Diffs()
    if not os.path.isdir(da) or not os.path.isdir(db):
        return Diffs([("run", "present" if os.path.isdir(da) else "<not run>",
                 "present" if os.path.isdir(db) else "<not run>", None)])
    ea, eb = _read(os.path.join(da, "exit_status.txt")), _read(os.path.join(db, "exit_status.txt"))
    if ea != eb:
        diffs.append(("exit_status", ea, eb, None))
    # both sides must be the same runs: same ranks and steps cap
    ja, jb = _read(os.path.join(da, "run.json")), _read(os.path.join(db, "run.json"))
    if ja and jb:
        ia, ib = json.loads(ja), json.loads(jb)
        for k in ("ranks", "steps_cap"):
            if ia.get(k) != ib.get(k):
                diffs.append((f"run.json/{k}", ia.get(k), ib.get(k), None))
    sa, sb = os.path.join(da, "summary.json"), os.path.join(db, "summary.json")
    if os.path.isfile(sa) and os.path.isfile(sb):
        try:
            with open(sa) as fh:
                a = json.load(fh)
            with open(sb) as fh:
                b = json.load(fh)
        except ValueError as e:
            diffs.append(("summary.json", "unreadable", str(e)[:60], None))
        else:
            compare_json(a, b, "", diffs, ignore_launches)
    elif os.path.isfile(sa) != os.path.isfile(sb):
        diffs.append(("summary.json", "present" if os.path.isfile(sa) else "<missing>",
                      "present" if os.path.isfile(sb) else "<missing>", None))
    ha, hb = os.path.join(da, "history.csv"), os.path.join(db, "history.csv")
    if os.path.isfile(ha) and os.path.isfile(hb):
        compare_csv(ha, hb, diffs)
    elif os.path.isfile(ha) != os.path.isfile(hb):
        diffs.append(("history.csv", "present" if os.path.isfile(ha) else "<missing>",
                      "present" if os.path.isfile(hb) else "<missing>", None))
    return diffs


def compare_all(base, other, selected, ignore_launches):
    """Prints one line per scene; returns the number of scenes that differ."""
    print(f"comparing {other} against {base} (rel tol {RTOL:g}"
          f"{', launches ignored' if ignore_launches else ''})", flush=True)
    bad = 0
    for name, _ in selected:
        diffs = compare_scene(os.path.join(base, name), os.path.join(other, name), ignore_launches)
        if not diffs:
            # bit-identical, or (said so) within the tolerance
            print(f"OK {name}" + (f" (max rel {diffs.worst_ok:.3g}, within tolerance)"
                                  if diffs.worst_ok else ""))
            continue
        bad += 1
        shown = "; ".join(
            f"{p} {a} {b}" + (f" (rel {rel:.3g})" if rel is not None else "")
            for p, a, b, rel in diffs[:MAX_SHOWN])
        more = f" (+{len(diffs) - MAX_SHOWN} more)" if len(diffs) > MAX_SHOWN else ""
        print(f"DIFF {name}: {shown}{more}")
    print(f"{len(selected) - bad} OK, {bad} DIFF of {len(selected)} scene(s)")
    return bad


def main():
    global RTOL
    ap = argparse.ArgumentParser(
        description="Run every scene of inputs/ and inputs/seed/ and/or compare two sets of "
                    "runs (summary.json, history.csv, exit status) to 1e-12 relative.",
        epilog="Scenes capped at --steps-cap steps: " + ", ".join(CAPPED))
    ap.add_argument("--capstan", default=os.path.join(ROOT, "build", "capstan"),
                    help="capstan binary to run (default: build/capstan)")
    ap.add_argument("--out", help="directory for the runs (OUT/<name>/)")
    ap.add_argument("--ranks", type=int, default=1, help="MPI ranks per run (default 1)")
    ap.add_argument("--steps-cap", type=int, default=3,
                    help="steps of the long scenes (CAPPED list) when they have more; "
                         "0: run them in full (default 3)")
    ap.add_argument("--only", help="comma-separated scene names (default: all)")
    ap.add_argument("--jobs", type=int, default=1, help="runs at a time (default 1)")
    ap.add_argument("--timeout", type=float, default=0, help="seconds per run (default: none)")
    ap.add_argument("--baseline", help="after running, compare OUT against this directory")
    ap.add_argument("--compare", nargs=2, metavar=("BASELINE_DIR", "OTHER_DIR"),
                    help="compare two existing sets of runs; runs nothing")
    ap.add_argument("--rtol", type=float, default=RTOL,
                    help="relative tolerance (default 1e-12; 0: bit-identical)")
    ap.add_argument("--ignore-launches", action="store_true",
                    help="do not compare the effects' kernel launch counts")
    ap.add_argument("--list", action="store_true", help="list the scenes and exit")
    args = ap.parse_args()
    RTOL = args.rtol

    selected = select(scenes(), args.only)
    if args.list:
        for name, path in selected:
            steps = scene_steps(path)
            capped = f" -> {args.steps_cap} (capped)" if (
                args.steps_cap > 0 and name in CAPPED and steps and steps > args.steps_cap) else ""
            print(f"{name:24s} {os.path.relpath(path, ROOT):36s} steps {steps}{capped}")
        return 0
    if args.compare:
        if args.out or args.baseline:
            ap.error("--compare runs nothing: no --out or --baseline with it")
        base, other = (os.path.abspath(d) for d in args.compare)
        for d in (base, other):
            if not os.path.isdir(d):
                ap.error(f"no directory {d}")
        return 1 if compare_all(base, other, selected, args.ignore_launches) else 0
    if not args.out:
        ap.error("--out DIR is needed to run scenes (or --compare BASELINE_DIR OTHER_DIR)")
    if args.baseline and not os.path.isdir(args.baseline):
        ap.error(f"no baseline directory {args.baseline}")
    run_all(args, selected)
    if args.baseline:
        print()
        bad = compare_all(os.path.abspath(args.baseline), os.path.abspath(args.out), selected,
                          args.ignore_launches)
        return 1 if bad else 0
    return 0


if __name__ == "__main__":
    sys.exit(main())
