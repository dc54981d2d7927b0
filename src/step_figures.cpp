#include "step_figures.hpp"

#include <Teuchos_CommHelpers.hpp>

#include <cmath>
#include <map>

#include "rolling.hpp"
#include "vec3.hpp"

namespace capstan {

namespace {

// Extrema of several figures over all ranks in one reduction: (min, -max)
// pairs under REDUCE_MIN.
class Extrema {
 public:
  explicit Extrema(int figures) : lo_(2 * size_t(figures), 1e300) {}
  void add(int k, double x) {
    lo_[2 * k] = std::min(lo_[2 * k], x);
    lo_[2 * k + 1] = std::min(lo_[2 * k + 1], -x);
  }
  void reduce(const Comm& comm) {
    std::vector<double> global(lo_.size());
    Teuchos::reduceAll(comm, Teuchos::REDUCE_MIN, int(lo_.size()), lo_.data(), global.data());
    lo_ = global;
  }
  StateFigures::Range range(int k) const { return {lo_[2 * k], -lo_[2 * k + 1]}; }

 private:
  std::vector<double> lo_;
};

}  // namespace

void measureStep(const Model& model, const std::vector<StepRecord>& earlier, StepRecord& rec) {
  const auto& assembly = *model.assembly;
  const auto reactions = assembly.constraintReactions();
  std::map<std::string, std::array<double, 3>> byName;
  for (size_t s = 0; s < reactions.size(); ++s) byName[assembly.constraints().supportNames[s]] = reactions[s];
  for (const auto& s : model.scene.supports) {
    SupportRecord sr;
    sr.name = s.name, sr.force = byName[s.name];
    rec.supports.push_back(sr);
  }
  // Foundations and capstans (contact, friction) report themselves.
  for (const auto& e : assembly.effects()) e->report(*model.comm, rec);
  // Rigid cores: the reactions at the face nodes are the force of the core on
  // the body; angular velocity over the step (formulation: increment / dt).
  for (const auto& core : assembly.rigidCores()) {
    auto& sr = *std::find_if(rec.supports.begin(), rec.supports.end(),
                             [&](const SupportRecord& x) { return x.name == core.name; });
    sr.core = true;
    sr.force = core.forceOnBody;
    sr.torque = core.torqueOnBody;
    sr.translation = core.translation;
    sr.rotation = core.rotation;
    double before = 0, tBefore = 0;
    if (!earlier.empty()) {
      tBefore = earlier.back().time;
      for (const auto& p : earlier.back().supports)
        if (p.name == core.name) before = p.rotation;
    }
    // Steady rolling: the angular velocity is the core's unknown itself.
    sr.angularVelocity = model.scene.analysis.steady() ? core.angularVelocity
                                                       : (core.rotation - before) / (rec.time - tBefore);
    const double ratio = speedRatio(model.scene, core, sr.angularVelocity);
    sr.hasSpeedRatio = !std::isnan(ratio);
    if (sr.hasSpeedRatio) sr.speedRatio = ratio;
  }
}

ElementFields elementFields(const Model& model) {
  auto& bricks = model.assembly->bricks();
  Matrix stress;
  Kokkos::View<double*> mises;
  bricks.centroidStress(model.assembly->positions(), stress, mises);
  return {Kokkos::create_mirror_view_and_copy(Kokkos::HostSpace(), stress),
          Kokkos::create_mirror_view_and_copy(Kokkos::HostSpace(), mises),
          Kokkos::create_mirror_view_and_copy(Kokkos::HostSpace(), bricks.pressure)};
}

StateFigures stateFigures(const Model& model) {
  enum { kMises = 6, kPressure = 7, kVolume = 8, kFigures = 9 };  // 0..5: the stress components
  StateFigures s;
  auto& bricks = model.assembly->bricks();
  const auto [hs, hm, hp] = elementFields(model);
  auto hv = Kokkos::create_mirror_view_and_copy(Kokkos::HostSpace(), bricks.volume);
  auto hV = Kokkos::create_mirror_view_and_copy(Kokkos::HostSpace(), bricks.referenceVolume);
  Extrema ex(kFigures);
  for (size_t e = 0; e < hs.extent(0); ++e) {
    for (int k = 0; k < 6; ++k) ex.add(k, hs(e, k));
    ex.add(kMises, hm(e));
    ex.add(kPressure, hp(e));
    ex.add(kVolume, std::fabs(hv(e) / hV(e) - 1));
  }
  ex.reduce(*model.comm);
  for (int k = 0; k < 6; ++k) s.stress[k] = ex.range(k);
  s.vonMises = ex.range(kMises);
  s.pressure = ex.range(kPressure);
  s.volumeChange = ex.range(kVolume).max;

  const auto& mesh = model.mesh;
  auto ud = model.u->getData();
  double md[3] = {0, 0, 0}, gmd[3];
  for (size_t n = 0; n < mesh.numOwnedNodes; ++n)
    for (int i = 0; i < 3; ++i) md[i] = std::max(md[i], std::fabs(ud[3 * n + i]));
  Teuchos::reduceAll(*model.comm, Teuchos::REDUCE_MAX, 3, md, gmd);
  s.maxDisplacement = {gmd[0], gmd[1], gmd[2]};

  for (const auto& face : mesh.faceNames) {
    double sum[4] = {0, 0, 0, 0}, gsum[4];
    for (int n : mesh.faceNodes(face)) {
      if (n >= int(mesh.numOwnedNodes)) continue;
      for (int i = 0; i < 3; ++i) sum[i] += ud[3 * n + i];
      sum[3] += 1;
    }
    Teuchos::reduceAll(*model.comm, Teuchos::REDUCE_SUM, 4, sum, gsum);
    s.faceMeans.push_back({face, {gsum[0] / gsum[3], gsum[1] / gsum[3], gsum[2] / gsum[3]}});
  }
  return s;
}

}  // namespace capstan
