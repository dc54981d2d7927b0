"""Shared helpers of the integration tests (tests/integration/*.py).

Every script takes the same command line (tests/CMakeLists.txt passes it):

    SCRIPT.py --capstan PATH/TO/capstan --shared PATH/TO/shared --inputs PATH/TO/inputs
              [--mpiexec MPIEXEC] [--mpiexec-flag=FLAG]... [--keep]

runs the driver in a temporary directory of its own (removed unless the test
fails or --keep is given), prints every figure it checks, and exits 1 with one
line per failed check.
"""
import argparse
import json
import math
import os
import shutil
import subprocess
import sys
import tempfile
import xml.etree.ElementTree as ET


class Test:
    """Command line, scratch directory, driver runs and the list of failed checks."""

    def __init__(self, name, description=""):
        ap = argparse.ArgumentParser(description=description)
        ap.add_argument("--capstan", required=True, help="the capstan driver")
        ap.add_argument("--shared", required=True, help="the shared/ directory (tools/check_summary.py)")
        ap.add_argument("--inputs", required=True, help="the repository's inputs/ directory")
        ap.add_argument("--mpiexec", default="mpiexec")
        ap.add_argument("--mpiexec-flag", action="append", default=[], dest="mpiexec_flags")
        ap.add_argument("--keep", action="store_true", help="keep the scratch directory")
        self.args = ap.parse_args()
        self.name = name
        self.capstan = os.path.abspath(self.args.capstan)
        self.inputs = os.path.abspath(self.args.inputs)
        self.check_summary_py = os.path.join(os.path.abspath(self.args.shared), "tools", "check_summary.py")
        self.failures = []
        self.checks = 0
        self.dir = tempfile.mkdtemp(prefix=f"capstan-{name}-")
        print(f"[{name}] scratch directory {self.dir}")
        if not os.path.isfile(self.capstan):
            self.fatal(f"no capstan driver at {self.capstan}")
        if not os.path.isfile(self.check_summary_py):
            self.fatal(f"no check_summary.py at {self.check_summary_py} "
                       "(set CAPSTAN_SHARED_DIR to the shared/ checkout)")

    # -- results -----------------------------------------------------------
    def check(self, ok, what):
        """Records one check; WHAT says what was compared, with the figures."""
        self.checks += 1
        print(f"  {'ok  ' if ok else 'FAIL'} {what}")
        if not ok:
            self.failures.append(what)
        return ok

    def fatal(self, what):
        self.failures.append(what)
        print(f"  FAIL {what}")
        self.finish()

    def finish(self):
        if self.failures:
            print(f"\n[{self.name}] {len(self.failures)} of {self.checks} checks FAILED "
                  f"(scratch directory kept: {self.dir}):")
            for f in self.failures:
                print(f"  - {f}")
            sys.exit(1)
        print(f"\n[{self.name}] all {self.checks} checks passed")
        if not self.args.keep:
            shutil.rmtree(self.dir, ignore_errors=True)
        sys.exit(0)

    # -- paths -------------------------------------------------------------
    def input(self, name):
        return os.path.join(self.inputs, name)

    def path(self, *parts):
        return os.path.join(self.dir, *parts)

    def scene_with(self, source, name, xml, anchor='<ParameterList name="Output">'):
        """A copy of scene SOURCE in the scratch directory (NAME) with XML inserted
        before ANCHOR (by default its Output list): e.g. a Solver list of one's own."""
        with open(source) as fh:
            text = fh.read()
        self.check(anchor in text, f"{os.path.basename(source)} has {anchor!r} to insert before")
        path = self.path(name)
        with open(path, "w") as fh:
            fh.write(text.replace(anchor, xml + anchor, 1))
        return path

    # -- running the driver --------------------------------------------------
    def command(self, args, ranks=1):
        cmd = [self.capstan] + list(args)
        if ranks > 1:
            cmd = [self.args.mpiexec] + self.args.mpiexec_flags + ["-n", str(ranks)] + cmd
        return cmd

    def capstan_run(self, args, ranks=1, env=None, cwd=None, timeout=600):
        """Runs the driver; returns the CompletedProcess (stdout, stderr as text)."""
        cmd = self.command(args, ranks)
        full_env = dict(os.environ)
        full_env.update({"OMPI_ALLOW_RUN_AS_ROOT": "1", "OMPI_ALLOW_RUN_AS_ROOT_CONFIRM": "1",
                         "OMPI_MCA_rmaps_base_oversubscribe": "1"})
        if env:
            full_env.update(env)
        print("  $ " + " ".join(_quote(c) for c in cmd))
        try:
            return subprocess.run(cmd, capture_output=True, text=True, env=full_env,
                                  cwd=cwd or self.dir, timeout=timeout)
        except subprocess.TimeoutExpired:
            self.fatal(f"timed out after {timeout} s: {' '.join(cmd)}")

    def run_scene(self, scene, out, sets=(), ranks=1, env=None, quiet=True, expect_rc=0, extra=()):
        """Runs SCENE into the scratch subdirectory OUT (EXTRA: more driver options,
        e.g. ["--log", "newton"]); checks the exit status and returns (completed
        process, summary dict or None, output directory)."""
        outdir = self.path(out)
        args = ["run", scene, "--output", outdir] + list(extra)
        for s in sets:
            args += ["--set", s]
        if quiet:
            args.append("--quiet")
        p = self.capstan_run(args, ranks=ranks, env=env)
        label = f"{os.path.basename(scene)} {' '.join(sets)} on {ranks} rank(s)".replace("  ", " ")
        if not self.check(p.returncode == expect_rc, f"{label}: exit status {p.returncode} (expected {expect_rc})"):
            tail = (p.stdout[-2000:] + "\n" + p.stderr[-3000:]).strip()
            print("    output tail:\n      " + tail.replace("\n", "\n      "))
        summary = None
        sp = os.path.join(outdir, "summary.json")
        if os.path.isfile(sp):
            try:
                with open(sp) as f:
                    summary = json.load(f)
            except ValueError as e:
                self.check(False, f"{sp}: not valid JSON: {e}")
        return p, summary, outdir

    def converged_run(self, scene, out, label, sets=(), ranks=1, env=None):
        """run_scene, checked to converge and to conform to interface.md; the
        summary, or None."""
        p, s, outdir = self.run_scene(scene, out, sets=sets, ranks=ranks, env=env)
        if s is None:
            self.check(False, f"{label}: no summary.json ({p.stderr.strip()[:200]})")
            return None
        self.check(s["converged"] is True, f"{label}: converged = {s['converged']} ({s['failure']!r})")
        self.conforms(outdir, scene)
        return s

    @staticmethod
    def log_events(outdir, event=None):
        """The events of OUTDIR/log.jsonl (a run with --log TOPIC), those named
        EVENT only if given, in order."""
        path = os.path.join(outdir, "log.jsonl")
        if not os.path.isfile(path):
            return []
        with open(path) as f:
            events = [json.loads(line) for line in f if line.strip()]
        return [e for e in events if event is None or e.get("event") == event]

    def conforms(self, outdir, scene=None):
        """shared/tools/check_summary.py on OUTDIR/summary.json (with --scene SCENE)."""
        cmd = [sys.executable, self.check_summary_py, os.path.join(outdir, "summary.json")]
        if scene:
            cmd += ["--scene", scene]
        p = subprocess.run(cmd, capture_output=True, text=True)
        msg = (p.stdout + p.stderr).strip().replace("\n", "; ")
        return self.check(p.returncode == 0, f"check_summary.py{' --scene' if scene else ''}: {msg}")


def _quote(s):
    return s if s and all(c.isalnum() or c in "-_./=:,{}" for c in s) else repr(s)


# -- comparisons -------------------------------------------------------------
def rel_diff(a, b, scale=None):
    """|a - b| / scale (scale defaults to |b|; an exact match is 0)."""
    if a == b:
        return 0.0
    s = abs(b) if scale is None else scale
    return abs(a - b) / s if s > 0 else math.inf


def worst_difference(ref, other):
    """The largest |other[k] - ref[k]| over REF's names, relative to REF's largest
    magnitude; a name missing from OTHER counts as NaN (fails any tolerance).
    Returns (worst, its name, scale)."""
    scale = max(abs(v) for v in ref.values())
    worst, where = 0.0, next(iter(ref), "")
    for name, v in ref.items():
        d = abs(other.get(name, math.nan) - v) / scale
        if not d <= worst:
            worst, where = d, name
    return worst, where, scale


def has_nan(obj):
    """True if a float in OBJ (nested dicts/lists) is NaN or infinite."""
    if isinstance(obj, float):
        return not math.isfinite(obj)
    if isinstance(obj, dict):
        return any(has_nan(v) for v in obj.values())
    if isinstance(obj, list):
        return any(has_nan(v) for v in obj)
    return False


STRESS = ("xx", "yy", "zz", "xy", "yz", "xz")


def summary_figures(summary):
    """Named scalar figures of a summary: final stress/pressure extrema, the face
    means of the displacement, and every support force of every step. Returns
    {group: {name: value}} with groups stress, displacement, force."""
    fin = summary["final"]
    stress = {}
    for c in STRESS:
        for m in ("min", "max"):
            stress[f"stress.{c}.{m}"] = fin["stress"][c][m]
    for m in ("min", "max"):
        stress[f"pressure.{m}"] = fin["pressure"][m]
        stress[f"von_mises.{m}"] = fin["von_mises"][m]
    disp = {}
    for face, v in fin["node_displacement_mean"].items():
        for i, x in enumerate(v):
            disp[f"node_displacement_mean.{face}[{'xyz'[i]}]"] = x
    force = {}
    for st in summary["steps"]:
        for kind in ("supports", "capstans"):
            for name, s in st.get(kind, {}).items():
                for i, x in enumerate(s["force"]):
                    force[f"step {st['step']} {kind}.{name}.force[{'xyz'[i]}]"] = x
    return {"stress": stress, "displacement": disp, "force": force}


# -- scenes ------------------------------------------------------------------
class SceneInfo:
    """A few values read from a scene file (Teuchos XML)."""

    def __init__(self, path):
        self.root = ET.parse(path).getroot()

    def _sub(self, node, name):
        for c in node:
            if c.tag == "ParameterList" and c.get("name") == name:
                return c
        return None

    def get(self, path, default=None):
        """Value of the parameter at PATH ("Mesh/Max") as text, or DEFAULT."""
        parts = path.split("/")
        node = self.root
        for p in parts[:-1]:
            node = self._sub(node, p)
            if node is None:
                return default
        for c in node:
            if c.tag == "Parameter" and c.get("name") == parts[-1]:
                return c.get("value")
        return default

    def number(self, path, default=None):
        v = self.get(path)
        return default if v is None else float(v)

    def vector(self, path, default=None):
        v = self.get(path)
        if v is None:
            return default
        return [float(x) for x in v.strip().strip("{}").split(",")]


# -- fields.h5 ---------------------------------------------------------------
def read_fields(path):
    """{step number: {"X": reference coordinates, "u": displacement, "x": coordinates,
    "stress": element stresses, "pressure", "hexahedra": connectivity, "quads":
    contact-face connectivity (or None), "faces": {name: contact-face field}}} from
    fields.h5 (needs h5py and numpy)."""
    import h5py
    import numpy as np
    out = {}
    with h5py.File(path, "r") as f:
        steps = sorted(f["steps"].keys())
        X = np.array(f["steps"][steps[0]]["coordinates"])
        hexes = np.array(f["mesh"]["hexahedra"])
        quads = np.array(f["mesh"]["quads"]) if "quads" in f["mesh"] else None
        for s in steps:
            g = f["steps"][s]
            faces = {}
            for k, v in (g["faces"].items() if "faces" in g else []):
                a = np.array(v)
                faces[k] = a.reshape(-1) if a.ndim == 2 and a.shape[1] == 1 else a  # scalars as 1-D
            out[int(s)] = {"X": X, "x": np.array(g["coordinates"]),
                           "u": np.array(g["nodes"]["displacement"]),
                           "stress": np.array(g["elements"]["stress"]),
                           "pressure": np.array(g["elements"]["pressure"]),
                           "hexahedra": hexes, "quads": quads, "faces": faces}
    return out


def by_reference_coordinates(X, values, digits=9):
    """{rounded reference coordinates: row of VALUES} for matching nodes across runs."""
    return {tuple(round(float(c), digits) for c in X[i]): values[i] for i in range(len(X))}
