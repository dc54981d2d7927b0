// The scene: a Teuchos XML parameter list, validated against the full list of
// valid parameters (with defaults and doc strings), then read into plain structs.
#pragma once

#include <Teuchos_ParameterList.hpp>

#include <array>
#include <string>
#include <vector>

#include "solver_settings.hpp"

namespace capstan {

struct MeshSpec {
  std::string type;  // Box | Annulus
  std::array<double, 3> min{}, max{};  // Box: its corners; Annulus: its bounding box
  std::array<int, 3> cells{};          // Box: x, y, z; Annulus: radial, circumferential, axial
  // Annulus: axis point at the zmin end (axis along +z), radii, length.
  std::array<double, 3> center{};
  double innerRadius = 0, outerRadius = 0, length = 0;
  double outerCellRatio = 1;             // radial grading (AnnulusGenerator)
  std::array<double, 3> fineSector{};    // {centre deg, width deg, fraction of cells}
  std::string partition = "Auto";        // over the MPI ranks: Auto | METIS | Slabs (partitionFor)
  std::vector<std::string> faceNames() const;
};

struct SupportSpec {
  std::string name, face, type;        // type: Fixed | Roller | Foundation | Displacement | Rigid Core
  std::array<bool, 3> components{};    // which of x, y, z the support acts on
  double stiffness = 0;                // Foundation
  std::array<double, 3> velocity{};    // Displacement: u = velocity * t
  // Rigid Core (interface.md "Pinch roller"): the face follows a rigid body
  // turning about axisDirection (unit) through axisPoint and translating along
  // the free components.
  std::array<double, 3> axisPoint{}, axisDirection{0, 0, 1};
  std::array<bool, 3> freeTranslation{};
  std::array<double, 3> force{};       // external force on the core, ramped to rampTime
  double rampTime = 0;                 // > 0 (the first step's end when not given)
  std::string rotation = "Fixed";      // Fixed | Free | Prescribed
  double torque = 0;                   // Free: external torque on the core, ramped like force
  double angularVelocity = 0;          // Prescribed
};

struct CapstanSpec {
  std::string name;
  double radius = 0;
  std::array<double, 3> axisPoint{}, axisDirection{}, velocity{};
  double angularVelocity = 0;
  std::vector<std::string> contactFaces;
  std::string method;  // Penalty | Augmented Lagrangian
  double penalty = 0, penetrationTolerance = 0, minimumSolvePenalty = 0;
  int maxAugmentations = 0;
  int quadrature = 0;  // kernels::FaceRule: 0 Gauss 2x2, 1 Gauss 3x3, 2 Nodal
  double smoothing = 0;  // Contact/Smoothing: pressure scale of the smoothed contact corner
  std::string frictionLaw;  // None | Tanh | Arctan | Coulomb
  double frictionCoefficient = 0, regularization = 0, tangentialPenalty = 0, frictionSmoothing = 0;
};

struct Scene {
  std::string file, title;
  MeshSpec mesh;
  double c = 1, pressurePenalty = 1e-3;
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

}  // namespace capstan
