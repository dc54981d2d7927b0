// Anderson acceleration of a fixed-point iteration x <- G(x) over distributed
// vectors (each rank holds its part; dot products are summed over ranks).
//
// Why: the pressure-anchor loop pbar <- p(x) converges at rate
// 1 / (1 + lambda / eps) per pressure mode, lambda the mode's eigenvalue of the
// Schur complement G^T K^-1 G. Q1P0 has nearly spurious pressure modes with
// tiny lambda, so the plain iteration crawls on them; Anderson mixing removes
// those few slow modes in a few iterations (it acts like GMRES on the loop).
#pragma once

#include <Teuchos_CommHelpers.hpp>

#include <cmath>
#include <deque>
#include <vector>

#include "types.hpp"

namespace capstan {

class AndersonMixing {
 public:
  AndersonMixing(int depth, RCP<const Comm> comm) : depth_(depth), comm_(std::move(comm)) {}

  // x: current iterate, g: G(x). Returns the next iterate.
  std::vector<double> next(const std::vector<double>& x, const std::vector<double>& g) {
    const size_t n = x.size();
    std::vector<double> f(n);
    for (size_t i = 0; i < n; ++i) f[i] = g[i] - x[i];
    if (started_) {
      std::vector<double> df(n), dg(n);
      for (size_t i = 0; i < n; ++i) df[i] = f[i] - fPrev_[i], dg[i] = g[i] - gPrev_[i];
      dF_.push_back(df);
      dG_.push_back(dg);
      if (int(dF_.size()) > depth_) dF_.pop_front(), dG_.pop_front();
    }
    fPrev_ = f;
    gPrev_ = g;
    started_ = true;
    const int m = int(dF_.size());
    if (m == 0) return g;
    // Least squares min |f - dF gamma| by the normal equations (m is small).
    std::vector<double> local(m * m + m, 0.0), A(m * m + m);
    for (int a = 0; a < m; ++a) {
      for (int b = 0; b < m; ++b) local[a * m + b] = dot(dF_[a], dF_[b]);
      local[m * m + a] = dot(dF_[a], f);
    }
    Teuchos::reduceAll(*comm_, Teuchos::REDUCE_SUM, int(local.size()), local.data(), A.data());
    std::vector<double> gamma;
    if (!solve(A, m, gamma)) {  // degenerate history: restart it
      dF_.clear(), dG_.clear();
      return g;
    }
    std::vector<double> out = g;
    for (int a = 0; a < m; ++a)
      for (size_t i = 0; i < n; ++i) out[i] -= gamma[a] * dG_[a][i];
    return out;
  }

 private:
  static double dot(const std::vector<double>& a, const std::vector<double>& b) {
    double s = 0;
    for (size_t i = 0; i < a.size(); ++i) s += a[i] * b[i];
    return s;
  }
  // Gaussian elimination with partial pivoting on [A | b] (A m x m, b after it).
  static bool solve(std::vector<double> Ab, int m, std::vector<double>& x) {
    double scale = 0;
    for (int a = 0; a < m; ++a) scale = std::max(scale, Ab[a * m + a]);
    if (!(scale > 0)) return false;
    for (int a = 0; a < m; ++a) Ab[a * m + a] += 1e-13 * scale;  // mild regularisation
    std::vector<double> b(Ab.begin() + m * m, Ab.end());
    for (int k = 0; k < m; ++k) {
      int piv = k;
      for (int r = k + 1; r < m; ++r)
        if (std::fabs(Ab[r * m + k]) > std::fabs(Ab[piv * m + k])) piv = r;
      if (std::fabs(Ab[piv * m + k]) < 1e-300) return false;
      for (int c = 0; c < m; ++c) std::swap(Ab[k * m + c], Ab[piv * m + c]);
      std::swap(b[k], b[piv]);
      for (int r = k + 1; r < m; ++r) {
        const double l = Ab[r * m + k] / Ab[k * m + k];
        for (int c = k; c < m; ++c) Ab[r * m + c] -= l * Ab[k * m + c];
        b[r] -= l * b[k];
      }
    }
    x.assign(m, 0.0);
    for (int k = m - 1; k >= 0; --k) {
      double s = b[k];
      for (int c = k + 1; c < m; ++c) s -= Ab[k * m + c] * x[c];
      x[k] = s / Ab[k * m + k];
    }
    for (double v : x)
      if (!std::isfinite(v)) return false;
    return true;
  }

  int depth_;
  RCP<const Comm> comm_;
  bool started_ = false;  // (a rank may hold no element: emptiness is no test)
  std::vector<double> fPrev_, gPrev_;
  std::deque<std::vector<double>> dF_, dG_;
};

}  // namespace capstan
