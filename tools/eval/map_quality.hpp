// The static map's quality in the dynamic-map benchmark's terms (Zhang, Khoche, Lilja et al., "A
// Dynamic Points Removal Benchmark in Point Cloud Maps", ITSC 2023: KTH DynamicMap_Benchmark),
// counted on a voxel grid: the points of the keyframe scans the map was built from, placed with
// the map's own keyframe poses, are labelled dynamic (inside the labelled box of an object whose
// labelled track moves) or static (everything else); a voxel takes the label of the majority of
// its points. A point is tested against the box where the object was when the lidar fired at it
// (sweep_timing.hpp): the labels are for the instant the sweep faces ahead, the points are not. SA
// is the share of static voxels the map keeps, DA the share of dynamic voxels it does not hold,
// AA = sqrt(SA x DA). The voxels are those of the grid the map counted its points on: each
// keyframe's points placed with the pose it was inserted with (MapKeyframe::T_grid_lidar), and a
// voxel is held when one of its points is in the map (the map keeps, per voxel, one point of the
// keyframes' scans, moved with its keyframe by any loop correction). Without a loop that is the
// map's own grid and the test is "the map has a point in the voxel"; after one, a sub-voxel shift
// of the map would otherwise spread the dense truth of one voxel over up to 8 voxels of the moved
// grid while its one map point lands in one of them, and SA would count the others as lost
// structure (urban-loop: 0.71 where the map had lost none).
#pragma once

#include <map>
#include <optional>
#include <set>
#include <string>
#include <vector>

#include "dlslot/sweep_timing.hpp"
#include "dlslot/types.hpp"

namespace dlslot::eval {

struct MapTruthOptions {
  double voxel_m = 0.2;
  double min_range_m = 2.5, max_range_m = 50.0;  // the mapper's range: points it never looked at are not scored
  // A labelled track moves when its box centres, in the world, span more than this (box noise of
  // labels is ~0.1-0.3 m; a parked car spans less, a car that drives off spans metres).
  double moving_span_m = 1.0;
  // The lowest band of a box is where its wheels meet the road: neither static nor dynamic, not scored.
  double bottom_band_m = 0.1;
  // A labelled box is tight on the object's surface, so sensor noise puts about half of the points
  // on its faces outside it: a point within this much outside a moving object's box (sides and
  // top; below it is the road) is the object's. 0.1 m: 3 sigma of the range noise at 30 m (2 cm +
  // 2 cm per 100 m, with the footprint term at 60 deg incidence) plus the beams' angle residuals.
  double label_tolerance_m = 0.1;
  // A map point is one of the truth's points (the mapper keeps a point of its keyframe's scan)
  // when they lie within this distance: the files' rounding (9 digits, float coordinates), far
  // below the spacing of a scan's points.
  double coincidence_m = 0.002;
  // Real KITTI labels cover what the camera sees: score only points in front of the camera within
  // its horizontal field of view (set from the calibration; empty = all around, the simulator's labels).
  std::optional<Pose> T_cam_lidar;
  double camera_half_fov_rad = 0.0;
  // The scans' firing order (period 0: de-skewed scans, every point tested against the t = 0 box).
  SweepTiming sweep;
};

// One keyframe: its scan (lidar frame), its pose in the map, the labelled boxes of its scan.
struct MapKeyframe {
  int frame = 0;
  PointCloud scan;
  Pose T_map_lidar = Pose::Identity();
  // The pose its points were inserted into the map with (the grid they were counted on); unset:
  // T_map_lidar (a map without loop corrections).
  std::optional<Pose> T_grid_lidar;
  // Lidar frame, box.id = labelled track id, with the box's motion relative to the lidar (from the
  // labels of the scans before and after; zero when the track is seen in one scan only).
  std::vector<MovingBox> labels;
  // DontCare boxes (lidar frame): objects too thinly seen to be labelled; their points are not
  // scored (KITTI's protocol for DontCare), whether the object moves is unknown.
  std::vector<Box> dontcare;
};

// The labels of scan `frame` with their motion relative to the lidar, from the same tracks' labels
// in the neighbouring scans (dt seconds apart; the central difference where both exist).
std::vector<MovingBox> movingLabels(const std::map<int, std::vector<Box>>& labels_by_frame, int frame, double dt);

struct MapScore {
  double voxel_m = 0;
  int64_t static_voxels = 0, dynamic_voxels = 0, static_kept = 0, dynamic_removed = 0;
  std::optional<double> sa, da, aa;
};

// Track ids whose centres (labels of each frame put in the world with `poses`) span > moving_span_m.
std::set<int> movingTracks(const std::map<int, std::vector<Box>>& labels_by_frame, const std::map<int, Pose>& poses,
                           double moving_span_m);

// map_points: the map's points (map frame, x y z columns).
MapScore scoreMap(const PointCloud& map_points, const std::vector<MapKeyframe>& keyframes, const std::set<int>& moving,
                  const MapTruthOptions& options);

// An accepted loop is false when its relative pose is more than 1 m or 2 deg off the truth's.
bool isFalseLoop(const Pose& measured_T_match_query, const Pose& truth_T_match_query, double max_m = 1.0,
                 double max_deg = 2.0);

}  // namespace dlslot::eval
