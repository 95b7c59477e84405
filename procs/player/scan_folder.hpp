// Your own recordings in: a folder of scans (PCL .pcd or KITTI-style .bin), their times, an
// optional ground-truth trajectory, and a YAML calibration describing the sensor.
//
//   DIR/000000.pcd ...      scans, in file-name order (or .bin: float32 x y z intensity)
//   DIR/times.txt           one time in seconds per scan; without it the file names must be
//                           timestamps (1650000000.123456.pcd in seconds, or integers of 13/16/19
//                           digits in milliseconds/microseconds/nanoseconds)
//   DIR/poses.txt           optional: the VEHICLE's ground-truth poses, KITTI 3x4 rows, one per scan
//   calib.yaml              the sensor (format in docs/data-formats.md):
//     sensor_to_vehicle: {translation: [x, y, z], rotation_rpy_deg: [roll, pitch, yaw]}
//     beams: {model: estimate}                                  (from the first scan), or
//     beams: {model: uniform, count: 32, elevation_deg: [10.67, -30.67]}   (top, bottom), or
//     beams: {model: hdl64}
//     range_m: [min, max]   points outside (horizontal range) are dropped before publishing
//     camera_calib: FILE    optional: KITTI calib for detection files in camera coordinates
//
// Scans stay in the sensor frame: the odometry follows each beam's ring, which a tilted
// mounting would bend. The extrinsics turn the vehicle's ground truth into the sensor's:
// T_world_sensor = inv(T_vehicle_sensor) * T_world_vehicle * T_vehicle_sensor (re-based).
#pragma once

#include <optional>
#include <string>
#include <vector>

#include "dlslot/kitti.hpp"
#include "dlslot/types.hpp"

namespace dlslot::player {

struct SensorCalibration {
  std::string path;                    // where it was read from
  Pose T_vehicle_sensor = Pose::Identity();
  std::string beam_model = "estimate";  // estimate | uniform | hdl64
  int beams = 0;                        // uniform: count, top and bottom elevations
  double top_elevation_deg = 0, bottom_elevation_deg = 0;
  double min_range_m = 0, max_range_m = 1e9;
  double vertical_angle_error_deg = 0;  // how far below its ray the sensor stores each point
  std::string camera_calib;             // absolute, or empty
};

// Throws InputError naming the file and the key for anything missing, unknown or out of range.
SensorCalibration readSensorCalibration(const std::string& path);

struct ScanFolder {
  std::string dir;
  std::vector<std::string> files;  // scan files in play order
  std::vector<double> times;       // seconds, one per scan
  std::vector<Pose> gt_poses;      // T_world_sensor per scan (empty without poses.txt)
};

// Lists and checks the folder (see the top of this file); throws InputError naming the file.
ScanFolder openScanFolder(const std::string& dir, const SensorCalibration& calib);

// One scan in the sensor frame: .pcd through PCL (x y z, and intensity when the file has it,
// else 0) or KITTI .bin. Throws InputError naming the file.
PointCloud readScanFile(const std::string& path);

// The points the pipeline gets: finite, within the calibration's horizontal range limits.
PointCloud limitRange(const PointCloud& scan, const SensorCalibration& calib);

// The beam layout seen in a scan of a spinning lidar: each beam sweeps one elevation, so the
// elevations of the points bunch around the beams' angles. Found as the peaks of an elevation
// histogram (0.05 deg bins, smoothed over 3); a peak needs a 2000th of the scan's points, so
// stray returns between rings do not make beams.
struct BeamLayout {
  int beams = 0;
  double top_elevation_deg = 0, bottom_elevation_deg = 0;
  bool uniform = false;  // the angles lie on a line over the beam index within a quarter gap (RMS)
};
BeamLayout estimateBeams(const PointCloud& scan);

// The frames of a folder as the player plays them (scans read on demand).
class FolderReader {
 public:
  // detection_paths: files in the existing formats (need calib.camera_calib: they are in camera
  // coordinates); scores below min_detection_score dropped.
  FolderReader(const std::string& dir, const SensorCalibration& calib,
               const std::vector<std::string>& detection_paths = {}, double min_detection_score = -1e300);
  int size() const { return static_cast<int>(folder_.files.size()); }
  const ScanFolder& folder() const { return folder_; }
  Frame read(int index) const;

 private:
  SensorCalibration calib_;
  ScanFolder folder_;
  std::vector<kitti::FrameBoxes> detections_;
};

}  // namespace dlslot::player
