#include "export.hpp"

#include <cmath>

namespace dlslot::eval {
namespace {

// The image rectangle covered by the box, or -1s when it cannot be projected.
Eigen::Vector4d projectedBox(const Box& box, const kitti::Calib& calib) {
  const Eigen::Matrix<double, 3, 4>& P2 = calib.P[2];
  const Eigen::Vector4d none(-1, -1, -1, -1);
  if (P2.isZero()) return none;
  const Pose T_rect_box = calib.T_rect_velo() * box.pose();
  Eigen::Vector2d lo(INFINITY, INFINITY), hi(-INFINITY, -INFINITY);
  for (int k = 0; k < 8; ++k) {
    const Eigen::Vector3d corner(((k & 1) ? 0.5 : -0.5) * box.size.x(), ((k & 2) ? 0.5 : -0.5) * box.size.y(),
                                 ((k & 4) ? 0.5 : -0.5) * box.size.z());
    const Eigen::Vector3d uvw = P2 * (T_rect_box * corner).homogeneous();
    if (!(uvw.z() > 0.1)) return none;
    const Eigen::Vector2d uv = uvw.head<2>() / uvw.z();
    lo = lo.cwiseMin(uv);
    hi = hi.cwiseMax(uv);
  }
  return Eigen::Vector4d(lo.x(), lo.y(), hi.x(), hi.y());
}

}  // namespace

void writeKittiTracks(const std::string& path, const std::vector<FrameTracks>& frames, const kitti::Calib& calib) {
  std::vector<kitti::LabelRow> rows;
  for (const FrameTracks& f : frames)
    for (const Box& b : f.boxes) {
      kitti::LabelRow r;
      r.frame = f.frame;
      r.track_id = b.id;
      r.type = b.type;
      r.box = kitti::lidarToCamera(b, calib);
      // Observation angle: the heading relative to the ray to the object (KITTI's alpha).
      const Eigen::Vector3d& c = r.box.bottom_center;
      r.alpha = wrapAngle(r.box.rotation_y - std::atan2(c.x(), c.z()));
      r.bbox2d = projectedBox(b, calib);
      r.score = b.score;
      rows.push_back(r);
    }
  kitti::writeTrackingLabels(path, rows);
}

std::vector<FrameTracks> readKittiTracks(const std::string& path, const kitti::Calib& calib, int num_frames,
                                         std::vector<FrameTracks>* dontcare) {
  const std::vector<kitti::FrameBoxes> by_frame = kitti::boxesByFrame(kitti::readTrackingLabels(path), calib, num_frames);
  std::vector<FrameTracks> out(by_frame.size());
  if (dontcare) dontcare->assign(by_frame.size(), {});
  for (size_t i = 0; i < by_frame.size(); ++i) {
    out[i] = {static_cast<int>(i), by_frame[i].boxes};
    if (dontcare) (*dontcare)[i] = {static_cast<int>(i), by_frame[i].dontcare};
  }
  return out;
}

}  // namespace dlslot::eval
