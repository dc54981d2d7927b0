// The figures of a converged state, reduced over all ranks: a step's record
// (supports' reactions, rigid cores' motion, capstans' forces, contact and
// friction figures) and the final state's extrema for summary.json.
#pragma once

#include <string>
#include <utility>
#include <vector>

#include "model.hpp"
#include "step_record.hpp"

namespace capstan {

// Fills rec.supports and rec.capstans from the last evaluation (collective).
// `earlier`: the steps before it (a core's angular velocity is its rotation's
// increment over the step).
void measureStep(const Model& model, const std::vector<StepRecord>& earlier, StepRecord& rec);

// The final state's figures (summary.json "final").
struct StateFigures {
  struct Range {
    double min = 0, max = 0;
  };
  Range vonMises, pressure;
  Range stress[6];  // xx yy zz xy yz xz
  double volumeChange = 0;  // max |v / V - 1|
  std::array<double, 3> maxDisplacement{};
  std::vector<std::pair<std::string, std::array<double, 3>>> faceMeans;  // mean displacement per named face
};
StateFigures stateFigures(const Model& model);

// Element stress (6 per element), von Mises and pressure on the host, at the
// last evaluated state.
struct ElementFields {
  Matrix::HostMirror stress;
  Kokkos::View<double*>::HostMirror mises, pressure;
};
ElementFields elementFields(const Model& model);

}  // namespace capstan
