#!/usr/bin/python3
"""capstan scene G1 solved with GetFEM (Debian's python3-getfem), for wall-time comparisons.

Problem (capstan inputs/seed/g1.xml, formulation.md sections 1, 2, 5, 6 "G"):
  block [0,7]x[0,1.75]x[0,4], structured hexahedra 14x4x6 times the refinement factor;
  incompressible neo-Hookean rubber, c = 1 (sigma = -p I + 2c (B - I));
  face y = 0 fixed; face y = 1.75 in frictionless contact with a rigid cylinder
  R = 2, axis along z through (3.5, 3.75 - 0.1 t, 0), t = 1..5 (final indentation 0.5).
  Output per step: Newton iterations and the y force of the body on the capstan.

GetFEM model (all in GetFEM's generic weak-form language, GWFL, assembled by GetFEM):
  * Q1 displacement (FEM_QK(3,1)), P0 pressure (FEM_QK_DISCONTINUOUS(3,0)),
    2x2x2 Gauss (IM_GAUSS_PARALLELEPIPED(3,3)), as capstan's Q1P0 brick.
  * Momentum written with capstan's stress, pulled back to the reference mesh:
      int (J (2c (F - F^-T) - p F^-T)) : Grad(w) dV      (= int sigma : grad(w) dv)
    i.e. exactly formulation.md section 1 (not GetFEM's "Incompressible Neo Hookean"
    law, which uses isochoric invariants J^-2/3 I1: same continuum model at J = 1,
    but a different discrete Q1P0 solution because J = 1 only holds per element).
  * Incompressibility  int q (J - 1) dV = 0  per element, EXACT (pressure is a Lagrange
    multiplier, no penalty). capstan uses eps1 = 1e-3 in its Newton steps but its pressure
    loop makes v_e = V_e exact, so the converged discrete problems are the same.
  * Contact: the gap g = R - |P (X + u - a(t))| of the analytic cylinder in the CURRENT
    configuration (large sliding, no linearisation), checked at the contact face nodes:
    a Q1 multiplier field lam (contact pressure) on face y = 1.75 and a nodal
    (Gauss-Lobatto 2x2) face quadrature, with the Alart-Curnier augmented-Lagrangian
    complementarity  lam = max(0, lam + r g)  solved by semi-smooth Newton together with
    u and p (one monolithic Newton per step, no Uzawa loop). This is capstan's G1 rule
    ("Augmented Lagrangian" -> Nodal contact points, exact contact) with a different
    algorithm: capstan runs Uzawa/saddle-point multiplier passes around Newton solves
    with eps2 = 1e-3; both converge to g = 0 at the contact nodes, so the discrete
    problems coincide (r only changes the Newton path, not the answer).
    GetFEM's own add_nodal/integral_contact_with_rigid_obstacle bricks are NOT used:
    they linearise the obstacle about the reference configuration (small sliding),
    which is a different (less accurate) model at this indentation.
  * Dirichlet y = 0 by GetFEM's Dirichlet condition with simplification (dofs removed).
  * Newton: own loop on GetFEM's model (md.assembly, md.rhs, md.tangent_matrix),
    full steps, linear solves by MUMPS (gf.linsolve('mumps'), sequential Debian build).
    Converged when |R|_2 <= max(rtol |R_0|_2, atol), R_0 the residual at the start of the
    step (after moving the cylinder), rtol = 1e-10 and atol = 1e-13 c L^2 (L the box
    diagonal) by default, i.e. capstan's defaults (Newton Relative Tolerance 1e-10,
    Newton Absolute Tolerance 0 -> 1e-13 c size^2). Predictor: previous step's solution
    (capstan: tangent predictor). Rows are GetFEM's (momentum, volume, gap/r).
  * Timing: wall time from mesh creation to the end of step 5 (model building, GWFL
    compilation, all assemblies and solves); force evaluation included, printing not.

Not part of the tests (CI installs no GetFEM): the benchmark behind issue 32's comparison,
docs/performance.md "Against GetFEM".

Usage (Debian: apt-get install -y python3-getfem; run with /usr/bin/python3):
  scripts/getfem-g1.py [--refine 1,2] [--rtol 1e-10] [--r 1000] [--check] [--blas-dir DIR]
  scripts/getfem-g1.py --compare build/capstan [--refine 1,2] [--rounds 5] [--ranks 1]
      alternates fresh processes of this script (one refinement) and of
      `capstan run g1.xml --set Mesh/Cells=... --quiet` and prints the per-round times
      and the median GetFEM/capstan ratios. Both run with OMP_NUM_THREADS=1 (and the
      BLAS thread variables = 1). Two ratios are shown: solve = GetFEM's mesh->step 5
      wall vs capstan's summary.json timing.total; process = whole process wall time
      (python start + import getfem vs capstan start-up, Trilinos init and output files).
      --ranks N runs capstan on N MPI ranks (mpiexec; the GetFEM run stays serial).
  --cpu-kernels unsets OPENBLAS_CORETYPE and OPENBLAS_L2_SIZE for both codes, so that
      OpenBLAS picks its kernels from the CPU (some machines set them to an older kernel
      set, e.g. Haswell's AVX2 on an AVX-512 CPU, because older OpenBLAS builds computed
      wrong results there: compare the forces with a run without it). The header line
      names the kernels in use.
  --blas-dir DIR puts DIR first on LD_LIBRARY_PATH (of both codes with --compare), e.g.
      apt-get download libopenblas0-serial && dpkg -x libopenblas0-serial_*.deb ob
      --blas-dir ob/usr/lib/x86_64-linux-gnu/openblas-serial
  (python3-getfem only pulls Debian's reference libblas3; MUMPS' dense kernels run
  about 2x faster on OpenBLAS; the system BLAS alternative is left untouched).
"""
import argparse
import json
import os
import statistics
import subprocess
import sys
import tempfile
import time

for _v in ("OMP_NUM_THREADS", "OPENBLAS_NUM_THREADS", "MKL_NUM_THREADS",
           "BLIS_NUM_THREADS", "GOTO_NUM_THREADS"):
    os.environ.setdefault(_v, "1")

import numpy as np

HERE = os.path.dirname(os.path.abspath(__file__))
DEFAULT_SCENE = os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "inputs", "seed", "g1.xml")
BASE_CELLS = (14, 4, 6)
LX, LY, LZ = 7.0, 1.75, 4.0
C = 1.0
RADIUS = 2.0
AXIS0 = np.array([3.5, 3.75, 0.0])
AXIS_DIR = np.array([0.0, 0.0, 1.0])
VELOCITY = np.array([0.0, -0.1, 0.0])
STEPS = 5


def ensure_getfem():
    """Installs Debian's python3-getfem on demand (apt-get, as root or through sudo);
    exits 1 with the reason where it cannot."""
    try:
        import getfem  # noqa: F401
        return
    except ImportError:
        pass
    sudo = [] if os.geteuid() == 0 else ["sudo"]
    env = dict(os.environ, DEBIAN_FRONTEND="noninteractive")

    def apt(*words):
        return subprocess.run(sudo + ["apt-get", *words, "-qq"], env=env).returncode == 0

    print("GetFEM missing: installing Debian's python3-getfem", file=sys.stderr, flush=True)
    apt("install", "-y", "python3-getfem") or (apt("update") and apt("install", "-y", "python3-getfem"))
    try:
        import getfem  # noqa: F401
    except ImportError:
        sys.exit("getfem-g1.py: python3-getfem is not installed and apt-get could not install it "
                 "(run as root, or with sudo, on Debian bookworm)")


def solve_getfem(refine, rtol=1e-10, atol=None, r_aug=1e3, max_iter=40, check=False,
                 verbose=True):
    import getfem as gf
    gf.util_trace_level(0)
    gf.util_warning_level(0)
    t0 = time.perf_counter()
    nx, ny, nz = (refine * n for n in BASE_CELLS)
    m = gf.Mesh("cartesian", np.linspace(0, LX, nx + 1), np.linspace(0, LY, ny + 1),
                np.linspace(0, LZ, nz + 1))
    BOTTOM, TOP = 1, 2
    m.set_region(BOTTOM, m.outer_faces_with_direction([0.0, -1.0, 0.0], 0.01))
    m.set_region(TOP, m.outer_faces_with_direction([0.0, 1.0, 0.0], 0.01))

    mfu = gf.MeshFem(m, 3)
    mfu.set_fem(gf.Fem("FEM_QK(3,1)"))
    mfp = gf.MeshFem(m, 1)
    mfp.set_fem(gf.Fem("FEM_QK_DISCONTINUOUS(3,0)"))
    mfl = gf.MeshFem(m, 1)
    mfl.set_fem(gf.Fem("FEM_QK(3,1)"))
    mim = gf.MeshIm(m, gf.Integ("IM_GAUSS_PARALLELEPIPED(3,3)"))
    # nodal rule on the faces: Gauss-Lobatto 2 points per direction
    mimc = gf.MeshIm(m, gf.Integ(
        "IM_PRODUCT(IM_PRODUCT(IM_GAUSSLOBATTO1D(1),IM_GAUSSLOBATTO1D(1)),IM_GAUSSLOBATTO1D(1))"))

    md = gf.Model("real")
    md.add_fem_variable("u", mfu)
    md.add_fem_variable("p", mfp)
    md.add_filtered_fem_variable("lam", mfl, TOP)
    md.add_initialized_data("c", [C])
    md.add_initialized_data("R", [RADIUS])
    md.add_initialized_data("r", [r_aug])
    md.add_initialized_data("a", AXIS0)
    bhat = AXIS_DIR / np.linalg.norm(AXIS_DIR)
    md.add_initialized_data("Pax", (np.eye(3) - np.outer(bhat, bhat)).flatten(order="F"), [3, 3])
    md.add_macro("F", "Id(3)+Grad_u")
    md.add_macro("J", "Det(F)")
    md.add_macro("dvec", "Pax*(X+u-a)")
    md.add_macro("e_r", "dvec/Norm(dvec)")
    md.add_macro("gap", "R-Norm(dvec)")
    md.add_nonlinear_term(mim, "(J*(2*c*(F-Inv(F)')-p*Inv(F)')):Grad_Test_u")
    md.add_nonlinear_term(mim, "-(J-1)*Test_p")
    md.add_nonlinear_term(mimc, "-lam*(e_r.Test_u)", TOP)
    md.add_nonlinear_term(mimc, "(lam-pos_part(lam+r*gap))/r*Test_lam", TOP)
    md.add_Dirichlet_condition_with_simplification("u", BOTTOM)

    if atol is None:
        atol = 1e-13 * C * (LX * LX + LY * LY + LZ * LZ)
    nbdof = md.nbdof()
    steps = []
    for step in range(1, STEPS + 1):
        ts = time.perf_counter()
        md.set_variable("a", AXIS0 + VELOCITY * step)
        its = 0
        md.assembly("build_all")
        res0 = res = np.linalg.norm(md.rhs())
        history = [res]
        while res > max(rtol * res0, atol):
            if its >= max_iter:
                raise RuntimeError("step %d: Newton did not converge (%g)" % (step, res))
            K = md.tangent_matrix()
            dx = gf.linsolve_mumps(K, md.rhs())
            md.to_variables(md.from_variables() + np.asarray(dx).ravel())
            its += 1
            md.assembly("build_all")
            res = np.linalg.norm(md.rhs())
            history.append(res)
        fy = gf.asm_generic(mimc, 0, "-lam*e_r(2)", TOP, md)
        rec = {"step": step, "newton_iterations": its, "force_y": float(fy),
               "residual": float(res), "residual0": float(res0),
               "wall": time.perf_counter() - ts}
        steps.append(rec)
        if check:  # not part of the timed problem, but cheap
            pen = md.interpolation("pos_part(gap)", mfl, TOP)
            rec["max_penetration_nodes"] = float(np.max(pen))
            rint = gf.asm_generic(mim, 1, "(J*(2*c*(F-Inv(F)')-p*Inv(F)')):Grad_Test_u",
                                  -1, md)
            iu = md.interval_of_variable("u")
            rint = rint[iu[0]:iu[0] + iu[1]]
            bd = mfu.basic_dof_on_region(BOTTOM)
            rec["base_force_y"] = float(np.sum(rint[bd[bd % 3 == 1]]))
            vol = gf.asm_generic(mim, 1, "J*Test_p", -1, md)
            ip = md.interval_of_variable("p")
            v = vol[ip[0]:ip[0] + ip[1]]
            v0 = (LX / nx) * (LY / ny) * (LZ / nz)
            rec["max_abs_volume_change"] = float(np.max(np.abs(v / v0 - 1)))
            rec["residual_history"] = [float(x) for x in history]
    wall = time.perf_counter() - t0
    return {"refine": refine, "blas": loaded_blas(), "cells": [nx, ny, nz],
            "dofs": int(nbdof), "wall": wall, "steps": steps, "rtol": rtol, "atol": atol, "r": r_aug}


def loaded_blas():
    """Path of the BLAS shared library mapped in this process (which one MUMPS uses)."""
    try:
        with open("/proc/self/maps") as f:
            libs = {l.split()[-1] for l in f if "blas" in l.split()[-1]}
        return ",".join(sorted(os.path.realpath(x) for x in libs)) or "?"
    except OSError:
        return "?"


def print_result(res):
    print("GetFEM G1 %dx: cells %s, %d unknowns (u, p, lam), wall %.3f s (mesh -> step 5)"
          % (res["refine"], "x".join(map(str, res["cells"])), res["dofs"], res["wall"]))
    print("  BLAS: %s" % res["blas"])
    for s in res["steps"]:
        extra = ""
        if "base_force_y" in s:
            extra = "  base Fy %.6f  max pen %.1e  max|dV/V| %.1e" % (
                s["base_force_y"], s["max_penetration_nodes"], s["max_abs_volume_change"])
        print("  step %d  newton %2d  Fy %.6f  |R| %.2e (|R0| %.2e)%s"
              % (s["step"], s["newton_iterations"], s["force_y"], s["residual"],
                 s["residual0"], extra))


def run_capstan(binary, scene, refine, outdir, args_blas_dir=None, ranks=1):
    cells = "{%d,%d,%d}" % tuple(refine * n for n in BASE_CELLS)
    cmd = [binary, "run", scene, "--output", outdir, "--set", "Mesh/Cells=" + cells, "--quiet"]
    if ranks > 1:
        cmd = ["mpiexec", "--oversubscribe", "-n", str(ranks)] + cmd
    t = time.perf_counter()
    env = dict(child_env(args_blas_dir), OMPI_ALLOW_RUN_AS_ROOT="1", OMPI_ALLOW_RUN_AS_ROOT_CONFIRM="1")
    subprocess.run(cmd, check=True, stdout=subprocess.DEVNULL, env=env)
    wall = time.perf_counter() - t
    with open(os.path.join(outdir, "summary.json")) as f:
        s = json.load(f)
    return wall, s


CPU_KERNELS = False  # --cpu-kernels: OpenBLAS' own choice of kernels for both codes


def child_env(blas_dir):
    env = dict(os.environ)
    if CPU_KERNELS:
        env.pop("OPENBLAS_CORETYPE", None)
        env.pop("OPENBLAS_L2_SIZE", None)
    if blas_dir:
        env["LD_LIBRARY_PATH"] = os.path.abspath(blas_dir) + (
            ":" + env["LD_LIBRARY_PATH"] if env.get("LD_LIBRARY_PATH") else "")
    return env


def run_getfem_process(refine, args):
    cmd = [sys.executable, os.path.abspath(__file__), "--refine", str(refine), "--json",
           "--rtol", repr(args.rtol), "--r", repr(args.r)]
    t = time.perf_counter()
    out = subprocess.run(cmd, check=True, capture_output=True, text=True,
                         env=child_env(args.blas_dir)).stdout
    wall = time.perf_counter() - t
    return wall, json.loads(out.strip().splitlines()[-1])


def compare(args, refines):
    # capstan's outputs go to a scratch folder, removed afterwards (never the source tree).
    with tempfile.TemporaryDirectory(prefix="g1cmp-") as tmp:
        compare_in(args, refines, tmp)


def openblas_kernels(blas_dir):
    """The kernel set OpenBLAS picks in the children's environment ('-': not OpenBLAS)."""
    code = ("import ctypes\ntry:\n l = ctypes.CDLL('libopenblas.so.0')\n"
            " l.openblas_get_corename.restype = ctypes.c_char_p\n"
            " print(l.openblas_get_corename().decode())\nexcept Exception:\n print('-')")
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True,
                         env=child_env(blas_dir)).stdout.strip()
    return out or "-"


def compare_in(args, refines, tmp):
    env = child_env(args.blas_dir)
    print("capstan: %s on %d rank(s); GetFEM: %s; Newton rtol %g; BLAS dir for both: %s; "
          "OpenBLAS kernels: %s (OPENBLAS_CORETYPE=%s); OMP_NUM_THREADS=%s"
          % (args.compare, args.ranks, sys.executable, args.rtol, args.blas_dir or "system default",
             openblas_kernels(args.blas_dir), env.get("OPENBLAS_CORETYPE", "unset"),
             os.environ.get("OMP_NUM_THREADS")), flush=True)
    for k in refines:
        rows = []
        for rnd in range(args.rounds):
            order = ("getfem", "capstan") if rnd % 2 == 0 else ("capstan", "getfem")
            row = {}
            for who in order:
                if who == "getfem":
                    row["gf_proc"], g = run_getfem_process(k, args)
                    row["gf_solve"] = g["wall"]
                    row["gf_res"] = g
                else:
                    row["cp_proc"], s = run_capstan(args.compare, args.scene, k,
                                                   os.path.join(tmp, "cap%dx" % k),
                                                   args.blas_dir, args.ranks)
                    row["cp_total"] = s["timing"]["total"]
                    row["cp_sum"] = s
            rows.append(row)
            print("  %dx round %d: GetFEM solve %.3f s proc %.3f s | capstan total %.3f s "
                  "proc %.3f s | ratio solve %.2f proc %.2f"
                  % (k, rnd + 1, row["gf_solve"], row["gf_proc"], row["cp_total"],
                     row["cp_proc"], row["gf_solve"] / row["cp_total"],
                     row["gf_proc"] / row["cp_proc"]), flush=True)
        g, s = rows[-1]["gf_res"], rows[-1]["cp_sum"]
        print("GetFEM BLAS: %s" % g["blas"])
        print("G1 %dx (%s cells), force on the capstan (y), GetFEM vs capstan:"
              % (k, "x".join(map(str, g["cells"]))))
        for gs, cs in zip(g["steps"], s["steps"]):
            cf = cs["capstans"]["capstan"]["force"][1]
            print("  step %d  GetFEM %.6f (%2d Newton)  capstan %.6f (%2d Newton)  rel diff %+.2e"
                  % (gs["step"], gs["force_y"], gs["newton_iterations"], cf,
                     cs["newton_iterations"], (gs["force_y"] - cf) / cf))
        med = lambda key: statistics.median(r[key] for r in rows)
        rs = [r["gf_solve"] / r["cp_total"] for r in rows]
        rp = [r["gf_proc"] / r["cp_proc"] for r in rows]
        print("G1 %dx, %d alternating rounds: median GetFEM solve %.3f s, capstan total %.3f s;"
              " ratio GetFEM/capstan solve median %.2f (min %.2f, max %.2f),"
              " process median %.2f (min %.2f, max %.2f)\n"
              % (k, args.rounds, med("gf_solve"), med("cp_total"), statistics.median(rs),
                 min(rs), max(rs), statistics.median(rp), min(rp), max(rp)), flush=True)


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--refine", default="1", help="comma list of refinement factors (1 = 14x4x6)")
    ap.add_argument("--rtol", type=float, default=1e-10, help="Newton relative tolerance")
    ap.add_argument("--r", type=float, default=1e3,
                    help="Alart-Curnier augmentation r (1/eps2; changes the path, not the answer)")
    ap.add_argument("--check", action="store_true",
                    help="also print base reaction, nodal penetration, volume change")
    ap.add_argument("--json", action="store_true", help="print one JSON line per refinement")
    ap.add_argument("--compare", metavar="CAPSTAN_BINARY")
    ap.add_argument("--scene", default=DEFAULT_SCENE)
    ap.add_argument("--rounds", type=int, default=5)
    ap.add_argument("--ranks", type=int, default=1,
                    help="capstan's MPI ranks (mpiexec; GetFEM's Debian build is serial)")
    ap.add_argument("--blas-dir", metavar="DIR",
                    help="directory with a libblas.so.3/liblapack.so.3 put first on "
                         "LD_LIBRARY_PATH of both codes (e.g. an extracted "
                         "libopenblas0-serial); default: the system's BLAS alternative")
    ap.add_argument("--cpu-kernels", action="store_true",
                    help="unset OPENBLAS_CORETYPE and OPENBLAS_L2_SIZE for both codes "
                         "(OpenBLAS' own choice of kernels for the CPU)")
    args = ap.parse_args()
    global CPU_KERNELS
    CPU_KERNELS = args.cpu_kernels
    ensure_getfem()
    if args.blas_dir and not args.compare and os.environ.get("G1_BLAS_SET") != "1":
        env = child_env(args.blas_dir)
        env["G1_BLAS_SET"] = "1"
        os.execve(sys.executable, [sys.executable] + sys.argv, env)
    refines = [int(x) for x in args.refine.split(",")]
    if args.compare:
        compare(args, refines)
        return
    for k in refines:
        res = solve_getfem(k, rtol=args.rtol, r_aug=args.r, check=args.check)
        if args.json:
            print(json.dumps(res))
        else:
            print_result(res)


if __name__ == "__main__":
    main()
