// The bird's-eye image of one frame: scan points (kept / removed as dynamic, shaded by height),
// ground truth, detections, associations, tracks (oriented boxes by id, labels, velocity arrows,
// static dashed / dynamic filled), the three ego trajectories, scale bar, legend and text.
// Deterministic: the same input gives the same pixels, so the same PNG bytes.
#pragma once

#include <opencv2/core.hpp>
#include <string>
#include <vector>

#include "render_config.hpp"
#include "render_input.hpp"

namespace dlslot::renderer {

cv::Mat renderBev(const RenderInput& in, const ViewConfig& view);

// PNG bytes: compression -1 = fastest (OpenCV's speed-tuned settings), 0-9 = zlib level with
// adaptive filters (smaller files, 2-4x slower).
std::vector<uchar> encodePng(const cv::Mat& img, int compression);
// The same, written to `path`; throws std::runtime_error naming the file when that fails.
void writePng(const std::string& path, const cv::Mat& img, int compression);

}  // namespace dlslot::renderer
