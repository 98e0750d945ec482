#pragma once
// Seeded random geometry for the tests: identical sequences on every platform
// (raw 64-bit engine draws, no std distributions).

#include <Eigen/Geometry>
#include <cmath>
#include <cstdint>
#include <random>

#include "dovetail/collision/types.h"

namespace dovetail::collision::test {

class Random {
 public:
  explicit Random(std::uint64_t seed) : engine_(seed) {}
  std::uint64_t bits() { return engine_(); }
  Real unit() { return static_cast<Real>(engine_() >> 11) * 0x1p-53; }
  Real uniform(Real lo, Real hi) { return lo + (hi - lo) * unit(); }
  std::int64_t integer(std::int64_t lo, std::int64_t hi) {
    return lo + static_cast<std::int64_t>(engine_() % static_cast<std::uint64_t>(hi - lo + 1));
  }
  bool coin() { return (engine_() >> 63) != 0; }
  Vec3 point(Real lo, Real hi) { return Vec3(uniform(lo, hi), uniform(lo, hi), uniform(lo, hi)); }
  Vec3 grid_point(std::int64_t range) {
    return Vec3(Real(integer(-range, range)), Real(integer(-range, range)),
                Real(integer(-range, range)));
  }
  /// A dyadic fraction k / 2^bits in [0, 1].
  Real dyadic(int bits) { return std::ldexp(Real(integer(0, std::int64_t{1} << bits)), -bits); }
  Mat3 rotation() {
    Eigen::Quaternion<Real> q(uniform(-1, 1), uniform(-1, 1), uniform(-1, 1), uniform(-1, 1));
    if (q.norm() < 1e-3) q = Eigen::Quaternion<Real>(1, 0, 0, 0);
    return q.normalized().toRotationMatrix();
  }

 private:
  std::mt19937_64 engine_;
};

/// x moved by `steps` units in the last place.
inline Real ulps(Real x, int steps) {
  for (; steps > 0; --steps) x = std::nextafter(x, HUGE_VAL);
  for (; steps < 0; ++steps) x = std::nextafter(x, -HUGE_VAL);
  return x;
}

/// p with each coordinate moved by up to max_ulps units in the last place.
/// Coordinates below 2^-306 in magnitude (zero included) are kept: their ulps
/// would leave the range in which the predicates are exact.
inline Vec3 nudge(Random& random, const Vec3& p, int max_ulps) {
  Vec3 q;
  for (int k = 0; k < 3; ++k) {
    const int steps = static_cast<int>(random.integer(-max_ulps, max_ulps));
    q[k] = std::abs(p[k]) < 0x1p-306 ? p[k] : ulps(p[k], steps);
  }
  return q;
}

}  // namespace dovetail::collision::test
