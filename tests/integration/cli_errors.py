#!/usr/bin/env python3
"""The command line contract (interface.md, "Command line").

Bad input exits 1, the message on stderr names the scene file and the parameter
path, and nothing is written (the output directory is not created; the working
directory gains nothing): malformed XML, an unknown parameter, a wrong type,
Cells with a 0, a missing scene file, an unwritable output directory, a bad
--set; also on 2 ranks. Then: `capstan --version` exits 0, `--help` prints
capstan's usage (not Kokkos' options page), `capstan params`
prints "Pressure Penalty", `capstan validate inputs/uniaxial.xml` exits 0 and
writes nothing.
"""
import os
import re
import sys

sys.dont_write_bytecode = True  # nothing written into the source tree
sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from capstan_test import Test  # noqa: E402

T = Test("cli_errors", __doc__)

GOOD = open(T.input("uniaxial.xml")).read()
scenes = T.path("scenes")
work = T.path("work")          # the driver's working directory: must stay empty
os.makedirs(scenes)
os.makedirs(work)


def scene_file(name, text):
    path = os.path.join(scenes, name)
    with open(path, "w") as f:
        f.write(text)
    return path


def edited(old, new):
    assert old in GOOD, f"test bug: {old!r} not in uniaxial.xml"
    return GOOD.replace(old, new, 1)


def listing(root):
    out = set()
    for d, dirs, files in os.walk(root):
        for n in dirs + files:
            out.add(os.path.relpath(os.path.join(d, n), root))
    return out


def bad_input(label, args, needles, ranks=1, outdir=None):
    """Runs ARGS in WORK; expects exit 1, NEEDLES in stderr, nothing written."""
    before = listing(work)
    p = T.capstan_run(args, ranks=ranks, cwd=work)
    T.check(p.returncode == 1, f"{label}: exit status {p.returncode} (1)")
    err = p.stderr.strip()
    first = err.splitlines()[0] if err else "(stderr empty)"
    for n in needles:
        T.check(n in err, f"{label}: stderr names {n!r}: {first[:300]}")
    after = listing(work)
    T.check(after == before, f"{label}: nothing written in the working directory (new: {sorted(after - before)})")
    if outdir:
        T.check(not os.path.exists(outdir), f"{label}: output directory {outdir} not created")


out = T.path("out-should-not-exist")

# Malformed XML: the element is never closed.
f = scene_file("malformed.xml", GOOD[: GOOD.index("<ParameterList name=\"Time\">")])
bad_input("malformed XML", ["run", f, "--output", out], [f, "XML"], outdir=out)

# Unknown parameter.
f = scene_file("unknown.xml", edited('<Parameter name="Cells"', '<Parameter name="Cels"'))
bad_input("unknown parameter", ["run", f, "--output", out], [f, "Mesh/Cels"], outdir=out)

# Wrong type: a string where a double belongs.
f = scene_file("wrongtype.xml", edited('<Parameter name="c" type="double" value="1"/>',
                                       '<Parameter name="c" type="string" value="soft"/>'))
bad_input("wrong type", ["run", f, "--output", out], [f, "Material/c"], outdir=out)

# Cells with a 0; no --output: the scene's own Output/Directory (relative to the
# working directory) must not appear either.
f = scene_file("cells0.xml", edited('value="{4, 2, 2}"', 'value="{4, 0, 2}"'))
bad_input("Cells with a 0", ["run", f], [f, "Mesh/Cells"], outdir=os.path.join(work, "out"))

# Missing scene file.
f = os.path.join(scenes, "no-such-scene.xml")
bad_input("missing scene file", ["run", f, "--output", out], [f], outdir=out)

# Unwritable output directory.
f = scene_file("good.xml", GOOD)
bad_input("unwritable output /proc/x", ["run", f, "--output", "/proc/x"], [f, "Output/Directory"])
T.check(not os.path.exists("/proc/x"), "/proc/x not created")

# Bad --set: unknown path, unparsable value.
bad_input("--set unknown path", ["run", f, "--output", out, "--set", "Mesh/Cels={8,2,2}"], [f, "Mesh/Cels"],
          outdir=out)
bad_input("--set unparsable value", ["run", f, "--output", out, "--set", "Material/c=abc"], [f, "Material/c"],
          outdir=out)

# The same on 2 ranks (each rank reads the scene; rank 0 checks the directory).
bad_input("Cells with a 0, 2 ranks", ["run", os.path.join(scenes, "cells0.xml"), "--output", out],
          [os.path.join(scenes, "cells0.xml"), "Mesh/Cells"], ranks=2, outdir=out)
bad_input("unwritable output /proc/x, 2 ranks", ["run", f, "--output", "/proc/x"], [f, "Output/Directory"],
          ranks=2)

# validate with a bad scene also exits 1.
bad_input("validate, unknown parameter", ["validate", os.path.join(scenes, "unknown.xml")],
          [os.path.join(scenes, "unknown.xml"), "Mesh/Cels"])

# --- good commands ---------------------------------------------------------
p = T.capstan_run(["--version"], cwd=work)
T.check(p.returncode == 0 and p.stdout.strip() != "",
        f"capstan --version: exit {p.returncode}, prints {p.stdout.strip()!r}")
for args in (["--help"], ["run", "-h"]):
    p = T.capstan_run(args, cwd=work)
    T.check(p.returncode == 0 and p.stdout.startswith("usage: capstan run") and "kokkos" not in p.stdout.lower(),
            f"capstan {' '.join(args)}: exit {p.returncode}, capstan's usage alone (not Kokkos' options): "
            f"{p.stdout[:80]!r}")
p = T.capstan_run(["params"], cwd=work)
T.check(p.returncode == 0, f"capstan params: exit {p.returncode}")
T.check("Pressure Penalty" in p.stdout, f"capstan params prints 'Pressure Penalty' ({len(p.stdout)} characters)")
T.check("Nonzero Pattern" in p.stdout and "Host Only Below" in p.stdout,
        "capstan params prints the MUMPS settings ('Nonzero Pattern', 'Host Only Below')")
before = listing(work)
p = T.capstan_run(["validate", T.input("uniaxial.xml")], cwd=work)
T.check(p.returncode == 0, f"capstan validate inputs/uniaxial.xml: exit {p.returncode} {p.stderr.strip()[:200]}")
T.check("Pressure Penalty" in p.stdout, "validate prints the resolved scene (with 'Pressure Penalty')")
T.check(listing(work) == before, f"validate writes nothing (new: {sorted(listing(work) - before)})")
T.check(not os.path.exists(os.path.join(work, "out")), "validate does not create the scene's Output/Directory")

# validate's scene reads back: validating it prints the same scene, on a box and
# an annulus (whose other mesh type's and support types' defaults are left out),
# with an accuracy preset (applied once).
for name, sets in (("uniaxial.xml", []), ("pinch-roller-slice-steady.xml", ["--set", "Accuracy=Standard"])):
    p = T.capstan_run(["validate", T.input(name)] + sets, cwd=work)
    again = scene_file("validated-" + name, p.stdout)
    q = T.capstan_run(["validate", again], cwd=work)
    strip = lambda text: re.sub(r' id="[0-9]+"', "", text)
    T.check(p.returncode == 0 and q.returncode == 0 and strip(p.stdout) == strip(q.stdout),
            f"validate's {name} {' '.join(sets)} reads back to the same scene: exit {q.returncode}, "
            f"{q.stderr.strip()[:200]}")
    if name.startswith("pinch"):
        T.check('name="Cells" type="Array(int)" value="{8, 128, 2}"' in q.stdout,
                "the preset's cells once ({8, 128, 2} from {4, 64, 1})")

T.finish()
