#!/usr/bin/env python3
"""A reduced accuracy study (scripts/study.py, small meshes) that checks what the full
studies of docs/accuracy.md show:

  * mesh convergence on a smooth problem (inputs/gravity.xml: a block sagging under its
    own weight on a lubricated base, no contact, no clamped corner) on 8x8x1, 16x16x2,
    32x32x4 bricks: the observed order of the nodal displacement (root mean square over
    the coarse mesh's nodes, differences of successive meshes) is >= 1.7, of the stress
    (sigma_yy min, the element stress at the base) >= 0.8; the errors of the study's
    quantities fall monotonically;
  * the penalty error of contact (G1 on 7x2x3 bricks, penalty method, nodal rule) scales
    like eps2: the least-squares slope of log(error) against log(eps2) over
    1e-2 ... 1e-5 is 1 +- 0.2, and the errors fall monotonically;
  * with the augmented Lagrangian the penalty error vanishes: eps2 = 1e-1 ... 1e-3 (and
    no solve-penalty floor) give the same force to 1e-8;
  * load steps on Coulomb stick/slip rolling (inputs/seed/stick-slip.xml; the stick
    zone makes the answer path dependent): 1, 2, 4 times the scene's steps, errors
    against the finest fall monotonically;
  * the base carries the block's weight (the body force) to 1e-8;
  * the study writes study.csv, study.md and study.png for every study.
"""
import csv
import json
import math
import os
import subprocess
import sys

sys.dont_write_bytecode = True
sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from capstan_test import Test  # noqa: E402

import h5py  # noqa: E402
import numpy as np  # noqa: E402

T = Test("accuracy_study", __doc__)
study_py = os.path.join(T.inputs, "..", "scripts", "study.py")
C = "Capstans/capstan/Contact/"


def study(name, scene, args):
    out = T.path(name)
    cmd = [sys.executable, study_py, T.input(scene), "--out", out, "--capstan", T.capstan] + args
    print("  $ " + " ".join(cmd))
    p = subprocess.run(cmd, capture_output=True, text=True)
    if not T.check(p.returncode == 0, f"{name}: study.py exit status {p.returncode}"):
        print(p.stdout[-3000:] + p.stderr[-3000:])
        return None
    for f in ("study.csv", "study.md", "study.png"):
        path = os.path.join(out, f)
        T.check(os.path.isfile(path) and os.path.getsize(path) > 0, f"{name}: {f} written")
    with open(os.path.join(out, "study.csv")) as f:
        rows = list(csv.DictReader(f))
    print("    " + open(os.path.join(out, "study.md")).read().replace("\n", "\n    "))
    return out, rows


def column(rows, sweep, name):
    return [float(r[name]) if r[name] not in ("", "None") else None for r in rows if r["sweep"] == sweep]


def falls(name, errors):
    ok = all(e is not None for e in errors) and all(a > b for a, b in zip(errors, errors[1:]))
    T.check(ok, f"{name}: errors fall monotonically {['%.2e' % e if e is not None else None for e in errors]}")


# -- mesh convergence on a smooth problem ---------------------------------------
res = study("gravity", "gravity.xml", ["--set", "Mesh/Cells={8,8,1}", "--sweep", "mesh=1,2,4"])
if res:
    out, rows = res
    for q in ("max_ux", "max_uy", "sigma_yy_min", "von_mises_max"):
        falls(f"gravity mesh sweep, {q}", column(rows, "mesh", q + "_error")[:-1])

    def nodal(i):
        with h5py.File(os.path.join(out, "runs", f"mesh-{i}", "fields.h5"), "r") as f:
            s = f["steps"][sorted(f["steps"])[-1]]
            u = s["nodes/displacement"][:]
            X = s["coordinates"][:] - u
        return {tuple(np.round(x, 9)): v for x, v in zip(X, u)}

    # The body force is carried by the base: it pushes up with the block's weight
    # b V = 1 x 0.25 (supports on the body), at every mesh.
    for i in range(3):
        with open(os.path.join(out, "runs", f"mesh-{i}", "summary.json")) as f:
            fy = json.load(f)["steps"][-1]["supports"]["base"]["force"][1]
        T.check(abs(fy - 0.25) < 1e-8 * 0.25, f"mesh {i}: base reaction {fy:.15f} = weight 0.25 (1e-8)")

    fields = [nodal(i) for i in range(3)]
    keys = list(fields[0])
    U = [np.array([f[k] for k in keys]) for f in fields]
    d = [math.sqrt(np.mean(np.sum((U[i + 1] - U[i]) ** 2, axis=1))) for i in range(2)]
    order = math.log2(d[0] / d[1])
    T.check(order >= 1.7, f"displacement order (nodal RMS at the 8x8x1 nodes): {d[0]:.3e} -> {d[1]:.3e}, "
                          f"order {order:.2f} >= 1.7")
    s = column(rows, "mesh", "sigma_yy_min")
    so = math.log2(abs(s[1] - s[0]) / abs(s[2] - s[1]))
    T.check(so >= 0.8, f"stress order (sigma_yy min {s[0]:.6f}, {s[1]:.6f}, {s[2]:.6f}): {so:.2f} >= 0.8")

# -- contact penalty: error ~ eps2, zero with the augmented Lagrangian -------------
eps = [1e-2, 1e-3, 1e-4, 1e-5]
res = study("g1-penalty", "seed/g1.xml",
            ["--set", "Mesh/Cells={7,2,3}", "--set", f"{C}Method=Penalty", "--set", f"{C}Quadrature=Nodal",
             "--reference-set", f"{C}Method=Augmented Lagrangian",
             "--sweep", "penalty=" + ",".join(f"{e:g}" for e in eps)])
if res:
    _, rows = res
    err = column(rows, "penalty", "capstan_force_error")
    falls("penalty sweep, capstan force", err)
    if None not in err:
        x, y = np.log10(eps), np.log10(err)
        slope = np.polyfit(x, y, 1)[0]
        T.check(abs(slope - 1) <= 0.2, f"penalty error ~ eps2^{slope:.3f}: slope within 1 +- 0.2")
res = study("g1-al", "seed/g1.xml",
            ["--set", "Mesh/Cells={7,2,3}", "--set", f"{C}Minimum Solve Penalty=0", "--set", f"{C}Penetration Tolerance=1e-10",
             "--sweep", "penalty=1e-1,1e-2,1e-3"])
if res:
    _, rows = res
    f = column(rows, "penalty", "capstan_force")
    spread = (max(f) - min(f)) / abs(f[-1])
    T.check(spread < 1e-8, f"augmented Lagrangian, eps2 = 1e-1 ... 1e-3: forces {f}, spread {spread:.1e} < 1e-8")

# -- load steps on a path-dependent (friction) case ---------------------------------
res = study("stick-slip-steps", "seed/stick-slip.xml", ["--sweep", "steps=1,2,4"])
if res:
    _, rows = res
    for q in ("capstan_force", "xmin_mean_ux", "max_ux"):
        falls(f"stick/slip steps sweep, {q}", column(rows, "steps", q + "_error")[:-1])

T.finish()
