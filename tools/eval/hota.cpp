#include "hota.hpp"

#include <cmath>
#include <map>

#include "dlslot/hungarian.hpp"

namespace dlslot::eval {
namespace {

constexpr double kEps = 1e-12;

// Dense indices for label and track ids.
struct IdIndex {
  std::map<int, int> index;
  int of(int id) { return index.emplace(id, static_cast<int>(index.size())).first->second; }
  int size() const { return static_cast<int>(index.size()); }
};

Eigen::MatrixXd similarities(const TrackingFrame& f, const MatchCriterion& c) {
  Eigen::MatrixXd s(f.truth.size(), f.tracks.size());
  for (size_t i = 0; i < f.truth.size(); ++i)
    for (size_t j = 0; j < f.tracks.size(); ++j) s(i, j) = c.similarity(f.truth[i].box, f.tracks[j].box);
  return s;
}

}  // namespace

std::optional<Hota> evaluateHota(const std::vector<TrackingFrame>& frames, const MatchCriterion& criterion) {
  IdIndex gt_ids, tr_ids;
  std::vector<std::vector<int>> gt_idx(frames.size()), tr_idx(frames.size());
  std::vector<Eigen::MatrixXd> sim(frames.size());
  for (size_t t = 0; t < frames.size(); ++t) {
    for (const Object& o : frames[t].truth) gt_idx[t].push_back(gt_ids.of(o.box.id));
    for (const Object& o : frames[t].tracks) tr_idx[t].push_back(tr_ids.of(o.box.id));
    sim[t] = similarities(frames[t], criterion);
  }
  const int G = gt_ids.size(), T = tr_ids.size();
  if (G == 0 && T == 0) return std::nullopt;

  // Global alignment score: how much each (label, track) pair could be matched over the whole
  // sequence, from similarities normalised per frame like an IoU.
  Eigen::MatrixXd potential = Eigen::MatrixXd::Zero(G, T);
  Eigen::VectorXd gt_count = Eigen::VectorXd::Zero(G), tr_count = Eigen::VectorXd::Zero(T);
  for (size_t t = 0; t < frames.size(); ++t) {
    const Eigen::MatrixXd& s = sim[t];
    const Eigen::VectorXd row_sum = s.rowwise().sum();
    const Eigen::RowVectorXd col_sum = s.colwise().sum();
    for (int i = 0; i < s.rows(); ++i)
      for (int j = 0; j < s.cols(); ++j) {
        const double denom = row_sum(i) + col_sum(j) - s(i, j);
        if (denom > kEps) potential(gt_idx[t][i], tr_idx[t][j]) += s(i, j) / denom;
      }
    for (int g : gt_idx[t]) gt_count(g) += 1;
    for (int h : tr_idx[t]) tr_count(h) += 1;
  }
  Eigen::MatrixXd alignment(G, T);
  for (int g = 0; g < G; ++g)
    for (int h = 0; h < T; ++h) alignment(g, h) = potential(g, h) / (gt_count(g) + tr_count(h) - potential(g, h));

  Hota out;
  for (int k = 1; k <= 19; ++k) out.alphas.push_back(0.05 * k);
  const size_t A = out.alphas.size();
  std::vector<double> tp(A, 0), fn(A, 0), fp(A, 0), loc(A, 0);
  std::vector<std::map<std::pair<int, int>, double>> matches(A);  // per alpha: (label, track) -> matched frames
  for (size_t t = 0; t < frames.size(); ++t) {
    const Eigen::MatrixXd& s = sim[t];
    const int ng = static_cast<int>(s.rows()), nh = static_cast<int>(s.cols());
    std::vector<int> col(ng, -1);
    if (ng > 0 && nh > 0) {
      Eigen::MatrixXd score(ng, nh);
      for (int i = 0; i < ng; ++i)
        for (int j = 0; j < nh; ++j) score(i, j) = alignment(gt_idx[t][i], tr_idx[t][j]) * s(i, j);
      col = solveAssignment(-score);
    }
    for (size_t a = 0; a < A; ++a) {
      int n = 0;
      for (int i = 0; i < ng; ++i) {
        if (col[i] < 0 || s(i, col[i]) < out.alphas[a] - kEps) continue;
        ++n;
        loc[a] += s(i, col[i]);
        matches[a][{gt_idx[t][i], tr_idx[t][col[i]]}] += 1;
      }
      tp[a] += n;
      fn[a] += ng - n;
      fp[a] += nh - n;
    }
  }

  for (size_t a = 0; a < A; ++a) {
    double assa = 0;  // each of the m TPs of a pair has that pair's association IoU
    for (const auto& [pair, m] : matches[a]) assa += m * m / (gt_count(pair.first) + tr_count(pair.second) - m);
    assa /= std::max(1.0, tp[a]);
    const double deta = tp[a] / std::max(1.0, tp[a] + fn[a] + fp[a]);
    const double h = std::sqrt(deta * assa);
    out.hota_by_alpha.push_back(h);
    out.hota += h / A;
    out.deta += deta / A;
    out.assa += assa / A;
    out.loca += (tp[a] > 0 ? loc[a] / tp[a] : 0.0) / A;
  }
  return out;
}

}  // namespace dlslot::eval
