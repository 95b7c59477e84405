#include "solid.hpp"

#include <algorithm>
#include <cmath>
#include <array>
#include <limits>
#include <vector>

namespace dlslot::sim {

Solid Solid::box(const Eigen::Vector3d& center, const Eigen::Vector3d& size, double yaw, float reflectivity) {
  Solid s;
  s.kind = SolidKind::Box;
  s.center = center;
  s.half = 0.5 * size;
  s.cos_yaw = std::cos(yaw);
  s.sin_yaw = std::sin(yaw);
  s.reflectivity = reflectivity;
  return s;
}

Solid Solid::cylinder(const Eigen::Vector2d& axis, double z_lo, double z_hi, double radius, float reflectivity) {
  Solid s;
  s.kind = SolidKind::Cylinder;
  s.center = Eigen::Vector3d(axis.x(), axis.y(), 0.5 * (z_lo + z_hi));
  s.half = Eigen::Vector3d(radius, radius, 0.5 * (z_hi - z_lo));
  s.reflectivity = reflectivity;
  return s;
}

Solid Solid::sphere(const Eigen::Vector3d& center, double radius, float reflectivity) {
  Solid s;
  s.kind = SolidKind::Sphere;
  s.center = center;
  s.half = Eigen::Vector3d::Constant(radius);
  s.reflectivity = reflectivity;
  return s;
}

Solid Solid::wheel(const Eigen::Vector3d& center, double radius, double width, double yaw, float reflectivity) {
  Solid s;
  s.kind = SolidKind::Wheel;
  s.center = center;
  s.half = Eigen::Vector3d(radius, 0.5 * width, radius);
  s.cos_yaw = std::cos(yaw);
  s.sin_yaw = std::sin(yaw);
  s.reflectivity = reflectivity;
  return s;
}

namespace {

// A vector in the frame of a yawed solid: x along its heading, y to its left, z up.
Eigen::Vector3d toLocal(const Solid& s, const Eigen::Vector3d& v) {
  return {s.cos_yaw * v.x() + s.sin_yaw * v.y(), -s.sin_yaw * v.x() + s.cos_yaw * v.y(), v.z()};
}
Eigen::Vector3d fromLocal(const Solid& s, const Eigen::Vector3d& v) {
  return {s.cos_yaw * v.x() - s.sin_yaw * v.y(), s.sin_yaw * v.x() + s.cos_yaw * v.y(), v.z()};
}

// The ray (o, d), relative to the axis' mid point, against a cylinder of radius r along z from
// -hz to hz: its side and its two caps. Wheels use it with their axle as z.
bool intersectAxialCylinder(const Eigen::Vector3d& o, const Eigen::Vector3d& d, double r, double hz, double max_s,
                            double& s) {
  double best = max_s;
  const double a = d.x() * d.x() + d.y() * d.y();
  if (a > 1e-12) {  // the side
    const double bh = o.x() * d.x() + o.y() * d.y();
    const double cc = o.x() * o.x() + o.y() * o.y() - r * r;
    const double disc = bh * bh - a * cc;
    if (disc >= 0) {
      const double t = (-bh - std::sqrt(disc)) / a;
      if (t > 0 && t < best && std::abs(o.z() + t * d.z()) <= hz) best = t;
    }
  }
  if (std::abs(d.z()) > 1e-12) {  // the caps
    for (double cap : {hz, -hz}) {
      const double t = (cap - o.z()) / d.z();
      if (t > 0 && t < best) {
        const double px = o.x() + t * d.x(), py = o.y() + t * d.y();
        if (px * px + py * py <= r * r) best = t;
      }
    }
  }
  if (best >= max_s) return false;
  s = best;
  return true;
}

// The outward normal at p (relative to the axis' mid point) of that cylinder.
Eigen::Vector3d axialCylinderNormal(const Eigen::Vector3d& p, double hz) {
  if (std::abs(p.z()) >= hz - 1e-6) return Eigen::Vector3d(0, 0, p.z() > 0 ? 1.0 : -1.0);
  const double n = p.head<2>().norm();
  return n > 0 ? Eigen::Vector3d(p.x() / n, p.y() / n, 0.0) : Eigen::Vector3d::UnitX();
}

// A wheel's local frame with its axle (local y) as the third axis, and back: (x, z, y).
Eigen::Vector3d swapYZ(const Eigen::Vector3d& v) { return {v.x(), v.z(), v.y()}; }

bool intersectBox(const Solid& b, const Eigen::Vector3d& o, const Eigen::Vector3d& d, double max_s, double& s) {
  const double rx = o.x() - b.center.x(), ry = o.y() - b.center.y();
  const double lo[3] = {b.cos_yaw * rx + b.sin_yaw * ry, -b.sin_yaw * rx + b.cos_yaw * ry, o.z() - b.center.z()};
  const double ld[3] = {b.cos_yaw * d.x() + b.sin_yaw * d.y(), -b.sin_yaw * d.x() + b.cos_yaw * d.y(), d.z()};
  double t_in = -std::numeric_limits<double>::infinity(), t_out = std::numeric_limits<double>::infinity();
  for (int i = 0; i < 3; ++i) {
    if (std::abs(ld[i]) < 1e-12) {
      if (std::abs(lo[i]) > b.half[i]) return false;
      continue;
    }
    const double inv = 1.0 / ld[i];
    double t1 = (-b.half[i] - lo[i]) * inv, t2 = (b.half[i] - lo[i]) * inv;
    if (t1 > t2) std::swap(t1, t2);
    t_in = std::max(t_in, t1);
    t_out = std::min(t_out, t2);
    if (t_in > t_out) return false;
  }
  if (t_in <= 0 || t_in >= max_s) return false;
  s = t_in;
  return true;
}

bool intersectCylinder(const Solid& c, const Eigen::Vector3d& o, const Eigen::Vector3d& d, double max_s, double& s) {
  return intersectAxialCylinder(o - c.center, d, c.half.x(), c.half.z(), max_s, s);
}

bool intersectWheel(const Solid& w, const Eigen::Vector3d& o, const Eigen::Vector3d& d, double max_s, double& s) {
  return intersectAxialCylinder(swapYZ(toLocal(w, o - w.center)), swapYZ(toLocal(w, d)), w.half.x(), w.half.y(),
                                max_s, s);
}

bool intersectSphere(const Solid& sp, const Eigen::Vector3d& o, const Eigen::Vector3d& d, double max_s, double& s) {
  const Eigen::Vector3d oc = o - sp.center;
  const double bh = oc.dot(d), cc = oc.squaredNorm() - sp.half.x() * sp.half.x();
  const double disc = bh * bh - cc;
  if (disc < 0 || cc < 0) return false;
  const double t = -bh - std::sqrt(disc);
  if (t <= 0 || t >= max_s) return false;
  s = t;
  return true;
}

bool chordBox(const Solid& b, const Eigen::Vector3d& o, const Eigen::Vector3d& d, double& s_in, double& s_out) {
  const double rx = o.x() - b.center.x(), ry = o.y() - b.center.y();
  const double lo[3] = {b.cos_yaw * rx + b.sin_yaw * ry, -b.sin_yaw * rx + b.cos_yaw * ry, o.z() - b.center.z()};
  const double ld[3] = {b.cos_yaw * d.x() + b.sin_yaw * d.y(), -b.sin_yaw * d.x() + b.cos_yaw * d.y(), d.z()};
  s_in = -std::numeric_limits<double>::infinity();
  s_out = std::numeric_limits<double>::infinity();
  for (int i = 0; i < 3; ++i) {
    if (std::abs(ld[i]) < 1e-12) {
      if (std::abs(lo[i]) > b.half[i]) return false;
      continue;
    }
    double t1 = (-b.half[i] - lo[i]) / ld[i], t2 = (b.half[i] - lo[i]) / ld[i];
    if (t1 > t2) std::swap(t1, t2);
    s_in = std::max(s_in, t1);
    s_out = std::min(s_out, t2);
    if (s_in > s_out) return false;
  }
  return s_out > 0;
}

bool chordSphere(const Solid& sp, const Eigen::Vector3d& o, const Eigen::Vector3d& d, double& s_in, double& s_out) {
  const Eigen::Vector3d oc = o - sp.center;
  const double bh = oc.dot(d), cc = oc.squaredNorm() - sp.half.x() * sp.half.x();
  const double disc = bh * bh - cc;
  if (disc < 0) return false;
  s_in = -bh - std::sqrt(disc);
  s_out = -bh + std::sqrt(disc);
  return s_out > 0;
}

// Footprint as a polygon (boxes) or a circle, for separating-axis tests in the plane.
struct Footprint {
  bool circle = false;
  Eigen::Vector2d c;
  double r = 0;
  std::array<Eigen::Vector2d, 4> corners;
  std::array<Eigen::Vector2d, 2> axes;
};

Footprint footprintOf(const Solid& s, double grow) {
  Footprint f;
  f.c = s.center.head<2>();
  if (s.kind != SolidKind::Box && s.kind != SolidKind::Wheel) {
    f.circle = true;
    f.r = s.half.x() + grow;
    return f;
  }
  const Eigen::Vector2d ax(s.cos_yaw, s.sin_yaw), ay(-s.sin_yaw, s.cos_yaw);
  const double hx = s.half.x() + grow, hy = s.half.y() + grow;
  f.axes = {ax, ay};
  f.corners = {f.c + hx * ax + hy * ay, f.c + hx * ax - hy * ay, f.c - hx * ax - hy * ay, f.c - hx * ax + hy * ay};
  return f;
}

void project(const Footprint& f, const Eigen::Vector2d& axis, double& lo, double& hi) {
  if (f.circle) {
    const double m = f.c.dot(axis);
    lo = m - f.r;
    hi = m + f.r;
    return;
  }
  lo = hi = f.corners[0].dot(axis);
  for (int i = 1; i < 4; ++i) {
    const double v = f.corners[i].dot(axis);
    lo = std::min(lo, v);
    hi = std::max(hi, v);
  }
}

}  // namespace

bool intersect(const Solid& solid, const Eigen::Vector3d& o, const Eigen::Vector3d& d, double max_s, double& s) {
  switch (solid.kind) {
    case SolidKind::Box:
      return intersectBox(solid, o, d, max_s, s);
    case SolidKind::Cylinder:
      return intersectCylinder(solid, o, d, max_s, s);
    case SolidKind::Sphere:
      return intersectSphere(solid, o, d, max_s, s);
    case SolidKind::Wheel:
      return intersectWheel(solid, o, d, max_s, s);
  }
  return false;
}

Eigen::Vector3d normalAt(const Solid& solid, const Eigen::Vector3d& p) {
  const Eigen::Vector3d r = p - solid.center;
  switch (solid.kind) {
    case SolidKind::Box: {
      const Eigen::Vector3d local = toLocal(solid, r);
      int axis = 0;
      double best = -1;
      for (int i = 0; i < 3; ++i) {
        const double v = std::abs(local[i]) / solid.half[i];
        if (v > best) {
          best = v;
          axis = i;
        }
      }
      Eigen::Vector3d n_local = Eigen::Vector3d::Zero();
      n_local[axis] = local[axis] >= 0 ? 1.0 : -1.0;
      return fromLocal(solid, n_local);
    }
    case SolidKind::Cylinder:
      return axialCylinderNormal(r, solid.half.z());
    case SolidKind::Wheel:
      return fromLocal(solid, swapYZ(axialCylinderNormal(swapYZ(toLocal(solid, r)), solid.half.y())));
    case SolidKind::Sphere: {
      const double n = r.norm();
      return n > 0 ? Eigen::Vector3d(r / n) : Eigen::Vector3d::UnitZ();
    }
  }
  return Eigen::Vector3d::UnitZ();
}

bool chord(const Solid& solid, const Eigen::Vector3d& o, const Eigen::Vector3d& d, double& s_in, double& s_out) {
  switch (solid.kind) {
    case SolidKind::Box: return chordBox(solid, o, d, s_in, s_out);
    case SolidKind::Sphere: return chordSphere(solid, o, d, s_in, s_out);
    case SolidKind::Cylinder:
    case SolidKind::Wheel: return false;
  }
  return false;
}

bool intersectPorous(const Solid& solid, const Eigen::Vector3d& o, const Eigen::Vector3d& d, double max_s, double u,
                     double& s) {
  if (solid.mean_free_path <= 0) return intersect(solid, o, d, max_s, s);
  double s_in, s_out;
  if (!chord(solid, o, d, s_in, s_out) || s_in <= 0) return false;  // like intersect(): not from inside
  const double hit = s_in - solid.mean_free_path * std::log(1.0 - u);
  if (hit >= s_out || hit >= max_s) return false;
  s = hit;
  return true;
}

bool overlaps(const Solid& a, const Solid& b, double margin) {
  if (a.zMax() < b.zMin() || b.zMax() < a.zMin()) return false;
  const Footprint fa = footprintOf(a, margin), fb = footprintOf(b, 0.0);
  if ((fa.c - fb.c).norm() > a.radiusXY() + b.radiusXY() + 1.5 * margin) return false;
  if (fa.circle && fb.circle) return (fa.c - fb.c).norm() <= fa.r + fb.r;
  // Separating axes: the boxes' edge normals, and for a circle the direction to the nearest corner.
  std::vector<Eigen::Vector2d> axes;
  for (const Footprint* f : {&fa, &fb})
    if (!f->circle) axes.insert(axes.end(), f->axes.begin(), f->axes.end());
  for (const Footprint* f : {&fa, &fb}) {
    if (!f->circle) continue;
    const Footprint& other = f == &fa ? fb : fa;
    Eigen::Vector2d nearest = other.corners[0];
    for (const auto& c : other.corners)
      if ((c - f->c).squaredNorm() < (nearest - f->c).squaredNorm()) nearest = c;
    if ((nearest - f->c).norm() > 1e-9) axes.push_back((nearest - f->c).normalized());
  }
  for (const Eigen::Vector2d& axis : axes) {
    double alo, ahi, blo, bhi;
    project(fa, axis, alo, ahi);
    project(fb, axis, blo, bhi);
    if (ahi < blo || bhi < alo) return false;
  }
  return true;
}

}  // namespace dlslot::sim
