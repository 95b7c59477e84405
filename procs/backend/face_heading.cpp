#include "backend/face_heading.hpp"

#include <Eigen/Dense>
#include <algorithm>
#include <cmath>
#include <vector>

namespace dlslot::backend {
namespace {

double wrapAngle(double a) { return std::remainder(a, 2.0 * M_PI); }

// The q-quantile of v (v reordered).
double quantile(std::vector<double>& v, double q) {
  const auto k = static_cast<std::ptrdiff_t>(q * static_cast<double>(v.size() - 1));
  std::nth_element(v.begin(), v.begin() + k, v.end());
  return v[k];
}

}  // namespace

std::optional<FaceHeading> faceHeading(const ObjectPoints& points, const Box& box, const Eigen::Vector3d& sensor,
                                       const FaceHeadingOptions& o) {
  const Eigen::Vector2d c = box.center.head<2>();
  const double hl = 0.5 * box.size.x(), hw = 0.5 * box.size.y();
  const double cb = std::cos(box.yaw), sb = std::sin(box.yaw);
  const auto inBox = [&](const Eigen::Vector2d& d) {
    return Eigen::Vector2d(cb * d.x() + sb * d.y(), -sb * d.x() + cb * d.y());
  };
  // The sides turned towards the sensor: the box's end (x) and side (y) faces, by where the sensor
  // is in the box's axes. Inside the footprint on both axes it sees no face at all.
  const Eigen::Vector2d s = inBox(sensor.head<2>() - c);
  const int end = s.x() > hl ? 1 : s.x() < -hl ? -1 : 0;
  const int side = s.y() > hw ? 1 : s.y() < -hw ? -1 : 0;
  if (end == 0 && side == 0) return std::nullopt;

  const double z_low = box.center.z() + (o.low_cut - 0.5) * box.size.z();
  const double z_high = box.center.z() + (o.high_cut - 0.5) * box.size.z();
  std::vector<Eigen::Vector2d> q;  // horizontal, from the box's centre (world axes)
  q.reserve(points.size());
  for (const Eigen::Vector3f& p : points) {
    if (p.z() < z_low || p.z() > z_high) continue;
    const Eigen::Vector2d d = p.head<2>().cast<double>() - c;
    const Eigen::Vector2d l = inBox(d);
    if (std::abs(l.x()) <= hl + o.margin && std::abs(l.y()) <= hw + o.margin) q.push_back(d);
  }
  if (static_cast<int>(q.size()) < o.min_points) return std::nullopt;

  // Unknowns: the heading theta and the offsets of the visible faces along their normals,
  // n1 = (cos, sin) for the end face (n1 . q = a), n2 = (-sin, cos) for the side face (n2 . q = b).
  double theta = box.yaw;
  double a = 0, b = 0;
  {
    // The faces' offsets from the points: the outer tail on the sensor's side, which a
    // neighbour's stray point or the far side's few returns do not move.
    std::vector<double> u1, u2;
    for (const Eigen::Vector2d& d : q) {
      const Eigen::Vector2d l = inBox(d);
      u1.push_back(l.x());
      u2.push_back(l.y());
    }
    if (end != 0) a = quantile(u1, end > 0 ? 0.9 : 0.1);
    if (side != 0) b = quantile(u2, side > 0 ? 0.9 : 0.1);
  }
  bool use_end = end != 0, use_side = side != 0;
  int on_faces = 0;
  Eigen::Matrix3d H = Eigen::Matrix3d::Zero();
  double sigma2 = 0;
  for (int it = 0; it < o.iterations; ++it) {
    const Eigen::Vector2d n1(std::cos(theta), std::sin(theta)), n2(-std::sin(theta), std::cos(theta));
    H.setZero();
    Eigen::Vector3d g = Eigen::Vector3d::Zero();
    double wrr = 0, wsum = 0;
    double lo[2] = {1e9, 1e9}, hi[2] = {-1e9, -1e9};  // each face's span along itself
    on_faces = 0;
    for (const Eigen::Vector2d& d : q) {
      const double u1 = n1.dot(d), u2 = n2.dot(d);
      const double r1 = u1 - a, r2 = u2 - b;
      // The face the point is nearer to, of those used.
      const bool on_end = use_end && (!use_side || std::abs(r1) <= std::abs(r2));
      const double r = on_end ? r1 : r2;
      Eigen::Vector3d J = on_end ? Eigen::Vector3d(u2, -1, 0) : Eigen::Vector3d(-u1, 0, -1);
      const double w = 1.0 / (1.0 + (r / o.cauchy_scale) * (r / o.cauchy_scale));
      H += w * J * J.transpose();
      g += w * J * r;
      wrr += w * r * r;
      wsum += w;
      if (std::abs(r) < 3 * o.cauchy_scale) {
        ++on_faces;
        const int k = on_end ? 0 : 1;
        const double along = on_end ? u2 : u1;
        lo[k] = std::min(lo[k], along);
        hi[k] = std::max(hi[k], along);
      }
    }
    sigma2 = std::max(o.point_sigma * o.point_sigma, wrr / std::max(wsum, 1e-9));
    // A face whose points span too little says nothing of the heading; the other one alone may.
    const bool end_ok = use_end && hi[0] - lo[0] >= o.min_face_span;
    const bool side_ok = use_side && hi[1] - lo[1] >= o.min_face_span;
    if (!end_ok && !side_ok) return std::nullopt;
    if (end_ok != use_end || side_ok != use_side) {
      use_end = end_ok;
      use_side = side_ok;
      continue;
    }
    // An unused face's offset is held: its row and column become the identity.
    if (!use_end) H.row(1).setZero(), H.col(1).setZero(), H(1, 1) = 1, g[1] = 0;
    if (!use_side) H.row(2).setZero(), H.col(2).setZero(), H(2, 2) = 1, g[2] = 0;
    const Eigen::Vector3d step = H.ldlt().solve(-g);
    if (!step.allFinite()) return std::nullopt;
    theta += std::clamp(step[0], -0.05, 0.05);
    a += step[1];
    b += step[2];
  }
  if (on_faces < o.min_points || std::abs(wrapAngle(theta - box.yaw)) > o.max_turn_rad) return std::nullopt;
  // The heading's information with the offsets eliminated (Schur complement), over the residuals'
  // variance and shrunk for correlated neighbours.
  const double h00 = H(0, 0) - H.block<1, 2>(0, 1) * H.block<2, 2>(1, 1).inverse() * H.block<2, 1>(1, 0);
  if (!(h00 > 0)) return std::nullopt;
  const double variance = sigma2 / (o.information_scale * h00) + o.accuracy_rad * o.accuracy_rad;
  const double sigma = std::sqrt(variance);
  if (!(sigma <= o.max_sigma_rad)) return std::nullopt;  // NaN too
  FaceHeading f;
  f.yaw = box.yaw + wrapAngle(theta - box.yaw);
  f.sigma = sigma;
  f.points = on_faces;
  f.faces = int(use_end) + int(use_side);
  return f;
}

}  // namespace dlslot::backend
