// The world boxes of small hulls (world/rotated_bounds.h): the two-wide form
// gives the least and greatest rotated coordinate of every point, as the
// scalar expression computes it, for every count of points.

#include "world/rotated_bounds.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <random>
#include <vector>

#include "dovetail/collision/pose_sampling.h"

namespace dovetail::collision {
namespace {

TEST(RotatedBounds, AreTheBoundsOfEveryRotatedPoint) {
  std::mt19937_64 rng(7);
  std::uniform_real_distribution<Real> coordinate(-3, 3);
  const std::vector<Transform> poses = random_poses(50, 1.0, 3);
  for (std::size_t n = 1; n <= 13; ++n) {
    for (const Transform& X : poses) {
      std::vector<Real> xyz(3 * n);
      for (Real& c : xyz) c = coordinate(rng);
      const Real* x = xyz.data();
      const Real* y = x + n;
      const Real* z = y + n;
      const auto [lo, hi] = detail::rotated_bounds(X.R, x, y, z, n);
      for (int k = 0; k < 3; ++k) {
        Real expect_lo = 1e300, expect_hi = -1e300;
        for (std::size_t i = 0; i < n; ++i) {
          const Real c = (X.R(k, 0) * x[i] + X.R(k, 1) * y[i]) + X.R(k, 2) * z[i];
          expect_lo = std::min(expect_lo, c);
          expect_hi = std::max(expect_hi, c);
        }
        EXPECT_EQ(lo[k], expect_lo) << "n " << n << " axis " << k;
        EXPECT_EQ(hi[k], expect_hi) << "n " << n << " axis " << k;
      }
    }
  }
}

}  // namespace
}  // namespace dovetail::collision
