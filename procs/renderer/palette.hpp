// The renderer's colours (BGR). Points use desaturated "cold" (kept) and "hot" (removed as
// dynamic) height ramps so the saturated overlays (tracks, trajectories) stand out on top of them.
#pragma once

#include <array>
#include <cstdint>
#include <opencv2/core.hpp>

namespace dlslot::renderer {

namespace colour {
inline const cv::Scalar kBackground(24, 20, 18);
inline const cv::Scalar kGrid(50, 44, 40);
inline const cv::Scalar kGridMajor(72, 64, 58);
inline const cv::Scalar kText(235, 235, 235);
inline const cv::Scalar kTextDim(165, 165, 165);
inline const cv::Scalar kWarning(70, 150, 255);
inline const cv::Scalar kDetection(60, 230, 255);     // yellow
inline const cv::Scalar kGroundTruth(120, 230, 120);  // green, as its trajectory
inline const cv::Scalar kOdometry(230, 90, 230);      // magenta
inline const cv::Scalar kSlot(255, 215, 0);           // cyan: DL-SLOT
inline const cv::Scalar kEgo(235, 235, 235);          // the ego vehicle, whatever estimates its pose
inline const cv::Scalar kPanel(16, 14, 12);
}  // namespace colour

// Point shading as one byte per point: 0 = nothing, 1..127 kept (low..high), 128..255 removed
// (low..high). Taking the maximum code per pixel shows the highest point, and a removed point
// over a kept one, without a depth buffer; one table lookup turns codes into colours.
class PointShading {
 public:
  PointShading(double min_z, double max_z);
  uint8_t code(float z, bool removed) const {
    int i = static_cast<int>((z - min_z_) * scale_);
    i = i < 0 ? 0 : (i > 126 ? 126 : i);
    return static_cast<uint8_t>(removed ? 128 + i : 1 + i);
  }
  const cv::Vec3b& colour(uint8_t code) const { return lut_[code]; }

 private:
  std::array<cv::Vec3b, 256> lut_;
  float min_z_, scale_;
};

// A distinct, stable colour per track id (golden-ratio hue steps); grey for id -1.
cv::Scalar trackColour(int id);
// The colour scaled towards black (factor 0..1), for fainter companions such as trails.
cv::Scalar dimmed(const cv::Scalar& c, double factor);

}  // namespace dlslot::renderer
