#pragma once

#include "effect.hpp"

#include <array>

namespace capstan {

// Dead body force b per unit reference volume on every brick (Loads/Body Force),
// ramped with time: b t / endTime. No stiffness (local().stiff is false).
class BodyForceEffect : public Effect {
 public:
  BodyForceEffect(const Mesh& mesh, std::array<double, 3> b, double endTime);
  void setInterval(double, double tEnd) override { scale_ = tEnd / endTime_; }

 protected:
  void launch(const NodalVectors& x, const NodalVectors& u, bool tangent, const TangentSink& sink) override;

 private:
  Matrix fullLoad_;  // the nodal loads of b itself, integrated once (they never change)
  double endTime_, scale_ = 0;
};

}  // namespace capstan
