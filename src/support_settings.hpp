// A support (one sublist of Supports), typed: declared and parsed side by side,
// the only place its defaults are stated. Foundations become effects
// (src/effects/factory.cpp), rigid cores RigidCores, the others held dofs
// (src/constraints.cpp).
#pragma once

#include <Teuchos_ParameterList.hpp>

#include <array>
#include <set>
#include <string>
#include <utility>
#include <vector>

#include "parameters.hpp"

namespace capstan {

// The unknowns a rigid core adds to the system: Tx Ty Tz, theta, and two
// unused slots so that the unknowns stay in blocks of 3 (DofLayout).
constexpr int kCoreUnknowns = 6;

struct SupportSpec {
  enum class Type { Fixed, Roller, Foundation, Displacement, RigidCore };
  enum class Rotation { Fixed, Free, Prescribed };  // of a rigid core about its axis

  std::string name, face;
  Type type = Type::Fixed;
  std::array<bool, 3> components{};    // which of x, y, z the support acts on
  double stiffness = 0;                // Foundation
  std::array<double, 3> velocity{};    // Displacement: u = velocity * t
  // Rigid Core (interface.md "Pinch roller"): the face follows a rigid body
  // turning about axisDirection (unit) through axisPoint and translating along
  // the free components.
  std::array<double, 3> axisPoint{}, axisDirection{0, 0, 1};
  std::array<bool, 3> freeTranslation{};
  std::array<double, 3> force{};       // external force on the core, ramped to rampTime
  double rampTime = 0;                 // > 0 once the scene is read (0: the first step's end)
  Rotation rotation = Rotation::Fixed;
  double torque = 0;                   // Free: external torque on the core, ramped to torqueRampTime
  double torqueRampTime = 0;           // > 0 once the scene is read (0: rampTime)
  double angularVelocity = 0;          // Prescribed

  bool isCore() const { return type == Type::RigidCore; }

  // The template every support sublist is checked against.
  static void declare(Teuchos::ParameterList& support);
  // A parameter of another type (Stiffness on a Fixed support, Components on
  // a Rigid Core) would be silently ignored, most likely a misspelled Type or
  // parameter: an error, checked before defaults fill in.
  static void rejectParametersOfOtherTypes(const Teuchos::ParameterList& supports, const ParameterReader& r);
  // Whether a support of `type` reads `parameter`.
  static bool readBy(const std::string& parameter, const std::string& type);
  static SupportSpec parse(const Teuchos::ParameterList& support, const std::string& name,
                           const std::set<std::string>& faces, const ParameterReader& r);
  static const std::vector<std::pair<const char*, Type>> types;
  static const std::vector<std::pair<const char*, Rotation>> rotations;
};

}  // namespace capstan
