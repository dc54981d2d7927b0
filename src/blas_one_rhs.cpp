// GEMM and TRSM with one right-hand side, done by GEMV and TRSV.
//
// Why: MUMPS' solve phase calls xGEMM and xTRSM with NRHS = 1 for every
// front, and OpenBLAS 0.3.21 (Debian's) handles those like any matrix
// product: it first copies ("packs") the front's block into a buffer, then
// multiplies by one column. The copy reads and writes the factors once more
// than the product itself. In G1 2x the packing took 19% of the run and the
// solves about 40% (`perf`, docs/performance.md "Against GetFEM"). GEMV and
// TRSV stream the block once. Newer OpenBLAS forwards such calls itself.
//
// How: capstan's programs define sgemm_, dgemm_, strsm_ and dtrsm_ and export
// them (CMakeLists.txt), so the dynamic linker binds MUMPS' (and Trilinos')
// calls here before the BLAS library; every other call goes on to the BLAS
// library's own routine (dlsym RTLD_NEXT). Same arithmetic, another order of
// the sums: results change in the last bits only. Not where the library has a
// small-matrix path that does not pack (below). CAPSTAN_BLAS_ONE_RHS=off or on
// in the environment overrides the choice (for comparisons).
#include <dlfcn.h>

#include <cstddef>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <initializer_list>

#include <strings.h>

extern "C" {
void sgemv_(const char*, const int*, const int*, const float*, const float*, const int*, const float*, const int*,
            const float*, float*, const int*, std::size_t);
void dgemv_(const char*, const int*, const int*, const double*, const double*, const int*, const double*, const int*,
            const double*, double*, const int*, std::size_t);
void strsv_(const char*, const char*, const char*, const int*, const float*, const int*, float*, const int*,
            std::size_t, std::size_t, std::size_t);
void dtrsv_(const char*, const char*, const char*, const int*, const double*, const int*, double*, const int*,
            std::size_t, std::size_t, std::size_t);
void sscal_(const int*, const float*, float*, const int*);
void dscal_(const int*, const double*, double*, const int*);
}

namespace {

template <class T>
using Gemm = void (*)(const char*, const char*, const int*, const int*, const int*, const T*, const T*, const int*,
                      const T*, const int*, const T*, T*, const int*, std::size_t, std::size_t);
template <class T>
using Trsm = void (*)(const char*, const char*, const char*, const char*, const int*, const int*, const T*, const T*,
                      const int*, T*, const int*, std::size_t, std::size_t, std::size_t, std::size_t);

// The BLAS library's own routine, the one the dynamic linker would have bound.
template <class F>
F blasRoutine(const char* name) {
  void* f = dlsym(RTLD_NEXT, name);
  if (!f) {
    std::fprintf(stderr, "capstan: no BLAS routine %s after capstan's own (%s)\n", name, dlerror());
    std::exit(3);
  }
  return reinterpret_cast<F>(f);
}

bool transposed(const char* op) { return *op != 'N' && *op != 'n'; }

// Whether the BLAS library multiplies small matrices without packing them: OpenBLAS' AVX-512
// kernels (SkylakeX, Cooperlake, SapphireRapids) have such a path, and there the library's own
// routines were as fast or faster on G1 2x (docs/performance.md, "Defaults and why").
bool libraryHasSmallGemm() {
  using CoreName = const char* (*)();
  const auto corename = reinterpret_cast<CoreName>(dlsym(RTLD_DEFAULT, "openblas_get_corename"));
  const char* core = corename ? corename() : nullptr;
  if (!core) return false;
  for (const char* name : {"skylakex", "cooperlake", "sapphirerapids"})
    if (strcasecmp(core, name) == 0) return true;
  return false;
}

// CAPSTAN_BLAS_ONE_RHS = on or off forces the choice; unset: on unless the library has that path.
bool enabled() {
  static const bool on = [] {
    const char* v = std::getenv("CAPSTAN_BLAS_ONE_RHS");
    if (v && (std::strcmp(v, "off") == 0 || std::strcmp(v, "0") == 0)) return false;
    if (v && (std::strcmp(v, "on") == 0 || std::strcmp(v, "1") == 0)) return true;
    return !libraryHasSmallGemm();
  }();
  return on;
}

void gemv(const char* t, const int* m, const int* n, const float* alpha, const float* a, const int* lda,
          const float* x, const int* incx, const float* beta, float* y, const int* incy) {
  sgemv_(t, m, n, alpha, a, lda, x, incx, beta, y, incy, 1);
}
void gemv(const char* t, const int* m, const int* n, const double* alpha, const double* a, const int* lda,
          const double* x, const int* incx, const double* beta, double* y, const int* incy) {
  dgemv_(t, m, n, alpha, a, lda, x, incx, beta, y, incy, 1);
}
void trsv(const char* uplo, const char* t, const char* diag, const int* n, const float* a, const int* lda, float* x,
          const int* incx) {
  strsv_(uplo, t, diag, n, a, lda, x, incx, 1, 1, 1);
}
void trsv(const char* uplo, const char* t, const char* diag, const int* n, const double* a, const int* lda,
          double* x, const int* incx) {
  dtrsv_(uplo, t, diag, n, a, lda, x, incx, 1, 1, 1);
}
void scal(const int* n, const float* alpha, float* x, const int* incx) { sscal_(n, alpha, x, incx); }
void scal(const int* n, const double* alpha, double* x, const int* incx) { dscal_(n, alpha, x, incx); }

template <class T>
struct Names;
template <>
struct Names<float> {
  static constexpr const char* gemm = "sgemm_";
  static constexpr const char* trsm = "strsm_";
};
template <>
struct Names<double> {
  static constexpr const char* gemm = "dgemm_";
  static constexpr const char* trsm = "dtrsm_";
};

// C = alpha op(A) op(B) + beta C. With one column (n = 1) this is
// y = alpha op(A) x + beta y, op(B)'s column x being B's column (stride 1)
// or, transposed, B's row (stride ldb). GEMV returns at once for an empty
// A without scaling y, so empty products stay with GEMM.
template <class T>
void gemm(const char* ta, const char* tb, const int* m, const int* n, const int* k, const T* alpha, const T* a,
          const int* lda, const T* b, const int* ldb, const T* beta, T* c, const int* ldc, std::size_t lta,
          std::size_t ltb) {
  if (*n == 1 && *m > 0 && *k > 0 && enabled()) {
    const int incb = transposed(tb) ? *ldb : 1, one = 1;
    const bool at = transposed(ta);
    const int rows = at ? *k : *m, cols = at ? *m : *k;
    gemv(at ? "T" : "N", &rows, &cols, alpha, a, lda, b, &incb, beta, c, &one);
    return;
  }
  static const auto blas = blasRoutine<Gemm<T>>(Names<T>::gemm);
  blas(ta, tb, m, n, k, alpha, a, lda, b, ldb, beta, c, ldc, lta, ltb);
}

// op(A) X = alpha B; from the left with one column: x = op(A)^-1 (alpha b).
template <class T>
void trsm(const char* side, const char* uplo, const char* ta, const char* diag, const int* m, const int* n,
          const T* alpha, const T* a, const int* lda, T* b, const int* ldb, std::size_t l1, std::size_t l2,
          std::size_t l3, std::size_t l4) {
  if ((*side == 'L' || *side == 'l') && *n == 1 && *m > 0 && enabled()) {
    const int one = 1;
    if (*alpha != T(1)) scal(m, alpha, b, &one);
    trsv(uplo, ta, diag, m, a, lda, b, &one);
    return;
  }
  static const auto blas = blasRoutine<Trsm<T>>(Names<T>::trsm);
  blas(side, uplo, ta, diag, m, n, alpha, a, lda, b, ldb, l1, l2, l3, l4);
}

}  // namespace

extern "C" {

void sgemm_(const char* ta, const char* tb, const int* m, const int* n, const int* k, const float* alpha,
            const float* a, const int* lda, const float* b, const int* ldb, const float* beta, float* c,
            const int* ldc, std::size_t lta, std::size_t ltb) {
  gemm(ta, tb, m, n, k, alpha, a, lda, b, ldb, beta, c, ldc, lta, ltb);
}

void dgemm_(const char* ta, const char* tb, const int* m, const int* n, const int* k, const double* alpha,
            const double* a, const int* lda, const double* b, const int* ldb, const double* beta, double* c,
            const int* ldc, std::size_t lta, std::size_t ltb) {
  gemm(ta, tb, m, n, k, alpha, a, lda, b, ldb, beta, c, ldc, lta, ltb);
}

void strsm_(const char* side, const char* uplo, const char* ta, const char* diag, const int* m, const int* n,
            const float* alpha, const float* a, const int* lda, float* b, const int* ldb, std::size_t l1,
            std::size_t l2, std::size_t l3, std::size_t l4) {
  trsm(side, uplo, ta, diag, m, n, alpha, a, lda, b, ldb, l1, l2, l3, l4);
}

void dtrsm_(const char* side, const char* uplo, const char* ta, const char* diag, const int* m, const int* n,
            const double* alpha, const double* a, const int* lda, double* b, const int* ldb, std::size_t l1,
            std::size_t l2, std::size_t l3, std::size_t l4) {
  trsm(side, uplo, ta, diag, m, n, alpha, a, lda, b, ldb, l1, l2, l3, l4);
}

}  // extern "C"
