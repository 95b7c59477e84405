// attachObjectPoints: the points a registered object is given from a scan. Its box grows with
// the box's own error at its range, so the face a far object shows is kept when the box falls
// short of it; a near box keeps the fixed margin and leaves a neighbour out.
#include <gtest/gtest.h>

#include "backend/object_points.hpp"

using namespace dlslot;
using namespace dlslot::backend;

namespace {

// A vertical face across the line of sight at x = face_x: 5 columns by 5 rows of points.
void addFace(std::vector<Eigen::Vector3f>& points, double face_x, double y0) {
  for (int i = 0; i < 5; ++i)
    for (int j = 0; j < 5; ++j) points.emplace_back(face_x, y0 + 0.4 * (i - 2), -0.5 + 0.4 * j);
}

PointCloud cloudOf(const std::vector<Eigen::Vector3f>& points) {
  PointCloud scan(4, static_cast<Eigen::Index>(points.size()));
  for (size_t i = 0; i < points.size(); ++i) scan.col(static_cast<Eigen::Index>(i)) << points[i], 0.0f;
  return scan;
}

ObservationInput carAt(double x, double y) {
  ObservationInput o;
  o.track_id = 1;
  o.box.type = "Car";
  o.box.center = Eigen::Vector3d(x, y, 0.0);
  o.box.size = Eigen::Vector3d(4.0, 2.0, 2.0);  // its floor at z = -1, the face rows from -0.5 up
  return o;
}

BackendConfig config(double margin_sigmas) {
  BackendConfig c;
  c.registration_types = {"Car"};
  c.observation_sigma << 0.13, 0.08, 0.15, 0.3, 0.3, 0.1;
  c.observation_sigma_growth_per_m = 0.035;
  c.registration_box_margin = 0.2;
  c.registration_box_margin_sigmas = margin_sigmas;
  c.registration_ground_clearance = 0.3;
  return c;
}

size_t pointsOf(const PointCloud& scan, const BackendConfig& c, const ObservationInput& o) {
  std::vector<ObservationInput> observations = {o};
  attachObjectPoints(scan, c, observations);
  return observations[0].points ? observations[0].points->size() : 0;
}

}  // namespace

TEST(ObjectPoints, AFarBoxKeepsTheFaceItsOwnErrorMovedOutOfIt) {
  // A car 100 m ahead whose box ends 0.5 m short of the face the scan shows (a box's position
  // sigma there: 0.13 x 4.5 = 0.585 m).
  std::vector<Eigen::Vector3f> points;
  addFace(points, 97.5, 0.0);
  const PointCloud scan = cloudOf(points);
  const ObservationInput far = carAt(100.0, 0.0);  // its near end at 98 m
  EXPECT_EQ(pointsOf(scan, config(2.0), far), 25u);
  EXPECT_EQ(pointsOf(scan, config(0.0), far), 0u);  // the fixed 0.2 m margin misses the face
}

TEST(ObjectPoints, ANearBoxKeepsItsNarrowMarginAndLeavesTheNeighbourOut) {
  // A car 5 m ahead (margin max(0.2, 2 x 0.13 x 1.175) = 0.31 m) with its rear face 0.1 m inside
  // its box, and a neighbour's side 0.6 m beyond its near end.
  std::vector<Eigen::Vector3f> points;
  addFace(points, 3.1, 0.0);
  addFace(points, 2.4, 0.0);
  const PointCloud scan = cloudOf(points);
  EXPECT_EQ(pointsOf(scan, config(2.0), carAt(5.0, 0.0)), 25u);
  // Only the classes the config registers get points.
  ObservationInput walker = carAt(5.0, 0.0);
  walker.box.type = "Pedestrian";
  EXPECT_EQ(pointsOf(scan, config(2.0), walker), 0u);
}
