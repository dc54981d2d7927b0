#!/usr/bin/env python3
"""A failure on one rank alone ends a 2-rank job instead of hanging it
(src/collective.hpp, FailureAgreement; used after every Newton solve, linear
solve and pressure step).

A rank-local exception inside a collective Trilinos call (the first robustness
campaign's hang: MueLu's set-up failing on one rank) left the other rank inside
that call for good. tests/failure_agreement_stuck.cpp on 2 ranks:

  * stuck: rank 1 fails while rank 0 waits in a barrier rank 1 never enters:
    exit 2, rank 1's message on stderr, within 30 s (patience 2 s);
  * one: rank 1 fails, rank 0 does not: both ranks get rank 1's message, exit 0;
  * both: both fail: both get rank 0's message; none: both get an empty one.
"""
import os
import subprocess
import sys
import time

sys.dont_write_bytecode = True
sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from capstan_test import Test  # noqa: E402

T = Test("failure_agreement", __doc__)
program = os.path.join(os.path.dirname(T.capstan), "tests", "failure_agreement_stuck")
T.check(os.path.exists(program), f"the test program {program} is built")


def run(mode):
    cmd = [T.args.mpiexec] + T.args.mpiexec_flags + ["-n", "2", program, mode]
    start = time.time()
    try:
        p = subprocess.run(cmd, capture_output=True, text=True, timeout=120)
    except subprocess.TimeoutExpired:
        return None, "", "", time.time() - start
    return p.returncode, p.stdout, p.stderr, time.time() - start


rc, out, err, wall = run("stuck")
T.check(rc == 2, f"stuck: exit status {rc} (2; None: hung past 120 s)")
T.check("injected failure on rank 1" in err and "the run stops here" in err,
        f"stuck: rank 1's message on stderr: {err.strip().splitlines()[0][:200] if err.strip() else '(empty)'}")
T.check(wall < 30, f"stuck: ended in {wall:.1f} s (< 30)")
for mode, want in (("one", "failure on rank 1"), ("both", "failure on rank 0"), ("none", "")):
    rc, out, err, wall = run(mode)
    lines = sorted(ln for ln in out.splitlines() if ln.startswith("rank "))
    T.check(rc == 0 and lines == [f"rank 0: agreed '{want}'", f"rank 1: agreed '{want}'"],
            f"{mode}: exit {rc}, {lines} (both '{want}')")
T.finish()
