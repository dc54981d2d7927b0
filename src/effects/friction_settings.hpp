// A capstan's Friction sublist, typed: declared and parsed side by side, the
// only place its defaults are stated. FrictionEffect reads it as it is.
#pragma once

#include <Teuchos_ParameterList.hpp>

#include <utility>
#include <vector>

#include "../parameters.hpp"

namespace capstan {

struct FrictionSettings {
  // Values are kernels::FrictionLaw's (checked in friction.cpp).
  enum class Law { None = 0, Tanh = 1, Arctan = 2, Coulomb = 3 };

  Law law = Law::None;
  double coefficient = 0;        // mu
  double regularization = 0;     // eps3 (Tanh) / eps4 (Arctan): slip speed scale
  double tangentialPenalty = 0;  // Coulomb eps_t; 0: the contact's solve penalty
  double smoothing = 0;          // Coulomb: width of the smoothed stick/slip corner

  // Some friction kernel runs (a zero coefficient still runs it).
  bool on() const { return law != Law::None; }
  // Friction that can carry a load (holds a free core's rotation).
  bool grips() const { return on() && coefficient > 0; }

  static void declare(Teuchos::ParameterList& friction);
  static FrictionSettings parse(const Teuchos::ParameterList& friction, const std::string& path,
                                const ParameterReader& r);
  static const std::vector<std::pair<const char*, Law>> laws;
};

}  // namespace capstan
