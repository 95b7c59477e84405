// The simulator's objects: a wheel is a cylinder lying across its heading (known intersections
// and normals); a vehicle stands on its tyres in arches cut into its sides, and only its mirrors
// reach out of its labelled box, no further than kPartsOutsideBoxM.
#include <gtest/gtest.h>

#include <cmath>

#include "sim/object_shape.hpp"
#include "sim/rng.hpp"

using namespace dlslot;

namespace {

// The first part of `parts` the ray meets, and where (index -1: none).
int firstHit(const std::vector<sim::Solid>& parts, const Eigen::Vector3d& o, const Eigen::Vector3d& d, double& s) {
  int hit = -1;
  s = 100.0;
  for (size_t i = 0; i < parts.size(); ++i) {
    double t;
    if (sim::intersect(parts[i], o, d, s, t)) {
      s = t;
      hit = static_cast<int>(i);
    }
  }
  return hit;
}

// A part's extent in the object's frame: (min, max) per axis. Parts of a vehicle are not yawed.
std::pair<Eigen::Vector3d, Eigen::Vector3d> extent(const sim::Solid& p) {
  return {p.center - p.half, p.center + p.half};
}

}  // namespace

TEST(SimSolid, AWheelIsACylinderLyingAcrossItsHeading) {
  const sim::Solid w = sim::Solid::wheel(Eigen::Vector3d(1, 2, 0.3), 0.3, 0.2, 0.0, 0.1f);
  double s = 0;
  // Along its heading (x) a ray meets the tread: a circle of radius 0.3 in x-z.
  ASSERT_TRUE(sim::intersect(w, Eigen::Vector3d(-4, 2, 0.3), Eigen::Vector3d::UnitX(), 100, s));
  EXPECT_NEAR(s, 4.7, 1e-12);
  EXPECT_TRUE(sim::normalAt(w, Eigen::Vector3d(0.7, 2, 0.3)).isApprox(-Eigen::Vector3d::UnitX()));
  // 0.25 m higher the tread is sqrt(0.3^2 - 0.25^2) thick from the axle.
  ASSERT_TRUE(sim::intersect(w, Eigen::Vector3d(-4, 2, 0.55), Eigen::Vector3d::UnitX(), 100, s));
  EXPECT_NEAR(s, 5 - std::sqrt(0.09 - 0.0625), 1e-12);
  EXPECT_FALSE(sim::intersect(w, Eigen::Vector3d(-4, 2, 0.61), Eigen::Vector3d::UnitX(), 100, s));
  // Along its axle (y) a ray meets the flat side, 0.1 m from the middle.
  ASSERT_TRUE(sim::intersect(w, Eigen::Vector3d(1.2, -3, 0.4), Eigen::Vector3d::UnitY(), 100, s));
  EXPECT_NEAR(s, 4.9, 1e-12);
  EXPECT_TRUE(sim::normalAt(w, Eigen::Vector3d(1.2, 1.9, 0.4)).isApprox(-Eigen::Vector3d::UnitY()));
  // From above it is the tread again, not a vertical cylinder's cap.
  ASSERT_TRUE(sim::intersect(w, Eigen::Vector3d(1, 2.05, 5), -Eigen::Vector3d::UnitZ(), 100, s));
  EXPECT_NEAR(s, 4.4, 1e-12);
  EXPECT_TRUE(sim::normalAt(w, Eigen::Vector3d(1, 2.05, 0.6)).isApprox(Eigen::Vector3d::UnitZ()));
  // Turned to head along y, its axle is along x.
  const sim::Solid turned = sim::Solid::wheel(Eigen::Vector3d(1, 2, 0.3), 0.3, 0.2, M_PI / 2, 0.1f);
  ASSERT_TRUE(sim::intersect(turned, Eigen::Vector3d(-4, 2, 0.4), Eigen::Vector3d::UnitX(), 100, s));
  EXPECT_NEAR(s, 4.9, 1e-12);
  EXPECT_TRUE(sim::normalAt(turned, Eigen::Vector3d(0.9, 2, 0.4)).isApprox(-Eigen::Vector3d::UnitX()));
  ASSERT_TRUE(sim::intersect(turned, Eigen::Vector3d(1, -3, 0.3), Eigen::Vector3d::UnitY(), 100, s));
  EXPECT_NEAR(s, 4.7, 1e-12);
}

TEST(SimObjectShape, VehiclesStandOnWheelsAndOnlyTheirMirrorsLeaveTheBox) {
  sim::Rng rng(7);
  for (const std::string type : {"Car", "Van", "Truck"}) {
    for (int k = 0; k < 20; ++k) {
      const Eigen::Vector3d size = sim::sampleSize(type, rng);
      const auto parts = sim::objectParts(type, size, 0.3f);
      const Eigen::Vector3d half = 0.5 * size;
      int tyres = 0;
      double reach = 0;
      std::vector<double> axles;
      for (const sim::Solid& p : parts) {
        const auto [lo, hi] = extent(p);
        // Within the box along it and in height; across it only the mirrors reach out.
        EXPECT_GE(lo.x(), -half.x() - 1e-9) << type;
        EXPECT_LE(hi.x(), half.x() + 1e-9) << type;
        EXPECT_GE(lo.z(), -half.z() - 1e-9) << type;
        EXPECT_LE(hi.z(), half.z() + 1e-9) << type;
        reach = std::max({reach, hi.y() - half.y(), -half.y() - lo.y()});
        if (p.kind == sim::SolidKind::Wheel) {
          ++tyres;
          EXPECT_NEAR(lo.z(), -half.z(), 1e-9) << type << ": a tyre stands on the road";
          EXPECT_LE(hi.y(), half.y()) << type << ": tyres are inside the body's width";
          if (p.center.y() > 0) axles.push_back(p.center.x());
        }
      }
      EXPECT_GT(reach, 0.1) << type << ": its mirrors reach out of the box";
      EXPECT_LE(reach, sim::kPartsOutsideBoxM + 1e-9) << type;
      EXPECT_EQ(tyres, type == "Truck" && size.x() >= 9.0 ? 6 : 4) << type;
      // From the side, at axle height, a ray through an arch meets the tyre; between the axles
      // it meets the body.
      for (double a : axles) {
        double s;
        const int hit = firstHit(parts, Eigen::Vector3d(a, 10, -half.z() + 0.45), -Eigen::Vector3d::UnitY(), s);
        ASSERT_GE(hit, 0) << type;
        EXPECT_EQ(parts[hit].kind, sim::SolidKind::Wheel) << type << " axle at " << a;
      }
      double s;
      const double between = 0.5 * (axles.front() + axles.back());
      const int body = firstHit(parts, Eigen::Vector3d(between, 10, -half.z() + (type == "Truck" ? 1.5 : 0.45)),
                                -Eigen::Vector3d::UnitY(), s);
      ASSERT_GE(body, 0) << type;
      EXPECT_EQ(parts[body].kind, sim::SolidKind::Box) << type;
      EXPECT_NEAR(10 - s, half.y(), 1e-9) << type << ": the body's side is the box's";
    }
  }
}
