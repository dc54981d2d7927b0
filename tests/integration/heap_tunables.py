#!/usr/bin/env python3
"""capstan runs with glibc malloc settings of its own (src/heap_tunables.hpp).

The launcher (build/capstan) starts the solver program with GLIBC_TUNABLES naming
glibc.malloc.hugetlb=1 (the heap in transparent huge pages), glibc.malloc.mmap_max=0
and a large glibc.malloc.trim_threshold (freed memory stays with the process, so
the GMRES basis and MueLu's matrices, allocated anew for every solve and set-up,
do not make the kernel zero fresh pages each time). On the virtual machines
capstan runs on that made G1 4x 1.4x faster on 1 rank, and G1 8x's first load
step 1.1x (1 rank) and 1.3x (2 ranks) faster again (docs/performance.md, "Huge
pages", "Page faults"). summary.json reports each rank's memory in huge pages
(memory.huge_pages_mib) and its page faults (memory.page_faults). seed/g1.xml,
GMRES + MueLu:

  * by default, every rank (1 and 2 ranks) holds some of its memory in huge pages;
  * with GLIBC_TUNABLES=glibc.malloc.hugetlb=0 (the user's own setting) none, and
    a user's other tunables are kept (huge pages still on);
  * on G1 3x (a GMRES basis of 51 MB, above glibc's 32 MiB mapping limit), one
    load step takes at most half the page faults of a run that sets glibc's own
    defaults back (glibc.malloc.mmap_max=65536, trim_threshold=131072);
  * all runs converge, conform to interface.md, and give the same forces and
    stresses as the run with glibc's defaults (1e-12: only the memory differs).

Where the kernel has huge pages off ([never]) the default run must report 0;
where it gives them to every program ([always]) the run without is not checked
for 0.
"""
import os
import sys

sys.dont_write_bytecode = True  # nothing written into the source tree
sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from capstan_test import Test, summary_figures, worst_difference  # noqa: E402

TOL = 1e-12
T = Test("heap_tunables", __doc__)
scene = T.input("seed/g1.xml")
sets = ["Solver/Linear Solver=GMRES", "Solver/Preconditioner=MueLu", "Output/Write Fields=false"]

mode = "unknown"
try:
    with open("/sys/kernel/mm/transparent_hugepage/enabled") as fh:
        mode = fh.read().split("[")[1].split("]")[0]
except (OSError, IndexError):
    pass
print(f"  kernel transparent huge pages: {mode}")


def run(label, tunables, ranks=1, extra=()):
    """One run with GLIBC_TUNABLES set as given; checks that it converged and conforms."""
    return T.converged_run(scene, label.replace(" ", "-").replace(",", "").replace("'", ""), label,
                           sets=sets + list(extra), ranks=ranks, env={"GLIBC_TUNABLES": tunables})


def same_answers(label, ref, s):
    """Forces, stresses and displacements as in the reference run, to TOL."""
    a, b = summary_figures(ref), summary_figures(s)
    for key in ("force", "stress", "displacement"):
        worst, where, scale = worst_difference(a[key], b[key])
        T.check(worst <= TOL, f"{label}: {key} worst {worst:.2e} of {scale:.4g} ({where}) (<= {TOL:g})")


runs = {}
# (label, GLIBC_TUNABLES, ranks, whether capstan asks for huge pages)
for label, tunables, ranks, on in (("default", "", 1, True), ("off", "glibc.malloc.hugetlb=0", 1, False),
                                   ("other tunable kept", "glibc.malloc.tcache_count=7", 1, True),
                                   ("default, 2 ranks", "", 2, True)):
    s = run(label, tunables, ranks)
    if s is None:
        continue
    huge = s["memory"].get("huge_pages_mib")
    if not T.check(isinstance(huge, list) and len(huge) == ranks, f"{label}: memory.huge_pages_mib per rank: {huge}"):
        continue
    print(f"  {label}: huge pages {huge} MiB, peak {s['memory']['peak_rss_mib']} MiB")
    if mode == "never":
        T.check(all(h == 0 for h in huge), f"{label}: no huge pages where the kernel gives none: {huge}")
    elif on:
        T.check(all(h > 0 for h in huge), f"{label}: every rank holds memory in huge pages: {huge} MiB")
    elif mode != "always":
        T.check(all(h == 0 for h in huge), f"{label}: GLIBC_TUNABLES=glibc.malloc.hugetlb=0 turns them off: {huge}")
    runs[label] = s

for label, s in runs.items():
    if "off" in runs and label != "off" and s["ranks"] == 1:
        same_answers(f"{label} against off", runs["off"], s)

# Page faults: capstan's settings against glibc's defaults set back by the user.
glibc_defaults = "glibc.malloc.mmap_max=65536:glibc.malloc.trim_threshold=131072"
faults = {}
for label, tunables in (("faults, capstan's heap", ""), ("faults, glibc's defaults", glibc_defaults)):
    s = run(label, tunables, extra=["Mesh/Cells={42,12,18}", "Time/Steps=1"])
    f = None if s is None else s["memory"].get("page_faults")
    if s is not None and T.check(isinstance(f, list) and len(f) == 1 and f[0] > 0,
                                 f"{label}: memory.page_faults per rank: {f}"):
        faults[label] = s
        print(f"  {label}: {f[0]:.0f} page faults, peak {s['memory']['peak_rss_mib']} MiB")
if len(faults) == 2:
    mine, theirs = (faults[k]["memory"]["page_faults"][0] for k in faults)
    T.check(mine <= 0.5 * theirs, f"capstan's heap takes at most half glibc's page faults: {mine:.0f} vs {theirs:.0f}")
    same_answers("faults runs", faults["faults, glibc's defaults"], faults["faults, capstan's heap"])

T.finish()
