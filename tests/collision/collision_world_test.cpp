// The pipeline must report exactly what testing every pair at the polygon
// level reports, identically for any thread count, with the right begin/end
// changes.

#include "dovetail/collision/collision_world.h"

#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <memory>
#include <vector>

#include "dovetail/collision/pose_sampling.h"
#include "dovetail/collision/primitives.h"

namespace dovetail::collision {
namespace {

std::shared_ptr<const Mesh> share(Mesh m) { return std::make_shared<const Mesh>(std::move(m)); }

/// Parts moving coherently (constant velocity and spin, bouncing inside a box).
struct MovingScene {
  std::vector<std::shared_ptr<const Mesh>> meshes;
  std::vector<Transform> poses;
  std::vector<Vec3> velocity;
  std::vector<Vec3> spin;  ///< axis * angle per frame
  Real half_size = 2.0;

  explicit MovingScene(int parts, std::uint64_t seed) {
    const std::vector<std::shared_ptr<const Mesh>> shapes = {
        share(make_sphere(0.5, 2)), share(make_torus(0.5, 0.15, 24, 12)),
        share(make_box(Vec3(0.4, 0.25, 0.3))), share(make_cylinder(0.2, 1.0, 16)),
        share(make_wavy_sheet(0.4, 0.05, 6.0, 8))};  // the sheet is open and nearly flat
    const std::vector<Transform> start = random_poses(parts, half_size * 0.8, seed);
    const std::vector<Transform> motion = random_poses(parts, 0.03, seed + 1);
    for (int i = 0; i < parts; ++i) {
      meshes.push_back(shapes[i % shapes.size()]);
      poses.push_back(start[i]);
      velocity.push_back(motion[i].t);
      const Eigen::AngleAxisd aa(motion[i].R);
      spin.push_back(aa.axis() * (0.05 * aa.angle() / M_PI));
    }
  }

  void advance() {
    for (std::size_t i = 0; i < poses.size(); ++i) {
      poses[i].t += velocity[i];
      for (int k = 0; k < 3; ++k) {
        if (std::abs(poses[i].t[k]) > half_size) velocity[i][k] = -velocity[i][k];
      }
      const Real angle = spin[i].norm();
      if (angle > 0)
        poses[i].R = Eigen::AngleAxisd(angle, spin[i] / angle).toRotationMatrix() * poses[i].R;
    }
  }
};

/// Every pair at the polygon level, as the reference.
std::vector<Contact> all_pairs_reference(const MovingScene& scene, const std::vector<PartId>& ids,
                                         Method method) {
  std::vector<std::shared_ptr<const CollisionModel>> models;
  for (const auto& mesh : scene.meshes) models.push_back(build_model(method, mesh));
  std::vector<Contact> contacts;
  for (std::size_t i = 0; i < ids.size(); ++i) {
    for (std::size_t j = i + 1; j < ids.size(); ++j) {
      Transform X_AB;
      X_AB.R = scene.poses[i].R.transpose() * scene.poses[j].R;
      X_AB.t = scene.poses[i].R.transpose() * (scene.poses[j].t - scene.poses[i].t);
      const CollideResult r = models[i]->collide(*models[j], X_AB, {.all_pairs = true});
      for (const TrianglePair& t : r.pairs) contacts.push_back({ids[i], ids[j], t.a, t.b});
    }
  }
  return contacts;
}

TEST(CollisionWorld, ContactsEqualEveryPairAtThePolygonLevel) {
  // Every other broad phase with the world prepared (hulls at once, so the
  // separating-plane test from the first step), the others not (each pair's
  // test deferred until it pays, PairPlan).
  bool prepare = true;
  for (BroadphaseMethod broadphase : all_broadphases()) {
    prepare = !prepare;
    MovingScene scene(14, 5);
    WorldSettings settings;
    settings.broadphase = broadphase;
    CollisionWorld world(settings);
    std::vector<PartId> ids;
    for (std::size_t i = 0; i < scene.meshes.size(); ++i) {
      ids.push_back(world.add_part({.mesh = scene.meshes[i], .X_WP = scene.poses[i]}));
    }
    if (prepare) world.prepare();
    std::size_t contacts = 0, frames_with_contact = 0, convex_separated = 0;
    for (int frame = 0; frame < 40; ++frame) {
      for (std::size_t i = 0; i < ids.size(); ++i) world.set_pose(ids[i], scene.poses[i]);
      const StepResult& r = world.step();
      ASSERT_EQ(r.contacts, all_pairs_reference(scene, ids, Method::kBrute))
          << broadphase_name(broadphase) << " frame " << frame;
      contacts += r.contacts.size();
      frames_with_contact += !r.contacts.empty();
      convex_separated += r.stats.convex_separated;
      scene.advance();
    }
    std::printf(
        "[ pipeline ] %s: 40 frames, %zu contacts, %zu frames with contact, %zu pairs separated by "
        "planes\n",
        std::string(broadphase_name(broadphase)).c_str(), contacts, frames_with_contact,
        convex_separated);
    EXPECT_GT(frames_with_contact, 5u);
    if (prepare) {
      EXPECT_GT(convex_separated, 0u);
    }
  }
}

TEST(CollisionWorld, IdenticalResultsForOneTwoAndEightThreads) {
  std::vector<std::vector<StepResult>> runs;
  for (int threads : {1, 2, 8}) {
    MovingScene scene(24, 9);
    CollisionWorld world({.method = Method::kBoxtree, .threads = threads});
    std::vector<PartId> ids;
    for (std::size_t i = 0; i < scene.meshes.size(); ++i) {
      ids.push_back(world.add_part({.mesh = scene.meshes[i], .X_WP = scene.poses[i]}));
    }
    std::vector<StepResult> steps;
    for (int frame = 0; frame < 40; ++frame) {
      for (std::size_t i = 0; i < ids.size(); ++i) world.set_pose(ids[i], scene.poses[i]);
      steps.push_back(world.step());
      scene.advance();
    }
    runs.push_back(std::move(steps));
  }
  std::size_t contacts = 0;
  for (std::size_t f = 0; f < runs[0].size(); ++f) {
    contacts += runs[0][f].contacts.size();
    for (std::size_t t = 1; t < runs.size(); ++t) {
      EXPECT_EQ(runs[t][f].contacts, runs[0][f].contacts) << "frame " << f;
      EXPECT_EQ(runs[t][f].began, runs[0][f].began) << "frame " << f;
      EXPECT_EQ(runs[t][f].ended, runs[0][f].ended) << "frame " << f;
      EXPECT_EQ(runs[t][f].stats.polygon.volume_tests, runs[0][f].stats.polygon.volume_tests);
      EXPECT_EQ(runs[t][f].stats.convex_separated, runs[0][f].stats.convex_separated);
    }
  }
  EXPECT_GT(contacts, 0u);
}

TEST(CollisionWorld, APartWithAMeshTheHierarchiesCannotTakeIsRefusedWhenAdded) {
  // A hand-made mesh with a NaN vertex: refused by add_part on the caller's
  // thread, not later inside a worker building its hierarchy; the world
  // stays usable.
  Mesh nan = make_box(Vec3(0.5, 0.5, 0.5));
  nan.source = "hand-made.mesh";
  nan.vertices[2].z() = std::numeric_limits<Real>::quiet_NaN();
  CollisionWorld world;
  EXPECT_THROW(world.add_part({.mesh = share(nan), .X_WP = {}, .name = "bad"}), MeshError);
  const auto box = share(make_box(Vec3(0.5, 0.5, 0.5)));
  const PartId a = world.add_part({.mesh = box, .X_WP = {}, .name = "a"});
  const PartId b = world.add_part({.mesh = box, .X_WP = {}, .name = "b"});
  EXPECT_EQ(a.index, 0u);  // the refused part took no slot
  EXPECT_EQ(b.index, 1u);
  EXPECT_EQ(world.step().colliding.size(), 1u);  // the two boxes overlap
}

TEST(CollisionWorld, BeginAndEndInTheRightFrames) {
  const auto box = share(make_box(Vec3(0.5, 0.5, 0.5)));
  CollisionWorld world;
  Transform left, right;
  left.t = Vec3(0, 0, 0);
  right.t = Vec3(2, 0, 0);
  const PartId a = world.add_part({.mesh = box, .X_WP = left, .name = "a"});
  const PartId b = world.add_part({.mesh = box, .X_WP = right, .name = "b"});
  // B moves left by 0.25 per frame: faces touch exactly at x = 1 (frame 4), overlap
  // after; then it moves back and the contact ends.
  std::vector<int> began, ended;
  for (int frame = 0; frame <= 16; ++frame) {
    Transform X = right;
    const int k = frame <= 8 ? frame : 16 - frame;
    X.t.x() = 2.0 - 0.25 * k;
    world.set_pose(b, X);
    const StepResult& r = world.step();
    if (!r.began.empty()) began.push_back(frame);
    if (!r.ended.empty()) ended.push_back(frame);
  }
  EXPECT_EQ(began, std::vector<int>({4}));  // touching counts
  EXPECT_EQ(ended, std::vector<int>({13}));
  (void)a;
}

TEST(CollisionWorld, LevelsOfDetailAndInterest) {
  const auto ring = share(make_torus(1.0, 0.2, 32, 12));
  const auto ball = share(make_sphere(0.3, 2));
  CollisionWorld world;
  const PartId r = world.add_part({.mesh = ring, .X_WP = Transform::identity()});
  const PartId s = world.add_part({.mesh = ball, .X_WP = Transform::identity()});
  // The ball sits in the hole of the ring: boxes and hulls overlap, triangles do not.
  EXPECT_TRUE(world.step().colliding.empty());
  world.set_pair_level(r, s, LevelOfDetail::kHull);
  EXPECT_EQ(world.step().colliding.size(), 1u);
  world.set_pair_level(r, s, LevelOfDetail::kBox);
  ASSERT_EQ(world.step().contacts.size(), 1u);
  EXPECT_EQ(world.last_step().contacts[0].triangle_a, kNoTriangle);
  world.set_interest(r, s, false);
  EXPECT_TRUE(world.step().colliding.empty());
  EXPECT_EQ(world.last_step().stats.tested_pairs, 0u);
}

TEST(CollisionWorld, FixedPartsAreNotTestedAgainstEachOther) {
  const auto box = share(make_box(Vec3(1, 1, 1)));
  CollisionWorld world;
  const PartId a = world.add_part({.mesh = box, .X_WP = Transform::identity(), .movable = false});
  const PartId b = world.add_part({.mesh = box, .X_WP = Transform::identity(), .movable = false});
  const StepResult& r = world.step();
  // Not even reported by the broad phase: the boxes of two fixed parts.
  EXPECT_EQ(r.stats.box_pairs, 0u);
  EXPECT_EQ(r.stats.tested_pairs, 0u);
  EXPECT_TRUE(r.colliding.empty());
  // Unless the pair is asked for.
  world.set_interest(a, b, true);
  const StepResult& asked = world.step();
  EXPECT_EQ(asked.stats.box_pairs, 1u);
  EXPECT_EQ(asked.stats.tested_pairs, 1u);
  EXPECT_EQ(asked.colliding.size(), 1u);
}

TEST(CollisionWorld, APairStillTouchingAtItsLastTrianglesSkipsTheHullTest) {
  // Two balls overlapping: the first step tests their hulls and then their
  // triangles; while the same triangles (or their neighbours) still cross,
  // later steps decide the pair by them alone. Apart, the hull test is back.
  // (Prepared: the hulls are built, so the hull test runs from the start.)
  const auto ball = share(make_sphere(0.5, 2));
  CollisionWorld world({.contacts = ContactDetail::kPairs});
  world.add_part({.mesh = ball, .X_WP = Transform::identity()});
  Transform X = Transform::identity();
  X.t = Vec3(0.9, 0, 0);
  const PartId b = world.add_part({.mesh = ball, .X_WP = X});
  world.prepare();
  const StepStats first = world.step().stats;
  EXPECT_EQ(first.convex_tests, 1u);
  EXPECT_EQ(first.polygon_pairs, 1u);
  EXPECT_EQ(first.colliding_pairs, 1u);
  EXPECT_GT(first.polygon.volume_tests, 0u);

  X.t.y() += 1e-3;
  world.set_pose(b, X);
  const StepStats held = world.step().stats;
  EXPECT_EQ(held.convex_tests, 0u);
  EXPECT_EQ(held.polygon_pairs, 1u);
  EXPECT_EQ(held.colliding_pairs, 1u);
  EXPECT_EQ(held.polygon.volume_tests, 0u);
  EXPECT_GT(held.polygon.triangle_tests, 0u);

  // Boxes still overlapping, balls apart: the old triangles no longer
  // cross, and the hulls' test separates the pair.
  X.t = Vec3(0.8, 0.8, 0);
  world.set_pose(b, X);
  const StepStats apart = world.step().stats;
  EXPECT_EQ(apart.box_pairs, 1u);
  EXPECT_EQ(apart.convex_tests, 1u);
  EXPECT_EQ(apart.convex_separated, 1u);
  EXPECT_EQ(apart.polygon_pairs, 0u);
  EXPECT_EQ(apart.colliding_pairs, 0u);
}

TEST(CollisionWorld, AContactThatMovesFarIsFoundAgainFromItsLargerTriangle) {
  // A thin rod through a ball, then moved sideways by more than a ring of
  // the ball's triangles: the rod's long side triangle still crosses the
  // ball, elsewhere. Searching it against the ball's hierarchy finds the
  // new contact without a traversal of the two hierarchies.
  const auto ball = share(make_sphere(0.5, 3));
  const auto rod = share(make_cylinder(0.02, 2.0, 64));
  CollisionWorld world({.contacts = ContactDetail::kPairs});
  world.add_part({.mesh = ball, .X_WP = Transform::identity()});
  Transform X = Transform::identity();
  X.t = Vec3(0.1, 0, 0);
  const PartId b = world.add_part({.mesh = rod, .X_WP = X});
  const StepStats first = world.step().stats;
  EXPECT_EQ(first.colliding_pairs, 1u);
  EXPECT_GT(first.polygon.volume_tests, 0u);

  X.t.x() = 0.35;
  world.set_pose(b, X);
  const StepStats moved = world.step().stats;
  EXPECT_EQ(moved.colliding_pairs, 1u);
  EXPECT_EQ(moved.polygon.volume_tests, 0u);
  EXPECT_GT(moved.polygon.triangle_volume_tests, 0u);
  EXPECT_EQ(moved.convex_tests, 0u);

  // Out of the ball, inside its box: searches and traversal find nothing.
  X.t = Vec3(0.45, 0.45, 0);
  world.set_pose(b, X);
  const StepStats apart = world.step().stats;
  EXPECT_EQ(apart.colliding_pairs, 0u);
}

TEST(CollisionWorld, ACacheUntestedForLongIsForgottenAndThePlanKept) {
  // A pair apart for 2,048 steps (its cache is freed by the first pass, every
  // 1,024 steps, after 1,024 steps untested) cannot start GJK warm any more,
  // keeps its plan, and is decided as before when it meets again.
  const auto ring = share(make_torus(1.0, 0.2, 32, 12));
  const auto ball = share(make_sphere(0.3, 2));
  CollisionWorld world;
  const PartId a = world.add_part({.mesh = ring, .X_WP = Transform::identity(), .movable = false});
  Transform touching = Transform::identity();
  touching.t = Vec3(1.0, 0, 0);  // the ball on the ring's tube
  const PartId b = world.add_part({.mesh = ball, .X_WP = touching});
  EXPECT_EQ(world.step().colliding.size(), 1u);
  const PartDistanceRequest hull{.level = LevelOfDetail::kHull};
  world.distance(a, b, hull);
  EXPECT_TRUE(world.distance(a, b, hull).warm_started);
  const std::vector<PairPlan> plans = world.plans();
  ASSERT_EQ(plans.size(), 1u);

  Transform far = Transform::identity();
  far.t = Vec3(10, 0, 0);
  world.set_pose(b, far);
  for (int k = 0; k < 2100; ++k) EXPECT_TRUE(world.step().colliding.empty());
  EXPECT_FALSE(world.distance(a, b, hull).warm_started);  // forgotten
  EXPECT_EQ(world.plans(), plans);                        // kept

  // A pair tested now and then keeps its cache.
  world.set_pose(b, touching);
  EXPECT_EQ(world.step().colliding.size(), 1u);
  world.distance(a, b, hull);
  for (int k = 0; k < 2100; ++k) {
    world.distance(a, b, hull);
    world.step();
  }
  EXPECT_TRUE(world.distance(a, b, hull).warm_started);
  EXPECT_EQ(world.plans(), plans);
}

TEST(CollisionWorld, RemovedPartsEndTheirContactsAndGoStale) {
  const auto box = share(make_box(Vec3(1, 1, 1)));
  CollisionWorld world;
  const PartId a = world.add_part({.mesh = box, .X_WP = Transform::identity()});
  const PartId b = world.add_part({.mesh = box, .X_WP = Transform::identity()});
  EXPECT_EQ(world.step().began.size(), 1u);
  world.remove_part(b);
  const StepResult& r = world.step();
  ASSERT_EQ(r.ended.size(), 1u);
  EXPECT_EQ(r.ended[0].b, b);
  EXPECT_THROW(world.set_pose(b, Transform::identity()), std::invalid_argument);
  const PartId c = world.add_part({.mesh = box, .X_WP = Transform::identity()});
  EXPECT_EQ(c.index, b.index);
  EXPECT_NE(c, b);
  EXPECT_EQ(world.step().began.size(), 1u);
  (void)a;
}

TEST(CollisionWorld, InstancesShareOneHierarchy) {
  const auto mesh = share(make_sphere(0.5, 3));
  CollisionWorld one, many;
  Transform X;
  one.add_part({.mesh = mesh, .X_WP = X});
  X.t.x() = 0.9;
  one.add_part({.mesh = mesh, .X_WP = X});
  for (int i = 0; i < 6; ++i) {
    X.t.x() = 0.9 * i;
    many.add_part({.mesh = mesh, .X_WP = X});
  }
  one.step();
  many.step();
  EXPECT_GT(one.model_bytes(), 0u);
  EXPECT_EQ(one.model_bytes(), many.model_bytes());
}

TEST(CollisionWorld, PrepareBuildsWhatTheStepsWouldBuild) {
  // After prepare(), stepping through every contact builds nothing more (the
  // hierarchies' bytes stay the same), for hull-level parts raised to exact
  // by a pair level, and for a hull-level part meeting a flat part (no hull,
  // so their pair is decided exactly).
  const auto sphere = share(make_sphere(0.5, 2));
  const auto box = share(make_box(Vec3(0.4, 0.3, 0.2)));
  const auto sheet = share(make_wavy_sheet(0.6, 0.0, 1.0, 6));
  const auto expect_nothing_more = [](CollisionWorld& world, PartId moving, const Vec3& meet) {
    world.prepare();
    const std::size_t prepared = world.model_bytes();
    Transform X;
    X.t = meet;
    world.set_pose(moving, X);
    EXPECT_FALSE(world.step().colliding.empty());
    EXPECT_GT(prepared, 0u);
    EXPECT_EQ(world.model_bytes(), prepared);
  };
  {
    CollisionWorld world;
    Transform X;
    const PartId a = world.add_part({.mesh = sphere, .X_WP = X, .level = LevelOfDetail::kHull});
    X.t.x() = 3;
    const PartId b = world.add_part({.mesh = box, .X_WP = X, .level = LevelOfDetail::kHull});
    world.set_pair_level(a, b, LevelOfDetail::kExact);
    expect_nothing_more(world, a, Vec3(2.7, 0, 0));
  }
  {
    CollisionWorld world;
    Transform X;
    const PartId a = world.add_part({.mesh = sphere, .X_WP = X, .level = LevelOfDetail::kHull});
    X.t.x() = 3;
    world.add_part({.mesh = sheet, .X_WP = X, .movable = false});
    expect_nothing_more(world, a, Vec3(3, 0, 0.2));
  }
}

}  // namespace
}  // namespace dovetail::collision

namespace dovetail::collision {
namespace {

TEST(CollisionWorld, HeavyPairsSplitOverThreadsGiveIdenticalResults) {
  // Parts large enough that their pairs are split over the threads.
  const auto sphere = share(make_sphere(0.5, 4));          // 5,120 triangles
  const auto torus = share(make_torus(0.5, 0.2, 64, 32));  // 4,096
  std::vector<std::vector<Contact>> runs;
  for (int threads : {1, 2, 8}) {
    CollisionWorld world({.threads = threads});
    const std::vector<Transform> poses = random_poses(6, 0.4, 77);
    for (std::size_t i = 0; i < poses.size(); ++i) {
      world.add_part({.mesh = i % 2 ? torus : sphere, .X_WP = poses[i]});
    }
    runs.push_back(world.step().contacts);
  }
  EXPECT_GT(runs[0].size(), 100u);
  EXPECT_EQ(runs[1], runs[0]);
  EXPECT_EQ(runs[2], runs[0]);
}

}  // namespace
}  // namespace dovetail::collision

namespace dovetail::collision {
namespace {

TEST(CollisionWorld, PairDetailFindsTheSamePairsAtAnyThreadCount) {
  // First-hit queries with last step's intersecting triangle pair tried
  // first, then the subtree pair around it (TraversalHint), must decide every
  // pair as the all-pairs queries do, for every hierarchy, whether the
  // hierarchies are built up front (prepare) or on first need.
  std::vector<std::vector<PartPair>> reference;
  {
    MovingScene scene(14, 5);
    CollisionWorld world;
    std::vector<PartId> ids;
    for (std::size_t i = 0; i < scene.meshes.size(); ++i) {
      ids.push_back(world.add_part({.mesh = scene.meshes[i], .X_WP = scene.poses[i]}));
    }
    for (int frame = 0; frame < 40; ++frame) {
      for (std::size_t i = 0; i < ids.size(); ++i) world.set_pose(ids[i], scene.poses[i]);
      reference.push_back(world.step().colliding);
      scene.advance();
    }
  }
  for (Method method : {Method::kObb, Method::kAabb, Method::kDop18, Method::kBoxtree}) {
    for (int threads : {1, 2, 8}) {
      MovingScene scene(14, 5);
      CollisionWorld world(
          {.method = method, .threads = threads, .contacts = ContactDetail::kPairs});
      std::vector<PartId> ids;
      for (std::size_t i = 0; i < scene.meshes.size(); ++i) {
        ids.push_back(world.add_part({.mesh = scene.meshes[i], .X_WP = scene.poses[i]}));
      }
      if (threads == 2) world.prepare();
      for (int frame = 0; frame < 40; ++frame) {
        for (std::size_t i = 0; i < ids.size(); ++i) world.set_pose(ids[i], scene.poses[i]);
        const StepResult& r = world.step();
        ASSERT_EQ(r.colliding, reference[frame])
            << method_name(method) << " threads " << threads << " frame " << frame;
        ASSERT_EQ(r.contacts.size(), r.colliding.size());
        for (const Contact& c : r.contacts) EXPECT_EQ(c.triangle_a, kNoTriangle);
        scene.advance();
      }
    }
  }
}

}  // namespace
}  // namespace dovetail::collision
