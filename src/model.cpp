#include "model.hpp"

#include <algorithm>

#include <Teuchos_CommHelpers.hpp>

#include <cmath>

#include "errors.hpp"

namespace capstan {

void Model::checkRanks(const Scene& scene, const Comm& comm) {
  const auto& m = scene.mesh;
  const double elements = double(m.cells[0]) * m.cells[1] * m.cells[2];
  if (elements < comm.getSize())
    throw InputError(scene.file + ": parameter 'Mesh/Cells': " + Teuchos::toString(elements) + " element(s) for " +
                     std::to_string(comm.getSize()) + " MPI ranks; every rank needs at least one");
}

Model::Model(const Scene& scene_, const RCP<const Comm>& comm_)
    : scene(scene_), comm(comm_), rank0(comm_->getRank() == 0) {
  const auto& m = scene.mesh;
  if (m.type == MeshSpec::Type::Annulus)
    generator = std::make_unique<AnnulusGenerator>(m.center, m.innerRadius, m.outerRadius, m.length, m.cells,
                                                   m.outerCellRatio, m.fineSector);
  else
    generator = std::make_unique<BoxGenerator>(m.min, m.max, m.cells);
  // Steady rolling differences friction along the rings of the contact faces.
  std::vector<std::string> streamlineFaces;
  if (scene.analysis.steady())
    for (const auto& c : scene.capstans)
      if (c.friction.on()) streamlineFaces.insert(streamlineFaces.end(), c.contactFaces.begin(), c.contactFaces.end());
  mesh = distributeMesh(*generator, comm, partitionFor(m.partition, m.cells[2], comm->getSize()), streamlineFaces);
  assembly = std::make_unique<Assembly>(mesh, scene);
  try {
    const bool friction = std::any_of(scene.capstans.begin(), scene.capstans.end(),
                                      [](const CapstanSpec& c) { return c.friction.on(); });
    newton = std::make_unique<NewtonSolver>(
        *assembly, scene.solver.resolved(long(assembly->dofMap()->getGlobalNumElements()),
                                         m.type == MeshSpec::Type::Annulus, friction, scene.analysis.steady()));
  } catch (const InputError& e) {  // the Solver/NOX or Solver/Stratimikos sublist
    throw InputError(scene.file + ": " + e.what());
  }
  if (scene.solver.pressureUpdate == SolverSettings::PressureUpdate::SaddlePoint) buildPressureStep();
  u = rcp(new Vector(assembly->dofMap()));
  for (const auto& core : assembly->rigidCores()) rolling = rolling || core.free[3];
  double size2 = 0;
  for (int d = 0; d < 3; ++d) size2 = std::max(size2, std::pow(m.max[d] - m.min[d], 2));
  forceScale = scene.c * size2;
  absTolerance = scene.solver.newtonAbsoluteTolerance;
  if (absTolerance == 0) absTolerance = 1e-13 * forceScale;
  long localFaces = long(assembly->contactFaceNodes().size() / 4);
  Teuchos::reduceAll(*comm, Teuchos::REDUCE_SUM, localFaces, Teuchos::outArg(numContactFaces));
}

void Model::buildPressureStep() {
  using S = SolverSettings;
  const auto schur = scene.solver.pressureStepSchur;
  const bool laplacian = schur == S::Schur::Laplacian || (schur == S::Schur::Auto && newton->iterative());
  // Auto: the factored block matrix for steady rolling above
  // kStepLUAboveDofs unknowns where Newton's solves factor the matrix (a
  // direct solver, or GMRES with the LU preconditioner; next to multigrid it
  // would be the largest factorisation of the run).
  const auto choice = scene.solver.pressureStepPreconditioner;
  const long dofs = long(assembly->dofMap()->getGlobalNumElements());
  const bool lu = choice == S::StepPreconditioner::LU ||
                  (choice == S::StepPreconditioner::Auto && scene.analysis.steady() && !newton->iterative() &&
                   dofs > S::kStepLUAboveDofs);
  const auto preconditioner = lu ? PressureStep::Preconditioner::LU : PressureStep::Preconditioner::Block;
  pressureStep = std::make_unique<PressureStep>(
      *assembly, laplacian ? PressureStep::Schur::Laplacian : PressureStep::Schur::Diagonal, preconditioner);
  monolithic = scene.solver.monolithic && !(scene.solver.monolithicIfExact && newton->iterative());
  if (monolithic && scene.solver.minimumSolvePenaltyAutomatic)
    assembly->bricks().setSolvePenalty(S::solvePenalty(scene.pressurePenalty, S::kMonolithicSolvePenalty, scene.c));
}

double Model::linearSolveSeconds() const {
  return newton->linearSolveSeconds() + (pressureStep ? pressureStep->seconds() : 0.0);
}

}  // namespace capstan
