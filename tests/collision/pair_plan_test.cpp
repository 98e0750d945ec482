// The pipeline's per-pair plans: what it builds, which level decides a pair,
// and that a tolerance never misses a contact and only adds pairs that are
// within it.

#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdio>
#include <memory>
#include <vector>

#include "dovetail/collision/collision_world.h"
#include "dovetail/collision/containment.h"
#include "dovetail/collision/convex.h"
#include "dovetail/collision/pose_sampling.h"
#include "dovetail/collision/primitives.h"

namespace dovetail::collision {
namespace {

std::shared_ptr<const Mesh> share(Mesh m) { return std::make_shared<const Mesh>(std::move(m)); }

bool convex(const Mesh& mesh) {
  const ConvexHull hull = compute_convex_hull(mesh.vertices, "test");
  return is_closed(mesh) && surface_on_hull(hull, mesh.vertices, mesh.triangles);
}

Transform at(const Vec3& t) {
  Transform X;
  X.t = t;
  return X;
}

TEST(SurfaceOnHull, BoxCylinderAndSphereAreConvexHolesTorusAndDentsAreNot) {
  EXPECT_TRUE(convex(make_box(Vec3(0.4, 0.25, 0.3))));
  EXPECT_TRUE(convex(make_cylinder(0.2, 1.0, 16)));
  EXPECT_TRUE(convex(make_sphere(0.5, 2)));
  EXPECT_FALSE(convex(make_block_with_hole(Vec3(1, 1, 1), 0.3, 0.5, 16)));
  EXPECT_FALSE(convex(make_torus(0.5, 0.15, 24, 12)));
  EXPECT_FALSE(convex(make_tube(0.5, 0.4, 1.0, 16)));
  // A sphere with one vertex pushed inwards: still convex while the vertex
  // stays above its neighbours' plane (about 0.95 of the radius), not below.
  Mesh dented = make_sphere(0.5, 2);
  dented.vertices[0] *= 0.98;
  EXPECT_TRUE(convex(dented));
  dented.vertices[0] *= 0.9 / 0.98;
  EXPECT_FALSE(convex(dented));
}

TEST(PairPlan, ExactPairsGoToObbTreesWithAFrontAndTheSeparatingPlaneOnceItPays) {
  // A ball hopping round a fixed torus, apart from it but inside its box: the
  // polygon level answers "apart" every step. The pair's separating-plane
  // test waits until those answers have cost as much work as the two hulls;
  // then the hulls are built, the pair is planned again, and the plane
  // separates it. Every verdict equals a brute-force query's.
  const auto torus = share(make_torus(0.5, 0.15, 12, 6));
  const auto ball = share(make_sphere(0.2, 1));
  CollisionWorld world;
  const PartId a = world.add_part({.mesh = torus, .X_WP = {}, .movable = false});
  const PartId b = world.add_part({.mesh = ball, .X_WP = at(Vec3(0.62, 0.62, 0))});
  const auto brute_torus = build_model(Method::kBrute, torus);
  const auto brute_ball = build_model(Method::kBrute, ball);
  world.step();
  std::vector<PairPlan> plans = world.plans();
  ASSERT_EQ(plans.size(), 1u);
  EXPECT_EQ(plans[0].pair, (PartPair{a, b}));
  EXPECT_EQ(plans[0].level, LevelOfDetail::kExact);
  EXPECT_EQ(plans[0].method, Method::kObb);
  EXPECT_TRUE(plans[0].front);
  EXPECT_FALSE(plans[0].convex_level);
  EXPECT_EQ(plans[0].max_size, 0);
  EXPECT_NE(plans[0].reason.find("OBB"), std::string::npos) << plans[0].reason;
  EXPECT_NE(plans[0].reason.find("once the answers 'apart' have cost as much work as building "
                                 "the hulls"),
            std::string::npos)
      << plans[0].reason;
  const std::uint64_t version = world.plans_version();
  int turned_on_at = -1;
  std::size_t separated = 0;
  for (int step = 1; step < 400; ++step) {
    // Hops between 26 and 66 degrees, 0.88 from the centre: the boxes
    // overlap, the ball is 0.03 off the torus; the front finds little to keep.
    const double angle = 0.8 + 0.35 * std::sin(1.7 * step);
    const Transform X = at(Vec3(0.88 * std::cos(angle), 0.88 * std::sin(angle), 0));
    world.set_pose(b, X);
    const StepResult& r = world.step();
    ASSERT_EQ(r.colliding.size(), brute_torus->collide(*brute_ball, X).colliding ? 1u : 0u)
        << "step " << step;
    separated += r.stats.convex_separated;
    if (turned_on_at < 0 && world.plans()[0].convex_level) turned_on_at = step;
  }
  ASSERT_GT(turned_on_at, 1) << "the test came at once, before any work was spent";
  EXPECT_GT(world.plans_version(), version);
  plans = world.plans_since(version);
  ASSERT_EQ(plans.size(), 1u);
  EXPECT_TRUE(plans[0].convex_level);
  EXPECT_NE(plans[0].reason.find("after the separating-plane test, turned on once the answers "
                                 "'apart' had cost as much work as building the hulls"),
            std::string::npos)
      << plans[0].reason;
  EXPECT_GT(separated, 0u);
  std::printf("[ plan     ] separating-plane test turned on at step %d, then separated %zu\n",
              turned_on_at, separated);
}

TEST(PairPlan, DeferredPlansAndTheirWorkAreTheSameAtAnyThreadCount) {
  // A light pair and a heavy one, both deferred, circling the torus for 300
  // steps: the heavy pair's queries would be split over the threads, which
  // does other work than one query with a front, so a deferred pair is
  // decided whole. The plans, their versions and every step's counters are
  // the same at 1, 2 and 8 threads.
  const auto torus = share(make_torus(0.5, 0.15, 32, 16));  // 1,024 triangles
  const auto big = share(make_sphere(0.2, 3));              // 1,280: heavy with the torus
  const auto small = share(make_sphere(0.2, 1));            // 80
  std::vector<std::vector<PairPlan>> plans;
  std::vector<std::vector<std::array<std::size_t, 5>>> counters;
  for (const int threads : {1, 2, 8}) {
    CollisionWorld world({.threads = threads});
    world.add_part({.mesh = torus, .X_WP = {}, .movable = false});
    const PartId a = world.add_part({.mesh = small, .X_WP = at(Vec3(0.88, 0, 0))});
    const PartId b = world.add_part({.mesh = big, .X_WP = at(Vec3(-0.88, 0, 0))});
    counters.emplace_back();
    for (int step = 0; step < 300; ++step) {
      const double angle = 0.8 + 0.35 * std::sin(1.7 * step);
      const double r = step % 7 == 0 ? 0.7 : 0.88;  // now and then in contact
      world.set_pose(a, at(Vec3(r * std::cos(angle), r * std::sin(angle), 0)));
      world.set_pose(b, at(Vec3(-r * std::cos(angle), -r * std::sin(angle), 0)));
      const StepStats& st = world.step().stats;
      counters.back().push_back({st.convex_tests, st.convex_separated, st.polygon_pairs,
                                 st.colliding_pairs, world.plans_version()});
    }
    plans.push_back(world.plans());
  }
  ASSERT_EQ(plans[0].size(), 2u);
  EXPECT_TRUE(plans[0][0].convex_level) << plans[0][0].reason;  // paid for its hulls
  EXPECT_TRUE(plans[0][1].convex_level) << plans[0][1].reason;  // and so for its hulls
  for (std::size_t k = 1; k < plans.size(); ++k) {
    EXPECT_EQ(counters[k], counters[0]) << "thread run " << k;
    ASSERT_EQ(plans[k].size(), plans[0].size());
    for (std::size_t i = 0; i < plans[0].size(); ++i) {
      EXPECT_EQ(plans[k][i].convex_level, plans[0][i].convex_level);
      EXPECT_EQ(plans[k][i].reason, plans[0][i].reason);
    }
  }
}

TEST(PairPlan, APreparedWorldOrOneGivenAMethodTestsTheSeparatingPlaneAtOnce) {
  // Hulls built beforehand cost the pair nothing: its test runs from the
  // first step. A world given a method builds them when it plans the pair.
  for (const bool given_method : {false, true}) {
    CollisionWorld world(given_method ? WorldSettings{.method = Method::kObb} : WorldSettings{});
    world.add_part({.mesh = share(make_box(Vec3(1, 1, 1))), .X_WP = {}, .movable = false});
    world.add_part({.mesh = share(make_torus(0.5, 0.15, 24, 12)), .X_WP = at(Vec3(0, 0, 1.1))});
    if (!given_method) world.prepare();
    world.step();
    ASSERT_EQ(world.plans().size(), 1u);
    EXPECT_TRUE(world.plans()[0].convex_level) << world.plans()[0].reason;
    EXPECT_EQ(world.plans()[0].reason.find("once the answers"), std::string::npos)
        << world.plans()[0].reason;
  }
}

TEST(PairPlan, AGivenMethodIsUsedWithoutAFront) {
  CollisionWorld world({.method = Method::kBoxtree});
  world.add_part({.mesh = share(make_box(Vec3(1, 1, 1))), .X_WP = {}, .movable = false});
  world.add_part({.mesh = share(make_sphere(0.5, 2)), .X_WP = at(Vec3(0, 0, 1.2))});
  world.step();
  ASSERT_EQ(world.plans().size(), 1u);
  EXPECT_EQ(world.plans()[0].method, Method::kBoxtree);
  EXPECT_FALSE(world.plans()[0].front);
}

TEST(PairPlan, ATolerancePutsConvexPairsOnTheHullLevelAndCutsTheOthers) {
  CollisionWorld world({.tolerance = 1e-3});
  const PartId box =
      world.add_part({.mesh = share(make_box(Vec3(1, 1, 1))), .X_WP = {}, .movable = false});
  const PartId ball =
      world.add_part({.mesh = share(make_sphere(0.5, 2)), .X_WP = at(Vec3(0, 0, 1.2))});
  const PartId ring =
      world.add_part({.mesh = share(make_torus(0.5, 0.15, 24, 12)), .X_WP = at(Vec3(0.3, 0, 1.1))});
  world.step();
  const std::vector<PairPlan> plans = world.plans();
  ASSERT_EQ(plans.size(), 3u);
  for (const PairPlan& p : plans) {
    const bool both_convex =
        (p.pair.a == box || p.pair.a == ball) && (p.pair.b == box || p.pair.b == ball);
    if (both_convex) {
      EXPECT_EQ(p.level, LevelOfDetail::kHull) << p.reason;
      EXPECT_FALSE(p.method.has_value());
    } else {
      EXPECT_EQ(p.level, LevelOfDetail::kExact) << p.reason;
      EXPECT_EQ(p.max_size, 1e-3);
    }
  }
  (void)ring;
}

TEST(PairPlan, TheScenesLevelsComeFirstAndAChangedLevelIsPlannedAgain) {
  CollisionWorld world({.tolerance = 1e-3});
  const PartId a =
      world.add_part({.mesh = share(make_box(Vec3(1, 1, 1))), .X_WP = {}, .movable = false});
  const PartId b = world.add_part({.mesh = share(make_torus(0.5, 0.15, 24, 12)),
                                   .X_WP = at(Vec3(0, 0, 1.1)),
                                   .level = LevelOfDetail::kBox});
  world.step();
  ASSERT_EQ(world.plans().size(), 1u);
  EXPECT_EQ(world.plans()[0].level, LevelOfDetail::kBox);
  const std::uint64_t version = world.plans_version();
  world.set_pair_level(a, b, LevelOfDetail::kHull);
  EXPECT_NE(world.plans_version(), version);
  EXPECT_TRUE(world.plans().empty());
  world.step();
  ASSERT_EQ(world.plans().size(), 1u);
  EXPECT_EQ(world.plans()[0].level, LevelOfDetail::kHull);
}

TEST(PairPlan, PlansSinceAVersionAreTheNewOnesOnly) {
  CollisionWorld world;
  const Mesh box = make_box(Vec3(1, 1, 1));
  const PartId fixed = world.add_part({.mesh = share(box), .X_WP = {}, .movable = false});
  const PartId near = world.add_part({.mesh = share(box), .X_WP = at(Vec3(0.9, 0, 0))});
  const PartId far = world.add_part({.mesh = share(box), .X_WP = at(Vec3(5, 0, 0))});
  world.step();
  EXPECT_EQ(world.plans_since(0), world.plans());
  ASSERT_EQ(world.plans().size(), 1u);
  const std::uint64_t first = world.plans_version();
  EXPECT_TRUE(world.plans_since(first).empty());
  // The far part comes near both: two new pairs, the old one not repeated.
  world.set_pose(far, at(Vec3(0.45, 0.9, 0)));
  world.step();
  const std::vector<PairPlan> made = world.plans_since(first);
  ASSERT_EQ(made.size(), 2u);
  EXPECT_EQ(made[0].pair, (PartPair{fixed, far}));
  EXPECT_EQ(made[1].pair, (PartPair{near, far}));
  EXPECT_EQ(world.plans().size(), 3u);
  // A pair planned again after a new level is new again; a removed part's
  // pairs are gone from both lists.
  const std::uint64_t second = world.plans_version();
  world.set_pair_level(fixed, near, LevelOfDetail::kHull);
  world.remove_part(far);
  world.step();
  const std::vector<PairPlan> again = world.plans_since(second);
  ASSERT_EQ(again.size(), 1u);
  EXPECT_EQ(again[0].pair, (PartPair{fixed, near}));
  EXPECT_EQ(again[0].level, LevelOfDetail::kHull);
  EXPECT_EQ(world.plans_since(0), world.plans());
}

TEST(PairPlan, APartNobodyComesNearGetsNeitherHullNorHierarchy) {
  CollisionWorld world;
  // A large fixed part and a small moving one far from it.
  world.add_part({.mesh = share(make_sphere(1.0, 4)), .X_WP = {}, .movable = false});
  const PartId small =
      world.add_part({.mesh = share(make_box(Vec3(0.1, 0.1, 0.1))), .X_WP = at(Vec3(5, 0, 0))});
  world.step();
  EXPECT_TRUE(world.plans().empty());
  EXPECT_EQ(world.model_bytes(), 0u);
  // Boxes overlapping, parts apart (the box's nearest corner is 1.06 from
  // the centre): the polygon level decides the pair on its hierarchies; the
  // hulls wait until its answers "apart" have cost as much as they would.
  world.set_pose(small, at(Vec3(0.85, 0.85, 0)));
  world.step();
  ASSERT_EQ(world.plans().size(), 1u);
  EXPECT_FALSE(world.plans()[0].convex_level);
  EXPECT_TRUE(world.last_step().colliding.empty());
  EXPECT_EQ(world.last_step().stats.polygon_pairs, 1u);
  const std::size_t hierarchies = world.model_bytes();
  EXPECT_GT(hierarchies, 0u);
  // In contact: decided on the same hierarchies, nothing more built.
  world.set_pose(small, at(Vec3(0.7, 0.7, 0)));
  world.step();
  EXPECT_EQ(world.last_step().colliding.size(), 1u);
  EXPECT_EQ(world.model_bytes(), hierarchies);
}

/// A ball in a ring's hole, 0.05 from its inner side: apart, but the hulls
/// overlap, so the polygon level decides. A tolerance of 0.5 cuts the
/// traversal at box pairs that small and reports contact; one of 0.01 is
/// smaller than any pair of leaf boxes and stays exact.
TEST(PairPlan, TheToleranceCutReportsPairsWithinItAndNoneBeyond) {
  const auto ring = share(make_torus(0.5, 0.15, 24, 12));
  const auto ball = share(make_sphere(0.3, 3));
  for (const Real tolerance : {0.0, 0.01, 0.5}) {
    CollisionWorld world({.tolerance = tolerance, .contacts = ContactDetail::kPairs});
    const PartId a = world.add_part({.mesh = ring, .X_WP = {}, .movable = false});
    const PartId b = world.add_part({.mesh = ball, .X_WP = {}});
    const StepResult& r = world.step();
    EXPECT_EQ(r.stats.polygon_pairs, 1u);
    EXPECT_EQ(r.colliding.size(), tolerance > 0.05 ? 1u : 0u) << "tolerance " << tolerance;
    const PartDistance d = world.distance(a, b, {.level = LevelOfDetail::kExact});
    EXPECT_NEAR(d.distance, 0.05, 0.01);
  }
}

/// Exact and tolerant pipelines side by side on a moving scene: the tolerant
/// one reports every exact contact, and each pair it adds is within the
/// tolerance (as solids: at most that far apart, or one inside the other).
TEST(PairPlan, AToleranceNeverMissesAContactAndAddsOnlyPairsWithinIt) {
  const Real tolerance = 0.25;
  const std::vector<std::shared_ptr<const Mesh>> shapes = {
      share(make_sphere(0.5, 2)), share(make_torus(0.5, 0.15, 24, 12)),
      share(make_box(Vec3(0.4, 0.25, 0.3))), share(make_cylinder(0.2, 1.0, 16))};
  const int n = 24;
  const std::vector<Transform> start = random_poses(n, 1.2, 5);
  const std::vector<Transform> motion = random_poses(n, 0.02, 6);
  CollisionWorld exact({.contacts = ContactDetail::kPairs});
  CollisionWorld tolerant({.tolerance = tolerance, .contacts = ContactDetail::kPairs});
  std::vector<PartId> ids;
  std::vector<Transform> poses = start;
  for (int i = 0; i < n; ++i) {
    ids.push_back(exact.add_part({.mesh = shapes[i % shapes.size()], .X_WP = poses[i]}));
    ASSERT_EQ(tolerant.add_part({.mesh = shapes[i % shapes.size()], .X_WP = poses[i]}), ids[i]);
  }
  std::size_t added = 0, exact_contacts = 0;
  for (int frame = 0; frame < 100; ++frame) {
    for (int i = 0; i < n; ++i) {
      poses[i].t += motion[i].t;
      exact.set_pose(ids[i], poses[i]);
      tolerant.set_pose(ids[i], poses[i]);
    }
    const std::vector<PartPair> want = exact.step().colliding;
    const std::vector<PartPair> got = tolerant.step().colliding;
    exact_contacts += want.size();
    for (const PartPair& p : want) {
      EXPECT_TRUE(std::find(got.begin(), got.end(), p) != got.end()) << "missed, frame " << frame;
    }
    for (const PartPair& p : got) {
      if (std::find(want.begin(), want.end(), p) != want.end()) continue;
      ++added;
      const PartDistance d = exact.distance(p.a, p.b, {.level = LevelOfDetail::kExact});
      if (d.distance <= tolerance) continue;
      // Apart by more than the tolerance as surfaces: then one solid holds the other.
      const Mesh& mesh_a = *shapes[p.a.index % shapes.size()];
      const Mesh& mesh_b = *shapes[p.b.index % shapes.size()];
      const Transform& X_WA = poses[p.a.index];
      const Transform& X_WB = poses[p.b.index];
      const Vec3 b_in_a = X_WA.R.transpose() * (X_WB.apply(mesh_b.vertices[0]) - X_WA.t);
      const Vec3 a_in_b = X_WB.R.transpose() * (X_WA.apply(mesh_a.vertices[0]) - X_WB.t);
      EXPECT_TRUE(point_inside(mesh_a, b_in_a) || point_inside(mesh_b, a_in_b))
          << "frame " << frame << ": added a pair " << d.distance << " apart";
    }
  }
  EXPECT_GT(exact_contacts, 20u);
  std::printf("[ tolerance ] %zu exact contacts, %zu pairs added within %.2f\n", exact_contacts,
              added, tolerance);
  bool hull_level = false;
  for (const PairPlan& p : tolerant.plans())
    hull_level = hull_level || p.level == LevelOfDetail::kHull;
  EXPECT_TRUE(hull_level);
}

}  // namespace
}  // namespace dovetail::collision
