// Compiled on its own, for this CPU, with hidden symbols (see dense_kernels.hpp).
#include "backend/dense_kernels.hpp"

#include <Eigen/Cholesky>
#include <algorithm>

namespace dlslot::backend::dense::raw {
namespace {

using Stride = Eigen::OuterStride<>;
using Map = Eigen::Map<Eigen::MatrixXd, 0, Stride>;
using ConstMap = Eigen::Map<const Eigen::MatrixXd, 0, Stride>;
using Block6 = Eigen::Map<Eigen::Matrix<double, 6, 6>>;
using ConstBlock6 = Eigen::Map<const Eigen::Matrix<double, 6, 6>>;
using Vector6Map = Eigen::Map<Eigen::Matrix<double, 6, 1>>;
using Rows6 = Eigen::Map<Eigen::Matrix<double, 6, Eigen::Dynamic, Eigen::RowMajor>, 0, Stride>;
using ConstRows6 = Eigen::Map<const Eigen::Matrix<double, 6, Eigen::Dynamic, Eigen::RowMajor>, 0, Stride>;

// B <- B - A X for a 6x6 A and 6 x n row-major B, X: row by row, each row a sum of scaled
// rows of X, which vectorizes along n (Eigen's general product costs more at these sizes).
void subtractProduct(const Eigen::Matrix<double, 6, 6>& A, const ConstRows6& X, Rows6& B) {
  for (int r = 0; r < 6; ++r)
    B.row(r) -= A(r, 0) * X.row(0) + A(r, 1) * X.row(1) + A(r, 2) * X.row(2) + A(r, 3) * X.row(3) +
                A(r, 4) * X.row(4) + A(r, 5) * X.row(5);
}

// B <- A B for a lower triangular 6x6 A, in place: row r needs rows c <= r only, so the rows
// are replaced from the last one up.
void multiplyLowerInPlace(const Eigen::Matrix<double, 6, 6>& A, Rows6& B) {
  for (int r = 5; r >= 0; --r) {
    B.row(r) *= A(r, r);
    for (int c = 0; c < r; ++c) B.row(r) += A(r, c) * B.row(c);
  }
}

// B <- A B for an upper triangular 6x6 A, in place (rows from the first one down).
void multiplyUpperInPlace(const Eigen::Matrix<double, 6, 6>& A, Rows6& B) {
  for (int r = 0; r < 6; ++r) {
    B.row(r) *= A(r, r);
    for (int c = r + 1; c < 6; ++c) B.row(r) += A(r, c) * B.row(c);
  }
}

}  // namespace

bool cholesky(double* A, int n, int lda) {
  Map M(A, n, n, Stride(lda));
  Eigen::LLT<Eigen::Ref<Eigen::MatrixXd, 0, Stride>> llt(M);  // in place
  return llt.info() == Eigen::Success;
}

void solveLower(const double* L, int n, int ldl, double* B, int m, int ldb) {
  const ConstMap Lm(L, n, n, Stride(ldl));
  Map Bm(B, n, m, Stride(ldb));
  Lm.triangularView<Eigen::Lower>().solveInPlace(Bm);
}

void solveLowerTransposed(const double* L, int n, int ldl, double* B, int m, int ldb) {
  const ConstMap Lm(L, n, n, Stride(ldl));
  Map Bm(B, n, m, Stride(ldb));
  Lm.triangularView<Eigen::Lower>().transpose().solveInPlace(Bm);
}

void subtractOuter(const double* X, int n, int k, int ldx, double* S, int lds) {
  // Nothing to subtract (and an empty X may have no storage: Eigen's kernel would bind a
  // reference to its null data, UBSan in ./dlslot test --sanitize).
  if (n == 0 || k == 0) return;
  Map(S, n, n, Stride(lds)).selfadjointView<Eigen::Lower>().rankUpdate(ConstMap(X, n, k, Stride(ldx)), -1.0);
}

void subtractProductTN(const double* A, int k, int m, int lda, const double* B, int n, int ldb, double* C, int ldc) {
  if (k == 0 || m == 0 || n == 0) return;  // as subtractOuter
  Map(C, m, n, Stride(ldc)).noalias() -= ConstMap(A, k, m, Stride(lda)).transpose() * ConstMap(B, k, n, Stride(ldb));
}

// Row by row of blocks: L(i,j) = (H(i,j) - sum_k L(i,k) L(j,k)^T) L(j,j)^-T for j < i, and
// L(i,i) the Cholesky factor of what remains on the diagonal; only blocks within the band.
bool bandCholesky(const double* H, int m, int w, const double* damping, double* L, double* L_inv) {
  auto at = [&](int i, int d) { return Block6(L + 36 * (i * (w + 1) + d)); };
  for (int i = 0; i < m; ++i) {
    for (int d = std::min(i, w); d >= 0; --d) {
      const int j = i - d;
      Eigen::Matrix<double, 6, 6> S = ConstBlock6(H + 36 * (i * (w + 1) + d));
      for (int k = std::max(0, i - w); k < j; ++k) S.noalias() -= at(i, i - k) * at(j, j - k).transpose();
      if (d > 0) {
        at(i, d).noalias() = S * ConstBlock6(L_inv + 36 * j).transpose();
        continue;
      }
      for (int r = 0; r < 6; ++r) S(r, r) += damping[6 * i + r];
      Eigen::LLT<Eigen::Matrix<double, 6, 6>> llt(S);
      if (llt.info() != Eigen::Success) return false;
      at(i, 0) = llt.matrixL();
      Block6(L_inv + 36 * i) = llt.matrixL().solve(Eigen::Matrix<double, 6, 6>::Identity());
    }
  }
  return true;
}

void bandSolveLower(const double* L, const double* L_inv, int m, int w, double* B, int cols, const int* widths) {
  if (cols == 1) {  // a vector (the gradient): fixed-size products
    for (int i = 0; i < m; ++i) {
      Vector6Map b(B + 6 * i);
      for (int k = std::max(0, i - w); k < i; ++k) b.noalias() -= ConstBlock6(L + 36 * (i * (w + 1) + i - k)) * Vector6Map(B + 6 * k);
      b = (ConstBlock6(L_inv + 36 * i) * b).eval();
    }
    return;
  }
  for (int i = 0; i < m; ++i) {
    const int n = widths ? widths[i] : cols;
    Rows6 Bi(B + 6 * i * cols, 6, n, Stride(cols));
    for (int k = std::max(0, i - w); k < i; ++k)
      subtractProduct(ConstBlock6(L + 36 * (i * (w + 1) + i - k)), ConstRows6(B + 6 * k * cols, 6, n, Stride(cols)), Bi);
    multiplyLowerInPlace(ConstBlock6(L_inv + 36 * i), Bi);
  }
}

void bandSolveLowerTransposed(const double* L, const double* L_inv, int m, int w, double* B, int cols) {
  if (cols == 1) {
    for (int i = m - 1; i >= 0; --i) {
      Vector6Map b(B + 6 * i);
      for (int k = i + 1; k <= std::min(m - 1, i + w); ++k)
        b.noalias() -= ConstBlock6(L + 36 * (k * (w + 1) + k - i)).transpose() * Vector6Map(B + 6 * k);
      b = (ConstBlock6(L_inv + 36 * i).transpose() * b).eval();
    }
    return;
  }
  for (int i = m - 1; i >= 0; --i) {
    Rows6 Bi(B + 6 * i * cols, 6, cols, Stride(cols));
    for (int k = i + 1; k <= std::min(m - 1, i + w); ++k)
      subtractProduct(ConstBlock6(L + 36 * (k * (w + 1) + k - i)).transpose(), ConstRows6(B + 6 * k * cols, 6, cols, Stride(cols)), Bi);
    multiplyUpperInPlace(ConstBlock6(L_inv + 36 * i).transpose(), Bi);
  }
}

}  // namespace dlslot::backend::dense::raw
