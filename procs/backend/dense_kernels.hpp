// The few dense kernels that take most of the window's time: the separator's Cholesky (the
// marginalization prior makes it dense), the Gram updates of the objects' Schur complements,
// and the marginalization's triangular solves. They are compiled for this machine's CPU
// (-march=native: AVX/FMA vector units the x86-64 baseline lacks) in a shared
// library of their own whose symbols are hidden but for these functions: Eigen's code inside,
// and every allocation it makes, never mix with the rest of the program's Eigen, which is
// built for any x86-64 like the Ceres, PCL and OpenCV it links (mixing them corrupts the heap).
// Column-major matrices with unit inner stride; only the lower triangles of L and S are used.
#pragma once

#include <Eigen/Core>

#define DLSLOT_DENSE_API __attribute__((visibility("default")))

namespace dlslot::backend::dense {

namespace raw {
DLSLOT_DENSE_API bool cholesky(double* A, int n, int lda);
DLSLOT_DENSE_API void solveLower(const double* L, int n, int ldl, double* B, int m, int ldb);
DLSLOT_DENSE_API void solveLowerTransposed(const double* L, int n, int ldl, double* B, int m, int ldb);
DLSLOT_DENSE_API void subtractGram(const double* Y, int k, int n, int ldy, double* S, int lds);
DLSLOT_DENSE_API void subtractOuter(const double* X, int n, int k, int ldx, double* S, int lds);
}  // namespace raw

using MatrixRef = Eigen::Ref<Eigen::MatrixXd>;
using ConstMatrixRef = Eigen::Ref<const Eigen::MatrixXd>;
using RowMatrix = Eigen::Matrix<double, Eigen::Dynamic, Eigen::Dynamic, Eigen::RowMajor>;

// A = L L^T in place, L in the lower triangle (the upper one is left alone); false when A is
// not positive definite.
inline bool cholesky(MatrixRef A) {
  return raw::cholesky(A.data(), static_cast<int>(A.rows()), static_cast<int>(A.outerStride()));
}
// B <- L^-1 B.
inline void solveLower(ConstMatrixRef L, MatrixRef B) {
  raw::solveLower(L.data(), static_cast<int>(L.rows()), static_cast<int>(L.outerStride()), B.data(),
                  static_cast<int>(B.cols()), static_cast<int>(B.outerStride()));
}
// B <- L^-T B.
inline void solveLowerTransposed(ConstMatrixRef L, MatrixRef B) {
  raw::solveLowerTransposed(L.data(), static_cast<int>(L.rows()), static_cast<int>(L.outerStride()), B.data(),
                            static_cast<int>(B.cols()), static_cast<int>(B.outerStride()));
}
// S <- S - Y^T Y on S's lower triangle.
inline void subtractGram(ConstMatrixRef Y, MatrixRef S) {
  raw::subtractGram(Y.data(), static_cast<int>(Y.rows()), static_cast<int>(Y.cols()), static_cast<int>(Y.outerStride()),
                    S.data(), static_cast<int>(S.outerStride()));
}
// subtractGram for a row-major Y (whose storage is Y^T column-major).
inline void subtractGramRows(const RowMatrix& Y, MatrixRef S) {
  raw::subtractOuter(Y.data(), static_cast<int>(Y.cols()), static_cast<int>(Y.rows()), static_cast<int>(Y.cols()),
                     S.data(), static_cast<int>(S.outerStride()));
}

}  // namespace dlslot::backend::dense
