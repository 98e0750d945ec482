#include "dovetail/collision/predicates.h"

#include <gtest/gtest.h>

#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>
#include <cstdint>
#include <random>
#include <vector>

#include "../support/random_geometry.h"
#include "core/predicates_inline.h"

namespace dovetail::collision {
namespace {

// Reference: the determinants evaluated exactly with big integers. Every
// double is m * 2^e with an integer m; all inputs of one determinant are
// scaled by the same power of two to integers, which leaves the sign unchanged.

/// Signed big integer, magnitude in base 2^32, little-endian, no leading zeros.
class BigInt {
 public:
  BigInt() = default;

  /// m * 2^shift for shift >= 0.
  static BigInt from_shifted(std::int64_t m, int shift) {
    BigInt r;
    r.negative_ = m < 0;
    std::uint64_t mag = m < 0 ? std::uint64_t(0) - std::uint64_t(m) : std::uint64_t(m);
    r.mag_.assign(shift / 32, 0);
    const int bits = shift % 32;
    const std::uint64_t low = mag << bits;
    const std::uint64_t high = bits == 0 ? 0 : mag >> (64 - bits);
    r.mag_.push_back(static_cast<std::uint32_t>(low));
    r.mag_.push_back(static_cast<std::uint32_t>(low >> 32));
    r.mag_.push_back(static_cast<std::uint32_t>(high));
    r.trim();
    return r;
  }

  int sign() const { return mag_.empty() ? 0 : (negative_ ? -1 : 1); }

  friend BigInt operator-(BigInt a) {
    a.negative_ = !a.negative_;
    a.trim();
    return a;
  }
  friend BigInt operator+(const BigInt& a, const BigInt& b) {
    BigInt r;
    if (a.negative_ == b.negative_) {
      r.mag_ = add_magnitudes(a.mag_, b.mag_);
      r.negative_ = a.negative_;
    } else if (compare_magnitudes(a.mag_, b.mag_) >= 0) {
      r.mag_ = subtract_magnitudes(a.mag_, b.mag_);
      r.negative_ = a.negative_;
    } else {
      r.mag_ = subtract_magnitudes(b.mag_, a.mag_);
      r.negative_ = b.negative_;
    }
    r.trim();
    return r;
  }
  friend BigInt operator-(const BigInt& a, const BigInt& b) { return a + (-b); }
  friend BigInt operator*(const BigInt& a, const BigInt& b) {
    BigInt r;
    if (a.mag_.empty() || b.mag_.empty()) return r;
    std::vector<std::uint64_t> acc(a.mag_.size() + b.mag_.size() + 1, 0);
    for (std::size_t i = 0; i < a.mag_.size(); ++i) {
      std::uint64_t carry = 0;
      for (std::size_t j = 0; j < b.mag_.size(); ++j) {
        const std::uint64_t t = std::uint64_t(a.mag_[i]) * b.mag_[j] + acc[i + j] + carry;
        acc[i + j] = t & 0xffffffffu;
        carry = t >> 32;
      }
      std::size_t k = i + b.mag_.size();
      while (carry != 0) {
        const std::uint64_t t = acc[k] + carry;
        acc[k++] = t & 0xffffffffu;
        carry = t >> 32;
      }
    }
    r.mag_.assign(acc.begin(), acc.end());
    r.negative_ = a.negative_ != b.negative_;
    r.trim();
    return r;
  }

 private:
  using Mag = std::vector<std::uint32_t>;

  void trim() {
    while (!mag_.empty() && mag_.back() == 0) mag_.pop_back();
    if (mag_.empty()) negative_ = false;
  }
  static int compare_magnitudes(const Mag& a, const Mag& b) {
    if (a.size() != b.size()) return a.size() < b.size() ? -1 : 1;
    for (std::size_t i = a.size(); i-- > 0;) {
      if (a[i] != b[i]) return a[i] < b[i] ? -1 : 1;
    }
    return 0;
  }
  static Mag add_magnitudes(const Mag& a, const Mag& b) {
    Mag r(std::max(a.size(), b.size()) + 1, 0);
    std::uint64_t carry = 0;
    for (std::size_t i = 0; i < r.size(); ++i) {
      const std::uint64_t t = carry + (i < a.size() ? a[i] : 0) + (i < b.size() ? b[i] : 0);
      r[i] = static_cast<std::uint32_t>(t);
      carry = t >> 32;
    }
    return r;
  }
  static Mag subtract_magnitudes(const Mag& a, const Mag& b) {  // |a| >= |b|
    Mag r(a.size(), 0);
    std::int64_t borrow = 0;
    for (std::size_t i = 0; i < a.size(); ++i) {
      std::int64_t t = std::int64_t(a[i]) - (i < b.size() ? b[i] : 0) - borrow;
      borrow = t < 0 ? 1 : 0;
      if (t < 0) t += std::int64_t(1) << 32;
      r[i] = static_cast<std::uint32_t>(t);
    }
    return r;
  }

  bool negative_ = false;
  Mag mag_;
};

/// Exact integers for a set of doubles, all scaled by one power of two.
std::vector<BigInt> to_common_integers(const std::vector<Real>& values) {
  int min_exponent = 0;
  bool any = false;
  std::vector<std::pair<std::int64_t, int>> parts;
  for (Real x : values) {
    int e = 0;
    const Real f = std::frexp(x, &e);
    const auto m = static_cast<std::int64_t>(std::ldexp(f, 53));
    parts.emplace_back(m, e - 53);
    if (x != 0 && (!any || e - 53 < min_exponent)) {
      min_exponent = e - 53;
      any = true;
    }
  }
  std::vector<BigInt> out;
  for (const auto& [m, e] : parts)
    out.push_back(BigInt::from_shifted(m, m == 0 ? 0 : e - min_exponent));
  return out;
}

int reference_orient3d(const Vec3& a, const Vec3& b, const Vec3& c, const Vec3& d) {
  const std::vector<BigInt> v = to_common_integers(
      {a.x(), a.y(), a.z(), b.x(), b.y(), b.z(), c.x(), c.y(), c.z(), d.x(), d.y(), d.z()});
  BigInt u[3], w[3], x[3];
  for (int k = 0; k < 3; ++k) {
    u[k] = v[3 + k] - v[k];
    w[k] = v[6 + k] - v[k];
    x[k] = v[9 + k] - v[k];
  }
  const BigInt det = u[0] * (w[1] * x[2] - w[2] * x[1]) + u[1] * (w[2] * x[0] - w[0] * x[2]) +
                     u[2] * (w[0] * x[1] - w[1] * x[0]);
  return det.sign();
}

int reference_orient2d(Real ax, Real ay, Real bx, Real by, Real cx, Real cy) {
  const std::vector<BigInt> v = to_common_integers({ax, ay, bx, by, cx, cy});
  return ((v[2] - v[0]) * (v[5] - v[1]) - (v[3] - v[1]) * (v[4] - v[0])).sign();
}

using test::Random;

using test::ulps;

using test::nudge;

/// Checks the filtered, exact and plane-side paths of orient3d against the reference.
void expect_orient3d_exact(const Vec3& a, const Vec3& b, const Vec3& c, const Vec3& d) {
  const int expected = reference_orient3d(a, b, c, d);
  ASSERT_EQ(orient3d(a, b, c, d), expected) << a.transpose() << " | " << b.transpose() << " | "
                                            << c.transpose() << " | " << d.transpose();
  ASSERT_EQ(detail::orient3d_exact(a, b, c, d), expected);
  ASSERT_EQ(detail::orient3d_adaptive(a, b, c, d), expected);
  // Each intermediate stage, when it decides, decides right.
  if (int sign; detail::orient3d_rounding_free(a, b, c, d, sign)) {
    ASSERT_EQ(sign, expected);
  }
  if (int sign; detail::orient3d_twice_precision(a, b, c, d, sign)) {
    ASSERT_EQ(sign, expected);
  }
  int sides[3];
  // The shared bound must cover every point, not only the first one.
  detail::TrianglePlane(a, b, c).sides(a, d, c, sides);
  ASSERT_EQ(sides[0], 0);
  ASSERT_EQ(sides[1], expected);
  ASSERT_EQ(sides[2], 0);
}

void expect_orient2d_exact(Real ax, Real ay, Real bx, Real by, Real cx, Real cy) {
  const int expected = reference_orient2d(ax, ay, bx, by, cx, cy);
  ASSERT_EQ(orient2d(ax, ay, bx, by, cx, cy), expected)
      << ax << " " << ay << " " << bx << " " << by << " " << cx << " " << cy;
  ASSERT_EQ(detail::orient2d_exact(ax, ay, bx, by, cx, cy), expected);
}

TEST(BigIntReference, AgreesWithInt64OnSmallIntegers) {
  Random random(11);
  for (int i = 0; i < 2000; ++i) {
    const std::int64_t v[6] = {random.integer(-1000, 1000), random.integer(-1000, 1000),
                               random.integer(-1000, 1000), random.integer(-1000, 1000),
                               random.integer(-1000, 1000), random.integer(-1000, 1000)};
    const std::int64_t det = (v[2] - v[0]) * (v[5] - v[1]) - (v[3] - v[1]) * (v[4] - v[0]);
    ASSERT_EQ(
        reference_orient2d(Real(v[0]), Real(v[1]), Real(v[2]), Real(v[3]), Real(v[4]), Real(v[5])),
        (det > 0) - (det < 0));
  }
  // Scaling by powers of two must not change the reference.
  EXPECT_EQ(reference_orient2d(0, 0, 0x1p-300, 0, 0, 0x1p+90), 1);
  EXPECT_EQ(reference_orient2d(0, 0, 0x1p+90, 0, 0, -0x1p-300), -1);
}

TEST(Orient3d, SignConventionAndAntisymmetry) {
  const Vec3 o(0, 0, 0), x(1, 0, 0), y(0, 1, 0), z(0, 0, 1);
  EXPECT_EQ(orient3d(o, x, y, z), 1);  // z is on the side of (x - o) x (y - o)
  EXPECT_EQ(orient3d(o, y, x, z), -1);
  EXPECT_EQ(orient3d(o, x, y, -z), -1);
  EXPECT_EQ(orient3d(o, x, y, Vec3(3, -7, 0)), 0);
  EXPECT_EQ(orient3d(o, o, y, z), 0);
  Random random(12);
  for (int i = 0; i < 2000; ++i) {
    const Vec3 a = random.point(-1, 1), b = random.point(-1, 1), c = random.point(-1, 1);
    const Vec3 d = nudge(random, a + 0.5 * (b - a) + 0.25 * (c - a), 3);
    const int s = orient3d(a, b, c, d);
    ASSERT_EQ(orient3d(b, a, c, d), -s);
    ASSERT_EQ(orient3d(b, c, a, d), s);
    ASSERT_EQ(orient3d(a, c, b, d), -s);
    ASSERT_EQ(orient3d(d, b, c, a), -s);
  }
}

TEST(Orient3d, MatchesIntegerDeterminantOnGrids) {
  Random random(13);
  for (int i = 0; i < 20000; ++i) {
    const bool small = i % 2 == 0;
    const std::int64_t range = small ? 3 : 1 << 20;
    const Vec3 a = random.grid_point(range), b = random.grid_point(range),
               c = random.grid_point(range), d = random.grid_point(range);
    const int expected = reference_orient3d(a, b, c, d);
    if (small) {
      // Plain integers suffice here; they also check the reference.
      const Vec3 u = b - a, v = c - a, w = d - a;
      const auto n = [](Real x) { return static_cast<std::int64_t>(x); };
      const std::int64_t det = n(u.x()) * (n(v.y()) * n(w.z()) - n(v.z()) * n(w.y())) +
                               n(u.y()) * (n(v.z()) * n(w.x()) - n(v.x()) * n(w.z())) +
                               n(u.z()) * (n(v.x()) * n(w.y()) - n(v.y()) * n(w.x()));
      ASSERT_EQ(expected, (det > 0) - (det < 0));
    }
    ASSERT_EQ(orient3d(a, b, c, d), expected);
    ASSERT_EQ(detail::orient3d_exact(a, b, c, d), expected);
  }
}

TEST(Orient3d, NearlyCoplanarPointsMatchReference) {
  Random random(14);
  for (int i = 0; i < 20000; ++i) {
    // d on the plane of a, b, c up to rounding, then moved by a few ulps.
    const Real scale = std::ldexp(1.0, static_cast<int>(random.integer(-40, 40)));
    const Vec3 a = random.point(-1, 1) * scale, b = random.point(-1, 1) * scale,
               c = random.point(-1, 1) * scale;
    const Real s = random.uniform(-2, 2), t = random.uniform(-2, 2);
    const Vec3 d = nudge(random, a + s * (b - a) + t * (c - a), 2);
    expect_orient3d_exact(a, b, c, d);
    if (HasFatalFailure()) return;
  }
}

TEST(Orient3d, RotatedCoplanarPointsAreDecidedByTwicePrecision) {
  // Exactly coplanar grid points, then rotated: the rounded points are off
  // the plane by about one ulp, too close for the first filter.
  Random random(19);
  int first_filter_open = 0;
  int twice_decided = 0;
  for (int i = 0; i < 20000; ++i) {
    const Vec3 e1 = random.grid_point(5), e2 = random.grid_point(5), o = random.grid_point(100);
    const auto at = [&] {
      return o + Real(random.integer(-9, 9)) * e1 + Real(random.integer(-9, 9)) * e2;
    };
    const Vec3 p[4] = {at(), at(), at(), at()};
    const Real angle = random.uniform(0, 6.283185307179586);
    const Vec3 axis = Vec3(random.uniform(-1, 1), random.uniform(-1, 1), 1).normalized();
    const Mat3 R = Eigen::AngleAxis<Real>(angle, axis).toRotationMatrix();
    const Vec3 a = R * p[0], b = R * p[1], c = R * p[2], d = R * p[3];
    expect_orient3d_exact(a, b, c, d);
    if (HasFatalFailure()) return;
    const Vec3 u = b - a, v = c - a, w = d - a;
    const Real det = u.cross(v).dot(w);
    const Real perm = (u.cwiseAbs().cross(v.cwiseAbs())).cwiseAbs().dot(w.cwiseAbs());
    if (std::abs(det) <= 8 * detail::kEpsilon * perm * 4) {
      ++first_filter_open;
      int sign;
      twice_decided += detail::orient3d_twice_precision(a, b, c, d, sign);
    }
  }
  // The family is hard for the first filter and the second one settles it.
  EXPECT_GT(first_filter_open, 5000);
  EXPECT_GT(twice_decided, first_filter_open * 9 / 10);
}

TEST(Orient3d, RoundingFreeStageDecidesSmallGrids) {
  Random random(20);
  for (int i = 0; i < 5000; ++i) {
    const Vec3 a = random.grid_point(1000), b = random.grid_point(1000),
               c = random.grid_point(1000), d = random.grid_point(1000);
    int sign;
    ASSERT_TRUE(detail::orient3d_rounding_free(a, b, c, d, sign));
    ASSERT_EQ(sign, reference_orient3d(a, b, c, d));
  }
  // A product that needs more than 53 bits is not rounding-free.
  int sign;
  EXPECT_FALSE(detail::orient3d_rounding_free(Vec3(0, 0, 0), Vec3(0x1p30 + 1, 0, 0),
                                              Vec3(0, 0x1p30 + 1, 0), Vec3(0, 0, 1), sign));
}

TEST(Orient3d, PlaneSidesShareOneBoundForAllThreePoints) {
  // Planes facing each axis; the near-plane point comes after a vertex, whose
  // w = 0 must not shrink the bound shared by the three points.
  Random random(22);
  for (int axis = 0; axis < 3; ++axis) {
    for (int i = 0; i < 3000; ++i) {
      auto on_plane = [&](Real height) {
        Vec3 p;
        p[axis] = height;
        p[(axis + 1) % 3] = random.uniform(-1, 1);
        p[(axis + 2) % 3] = random.uniform(-1, 1);
        return p;
      };
      const Vec3 a = on_plane(0.5), b = on_plane(0.5 + random.uniform(-1e-3, 1e-3)),
                 c = on_plane(0.5 + random.uniform(-1e-3, 1e-3));
      const Real s = random.uniform(-1, 2), t = random.uniform(-1, 2);
      const Vec3 d = nudge(random, a + s * (b - a) + t * (c - a), 2);
      const int expected = reference_orient3d(a, b, c, d);
      int sides[3];
      detail::TrianglePlane(a, b, c).sides(a, d, b, sides);
      ASSERT_EQ(sides[1], expected) << "axis " << axis << " case " << i;
      detail::TrianglePlane(a, b, c).sides(c, b, d, sides);
      ASSERT_EQ(sides[2], expected) << "axis " << axis << " case " << i;
    }
  }
}

TEST(Orient3d, SliverAndFarOffsetInputsMatchReference) {
  Random random(15);
  for (int i = 0; i < 5000; ++i) {
    // A plane far from the origin and nearly degenerate triangles on it.
    const Vec3 offset = random.point(-1e6, 1e6);
    const Vec3 a = offset + random.point(-1, 1);
    const Vec3 b = nudge(random, a + random.point(-1e-9, 1e-9), 1);
    const Vec3 c = nudge(random, a + 0.5 * (b - a), 4);
    const Vec3 d = nudge(random, a + 3.0 * (c - a), 4);
    expect_orient3d_exact(a, b, c, d);
    if (HasFatalFailure()) return;
  }
}

TEST(Orient3d, ExtremeMagnitudesInsideDocumentedRange) {
  Random random(16);
  for (int i = 0; i < 5000; ++i) {
    // Integer-grid configurations scaled by powers of two down to 2^-358 and
    // up to 1e30: the sign must survive exactly.
    const int e = static_cast<int>(random.integer(-358 + 3, 99 - 21));
    const Vec3 a = random.grid_point(1 << 20), b = random.grid_point(1 << 20),
               c = random.grid_point(1 << 20);
    const Vec3 d = a + 2.0 * (b - a) - 3.0 * (c - a) + Vec3(0, 0, Real(random.integer(-1, 1)));
    expect_orient3d_exact(std::ldexp(1.0, e) * a, std::ldexp(1.0, e) * b, std::ldexp(1.0, e) * c,
                          std::ldexp(1.0, e) * d);
    if (HasFatalFailure()) return;
    // Mixed magnitudes: tiny coordinates beside large ones.
    const Vec3 p = random.point(-1e30, 1e30);
    const Vec3 q = Vec3(std::ldexp(random.uniform(-1, 1), -300), random.uniform(-1e30, 1e30),
                        std::ldexp(random.uniform(-1, 1), -250));
    const Vec3 r = nudge(random, 0.5 * (p + q), 1);
    Vec3 s = nudge(random, 2.0 * r - p, 1);
    for (int k = 0; k < 3; ++k) {
      if (std::abs(s[k]) < 0x1p-306) s[k] = 0;  // keep the input inside the range
    }
    expect_orient3d_exact(p, q, r, s);
    if (HasFatalFailure()) return;
  }
  // The smallest positive determinant inside the range: 2^-1074.
  const Real t = 0x1p-358;
  EXPECT_EQ(orient3d(Vec3(0, 0, 0), Vec3(t, 0, 0), Vec3(0, t, 0), Vec3(0, 0, t)), 1);
  EXPECT_EQ(orient3d(Vec3(0, 0, 0), Vec3(0, t, 0), Vec3(t, 0, 0), Vec3(0, 0, t)), -1);
  // The largest coordinates allowed by mesh validation, 1 ulp off the plane.
  const Real big = 1e30;
  EXPECT_EQ(orient3d(Vec3(-big, -big, big), Vec3(big, -big, big), Vec3(-big, big, big),
                     Vec3(big, big, ulps(big, 1))),
            1);
}

TEST(Orient2d, ClassicNearCollinearGrid) {
  // Points near (0.5, 0.5) on a 256 x 256 grid of ulps against the line
  // through (12, 12) and (24, 24): plain floating point gets this wrong.
  const Real u = 0x1p-53;
  int disagreements_with_plain = 0;
  for (int i = 0; i < 256; ++i) {
    for (int j = 0; j < 256; ++j) {
      const Real px = 0.5 + i * u, py = 0.5 + j * u;
      expect_orient2d_exact(px, py, 12, 12, 24, 24);
      if (HasFatalFailure()) return;
      const Real plain = (12 - px) * (24 - py) - (12 - py) * (24 - px);
      const int plain_sign = (plain > 0) - (plain < 0);
      disagreements_with_plain += plain_sign != orient2d(px, py, 12, 12, 24, 24);
    }
  }
  EXPECT_GT(disagreements_with_plain, 0);  // the inputs do exercise the exact stage
}

TEST(Orient2d, RandomNearCollinearAndExtremeInputs) {
  Random random(17);
  for (int i = 0; i < 20000; ++i) {
    const Real scale = std::ldexp(1.0, static_cast<int>(random.integer(-500, 90)));
    const Real ax = random.uniform(-1, 1) * scale, ay = random.uniform(-1, 1) * scale;
    const Real bx = random.uniform(-1, 1) * scale, by = random.uniform(-1, 1) * scale;
    const Real t = random.uniform(-3, 3);
    const Real cx = ulps(ax + t * (bx - ax), static_cast<int>(random.integer(-2, 2)));
    const Real cy = ulps(ay + t * (by - ay), static_cast<int>(random.integer(-2, 2)));
    expect_orient2d_exact(ax, ay, bx, by, cx, cy);
    if (HasFatalFailure()) return;
  }
  EXPECT_EQ(orient2d(0, 0, 0x1p-537, 0, 0, 0x1p-537), 1);
  EXPECT_EQ(orient2d(0, 0, 1, 1, 3, 3), 0);
  EXPECT_EQ(orient2d(0, 0, 1, 0, 0, 1), 1);
}

TEST(IsDegenerateTriangle, ExactCollinearity) {
  EXPECT_TRUE(is_degenerate_triangle(Vec3(1, 2, 3), Vec3(1, 2, 3), Vec3(4, 5, 6)));
  EXPECT_TRUE(is_degenerate_triangle(Vec3(1, 2, 3), Vec3(1, 2, 3), Vec3(1, 2, 3)));
  EXPECT_TRUE(is_degenerate_triangle(Vec3(0, 0, 0), Vec3(1, 2, 3), Vec3(-2, -4, -6)));
  EXPECT_FALSE(is_degenerate_triangle(Vec3(0, 0, 0), Vec3(1, 0, 0), Vec3(0, 1, 0)));
  // Only one projection sees the area (the triangle is in a coordinate plane).
  EXPECT_FALSE(is_degenerate_triangle(Vec3(0, 0, 5), Vec3(1, 0, 5), Vec3(0, 0x1p-300, 5)));
  EXPECT_FALSE(is_degenerate_triangle(Vec3(0, 0, 0), Vec3(0, 1, 0), Vec3(0, 0, 1)));
  Random random(18);
  for (int i = 0; i < 5000; ++i) {
    // Collinear by construction on a grid, at any power-of-two scale.
    const Real scale = std::ldexp(1.0, static_cast<int>(random.integer(-300, 70)));
    const Vec3 a = random.grid_point(1 << 20) * scale;
    const Vec3 dir = random.grid_point(1 << 10) * scale;
    const Vec3 b = a + Real(random.integer(-64, 64)) * dir;
    const Vec3 c = a + Real(random.integer(-64, 64)) * dir;
    ASSERT_TRUE(is_degenerate_triangle(a, b, c));
    // One ulp off the line is not degenerate unless the points coincide.
    Vec3 c_off = c;
    const int k = static_cast<int>(random.integer(0, 2));
    c_off[k] = ulps(c[k], 1);
    const bool cross_zero =
        reference_orient2d(a.y(), a.z(), b.y(), b.z(), c_off.y(), c_off.z()) == 0 &&
        reference_orient2d(a.z(), a.x(), b.z(), b.x(), c_off.z(), c_off.x()) == 0 &&
        reference_orient2d(a.x(), a.y(), b.x(), b.y(), c_off.x(), c_off.y()) == 0;
    ASSERT_EQ(is_degenerate_triangle(a, b, c_off), cross_zero);
  }
}

}  // namespace
}  // namespace dovetail::collision
