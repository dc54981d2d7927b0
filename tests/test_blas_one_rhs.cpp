// GEMM and TRSM with one right-hand side by GEMV and TRSV (src/blas_one_rhs.cpp):
// each case against a plain loop in double precision, for both precisions,
// every transposition, strided operands, and the shapes that go on to the BLAS
// library's own routine.
#include <dlfcn.h>
#include <gtest/gtest.h>

#include <cmath>
#include <cstddef>
#include <random>
#include <vector>

extern "C" {
void sgemm_(const char*, const char*, const int*, const int*, const int*, const float*, const float*, const int*,
            const float*, const int*, const float*, float*, const int*, std::size_t, std::size_t);
void dgemm_(const char*, const char*, const int*, const int*, const int*, const double*, const double*, const int*,
            const double*, const int*, const double*, double*, const int*, std::size_t, std::size_t);
void strsm_(const char*, const char*, const char*, const char*, const int*, const int*, const float*, const float*,
            const int*, float*, const int*, std::size_t, std::size_t, std::size_t, std::size_t);
void dtrsm_(const char*, const char*, const char*, const char*, const int*, const int*, const double*,
            const double*, const int*, double*, const int*, std::size_t, std::size_t, std::size_t, std::size_t);
}

namespace {

void gemm(const char* ta, const char* tb, int m, int n, int k, float alpha, const float* a, int lda, const float* b,
          int ldb, float beta, float* c, int ldc) {
  sgemm_(ta, tb, &m, &n, &k, &alpha, a, &lda, b, &ldb, &beta, c, &ldc, 1, 1);
}
void gemm(const char* ta, const char* tb, int m, int n, int k, double alpha, const double* a, int lda,
          const double* b, int ldb, double beta, double* c, int ldc) {
  dgemm_(ta, tb, &m, &n, &k, &alpha, a, &lda, b, &ldb, &beta, c, &ldc, 1, 1);
}
void trsm(const char* side, const char* uplo, const char* ta, const char* diag, int m, int n, float alpha,
          const float* a, int lda, float* b, int ldb) {
  strsm_(side, uplo, ta, diag, &m, &n, &alpha, a, &lda, b, &ldb, 1, 1, 1, 1);
}
void trsm(const char* side, const char* uplo, const char* ta, const char* diag, int m, int n, double alpha,
          const double* a, int lda, double* b, int ldb) {
  dtrsm_(side, uplo, ta, diag, &m, &n, &alpha, a, &lda, b, &ldb, 1, 1, 1, 1);
}

template <class T>
std::vector<T> randomValues(std::size_t n, std::mt19937& rng) {
  std::uniform_real_distribution<double> d(-1, 1);
  std::vector<T> v(n);
  for (auto& x : v) x = T(d(rng));
  return v;
}

// Column-major element (i, j) of op(X) for X stored with leading dimension ld.
template <class T>
double at(const std::vector<T>& x, int ld, bool t, int i, int j) {
  return t ? x[i * ld + j] : x[j * ld + i];
}

template <class T>
double tolerance() {
  return sizeof(T) == 4 ? 2e-5 : 1e-13;
}

template <class T>
void checkGemm(int m, int n, int k) {
  std::mt19937 rng(7 + m + 31 * n + 17 * k);
  for (const char* ta : {"N", "T"})
    for (const char* tb : {"N", "T"}) {
      const bool at_ = *ta == 'T', bt = *tb == 'T';
      const int lda = (at_ ? k : m) + 3, ldb = (bt ? n : k) + 2, ldc = m + 1;
      const auto a = randomValues<T>(std::size_t(lda) * (at_ ? m : k), rng);
      const auto b = randomValues<T>(std::size_t(ldb) * (bt ? k : n), rng);
      auto c = randomValues<T>(std::size_t(ldc) * n, rng);
      const auto c0 = c;
      const T alpha = T(0.75), beta = T(-0.5);
      gemm(ta, tb, m, n, k, alpha, a.data(), lda, b.data(), ldb, beta, c.data(), ldc);
      for (int j = 0; j < n; ++j)
        for (int i = 0; i < ldc; ++i) {
          const std::size_t p = std::size_t(j) * ldc + i;
          if (i >= m) {  // outside C: untouched
            EXPECT_EQ(c[p], c0[p]);
            continue;
          }
          double want = beta * double(c0[p]);
          for (int l = 0; l < k; ++l) want += alpha * at(a, lda, at_, i, l) * at(b, ldb, bt, l, j);
          EXPECT_NEAR(c[p], want, tolerance<T>() * k) << ta << tb << " m=" << m << " n=" << n << " k=" << k;
        }
    }
}

template <class T>
void checkTrsm(int m, int n) {
  std::mt19937 rng(11 + m + 13 * n);
  for (const char* uplo : {"U", "L"})
    for (const char* ta : {"N", "T"})
      for (const char* diag : {"N", "U"})
        for (const T alpha : {T(1), T(0.5)}) {
          const int lda = m + 2, ldb = m + 1;
          auto a = randomValues<T>(std::size_t(lda) * m, rng);
          for (int i = 0; i < m; ++i) a[i * lda + i] = T(2 + i % 3);  // well conditioned
          const auto b0 = randomValues<T>(std::size_t(ldb) * n, rng);
          auto x = b0;
          trsm("L", uplo, ta, diag, m, n, alpha, a.data(), lda, x.data(), ldb);
          // op(A) x = alpha b, with A's other triangle (and a unit diagonal) ignored.
          auto aij = [&](int i, int j) {
            if (i == j) return *diag == 'U' ? 1.0 : double(a[i * lda + i]);
            const bool upper = *uplo == 'U';
            if ((upper && i > j) || (!upper && i < j)) return 0.0;
            return double(a[std::size_t(j) * lda + i]);
          };
          for (int j = 0; j < n; ++j)
            for (int i = 0; i < m; ++i) {
              double lhs = 0;
              for (int l = 0; l < m; ++l)
                lhs += (*ta == 'T' ? aij(l, i) : aij(i, l)) * x[std::size_t(j) * ldb + l];
              EXPECT_NEAR(lhs, alpha * double(b0[std::size_t(j) * ldb + i]), tolerance<T>() * m)
                  << uplo << ta << diag << " alpha=" << alpha << " m=" << m << " n=" << n;
            }
          for (int j = 0; j < n; ++j) EXPECT_EQ(x[std::size_t(j) * ldb + m], b0[std::size_t(j) * ldb + m]);
        }
}

}  // namespace

// One column: GEMV's path. Several columns and empty products: the library's.
TEST(BlasOneRhs, GemmOneColumnAndOthers) {
  for (int n : {1, 3}) {
    checkGemm<float>(37, n, 23);
    checkGemm<double>(37, n, 23);
    checkGemm<double>(1, n, 40);
  }
  checkGemm<double>(5, 1, 0);  // k = 0: C = beta C (GEMV would leave C as it is)
  checkGemm<float>(5, 1, 0);
}

TEST(BlasOneRhs, TrsmOneColumnAndOthers) {
  for (int n : {1, 2}) {
    checkTrsm<float>(29, n);
    checkTrsm<double>(29, n);
  }
}

// MUMPS binds to the program's routines: the global scope finds them before
// the BLAS library's, which are still there behind them.
TEST(BlasOneRhs, ProgramRoutinesComeFirst) {
  for (const char* name : {"sgemm_", "dgemm_", "strsm_", "dtrsm_"}) {
    void* first = dlsym(RTLD_DEFAULT, name);
    void* next = dlsym(RTLD_NEXT, name);
    ASSERT_NE(first, nullptr) << name;
    ASSERT_NE(next, nullptr) << name;
    EXPECT_NE(first, next) << name;
  }
  EXPECT_EQ(dlsym(RTLD_DEFAULT, "dgemm_"), reinterpret_cast<void*>(&dgemm_));
  EXPECT_EQ(dlsym(RTLD_DEFAULT, "strsm_"), reinterpret_cast<void*>(&strsm_));
}
