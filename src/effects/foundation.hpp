#pragma once

#include "effect.hpp"
#include "../support_settings.hpp"

#include <array>
#include <string>

namespace capstan {

// Elastic foundation on one face: t = -k (x - X) on the listed components.
class FoundationEffect : public Effect {
 public:
  FoundationEffect(const Mesh& mesh, const SupportSpec& support);
  // Total force the foundation exerts on the body (this rank's faces).
  std::array<double, 3> localForceOnBody() const;
  // Its force on the body, in its support's record.
  void report(const Teuchos::Comm<int>& comm, StepRecord& rec) const override;

 protected:
  void launch(const NodalVectors& x, const NodalVectors& u, bool tangent, const TangentSink& sink) override;

 private:
  Kokkos::View<int* [4], Kokkos::LayoutRight> nodes_;
  Kokkos::View<double* [4][3], Kokkos::LayoutRight> X_;
  std::string support_;
  double k_;
  int mask_[3];
};

}  // namespace capstan
