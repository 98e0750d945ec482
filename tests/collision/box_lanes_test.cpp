// The OBB tree's lane test (box_lanes.h): the AVX2 lanes give the scalar
// lanes' bits, the verdict is the separating-axis test's, the gap never
// exceeds the widest separating gap, and touching boxes overlap.

#include "polygon/box_lanes.h"

#include <gtest/gtest.h>

#include <Eigen/Geometry>
#include <algorithm>
#include <array>
#include <cmath>
#include <cstring>
#include <random>
#include <vector>

#include "dovetail/collision/types.h"
#include "polygon/box_lanes_scalar.h"

namespace dovetail::collision {
namespace {

/// A box as the OBB tree stores it: the rotation into its frame (rows are
/// its axes), centre, half extents; and one double after, as a node has.
struct StoredBox {
  std::array<double, 16> data{};
};

StoredBox stored(const Mat3& axes, const Vec3& centre, const Vec3& half) {
  StoredBox s;
  Eigen::Map<Mat3>(s.data.data()) = axes.transpose();
  Eigen::Map<Vec3>(s.data.data() + 9) = centre;
  Eigen::Map<Vec3>(s.data.data() + 12) = half;
  s.data[15] = 12345.0;  // what follows a node's box: its link, read as a double
  return s;
}

struct Box {
  Mat3 axes;  ///< columns
  Vec3 centre;
  Vec3 half;
};

/// The widest gap over the fifteen axes, each unnormalized axis as the
/// tree's test takes it: the plain textbook projection, for reference.
double reference_gap(const Box& a, const Box& b) {
  std::array<Vec3, 15> axes;
  for (int i = 0; i < 3; ++i) {
    axes[i] = a.axes.col(i);
    axes[3 + i] = b.axes.col(i);
    for (int j = 0; j < 3; ++j) axes[6 + 3 * i + j] = a.axes.col(i).cross(b.axes.col(j));
  }
  double widest = -std::numeric_limits<double>::infinity();
  for (const Vec3& n : axes) {
    double ra = 0, rb = 0;
    for (int k = 0; k < 3; ++k) {
      ra += a.half[k] * std::abs(n.dot(a.axes.col(k)));
      rb += b.half[k] * std::abs(n.dot(b.axes.col(k)));
    }
    widest = std::max(widest, std::abs(n.dot(b.centre - a.centre)) - ra - rb);
  }
  return widest;
}

class BoxLanes : public ::testing::Test {
 protected:
  Mat3 rotation() {
    Eigen::Quaterniond q(u_(rng_), u_(rng_), u_(rng_), u_(rng_));
    return q.normalized().toRotationMatrix();
  }
  /// Boxes of mixed shapes (cubes, plates, needles), most near each other.
  Box box(double spread) {
    Box b{rotation(), Vec3(u_(rng_), u_(rng_), u_(rng_)) * spread, Vec3::Zero()};
    for (int k = 0; k < 3; ++k) b.half[k] = std::pow(10.0, -2.0 * std::abs(u_(rng_))) * 0.5;
    return b;
  }
  /// B's box in A's frame, through the move under test (identity pose).
  static detail::BoxLanes lanes(const detail::BoxLaneOps& ops, const Box& b) {
    const StoredBox s = stored(b.axes, b.centre, b.half);
    const Mat3 R = Mat3::Identity();
    const Vec3 t = Vec3::Zero();
    detail::BoxLanes out;
    ops.move(s.data.data(), R.data(), t.data(), out);
    return out;
  }

  std::mt19937 rng_{20261127};
  std::uniform_real_distribution<double> u_{-1.0, 1.0};
};

TEST_F(BoxLanes, WideLanesGiveTheScalarLanesBits) {
  const detail::BoxLaneOps wide = detail::box_lane_ops_avx2();
  if (!wide.gap) GTEST_SKIP() << "no AVX2 lanes on this build or processor";
  const detail::BoxLaneOps scalar = detail::box_lane_ops_scalar();
  int separated = 0;
  for (int n = 0; n < 20000; ++n) {
    const Box a = box(0.08);
    const Box b = box(0.08);
    const StoredBox sa = stored(a.axes, a.centre, a.half);
    // A pose of B's frame in A's, as a query has.
    const Mat3 R = rotation();
    const Vec3 t = Vec3(u_(rng_), u_(rng_), u_(rng_)) * 0.05;
    const StoredBox sb = stored(b.axes, b.centre, b.half);
    detail::BoxLanes lw, ls;
    wide.move(sb.data.data(), R.data(), t.data(), lw);
    scalar.move(sb.data.data(), R.data(), t.data(), ls);
    ASSERT_EQ(std::memcmp(&lw, &ls, sizeof lw), 0) << "move differs at pair " << n;
    const double margin = n % 2 ? 0.0 : 1e-12;
    const double gw = wide.gap(sa.data.data(), lw, margin);
    const double gs = scalar.gap(sa.data.data(), ls, margin);
    ASSERT_EQ(std::memcmp(&gw, &gs, sizeof gw), 0) << "gap differs at pair " << n;
    separated += gs > 0;
  }
  // Both verdicts occur often: the comparison covers the early exit and the
  // full test.
  EXPECT_GT(separated, 4000);
  EXPECT_LT(separated, 16000);
}

TEST_F(BoxLanes, VerdictIsTheSeparatingAxisTestsAndTheGapNeverExceedsIt) {
  const detail::BoxLaneOps ops = detail::box_lane_ops();
  int clear = 0, sep = 0;
  for (int n = 0; n < 20000; ++n) {
    const Box a = box(0.12);
    const Box b = box(0.12);
    const double reference = reference_gap(a, b);
    const StoredBox sa = stored(a.axes, a.centre, a.half);
    const double gap = ops.gap(sa.data.data(), lanes(ops, b), 0.0);
    ASSERT_GE(gap, 0.0);
    ASSERT_LE(gap, std::max(reference, 0.0) + 1e-12) << "pair " << n;
    if (std::abs(reference) < 1e-9) continue;  // rounding may go either way
    ++clear;
    sep += reference > 0;
    ASSERT_EQ(gap > 0, reference > 0) << "pair " << n << ", reference gap " << reference;
  }
  EXPECT_GT(clear, 19000);
  EXPECT_GT(sep, 4000);  // both verdicts, often
  EXPECT_LT(sep, 16000);
}

TEST_F(BoxLanes, TouchingBoxesOverlapAtAnyTurn) {
  const detail::BoxLaneOps ops = detail::box_lane_ops();
  for (int n = 0; n < 2000; ++n) {
    // Two boxes sharing a face (A's +x face, B's -x face), turned and moved
    // together: a zero gap, which the margin must keep.
    const Mat3 turn = rotation();
    const Vec3 shift = Vec3(u_(rng_), u_(rng_), u_(rng_)) * 100.0;
    const Vec3 ha(0.5, 0.3, 0.2), hb(0.25, 0.1, 0.4);
    const Box a{turn, shift, ha};
    const Box b{turn, shift + turn * Vec3(ha.x() + hb.x(), 0.05, -0.1), hb};
    const StoredBox sa = stored(a.axes, a.centre, a.half);
    const double margin = 0x1.0p-40 * 400.0;
    EXPECT_FALSE(ops.gap(sa.data.data(), lanes(ops, b), margin) > 0) << "turn " << n;
  }
}

/// The widest gap between a box and a triangle over the thirteen
/// separating axes (the box's three, the normal, the nine edge pairs),
/// each normalized: negative exactly when they meet.
double reference_triangle_gap(const Box& box, const std::array<Vec3, 3>& t, int axes = 13) {
  std::vector<Vec3> normals;
  for (int i = 0; i < 3; ++i) normals.push_back(box.axes.col(i));
  normals.push_back((t[1] - t[0]).cross(t[2] - t[0]));
  for (int i = 0; i < 3; ++i) {
    for (int k = 0; k < 3; ++k) normals.push_back(box.axes.col(i).cross(t[(k + 1) % 3] - t[k]));
  }
  double widest = -std::numeric_limits<double>::infinity();
  for (int a = 0; a < axes; ++a) {
    const double length = normals[a].norm();
    if (length < 1e-12) continue;
    const Vec3 n = normals[a] / length;
    double radius = 0;
    for (int k = 0; k < 3; ++k) radius += box.half[k] * std::abs(n.dot(box.axes.col(k)));
    const double c = n.dot(box.centre);
    double lo = std::numeric_limits<double>::infinity(), hi = -lo;
    for (const Vec3& p : t) {
      lo = std::min(lo, n.dot(p));
      hi = std::max(hi, n.dot(p));
    }
    widest = std::max({widest, lo - (c + radius), (c - radius) - hi});
  }
  return widest;
}

TEST_F(BoxLanes, WideTriangleTestGivesTheScalarVerdict) {
  const detail::BoxLaneOps wide = detail::box_lane_ops_avx2();
  if (!wide.meets_triangle) GTEST_SKIP() << "no AVX2 lanes on this build or processor";
  const detail::BoxLaneOps scalar = detail::box_lane_ops_scalar();
  int meeting = 0;
  for (int n = 0; n < 20000; ++n) {
    const Box b = box(0.08);
    const StoredBox s = stored(b.axes, b.centre, b.half);
    const Vec3 at = Vec3(u_(rng_), u_(rng_), u_(rng_)) * 0.1;
    const std::array<Vec3, 3> t{at + Vec3(u_(rng_), u_(rng_), u_(rng_)) * 0.2,
                                at + Vec3(u_(rng_), u_(rng_), u_(rng_)) * 0.2,
                                at + Vec3(u_(rng_), u_(rng_), u_(rng_)) * 0.2};
    const detail::TriangleLanes lanes = detail::triangle_lanes(t, n % 2 ? 0.0 : 1e-12);
    const bool w = wide.meets_triangle(s.data.data(), lanes);
    ASSERT_EQ(w, scalar.meets_triangle(s.data.data(), lanes)) << "case " << n;
    meeting += w;
  }
  EXPECT_GT(meeting, 4000);  // both verdicts, often
  EXPECT_LT(meeting, 16000);
}

TEST_F(BoxLanes, TriangleTestNeverPassesOverATriangleThatMeetsTheBox) {
  const detail::BoxLaneOps ops = detail::box_lane_ops();
  int meet = 0, apart = 0;
  for (int n = 0; n < 20000; ++n) {
    const Box b = box(0.1);
    const StoredBox s = stored(b.axes, b.centre, b.half);
    const Vec3 at = Vec3(u_(rng_), u_(rng_), u_(rng_)) * 0.15;
    const double size = std::pow(10.0, -2.0 * std::abs(u_(rng_)));  // slivers to large
    const std::array<Vec3, 3> t{at + Vec3(u_(rng_), u_(rng_), u_(rng_)) * size,
                                at + Vec3(u_(rng_), u_(rng_), u_(rng_)) * size,
                                at + Vec3(u_(rng_), u_(rng_), u_(rng_)) * size};
    const bool meets = ops.meets_triangle(s.data.data(), detail::triangle_lanes(t, 1e-12));
    const double full = reference_triangle_gap(b, t);
    const double own = reference_triangle_gap(b, t, 4);  // the axes the test tries
    if (full < -1e-9) {
      ++meet;
      ASSERT_TRUE(meets) << "case " << n << ": they meet, gap " << full;
    }
    if (own > 1e-9) {
      ++apart;
      ASSERT_FALSE(meets) << "case " << n << ": apart on its own axes by " << own;
    }
  }
  EXPECT_GT(meet, 2000);
  EXPECT_GT(apart, 2000);
}

TEST_F(BoxLanes, ATriangleLyingOnAFaceMeetsTheBoxAtAnyTurn) {
  const detail::BoxLaneOps ops = detail::box_lane_ops();
  for (int n = 0; n < 2000; ++n) {
    // A triangle in the plane of the box's +y face, far from the origin.
    const Mat3 turn = rotation();
    const Vec3 shift = Vec3(u_(rng_), u_(rng_), u_(rng_)) * 100.0;
    const Box b{turn, shift, Vec3(0.5, 0.3, 0.2)};
    const std::array<Vec3, 3> t{shift + turn * Vec3(0.4, 0.3, 0.1),
                                shift + turn * Vec3(0.9, 0.3, -0.6),
                                shift + turn * Vec3(-0.2, 0.3, 0.5)};
    const double margin = 0x1.0p-36 * 400.0;
    EXPECT_TRUE(ops.meets_triangle(stored(b.axes, b.centre, b.half).data.data(),
                                   detail::triangle_lanes(t, margin)))
        << "turn " << n;
  }
}

}  // namespace
}  // namespace dovetail::collision
