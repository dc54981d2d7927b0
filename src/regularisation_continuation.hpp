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
// started through a sequence of wider laws, v x 3^k for k = K, ..., 1, each
// solve starting from the last, and ends with the scene's own law (k = 0).
// 3^K is about a third of the travel over v: the first law is smooth on the
// scale of the increment, and each next one sees its sticking points within a
// few of its v (3 per stage converged in a handful of Newton iterations each
// in H4; 10 per stage stagnated).
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
  // travel over slip scale above 3).
  bool applies() const { return stages_ > 0; }
  // The solve through the stages from u (the failed solve's start, in place).
  // The iterations of every stage are summed in the result; it fails where a
  // stage fails.
  NewtonResult solve(NewtonSolver& newton, Vector& u, double tolerance);
  int stages() const { return stages_; }

 private:
  void setScale(double scale);
  std::vector<FrictionEffect*> frictions_;
  Log& log_;
  int stages_ = 0;
};

}  // namespace capstan
