// A one-scan nearest-neighbour index for scan-to-scan matching: the previous scan's feature
// points bucketed by cubic cell (points contiguous per cell, cells found through BlockIndex).
// Built in O(n) once per scan where the kd-tree it replaces took O(n log n) (8 % of the
// odometry's instructions on the real slice for the tree of ~40k less-flat points); a query
// visits shells of cells around the query cell, nearest first, and stops as soon as no farther
// cell can hold a closer point: the exact k nearest within the radius.
#pragma once

#include <Eigen/Core>
#include <vector>

#include "block_index.hpp"
#include "feature_extraction.hpp"

namespace dlslot::odometry {

class PointGrid {
 public:
  explicit PointGrid(double cell_m) : cell_(cell_m) {}
  // Indexes `cloud` (kept by reference: it must outlive the grid's use).
  void build(const FeatureCloud& cloud);
  // Indices into the cloud of the k points nearest to q with squared distance < max_d2, nearest
  // first (fewer when there are not k); d2 gets their squared distances.
  void nearest(const Eigen::Vector3f& q, int k, float max_d2, std::vector<int>& idx, std::vector<float>& d2) const;
  bool empty() const { return points_.empty(); }

 private:
  int64_t key(int64_t x, int64_t y, int64_t z) const;
  int64_t cellOf(float v) const;
  // Adds the points of cell (x, y, z) to the k best.
  void visit(int64_t x, int64_t y, int64_t z, const Eigen::Vector3f& q, int k, float max_d2, std::vector<int>& idx,
             std::vector<float>& d2) const;

  double cell_;
  Eigen::Matrix<int64_t, 3, 1> lo_, hi_;  // the cells' bounding box: shells are clipped to it
  BlockIndex cells_;                    // cell key -> cell number
  std::vector<int> start_;              // cell c holds points_[start_[c], start_[c + 1])
  std::vector<Eigen::Vector3f> points_; // grouped by cell
  std::vector<int> original_;           // their indices in the cloud
};

}  // namespace dlslot::odometry
