// How densely the lidar samples the labelled objects: the points inside each labelled box, by
// class and range. It compares data sets on the terms that decide what per-object registration
// and detection can do (a simulated car must be sampled like a real one at the same range), where
// a count per object over a whole drive mostly compares how close the traffic passed.
#pragma once

#include <string>
#include <vector>

#include "dlslot/types.hpp"

namespace dlslot::eval {

struct ObjectPointOptions {
  // A labelled box is tight on the surface: range noise puts about half of its surface points just
  // outside, so the box is grown on its sides and top by this (as the map truth's label_tolerance_m).
  double margin_m = 0.1;
  // The lowest band of the box is where the wheels meet the road: the road's points, not the object's.
  double bottom_band_m = 0.1;
  std::vector<double> range_edges_m = {0, 10, 20, 30, 40, 60};  // bins [e_i, e_i+1) of the box centre's range
};

// One labelled object in one scan.
struct ObjectPoints {
  int frame = 0;
  std::string type;
  double range_m = 0;  // horizontal distance of the box centre from the lidar
  int points = 0;
};

// The points of `scan` (lidar frame) inside each of `labels` (lidar frame).
std::vector<ObjectPoints> countObjectPoints(int frame, const PointCloud& scan, const std::vector<Box>& labels,
                                            const ObjectPointOptions& options);

// Per class and range bin: how many labelled objects, and the quartiles of their point counts.
struct ObjectPointRow {
  std::string type;
  double range_lo_m = 0, range_hi_m = 0;
  int objects = 0;
  double p25 = 0, median = 0, p75 = 0;
};
std::vector<ObjectPointRow> summariseObjectPoints(const std::vector<ObjectPoints>& samples,
                                                  const ObjectPointOptions& options);

// The rows as a Markdown table, and every sample as CSV (frame,type,range_m,points).
std::string objectPointTable(const std::vector<ObjectPointRow>& rows);
void writeObjectPointsCsv(const std::string& path, const std::vector<ObjectPoints>& samples);

}  // namespace dlslot::eval
