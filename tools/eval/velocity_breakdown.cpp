#include "velocity_breakdown.hpp"

#include <algorithm>
#include <cctype>
#include <cmath>
#include <cstdio>
#include <functional>
#include <map>

#include <Eigen/Cholesky>

namespace dlslot::eval {
namespace {

std::string ageBin(int age) {
  if (age < 5) return "0-4";
  if (age < 10) return "5-9";
  if (age < 20) return "10-19";
  return "20+";
}

std::string rangeBin(double range_m) {
  if (range_m < 20) return "0-20";
  if (range_m < 40) return "20-40";
  if (range_m < 60) return "40-60";
  return "60+";
}

std::string lower(std::string s) {
  for (char& c : s) c = static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
  return s;
}

VelocityGroup summarize(std::string dimension, std::string bin, std::vector<double> errors) {
  VelocityGroup g{std::move(dimension), std::move(bin), static_cast<int>(errors.size()), {}, {}, {}};
  if (errors.empty()) return g;
  double sq = 0, sum = 0;
  for (double e : errors) {
    sq += e * e;
    sum += e;
  }
  g.rmse_mps = std::sqrt(sq / errors.size());
  g.mean_mps = sum / errors.size();
  std::sort(errors.begin(), errors.end());
  g.p90_mps = errors[std::min(errors.size() - 1, static_cast<size_t>(0.9 * errors.size()))];
  return g;
}

}  // namespace

std::vector<VelocityGroup> breakdownVelocityErrors(const std::vector<VelocityPair>& pairs, int num_frames) {
  const int stretch = std::max(1, (num_frames + 9) / 10);
  const auto frameBin = [&](int index) {
    char buf[32];
    const int first = index / stretch * stretch;
    std::snprintf(buf, sizeof buf, "%03d-%03d", first, std::min(num_frames, first + stretch) - 1);
    return std::string(buf);
  };
  // Ordered bins per dimension; std::map keeps classes and frame stretches sorted.
  std::map<std::string, std::vector<double>> age, cls, motion, range, frames;
  for (const VelocityPair& p : pairs) {
    motion[p.dynamic ? "dynamic" : "static"].push_back(p.error());
    if (!p.dynamic) continue;
    age[ageBin(p.track_age)].push_back(p.error());
    cls[lower(p.type)].push_back(p.error());
    range[rangeBin(p.range_m)].push_back(p.error());
    frames[frameBin(p.frame_index)].push_back(p.error());
  }
  std::vector<VelocityGroup> out;
  for (const char* bin : {"0-4", "5-9", "10-19", "20+"})
    if (age.count(bin)) out.push_back(summarize("age", bin, age[bin]));
  for (auto& [bin, e] : cls) out.push_back(summarize("class", bin, std::move(e)));
  for (const char* bin : {"dynamic", "static"})
    if (motion.count(bin)) out.push_back(summarize("motion", bin, motion[bin]));
  for (const char* bin : {"0-20", "20-40", "40-60", "60+"})
    if (range.count(bin)) out.push_back(summarize("range", bin, range[bin]));
  for (auto& [bin, e] : frames) out.push_back(summarize("frames", bin, std::move(e)));
  return out;
}

std::optional<double> VelocityPair::nees() const {
  if (!track_covariance) return std::nullopt;
  const Eigen::LLT<Eigen::Matrix2d> llt(*track_covariance);
  if (llt.info() != Eigen::Success) return std::nullopt;
  const Eigen::Vector2d e = truth - track;
  return e.dot(llt.solve(e));
}

VelocityCalibration velocityCalibration(const std::vector<VelocityPair>& pairs, int min_age, int max_age) {
  constexpr double kChiSquare2Dof95 = 5.991;
  VelocityCalibration c;
  double sum = 0;
  int within = 0;
  for (const VelocityPair& p : pairs) {
    if (!p.dynamic || p.track_age < min_age || p.track_age > max_age) continue;
    const std::optional<double> nees = p.nees();
    if (!nees) continue;
    ++c.pairs;
    sum += *nees;
    within += *nees <= kChiSquare2Dof95;
  }
  if (c.pairs == 0) return c;
  c.nees_mean = sum / c.pairs;
  c.within_95 = static_cast<double>(within) / c.pairs;
  return c;
}

namespace {

// Dynamic pairs binned by bin_of (none: the pair counts nowhere); bin k holds [k, k + 1) x width.
std::vector<VelocityBin> velocityErrorBins(const std::vector<VelocityPair>& pairs, double width, int min_pairs,
                                           const std::function<std::optional<int>(const VelocityPair&)>& bin_of) {
  struct Sums {
    int pairs = 0, with_covariance = 0;
    double error_sq = 0, trace = 0;
  };
  std::map<int, Sums> bins;
  for (const VelocityPair& p : pairs) {
    const std::optional<int> bin = p.dynamic ? bin_of(p) : std::nullopt;
    if (!bin) continue;
    Sums& s = bins[*bin];
    ++s.pairs;
    s.error_sq += p.error() * p.error();
    if (p.track_covariance) {
      ++s.with_covariance;
      s.trace += p.track_covariance->trace();
    }
  }
  std::vector<VelocityBin> out;
  for (const auto& [index, s] : bins) {
    if (s.pairs < min_pairs) continue;
    VelocityBin b{index * width, (index + 1) * width, s.pairs, std::sqrt(s.error_sq / s.pairs), std::nullopt};
    if (s.with_covariance > 0) b.own_rms_mps = std::sqrt(s.trace / s.with_covariance);
    out.push_back(b);
  }
  return out;
}

}  // namespace

std::vector<VelocityBin> velocityErrorByRange(const std::vector<VelocityPair>& pairs, double bin_m, int min_age,
                                              int max_age, int min_pairs) {
  return velocityErrorBins(pairs, bin_m, min_pairs, [&](const VelocityPair& p) -> std::optional<int> {
    if (p.track_age < min_age || p.track_age > max_age) return std::nullopt;
    return static_cast<int>(std::floor(p.range_m / bin_m));
  });
}

std::vector<VelocityBin> velocityErrorByAge(const std::vector<VelocityPair>& pairs, int last_age, int min_pairs) {
  return velocityErrorBins(pairs, 1.0, min_pairs, [&](const VelocityPair& p) -> std::optional<int> {
    return std::min(p.track_age, last_age);
  });
}

}  // namespace dlslot::eval
