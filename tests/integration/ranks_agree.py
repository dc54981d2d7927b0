#!/usr/bin/env python3
"""A distributed run gives the results of a serial one (interface.md: "mpiexec -n 2
capstan run SCENE.xml  # distributed run, same results as one rank").

inputs/uniaxial.xml, inputs/shear.xml and G1 (inputs/seed/g1.xml, contact with the
augmented Lagrangian), H1 (tanh friction) and H5 (Coulomb friction) on 1 and 2 ranks:
  * summary.json: "ranks" is 1 and 2; both converge with the same number of steps;
  * final stress, pressure and von Mises extrema, the face means of the
    displacement and every support and capstan force of every step agree to 1e-8
    relative to the largest magnitude of their kind;
  * fields.h5: the final displacement of every node, matched by its reference
    coordinates (node order depends on the partition), agrees to 1e-8 x max |u|.
METIS splits the 2-rank runs of these thin meshes by default (Mesh/Partition = Auto;
summary.json mesh.partition; mesh.cut_faces is 0 on 1 rank, above 0 on 2). Then G1 with Solver/Linear Solver = Direct on 2 ranks: MUMPS
factors the distributed matrix: every summary figure agrees with 1 rank's Auto run
(GMRES with MUMPS' LU as preconditioner), and the Newton iterations of every step are
those of Direct on 1 rank (the monolithic pressure loop's steps stop at a GMRES tolerance,
so an exact and a preconditioned solve may take a step more or less). And G1 with Mesh/Partition = Slabs on 2 ranks: 56 faces cut (one plane of
14 x 4), every summary figure as on 1 rank. Auto on 2 ranks, one step: G1 with 32 layers
(16 a rank) is split into slabs (56 faces cut), with 30 layers (15 a rank) by METIS (which
here finds a plane too).
Repeatability (docs/performance.md, "Repeatability"): G1 run again on 1 rank and on 2
(below 2,000 unknowns MUMPS factors on rank 0 alone) gives a summary.json equal to the
first run's to the last digit, timings and memory aside.
"""
import os
import sys

sys.dont_write_bytecode = True  # nothing written into the source tree
sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from capstan_test import Test, by_reference_coordinates, read_fields, summary_figures, worst_difference  # noqa: E402

TOL = 1e-8
T = Test("ranks_agree", __doc__)
serial = {}  # scene -> its 1-rank summary
distributed = {}  # scene -> its 2-rank summary

for name in ("uniaxial.xml", "shear.xml", "seed/g1.xml", "seed/h1.xml", "seed/h5.xml"):
    scene = T.input(name)
    results = {}
    for ranks in (1, 2):
        p, s, out = T.run_scene(scene, f"{os.path.basename(name)[:-4]}-{ranks}", ranks=ranks)
        if s is None:
            T.check(False, f"{name} on {ranks} rank(s): no summary.json")
            continue
        T.check(s["ranks"] == ranks, f"{name} on {ranks} rank(s): summary ranks = {s['ranks']} ({ranks})")
        T.check(s["converged"] is True, f"{name} on {ranks} rank(s): converged = {s['converged']} ({s['failure']!r})")
        T.conforms(out, scene)
        results[ranks] = (s, out)
    if len(results) < 2:
        continue
    (s1, out1), (s2, out2) = results[1], results[2]
    serial[name], distributed[name] = s1, s2
    T.check(len(s1["steps"]) == len(s2["steps"]),
            f"{name}: {len(s1['steps'])} steps on 1 rank, {len(s2['steps'])} on 2")
    sizes = ("nodes", "elements", "dofs", "contact_faces")
    T.check(all(s1["mesh"][k] == s2["mesh"][k] for k in sizes), f"{name}: mesh sizes {s1['mesh']} vs {s2['mesh']}")
    T.check(s1["mesh"]["cut_faces"] == 0 < s2["mesh"]["cut_faces"] and s2["mesh"]["partition"] == "METIS",
            f"{name}: METIS by default, faces cut: 1 rank {s1['mesh']['cut_faces']}, 2 ranks {s2['mesh']['cut_faces']}")
    g1, g2 = summary_figures(s1), summary_figures(s2)
    for group in g1:
        missing = set(g1[group]) ^ set(g2[group])
        if missing:
            T.check(False, f"{name}: {group} figures present in one run only: {sorted(missing)[:5]}")
            continue
        worst, k, scale = worst_difference(g1[group], g2[group])
        T.check(worst <= TOL,
                f"{name}: {group}: {len(g1[group])} figures, scale {scale:.4g}, worst rel. diff {worst:.2e} "
                f"({k}: 1 rank {g1[group][k]!r}, 2 ranks {g2[group][k]!r})")
    # Nodal displacements, matched by reference coordinates.
    try:
        f1 = read_fields(os.path.join(out1, "fields.h5"))
        f2 = read_fields(os.path.join(out2, "fields.h5"))
    except Exception as e:  # noqa: BLE001
        T.check(False, f"{name}: cannot read fields.h5: {e}")
        continue
    T.check(sorted(f1) == sorted(f2), f"{name}: fields.h5 steps {sorted(f1)} vs {sorted(f2)}")
    last = max(f1)
    u1 = by_reference_coordinates(f1[last]["X"], f1[last]["u"])
    u2 = by_reference_coordinates(f2[last]["X"], f2[last]["u"])
    T.check(len(u1) == len(f1[last]["X"]) and set(u1) == set(u2),
            f"{name}: {len(u1)} nodes on 1 rank, {len(u2)} on 2, same reference coordinates: {set(u1) == set(u2)}")
    if set(u1) == set(u2):
        umax = max(abs(x) for v in u1.values() for x in v)
        worst = max(abs(a - b) for key in u1 for a, b in zip(u1[key], u2[key])) / umax
        T.check(worst <= TOL, f"{name}: fields.h5 step {last}: nodal displacement, {len(u1)} nodes, "
                f"max |u| = {umax:.4g}, worst diff / max |u| = {worst:.2e}")

# Solver/Linear Solver = Direct on 2 ranks: MUMPS on the distributed matrix (Amesos2's
# KLU2 solved it wrongly in Trilinos 13.2), the answer and the iterations of 1 rank.
g1 = T.input("seed/g1.xml")
_, direct1, _ = T.run_scene(g1, "g1-direct-1", sets=["Solver/Linear Solver=Direct", "Output/Write Fields=false"])
p, s, out = T.run_scene(g1, "g1-direct-2", sets=["Solver/Linear Solver=Direct", "Output/Write Fields=false"], ranks=2)
if s is not None and direct1 is not None and "seed/g1.xml" in serial:
    T.check(s["converged"] is True, f"G1, Direct on 2 ranks: converged = {s['converged']} ({s['failure']!r})")
    T.conforms(out, g1)
    for group, ref in summary_figures(serial["seed/g1.xml"]).items():
        worst, k, scale = worst_difference(ref, summary_figures(s)[group])
        T.check(worst <= TOL, f"G1, Direct on 2 ranks: {group} agrees with 1 rank: worst {worst:.2e} ({k}) (<= {TOL:g})")
    newton1 = [st["newton_iterations"] for st in direct1["steps"]]
    newton2 = [st["newton_iterations"] for st in s["steps"]]
    T.check(newton1 == newton2,
            f"G1, Direct on 2 ranks: Newton iterations per step {newton2} as Direct on 1 rank {newton1}")
else:
    T.check(False, "G1, Direct on 2 ranks: no summary.json (or no 1-rank run to compare with)")

# Mesh/Partition = Slabs on 2 ranks: G1's 6 layers of 14 x 4 cells in two slabs of 3,
# one plane of 56 faces between them; the same answer as 1 rank.
p, s, out = T.run_scene(g1, "g1-slabs-2", sets=["Mesh/Partition=Slabs", "Output/Write Fields=false"], ranks=2)
if s is not None and "seed/g1.xml" in serial:
    T.check(s["converged"] is True, f"G1, slabs on 2 ranks: converged = {s['converged']} ({s['failure']!r})")
    T.conforms(out, g1)
    T.check(s["mesh"]["partition"] == "Slabs" and s["mesh"]["cut_faces"] == 14 * 4,
            f"G1, slabs on 2 ranks: mesh.partition {s['mesh']['partition']!r}, cut_faces {s['mesh']['cut_faces']} (56)")
    for group, ref in summary_figures(serial["seed/g1.xml"]).items():
        worst, k, scale = worst_difference(ref, summary_figures(s)[group])
        T.check(worst <= TOL, f"G1, slabs on 2 ranks: {group} agrees with 1 rank: worst {worst:.2e} ({k}) (<= {TOL:g})")
else:
    T.check(False, "G1, slabs on 2 ranks: no summary.json (or no 1-rank run to compare with)")

# Mesh/Partition = Auto: slabs once each rank's slab is 16 cell layers thick.
for layers, want in ((32, "Slabs"), (30, "METIS")):
    p, s, out = T.run_scene(g1, f"g1-auto-{layers}", ranks=2,
                            sets=[f"Mesh/Cells={{14,4,{layers}}}", "Time/Steps=1", "Output/Write Fields=false"])
    if s is None:
        T.check(False, f"G1 with {layers} layers, Auto on 2 ranks: no summary.json")
        continue
    cut = s["mesh"]["cut_faces"]
    T.check(s["converged"] is True and s["mesh"]["partition"] == want and (cut == 14 * 4 or want == "METIS"),
            f"G1 with {layers} layers, Auto on 2 ranks: mesh.partition {s['mesh']['partition']!r} ({want}), "
            f"cut_faces {cut}, converged {s['converged']}")



def without_timings(d):
    """summary.json less what a run measures of itself (seconds, memory, the build)."""
    if isinstance(d, dict):
        return {k: without_timings(v) for k, v in d.items()
                if k not in ("timing", "memory", "wall_seconds", "seconds", "version")}
    if isinstance(d, list):
        return [without_timings(x) for x in d]
    return d


for ranks, first in ((1, serial), (2, distributed)):
    p, s, out = T.run_scene(g1, f"g1-again-{ranks}", ranks=ranks)
    if s is None or "seed/g1.xml" not in first:
        T.check(False, f"G1 again on {ranks} rank(s): no summary.json (or no first run)")
        continue
    a, b = without_timings(first["seed/g1.xml"]), without_timings(s)
    differing = [k for k in a if a[k] != b.get(k)]
    T.check(a == b, f"G1 again on {ranks} rank(s): summary.json equal to the first run's, timings aside "
                    f"(differing: {differing})")

T.finish()
