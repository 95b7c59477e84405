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

double sideSine(const Box& box) {
  const Eigen::Vector2d c = box.center.head<2>();
  if (c.norm() < 1e-6) return 0.0;
  return std::abs(std::cos(box.yaw) * c.y() - std::sin(box.yaw) * c.x()) / c.norm();
}

double columnSpacing(double range, double sin_angle, double azimuth_step_rad) {
  return range * azimuth_step_rad / std::max(std::abs(sin_angle), 1e-3);
}

double sideEndSigma(double range, double sin_angle, double azimuth_step_rad, double floor_m) {
  // A uniform error over a width w has standard deviation w / sqrt(12).
  return std::hypot(columnSpacing(range, sin_angle, azimuth_step_rad) / std::sqrt(12.0), floor_m);
}

namespace {

// Where points lie as the sensor sees them: their farthest horizontal range and the lowest and
// highest slope z / range (an elevation's tangent: a ring keeps its slope). Widened by `points`.
struct SightBand {
  double far = 0;
  double lowest = std::numeric_limits<double>::infinity(), highest = -std::numeric_limits<double>::infinity();
  // Every point (an index with no objects to serve keeps them all).
  static SightBand everything() {
    const double inf = std::numeric_limits<double>::infinity();
    return SightBand{inf, -inf, inf};
  }
  void widen(const ObjectPoints& points) {
    for (const Eigen::Vector3f& p : points) {
      const double r = std::hypot(p.x(), p.y());
      if (r < 1e-6) continue;
      far = std::max(far, r);
      lowest = std::min(lowest, p.z() / r);
      highest = std::max(highest, p.z() / r);
    }
  }
  // The points of another object on one of these rings have its very slope: held to within the
  // coordinates' rounding (1e-4, 0.006 deg; the rings are 0.4 deg apart), not left to it.
  bool holdsSlope(double z, double r) const { return z >= (lowest - 1e-4) * r && z <= (highest + 1e-4) * r; }
};

}  // namespace

AzimuthIndex::AzimuthIndex(const PointCloud& scan, double step_rad, const std::vector<const ObjectPoints*>& objects)
    : scan_(&scan), step_(step_rad) {
  SightBand band = objects.empty() ? SightBand::everything() : SightBand{};
  for (const ObjectPoints* points : objects) band.widen(*points);
  const int bins = static_cast<int>(std::ceil(2.0 * M_PI / step_));
  std::vector<int> bin(scan.cols(), -1);
  start_.assign(bins + 1, 0);
  const double far2 = band.far * band.far;
  for (Eigen::Index i = 0; i < scan.cols(); ++i) {
    const double x = scan(0, i), y = scan(1, i), z = scan(2, i), r2 = x * x + y * y;
    if (r2 >= far2 || !band.holdsSlope(z, std::sqrt(r2))) continue;
    bin[i] = std::min(static_cast<int>((std::atan2(y, x) + M_PI) / step_), bins - 1);
    ++start_[bin[i] + 1];
  }
  for (int b = 0; b < bins; ++b) start_[b + 1] += start_[b];
  order_.resize(start_.back());
  std::vector<int> next(start_.begin(), start_.end() - 1);
  for (Eigen::Index i = 0; i < scan.cols(); ++i)
    if (bin[i] >= 0) order_[next[bin[i]]++] = static_cast<int>(i);
}

std::vector<int> AzimuthIndex::near(double from, double to) const {
  const int bins = static_cast<int>(start_.size()) - 1;
  const int first = static_cast<int>(std::floor((from + M_PI) / step_));
  const int count = std::min(bins, static_cast<int>(std::floor((to + M_PI) / step_)) - first + 1);
  std::vector<int> out;
  for (int k = 0; k < count; ++k) {
    const int b = ((first + k) % bins + bins) % bins;
    out.insert(out.end(), order_.begin() + start_[b], order_.begin() + start_[b + 1]);
  }
  return out;
}

EndsSeen endsSeen(const AzimuthIndex& index, const ObjectPoints& points, const Box& crop) {
  const Eigen::Vector3d d(std::cos(crop.yaw), std::sin(crop.yaw), 0.0);
  const std::optional<SideEnds> ends = sideEnds(points, d);
  const double range = crop.center.head<2>().norm();
  if (!ends || range < 1e-3) return EndsSeen{false, false};
  const double spacing = columnSpacing(range, sideSine(crop), index.step());
  const double centre = d.dot(crop.center);
  // An occluder hides the object on the rings that hit it: at the elevations of its points.
  SightBand band;
  band.widen(points);
  const BoxContainment own(crop, 0.0);
  const PointCloud& scan = index.scan();
  const auto hidden = [&](double end, double crop_end) {
    if (std::abs(crop_end - end) < spacing) return true;
    // The azimuths (about the first such point's, so none wraps) and nearest range of the end's points.
    std::optional<double> reference;
    double lo = 0, hi = 0, nearest = std::numeric_limits<double>::infinity();
    for (const Eigen::Vector3f& p : points) {
      if (std::abs(d.dot(p.cast<double>()) - end) > spacing) continue;
      const double a = std::atan2(p.y(), p.x());
      if (!reference) reference = a;
      const double r = std::remainder(a - *reference, 2.0 * M_PI);
      lo = std::min(lo, r);
      hi = std::max(hi, r);
      nearest = std::min(nearest, std::hypot(static_cast<double>(p.x()), static_cast<double>(p.y())));
    }
    if (!reference) return true;
    const double margin = 2.0 * index.step();
    for (int i : index.near(*reference + lo - margin, *reference + hi + margin)) {
      const double x = scan(0, i), y = scan(1, i), z = scan(2, i), r = std::hypot(x, y);
      if (!band.holdsSlope(z, r) || own.contains(x, y, z)) continue;
      if (r < nearest) return true;
    }
    return false;
  };
  return EndsSeen{!hidden(ends->low, centre - 0.5 * crop.size.x()), !hidden(ends->high, centre + 0.5 * crop.size.x())};
}

EndsSeen endsThatCount(const SideEnds& ends, EndsSeen seen, int points, double vehicle_length, double length_tolerance,
                       double box_middle, double box_sigma, int min_points) {
  if (ends.length() >= vehicle_length - length_tolerance) return EndsSeen{};
  if (seen.both() || points < min_points) return EndsSeen{false, false};
  const double limit = 3.0 * box_sigma;
  seen.low = seen.low && std::abs(ends.low - (box_middle - 0.5 * vehicle_length)) <= limit;
  seen.high = seen.high && std::abs(ends.high - (box_middle + 0.5 * vehicle_length)) <= limit;
  return seen;
}

std::optional<PairSpeed> sidePairSpeed(const SideView& previous, const SideView& current, const Eigen::Vector2d& d,
                                       double vehicle_length, double length_tolerance, double dt) {
  if (!(dt > 0)) return std::nullopt;
  const double l0 = previous.ends.length(), l1 = current.ends.length();
  const double v0 = previous.end_sigma * previous.end_sigma, v1 = current.end_sigma * current.end_sigma;
  PairSpeed p;
  p.u = d;
  if (previous.seen.both() && current.seen.both()) {
    if (std::abs(l0 - vehicle_length) > length_tolerance || std::abs(l1 - vehicle_length) > length_tolerance)
      return std::nullopt;
    // A length is the difference of two ends; the change of length that of two lengths.
    if (std::abs(l1 - l0) > 3.0 * std::sqrt(2.0 * v0 + 2.0 * v1)) return std::nullopt;
    p.speed = (current.ends.middle() - previous.ends.middle()) / dt;
    p.sigma = std::sqrt(v0 + v1) / dt;
  } else {
    if (previous.seen.low && current.seen.low)
      p.speed = (current.ends.low - previous.ends.low) / dt;
    else if (previous.seen.high && current.seen.high)
      p.speed = (current.ends.high - previous.ends.high) / dt;
    else
      return std::nullopt;
    p.sigma = std::sqrt(2.0 * (v0 + v1)) / dt;
  }
  if (!std::isfinite(p.speed) || !(p.sigma > 0) || !std::isfinite(p.sigma)) return std::nullopt;
  return p;
}

namespace {

// One end of one scan: its position along d, its time and variance.
struct EndSample {
  double time = 0, position = 0, variance = 0;
};

// Weighted least squares of the ends on time, each end (low, high) with its own intercept at its
// weighted mean time, and the weight behind each intercept. Nothing without two distinct times on
// a common end.
struct EndsFit {
  SideLine line;
  double mean_time[2] = {0, 0}, mean_position[2] = {0, 0}, weight[2] = {0, 0};
  // An end's position at `time` as the fit gives it.
  double at(int end, double time) const { return mean_position[end] + line.speed * (time - mean_time[end]); }
};
using ScanEnds = std::vector<std::pair<int, EndSample>>;  // (end: 0 low, 1 high, sample)

std::optional<EndsFit> fitEnds(const std::vector<const ScanEnds*>& scans) {
  EndsFit fit;
  double sw = 0, swt = 0;
  for (const ScanEnds* s : scans)
    for (const auto& [end, e] : *s) {
      const double w = 1.0 / e.variance;
      fit.weight[end] += w;
      fit.mean_time[end] += w * e.time;
      fit.mean_position[end] += w * e.position;
      sw += w;
      swt += w * e.time;
    }
  for (int end = 0; end < 2; ++end)
    if (fit.weight[end] > 0) {
      fit.mean_time[end] /= fit.weight[end];
      fit.mean_position[end] /= fit.weight[end];
    }
  double stt = 0, sty = 0;
  for (const ScanEnds* s : scans)
    for (const auto& [end, e] : *s) {
      const double dt = e.time - fit.mean_time[end];
      stt += dt * dt / e.variance;
      sty += dt * (e.position - fit.mean_position[end]) / e.variance;
    }
  if (!(stt > 1e-12) || !(sw > 0)) return std::nullopt;
  fit.line.speed = sty / stt;
  fit.line.sigma = 1.0 / std::sqrt(stt);
  fit.line.time = swt / sw;
  fit.line.scans = static_cast<int>(scans.size());
  return fit;
}

}  // namespace

std::optional<SideLine> sideLine(const std::vector<SideScan>& scans, double vehicle_length, double length_tolerance) {
  std::vector<double> lengths;
  for (const SideScan& s : scans)
    if (s.view.seen.both() && std::abs(s.view.ends.length() - vehicle_length) <= length_tolerance)
      lengths.push_back(s.view.ends.length());
  double median_length = vehicle_length;
  if (!lengths.empty()) {
    std::nth_element(lengths.begin(), lengths.begin() + lengths.size() / 2, lengths.end());
    median_length = lengths[lengths.size() / 2];
  }
  std::vector<ScanEnds> samples;
  for (const SideScan& s : scans) {
    const double l = s.view.ends.length(), variance = s.view.end_sigma * s.view.end_sigma;
    if (!(s.view.end_sigma > 0) || !std::isfinite(variance)) continue;
    ScanEnds ends;
    if (s.view.seen.both()) {
      // A length is the difference of two ends (variance 2 s^2), two lengths' difference 4 s^2.
      if (std::abs(l - vehicle_length) > length_tolerance || std::abs(l - median_length) > 3.0 * 2.0 * s.view.end_sigma)
        continue;
    }
    if (s.view.seen.low) ends.push_back({0, EndSample{s.time, s.view.ends.low, variance}});
    if (s.view.seen.high) ends.push_back({1, EndSample{s.time, s.view.ends.high, variance}});
    if (!ends.empty()) samples.push_back(std::move(ends));
  }
  std::vector<const ScanEnds*> kept;
  for (const ScanEnds& s : samples)
    if (samples.size() >= 4 || s.size() == 2) kept.push_back(&s);
  // Each scan against the line through the others (a stray scan at either end of the run pulls
  // the line through all of them toward itself), in the standard deviations of the difference of
  // its seen ends' mean: the one furthest off beyond three is left out.
  if (kept.size() >= 4) {
    auto worst = kept.end();
    double worst_z = 3.0;
    for (auto it = kept.begin(); it != kept.end(); ++it) {
      std::vector<const ScanEnds*> others(kept.begin(), kept.end());
      others.erase(others.begin() + (it - kept.begin()));
      const std::optional<EndsFit> fit = fitEnds(others);
      if (!fit) continue;
      // The mean of its ends' residuals: their own and their intercepts' variances average down,
      // the slope's does not (one slope for both).
      double residual = 0, variance = 0, dt = 0;
      const double n = static_cast<double>((*it)->size());
      bool fitted = true;
      for (const auto& [end, e] : **it) {
        if (!(fit->weight[end] > 0)) fitted = false;
        residual += (e.position - fit->at(end, e.time)) / n;
        variance += (e.variance + 1.0 / fit->weight[end]) / (n * n);
        dt += (e.time - fit->mean_time[end]) / n;
      }
      if (!fitted) continue;
      variance += fit->line.sigma * fit->line.sigma * dt * dt;
      const double z = std::abs(residual) / std::sqrt(variance);
      if (z > worst_z) {
        worst_z = z;
        worst = it;
      }
    }
    if (worst != kept.end()) kept.erase(worst);
  }
  const std::optional<EndsFit> fit = fitEnds(kept);
  if (!fit) return std::nullopt;
  return fit->line;
}

}  // namespace dlslot::backend
