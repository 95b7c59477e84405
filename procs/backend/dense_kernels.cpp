// Compiled on its own, for this CPU, with hidden symbols (see dense_kernels.hpp).
#include "backend/dense_kernels.hpp"

#include <Eigen/Cholesky>

namespace dlslot::backend::dense::raw {
namespace {

using Stride = Eigen::OuterStride<>;
using Map = Eigen::Map<Eigen::MatrixXd, 0, Stride>;
using ConstMap = Eigen::Map<const Eigen::MatrixXd, 0, Stride>;

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

void subtractGram(const double* Y, int k, int n, int ldy, double* S, int lds) {
  Map(S, n, n, Stride(lds)).selfadjointView<Eigen::Lower>().rankUpdate(ConstMap(Y, k, n, Stride(ldy)).transpose(), -1.0);
}

void subtractOuter(const double* X, int n, int k, int ldx, double* S, int lds) {
  Map(S, n, n, Stride(lds)).selfadjointView<Eigen::Lower>().rankUpdate(ConstMap(X, n, k, Stride(ldx)), -1.0);
}

}  // namespace dlslot::backend::dense::raw
