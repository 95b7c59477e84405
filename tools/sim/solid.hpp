// The solids the world is made of: upright boxes (yaw only), vertical cylinders, spheres and
// wheels (cylinders lying across a heading), with a surface reflectivity. Buildings, poles, trees and every object are built from these.
#pragma once

#include <Eigen/Core>
#include <cmath>
#include <cstdint>

namespace dlslot::sim {

enum class SolidKind : uint8_t { Box, Cylinder, Sphere, Wheel };

struct Solid {
  SolidKind kind = SolidKind::Box;
  Eigen::Vector3d center = Eigen::Vector3d::Zero();  // cylinder: axis point at mid height
  Eigen::Vector3d half = Eigen::Vector3d::Zero();    // box: half extents along its heading, left, up;
                                                     // cylinder: (r, r, half height); sphere: (r, r, r);
                                                     // wheel: (r, half width, r)
  double cos_yaw = 1.0, sin_yaw = 0.0;               // boxes and wheels (a wheel's axle is across it)
  float reflectivity = 0.2f;                         // KITTI-like reflectance of the surface, 0..1
  float mean_free_path = 0.0f;                       // > 0: porous (foliage, wire fence), see intersectPorous
  int owner = -1;                                    // what it belongs to (an object, a static structure)

  static Solid box(const Eigen::Vector3d& center, const Eigen::Vector3d& size, double yaw, float reflectivity);
  static Solid cylinder(const Eigen::Vector2d& axis, double z_lo, double z_hi, double radius, float reflectivity);
  static Solid sphere(const Eigen::Vector3d& center, double radius, float reflectivity);
  // A cylinder whose axis lies horizontal, across the heading `yaw` (a wheel rolling along it).
  static Solid wheel(const Eigen::Vector3d& center, double radius, double width, double yaw, float reflectivity);

  double zMin() const { return center.z() - half.z(); }
  double zMax() const { return center.z() + half.z(); }
  double radiusXY() const {
    return kind == SolidKind::Box || kind == SolidKind::Wheel ? std::hypot(half.x(), half.y()) : half.x();
  }
};

// Distance along the unit ray (o, d) to the solid's surface if it is hit in (0, max_s); rays
// starting inside a solid do not hit it.
bool intersect(const Solid& solid, const Eigen::Vector3d& o, const Eigen::Vector3d& d, double max_s, double& s);
// Where the unit ray (o, d) enters and leaves the solid (s_in may be <= 0 when o is inside); boxes
// and spheres only (cylinders and wheels: false).
bool chord(const Solid& solid, const Eigen::Vector3d& o, const Eigen::Vector3d& d, double& s_in, double& s_out);
// A porous solid stops the ray an exponential depth of mean `mean_free_path` after it enters,
// -mean_free_path * ln(1 - u) with u uniform in [0, 1) (one draw per ray and solid), if that is
// before it leaves and before max_s; otherwise the ray passes through. Opaque solids: intersect().
bool intersectPorous(const Solid& solid, const Eigen::Vector3d& o, const Eigen::Vector3d& d, double max_s, double u,
                     double& s);
// Outward unit normal of the surface at (or next to) p.
Eigen::Vector3d normalAt(const Solid& solid, const Eigen::Vector3d& p);
// True when the two solids' footprints overlap (grown by `margin`) and their height ranges meet.
bool overlaps(const Solid& a, const Solid& b, double margin);

}  // namespace dlslot::sim
