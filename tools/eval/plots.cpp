#include "plots.hpp"

#include <algorithm>
#include <cmath>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>
#include <vector>

#include "dlslot/input_error.hpp"
#include "ego_metrics.hpp"

namespace dlslot::eval {
namespace {

using Series = std::vector<Eigen::Vector2d>;

const cv::Scalar kTruthColour(170, 170, 170);
const std::vector<cv::Scalar> kColours = {{200, 90, 30}, {40, 40, 220}, {40, 160, 40}, {180, 40, 180}, {0, 140, 230}};

// A data-to-pixel mapping with axes, ticks and a legend.
class Plot {
 public:
  Plot(Eigen::Vector2d lo, Eigen::Vector2d hi, bool equal_scale) : image_(kHeight, kWidth, CV_8UC3, cv::Scalar(255, 255, 255)) {
    for (int k = 0; k < 2; ++k)
      if (!(hi[k] - lo[k] > 1e-9)) {  // a flat range still gets some extent
        lo[k] -= 1.0;
        hi[k] += 1.0;
      }
    const Eigen::Vector2d pad = 0.04 * (hi - lo);
    lo -= pad;
    hi += pad;
    const Eigen::Vector2d pixels(kWidth - kLeft - kRight, kHeight - kTop - kBottom);
    scale_ = pixels.cwiseQuotient(hi - lo);
    if (equal_scale) {  // same metres per pixel on both axes, data centred
      const double s = scale_.minCoeff();
      const Eigen::Vector2d centre = 0.5 * (lo + hi), half = 0.5 * pixels / s;
      lo = centre - half;
      hi = centre + half;
      scale_.setConstant(s);
    }
    lo_ = lo;
    hi_ = hi;
  }

  cv::Point toPixel(const Eigen::Vector2d& p) const {
    return {static_cast<int>(std::lround(kLeft + (p.x() - lo_.x()) * scale_.x())),
            static_cast<int>(std::lround(kHeight - kBottom - (p.y() - lo_.y()) * scale_.y()))};
  }

  void axes(const std::string& x_label, const std::string& y_label, const std::string& title) {
    const cv::Scalar grid(225, 225, 225), ink(60, 60, 60);
    for (int k = 0; k < 2; ++k) {
      const double step = tickStep(hi_[k] - lo_[k]);
      for (double v = std::ceil(lo_[k] / step) * step; v <= hi_[k]; v += step) {
        Eigen::Vector2d a = lo_, b = hi_;
        a[k] = b[k] = v;
        cv::line(image_, toPixel(a), toPixel(b), grid, 1);
        char text[32];
        std::snprintf(text, sizeof text, "%g", std::abs(v) < 1e-9 * step ? 0.0 : v);
        const cv::Point at = toPixel(a);
        if (k == 0)
          cv::putText(image_, text, {at.x - 12, kHeight - kBottom + 18}, cv::FONT_HERSHEY_SIMPLEX, 0.4, ink, 1, cv::LINE_AA);
        else
          cv::putText(image_, text, {8, at.y + 4}, cv::FONT_HERSHEY_SIMPLEX, 0.4, ink, 1, cv::LINE_AA);
      }
    }
    cv::rectangle(image_, {kLeft, kTop}, {kWidth - kRight, kHeight - kBottom}, ink, 1);
    int baseline = 0;
    const int x_label_width = cv::getTextSize(x_label, cv::FONT_HERSHEY_SIMPLEX, 0.5, 1, &baseline).width;
    cv::putText(image_, x_label, {(kWidth - x_label_width) / 2, kHeight - 12}, cv::FONT_HERSHEY_SIMPLEX, 0.5, ink, 1,
                cv::LINE_AA);
    cv::putText(image_, y_label, {8, kTop - 10}, cv::FONT_HERSHEY_SIMPLEX, 0.5, ink, 1, cv::LINE_AA);
    const cv::Size size = cv::getTextSize(title, cv::FONT_HERSHEY_SIMPLEX, 0.6, 1, &baseline);
    cv::putText(image_, title, {(kWidth - size.width) / 2, 22}, cv::FONT_HERSHEY_SIMPLEX, 0.6, ink, 1, cv::LINE_AA);
  }

  // A dot marks the first point (where a trajectory starts), or every point (sparse bins).
  enum class Dots { First, Every };
  void line(const Series& s, const cv::Scalar& colour, int thickness, const std::string& name, Dots dots = Dots::First,
            bool dashed = false) {
    std::vector<cv::Point> px;
    for (const auto& p : s) px.push_back(toPixel(p));
    if (!dashed) {
      cv::polylines(image_, px, false, colour, thickness, cv::LINE_AA);
    } else {
      constexpr double kOn = 8, kPeriod = 14;  // pixels
      for (size_t i = 1; i < px.size(); ++i) {
        const cv::Point2d a = px[i - 1], d = cv::Point2d(px[i]) - a;
        const double length = std::hypot(d.x, d.y);
        for (double t = 0; t < length; t += kPeriod)
          cv::line(image_, a + d * (t / length), a + d * (std::min(t + kOn, length) / length), colour, thickness,
                   cv::LINE_AA);
      }
    }
    // A dashed series' dots are rings, so a lone point still tells which series it is.
    for (size_t i = 0; i < px.size() && (i == 0 || dots == Dots::Every); ++i)
      cv::circle(image_, px[i], dashed ? 5 : 4, colour, dashed ? 2 : cv::FILLED, cv::LINE_AA);
    if (!px.empty()) legend_.push_back({name, colour, dashed});
  }

  void save(const std::string& path) {
    int y = kTop + 20;
    for (const auto& [name, colour, dashed] : legend_) {
      const int x0 = kWidth - kRight - 170, x1 = kWidth - kRight - 145;
      if (dashed) {
        cv::line(image_, {x0, y - 4}, {x0 + 8, y - 4}, colour, 1, cv::LINE_AA);
        cv::line(image_, {x1 - 8, y - 4}, {x1, y - 4}, colour, 1, cv::LINE_AA);
        cv::circle(image_, {(x0 + x1) / 2, y - 4}, 5, colour, 2, cv::LINE_AA);
      } else {
        cv::line(image_, {x0, y - 4}, {x1, y - 4}, colour, 3, cv::LINE_AA);
      }
      cv::putText(image_, name, {kWidth - kRight - 138, y}, cv::FONT_HERSHEY_SIMPLEX, 0.45, colour, 1, cv::LINE_AA);
      y += 20;
    }
    if (!cv::imwrite(path, image_)) throw InputError(path, 0, "cannot write the PNG");
  }

 private:
  static double tickStep(double range) {
    const double raw = range / 6.0, p = std::pow(10.0, std::floor(std::log10(raw)));
    for (double m : {1.0, 2.0, 5.0})
      if (m * p >= raw) return m * p;
    return 10.0 * p;
  }
  static constexpr int kWidth = 1000, kHeight = 800, kLeft = 70, kRight = 20, kTop = 60, kBottom = 50;
  cv::Mat image_;
  Eigen::Vector2d lo_, hi_, scale_;
  struct LegendEntry {
    std::string name;
    cv::Scalar colour;
    bool dashed;
  };
  std::vector<LegendEntry> legend_;
};

Series bev(const Trajectory& t) {
  Series s;
  for (const Pose& T : t.poses) s.push_back(T.translation().head<2>());
  return s;
}

void bounds(const Series& s, Eigen::Vector2d& lo, Eigen::Vector2d& hi) {
  for (const auto& p : s) {
    lo = lo.cwiseMin(p);
    hi = hi.cwiseMax(p);
  }
}

}  // namespace

void plotTrajectories(const std::string& path, const std::map<std::string, Trajectory>& sources,
                      const std::optional<Trajectory>& truth) {
  Eigen::Vector2d lo = Eigen::Vector2d::Constant(INFINITY), hi = -lo;
  std::vector<std::pair<std::string, Series>> series;
  if (truth) series.emplace_back("ground truth", bev(*truth));
  for (const auto& [name, t] : sources) series.emplace_back(name, bev(t));
  for (const auto& s : series) bounds(s.second, lo, hi);
  if (!lo.allFinite()) lo = hi = Eigen::Vector2d::Zero();
  Plot plot(lo, hi, true);
  plot.axes("x [m]", "y [m]", "trajectories, bird's-eye view");
  // The ground truth wide and light underneath, so an estimate on top of it stays visible.
  size_t c = 0;
  for (const auto& [name, s] : series) {
    const bool is_truth = truth && name == "ground truth";
    plot.line(s, is_truth ? kTruthColour : kColours[c++ % kColours.size()], is_truth ? 6 : 2, name);
  }
  plot.save(path);
}

void plotErrorOverDistance(const std::string& path, const std::map<std::string, Trajectory>& sources,
                           const Trajectory& truth) {
  Eigen::Vector2d lo(0, 0), hi = lo;
  std::vector<std::pair<std::string, Series>> series;
  for (const auto& [name, t] : sources) {
    const auto [est, gt] = commonFrames(t, truth);
    if (est.empty()) continue;
    const std::vector<double> dist = pathDistances(gt), err = alignedPositionErrors(est, gt);
    Series s;
    for (size_t i = 0; i < dist.size(); ++i) s.emplace_back(dist[i], err[i]);
    bounds(s, lo, hi);
    series.emplace_back(name, std::move(s));
  }
  Plot plot(lo, hi, false);
  plot.axes("distance along ground truth [m]", "position error after alignment [m]", "translation error over distance");
  size_t c = 0;
  for (const auto& [name, s] : series) plot.line(s, kColours[c++ % kColours.size()], 2, name);
  plot.save(path);
}

namespace {

// Each bin's error (own = false) or its tracks' own sigma at x_of(bin); bins without a covariance
// have no sigma point.
Series binSeries(const std::vector<VelocityBin>& bins, bool own, double (*x_of)(const VelocityBin&)) {
  Series s;
  for (const VelocityBin& b : bins)
    if (!own || b.own_rms_mps) s.emplace_back(x_of(b), own ? *b.own_rms_mps : b.rmse_mps);
  return s;
}

}  // namespace

void plotVelocityErrorByRange(const std::string& path, const std::vector<VelocityBin>& young,
                              const std::vector<VelocityBin>& older) {
  const auto centre = [](const VelocityBin& b) { return 0.5 * (b.from + b.to); };
  const Series young_error = binSeries(young, false, centre), young_own = binSeries(young, true, centre);
  const Series older_error = binSeries(older, false, centre), older_own = binSeries(older, true, centre);
  Eigen::Vector2d lo(0, 0), hi = lo;
  for (const auto* bins : {&young, &older})
    for (const VelocityBin& b : *bins) hi.x() = std::max(hi.x(), b.to);  // whole bins, from the sensor on
  for (const Series* s : {&young_error, &young_own, &older_error, &older_own}) bounds(*s, lo, hi);
  hi.y() *= 1.25;  // room for the legend above the curves
  Plot plot(lo, hi, false);
  plot.axes("range of the object [m]", "velocity error, RMS [m/s]", "velocity error of moving objects by range");
  plot.line(young_error, kColours[1], 2, "young (< 5 scans)", Plot::Dots::Every);
  plot.line(young_own, kColours[1], 1, "its own sigma", Plot::Dots::Every, true);
  plot.line(older_error, kColours[0], 2, "5+ scans", Plot::Dots::Every);
  plot.line(older_own, kColours[0], 1, "its own sigma", Plot::Dots::Every, true);
  plot.save(path);
}

void plotVelocityErrorByAge(const std::string& path, const std::vector<VelocityBin>& bins, int last_age) {
  const auto age = [](const VelocityBin& b) { return b.from; };
  const Series error = binSeries(bins, false, age), own = binSeries(bins, true, age);
  Eigen::Vector2d lo(0, 0), hi = lo;
  bounds(error, lo, hi);
  bounds(own, lo, hi);
  hi.y() *= 1.15;
  Plot plot(lo, hi, false);
  plot.axes("track age [scans since its first output; " + std::to_string(last_age) + ": that and older]",
            "velocity error, RMS [m/s]", "velocity error of moving objects by track age");
  plot.line(error, kColours[0], 2, "error", Plot::Dots::Every);
  plot.line(own, kColours[0], 1, "its own sigma", Plot::Dots::Every, true);
  plot.save(path);
}

}  // namespace dlslot::eval
