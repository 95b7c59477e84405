// Drawing primitives the per-frame and summary images share: oriented boxes, dashed and
// translucent shapes, labels with a backdrop, the scale bar and the legend. Positions are in
// pixels (double); lines are drawn anti-aliased with sub-pixel precision.
#pragma once

#include <Eigen/Core>
#include <array>
#include <opencv2/core.hpp>
#include <string>
#include <vector>

#include "dlslot/types.hpp"

namespace dlslot::renderer {

using Polygon = std::vector<Eigen::Vector2d>;

// printf into a std::string, for the image's text.
std::string strf(const char* fmt, ...) __attribute__((format(printf, 1, 2)));

// A w x h BGR image of one colour. OpenCV 4.6 fills 3-channel images with a scalar at ~13 ms per
// megapixel; one row copied down is ~30x faster.
cv::Mat solidImage(int width, int height, const cv::Scalar& colour);

// The footprint of a box (l x w about its centre, heading x) in the frame of T_frame_box.
std::array<Eigen::Vector3d, 4> footprint(const Pose& T_frame_box, const Eigen::Vector3d& size);

void line(cv::Mat& img, const Eigen::Vector2d& a, const Eigen::Vector2d& b, const cv::Scalar& colour,
          int thickness = 1);
void dashedLine(cv::Mat& img, const Eigen::Vector2d& a, const Eigen::Vector2d& b, const cv::Scalar& colour,
                int thickness, double dash_px, double gap_px);
void polyline(cv::Mat& img, const Polygon& pts, bool closed, const cv::Scalar& colour, int thickness = 1);
void dashedPolygon(cv::Mat& img, const Polygon& pts, const cv::Scalar& colour, int thickness, double dash_px = 5,
                   double gap_px = 4);
// Fills a convex polygon blended with `alpha` (0..1) over what is drawn, touching only its bounding box.
void fillTranslucent(cv::Mat& img, const Polygon& pts, const cv::Scalar& colour, double alpha);
// Darkens a rectangle towards the panel colour, for text that must stay readable over points.
void shade(cv::Mat& img, const cv::Rect& rect, double alpha = 0.8);
void arrow(cv::Mat& img, const Eigen::Vector2d& from, const Eigen::Vector2d& to, const cv::Scalar& colour,
           int thickness = 1);

// Text (Hershey simplex, anti-aliased); `origin` is the baseline's left end.
constexpr double kSmallFont = 0.42, kNormalFont = 0.5, kTitleFont = 0.62;
void text(cv::Mat& img, const std::string& s, cv::Point origin, const cv::Scalar& colour, double scale = kSmallFont,
          int thickness = 1);
cv::Size textSize(const std::string& s, double scale = kSmallFont, int thickness = 1);
// A short label on a dark backdrop, left end of its baseline at `origin`; returns its backdrop.
cv::Rect label(cv::Mat& img, const std::string& s, cv::Point origin, const cv::Scalar& colour,
               double scale = kSmallFont);
// Labels that step down past the ones already placed instead of covering them (greedy, in call
// order, so the result is deterministic).
class LabelPlacer {
 public:
  void place(cv::Mat& img, const std::string& s, cv::Point origin, const cv::Scalar& colour);

 private:
  std::vector<cv::Rect> placed_;
};

// Lines of text on a shaded panel whose top-left (top-right when right_aligned) corner is
// `corner`; returns the panel's rectangle.
struct TextLine {
  std::string text;
  cv::Scalar colour;
  double scale = kSmallFont;
};
cv::Rect textPanel(cv::Mat& img, const std::vector<TextLine>& lines, cv::Point corner, bool right_aligned = false);

// A bar of a round length (1, 2 or 5 x 10^k m) about a fifth of the image wide, bottom right.
void scaleBar(cv::Mat& img, double metres_per_pixel);

struct LegendEntry {
  enum class Swatch { Line, DashedLine, Box, DashedBox, FilledBox, Dots, Cross } swatch;
  cv::Scalar colour;
  std::string text;
  cv::Scalar colour2 = cv::Scalar(-1, -1, -1, -1);  // Dots: second shade; unused when negative
};
// The legend on a shaded panel, bottom left.
void legend(cv::Mat& img, const std::vector<LegendEntry>& entries);

}  // namespace dlslot::renderer
