// Deterministic random numbers for the simulator. std:: distributions differ between standard
// libraries, so these are written out: same seed, same bytes on any platform.
#pragma once

#include <cmath>
#include <cstdint>
#include <initializer_list>

namespace dlslot::sim {

// SplitMix64 finalizer: a good 64-bit mix, also used to derive independent streams from keys.
inline uint64_t mix64(uint64_t x) {
  x += 0x9e3779b97f4a7c15ULL;
  x = (x ^ (x >> 30)) * 0xbf58476d1ce4e5b9ULL;
  x = (x ^ (x >> 27)) * 0x94d049bb133111ebULL;
  return x ^ (x >> 31);
}

// A stream key from several integers (seed, frame, beam, ...), so every frame and every ray has
// its own stream: results do not depend on the order things are computed in (or on threads).
inline uint64_t streamKey(std::initializer_list<uint64_t> parts) {
  uint64_t h = 0x6a09e667f3bcc909ULL;
  for (uint64_t p : parts) h = mix64(h ^ mix64(p));
  return h;
}

class Rng {
 public:
  explicit Rng(uint64_t key) : state_(key) {}
  uint64_t next() { return mix64(state_ += 0x9e3779b97f4a7c15ULL); }
  // Uniform in [0, 1) with 53 random bits.
  double uniform() { return static_cast<double>(next() >> 11) * 0x1.0p-53; }
  double uniform(double lo, double hi) { return lo + (hi - lo) * uniform(); }
  int uniformInt(int lo, int hi_inclusive) { return lo + static_cast<int>(uniform() * (hi_inclusive - lo + 1)); }
  bool chance(double p) { return uniform() < p; }
  // Box-Muller; one value per call keeps the stream simple to reason about.
  double normal(double mean = 0.0, double sigma = 1.0) {
    const double u1 = 1.0 - uniform(), u2 = uniform();
    return mean + sigma * std::sqrt(-2.0 * std::log(u1)) * std::cos(2.0 * M_PI * u2);
  }
  // Two independent standard normals from one Box-Muller draw (the hot path: every lidar return).
  void normalPair(double& a, double& b) {
    const double u1 = 1.0 - uniform(), u2 = uniform();
    const double r = std::sqrt(-2.0 * std::log(u1));
    double s, c;
    sincos(2.0 * M_PI * u2, &s, &c);
    a = r * c;
    b = r * s;
  }
  // Poisson by inversion (small means only: false positives per frame).
  int poisson(double mean) {
    const double limit = std::exp(-mean);
    double p = uniform();
    int k = 0;
    while (p > limit && k < 1000) {
      p *= uniform();
      ++k;
    }
    return k;
  }

 private:
  uint64_t state_;
};

}  // namespace dlslot::sim
