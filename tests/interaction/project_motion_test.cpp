// The motion projection of sliding (step 4): the exact closest motion that
// the contacts allow, checked against brute force over every active set.

#include <gtest/gtest.h>

#include <cmath>
#include <cstdint>
#include <optional>
#include <random>
#include <vector>

#include "dovetail/interaction/sliding.h"

namespace dovetail::interaction {
namespace {

/// The metric's inverse diag(1, 1, 1, 1/L^2, 1/L^2, 1/L^2).
Motion metric_inverse(Real length) {
  Motion m;
  m << 1, 1, 1, 1 / (length * length), 1 / (length * length), 1 / (length * length);
  return m;
}

/// The projection by brute force: for every subset S of at most six constraints, the
/// closest motion with S tight; the one that meets every constraint with non-negative
/// multipliers is the projection (unique: the problem is strictly convex).
std::optional<Motion> brute_force(const Motion& wanted, const std::vector<Motion>& a,
                                  const std::vector<Real>& b, Real length) {
  const Motion m_inv = metric_inverse(length);
  const std::size_t m = a.size();
  std::optional<Motion> best;
  for (std::uint32_t set = 0; set < (1u << m); ++set) {
    std::vector<std::size_t> s;
    for (std::size_t i = 0; i < m; ++i) {
      if (set & (1u << i)) s.push_back(i);
    }
    if (s.size() > 6) continue;
    Eigen::MatrixXd N(6, static_cast<Eigen::Index>(s.size()));
    Eigen::VectorXd rhs(static_cast<Eigen::Index>(s.size()));
    for (std::size_t j = 0; j < s.size(); ++j) {
      N.col(static_cast<Eigen::Index>(j)) = a[s[j]];
      rhs[static_cast<Eigen::Index>(j)] = b[s[j]] - a[s[j]].dot(wanted);
    }
    Motion x = wanted;
    if (!s.empty()) {
      const Eigen::MatrixXd G = N.transpose() * m_inv.asDiagonal() * N;
      Eigen::FullPivLU<Eigen::MatrixXd> lu(G);
      if (lu.rank() < static_cast<Eigen::Index>(s.size())) continue;
      const Eigen::VectorXd lambda = lu.solve(rhs);
      if ((lambda.array() < -1e-12).any()) continue;
      x += m_inv.asDiagonal() * (N * lambda);
    }
    bool feasible = true;
    for (std::size_t i = 0; i < m; ++i) feasible = feasible && a[i].dot(x) >= b[i] - 1e-12;
    if (feasible) {
      best = x;
      break;
    }
  }
  return best;
}

TEST(ProjectMotion, EqualsTheBruteForceProjectionOnRandomContacts) {
  std::mt19937_64 rng(7);
  std::normal_distribution<Real> normal;
  std::uniform_real_distribution<Real> offset(-1e-3, 1e-3);
  int constrained = 0, infeasible = 0;
  for (int trial = 0; trial < 400; ++trial) {
    const std::size_t m = 1 + static_cast<std::size_t>(trial % 10);
    const Real length = 0.05 * (1 + trial % 3);
    std::vector<Motion> a(m);
    std::vector<Real> b(m);
    for (std::size_t i = 0; i < m; ++i) {
      // A contact's row (n, r x n) at a point r within the part's size.
      Vec3 n(normal(rng), normal(rng), normal(rng));
      n.normalize();
      const Vec3 r = 0.03 * Vec3(normal(rng), normal(rng), normal(rng));
      a[i] << n, r.cross(n);
      b[i] = trial % 2 == 0 ? 0 : offset(rng);
    }
    Motion wanted;
    for (int k = 0; k < 6; ++k) wanted[k] = (k < 3 ? 1e-2 : 0.2) * normal(rng);
    const std::optional<Motion> x = project_motion(wanted, a, b, length);
    const std::optional<Motion> expected = brute_force(wanted, a, b, length);
    ASSERT_EQ(x.has_value(), expected.has_value()) << "trial " << trial;
    if (!x) {
      ++infeasible;
      continue;
    }
    if ((*x - wanted).norm() > 0) ++constrained;
    EXPECT_LT((*x - *expected).norm(), 1e-9 * (1 + wanted.norm())) << "trial " << trial;
    for (std::size_t i = 0; i < m; ++i) EXPECT_GE(a[i].dot(*x), b[i] - 1e-14) << "trial " << trial;
  }
  // The instances exercise the method: most move, and with b = 0 none is infeasible
  // (standing still always meets n . x >= 0).
  EXPECT_GT(constrained, 300);
  EXPECT_LT(infeasible, 200);
}

TEST(ProjectMotion, APegInAHoleKeepsOnlyTheMotionAlongTheAxis) {
  // Contacts all around the hole's wall at two heights, normals pointing inward at the peg.
  std::vector<Motion> a;
  for (int ring = 0; ring < 2; ++ring) {
    for (int k = 0; k < 8; ++k) {
      const Real phi = 2 * std::acos(Real{-1}) * k / 8;
      const Vec3 p(0.01 * std::cos(phi), 0.01 * std::sin(phi), ring == 0 ? 0.0 : 0.03);
      const Vec3 n = -Vec3(p.x(), p.y(), 0).normalized();
      Motion row;
      row << n, p.cross(n);
      a.push_back(row);
    }
  }
  const std::vector<Real> b(a.size(), 0);
  Motion wanted;
  wanted << 2e-3, -1e-3, -5e-3, 0.02, 0.01, 0.3;
  const std::optional<Motion> x = project_motion(wanted, a, b, 0.1);
  ASSERT_TRUE(x.has_value());
  // Down the axis and about it: both are free; every sideways move and tilt is not.
  EXPECT_NEAR((*x)[2], -5e-3, 1e-15);
  EXPECT_NEAR((*x)[5], 0.3, 1e-12);
  EXPECT_NEAR((*x)[0], 0, 1e-15);
  EXPECT_NEAR((*x)[1], 0, 1e-15);
  EXPECT_NEAR((*x)[3], 0, 1e-12);
  EXPECT_NEAR((*x)[4], 0, 1e-12);
}

TEST(ProjectMotion, ContactsThatAskForMoreRoomThanThereIsHaveNoProjection) {
  // Wedged: out of the left wall by 1 um and out of the right one by 1 um, facing each other.
  Motion left, right;
  left << 1, 0, 0, 0, 0, 0;
  right << -1, 0, 0, 0, 0, 0;
  const std::vector<Motion> a{left, right};
  Motion wanted = Motion::Zero();
  EXPECT_FALSE(project_motion(wanted, a, std::vector<Real>{1e-6, 1e-6}, 0.1).has_value());
  // With no room asked for, standing still (the wanted motion here) is the answer.
  const std::optional<Motion> x = project_motion(wanted, a, std::vector<Real>{0, 0}, 0.1);
  ASSERT_TRUE(x.has_value());
  EXPECT_EQ(*x, Motion::Zero());
}

TEST(ProjectMotion, AnUnconstrainedMotionIsKeptBitForBit) {
  Motion wanted;
  wanted << 1e-3, 2e-3, -3e-3, 0.1, -0.2, 0.05;
  Motion away;
  away << 0, 0, -1, 0, 0, 0;  // met already: wanted moves 3 mm along -z
  const std::vector<Motion> a{away};
  const std::optional<Motion> x = project_motion(wanted, a, std::vector<Real>{0}, 0.1);
  ASSERT_TRUE(x.has_value());
  EXPECT_EQ(*x, wanted);
}

}  // namespace
}  // namespace dovetail::interaction
