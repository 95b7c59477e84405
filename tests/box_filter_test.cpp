// pointsInBoxes (the A-LOAM* filter, paper III-D) and pointsOfBoxes (each object's points) against
// Box::contains point by point: boxes scattered, overlapping, at the edges of the scan and none at all.
#include <gtest/gtest.h>

#include <random>

#include "dlslot/box_filter.hpp"

namespace dlslot {
namespace {

TEST(BoxFilter, EqualsTestingEveryPointAgainstEveryBox) {
  std::mt19937 rng(21);
  std::uniform_real_distribution<double> U(-1.0, 1.0);
  PointCloud scan(4, 50000);
  for (Eigen::Index i = 0; i < scan.cols(); ++i) scan.col(i) << 60 * U(rng), 60 * U(rng), 2 * U(rng), 0;
  for (int n : {0, 1, 25}) {
    std::vector<Box> boxes;
    for (int b = 0; b < n; ++b) {
      Box box;
      box.center = Eigen::Vector3d(60 * U(rng), 60 * U(rng), 0.5 * U(rng));
      box.size = Eigen::Vector3d(4 + 2 * U(rng), 2 + U(rng), 1.5 + 0.3 * U(rng));
      box.yaw = 3 * U(rng);
      boxes.push_back(box);
    }
    if (n == 25) boxes[1].center = boxes[0].center + Eigen::Vector3d(1, 0.5, 0);  // overlapping
    for (double margin : {0.0, 0.3}) {
      const std::vector<bool> inside = pointsInBoxes(scan, boxes, margin);
      // pointsOfBoxes: each box's points, a point in two overlapping boxes in both.
      const std::vector<std::vector<int>> members = pointsOfBoxes(scan, boxes, margin);
      ASSERT_EQ(members.size(), boxes.size());
      std::vector<size_t> next(boxes.size(), 0);
      int count = 0;
      for (Eigen::Index i = 0; i < scan.cols(); ++i) {
        bool expected = false;
        for (size_t b = 0; b < boxes.size(); ++b) {
          const bool in_b = boxes[b].contains(scan.col(i).head<3>().cast<double>(), margin);
          expected = expected || in_b;
          if (!in_b) continue;
          ASSERT_LT(next[b], members[b].size()) << "box " << b;
          ASSERT_EQ(members[b][next[b]++], i) << "box " << b;
        }
        ASSERT_EQ(inside[i], expected) << "point " << i << ", " << n << " boxes, margin " << margin;
        count += expected;
      }
      for (size_t b = 0; b < boxes.size(); ++b) EXPECT_EQ(next[b], members[b].size()) << "box " << b;
      if (n == 25) {
        EXPECT_GT(count, 100);
      }
    }
  }
}

}  // namespace
}  // namespace dlslot
