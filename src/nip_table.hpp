// nip.csv (interface.md, "Steady rolling"): one row per contact point in
// contact and converged step, `step,capstan,s,z,pressure,shear,slip_rate,state`.
// s: arc length on the capstan's surface from the line of centres (the
// capstan's axis to the roller's; on a box, the perpendicular from the axis
// to the faces it touches), positive along the capstan's surface
// motion; z: along the capstan's axis; shear and slip_rate: the friction
// traction on the body and the body's slip rate on the capstan along that
// motion. Written in both analyses (quasi-static: the step's last increment).
#pragma once

#include <filesystem>
#include <string>

namespace capstan {

struct Model;

class NipTable {
 public:
  static constexpr const char* kHeader = "step,capstan,s,z,pressure,shear,slip_rate,state";
  NipTable(const Model& model, std::filesystem::path file);
  // The file with the rows so far; a restart (lastKept >= 0) first keeps the
  // earlier run's rows of steps up to lastKept, from `earlier` (its nip.csv; this
  // file where empty) (collective: rank 0 writes).
  void open(int lastKept, const std::filesystem::path& earlier = {});
  // The converged step's rows, gathered on rank 0 (collective), and the file.
  void add(int step);

 private:
  std::string rows(int step) const;  // this rank's
  const Model& m_;
  std::filesystem::path file_;
  std::string text_;  // rank 0: every row so far
};

}  // namespace capstan
