#pragma once

#include <array>

#include "effect.hpp"

namespace capstan {

// Q1P0 incompressible neo-Hookean bricks, the whole body.
class BrickEffect : public Effect {
 public:
  BrickEffect(const Mesh& mesh, double c, double penalty, double volumeTolerance);
  Kokkos::View<double*> pressureAnchor;  // pbar per element (outer loop updates it)
  Kokkos::View<double*> pressure;        // p(x) at the last evaluation
  Kokkos::View<double*> volume;          // v at the last evaluation
  Kokkos::View<double*> referenceVolume; // V
  Kokkos::View<double*> minJacobian;     // smallest Gauss-point det F
  // Element Cauchy stress (xx yy zz xy yz xz) and von Mises at the centroids.
  void centroidStress(const NodalVectors& x, Matrix& stress, Kokkos::View<double*>& mises) const;
  double c() const { return c_; }
  // The smallest Gauss-point det F of the last evaluation over all ranks, and
  // where its element's reference centroid lies: how near the mesh is to folding.
  struct Compression {
    double detF = 1;
    std::array<double, 3> centroid{};
  };
  Compression mostCompressed(const Teuchos::Comm<int>& comm) const;
  // The penalty eps of the Newton solves (the scene's eps1, raised to
  // Solver/Minimum Solve Penalty).
  double solvePenalty() const { return penalty_; }
  // Model raises the automatic floor for the monolithic loop (src/model.cpp).
  void setSolvePenalty(double eps) { penalty_ = eps; }
  // d v_e / d x at positions x (overlapped nodes), 24 per element (dof 3a+i).
  void volumeGradients(const NodalVectors& x, Matrix& g) const;
  // c_e = v_e - V_e with the anchor pbar_e: force -1 (dR/dpbar = -g_e),
  // Schur complement eps V_e, every element a row.
  void constraintRows(const NodalVectors& x, ConstraintRows& rows) const override;

  // Pressure anchors: G(pbar) = p(x); violation max |v/V - 1|.
  Kokkos::View<double*> multipliers() override { return pressureAnchor; }
  int multiplierSites(std::vector<int>& nodes) const override;  // an element's 8 nodes
  void multiplierMap(const Kokkos::View<double*>& next) const override;
  double constraintViolation() const override;
  double constraintTolerance() const override { return volumeTolerance_; }
  std::string constraintName() const override { return "volume change"; }

 protected:
  void launch(const NodalVectors& x, const NodalVectors& u, bool tangent, const TangentSink& sink) override;

 private:
  Kokkos::View<int* [8], Kokkos::LayoutRight> nodes_;
  Kokkos::View<double* [8][3], Kokkos::LayoutRight> X_;
  double c_, penalty_, volumeTolerance_;
};

}  // namespace capstan
