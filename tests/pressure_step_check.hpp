// The saddle-point step (src/pressure_step.hpp) checked through the
// assembly's own residual and constraint values, at the state of its last
// evaluation (f, W: its residual and tangent):
// - each effect's columns: (R(mu_i + s dmu_i) - R(mu_i)) / s against the
//   step's dR/dmu_i dmu_i, relative (R is linear in every multiplier while the
//   points keep their contact and stick states);
// - every row's linearisation c_j + dc_j/dx . dx = 0, a central difference
//   along dx: returned per effect as max |c + dc/dx dx| / max |c| (all ranks).
// Shared by tests/test_assembly.cpp and tests/test_steady_rolling.cpp.
#pragma once

#include <Tpetra_Core.hpp>
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <map>
#include <string>
#include <tuple>
#include <vector>

#include <Tpetra_Export.hpp>

#include "assembly.hpp"
#include "newton.hpp"
#include "pressure_step.hpp"

namespace capstan::test {

// Each rank's constraint values c_j by (effect, multiplier index, row of that
// multiplier: a stick traction has one per tangent), at the last evaluation.
using RowKey = std::tuple<size_t, int, int>;
inline std::map<RowKey, double> constraintValues(Assembly& assembly) {
  std::map<RowKey, double> out;
  ConstraintRows rows;
  for (size_t i = 0; i < assembly.effects().size(); ++i) {
    assembly.effects()[i]->constraintRows(assembly.positions(), rows);
    std::map<int, int> seen;
    for (size_t k = 0; k < rows.size(); ++k) out[{i, rows.multiplier[k], seen[rows.multiplier[k]]++}] = rows.value[k];
  }
  return out;
}

struct StepCheck {
  PressureStep::Result result;
  std::map<std::string, double> rowError;  // by effect name
  std::map<std::string, long> rows;        // by effect name, all ranks
  // By effect name: |dR/dmu_i dmu_i - the residual's change| / |the change|.
  std::map<std::string, double> columnError;
};

inline StepCheck checkPressureStep(Assembly& assembly, NewtonSolver& newton, const Vector& u, const Vector& f,
                                   const CrsMatrix& W,
                                   PressureStep::Preconditioner preconditioner = PressureStep::Preconditioner::Block,
                                   Vector* dxOut = nullptr) {
  auto comm = Tpetra::getDefaultComm();
  StepCheck out;
  const auto c0 = constraintValues(assembly);

  std::vector<Kokkos::View<double*>> dmu;
  PressureStep step(assembly, PressureStep::Schur::Laplacian, preconditioner);
  Vector dx(assembly.dofMap());
  out.result = step.solve(W, newton.approximateInverse(), f, 1e-12, 0.0, 500, dx, dmu);
  EXPECT_LT(out.result.reduction, 1e-11);
  if (dxOut) dxOut->update(1.0, dx, 0.0);

  // Momentum rows.
  std::vector<std::vector<double>> mu0;
  for (const auto& e : assembly.effects()) {
    auto h = Kokkos::create_mirror_view_and_copy(Kokkos::HostSpace(), e->multipliers());
    mu0.emplace_back(h.data(), h.data() + h.size());
  }
  auto setMultipliers = [&](double s) {
    for (size_t i = 0; i < mu0.size(); ++i) {
      auto mu = assembly.effects()[i]->multipliers();
      if (mu.extent(0) == 0) continue;
      auto h = Kokkos::create_mirror_view(mu);
      auto d = Kokkos::create_mirror_view_and_copy(Kokkos::HostSpace(), dmu[i]);
      for (size_t k = 0; k < h.extent(0); ++k) h(k) = mu0[i][k] + s * d(k);
      Kokkos::deep_copy(mu, h);
    }
  };
  // Each effect's columns: (R(mu_i + s dmu_i) - R(mu_i)) / s against the
  // step's dR/dmu_i dmu_i (force_j gradient_j, or the row's own column).
  const double s = 1e-4;
  for (size_t i = 0; i < mu0.size(); ++i) {
    auto mu = assembly.effects()[i]->multipliers();
    if (mu.extent(0) == 0) continue;
    Vector measured(assembly.dofMap()), predicted(assembly.dofMap());
    {
      auto h = Kokkos::create_mirror_view(mu);
      auto d = Kokkos::create_mirror_view_and_copy(Kokkos::HostSpace(), dmu[i]);
      for (size_t k = 0; k < h.extent(0); ++k) h(k) = mu0[i][k] + s * d(k);
      Kokkos::deep_copy(mu, h);
    }
    EXPECT_TRUE(assembly.evaluate(u, &measured, nullptr));
    setMultipliers(0);
    measured.update(-1 / s, f, 1 / s);
    ConstraintRows rows;
    assembly.effects()[i]->constraintRows(assembly.positions(), rows);
    std::vector<size_t> start;
    std::vector<GO> cols;
    std::vector<double> vals;
    const bool own = rows.column.extent(0) > 0;
    if (rows.size() > 0)
      assembly.chainRows(*assembly.effects()[i], own ? rows.column : rows.gradient, start, cols, vals, &rows.entity, true);
    // Summed over this rank's rows by global dof, then exported (ADD): a row
    // reaches dofs other ranks own.
    std::map<GO, double> byDof;
    auto d = Kokkos::create_mirror_view_and_copy(Kokkos::HostSpace(), dmu[i]);
    for (size_t k = 0; k < rows.size(); ++k) {
      double dm = 0;
      if (rows.direction.empty()) dm = d(rows.multiplier[k]);
      else
        for (int c = 0; c < 3; ++c) dm += d(rows.multiplier[k] + c) * rows.direction[3 * k + c];
      for (size_t l = start[k]; l < start[k + 1]; ++l) byDof[cols[l]] += (own ? 1.0 : rows.force[k]) * vals[l] * dm;
    }
    std::vector<GO> gids;
    for (const auto& [g, x] : byDof) gids.push_back(g);
    auto touched = rcp(new Map(Teuchos::OrdinalTraits<Tpetra::global_size_t>::invalid(),
                               Teuchos::ArrayView<const GO>(gids.data(), gids.size()), GO(0), comm));
    Vector local(touched);
    {
      auto ld = local.getDataNonConst();
      size_t k = 0;
      for (const auto& [g, x] : byDof) ld[k++] = x;
    }
    predicted.doExport(local, Tpetra::Export<LO, GO>(touched, assembly.dofMap()), Tpetra::ADD);
    const double scale = measured.norm2();
    predicted.update(-1.0, measured, 1.0);
    const double error = predicted.norm2();  // collective
    out.columnError[assembly.effects()[i]->name()] = scale > 0 ? error / scale : error;
  }

  // Constraint rows: (c(u + h dx) - c(u - h dx)) / 2h = -c (D = 0 here: exact
  // contact and stick, and the anchors do not enter v).
  const double h = 1e-5;
  std::map<RowKey, double> cp, cm;
  for (double sign : {1.0, -1.0}) {
    Vector us(u, Teuchos::Copy);
    us.update(sign * h, dx, 1.0);
    EXPECT_TRUE(assembly.evaluate(us, nullptr, nullptr));
    (sign > 0 ? cp : cm) = constraintValues(assembly);
  }
  const size_t n = assembly.effects().size();
  std::vector<double> worst(n, 0.0), largest(n, 0.0), count(n, 0.0);
  for (const auto& [key, c] : c0) {
    const size_t i = std::get<0>(key);
    EXPECT_TRUE(cp.count(key) && cm.count(key)) << "row " << i << "/" << std::get<1>(key) << " changed state";
    if (!cp.count(key) || !cm.count(key)) continue;
    worst[i] = std::max(worst[i], std::fabs((cp[key] - cm[key]) / (2 * h) + c));
    largest[i] = std::max(largest[i], std::fabs(c));
    count[i] += 1;
  }
  for (size_t i = 0; i < n; ++i) {
    double w = 0, l = 0, rows = 0;
    Teuchos::reduceAll(*comm, Teuchos::REDUCE_MAX, worst[i], Teuchos::outArg(w));
    Teuchos::reduceAll(*comm, Teuchos::REDUCE_MAX, largest[i], Teuchos::outArg(l));
    Teuchos::reduceAll(*comm, Teuchos::REDUCE_SUM, count[i], Teuchos::outArg(rows));
    const std::string& name = assembly.effects()[i]->name();
    out.rows[name] = long(rows);
    if (rows > 0) out.rowError[name] = l > 0 ? w / l : w;
  }
  return out;
}

}  // namespace capstan::test
