#!/usr/bin/env python3
"""Bad input, one case per class (interface.md: exit 1, the message names the file
and the parameter path, nothing is written).

Every case runs `capstan run` twice: into an output directory that exists and
holds only a marker file (nothing else may appear, the marker is untouched), and
into one that does not exist (it must not be created); the working directory
must stay empty. Classes: wrong types, out-of-range values, wrong array lengths,
unknown face names, a zero axis direction, Radius <= 0, malformed XML (unclosed,
mismatched, duplicated, too deeply nested, unknown elements), an empty file,
binary garbage, a missing scene file, an output directory under a regular file,
bad NOX, Stratimikos, Belos and Ifpack2 sublists (MueLu's own parameters too, MUMPS'
Precision, also in a MUMPS list the run does not use, and by `capstan validate`), a mesh with fewer cells than ranks, numbers beyond the magnitudes capstan
computes with (1e-25 to 1e25), cells flatter than 1e-6, parameters of another support
type, two supports prescribing one component, and bad --set values.

An output directory another run is writing to: exit 1, the message names the file,
Output/Directory and the other run; the other run ends as it would have, its
fields.h5 whole.

Then the warning for a capstan that can never touch its contact faces: printed
(naming the file and the capstan), the run goes on and exits 0; no warning for
G1, nor for a capstan that starts far away but moves into the body. And the
warning for a Gauss rule named with a penalty stiffer than 1e-3 h / c (Auto
would give it the nodal rule): G1 at Penalty 3e-4 (h / c = 0.5) is warned, with
the file, the parameter and the threshold, and runs; at 5e-4 it is not.
"""
import os
import subprocess
import sys
import time

sys.dont_write_bytecode = True
sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from capstan_test import Test, read_fields  # noqa: E402

T = Test("bad_input", __doc__)
G1 = open(T.input("seed/g1.xml")).read()
scenes = T.path("scenes")
work = T.path("work")
os.makedirs(scenes)
os.makedirs(work)
MARKER = "marker.txt"
counter = [0]


def edited(*pairs):
    text = G1
    for old, new in pairs:
        assert old in text, f"test bug: {old!r} not in g1.xml"
        text = text.replace(old, new, 1)
    return text


def scene_file(name, content):
    path = os.path.join(scenes, name)
    with open(path, "wb" if isinstance(content, bytes) else "w") as f:
        f.write(content)
    return path


def listing(root):
    out = {}
    for d, dirs, files in os.walk(root):
        for n in dirs + files:
            p = os.path.join(d, n)
            out[os.path.relpath(p, root)] = os.stat(p).st_mtime_ns
    return out


def case(label, scene, needles, args=(), ranks=1, outdir_kinds=("existing", "missing")):
    """Runs SCENE with ARGS into an existing (marker only) and a missing output
    directory; expects exit 1, every needle in stderr, nothing written."""
    for kind in outdir_kinds:
        counter[0] += 1
        out = T.path("out", f"{counter[0]}-{kind}")
        if kind == "existing":
            os.makedirs(out)
            with open(os.path.join(out, MARKER), "w") as f:
                f.write("marker\n")
        before_out, before_work = (listing(out) if kind == "existing" else None), listing(work)
        p = T.capstan_run(["run", scene, "--output", out, "--quiet"] + list(args), ranks=ranks, cwd=work)
        tag = f"{label} ({kind} output directory{', 2 ranks' if ranks > 1 else ''})"
        T.check(p.returncode == 1, f"{tag}: exit status {p.returncode} (1)")
        err = p.stderr.strip()
        first = err.splitlines()[0] if err else "(stderr empty)"
        for n in needles:
            T.check(n in err, f"{tag}: stderr names {n!r}: {first[:260]}")
        if kind == "existing":
            T.check(listing(out) == before_out, f"{tag}: output directory holds only the marker "
                                                f"({sorted(listing(out))})")
        else:
            T.check(not os.path.exists(out), f"{tag}: output directory not created")
        T.check(listing(work) == before_work, f"{tag}: working directory unchanged")


def bad_value(label, pairs, needle):
    f = scene_file(label.replace(" ", "_").replace("/", "_") + ".xml", edited(*pairs))
    case(label, f, [f, needle])


C = "Capstans/capstan"
RADIUS = '<Parameter name="Radius"           type="double"        value="2"/>'
AXIS = '<Parameter name="Axis Direction"   type="Array(double)" value="{0, 0, 1}"/>'
POINT = '<Parameter name="Axis Point"       type="Array(double)" value="{3.5, 3.75, 0}"/>'

# --- wrong types ------------------------------------------------------------------
bad_value("type: string for double", [('name="c" type="double" value="1"', 'name="c" type="string" value="soft"')],
          "Material/c")
bad_value("type: text in a double", [('name="c" type="double" value="1"', 'name="c" type="double" value="abc"')],
          "Material/c")
bad_value("type: 5.5 for an int", [('type="int"    value="5"', 'type="int"    value="5.5"')], "Time/Steps")
bad_value("type: Array(double) for Cells", [('type="Array(int)"    value="{14, 4, 6}"',
                                             'type="Array(double)"    value="{14, 4, 6}"')], "Mesh/Cells")
bad_value("type: bad bool", [('<Parameter name="Directory"',
                              '<Parameter name="Write Fields" type="bool" value="maybe"/><Parameter name="Directory"')],
          "Output/Write Fields")
bad_value("type: unknown type", [('name="c" type="double" value="1"', 'name="c" type="complex" value="1"')],
          "Material/c")
bad_value("type: a parameter where a sublist belongs",
          [('<ParameterList name="base">', '<Parameter name="x" type="int" value="1"/><ParameterList name="base">')],
          "Supports/x")

# --- out-of-range values ------------------------------------------------------------
bad_value("range: c = -1", [('name="c" type="double" value="1"', 'name="c" type="double" value="-1"')], "Material/c")
bad_value("range: Steps = 0", [('type="int"    value="5"', 'type="int"    value="0"')], "Time/Steps")
bad_value("range: Steps beyond int", [('type="int"    value="5"', 'type="int"    value="99999999999"')], "Time/Steps")
bad_value("range: Step Size = 0", [('name="Step Size" type="double" value="1"', 'name="Step Size" type="double" value="0"')],
          "Time/Step Size")
bad_value("range: Cells with a 0", [('value="{14, 4, 6}"', 'value="{14, 0, 6}"')], "Mesh/Cells")
bad_value("range: Cells too many", [('value="{14, 4, 6}"', 'value="{100000, 100000, 100000}"')], "Mesh/Cells")
bad_value("range: Max below Min", [('value="{7, 1.75, 4}"', 'value="{7, -1.75, 4}"')], "Mesh/Max")
bad_value("range: nan in Min", [('value="{0, 0, 0}"', 'value="{nan, 0, 0}"')], "Mesh/Min")
bad_value("range: 1e999 in Velocity", [('value="{0, -0.1, 0}"', 'value="{0, -1e999, 0}"')], f"{C}/Velocity")
bad_value("range: negative friction", [('<Parameter name="Law" type="string" value="None"/>',
                                        '<Parameter name="Law" type="string" value="Tanh"/>'
                                        '<Parameter name="Coefficient" type="double" value="-0.1"/>')],
          f"{C}/Friction/Coefficient")
bad_value("range: Checkpoint Every = -1", [('<Parameter name="Directory"',
                                            '<Parameter name="Checkpoint Every" type="int" value="-1"/>'
                                            '<Parameter name="Directory"')], "Output/Checkpoint Every")

# --- wrong array lengths ----------------------------------------------------------------
bad_value("length: Min with 2 values", [('value="{0, 0, 0}"', 'value="{0, 0}"')], "Mesh/Min")
bad_value("length: Axis Point with 4 values", [(POINT, POINT.replace("{3.5, 3.75, 0}", "{3.5, 3.75, 0, 1}"))],
          f"{C}/Axis Point")
bad_value("length: empty Cells", [('value="{14, 4, 6}"', 'value="{}"')], "Mesh/Cells")
bad_value("length: not a list", [('value="{0, 0, 0}"', 'value="0, 0, 0"')], "Mesh/Min")

# --- unknown face names -------------------------------------------------------------------
bad_value("face: support on 'top'", [('name="Face" type="string" value="ymin"', 'name="Face" type="string" value="top"')],
          "Supports/base/Face")
bad_value("face: contact face 'top'", [('value="ymax"', 'value="ymax top"')], f"{C}/Contact Faces")

# --- zero axis direction, radius <= 0 ---------------------------------------------------------
bad_value("axis direction {0, 0, 0}", [(AXIS, AXIS.replace("{0, 0, 1}", "{0, 0, 0}"))], f"{C}/Axis Direction")
bad_value("Radius = 0", [(RADIUS, RADIUS.replace('"2"', '"0"'))], f"{C}/Radius")
bad_value("Radius = -2", [(RADIUS, RADIUS.replace('"2"', '"-2"'))], f"{C}/Radius")

# --- malformed XML ------------------------------------------------------------------------
f = scene_file("unclosed.xml", G1[: G1.index('<ParameterList name="Time">')])
case("XML: unclosed element", f, [f, "XML"])
f = scene_file("mismatched.xml", edited(('<ParameterList name="Time">', '<Foo name="Time">')))
case("XML: mismatched tag", f, [f, "XML"])
f = scene_file("deep.xml", '<ParameterList name="Scene">' + '<ParameterList name="a">' * 100000 +
               '</ParameterList>' * 100000 + '</ParameterList>')
case("XML: 100000 nested lists", f, [f, "nested deeper"])
bad_value("XML: unknown element", [('<ParameterList name="Time">', '<ParameterList name="Time"><Foo/>')], "Time")
bad_value("XML: parameter twice", [('<Parameter name="c" type="double" value="1"/>',
                                    '<Parameter name="c" type="double" value="1"/><Parameter name="c" type="double" value="2"/>')],
          "Material/c")
bad_value("XML: no value attribute", [('<Parameter name="c" type="double" value="1"/>', '<Parameter name="c" type="double"/>')],
          "Material/c")
f = scene_file("text.xml", "just some text\n")
case("XML: plain text", f, [f, "XML"])

# --- empty, binary, missing ---------------------------------------------------------------
f = scene_file("empty.xml", "")
case("empty file", f, [f, "empty"])
f = scene_file("blank.xml", "  \n\t\n")
case("blank file", f, [f, "empty"])
f = scene_file("garbage.xml", bytes((i * 151 + 7) % 256 for i in range(4096)))
case("binary garbage", f, [f, "binary"])
f = scene_file("garbage-tail.xml", G1[:300].encode() + b"\x00\x01\x02\xff" * 64)
case("XML then binary garbage", f, [f, "binary"])
f = os.path.join(scenes, "no-such-scene.xml")
case("missing scene file", f, [f, "cannot open"])
case("a directory as the scene", scenes, [scenes, "directory"])

# --- unwritable output directory: a path under a regular file --------------------------------
good = scene_file("good.xml", G1)
regular = T.path("a-regular-file")
with open(regular, "w") as fh:
    fh.write("not a directory\n")
before = os.stat(regular).st_mtime_ns
for sub in ("out", "deeper/out"):
    target = os.path.join(regular, sub)
    p = T.capstan_run(["run", good, "--output", target, "--quiet"], cwd=work)
    T.check(p.returncode == 1, f"output under a regular file ({sub}): exit status {p.returncode} (1)")
    err = p.stderr.strip()
    T.check(good in err and "Output/Directory" in err,
            f"output under a regular file ({sub}): stderr names the file and 'Output/Directory': {err[:260]}")
    T.check(os.path.isfile(regular) and os.stat(regular).st_mtime_ns == before,
            f"output under a regular file ({sub}): the regular file is untouched")
T.check(listing(work) == {}, "output under a regular file: working directory unchanged")

# --- Trilinos sublists, ranks, --set -----------------------------------------------------------
bad_value("NOX: unknown solver", [('<ParameterList name="Output">',
                                   '<ParameterList name="Solver"><ParameterList name="NOX">'
                                   '<Parameter name="Nonlinear Solver" type="string" value="Bogus"/>'
                                   '</ParameterList></ParameterList><ParameterList name="Output">')], "Solver/NOX")
bad_value("Stratimikos: unknown solver", [('<ParameterList name="Output">',
                                           '<ParameterList name="Solver"><ParameterList name="Stratimikos">'
                                           '<Parameter name="Linear Solver Type" type="string" value="Bogus"/>'
                                           '</ParameterList></ParameterList><ParameterList name="Output">')],
          "Solver/Stratimikos")
# MUMPS' Precision: a word it does not know, and Single for a direct solve (float factors
# would give Newton directions to about 1e-7 only).
for label, solver, value in (("MUMPS: unknown precision", "GMRES", "Quad"),
                             ("MUMPS: single-precision direct solve", "Direct", "Single")):
    lists = "Preconditioner Types" if solver == "GMRES" else "Linear Solver Types"
    bad_value(label, [('<ParameterList name="Output">',
                       f'<ParameterList name="Solver"><Parameter name="Linear Solver" type="string" value="{solver}"/>'
                       + ('<Parameter name="Preconditioner" type="string" value="LU"/>' if solver == "GMRES" else "")
                       + f'<ParameterList name="Stratimikos"><ParameterList name="{lists}"><ParameterList name="MUMPS">'
                       f'<Parameter name="Precision" type="string" value="{value}"/>'
                       '</ParameterList></ParameterList></ParameterList></ParameterList><ParameterList name="Output">')],
              "Precision")
# A MUMPS list the run does not use (GMRES, the default preconditioner) is checked as well, and
# by `capstan validate`, its parameter named in full (randomized sweep 13: Precision = Half ran to
# exit 0, and validate passed any value).
unused = ('<ParameterList name="Output">',
          '<ParameterList name="Solver"><Parameter name="Linear Solver" type="string" value="GMRES"/>'
          '<ParameterList name="Stratimikos"><ParameterList name="Linear Solver Types"><ParameterList name="MUMPS">'
          '<Parameter name="Precision" type="string" value="Half"/>'
          '</ParameterList></ParameterList></ParameterList></ParameterList><ParameterList name="Output">')
MUMPS_PATH = "Solver/Stratimikos/Linear Solver Types/MUMPS/Precision"
bad_value("MUMPS: unused list, unknown precision", [unused], MUMPS_PATH)
f = scene_file("mumps_unused_validate.xml", edited(unused))
p = T.capstan_run(["validate", f], cwd=work)
T.check(p.returncode == 1 and MUMPS_PATH in p.stderr and f in p.stderr,
        f"validate, an unused MUMPS list's unknown precision: exit {p.returncode} (1), names the file and {MUMPS_PATH}")
# MueLu reads its list only when it builds a preconditioner: capstan builds one before
# the run when a scene passes its own (an unknown smoother, a value of the wrong type).
for label, param in (("MueLu: unknown smoother", '<Parameter name="smoother: type" type="string" value="Bogus"/>'),
                     ("MueLu: wrong type", '<Parameter name="aggregation: drop tol" type="string" value="abc"/>')):
    f = scene_file(label.replace(" ", "_").replace(":", "") + ".xml", edited((
        '<ParameterList name="Output">',
        '<ParameterList name="Solver"><Parameter name="Linear Solver" type="string" value="GMRES"/>'
        '<Parameter name="Preconditioner" type="string" value="MueLu"/><ParameterList name="Stratimikos">'
        '<ParameterList name="Preconditioner Types"><ParameterList name="MueLu">' + param +
        '</ParameterList></ParameterList></ParameterList></ParameterList><ParameterList name="Output">')))
    case(label, f, [f, "Solver/Stratimikos/Preconditioner Types"])
    case(label + ", 2 ranks", f, [f, "Solver/Stratimikos/Preconditioner Types"], ranks=2, outdir_kinds=("missing",))
f = scene_file("one-cell.xml", edited(('value="{14, 4, 6}"', 'value="{1, 1, 1}"')))
case("one cell on 2 ranks", f, [f, "Mesh/Cells"], ranks=2)
case("--set: 1e999", good, [good, "Material/c"], args=["--set", "Material/c=1e999"])
case("--set: list with a word", good, [good, "Mesh/Cells"], args=["--set", "Mesh/Cells={4,two,2}"])
case("--set: a bool that is neither", good, [good, "Output/Write Fields", "bool"],
     args=["--set", "Output/Write Fields=maybe"])
case("--set: 2 ranks, negative radius", good, [good, f"{C}/Radius"], args=["--set", f"{C}/Radius=-1"], ranks=2)

# --- supports: a parameter of another type, one component held twice --------------------
case("Stiffness on a Fixed support", good, [good, "Supports/base/Stiffness", "Foundation"],
     args=["--set", "Supports/base/Stiffness=2"])
case("Velocity on a Fixed support", good, [good, "Supports/base/Velocity", "Displacement"],
     args=["--set", "Supports/base/Velocity={0, 1, 0}"])
f = scene_file("two-supports-one-face.xml", edited(('<ParameterList name="base">',
    '<ParameterList name="push"><Parameter name="Face" type="string" value="ymin"/>'
    '<Parameter name="Type" type="string" value="Displacement"/><Parameter name="Components" type="string" value="y"/>'
    '<Parameter name="Velocity" type="Array(double)" value="{0, 0.1, 0}"/></ParameterList><ParameterList name="base">')))
case("two supports holding one face's y", f, [f, "Supports/", "/Face", "ymin"])
# --- Solver/Belos and Solver/Ifpack2: passed through, names checked ---------------------
KRYLOV = ["--set", "Solver/Linear Solver=GMRES", "--set", "Solver/Preconditioner=ILU"]
case("Solver/Belos: an unknown name", good, [good, "Solver/Belos/Bogus"], args=KRYLOV + ["--set", "Solver/Belos/Bogus=1"])
case("Solver/Belos: a word for an int", good, [good, "Solver/Belos/Num Blocks"],
     args=KRYLOV + ["--set", "Solver/Belos/Num Blocks=many"])
case("Solver/Belos: a value Belos refuses (Num Blocks = 0)", good, [good, "Solver/Belos", "Num Blocks"],
     args=KRYLOV + ["--set", "Solver/Belos/Num Blocks=0"])
case("Solver/Ifpack2: an unknown name", good, [good, "Solver/Ifpack2", "bogus"],
     args=KRYLOV + ["--set", "Solver/Ifpack2/bogus=0"])
# Ifpack2's block relaxation crashes on capstan's matrices in Trilinos 13.2: refused
# wherever it is named (as MueLu's smoother, or Ifpack2's own).
ML = "Solver/Stratimikos/Preconditioner Types/MueLu"
case("MueLu: block relaxation as smoother", good, [good, f"{ML}/smoother: type", "block relaxation"],
     args=["--set", "Solver/Linear Solver=GMRES", "--set", "Solver/Preconditioner=MueLu",
           "--set", f"{ML}/smoother: type=BLOCK_RELAXATION"])
case("Solver/Stratimikos: Ifpack2's block relaxation", good,
     [good, "Solver/Stratimikos/Preconditioner Types/Ifpack2/Prec Type", "block relaxation"],
     args=KRYLOV + ["--set", "Solver/Stratimikos/Preconditioner Types/Ifpack2/Prec Type=Block Relaxation"])

# --- a capstan that can never touch its faces: warning, the run goes on ------------------------
far = scene_file("far.xml", edited((POINT, POINT.replace("{3.5, 3.75, 0}", "{3.5, 100, 0}"))))
p, s, _ = T.run_scene(far, "far", sets=["Time/Steps=1"])
err = p.stderr.strip()
T.check("WARNING" in err and far in err and "Capstans/capstan" in err and "never touch" in err,
        f"unreachable capstan: warning naming the file and the capstan: {err[:300]}")
T.check(s is not None and s["converged"] and s["steps"][0]["capstans"]["capstan"]["contact_points"] == 0,
        "unreachable capstan: the run goes on (converged, 0 contact points)")
p = T.capstan_run(["validate", far], cwd=work)
T.check(p.returncode == 0 and "never touch" in p.stderr, f"unreachable capstan: validate warns too, exit {p.returncode}")
# Near misses are not flagged: G1 itself, a capstan that starts 40 away but moves
# 50 towards the body, a capstan far along its own (infinite) axis, and one whose
# gap (1) is within the body's size (the body could deform towards it).
for label, text in (("G1", G1),
                    ("moving in", edited((POINT, POINT.replace("{3.5, 3.75, 0}", "{3.5, 40, 0}")),
                                         ('value="{0, -0.1, 0}"', 'value="{0, -10, 0}"'))),
                    ("far along its axis", edited((POINT, POINT.replace("{3.5, 3.75, 0}", "{3.5, 3.75, 1000}")))),
                    ("gap 1", edited((POINT, POINT.replace("{3.5, 3.75, 0}", "{3.5, 4.75, 0}")),
                                     ('value="{0, -0.1, 0}"', 'value="{0, 0, 0}"')))):
    f = scene_file(f"near-{label.replace(' ', '_')}.xml", text)
    p = T.capstan_run(["validate", f], cwd=work)
    T.check(p.returncode == 0 and "WARNING" not in p.stderr,
            f"no warning for {label}: exit {p.returncode}, stderr {p.stderr.strip()[:200]!r}")
T.check(listing(work) == {}, "validate writes nothing")
# --- a Gauss rule with a penalty stiff enough to lock it: warning, the run goes on ---------
for penalty, warned in (("3e-4", True), ("5e-4", False)):
    p, s, _ = T.run_scene(T.input("seed/g1.xml"), f"gauss-{penalty}",
                          sets=["Capstans/capstan/Contact/Method=Penalty", f"Capstans/capstan/Contact/Penalty={penalty}",
                                "Capstans/capstan/Contact/Quadrature=Gauss 2x2", "Time/Steps=1"])
    err = p.stderr.strip()
    says = ("WARNING" in err and T.input("seed/g1.xml") in err and "Capstans/capstan/Contact/Quadrature" in err
            and "0.001 h / c = 0.0005" in err)
    T.check(says == warned and ("WARNING" in err) == warned and s is not None and s["converged"],
            f"Gauss 2x2 at Penalty {penalty}: {'a' if warned else 'no'} warning, converged: {err[:300]!r}")
# --- rigid cores: singular set-ups and misplaced parameters (on the roller slice) ----
SLICE = T.input("pinch-roller-slice.xml")


def roller_case(label, sets, needle):
    case(label, SLICE, [SLICE, needle], args=[a for kv in sets for a in ("--set", kv)])


roller_case("core: free rotation, no friction", ["Capstans/capstan/Friction/Law=None"], "Supports/core/Rotation")
roller_case("core: free along the capstan axis", ["Supports/core/Free Translation=yz"], "Supports/core/Free Translation")
roller_case("core: force along a held direction", ["Supports/core/Force={1, -0.25, 0}"], "Supports/core/Force")
roller_case("core: torque without free rotation", ["Supports/core/Rotation=Fixed", "Supports/core/Torque=0.1"],
            "Supports/core/Torque")
roller_case("core: unknown rotation", ["Supports/core/Rotation=Spinning"], "Supports/core/Rotation")
roller_case("core: zero axis", ["Supports/core/Axis Direction={0, 0, 0}"], "Supports/core/Axis Direction")
roller_case("core: negative contact smoothing", ["Capstans/capstan/Contact/Smoothing=-1"], "Capstans/capstan/Contact/Smoothing")
roller_case("rigid-core parameter on a Roller", ["Supports/front/Torque=1"], "Supports/front/Torque")
roller_case("a ring cell of half the ring or more (3 cells, a fine sector)", ["Mesh/Cells={1, 3, 1}"],
            "Mesh/Cells")
roller_case("a magnitude beyond 1e25 (c = 1e300)", ["Material/c=1e300"], "Material/c")
roller_case("a magnitude below 1e-25 (Length = 1e-300)", ["Mesh/Length=1e-300"], "Mesh/Length")
roller_case("flat cells (Outer Cell Ratio 1e-20)", ["Mesh/Outer Cell Ratio=1e-20"], "Mesh")
roller_case("flat cells (a Fine Sector of 1e-20 degrees)", ["Mesh/Fine Sector={-90, 1e-20, 0.5}"], "Mesh")
roller_case("Components on a Rigid Core", ["Supports/core/Components=y"], "Supports/core/Components")
roller_case("Stiffness on a Rigid Core", ["Supports/core/Stiffness=3"], "Supports/core/Stiffness")
STEADY = T.input("pinch-roller-slice-steady.xml")
case("steady rolling, a capstan across the annulus axis", STEADY, [STEADY, f"{C}/Axis Direction"],
     args=["--set", f"{C}/Axis Direction={{0, 1, 0}}"])
for pc in ("MueLu", "Jacobi"):
    case(f"steady rolling, a free-turning core, GMRES + {pc}", STEADY, [STEADY, "Solver/Preconditioner", pc],
         args=["--set", "Solver/Linear Solver=GMRES", "--set", f"Solver/Preconditioner={pc}"])

# --- an output directory in use by another run ------------------------------------------
# A 10-step steady brake sweep (a few seconds) holds the directory; a second run into it
# must stop before it touches anything (HDF5 would truncate the first run's fields.h5).
busy = T.path("out", "busy")
sweep = T.input("pinch-roller-steady.xml")
first = subprocess.Popen(T.command(["run", sweep, "--output", busy, "--quiet", "--set", "Time/Steps=10",
                                    "--set", "Supports/core/Torque=18",
                                    "--set", "Supports/core/Torque Ramp Time=0.010"]),
                         stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True, cwd=work)
lock = os.path.join(busy, ".capstan-lock")
for _ in range(600):
    if os.path.exists(os.path.join(busy, "fields.h5")) or first.poll() is not None:
        break
    time.sleep(0.02)
second = T.capstan_run(["run", T.input("pinch-roller-slice-steady.xml"), "--output", busy, "--quiet"], cwd=work)
running = first.poll() is None
_, first_err = first.communicate(timeout=600)
T.check(running, "the first run was still running when the second started (else the case tests nothing)")
T.check(second.returncode == 1 and all(n in second.stderr for n in ("pinch-roller-slice-steady.xml", "Output/Directory",
                                                                     f"another capstan run is writing there (process {first.pid})")),
        f"a second run into a busy directory: exit {second.returncode}, {second.stderr.strip()[:300]}")
T.check(first.returncode == 0, f"the first run ends as it would: exit {first.returncode}, {first_err.strip()[-300:]}")
fields = os.path.join(busy, "fields.h5")
steps = max(read_fields(fields)) if first.returncode == 0 and os.path.exists(fields) else None
T.check(steps == 10, f"its fields.h5 holds its steps to 10 ({steps})")
T.check(not os.path.exists(lock), "the lock file is gone once the run ends")
T.check(listing(work) == {}, "the working directory stays empty")

T.finish()
