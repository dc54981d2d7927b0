#pragma once

#include "effect.hpp"

#include <array>
#include <string>

namespace capstan {

// Elastic foundation on one face: t = -k (x - X) on the listed components.
class FoundationEffect : public Effect {
 public:
  FoundationEffect(const std::string& name, const Mesh& mesh, const std::string& face, double k,
                   std::array<bool, 3> components);
  // Total force the foundation exerts on the body (this rank's faces).
  std::array<double, 3> localForceOnBody() const;

 protected:
  void launch(const NodalVectors& x, const NodalVectors& u, bool tangent, const TangentSink& sink) override;

 private:
  Kokkos::View<int* [4], Kokkos::LayoutRight> nodes_;
  Kokkos::View<double* [4][3], Kokkos::LayoutRight> X_;
  double k_;
  int mask_[3];
};

}  // namespace capstan
