// The scene: a Teuchos XML parameter list, validated against the full list of
// valid parameters (with defaults and doc strings), then read into plain structs.
#pragma once

#include <Teuchos_ParameterList.hpp>

#include <array>
#include <cmath>
#include <string>
#include <vector>

#include "analysis_settings.hpp"
#include "effects/contact_settings.hpp"
#include "effects/friction_settings.hpp"
#include "solver_settings.hpp"
#include "support_settings.hpp"

namespace capstan {

struct MeshSpec {
  enum class Type { Box, Annulus };
  Type type = Type::Box;
  std::array<double, 3> min{}, max{};  // Box: its corners; Annulus: its bounding box
  std::array<int, 3> cells{};          // Box: x, y, z; Annulus: radial, circumferential, axial
  // Annulus: axis point at the zmin end (axis along +z), radii, length.
  std::array<double, 3> center{};
  double innerRadius = 0, outerRadius = 0, length = 0;
  double outerCellRatio = 1;             // radial grading (AnnulusGenerator)
  std::array<double, 3> fineSector{};    // {centre deg, width deg, fraction of cells}
  std::string partition = "Auto";        // over the MPI ranks: Auto | METIS | Slabs (partitionFor)
  std::vector<std::string> faceNames() const;
  static const std::vector<std::pair<const char*, Type>> types;
};

// A rigid cylinder (formulation.md §2): its motion here, its contact and
// friction in their own settings.
struct CapstanSpec {
  std::string name;
  double radius = 0;
  std::array<double, 3> axisPoint{}, axisDirection{}, velocity{};
  double angularVelocity = 0;
  std::vector<std::string> contactFaces;
  ContactSettings contact;
  FrictionSettings friction;
  // How fast its surface travels: |omega| R + |velocity|.
  double surfaceSpeed() const {
    return std::fabs(angularVelocity) * radius +
           std::sqrt(velocity[0] * velocity[0] + velocity[1] * velocity[1] + velocity[2] * velocity[2]);
  }
};

struct Scene {
  std::string file, title;
  AnalysisSettings analysis;       // Quasi-Static or Steady Rolling
  MeshSpec mesh;
  double c = 1, pressurePenalty = 0;  // pressurePenalty 0: automatic (SolverSettings::solvePenalty)
  std::array<double, 3> bodyForce{};  // Loads/Body Force at the end of the run
  std::vector<SupportSpec> supports;
  std::vector<CapstanSpec> capstans;
  int steps = 1;
  double stepSize = 1;
  SolverSettings solver;           // the Solver sublist, typed and resolved
  std::string outputDirectory;
  bool writeFields = true;
  int checkpointEvery = 0;         // Output/Checkpoint Every: steps between checkpoints, 0 = none
  // Valid but suspicious input (e.g. a capstan that can never touch its faces):
  // printed by the driver, the run goes on.
  std::vector<std::string> warnings;
  Teuchos::ParameterList resolved; // the whole scene with defaults filled in
};

// Every valid parameter with its default and doc string (`capstan params`).
Teuchos::ParameterList validParameters();

// Reads, overrides (--set PATH=VALUE), validates. Throws InputError naming the
// file and the parameter path.
Scene loadScene(const std::string& file, const std::vector<std::string>& sets,
                const std::string& outputOverride);

// loadScene on the file's content (named `file` in messages): the parse and
// validation the driver runs, without the file (fuzz/scene_fuzz.cpp). Any input
// gives a Scene or an InputError.
Scene parseScene(const std::string& content, const std::string& file, const std::vector<std::string>& sets,
                 const std::string& outputOverride);

// The resolved scene as `capstan validate` prints it: every parameter the
// scene's types read, with its value or default, as a scene file that
// capstan reads back to the same scene.
Teuchos::ParameterList printableScene(const Scene& scene);

}  // namespace capstan
