// Continuation in the friction regularisation (docs/friction.md, "Tiny
// regularisation"): Tanh and Arctan give the friction traction as
// mu t_n phi(|slip| / v), v = eps3 dt. Newton's linear model of that law holds
// only within about v of zero slip, while the capstan's surface travels
// (|omega| R + |velocity|) dt in the increment: 25,000 v in the study's H4.
// Where part of the contact sticks, Newton must land those points within v of
// zero slip from a state where they slip by the whole travel; it reverses
// every slip instead, and fails. Step cuts do not help (v and the travel both
// scale with dt).
//
// So when a Newton solve fails with such a law, it is repeated from where it
// started through a sequence of wider laws, v x 3^k for k = k0, ..., 1, each
// solve starting from the last, and ends with the scene's own law (k = 0).
// Each law sees its sticking points within a few of its v (3 per stage
// converged in a handful of Newton iterations each in H4; 10 per stage
// stagnated). A short sequence first, k0 = 2: a wide law moves a free
// roller's steady state far from the scene's (the steady slice with Tanh,
// eps3 = 1e-2, fails from k0 >= 4 and converges from 2 or 3). If that fails,
// the whole sequence from where the solve started, 3^K about a third of the
// travel over v: the first law smooth on the scale of the increment (H4's
// first step and H5 at eps3 = 1e-5 need it).
//
// Coulomb with the exact stick/slip corner: a point whose trial traction sits
// at the cone's edge (within 1e-7 on the fast rollers) gives Newton one side's
// generalised Jacobian, along whose direction |R| can rise: the line search
// fails after one good step, at |R| ~ 1e-4 of its start. A failed solve is
// then repeated from its start with the corner smoothed (Friction/Smoothing =
// kCornerSmoothing: stick tractions softened by about delta^2 / 4), and ends
// with the exact corner from that answer.
#pragma once

#include <string>
#include <vector>

#include "log.hpp"
#include "newton.hpp"

namespace capstan {

class FrictionEffect;

class RegularisationContinuation {
 public:
  RegularisationContinuation(const std::vector<FrictionEffect*>& frictions, Log& log);
  // Whether a failed solve can be retried this way (some regularised law with
  // travel over slip scale above 3, or Coulomb with the exact corner).
  bool applies() const { return stages_ > 0 || !corners_.empty(); }
  // Whether it widens a regularised law (else: Coulomb's corner only).
  bool regularised() const { return stages_ > 0; }
  // Whether a retry can change a failed solve now: a regularised law or
  // Coulomb's exact corner in force (not friction switched off, nor Tanh in
  // Coulomb's place: steady rolling's start, src/steady_rolling.cpp).
  bool canRetry() const;
  // The solve through the stages from u (the failed solve's start, in place):
  // the short sequence, then if it fails the whole one. The iterations of
  // every stage are summed in the result.
  NewtonResult solve(NewtonSolver& newton, Vector& u, double tolerance);
  int stages() const { return stages_; }

 private:
  // Stages 3^first, ..., 3^0 from u; adds to `total`, false where one fails.
  bool sequence(NewtonSolver& newton, Vector& u, double tolerance, int first, NewtonResult& total);
  void setScale(double scale);
  // Coulomb: the smoothed corner's solve, then the exact corner's from it.
  bool cornerSequence(NewtonSolver& newton, Vector& u, double tolerance, NewtonResult& total);
  // Adds a stage's solve to `total`; false where it failed.
  // power >= 0: the regularisation's stage 3^power (logged as such).
  bool stage(NewtonSolver& newton, Vector& u, double tolerance, const std::string& what, int power,
             NewtonResult& total);
  std::vector<FrictionEffect*> frictions_;
  std::vector<FrictionEffect*> corners_;  // Coulomb with the exact corner
  Log& log_;
  int stages_ = 0;
};

}  // namespace capstan
