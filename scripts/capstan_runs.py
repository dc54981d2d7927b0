"""Running capstan from the study scripts (scaling.py, speedup.py, the benches):
the command line of one run, the run itself, and the totals of its summary.json."""
import json
import os
import subprocess
import sys
import time

ROOT = os.path.normpath(os.path.join(os.path.dirname(os.path.abspath(__file__)), ".."))
CAPSTAN = os.path.join(ROOT, "build", "capstan")
# The scaling cases: scene and the cells of the 1x mesh (refined by a factor
# in every direction).
CASES = {"G1": ("inputs/seed/g1.xml", (14, 4, 6)), "H1": ("inputs/seed/h1.xml", (20, 2, 1))}
# The slice scenes' Mesh/Fine Sector (inputs/pinch-roller-*slice*.xml, -braked*.xml):
# centre, width (deg), fraction of the circumferential cells in it.
SECTOR = (-65.0, 60.0, 0.6)
ENV = dict(os.environ, OMPI_ALLOW_RUN_AS_ROOT="1", OMPI_ALLOW_RUN_AS_ROOT_CONFIRM="1")


def command(capstan, scene, out, cells, ranks, sets=(), steps=0):
    """`capstan run` of `scene` with GMRES + MueLu and no field output, so that
    every size and rank count runs the same method; `sets` are extra --set
    PATH=VALUE strings."""
    cmd = [capstan, "run", os.path.join(ROOT, scene), "--output", out, "--quiet",
           "--set", "Mesh/Cells={%d,%d,%d}" % tuple(cells),
           "--set", "Solver/Linear Solver=GMRES", "--set", "Solver/Preconditioner=MueLu",
           "--set", "Output/Write Fields=false"]
    for extra in sets:
        cmd += ["--set", extra]
    if steps:
        cmd += ["--set", f"Time/Steps={steps}"]
    if ranks > 1:
        cmd = ["mpiexec", "--oversubscribe", "-n", str(ranks)] + cmd
    return cmd


def fine_cell(nt, sector=SECTOR):
    """(cells in the sector, fine cell angle in degrees) for nt circumferential cells, as
    AnnulusGenerator does it (std::lround, clamped to 1 .. nt-1)."""
    m = min(max(int(sector[2] * nt + 0.5), 1), nt - 1)
    return m, sector[1] / m


def turned_sector(nt, turn, sector=SECTOR):
    """The mesh turned by `turn` fine cells (a mesh phase): (the sector's centre, its
    Mesh/Fine Sector setting) for nt circumferential cells."""
    centre = sector[0] - turn * fine_cell(nt, sector)[1]
    return centre, "Mesh/Fine Sector={%.10g, %g, %g}" % (centre, sector[1], sector[2])


def run_scene(capstan, scene, out, sets=(), ranks=1, extra=(), env=None, timeout=None):
    """One quiet `capstan run` of inputs/SCENE with no field output, timed:
    (exit status, wall seconds, summary.json or None). EXTRA: more driver options
    (e.g. ["--log", "newton"]); ENV: variables added to the run's environment;
    TIMEOUT: seconds, past which subprocess.TimeoutExpired is raised."""
    cmd = [capstan, "run", os.path.join(ROOT, "inputs", scene), "--output", out, "--quiet",
           "--set", "Output/Write Fields=false"] + list(extra)
    for s in sets:
        cmd += ["--set", s]
    if ranks > 1:
        cmd = ["mpiexec", "--oversubscribe", "-n", str(ranks)] + cmd
    t0 = time.perf_counter()
    p = subprocess.run(cmd, capture_output=True, text=True, env=dict(ENV, **(env or {})), timeout=timeout)
    wall = time.perf_counter() - t0
    path = os.path.join(out, "summary.json")
    if not os.path.isfile(path):
        return p.returncode, wall, None
    with open(path) as f:
        return p.returncode, wall, json.load(f)


def summary(out, cmd, tag, script):
    """OUT/summary.json, after running `cmd` if it is not there yet (a run made
    earlier, or by hand, is reused; delete OUT to redo it)."""
    path = os.path.join(out, "summary.json")
    if not os.path.isfile(path):
        print(f"  {tag} ...", flush=True)
        run = subprocess.run(cmd, env=ENV, capture_output=True, text=True)
        if not os.path.isfile(path):
            sys.exit(f"{script}: {tag} wrote no summary.json (exit {run.returncode}):\n{run.stderr}")
    with open(path) as fh:
        return json.load(fh)


def totals(s):
    """Newton iterations, Krylov iterations (all), and those of the pressure
    steps (None in summaries written before the key existed)."""
    steps = s["steps"]
    newton = sum(st["newton_iterations"] for st in steps)
    linear = sum(st["linear_iterations"] for st in steps)
    pstep = (sum(st["pressure_step_iterations"] for st in steps)
             if all("pressure_step_iterations" in st for st in steps) else None)
    return newton, linear, pstep


def write_report(path, lines):
    """Writes the markdown lines to `path` and prints them."""
    text = "\n".join(lines) + "\n"
    with open(path, "w") as fh:
        fh.write(text)
    print(text)


def pyplot():
    """matplotlib's pyplot, drawing to files only (no display needed)."""
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    return plt


def save_png(fig, path, dpi=130):
    """Writes the figure to `path` (its folder made if need be) and says so."""
    os.makedirs(os.path.dirname(os.path.abspath(path)), exist_ok=True)
    fig.savefig(path, dpi=dpi)
    print(f"wrote {path}")
