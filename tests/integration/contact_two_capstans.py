#!/usr/bin/env python3
"""Several capstans in one scene (inputs/two-capstans.xml): two capstans at x = 1.75 and
x = 5.25 press the G1 block; the right one also lists xmax as a candidate face.

  * it converges and conforms; each capstan is its own effect (brick, contact:left,
    contact:right and nothing else); mesh.contact_faces counts the union of candidate
    faces, 14 x 6 (ymax) + 4 x 6 (xmax) = 108;
  * equilibrium at every step: base reaction = left force + right force (1e-8);
  * mirror symmetry about x = 3.5: the two capstan forces are mirror images (x opposite,
    y equal) to 1e-8 of |F|, with the same contact point counts;
  * max_penetration <= 5e-5 for both;
  * capstans may have any name (interface.md): with the left one named 'left, "A"' the
    CSV files quote it, so history.csv's and nip.csv's rows keep their header's columns
    and nip.csv's capstan column reads back as the name (1 step).
"""
import os
import sys

sys.dont_write_bytecode = True
sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from capstan_test import Test  # noqa: E402

T = Test("contact_two_capstans", __doc__)
scene = T.input("two-capstans.xml")
p, s, out = T.run_scene(scene, "two")
if s is None:
    T.fatal("no summary.json")
T.check(s["converged"] is True, f"converged = {s['converged']} ({s['failure']!r})")
T.conforms(out, scene)
T.check(sorted(s["effects"]) == ["brick", "contact:left", "contact:right"], f"effects: {sorted(s['effects'])}")
T.check(s["mesh"]["contact_faces"] == 108, f"mesh.contact_faces = {s['mesh']['contact_faces']} (108)")
for st in s["steps"]:
    L, R = st["capstans"]["left"], st["capstans"]["right"]
    B = st["supports"]["base"]["force"]
    scale = max(abs(x) for x in B)
    eq = max(abs(B[i] - L["force"][i] - R["force"][i]) for i in range(3)) / scale
    T.check(eq <= 1e-8, f"step {st['step']}: base {B[1]:.10g} = left + right {L['force'][1] + R['force'][1]:.10g} "
            f"(rel. {eq:.1e})")
    mirror = [-R["force"][0], R["force"][1], R["force"][2]]
    sym = max(abs(a - b) for a, b in zip(L["force"], mirror)) / max(abs(x) for x in L["force"])
    T.check(sym <= 1e-8 and L["contact_points"] == R["contact_points"],
            f"step {st['step']}: left {L['force'][:2]} mirrors right {R['force'][:2]} (rel. {sym:.1e}), "
            f"points {L['contact_points']} / {R['contact_points']}")
    T.check(max(L["max_penetration"], R["max_penetration"]) <= 5e-5,
            f"step {st['step']}: max_penetration {L['max_penetration']:.1e}, {R['max_penetration']:.1e} <= 5e-5")

import csv  # noqa: E402

NAME = 'left, "A"'
with open(scene) as fh:
    text = fh.read()
named = T.path("two-named.xml")
with open(named, "w") as fh:
    fh.write(text.replace('<ParameterList name="left">', '<ParameterList name="left, &quot;A&quot;">', 1))
p, s2, out2 = T.run_scene(named, "named", sets=["Time/Steps=1", "Output/Write Fields=false"])
if s2 is not None:
    T.check(NAME in s2["steps"][0]["capstans"], f"summary.json names the capstan {NAME!r}")
    for name in ("history.csv", "nip.csv"):
        with open(os.path.join(out2, name)) as fh:
            rows = list(csv.reader(fh))
        T.check(len(rows) > 1 and all(len(r) == len(rows[0]) for r in rows),
                f"{name}: every row has the header's {len(rows[0])} columns")
    with open(os.path.join(out2, "nip.csv")) as fh:
        names = {r["capstan"] for r in csv.DictReader(fh)}
    T.check(names == {NAME, "right"}, f"nip.csv's capstans read back: {sorted(names)}")
T.finish()
