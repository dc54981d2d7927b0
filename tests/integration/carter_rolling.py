#!/usr/bin/env python3
"""Carter's rolling contact (formulation.md §8, "Analytical checks") in steady rolling:
scripts/carter-check.py on inputs/carter-roller-steady.xml (a coating 20 Hertz
half-widths thick, p0 = 0.1 G, Coulomb mu = 0.8), at the coarse mesh 12x250x1 (nip
nodes a/7 apart) to keep the test short:
  * free-rolling creep below 10% of the largest braked creep;
  * braked creep within 10% of Carter's (mu a / R)(1 - sqrt(1 - Q/(mu P))) at
    Q/(mu P) = 0.25, 0.5, 0.75 (measured at this mesh: -7.5, -6.0, -4.2%; at the
    scene's 24x500x1: -2.4, -1.6, -3.3%, docs/steady-rolling.md);
  * the stick zone at the leading edge, its half-width within 10% (+ half a node
    spacing) of Carter's a sqrt(1 - Q/(mu P)).
The script's exit status carries the checks.
"""
import os
import subprocess
import sys

sys.dont_write_bytecode = True  # nothing written into the source tree
sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from capstan_test import Test  # noqa: E402

T = Test("carter_rolling", __doc__)
script = os.path.normpath(os.path.join(T.inputs, "..", "scripts", "carter-check.py"))
cmd = [sys.executable, script, "--capstan", T.capstan, "--scene", T.input("carter-roller-steady.xml"),
       "--out", T.path("carter"), "--set", "Mesh/Cells={12, 250, 1}"]
print("  $ " + " ".join(cmd))
p = subprocess.run(cmd, capture_output=True, text=True, timeout=600)
print("    " + p.stdout.strip().replace("\n", "\n    "))
T.check(p.returncode == 0, f"carter-check.py: exit status {p.returncode}: {p.stderr.strip()[-500:]}")
T.check(p.stdout.count("PASS") >= 8 and "FAIL" not in p.stdout, "every Carter check passes")
T.finish()
