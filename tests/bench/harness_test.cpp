// The benchmark protocols shared by `dovetail bench` and the bench programs:
// the tumble's poses, and that the protocols count verdicts, false positives
// and false negatives right.

#include "harness.h"

#include <gtest/gtest.h>

#include <cmath>

#include "dovetail/collision/primitives.h"

namespace dovetail::bench {
namespace {

using collision::Real;
using collision::Transform;
using collision::Vec3;

MeshPtr shared(collision::Mesh mesh) {
  return std::make_shared<const collision::Mesh>(std::move(mesh));
}

TEST(Tumble, DistancesIncludeBothEndsWithoutDrift) {
  const std::vector<Real> d = collision::tumble_distances({});
  ASSERT_EQ(d.size(), 31u);
  EXPECT_EQ(d.front(), 0.0);
  EXPECT_NEAR(d.back(), 3.0, 1e-12);
  EXPECT_EQ(d[7], 7 * 0.1);  // k * step, not a running sum
  const std::vector<Real> odd =
      collision::tumble_distances({.first_distance = 0, .last_distance = 1, .distance_step = 0.3});
  EXPECT_EQ(odd.size(), 4u);  // 0, 0.3, 0.6, 0.9
  EXPECT_THROW(collision::tumble_distances({.first_distance = 1, .last_distance = 0}),
               std::invalid_argument);
  EXPECT_THROW(collision::tumble_distances({.distance_step = 0}), std::invalid_argument);
  EXPECT_THROW(collision::tumble_poses({.turns = 0}), std::invalid_argument);
}

TEST(Tumble, PosesTurnOnceRoundAtEveryDistance) {
  const collision::TumbleSettings settings{
      .first_distance = 0.5, .last_distance = 1.5, .distance_step = 0.5, .turns = 8};
  const std::vector<collision::TumblePose> poses = collision::tumble_poses(settings);
  ASSERT_EQ(poses.size(), 3u * 8u);
  for (std::size_t i = 0; i < poses.size(); ++i) {
    const collision::TumblePose& p = poses[i];
    EXPECT_EQ(p.distance_index, i / 8);
    EXPECT_EQ(p.X_AB.t, Vec3(0.5 * static_cast<Real>(1 + i / 8), 0, 0));
    EXPECT_LT((p.X_AB.R * p.X_AB.R.transpose() - collision::Mat3::Identity()).norm(), 1e-12);
    EXPECT_NEAR(p.X_AB.R.determinant(), 1.0, 1e-12);
  }
  EXPECT_EQ(poses[0].X_AB.R, collision::Mat3::Identity());  // every turn starts unturned
  // Half a turn about the oblique axis and a full one about z: a half turn about the axis.
  const Vec3 axis = Vec3(1, 2, 3).normalized();
  EXPECT_LT((poses[4].X_AB.R * axis - axis).norm(), 1e-12);
  EXPECT_NEAR(poses[4].X_AB.R.trace(), -1.0, 1e-12);
}

TEST(Harness, NormalizedFitsTheUnitBoxCentred) {
  collision::Mesh box = collision::make_box(Vec3(3, 1, 0.5));
  for (Vec3& v : box.vertices) v += Vec3(100, -7, 2);
  const collision::Mesh m = normalized(box);
  Vec3 lo = m.vertices.front(), hi = lo;
  for (const Vec3& v : m.vertices) {
    lo = lo.cwiseMin(v);
    hi = hi.cwiseMax(v);
  }
  EXPECT_NEAR(lo.x(), -1, 1e-12);
  EXPECT_NEAR(hi.x(), 1, 1e-12);
  EXPECT_NEAR(lo.y() + hi.y(), 0, 1e-12);
  EXPECT_NEAR(hi.y() - lo.y(), 2.0 / 3.0, 1e-12);  // scaled uniformly
}

TEST(Harness, TumbleExactMethodsAgreeAndFarPosesAreFree) {
  const MeshPtr a = shared(normalized(collision::make_sphere(1.0, 3)));
  const MeshPtr b = shared(normalized(collision::make_box(Vec3(1, 0.2, 0.2))));  // a bar
  std::vector<Contender> contenders = exact_contenders(a, b);
  contenders.push_back(hull_plane_contender(a, b));
  const collision::TumbleSettings settings{.turns = 24};
  const TumbleResult result = run_tumble(contenders, settings);
  ASSERT_EQ(result.cells.size(), contenders.size());
  EXPECT_EQ(result.reference, 0u);
  for (std::size_t c = 0; c < contenders.size(); ++c) {
    EXPECT_EQ(result.disagreements[c], 0u) << contenders[c].name;
    for (const TumbleCell& cell : result.cells[c]) EXPECT_EQ(cell.colliding + cell.free, 24);
    // Both fit in a ball of radius 1.04: centres 3 apart never touch; at 0 the
    // bar's ends always pierce the sphere.
    EXPECT_EQ(result.cells[c].back().colliding, 0) << contenders[c].name;
    EXPECT_EQ(result.cells[c].front().free, 0) << contenders[c].name;
  }
  const std::size_t hull_plane = contenders.size() - 1;
  for (std::size_t d = 0; d < result.distances.size(); ++d) {
    // The convex level is conservative: it never calls a colliding pose free.
    EXPECT_GE(result.cells[hull_plane][d].colliding, result.cells[0][d].colliding);
  }
}

TEST(Harness, PosesCountFalsePositivesAndNegativesAgainstTheExactAnswer) {
  const MeshPtr a = shared(collision::make_sphere(0.6, 3));
  const MeshPtr b = shared(collision::make_torus(0.7, 0.25, 32, 16));
  collision::ContactPoseSettings settings;
  settings.directions = 12;
  const auto model_a = collision::build_model(collision::Method::kObb, a);
  const auto model_b = collision::build_model(collision::Method::kObb, b);
  const std::vector<collision::SampledPose> poses =
      collision::contact_distance_poses(*model_a, *model_b, settings);

  std::vector<Contender> contenders = exact_contenders(a, b);
  const std::size_t exact_count = contenders.size();
  for (Contender& c : approximate_contenders(a, b)) contenders.push_back(std::move(c));
  const auto constant = [](std::string name, std::string family, bool exact, bool verdict) {
    return Contender{
        .name = std::move(name),
        .family = std::move(family),
        .exact = exact,
        .query = [verdict](const Transform&, collision::CollideStats&) { return verdict; }};
  };
  contenders.push_back(constant("always", "volume", false, true));
  contenders.push_back(constant("never", "volume", false, false));
  const PoseResult result = run_contact_poses(contenders, poses, settings.gaps, 2);

  ASSERT_EQ(result.poses, poses.size());
  ASSERT_GT(result.colliding, 0u);
  ASSERT_LT(result.colliding, poses.size());
  for (std::size_t c = 0; c < exact_count; ++c) {
    EXPECT_EQ(result.rows[c].false_positives + result.rows[c].false_negatives, 0u)
        << contenders[c].name;
    EXPECT_GT(result.rows[c].volume_tests, 0) << contenders[c].name;
  }
  EXPECT_TRUE(exact_contenders_wrong(contenders, result).empty());
  // Every approximation of the pipeline is conservative: no false negative.
  for (std::size_t c = exact_count; c + 2 < contenders.size(); ++c) {
    EXPECT_EQ(result.rows[c].false_negatives, 0u) << contenders[c].name;
  }
  const PoseRow& always = result.rows[contenders.size() - 2];
  const PoseRow& never = result.rows.back();
  EXPECT_EQ(always.false_positives, poses.size() - result.colliding);
  EXPECT_EQ(always.false_negatives, 0u);
  EXPECT_EQ(never.false_positives, 0u);
  EXPECT_EQ(never.false_negatives, result.colliding);
  EXPECT_EQ(never.us_per_gap.size(), settings.gaps.size());
  EXPECT_GT(result.best_exact_us, 0);

  // An exact method that is wrong is named.
  contenders.push_back(constant("broken", "exact", true, true));
  const PoseResult with_broken = run_contact_poses(contenders, poses, settings.gaps, 1);
  EXPECT_EQ(exact_contenders_wrong(contenders, with_broken), "broken");
}

}  // namespace
}  // namespace dovetail::bench
