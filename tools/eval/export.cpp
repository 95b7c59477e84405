#include "export.hpp"

namespace dlslot::eval {

ExportCount writeKittiTracks(const std::string& path, const std::vector<FrameTracks>& frames, const kitti::Calib& calib,
                             const kitti::ImageSize& image) {
  std::vector<kitti::LabelRow> rows;
  ExportCount count;
  for (const FrameTracks& f : frames)
    for (const Box& b : f.boxes) {
      if (std::optional<kitti::LabelRow> row = kitti::resultRow(f.frame, b, calib, image))
        rows.push_back(std::move(*row));
      else
        ++count.outside_image;
    }
  count.written = static_cast<int>(rows.size());
  kitti::writeTrackingLabels(path, rows);
  return count;
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
