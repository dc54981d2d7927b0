// Physical effects: each is a small object the scene switches on, owning its
// data and launching its Kokkos kernel over its entities (bricks or faces). All
// of them hand the same thing to the one assembly path: per-entity dof ids,
// residual and tangent (LocalSystem).
#pragma once

#include <Kokkos_Core.hpp>

#include <array>
#include <string>
#include <vector>

namespace capstan {

struct Mesh;

using ExecSpace = Kokkos::DefaultExecutionSpace;
// Row-major per entity, so a kernel works on contiguous element data.
using IntMatrix = Kokkos::View<int**, Kokkos::LayoutRight>;
using Matrix = Kokkos::View<double**, Kokkos::LayoutRight>;
using Tensor3 = Kokkos::View<double***, Kokkos::LayoutRight>;
using NodalVectors = Kokkos::View<double* [3], Kokkos::LayoutRight>;

struct LocalSystem {
  IntMatrix dofs;  // [entity][k]: overlapped dof ids (3 * node + component)
  Matrix R;        // [entity][k]
  Tensor3 K;       // [entity][k][l]
};

class Effect {
 public:
  explicit Effect(std::string name) : name_(std::move(name)) {}
  virtual ~Effect() = default;
  const std::string& name() const { return name_; }
  // Residual (and tangent) at current positions x and displacements u (overlapped nodes).
  void evaluate(const NodalVectors& x, const NodalVectors& u, bool tangent);
  const LocalSystem& local() const { return local_; }
  long launches() const { return launches_; }
  double seconds() const { return seconds_; }

 protected:
  virtual void launch(const NodalVectors& x, const NodalVectors& u, bool tangent) = 0;
  LocalSystem local_;

 private:
  std::string name_;
  long launches_ = 0;
  double seconds_ = 0;
};

// Q1P0 incompressible neo-Hookean bricks, the whole body.
class BrickEffect : public Effect {
 public:
  BrickEffect(const Mesh& mesh, double c, double penalty);
  Kokkos::View<double*> pressureAnchor;  // pbar per element (outer loop updates it)
  Kokkos::View<double*> pressure;        // p(x) at the last evaluation
  Kokkos::View<double*> volume;          // v at the last evaluation
  Kokkos::View<double*> referenceVolume; // V
  Kokkos::View<double*> minJacobian;     // smallest Gauss-point det F
  // Element Cauchy stress (xx yy zz xy yz xz) and von Mises at the centroids.
  void centroidStress(const NodalVectors& x, Matrix& stress, Kokkos::View<double*>& mises) const;
  double c() const { return c_; }

 protected:
  void launch(const NodalVectors& x, const NodalVectors& u, bool tangent) override;

 private:
  Kokkos::View<int* [8], Kokkos::LayoutRight> nodes_;
  Kokkos::View<double* [8][3], Kokkos::LayoutRight> X_;
  double c_, penalty_;
};

// Elastic foundation on one face: t = -k (x - X) on the listed components.
class FoundationEffect : public Effect {
 public:
  FoundationEffect(const std::string& name, const Mesh& mesh, const std::string& face, double k,
                   std::array<bool, 3> components);
  // Total force the foundation exerts on the body (this rank's faces).
  std::array<double, 3> localForceOnBody() const;

 protected:
  void launch(const NodalVectors& x, const NodalVectors& u, bool tangent) override;

 private:
  Kokkos::View<int* [4], Kokkos::LayoutRight> nodes_;
  Kokkos::View<double* [4][3], Kokkos::LayoutRight> X_;
  double k_;
  int mask_[3];
};

}  // namespace capstan
