// The KITTI readers on bytes already in hand: `path` only names the source in errors. The path
// readers of kitti.hpp open the file (refusing a directory) and call these, so the parsing and
// the validation of every field live here once; the fuzz targets (tests/fuzz) feed these straight
// from memory, without a file round trip per input.
#pragma once

#include <cstddef>
#include <istream>
#include <string>
#include <vector>

#include "dlslot/kitti.hpp"

namespace dlslot::kitti {

Calib readCalib(std::istream& in, const std::string& path);
std::vector<LabelRow> readTrackingLabels(std::istream& in, const std::string& path);
std::vector<LabelRow> readCsvDetections(std::istream& in, const std::string& path);
std::vector<OxtsRecord> readOxts(std::istream& in, const std::string& path);
std::vector<Pose> readPoses(std::istream& in, const std::string& path);
std::vector<double> readTimes(std::istream& in, const std::string& path);
// A whole scan's bytes: float32 x y z reflectance per point, every value finite.
PointCloud readVelodyne(const char* data, std::size_t bytes, const std::string& path);

}  // namespace dlslot::kitti
