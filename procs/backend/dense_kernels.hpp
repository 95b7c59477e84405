// The few dense kernels that take most of the window's time: the separator's Cholesky (the
// marginalization prior makes it dense), the Gram updates of the objects' Schur complements,
// and the marginalization's triangular solves. They are compiled for this machine's CPU
// (-march=native: AVX/FMA vector units the x86-64 baseline lacks) in a shared
// library of their own whose symbols are hidden but for these functions: Eigen's code inside,
// and every allocation it makes, never mix with the rest of the program's Eigen, which is
// built for any x86-64 like the Ceres, PCL and OpenCV it links (mixing them corrupts the heap).
// Column-major matrices with unit inner stride; only the lower triangles of L and S are used.
// The band kernels work on a symmetric matrix of 6x6 blocks that is zero beyond w blocks from
// the diagonal (an object's chain in time), kept as its lower band: block (i, i - d) at
// [i * (w + 1) + d], each 36 doubles column-major.
#pragma once

#include <Eigen/Core>
#include <vector>

#define DLSLOT_DENSE_API __attribute__((visibility("default")))

namespace dlslot::backend::dense {

namespace raw {
DLSLOT_DENSE_API bool cholesky(double* A, int n, int lda);
DLSLOT_DENSE_API void solveLower(const double* L, int n, int ldl, double* B, int m, int ldb);
DLSLOT_DENSE_API void solveLowerTransposed(const double* L, int n, int ldl, double* B, int m, int ldb);
DLSLOT_DENSE_API void subtractOuter(const double* X, int n, int k, int ldx, double* S, int lds);
DLSLOT_DENSE_API void subtractProductTN(const double* A, int k, int m, int lda, const double* B, int n, int ldb,
                                        double* C, int ldc);
DLSLOT_DENSE_API bool bandCholesky(const double* H, int m, int w, const double* damping, double* L, double* L_inv);
DLSLOT_DENSE_API void bandSolveLower(const double* L, const double* L_inv, int m, int w, double* B, int cols,
                                     const int* widths);
DLSLOT_DENSE_API void bandSolveLowerTransposed(const double* L, const double* L_inv, int m, int w, double* B,
                                               int cols);
}  // namespace raw

using MatrixRef = Eigen::Ref<Eigen::MatrixXd>;
using ConstMatrixRef = Eigen::Ref<const Eigen::MatrixXd>;
using RowMatrix = Eigen::Matrix<double, Eigen::Dynamic, Eigen::Dynamic, Eigen::RowMajor>;
using Matrix6 = Eigen::Matrix<double, 6, 6>;

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
// C <- C - A^T B.
inline void subtractProductTN(ConstMatrixRef A, ConstMatrixRef B, MatrixRef C) {
  raw::subtractProductTN(A.data(), static_cast<int>(A.rows()), static_cast<int>(A.cols()),
                         static_cast<int>(A.outerStride()), B.data(), static_cast<int>(B.cols()),
                         static_cast<int>(B.outerStride()), C.data(), static_cast<int>(C.outerStride()));
}
// S <- S - Y^T Y on S's lower triangle, for a row-major Y (whose storage is Y^T column-major).
inline void subtractGramRows(const RowMatrix& Y, MatrixRef S) {
  raw::subtractOuter(Y.data(), static_cast<int>(Y.cols()), static_cast<int>(Y.rows()), static_cast<int>(Y.cols()),
                     S.data(), static_cast<int>(S.outerStride()));
}

// The band's Cholesky factor: L (same layout as H) and the inverses of its diagonal blocks
// (substitution by products; 6x6 triangular solves are slow). `damping` (6m values) is added to
// H's diagonal first (Levenberg-Marquardt). False when the damped band is not positive definite.
inline bool bandCholesky(const std::vector<Matrix6>& H, int m, int w, const Eigen::VectorXd& damping,
                         std::vector<Matrix6>& L, std::vector<Matrix6>& L_inv) {
  L.resize(H.size());
  L_inv.resize(m);
  return raw::bandCholesky(H[0].data(), m, w, damping.data(), L[0].data(), L_inv[0].data());
}
// B <- L^-1 B for a row-major B of 6m rows. With `widths`, row block i of B is zero beyond
// widths[i] columns (non-decreasing in i: a staircase) and only those are touched.
inline void bandSolveLower(const std::vector<Matrix6>& L, const std::vector<Matrix6>& L_inv, int w, RowMatrix& B,
                           const std::vector<int>* widths = nullptr) {
  raw::bandSolveLower(L[0].data(), L_inv[0].data(), static_cast<int>(L_inv.size()), w, B.data(),
                      static_cast<int>(B.cols()), widths ? widths->data() : nullptr);
}
// B <- L^-T B for a row-major B of 6m rows.
inline void bandSolveLowerTransposed(const std::vector<Matrix6>& L, const std::vector<Matrix6>& L_inv, int w,
                                     RowMatrix& B) {
  raw::bandSolveLowerTransposed(L[0].data(), L_inv[0].data(), static_cast<int>(L_inv.size()), w, B.data(),
                                static_cast<int>(B.cols()));
}

}  // namespace dlslot::backend::dense
