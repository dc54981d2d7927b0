// The Analysis sublist (interface.md, "Steady rolling"): which problem each
// step solves. Declared, parsed and checked against the rest of the scene here.
#pragma once

#include <Teuchos_ParameterList.hpp>

#include <utility>
#include <vector>

#include "parameters.hpp"

namespace capstan {

struct Scene;

struct AnalysisSettings {
  // QuasiStatic: a Lagrangian mesh moved through the load steps (formulation.md
  // §5). SteadyRolling: each step's steady rolling state, the mesh fixed and
  // the material flowing through it about the annulus axis (§8).
  enum class Type { QuasiStatic, SteadyRolling };
  Type type = Type::QuasiStatic;
  // Steady rolling: order of the upwind difference along the rings (1 or 2).
  int upwindOrder = 2;
  // Steady rolling with Coulomb friction (or a much narrower Tanh or Arctan): the Tanh laws the
  // start from rest passes through, as fractions of the capstan's surface speed, widest first;
  // chosen by the Newton totals over many scenes (docs/steady-rolling.md, "The scales").
  std::vector<double> startSlipScales = {0.06, 0.015, 0.004};

  bool steady() const { return type == Type::SteadyRolling; }
  const char* name() const { return nameOf(type, types); }

  static void declare(Teuchos::ParameterList& analysis);
  static AnalysisSettings parse(const Teuchos::ParameterList& analysis, const ParameterReader& r);
  // Steady rolling needs an annulus turning about its own axis on a Rigid Core
  // (or Fixed) inner face, and spinning capstans parallel to it that stay put:
  // anything else fails with the parameter's path.
  static void checkScene(const Scene& scene, const ParameterReader& r);
  static const std::vector<std::pair<const char*, Type>> types;
};

}  // namespace capstan
