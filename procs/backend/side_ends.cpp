#include "backend/side_ends.hpp"

#include <algorithm>
#include <cmath>
#include <limits>

namespace dlslot::backend {

std::optional<SideEnds> sideEnds(const ObjectPoints& points, const Eigen::Vector3d& d) {
  if (points.size() < 2) return std::nullopt;
  SideEnds e{std::numeric_limits<double>::infinity(), -std::numeric_limits<double>::infinity()};
  for (const Eigen::Vector3f& p : points) {
    const double s = d.dot(p.cast<double>());
    e.low = std::min(e.low, s);
    e.high = std::max(e.high, s);
  }
  return e;
}

double sideEndSigma(double range, double sin_angle, double azimuth_step_rad, double floor_m) {
  // A uniform error over a width w has standard deviation w / sqrt(12).
  const double spacing = range * azimuth_step_rad / std::max(std::abs(sin_angle), 1e-3);
  return std::hypot(spacing / std::sqrt(12.0), floor_m);
}

std::optional<PairSpeed> sidePairSpeed(const SideView& previous, const SideView& current, const Eigen::Vector2d& d,
                                       double vehicle_length, double length_tolerance, double dt) {
  if (!(dt > 0)) return std::nullopt;
  const double l0 = previous.ends.length(), l1 = current.ends.length();
  if (std::abs(l0 - vehicle_length) > length_tolerance || std::abs(l1 - vehicle_length) > length_tolerance)
    return std::nullopt;
  const double v0 = previous.end_sigma * previous.end_sigma, v1 = current.end_sigma * current.end_sigma;
  // A length is the difference of two ends; the change of length that of two lengths.
  if (std::abs(l1 - l0) > 3.0 * std::sqrt(2.0 * v0 + 2.0 * v1)) return std::nullopt;
  PairSpeed p;
  p.u = d;
  p.speed = (current.ends.middle() - previous.ends.middle()) / dt;
  p.sigma = std::sqrt(v0 + v1) / dt;
  if (!std::isfinite(p.speed) || !(p.sigma > 0) || !std::isfinite(p.sigma)) return std::nullopt;
  return p;
}

namespace {

// Weighted least squares of the middles on time (a middle's variance s^2 / 2), with the intercept
// at the weighted mean time; nothing without two distinct times.
struct MiddlesFit {
  SideLine line;
  double intercept = 0, intercept_variance = 0;
};
std::optional<MiddlesFit> fitMiddles(const std::vector<const SideScan*>& scans) {
  const auto weight = [](const SideScan* s) { return 2.0 / (s->view.end_sigma * s->view.end_sigma); };
  double sw = 0, st = 0, sy = 0;
  for (const SideScan* s : scans) {
    sw += weight(s);
    st += weight(s) * s->time;
    sy += weight(s) * s->view.ends.middle();
  }
  if (scans.size() < 2 || !(sw > 0)) return std::nullopt;
  const double t_mean = st / sw;
  double stt = 0, sty = 0;
  for (const SideScan* s : scans) {
    const double dt = s->time - t_mean;
    stt += weight(s) * dt * dt;
    sty += weight(s) * dt * s->view.ends.middle();
  }
  if (!(stt > 1e-12)) return std::nullopt;
  MiddlesFit fit;
  fit.line.speed = sty / stt;
  fit.line.sigma = 1.0 / std::sqrt(stt);
  fit.line.time = t_mean;
  fit.line.scans = static_cast<int>(scans.size());
  fit.intercept = sy / sw;
  fit.intercept_variance = 1.0 / sw;
  return fit;
}

}  // namespace

std::optional<SideLine> sideLine(const std::vector<SideScan>& scans, double vehicle_length, double length_tolerance) {
  std::vector<double> lengths;
  for (const SideScan& s : scans)
    if (std::abs(s.view.ends.length() - vehicle_length) <= length_tolerance) lengths.push_back(s.view.ends.length());
  if (lengths.size() < 2) return std::nullopt;
  std::nth_element(lengths.begin(), lengths.begin() + lengths.size() / 2, lengths.end());
  const double median_length = lengths[lengths.size() / 2];
  std::vector<const SideScan*> kept;
  for (const SideScan& s : scans) {
    const double l = s.view.ends.length();
    // A length is the difference of two ends (variance 2 s^2), two lengths' difference 4 s^2.
    if (s.view.end_sigma > 0 && std::abs(l - vehicle_length) <= length_tolerance &&
        std::abs(l - median_length) <= 3.0 * 2.0 * s.view.end_sigma)
      kept.push_back(&s);
  }
  // Each middle against the line through the others (a stray middle at either end of the run
  // pulls the line through all of them toward itself), in the standard deviations of the
  // difference: the one furthest off beyond three is left out.
  if (kept.size() >= 4) {
    auto worst = kept.end();
    double worst_z = 3.0;
    for (auto it = kept.begin(); it != kept.end(); ++it) {
      std::vector<const SideScan*> others(kept.begin(), kept.end());
      others.erase(others.begin() + (it - kept.begin()));
      const std::optional<MiddlesFit> fit = fitMiddles(others);
      if (!fit) continue;
      const double dt = (*it)->time - fit->line.time;
      const double predicted = fit->intercept + fit->line.speed * dt;
      const double variance = 0.5 * (*it)->view.end_sigma * (*it)->view.end_sigma + fit->intercept_variance +
                              fit->line.sigma * fit->line.sigma * dt * dt;
      const double z = std::abs((*it)->view.ends.middle() - predicted) / std::sqrt(variance);
      if (z > worst_z) {
        worst_z = z;
        worst = it;
      }
    }
    if (worst != kept.end()) kept.erase(worst);
  }
  const std::optional<MiddlesFit> fit = fitMiddles(kept);
  if (!fit) return std::nullopt;
  return fit->line;
}

}  // namespace dlslot::backend
