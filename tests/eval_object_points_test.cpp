// dlslot-eval --object-points: the points inside each labelled box, by class and range.
#include <gtest/gtest.h>

#include "object_points.hpp"

using namespace dlslot;
using namespace dlslot::eval;

namespace {
PointCloud cloud(const std::vector<Eigen::Vector3d>& pts) {
  PointCloud c(4, static_cast<Eigen::Index>(pts.size()));
  for (size_t i = 0; i < pts.size(); ++i) c.col(static_cast<Eigen::Index>(i)) << pts[i].cast<float>(), 0.5f;
  return c;
}
}  // namespace

TEST(ObjectPoints, CountsWhatLiesInTheGrownBoxAboveItsBottomBand) {
  Box car;  // 4 x 2 x 1.5 m, turned 90 deg, centre 15 m ahead at road height + 0.75
  car.center = {15, 0, -0.98};
  car.size = {4, 2, 1.5};
  car.yaw = M_PI / 2;
  car.type = "Car";
  std::vector<Eigen::Vector3d> pts = {
      {15, 0, -0.98},          // centre
      {15.95, 1.95, -0.5},     // inside (turned: x spans the width 2 m, y the length 4 m)
      {16.05, 0, -0.5},        // 0.05 m outside the side: within the 0.1 m margin
      {16.2, 0, -0.5},         // 0.2 m outside: not the car's
      {15, 2.5, -0.5},         // beyond the turned length
      {15, 0, -1.70},          // in the bottom band (0.03 m above the floor): the road's
      {15, 0, -0.16},          // 0.07 m above the roof: within the margin
      {-15, 0, -0.98}};        // the mirror image behind the sensor
  const std::vector<ObjectPoints> n = countObjectPoints(7, cloud(pts), {car}, ObjectPointOptions{});
  ASSERT_EQ(n.size(), 1u);
  EXPECT_EQ(n[0].points, 4);
  EXPECT_EQ(n[0].frame, 7);
  EXPECT_EQ(n[0].type, "Car");
  EXPECT_NEAR(n[0].range_m, 15.0, 1e-9);
}

TEST(ObjectPoints, SummarisesByClassAndRangeBin) {
  std::vector<ObjectPoints> s;
  for (int p : {100, 200, 300, 400, 500}) s.push_back({0, "Car", 12.0, p});
  s.push_back({0, "Car", 35.0, 50});
  s.push_back({0, "Pedestrian", 12.0, 80});
  s.push_back({0, "Car", 75.0, 9});  // beyond the last edge: not binned
  const std::vector<ObjectPointRow> rows = summariseObjectPoints(s, ObjectPointOptions{});
  ASSERT_EQ(rows.size(), 3u);
  EXPECT_EQ(rows[0].type, "Car");
  EXPECT_EQ(rows[0].range_lo_m, 10);
  EXPECT_EQ(rows[0].range_hi_m, 20);
  EXPECT_EQ(rows[0].objects, 5);
  EXPECT_EQ(rows[0].median, 300);
  EXPECT_EQ(rows[0].p25, 200);
  EXPECT_EQ(rows[0].p75, 400);
  EXPECT_EQ(rows[1].range_lo_m, 30);
  EXPECT_EQ(rows[1].median, 50);
  EXPECT_EQ(rows[2].type, "Pedestrian");
  EXPECT_NE(objectPointTable(rows).find("| Car | 10-20 | 5 | 300 | 200-400 |"), std::string::npos);
  ObjectPointOptions bad;
  bad.range_edges_m = {10, 5};
  EXPECT_THROW(summariseObjectPoints(s, bad), std::invalid_argument);
}
