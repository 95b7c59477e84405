#include "frame_writer.hpp"

#include <cstdio>
#include <filesystem>
#include <stdexcept>

#include "bev_renderer.hpp"
#include "dlslot/box_filter.hpp"
#include "summary_renderer.hpp"

namespace dlslot::renderer {

FrameWriter::FrameWriter(std::string out_dir, const RendererConfig& cfg) : out_dir_(std::move(out_dir)), cfg_(cfg) {
  std::error_code ec;
  std::filesystem::create_directories(out_dir_, ec);
  if (ec || !std::filesystem::is_directory(out_dir_))
    throw std::runtime_error(out_dir_ + ": cannot create output directory" + (ec ? " (" + ec.message() + ")" : ""));
  if (cfg_.summary.enabled && cfg_.summary.map_cell_m > 0)
    map_ = std::make_unique<DensityMap>(cfg_.summary.map_cell_m, cfg_.summary.map_min_height_m);
}

std::string FrameWriter::framePath(int frame) const {
  char name[32];
  std::snprintf(name, sizeof name, "%06d.png", frame);
  return (std::filesystem::path(out_dir_) / name).string();
}

std::string FrameWriter::write(const RenderInput& in) {
  const std::string path = framePath(in.frame);
  writePng(path, renderBev(in, cfg_.view), cfg_.png_compression);
  if (map_ && in.has_scan && in.ego_pose) {
    // A subsample is plenty for a map drawn at the summary's scale; moving objects stay out.
    const int stride = cfg_.summary.map_point_stride;
    PointCloud sample(4, (in.scan.cols() + stride - 1) / stride);
    for (Eigen::Index i = 0, j = 0; i < in.scan.cols(); i += stride, ++j) sample.col(j) = in.scan.col(i);
    if (in.has_detections && !in.detections.empty())
      sample = keepOutside(sample, objectPoints(sample, in.detections, cfg_.view.removal_margin_m,
                                                    cfg_.view.removal_ground_clearance_m));
    map_->add(sample, *in.ego_pose);
  }
  return path;
}

std::string FrameWriter::writeSummary(const RunSummary& run) {
  if (!cfg_.summary.enabled) return "";
  const std::string path = (std::filesystem::path(out_dir_) / "summary.png").string();
  writePng(path, renderSummary(run, map_.get(), cfg_.summary), cfg_.png_compression);
  return path;
}

}  // namespace dlslot::renderer
