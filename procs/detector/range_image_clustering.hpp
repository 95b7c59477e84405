// Clustering of the obstacle points in the range image: each point is a pixel (azimuth column,
// elevation row), and two points are neighbours when their pixels are at most neighbour_rows x
// neighbour_columns apart and the points themselves closer than max(distance_m, distance_per_m x
// range). Connected components of that relation are the clusters.
//
// Chosen over PCL's EuclideanClusterExtraction (k-d tree radius search) because it is faster on
// the same points: on the real KITTI scans (kitti-tracking-0000-head, ~123k points, ~45k obstacle
// points) bench/detector_bench.cpp measured the numbers quoted in docs/detector.md.
// The neighbourhood comes from the scan's own structure, so no tree is built.
#pragma once

#include <vector>

#include "detector/detector_config.hpp"
#include "detector/scan_layout.hpp"

namespace dlslot::detector {

// The clusters (indices into the scan), each with at least min_points points; points that share
// a pixel with a nearer one join that point's cluster when close enough to it.
std::vector<std::vector<int>> clusterRangeImage(const PointCloud& scan, const ScanLayout& layout,
                                                const std::vector<uint8_t>& obstacle, const ClusteringConfig& cfg);

// Joins clusters of one object the range image split: a car's roof seen from above the car is hit
// by successive beams metres apart along the ray, so its far part is no pixel neighbour of the
// rest. Two clusters whose bird's-eye bounding boxes overlap (grown by margin_m) become one when
// the joined box stays object-sized (diagonal <= max_diagonal_m), so walls swallow nothing.
// Clusters below min_points are dropped after joining.
std::vector<std::vector<int>> joinOverlappingClusters(const PointCloud& scan, std::vector<std::vector<int>> clusters,
                                                      double margin_m, double max_diagonal_m, int min_points);

}  // namespace dlslot::detector
