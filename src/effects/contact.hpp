#pragma once

#include "effect.hpp"
#include "../scene.hpp"

#include "../../kernels/contact.hpp"

#include <array>
#include <string>
#include <vector>

namespace capstan {

// Normal contact of candidate faces with one rigid capstan (kernels/contact.hpp).
// Penalty or augmented Lagrangian; faces the capstan does not touch are
// inactive and cost only their gap check.
class ContactEffect : public Effect {
 public:
  // `c`: the body's material constant (the automatic solve penalty).
  // `exactStick`: the friction on these faces sticks exactly (steady Coulomb).
  ContactEffect(const std::string& name, const Mesh& mesh, const std::vector<int>& quads,
                const CapstanSpec& capstan, double c, bool exactStick = false);

  void setInterval(double tStart, double tEnd) override;
  // Multipliers only where they change the answer: the augmented Lagrangian,
  // or a penalty solved at a larger penalty than the scene's.
  bool augmented() const { return compliance_ < solvePenalty_; }
  double solvePenalty() const { return solvePenalty_; }
  // A Gauss rule the scene names with a Penalty that Auto would give the nodal
  // rule: what the run warns of (empty otherwise).
  const std::string& quadratureWarning() const { return quadratureWarning_; }
  // Faces near the capstan longer than its diameter: what the run warns of (empty otherwise).
  const std::string& coarseFacesWarning() const { return coarseFacesWarning_; }
  // A plain penalty soft for this mesh and material (empty if none).
  const std::string& softPenaltyWarning() const { return softPenaltyWarning_; }
  Kokkos::View<double*> multipliers() override {
    return augmented() ? lambda_ : Kokkos::View<double*>();
  }
  void multiplierMap(const Kokkos::View<double*>& next) const override;
  void projectMultipliers() override;
  // Exact contact with the nodal rule: each point's node.
  int multiplierSites(std::vector<int>& nodes) const override;
  // Plain Uzawa: each update removes most of the penetration already (the
  // penalty is much stiffer than the body), and mixing across the kink of
  // max(0, .) where points enter or leave contact made the loop wander.
  bool accelerated() const override { return false; }
  double constraintViolation() const override;
  // Exact contact's points in contact (t_n > 0; the augmented Lagrangian
  // without a smoothed corner): c_q = g_q - kappa lambda_q, gradient -N_a e,
  // force w (1 - kappa / eps) (w: reference area weight), Schur complement
  // -eps. Other points keep the plain update.
  void constraintRows(const NodalVectors& x, ConstraintRows& rows) const override;
  double constraintTolerance() const override { return tolerance_; }
  std::string constraintName() const override { return name() + " penetration"; }
  int maxAugmentations() const override { return settings().maxAugmentations; }
  // Starts the capstan's record: force, torque, penetration, pressure, area, width.
  void report(const Teuchos::Comm<int>& comm, StepRecord& rec) const override;

  // This rank's share of the capstan's figures at the last evaluation. The
  // contact angles are measured about the axis from `reference` (a unit vector
  // normal to the axis; zero: angles not wanted).
  struct Figures {
    std::array<double, 3> force{};  // body on capstan
    double torque = 0;              // body on capstan, about its axis
    double maxPenetration = 0, peakPressure = 0, area = 0;
    long points = 0;
    double angleMin = 0, angleMax = 0;  // +-inf-like sentinels when no point
  };
  Figures figures(const std::array<double, 3>& reference) const;
  // Per face: mean contact pressure, largest gap, mean traction on the body (3).
  void faceFields(std::vector<double>& pressure, std::vector<double>& gap,
                  std::vector<double>& traction) const;
  const std::array<double, 3>& axisDirection() const { return beta_; }
  double radius() const { return capstan_.radius; }
  // The face the capstan cuts deepest between its contact points, relative to the face's
  // longest edge (collective; kernels::faceCut): a quarter of an edge or more means the body
  // has passed through the capstan, or the faces are too coarse to hold it.
  struct Cut {
    double depth = 0, edge = 0;
    std::array<double, 3> at{};
  };
  Cut deepestCut(const NodalVectors& x, const Teuchos::Comm<int>& comm) const;
  // The body's node (any node, x: all of this rank's) deepest inside the capstan (collective;
  // `edge` unused): beyond the contact points' own penetration only where the capstan is
  // inside the body, which its faces closed behind.
  Cut deepestNode(const NodalVectors& x, const Teuchos::Comm<int>& comm) const;
  // The shortest candidate face edge over all ranks (the mesh's scale at the contact).
  double shortestEdge() const { return shortestEdge_; }
  // Predictor: the contact tangent without its geometric stiffness (see
  // kernels/contact.hpp).
  void setPredicting(bool on) override { predicting_ = on; }
  // What friction on the same faces needs: the cylinder now, the normal
  // multipliers, the penalties and the rule.
  kernels::Cylinder cylinder() const;
  Kokkos::View<double*> normalMultipliers() const { return lambda_; }
  double compliance() const { return compliance_; }
  kernels::FaceRule rule() const { return kernels::FaceRule(int(settings().quadrature)); }
  const CapstanSpec& capstan() const { return capstan_; }
  const ContactSettings& settings() const { return capstan_.contact; }
  size_t numFaces() const { return nodes_.extent(0); }
  // Per face and point at the last evaluation (host copy), fields PointField.
  enum PointField { kGap = 0, kPressure, kWeight, kArea, kE, kX = kE + 3 };
  using Points = Kokkos::View<double** [10], Kokkos::LayoutRight>;
  Points::HostMirror pointsOnHost() const { return Kokkos::create_mirror_view_and_copy(Kokkos::HostSpace(), points_); }

 protected:
  void launch(const NodalVectors& x, const NodalVectors& u, bool tangent, const TangentSink& sink) override;

 private:
  Kokkos::View<int* [4], Kokkos::LayoutRight> nodes_;
  Kokkos::View<double* [4][3], Kokkos::LayoutRight> X_;
  Kokkos::View<double*> lambda_;  // [face * kMaxFacePoints + q]
  // Per face and point at the last evaluation: gap, pressure, weight, area, e (3), x (3).
  Points points_;
  CapstanSpec capstan_;
  double shortestEdge_ = 0;
  double tolerance_ = 0;          // on eps |t_n - lambda| (length), resolved against the mesh
  std::array<double, 3> beta_{};  // unit axis direction
  double time_ = 0;
  std::string quadratureWarning_;
  std::string coarseFacesWarning_;
  std::string softPenaltyWarning_;
  bool predicting_ = false;
  double solvePenalty_ = 1e-3;  // eps of the Newton solves
  double compliance_ = 1e-3;    // kappa: g = kappa t_n at the fixed point (0: exact contact)
};

}  // namespace capstan
