// What a run reports of each converged load step: one definition, walked by
// every writer (summary.json, history.csv, the progress line, checkpoints).
//
// walkStep(v, record) visits each field once, in the order summary.json lists
// them; a writer is a visitor with
//   field(name, value, show)  a number, an int or a 3-vector; `show` names it
//                             on the progress line (empty: not shown there);
//   flag(name, on, fields)    fields present only when `on` (a rigid core's
//                             motion): inline in JSON and CSV;
//   group(name, on, fields)   a nested object (JSON: an object or null);
//   list(name, items, walk)   named items (supports, capstans): a JSON object
//                             keyed by the items' names.
// Adding a figure is one line here, and every output has it.
#pragma once

#include <array>
#include <string>
#include <vector>

namespace capstan {

// How a field shows on the progress line: its label and printf format.
struct Show {
  const char* label = nullptr;
  const char* format = nullptr;
};

// One capstan's figures at a converged step (global).
struct CapstanRecord {
  std::string name;
  std::array<double, 3> force{};  // body on capstan
  double torque = 0, maxPenetration = 0, peakPressure = 0, area = 0, width = 0;
  long points = 0;
  bool friction = false;
  long stick = 0, slip = 0;
  double frictionIntegral = 0, normalIntegral = 0, maxFrictionRatio = 0;
  double slipPower = 0;  // friction dissipation in the nip (>= 0; 0 without friction)
};

// A support's figures at a converged step (global). Rigid cores add their
// motion and torque.
struct SupportRecord {
  std::string name;
  std::array<double, 3> force{};  // support (core) on body
  bool core = false;
  double torque = 0, rotation = 0, angularVelocity = 0;
  std::array<double, 3> translation{};
  bool hasSpeedRatio = false;
  double speedRatio = 0;  // roller surface speed / capstan surface speed
};

struct StepRecord {
  int step = 0;
  double time = 0;
  int newton = 0, linear = 0, cutbacks = 0, augmentations = 0;
  int pressureStep = 0;  // Krylov iterations of the saddle-point pressure steps (part of linear)
  // 1: the step's last solve met its tolerances with Coulomb's stick and slip
  // frozen (AugmentationLoop's last resort; its answer is one admissible state,
  // which may not be the one a finer radial mesh converges to: docs/friction.md).
  int statesFrozen = 0;
  double residual = 0, wall = 0, volumeChange = 0;
  std::vector<CapstanRecord> capstans;
  std::vector<SupportRecord> supports;
  double maxPenetration() const;
};

template <class V, class C>
void walkCapstan(V& v, C& c) {
  v.field("force", c.force);
  v.field("max_penetration", c.maxPenetration);
  v.field("contact_points", c.points);
  v.field("stick_points", c.stick);
  v.field("slip_points", c.slip);
  v.field("torque", c.torque);
  v.field("contact_area", c.area);
  v.field("peak_pressure", c.peakPressure);
  v.field("contact_width", c.width);
  v.field("slip_power", c.slipPower);
  v.group("friction", c.friction, [&] {
    v.field("traction_integral", c.frictionIntegral);
    v.field("normal_traction_integral", c.normalIntegral);
    v.field("max_traction_ratio", c.maxFrictionRatio);
  });
}

template <class V, class S>
void walkSupport(V& v, S& s) {
  v.field("force", s.force);
  v.flag("core", s.core, [&] {
    v.field("torque", s.torque, Show{"torque", "%.4g"});
    v.field("translation", s.translation);
    v.field("rotation", s.rotation, Show{"rotation", "%.5g"});
    v.field("angular_velocity", s.angularVelocity, Show{"omega", "%.5g"});
  });
  v.flag("has_speed_ratio", s.hasSpeedRatio, [&] { v.field("speed_ratio", s.speedRatio, Show{"speed_ratio", "%.6f"}); });
}

template <class V, class R>
void walkStep(V& v, R& r) {
  v.field("step", r.step);
  v.field("time", r.time, Show{"t", "%.4g"});
  v.field("newton_iterations", r.newton, Show{"newton", "%d"});
  v.field("linear_iterations", r.linear, Show{"linear", "%d"});
  v.field("pressure_step_iterations", r.pressureStep);
  v.field("cutbacks", r.cutbacks);
  v.field("augmentations", r.augmentations);
  v.field("states_frozen", r.statesFrozen);
  v.field("residual_norm", r.residual, Show{"|R|", "%.3e"});
  v.field("max_abs_volume_change", r.volumeChange, Show{"dV", "%.1e"});
  v.list("capstans", r.capstans, [&](auto& c) { walkCapstan(v, c); });
  v.list("supports", r.supports, [&](auto& s) { walkSupport(v, s); });
  v.field("wall_seconds", r.wall);
}

// The writers.
std::string toJson(const StepRecord& record);
// history.csv: a header of the columns (from a record of the run: its supports
// and capstans), then a row per record.
std::string csvHeader(const StepRecord& layout);
std::string csvRow(const StepRecord& record);
// The progress lines: "step k/N  t=..  newton=..", then a line per support or
// capstan with fields to show.
std::vector<std::string> progressLines(const StepRecord& record, int steps, double elapsed);

namespace checkpoint {
class Writer;
class Reader;
void put(Writer& w, const StepRecord& record);
StepRecord get(Reader& in);
}  // namespace checkpoint

}  // namespace capstan
