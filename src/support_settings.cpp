#include "support_settings.hpp"

#include <algorithm>
#include <cmath>

#include "vec3.hpp"

namespace capstan {

using Teuchos::Array;

const std::vector<std::pair<const char*, SupportSpec::Type>> SupportSpec::types = {
    {"Fixed", Type::Fixed},
    {"Roller", Type::Roller},
    {"Foundation", Type::Foundation},
    {"Displacement", Type::Displacement},
    {"Rigid Core", Type::RigidCore}};
const std::vector<std::pair<const char*, SupportSpec::Rotation>> SupportSpec::rotations = {
    {"Fixed", Rotation::Fixed}, {"Free", Rotation::Free}, {"Prescribed", Rotation::Prescribed}};

namespace {
Array<double> vec3(double a, double b, double c) { return Teuchos::tuple(a, b, c); }
// The parameters that only some types read (Face and Type: every type).
struct TypedParameter {
  const char* name;
  std::vector<const char*> types;
};
const std::vector<TypedParameter> kTypedParameters = {
    {"Components", {"Roller", "Foundation", "Displacement"}},
    {"Stiffness", {"Foundation"}},
    {"Velocity", {"Displacement"}},
    {"Axis Point", {"Rigid Core"}},
    {"Axis Direction", {"Rigid Core"}},
    {"Free Translation", {"Rigid Core"}},
    {"Force", {"Rigid Core"}},
    {"Force Ramp Time", {"Rigid Core"}},
    {"Rotation", {"Rigid Core"}},
    {"Torque", {"Rigid Core"}},
    {"Torque Ramp Time", {"Rigid Core"}},
    {"Angular Velocity", {"Rigid Core"}}};
}  // namespace

bool SupportSpec::readBy(const std::string& parameter, const std::string& type) {
  for (const auto& p : kTypedParameters)
    if (parameter == p.name) return std::find(p.types.begin(), p.types.end(), type) != p.types.end();
  return true;
}

void SupportSpec::declare(Teuchos::ParameterList& s) {
  s.set("Face", std::string(""), "Name of the mesh face it acts on");
  s.set("Type", std::string("Fixed"), "Fixed | Roller | Foundation | Displacement | Rigid Core");
  s.set("Components", std::string("xyz"), "Roller, Foundation, Displacement: components acted on, e.g. \"y\" or \"xz\"");
  s.set("Stiffness", 1.0, "Foundation: k > 0, traction -k (x - X) per reference area");
  s.set("Velocity", vec3(0, 0, 0), "Displacement: u = Velocity * t on the listed components");
  s.set("Axis Point", vec3(0, 0, 0), "Rigid Core: a point of the core's axis");
  s.set("Axis Direction", vec3(0, 0, 1), "Rigid Core: the axis it turns about (right-hand rule, non-zero)");
  s.set("Free Translation", std::string(""),
        "Rigid Core: the components it may translate along, e.g. \"y\"; \"\" holds all");
  s.set("Force", vec3(0, 0, 0),
        "Rigid Core: external force on the core (a spring's preload), only along free components");
  s.set("Force Ramp Time", 0.0,
        "Rigid Core: Force and Torque grow linearly from 0 and are reached at this time (> 0), then "
        "held; 0 = the first step's end");
  s.set("Rotation", std::string("Fixed"), "Rigid Core: Fixed | Free | Prescribed (about the axis)");
  s.set("Torque", 0.0,
        "Rigid Core, Rotation = Free: external torque on the core about its axis (right-hand rule; "
        "a brake acts against the rotation), ramped to Torque Ramp Time");
  s.set("Torque Ramp Time", 0.0,
        "Rigid Core: Torque grows linearly from 0 and is reached at this time (> 0), then held; "
        "0 = Force Ramp Time. A brake sweep is one run whose Torque Ramp Time is its last step's time");
  s.set("Angular Velocity", 0.0, "Rigid Core, Rotation = Prescribed: rad per unit time, right-hand rule");
}

void SupportSpec::rejectParametersOfOtherTypes(const Teuchos::ParameterList& sups, const ParameterReader& r) {
  for (auto it = sups.begin(); it != sups.end(); ++it) {
    const std::string name = sups.name(it);
    if (!sups.isSublist(name)) continue;  // the validator reports it
    const auto& s = sups.sublist(name);
    const std::string type = s.isType<std::string>("Type") ? s.get<std::string>("Type") : "Fixed";
    if (std::none_of(types.begin(), types.end(), [&](const auto& t) { return type == t.first; }))
      continue;  // the Type's own message comes first
    for (const auto& p : kTypedParameters) {
      if (!s.isParameter(p.name) || readBy(p.name, type)) continue;
      std::string owners;
      for (size_t k = 0; k < p.types.size(); ++k)
        owners += std::string(k == 0 ? "" : k + 1 == p.types.size() ? " or " : ", ") + p.types[k];
      r.fail("Supports/" + name + "/" + p.name,
             "is a parameter of Type = " + owners + (p.types.size() == 1 ? " only" : "") + ", not of " + type);
    }
  }
}

namespace {
// Rigid Core: the rigid body's axis, its free components and its loads.
void readRigidCore(const Teuchos::ParameterList& s, const std::string& path, const ParameterReader& r,
                   SupportSpec& spec) {
  using Rotation = SupportSpec::Rotation;
  spec.axisPoint = r.three<double>(s, path, "Axis Point");
  auto& d = spec.axisDirection;
  d = r.three<double>(s, path, "Axis Direction");
  const double m = std::max({std::fabs(d[0]), std::fabs(d[1]), std::fabs(d[2])});
  if (!(m > 0)) r.fail(path + "/Axis Direction", "must be a finite non-zero vector");
  d = unit(scaledDirection(d));
  const std::string free = s.get<std::string>("Free Translation");
  if (free.find_first_not_of(" ,") != std::string::npos)
    spec.freeTranslation = r.components(free, path + "/Free Translation");
  spec.force = r.three<double>(s, path, "Force");
  for (int i = 0; i < 3; ++i)
    if (spec.force[i] != 0 && !spec.freeTranslation[i])
      r.fail(path + "/Force", std::string("component ") + char('x' + i) + " is not zero, but the core is held along " +
                                  char('x' + i) + " (not in Free Translation '" + free + "')");
  spec.rampTime = r.nonNegative(s, path, "Force Ramp Time");
  spec.rotation = r.choice(s, path, "Rotation", SupportSpec::rotations);
  const std::string rotation = nameOf(spec.rotation, SupportSpec::rotations);
  spec.torque = r.finite(s, path, "Torque");
  spec.torqueRampTime = r.nonNegative(s, path, "Torque Ramp Time");
  if (spec.torque != 0 && spec.rotation != Rotation::Free)
    r.fail(path + "/Torque", "an applied torque needs Rotation = Free (it is '" + rotation + "')");
  spec.angularVelocity = r.finite(s, path, "Angular Velocity");
  if (spec.angularVelocity != 0 && spec.rotation != Rotation::Prescribed)
    r.fail(path + "/Angular Velocity", "needs Rotation = Prescribed (it is '" + rotation + "')");
}
}  // namespace

SupportSpec SupportSpec::parse(const Teuchos::ParameterList& s, const std::string& name,
                               const std::set<std::string>& faces, const ParameterReader& r) {
  const std::string path = "Supports/" + name;
  SupportSpec spec;
  spec.name = name;
  spec.face = s.get<std::string>("Face");
  spec.type = r.choice(s, path, "Type", types);
  if (!faces.count(spec.face)) {
    std::string list;
    for (const auto& f : faces) list += (list.empty() ? "" : " ") + f;
    r.fail(path + "/Face", "'" + spec.face + "' is not a face of the mesh (" + list + ")");
  }
  if (spec.type == Type::Fixed || spec.type == Type::RigidCore) spec.components = {true, true, true};
  else spec.components = r.components(s.get<std::string>("Components"), path + "/Components");
  if (spec.type == Type::Foundation) spec.stiffness = r.positive(s, path, "Stiffness");
  spec.velocity = r.three<double>(s, path, "Velocity");
  if (spec.type == Type::RigidCore) readRigidCore(s, path, r, spec);
  return spec;
}

}  // namespace capstan
