// Distances between parts of a CollisionWorld: exact level against brute
// force, hull level against GJK on the hulls, warm start against cold start
// over coherent frames, and the same bits for any thread count.

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <limits>
#include <memory>
#include <stdexcept>
#include <vector>

#include "dovetail/collision/collision_world.h"
#include "dovetail/collision/convex.h"
#include "dovetail/collision/distance.h"
#include "dovetail/collision/mesh.h"
#include "dovetail/collision/primitives.h"

namespace dovetail::collision {
namespace {

std::shared_ptr<const Mesh> share(Mesh m) { return std::make_shared<const Mesh>(std::move(m)); }

/// X_AB = X_WA^-1 X_WB, computed as the world computes it.
Transform relative(const Transform& X_WA, const Transform& X_WB) {
  Transform X;
  X.R = X_WA.R.transpose() * X_WB.R;
  X.t = X_WA.R.transpose() * (X_WB.t - X_WA.t);
  return X;
}

/// One triangle of a mesh, as a mesh.
Mesh triangle(const Mesh& mesh, std::uint32_t t) {
  const TriangleIndices& f = mesh.triangles.at(t);
  return make_mesh({mesh.vertices[f[0]], mesh.vertices[f[1]], mesh.vertices[f[2]]}, {{0, 1, 2}},
                   "triangle");
}

/// A few primitives on a small circle, each moving towards the centre and
/// back while it spins: the pairs approach, touch, pass through each other
/// and separate again.
struct Scene {
  std::vector<std::shared_ptr<const Mesh>> meshes;
  std::vector<Vec3> centre, spin_axis;
  std::vector<Real> spin_rate;

  Scene() {
    meshes = {share(make_sphere(0.5, 1)), share(make_torus(0.5, 0.15, 16, 8)),
              share(make_box(Vec3(0.4, 0.25, 0.3))), share(make_cylinder(0.2, 1.0, 12))};
    for (std::size_t i = 0; i < meshes.size(); ++i) {
      const Real angle = 2 * M_PI * static_cast<Real>(i) / static_cast<Real>(meshes.size());
      centre.emplace_back(1.1 * std::cos(angle), 1.1 * std::sin(angle), 0.1 * static_cast<Real>(i));
      spin_axis.push_back(Vec3(1, 2 + static_cast<Real>(i), 3).normalized());
      spin_rate.push_back(0.02 * static_cast<Real>(i + 1));
    }
  }

  Transform pose(std::size_t i, int frame) const {
    Transform X;
    X.R = Eigen::AngleAxis<Real>(spin_rate[i] * frame, spin_axis[i]).toRotationMatrix();
    X.t = centre[i] * (0.55 + 0.45 * std::cos(0.05 * frame));
    return X;
  }
};

TEST(WorldDistance, ExactLevelEqualsBruteForceOverFrames) {
  const Scene scene;
  CollisionWorld world;
  std::vector<PartId> ids;
  for (std::size_t i = 0; i < scene.meshes.size(); ++i) {
    ids.push_back(world.add_part({.mesh = scene.meshes[i], .X_WP = scene.pose(i, 0)}));
  }
  int queries = 0, colliding = 0;
  for (int frame = 0; frame < 64; frame += 3) {
    for (std::size_t i = 0; i < ids.size(); ++i) world.set_pose(ids[i], scene.pose(i, frame));
    const StepResult& step = world.step();
    for (std::size_t i = 0; i < ids.size(); ++i) {
      for (std::size_t j = i + 1; j < ids.size(); ++j) {
        SCOPED_TRACE(testing::Message() << "frame " << frame << " pair " << i << ", " << j);
        const Transform X_WA = scene.pose(i, frame), X_WB = scene.pose(j, frame);
        const DistanceResult brute =
            distance_brute(*scene.meshes[i], *scene.meshes[j], relative(X_WA, X_WB));
        const PartDistance d = world.distance(ids[i], ids[j]);
        ++queries;
        EXPECT_EQ(d.level, LevelOfDetail::kExact);
        EXPECT_EQ(d.distance, brute.distance);
        // The nearest pair need not be unique (parallel faces): the points are
        // those of the reported triangle pair, as far apart as the meshes;
        // intersecting, a common point.
        const Transform X_AB = relative(X_WA, X_WB);
        const DistanceResult pair = distance_brute(triangle(*scene.meshes[i], d.triangle_a),
                                                   triangle(*scene.meshes[j], d.triangle_b), X_AB);
        EXPECT_EQ(pair.distance, d.distance);
        EXPECT_NEAR((d.p_W - d.q_W).norm(), d.distance, 1e-12);
        if (d.distance == 0) {
          EXPECT_EQ(d.p_W, d.q_W);
        }
        EXPECT_EQ(d.gjk_iterations, 0);
        // 0 exactly when the pipeline reports the pair colliding.
        const bool in_contact = std::find(step.colliding.begin(), step.colliding.end(),
                                          PartPair{ids[i], ids[j]}) != step.colliding.end();
        EXPECT_EQ(d.intersecting, in_contact);
        EXPECT_EQ(d.distance == 0, in_contact);
        colliding += in_contact;
        // Swapped roles: the same distance, the points swapped.
        const PartDistance swapped = world.distance(ids[j], ids[i]);
        EXPECT_EQ(swapped.distance, d.distance);
        EXPECT_EQ(swapped.p_W, d.q_W);
        EXPECT_EQ(swapped.q_W, d.p_W);
        EXPECT_EQ(swapped.triangle_a, d.triangle_b);
        // Tolerance queries around the distance.
        for (const Real eps : {0.0, 0.5 * d.distance, d.distance, 1.5 * d.distance, 0.1}) {
          EXPECT_EQ(world.within(ids[i], ids[j], eps), brute.distance <= eps) << eps;
        }
      }
    }
  }
  std::printf("[ distance ] exact level: %d pair queries, %d colliding, all equal to brute force\n",
              queries, colliding);
  EXPECT_GT(colliding, 0);
  EXPECT_LT(colliding, queries);
}

TEST(WorldDistance, HullLevelEqualsGjkOnTheHulls) {
  const Scene scene;
  CollisionWorld world;
  std::vector<PartId> ids;
  std::vector<ConvexHull> hulls;
  for (std::size_t i = 0; i < scene.meshes.size(); ++i) {
    ids.push_back(world.add_part(
        {.mesh = scene.meshes[i], .X_WP = scene.pose(i, 0), .level = LevelOfDetail::kHull}));
    hulls.push_back(compute_convex_hull(scene.meshes[i]->vertices, scene.meshes[i]->source));
  }
  std::vector<GjkCache> caches(ids.size() * ids.size());
  int intersecting = 0, queries = 0;
  for (int frame = 0; frame < 64; ++frame) {
    for (std::size_t i = 0; i < ids.size(); ++i) world.set_pose(ids[i], scene.pose(i, frame));
    for (std::size_t i = 0; i < ids.size(); ++i) {
      for (std::size_t j = i + 1; j < ids.size(); ++j) {
        SCOPED_TRACE(testing::Message() << "frame " << frame << " pair " << i << ", " << j);
        const Transform X_WA = scene.pose(i, frame);
        const Transform X_AB = relative(X_WA, scene.pose(j, frame));
        const GjkResult g = gjk(hulls[i], hulls[j], X_AB, &caches[i * ids.size() + j]);
        const PartDistance d = world.distance(ids[i], ids[j]);
        ++queries;
        intersecting += d.intersecting;
        EXPECT_EQ(d.level, LevelOfDetail::kHull);
        EXPECT_EQ(d.distance, g.distance);
        EXPECT_EQ(d.intersecting, g.intersecting);
        EXPECT_EQ(d.p_W, X_WA.apply(g.closest_a));
        EXPECT_EQ(d.q_W, X_WA.apply(g.closest_b));
        EXPECT_EQ(d.feature_a, g.feature_a);
        EXPECT_EQ(d.feature_b, g.feature_b);
        EXPECT_EQ(d.gjk_iterations, g.iterations);
        EXPECT_EQ(d.warm_started, frame > 0);
        EXPECT_EQ(d.triangle_a, kNoTriangle);
        // A cold start finds the same distance up to GJK's tolerance.
        const GjkResult cold = gjk(hulls[i], hulls[j], X_AB);
        EXPECT_EQ(cold.intersecting, g.intersecting);
        EXPECT_NEAR(cold.distance, g.distance, 1e-9);
        // The hulls are never farther apart than the meshes.
        EXPECT_LE(d.distance,
                  distance_brute(*scene.meshes[i], *scene.meshes[j], X_AB).distance + 1e-12);
      }
    }
  }
  std::printf("[ distance ] hull level: %d pair queries, %d intersecting, all equal to GJK\n",
              queries, intersecting);
  EXPECT_GT(intersecting, 0);
  EXPECT_LT(intersecting, queries);
}

TEST(WorldDistance, WarmStartTakesFewerIterationsThanCold) {
  const Scene scene;
  CollisionWorld warm_world, cold_world;
  std::vector<PartId> warm_ids, cold_ids;
  for (std::size_t i = 0; i < scene.meshes.size(); ++i) {
    const PartDef def{.mesh = scene.meshes[i], .X_WP = scene.pose(i, 0)};
    warm_ids.push_back(warm_world.add_part(def));
    cold_ids.push_back(cold_world.add_part(def));
  }
  long warm = 0, cold = 0, queries = 0;
  const PartDistanceRequest hull{.level = LevelOfDetail::kHull};
  const PartDistanceRequest hull_cold{.level = LevelOfDetail::kHull, .warm_start = false};
  for (int frame = 0; frame < 400; ++frame) {  // 90 Hz-like small steps
    for (std::size_t i = 0; i < warm_ids.size(); ++i) {
      warm_world.set_pose(warm_ids[i], scene.pose(i, frame));
      cold_world.set_pose(cold_ids[i], scene.pose(i, frame));
    }
    for (std::size_t i = 0; i < warm_ids.size(); ++i) {
      for (std::size_t j = i + 1; j < warm_ids.size(); ++j) {
        const PartDistance w = warm_world.distance(warm_ids[i], warm_ids[j], hull);
        const PartDistance c = cold_world.distance(cold_ids[i], cold_ids[j], hull_cold);
        EXPECT_FALSE(c.warm_started);
        EXPECT_EQ(w.warm_started, frame > 0);
        EXPECT_EQ(w.intersecting, c.intersecting);
        EXPECT_NEAR(w.distance, c.distance, 1e-9);
        warm += w.gjk_iterations;
        cold += c.gjk_iterations;
        ++queries;
      }
    }
  }
  std::printf(
      "[ distance ] coherent frames: %ld hull-level queries, GJK iterations warm %ld (%.2f per "
      "query), cold %ld (%.2f per query)\n",
      queries, warm, static_cast<double>(warm) / static_cast<double>(queries), cold,
      static_cast<double>(cold) / static_cast<double>(queries));
  EXPECT_LT(warm, cold);
}

TEST(WorldDistance, ZeroWhenColliding) {
  const auto sphere = share(make_sphere(0.5, 2));
  const auto box = share(make_box(Vec3(0.5, 0.5, 0.5)));
  CollisionWorld world;
  Transform X_WB;
  X_WB.t = Vec3(0.8, 0.1, 0);  // sphere and box overlap by 0.2
  const PartId a = world.add_part({.mesh = sphere, .X_WP = {}});
  const PartId b = world.add_part({.mesh = box, .X_WP = X_WB});
  for (const LevelOfDetail level : {LevelOfDetail::kHull, LevelOfDetail::kExact}) {
    const PartDistance d = world.distance(a, b, {.level = level});
    EXPECT_EQ(d.level, level);
    EXPECT_EQ(d.distance, 0);
    EXPECT_TRUE(d.intersecting);
    EXPECT_TRUE(world.within(a, b, 0, {.level = level}));
  }
  EXPECT_EQ(world.distance(a, b).p_W, world.distance(a, b).q_W);  // exact: a common point
  // Apart: both levels measure the meshes' distance (both parts are convex).
  X_WB.t = Vec3(1.3, 0.1, 0);
  world.set_pose(b, X_WB);
  const Real apart = distance_brute(*sphere, *box, X_WB).distance;
  ASSERT_GT(apart, 0.25);
  for (const LevelOfDetail level : {LevelOfDetail::kHull, LevelOfDetail::kExact}) {
    const PartDistance d = world.distance(a, b, {.level = level});
    EXPECT_FALSE(d.intersecting);
    EXPECT_NEAR(d.distance, apart, 1e-12);
    EXPECT_NEAR((d.p_W - d.q_W).norm(), apart, 1e-12);
    EXPECT_FALSE(world.within(a, b, apart - 0.01, {.level = level}));
    EXPECT_TRUE(world.within(a, b, apart + 0.01, {.level = level}));
  }
}

TEST(WorldDistance, LevelFollowsThePairAndFlatPartsAreExact) {
  const auto sphere = share(make_sphere(0.5, 1));
  const auto sheet = share(make_wavy_sheet(0.4, 0.0, 1.0, 4));  // flat: no hull
  CollisionWorld world;
  Transform X;
  X.t = Vec3(1.5, 0, 0);
  const PartId a = world.add_part({.mesh = sphere, .X_WP = {}});
  const PartId b = world.add_part({.mesh = sphere, .X_WP = X, .level = LevelOfDetail::kHull});
  X.t = Vec3(0, 2, 0);
  const PartId c = world.add_part({.mesh = sheet, .X_WP = X, .level = LevelOfDetail::kBox});
  EXPECT_EQ(world.distance(a, b).level, LevelOfDetail::kHull);  // the coarser part's level
  world.set_pair_level(a, b, LevelOfDetail::kExact);
  EXPECT_EQ(world.distance(a, b).level, LevelOfDetail::kExact);
  world.set_pair_level(a, b, LevelOfDetail::kBox);
  EXPECT_EQ(world.distance(a, b).level, LevelOfDetail::kHull);  // box pairs are measured on hulls
  EXPECT_EQ(world.distance(a, b, {.level = LevelOfDetail::kExact}).level, LevelOfDetail::kExact);
  // The flat sheet has no hull: measured exactly whatever is asked.
  EXPECT_EQ(world.distance(a, c).level, LevelOfDetail::kExact);
  EXPECT_EQ(world.distance(a, c, {.level = LevelOfDetail::kHull}).level, LevelOfDetail::kExact);
  EXPECT_EQ(world.distance(a, c).distance,
            distance_brute(*sphere, *sheet, relative(world.pose(a), world.pose(c))).distance);
}

TEST(WorldDistance, DistanceModelsAreBuiltOncePerMesh) {
  const auto sphere = share(make_sphere(0.5, 2));
  CollisionWorld world;
  Transform X;
  X.t = Vec3(1.5, 0, 0);
  const PartId a = world.add_part({.mesh = sphere, .X_WP = {}});
  const PartId b = world.add_part({.mesh = sphere, .X_WP = X});
  X.t = Vec3(0, 1.5, 0);
  const PartId c = world.add_part({.mesh = sphere, .X_WP = X});
  world.prepare();
  const std::size_t before = world.model_bytes();
  world.distance(a, b);
  const std::size_t after = world.model_bytes();
  EXPECT_EQ(after - before, build_distance_model(sphere)->info().bytes);
  world.distance(b, c);
  world.within(a, c, 0.1);
  EXPECT_EQ(world.model_bytes(), after);
}

TEST(WorldDistance, UnknownOrRemovedPartThrows) {
  const auto sphere = share(make_sphere(0.5, 1));
  CollisionWorld world;
  Transform X;
  X.t = Vec3(2, 0, 0);
  const PartId a = world.add_part({.mesh = sphere, .X_WP = {}});
  const PartId b = world.add_part({.mesh = sphere, .X_WP = X});
  EXPECT_THROW(world.distance(a, PartId{}), std::invalid_argument);
  EXPECT_THROW(world.distance(PartId{7, 0}, a), std::invalid_argument);
  EXPECT_THROW(world.distance(a, a), std::invalid_argument);
  EXPECT_THROW(world.within(a, b, -1), std::invalid_argument);
  EXPECT_THROW(world.within(a, b, std::numeric_limits<Real>::quiet_NaN()), std::invalid_argument);
  world.distance(a, b, {.level = LevelOfDetail::kHull});
  world.remove_part(b);
  EXPECT_THROW(world.distance(a, b), std::invalid_argument);
  EXPECT_THROW(world.within(b, a, 1), std::invalid_argument);
  // The slot is reused with a new generation: the old id stays stale, the new one works,
  // and the new pair starts without the removed pair's cache.
  const PartId d = world.add_part({.mesh = sphere, .X_WP = X});
  EXPECT_EQ(d.index, b.index);
  EXPECT_THROW(world.distance(a, b), std::invalid_argument);
  const PartDistance r = world.distance(a, d, {.level = LevelOfDetail::kHull});
  EXPECT_FALSE(r.warm_started);
  EXPECT_NEAR(r.distance, distance_brute(*sphere, *sphere, X).distance, 1e-12);
}

TEST(WorldDistance, SameBitsForOneTwoAndEightThreads) {
  const Scene scene;
  std::vector<std::vector<PartDistance>> runs;
  for (const int threads : {1, 2, 8}) {
    CollisionWorld world({.threads = threads});
    std::vector<PartId> ids;
    for (std::size_t i = 0; i < scene.meshes.size(); ++i) {
      ids.push_back(
          world.add_part({.mesh = scene.meshes[i],
                          .X_WP = scene.pose(i, 0),
                          .level = i % 2 ? LevelOfDetail::kHull : LevelOfDetail::kExact}));
    }
    std::vector<PartDistance> out;
    for (int frame = 0; frame < 40; frame += 2) {
      for (std::size_t i = 0; i < ids.size(); ++i) world.set_pose(ids[i], scene.pose(i, frame));
      world.step();  // shares the pairs' GJK caches with the distance queries
      for (std::size_t i = 0; i < ids.size(); ++i) {
        for (std::size_t j = i + 1; j < ids.size(); ++j)
          out.push_back(world.distance(ids[i], ids[j]));
      }
    }
    runs.push_back(std::move(out));
  }
  for (std::size_t r = 1; r < runs.size(); ++r) {
    ASSERT_EQ(runs[r].size(), runs[0].size());
    for (std::size_t k = 0; k < runs[0].size(); ++k) {
      const PartDistance &x = runs[0][k], &y = runs[r][k];
      EXPECT_EQ(x.distance, y.distance);
      EXPECT_EQ(x.p_W, y.p_W);
      EXPECT_EQ(x.q_W, y.q_W);
      EXPECT_EQ(x.level, y.level);
      EXPECT_EQ(x.gjk_iterations, y.gjk_iterations);
      EXPECT_EQ(x.feature_a, y.feature_a);
      EXPECT_EQ(x.triangle_a, y.triangle_a);
      EXPECT_EQ(x.stats.volume_tests, y.stats.volume_tests);
    }
  }
}

}  // namespace
}  // namespace dovetail::collision
