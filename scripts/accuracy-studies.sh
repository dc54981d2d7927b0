#!/usr/bin/env bash
# The accuracy studies of docs/accuracy.md: G1 and H1, every knob, with scripts/study.py,
# and the pinch-roller nip's speed ratio with scripts/nip-accuracy.py.
#   scripts/accuracy-studies.sh            (about 45 min on 2 cores; the G1 4x mesh
#                                           (46 s today) is taken from out/g1-refine-4
#                                           when scripts/g1-refinement.sh has already
#                                           run it)
# Results: out/study-<case>/study.{csv,md,png}. Runs already done are reused.
set -euo pipefail
cd "$(dirname "$0")/.."
study() { /usr/bin/python3 scripts/study.py "$@"; }
contact=capstan_force,peak_pressure,contact_width,max_ux,von_mises_max,sigma_yy_min,max_penetration

# The 4x refined G1 is taken from scripts/g1-refinement.sh if it has run it
# (same scene, same settings).
if [ -f out/g1-refine-4/summary.json ] && [ ! -f out/study-g1/runs/mesh-2/summary.json ]; then
  mkdir -p out/study-g1/runs && cp -r out/g1-refine-4 out/study-g1/runs/mesh-2
fi

# G1: augmented Lagrangian (the scene's method). Mesh, load steps, Newton tolerance,
# penetration tolerance.
study inputs/seed/g1.xml --out out/study-g1 --columns $contact \
  --sweep mesh=1,2,4 --sweep steps=1,2,4 \
  --sweep "Solver/Newton Relative Tolerance=1e-4,1e-6,1e-8,1e-10" \
  --sweep "Capstans/capstan/Contact/Penetration Tolerance=1e-1,1e-2,1e-3,1e-5"
# G1 with the penalty method (nodal rule; the quadrature sweep at eps2 = 1e-3): its
# error against the augmented Lagrangian.
study inputs/seed/g1.xml --out out/study-g1-penalty --columns $contact \
  --set "Capstans/capstan/Contact/Method=Penalty" --set "Capstans/capstan/Contact/Quadrature=Nodal" \
  --reference-set "Capstans/capstan/Contact/Method=Augmented Lagrangian" \
  --reference-set "Capstans/capstan/Contact/Quadrature=Nodal" \
  --sweep penalty=1e-1,1e-2,1e-3,1e-4,1e-5 --sweep quadrature="Nodal,Gauss 2x2,Gauss 3x3"
# H1: the study's rolling case (penalty contact, tanh friction). Mesh, load steps,
# friction regularisation, contact penalty.
study inputs/seed/h1.xml --out out/study-h1 --columns $contact,xmin_mean_ux \
  --sweep mesh=1,2,4 --sweep steps=1,2,4,8 \
  --sweep regularization=1e-1,1e-2,1e-3,1e-4,1e-6 \
  --sweep penalty=1e-1,1e-2,1e-3,1e-4,1e-5 \
  --sweep "Solver/Newton Relative Tolerance=1e-4,1e-6,1e-8,1e-10"
# Coulomb stick/slip: the stick zone makes the answer depend on the load steps.
study inputs/seed/stick-slip.xml --out out/study-stick-slip --columns $contact,xmin_mean_ux --sweep steps=1,2,4,8
# A smooth problem (no contact): the element's own convergence orders.
study inputs/gravity.xml --out out/study-gravity --columns max_ux,max_uy,sigma_yy_min,von_mises_max --set "Mesh/Cells={8,8,1}" --sweep mesh=1,2,4

# The pinch-roller slice's speed ratio, steady (mesh phases) and quasi-static (steps),
# free and braked at 0.3 N mm/mm (about 7 min each).
/usr/bin/python3 scripts/nip-accuracy.py --out out/nip-accuracy --png docs/img/accuracy-nip.png
/usr/bin/python3 scripts/nip-accuracy.py --torque 0.3 --out out/nip-accuracy-brake --png docs/img/accuracy-nip-brake.png

# The presets (Draft, Standard, Fine) on G1 and H1: error and wall time. Standard and
# Fine are the 2x and 4x meshes of the mesh sweeps above (same settings): reused.
reuse() { [ -f "$2/summary.json" ] && echo "--reuse $1=$2"; true; }
/usr/bin/python3 scripts/accuracy-presets.py inputs/seed/g1.xml --out out/presets-g1 \
  $(reuse Standard out/study-g1/runs/mesh-1) $(reuse Fine out/study-g1/runs/mesh-2)
/usr/bin/python3 scripts/accuracy-presets.py inputs/seed/h1.xml --out out/presets-h1 \
  $(reuse Standard out/study-h1/runs/mesh-1) $(reuse Fine out/study-h1/runs/mesh-2)
