#include "drawing.hpp"

#include <algorithm>
#include <cmath>
#include <cstdarg>
#include <cstdio>
#include <opencv2/imgproc.hpp>

#include "palette.hpp"
#include "view_transform.hpp"

namespace dlslot::renderer {

std::string strf(const char* fmt, ...) {
  char buf[512];
  va_list args;
  va_start(args, fmt);
  std::vsnprintf(buf, sizeof buf, fmt, args);
  va_end(args);
  return buf;
}

cv::Mat solidImage(int width, int height, const cv::Scalar& colour) {
  cv::Mat img(height, width, CV_8UC3);
  const cv::Vec3b c(static_cast<uchar>(colour[0]), static_cast<uchar>(colour[1]), static_cast<uchar>(colour[2]));
  cv::Vec3b* first = img.ptr<cv::Vec3b>(0);
  std::fill(first, first + width, c);
  for (int r = 1; r < height; ++r) std::copy(first, first + width, img.ptr<cv::Vec3b>(r));
  return img;
}

std::array<Eigen::Vector3d, 4> footprint(const Pose& T_frame_box, const Eigen::Vector3d& size) {
  const double l = 0.5 * size.x(), w = 0.5 * size.y();
  return {T_frame_box * Eigen::Vector3d(l, w, 0), T_frame_box * Eigen::Vector3d(-l, w, 0),
          T_frame_box * Eigen::Vector3d(-l, -w, 0), T_frame_box * Eigen::Vector3d(l, -w, 0)};
}

void line(cv::Mat& img, const Eigen::Vector2d& a, const Eigen::Vector2d& b, const cv::Scalar& colour,
          int thickness) {
  cv::line(img, subpixel(a), subpixel(b), colour, thickness, cv::LINE_AA, kShift);
}

void dashedLine(cv::Mat& img, const Eigen::Vector2d& a, const Eigen::Vector2d& b, const cv::Scalar& colour,
                int thickness, double dash_px, double gap_px) {
  const double len = (b - a).norm();
  if (len < 1e-9) return;
  const Eigen::Vector2d dir = (b - a) / len;
  for (double s = 0; s < len; s += dash_px + gap_px) line(img, a + s * dir, a + std::min(s + dash_px, len) * dir, colour, thickness);
}

void polyline(cv::Mat& img, const Polygon& pts, bool closed, const cv::Scalar& colour, int thickness) {
  if (pts.size() < 2) return;
  std::vector<cv::Point> p;
  p.reserve(pts.size());
  for (const auto& q : pts) p.push_back(subpixel(q));
  cv::polylines(img, p, closed, colour, thickness, cv::LINE_AA, kShift);
}

void dashedPolygon(cv::Mat& img, const Polygon& pts, const cv::Scalar& colour, int thickness, double dash_px,
                   double gap_px) {
  for (size_t i = 0; i < pts.size(); ++i) dashedLine(img, pts[i], pts[(i + 1) % pts.size()], colour, thickness, dash_px, gap_px);
}

void fillTranslucent(cv::Mat& img, const Polygon& pts, const cv::Scalar& colour, double alpha) {
  std::vector<cv::Point> p;
  for (const auto& q : pts) p.push_back(subpixel(q));
  cv::Rect box = cv::boundingRect(p);
  box = cv::Rect(box.x >> kShift, box.y >> kShift, (box.width >> kShift) + 2, (box.height >> kShift) + 2) &
        cv::Rect(0, 0, img.cols, img.rows);
  if (box.area() == 0) return;
  cv::Mat roi = img(box), layer = roi.clone();
  for (auto& q : p) q -= cv::Point(box.x << kShift, box.y << kShift);
  cv::fillConvexPoly(layer, p, colour, cv::LINE_AA, kShift);
  cv::addWeighted(layer, alpha, roi, 1.0 - alpha, 0.0, roi);
}

void shade(cv::Mat& img, const cv::Rect& rect, double alpha) {
  const cv::Rect r = rect & cv::Rect(0, 0, img.cols, img.rows);
  if (r.area() == 0) return;
  cv::Mat roi = img(r);
  roi = roi * (1.0 - alpha) + colour::kPanel * alpha;
}

void arrow(cv::Mat& img, const Eigen::Vector2d& from, const Eigen::Vector2d& to, const cv::Scalar& colour,
           int thickness) {
  const double len = (to - from).norm();
  if (len < 1.0) return;
  // A fixed-size head (not a fraction of the length) keeps short and long arrows readable.
  cv::arrowedLine(img, subpixel(from), subpixel(to), colour, thickness, cv::LINE_AA, kShift,
                  std::min(0.45, 7.0 / len));
}

void text(cv::Mat& img, const std::string& s, cv::Point origin, const cv::Scalar& colour, double scale,
          int thickness) {
  cv::putText(img, s, origin, cv::FONT_HERSHEY_SIMPLEX, scale, colour, thickness, cv::LINE_AA);
}

cv::Size textSize(const std::string& s, double scale, int thickness) {
  int baseline = 0;
  return cv::getTextSize(s, cv::FONT_HERSHEY_SIMPLEX, scale, thickness, &baseline);
}

cv::Rect label(cv::Mat& img, const std::string& s, cv::Point origin, const cv::Scalar& colour, double scale) {
  const cv::Size sz = textSize(s, scale);
  const cv::Rect backdrop(origin.x - 2, origin.y - sz.height - 3, sz.width + 4, sz.height + 6);
  shade(img, backdrop, 0.75);
  text(img, s, origin, colour, scale);
  return backdrop;
}

void LabelPlacer::place(cv::Mat& img, const std::string& s, cv::Point origin, const cv::Scalar& colour) {
  const cv::Size sz = textSize(s);
  auto backdrop = [&](cv::Point o) { return cv::Rect(o.x - 2, o.y - sz.height - 3, sz.width + 4, sz.height + 6); };
  for (int tries = 0; tries < 6; ++tries) {
    bool free = true;
    for (const cv::Rect& r : placed_) free = free && (r & backdrop(origin)).area() == 0;
    if (free) break;
    origin.y += sz.height + 7;
  }
  placed_.push_back(label(img, s, origin, colour));
}

cv::Rect textPanel(cv::Mat& img, const std::vector<TextLine>& lines, cv::Point corner, bool right_aligned) {
  const int pad = 8, gap = 6;
  int w = 0, h = pad;
  std::vector<cv::Size> sizes;
  for (const TextLine& l : lines) {
    sizes.push_back(textSize(l.text.empty() ? " " : l.text, l.scale));
    w = std::max(w, sizes.back().width);
    h += sizes.back().height + gap;
  }
  const cv::Rect panel(right_aligned ? corner.x - w - 2 * pad : corner.x, corner.y, w + 2 * pad, h + pad - gap + 2);
  shade(img, panel);
  int y = panel.y + pad;
  for (size_t i = 0; i < lines.size(); ++i) {
    y += sizes[i].height;
    text(img, lines[i].text, cv::Point(panel.x + pad, y), lines[i].colour, lines[i].scale);
    y += gap;
  }
  return panel;
}

void scaleBar(cv::Mat& img, double metres_per_pixel) {
  // The longest round length not wider than a fifth of the image.
  const double target = 0.2 * img.cols * metres_per_pixel;
  double step = std::pow(10.0, std::floor(std::log10(target)));
  for (double m : {5.0, 2.0, 1.0})
    if (m * step <= target) {
      step *= m;
      break;
    }
  const int len = static_cast<int>(std::lround(step / metres_per_pixel));
  char buf[32];
  if (step >= 1000)
    std::snprintf(buf, sizeof buf, "%g km", step / 1000);
  else if (step >= 1)
    std::snprintf(buf, sizeof buf, "%g m", step);
  else
    std::snprintf(buf, sizeof buf, "%g cm", step * 100);
  const cv::Size ts = textSize(buf, kNormalFont);
  const int right = img.cols - 20, base = img.rows - 18;
  const int left = right - len;
  shade(img, cv::Rect(left - 10, base - ts.height - 22, len + 20, ts.height + 32));
  // Alternating half bars, like a map's scale.
  cv::rectangle(img, cv::Rect(left, base - 6, len, 6), colour::kText, cv::FILLED);
  cv::rectangle(img, cv::Rect(left + len / 4, base - 5, len / 4, 4), colour::kPanel, cv::FILLED);
  cv::rectangle(img, cv::Rect(left + 3 * len / 4, base - 5, len - 3 * len / 4 - 1, 4), colour::kPanel, cv::FILLED);
  text(img, buf, cv::Point(left + (len - ts.width) / 2, base - 12), colour::kText, kNormalFont);
}

void legend(cv::Mat& img, const std::vector<LegendEntry>& entries) {
  if (entries.empty()) return;
  const int pad = 8, row = 18, swatch_w = 26;
  int w = 0;
  for (const auto& e : entries) w = std::max(w, textSize(e.text).width);
  const int h = pad * 2 + row * static_cast<int>(entries.size()) - 4;
  const cv::Rect panel(12, img.rows - h - 12, w + swatch_w + 3 * pad, h);
  shade(img, panel);
  int y = panel.y + pad + row / 2 - 2;
  for (const auto& e : entries) {
    const Eigen::Vector2d a(panel.x + pad, y), b(panel.x + pad + swatch_w, y);
    const Polygon rect = {Eigen::Vector2d(a.x() + 3, y - 5), Eigen::Vector2d(b.x() - 3, y - 5),
                          Eigen::Vector2d(b.x() - 3, y + 5), Eigen::Vector2d(a.x() + 3, y + 5)};
    switch (e.swatch) {
      case LegendEntry::Swatch::Line: line(img, a, b, e.colour, 2); break;
      case LegendEntry::Swatch::DashedLine: dashedLine(img, a, b, e.colour, 1, 4, 3); break;
      case LegendEntry::Swatch::Box: polyline(img, rect, true, e.colour, 1); break;
      case LegendEntry::Swatch::DashedBox: dashedPolygon(img, rect, e.colour, 1, 3, 2); break;
      case LegendEntry::Swatch::FilledBox:
        fillTranslucent(img, rect, e.colour, 0.35);
        polyline(img, rect, true, e.colour, 1);
        break;
      case LegendEntry::Swatch::Dots:
        for (int i = 0; i < 7; ++i) {
          const cv::Scalar& c = (e.colour2[0] >= 0 && i % 2) ? e.colour2 : e.colour;
          cv::rectangle(img, cv::Rect(static_cast<int>(a.x()) + 2 + 3 * i, y - 3 + (i * 5) % 7, 2, 2), c, cv::FILLED);
        }
        break;
      case LegendEntry::Swatch::Cross:
        line(img, Eigen::Vector2d(a.x() + 9, y - 4), Eigen::Vector2d(a.x() + 17, y + 4), e.colour, 1);
        line(img, Eigen::Vector2d(a.x() + 9, y + 4), Eigen::Vector2d(a.x() + 17, y - 4), e.colour, 1);
        break;
    }
    text(img, e.text, cv::Point(panel.x + 2 * pad + swatch_w, y + 5), colour::kText);
    y += row;
  }
}

}  // namespace dlslot::renderer
