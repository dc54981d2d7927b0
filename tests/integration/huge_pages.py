#!/usr/bin/env python3
"""capstan runs with its heap in transparent huge pages (src/huge_pages.hpp).

The driver runs itself again at start-up with GLIBC_TUNABLES naming
glibc.malloc.hugetlb=1, so that glibc asks the kernel for huge pages; on the
virtual machines capstan runs on that made G1 4x 1.4x faster on 1 rank
(docs/performance.md, "Huge pages"). summary.json reports each rank's memory in
huge pages at the end of the run (memory.huge_pages_mib). seed/g1.xml, GMRES +
MueLu:

  * by default, every rank (1 and 2 ranks) holds some of its memory in huge pages;
  * with GLIBC_TUNABLES=glibc.malloc.hugetlb=0 (the user's own setting) none, and
    a user's other tunables are kept (huge pages still on);
  * all runs converge, conform to interface.md, and give the same forces and
    stresses as the run without huge pages (1e-12: only the memory differs).

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
T = Test("huge_pages", __doc__)
scene = T.input("seed/g1.xml")
sets = ["Solver/Linear Solver=GMRES", "Solver/Preconditioner=MueLu", "Output/Write Fields=false"]

mode = "unknown"
try:
    with open("/sys/kernel/mm/transparent_hugepage/enabled") as fh:
        mode = fh.read().split("[")[1].split("]")[0]
except (OSError, IndexError):
    pass
print(f"  kernel transparent huge pages: {mode}")

runs = {}
# (label, GLIBC_TUNABLES, ranks, whether capstan asks for huge pages)
for label, tunables, ranks, on in (("default", "", 1, True), ("off", "glibc.malloc.hugetlb=0", 1, False),
                                   ("other tunable kept", "glibc.malloc.tcache_count=7", 1, True),
                                   ("default, 2 ranks", "", 2, True)):
    p, s, out = T.run_scene(scene, label.replace(" ", "-").replace(",", ""), sets=sets, ranks=ranks,
                            env={"GLIBC_TUNABLES": tunables})
    if s is None:
        T.check(False, f"{label}: no summary.json")
        continue
    T.check(s["converged"] is True, f"{label}: converged = {s['converged']} ({s['failure']!r})")
    T.conforms(out, scene)
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

if "off" in runs:
    ref = summary_figures(runs["off"])
    for label, s in runs.items():
        if label == "off" or s["ranks"] != 1:
            continue
        fig = summary_figures(s)
        for key in ("force", "stress", "displacement"):
            worst, where, scale = worst_difference(ref[key], fig[key])
            T.check(worst <= TOL, f"{label} against off: {key} worst {worst:.2e} of {scale:.4g} ({where}) "
                                  f"(<= {TOL:g})")

T.finish()
