// Message <-> Eigen conversion, in one place. Cores never see LCM types; nodes call these.
#pragma once

#include <Eigen/Core>
#include <string>
#include <utility>
#include <vector>

#include "dlslot/box_t.hpp"
#include "dlslot/point_cloud_t.hpp"
#include "dlslot/pose_t.hpp"
#include "dlslot/stage_timing_t.hpp"
#include "dlslot/types.hpp"

namespace dlslot {

using Matrix6d = Eigen::Matrix<double, 6, 6>;
using StageTimings = std::vector<std::pair<std::string, double>>;  // (stage name, ms)

pose_t toMsg(const Pose& T);
Pose fromMsg(const pose_t& m);  // re-normalises the quaternion

box_t toMsg(const Box& b);
Box fromMsg(const box_t& m);
std::vector<box_t> toMsg(const std::vector<Box>& boxes);
std::vector<Box> fromMsg(const std::vector<box_t>& boxes);

void toMsg(const Matrix6d& cov, double out[36]);  // row-major
Matrix6d covFromMsg(const double in[36]);

// Fills a point_cloud_t's arrays (num_points included) from a scan.
void toMsg(const PointCloud& scan, point_cloud_t& out);
PointCloud fromMsg(const point_cloud_t& m);

std::vector<stage_timing_t> toMsg(const StageTimings& t);
StageTimings fromMsg(const std::vector<stage_timing_t>& t);

// True when every number of the box is finite and its size positive.
bool isValid(const box_t& b);

}  // namespace dlslot
