// Reading and writing the KITTI tracking and odometry formats (design brief section 3-4).
// Every reader throws InputError naming the file, the line and what was expected.
#pragma once

#include <array>
#include <optional>
#include <string>
#include <vector>

#include "dlslot/types.hpp"

namespace dlslot::kitti {

// Calibration of one sequence. Accepts both key spellings (R_rect / R0_rect, Tr_velo_cam /
// Tr_velo_to_cam, Tr_imu_velo / Tr_imu_to_velo), with or without a colon.
struct Calib {
  Eigen::Matrix3d R_rect = Eigen::Matrix3d::Identity();
  Pose T_cam_velo = Pose::Identity();              // Tr_velo_cam: velodyne -> camera 0
  std::optional<Pose> T_velo_imu;                  // Tr_imu_velo: imu -> velodyne
  using Projection = Eigen::Matrix<double, 3, 4>;
  std::array<Projection, 4> P = {Projection::Zero(), Projection::Zero(), Projection::Zero(),
                                 Projection::Zero()};  // P0..P3 (zero when absent)

  // Rectified camera frame <- velodyne: p_rect = R_rect * T_cam_velo * p_velo.
  Pose T_rect_velo() const;
};
Calib readCalib(const std::string& path);
void writeCalib(const std::string& path, const Calib& calib);  // KITTI tracking spelling, no colon

// One velodyne scan (.bin: float32 x y z reflectance). Throws on a size that is not a multiple
// of 16 bytes and on NaN or infinite values.
PointCloud readVelodyne(const std::string& path);
void writeVelodyne(const std::string& path, const PointCloud& scan);

// A box as KITTI writes it: rectified camera frame, bottom centre, (h, w, l), rotation_y.
struct CameraBox {
  double h = 0, w = 0, l = 0;
  Eigen::Vector3d bottom_center = Eigen::Vector3d::Zero();
  double rotation_y = 0;
};
// p_velo = inv(T_rect_velo) * p_rect, z += h/2, yaw = -(rotation_y + pi/2), (h,w,l) -> (l,w,h).
Box cameraToLidar(const CameraBox& cam, const Calib& calib);
CameraBox lidarToCamera(const Box& box, const Calib& calib);

// One row of label_02/SSSS.txt, or of a detection file in the tracking format (+ score column).
struct LabelRow {
  int frame = 0;
  int track_id = -1;
  std::string type;
  double truncated = 0;
  int occluded = 0;
  double alpha = 0;
  Eigen::Vector4d bbox2d = Eigen::Vector4d::Zero();  // left top right bottom, pixels
  CameraBox box;
  std::optional<double> score;
};
std::vector<LabelRow> readTrackingLabels(const std::string& path);  // 17 or 18 fields a line
void writeTrackingLabels(const std::string& path, const std::vector<LabelRow>& rows);

// The left colour camera's image (image_02), where KITTI scores results; most tracking sequences
// are 1242 x 375 (a few are 1224 x 370 or 1238 x 374).
struct ImageSize {
  double width = 1242, height = 375;
};
// Where a box appears in image_02: what a KITTI results row needs besides the 3-D box.
struct ImageBox {
  Eigen::Vector4d bbox2d = Eigen::Vector4d::Zero();     // left top right bottom, clipped to [0, w-1] x [0, h-1]
  Eigen::Vector4d unclipped = Eigen::Vector4d::Zero();  // the same before clipping to the image
  double alpha = 0;  // observationAngle()
};
// KITTI's alpha: rotation_y - atan2(x, z) of the box position, wrapped to (-pi, pi].
double observationAngle(const CameraBox& box);
// The 8 corners projected with P2 (the edges cut at a near plane 0.1 m in front of the camera, so
// a box partly behind it gets the image of its visible part). nullopt when the box is not in the
// image: all of it behind the camera, or its projection entirely outside. Throws
// std::invalid_argument when the calibration has no P2.
std::optional<ImageBox> projectToImage(const CameraBox& box, const Calib& calib, const ImageSize& image = {});
// One KITTI tracking results row for a box in the lidar frame: frame, track id (box.id), type,
// truncated 0, occluded 0, alpha, 2-D box, the camera box, score (box.score). nullopt when the box
// is not in the image: the devkit scores only what the camera sees, so such rows must not be written.
std::optional<LabelRow> resultRow(int frame, const Box& box_lidar, const Calib& calib, const ImageSize& image = {});
// The same row without its image fields (2-D box -1, alpha -10, the devkit's "unknown"), for a box
// the camera does not see: what a results file for labels all around the scan holds there.
LabelRow unprojectedRow(int frame, const Box& box_lidar, const Calib& calib);
// The same for a row whose 3-D box is already in the camera frame: fills bbox2d and alpha from row.box.
std::optional<LabelRow> resultRow(LabelRow row, const Calib& calib, const ImageSize& image = {});

// The comma-separated detection format: frame,type,x1,y1,x2,y2,score,h,w,l,x,y,z,rot_y,alpha
// with type 1 Pedestrian, 2 Car, 3 Cyclist.
std::vector<LabelRow> readCsvDetections(const std::string& path);
// A detection file of either format (tracking format with a score column, or comma-separated),
// told apart by its first line.
std::vector<LabelRow> readDetectionRows(const std::string& path);

// Groups rows by frame, converted to the lidar frame. DontCare rows go to `dontcare` when given
// (else dropped); rows with score < min_score are dropped (rows without score are kept).
struct FrameBoxes {
  std::vector<Box> boxes;
  std::vector<Box> dontcare;
};
std::vector<FrameBoxes> boxesByFrame(const std::vector<LabelRow>& rows, const Calib& calib, int num_frames,
                                     double min_score = -1e300);

// One oxts line: 30 numbers (lat lon alt roll pitch yaw vn ve vf vl vu ax ay az af al au wx wy wz
// wf wl wu posacc velacc navstat numsats posmode velmode orimode).
using OxtsRecord = std::array<double, 30>;
std::vector<OxtsRecord> readOxts(const std::string& path);
void writeOxts(const std::string& path, const std::vector<OxtsRecord>& rows);
// Ego lidar poses T_world_lidar from oxts (Mercator with scale cos(lat0), T_w_imu = [Rz Ry Rx | t],
// T_w_velo = T_w_imu * inv(T_velo_imu)), re-based so the first frame is the identity.
std::vector<Pose> oxtsToLidarPoses(const std::vector<OxtsRecord>& rows, const Pose& T_velo_imu);
// The inverse for the simulator: oxts records (lat, lon, alt, roll, pitch, yaw; other fields 0)
// whose oxtsToLidarPoses() gives back `poses`, for a chosen origin latitude/longitude.
std::vector<OxtsRecord> lidarPosesToOxts(const std::vector<Pose>& poses, const Pose& T_velo_imu,
                                         double lat0_deg, double lon0_deg, double alt0);

// KITTI 3x4 row-major pose files (one pose a line), and KITTI odometry times.txt (seconds).
std::vector<Pose> readPoses(const std::string& path);
void writePoses(const std::string& path, const std::vector<Pose>& poses);
std::vector<double> readTimes(const std::string& path);

// Where a sequence's files are. `root` is a KITTI tracking root (holding training/) or an
// odometry root (holding sequences/); which one is detected from what exists.
struct SequencePaths {
  enum class Layout { Tracking, Odometry } layout = Layout::Tracking;
  std::string velodyne_dir;     // "" for a tracking sequence without scans (labels, calib, detections only)
  std::string calib;            // calib file
  std::string labels;           // label_02 file ("" when absent)
  std::string oxts;             // "" when absent
  std::string poses;            // "" when absent
  bool poses_are_lidar = false; // tracking layout training/poses/SSSS.txt (simulator): T_world_lidar;
                                // odometry layout poses/XX.txt: T_world_cam0 (converted with the calib)
  std::string times;            // odometry times.txt ("" when absent)
  int num_frames = 0;           // number of .bin files (must be 000000..N-1); without scans, set by SequenceReader
};
SequencePaths locateSequence(const std::string& root, const std::string& sequence);

// The class-compatibility rule of the KITTI tracking devkit: Car matches Van, Pedestrian
// matches Person_sitting; else the names must be equal.
bool classesCompatible(const std::string& a, const std::string& b);

}  // namespace dlslot::kitti

namespace dlslot::kitti {

// Reads a whole sequence frame by frame: scans, detections (lidar frame), labels, ground-truth
// ego poses. The player, the offline tools and tests all read data through this one class.
class SequenceReader {
 public:
  // detection_paths: files in the tracking format (+score) or the comma-separated per-class
  // format, or directories holding SSSS.txt; the format is detected from the content.
  SequenceReader(const std::string& root, const std::string& sequence,
                 const std::vector<std::string>& detection_paths = {}, double min_detection_score = -1e300,
                 double frame_period_s = 0.1);
  int size() const { return paths_.num_frames; }
  // False for a tracking sequence with labels/detections but no velodyne/: its frames have empty
  // scans and it has as many frames as its labels and detections reach.
  bool hasScans() const { return !paths_.velodyne_dir.empty(); }
  const SequencePaths& paths() const { return paths_; }
  const Calib& calib() const { return calib_; }
  bool hasGroundTruthPoses() const { return !gt_poses_.empty(); }
  bool hasLabels() const { return !labels_.empty(); }
  const std::vector<Pose>& groundTruthPoses() const { return gt_poses_; }
  Frame read(int index) const;  // throws InputError for a bad .bin

 private:
  SequencePaths paths_;
  Calib calib_;
  std::vector<Pose> gt_poses_;
  std::vector<FrameBoxes> labels_, detections_;
  std::vector<double> times_;
  double frame_period_s_;
};

}  // namespace dlslot::kitti
