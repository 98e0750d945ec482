// Where sliding is hard: a sharp edge, and two held parts sliding against
// each other at once. And the step itself: both contact searches stop at the
// contact pose, and a proof of a free pose covers only what it was made for.

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>

#include "dovetail/collision/contacts.h"
#include "dovetail/collision/distance.h"
#include "dovetail/collision/primitives.h"
#include "dovetail/interaction/glove_source.h"
#include "dovetail/interaction/grasping.h"

namespace dovetail::interaction {
namespace {

using engine::Event;
using engine::EventKind;

std::shared_ptr<const collision::Mesh> box(const Vec3& half) {
  return std::make_shared<const collision::Mesh>(collision::make_box(half));
}

/// Deepest penetration between two parts of the simulation now.
Real depth_between(const engine::Simulation& sim, const std::string& a, const std::string& b) {
  const auto ma = collision::build_model(collision::Method::kObb,
                                         sim.scene().collision_mesh(sim.scene().get(a)));
  const auto mb = collision::build_model(collision::Method::kObb,
                                         sim.scene().collision_mesh(sim.scene().get(b)));
  const Transform X_WA = sim.scene().world_pose(a), X_WB = sim.scene().world_pose(b);
  const Transform X_AB{X_WA.R.transpose() * X_WB.R, X_WA.R.transpose() * (X_WB.t - X_WA.t)};
  Real depth = 0;
  for (const collision::ContactPatch& p : collision::compute_contacts(*ma, *mb, X_AB)) {
    depth = std::max(depth, p.depth);
  }
  return depth;
}

bool same_pose(const Transform& a, const Transform& b) { return a.R == b.R && a.t == b.t; }

/// A hand far above that holds `part` and moves by `moves` (reach steps of `duration`).
GlovePlan moves_by(const Vec3& start, std::initializer_list<Vec3> moves, Real duration) {
  GlovePlan plan;
  plan.start.p_WH = start;
  Vec3 at = start;
  for (const Vec3& move : moves) {
    at += move;
    PlanStep step{.kind = PlanStep::Kind::kReach, .duration = duration};
    step.poses = {{at, Quaternion{}}};
    plan.steps.push_back(step);
  }
  return plan;
}

TEST(SlidingCases, ACubePressedOntoABlockSlidesAlongItsTopAndOverItsSharpEdge) {
  // A 10 mm cube held 5 mm below the block's top face (the band pulls it into the
  // block), carried 80 mm sideways past the block's edge. Expected: it slides along the
  // top face without penetrating, over the edge, and then follows the hand down
  // to its target, the band relaxed.
  engine::Scene scene;
  scene.add_part({.name = "block", .movable = false, .render_mesh = box(Vec3(0.03, 0.02, 0.03))});
  scene.add_part({.name = "cube",
                  .X_QP = {Mat3::Identity(), Vec3(-0.02, 0.0251, 0)},
                  .render_mesh = box(Vec3::Constant(0.005))});
  engine::Simulation sim(std::move(scene));
  const Vec3 hand0(-0.02, 0.2, 0);
  Hand hand(sim, std::make_shared<SimulatedGlove>(
                     moves_by(hand0, {Vec3(0, -0.005, 0), Vec3(0.08, 0, 0)}, 1.0)));
  Grasping grasping(sim, hand);
  grasping.hold("cube", GraspType::kPower);
  Real max_depth = 0;
  Real lowest_on_top = 1;
  for (int frame = 0; frame < 200; ++frame) {
    sim.step();
    max_depth = std::max(max_depth, depth_between(sim, "block", "cube"));
    const Vec3 c = sim.scene().world_pose("cube").t;
    if (c.x() < 0.03 - 0.005) lowest_on_top = std::min(lowest_on_top, c.y() - 0.005);
  }
  EXPECT_LT(max_depth, 1e-5);
  EXPECT_GE(lowest_on_top, 0.02) << "never into the top face";
  EXPECT_LT(lowest_on_top, 0.02 + 1e-4) << "but pressed onto it";
  const Vec3 c = sim.scene().world_pose("cube").t;
  EXPECT_NEAR(c.x(), 0.06, 5e-6) << "past the edge, where the hand wants it (to the rest step)";
  EXPECT_NEAR(c.y(), 0.0201, 5e-6);
  EXPECT_TRUE(grasping.held());
}

TEST(SlidingCases, APartHeldWhileTouchingAnotherMovesOffIt) {
  // The cube starts resting face on face on the block (touching counts as colliding,
  // so every step used to be blocked at its start). The hand first presses it 5 mm
  // down and 20 mm along, then lifts it 50 mm. Expected: it slides along the top face
  // without entering it, then leaves it, still held.
  engine::Scene scene;
  scene.add_part({.name = "block", .movable = false, .render_mesh = box(Vec3(0.03, 0.02, 0.03))});
  scene.add_part({.name = "cube",
                  .X_QP = {Mat3::Identity(), Vec3(-0.01, 0.025, 0)},
                  .render_mesh = box(Vec3::Constant(0.005))});
  engine::Simulation sim(std::move(scene));
  Hand hand(sim, std::make_shared<SimulatedGlove>(moves_by(
                     Vec3(-0.01, 0.2, 0), {Vec3(0.02, -0.005, 0), Vec3(0, 0.055, 0)}, 1.0)));
  Grasping grasping(sim, hand);
  grasping.hold("cube", GraspType::kPower);
  Real max_depth = 0;
  Real lowest = 1;
  for (int frame = 0; frame < 90; ++frame) {  // pressed and carried along
    sim.step();
    max_depth = std::max(max_depth, depth_between(sim, "block", "cube"));
    lowest = std::min(lowest, sim.scene().world_pose("cube").t.y() - 0.005);
  }
  EXPECT_GE(lowest, 0.02) << "never into the top face";
  EXPECT_NEAR(sim.scene().world_pose("cube").t.x(), 0.01, 1e-4) << "slid along it";
  for (int frame = 0; frame < 120; ++frame) sim.step();  // lifted
  const Vec3 c = sim.scene().world_pose("cube").t;
  EXPECT_NEAR(c.y(), 0.075, 1e-4) << "lifted off, where the hand wants it";
  EXPECT_LT(max_depth, 1e-5);
  EXPECT_TRUE(grasping.held());
}

TEST(SlidingCases, APartHeldWhileOverlappingAnotherStaysWhereItIsAndIsNeverLost) {
  // The cube starts 1 mm inside the block (as a part just snapped into a seat may be
  // at the skin's scale) and the hand pulls it further in: every step is blocked at
  // its start with no contact to name. Expected: no slide event names a part, the
  // cube does not move, and it stays held until the band breaks.
  engine::Scene scene;
  scene.add_part({.name = "block", .movable = false, .render_mesh = box(Vec3(0.03, 0.02, 0.03))});
  scene.add_part({.name = "cube",
                  .X_QP = {Mat3::Identity(), Vec3(0, 0.024, 0)},
                  .render_mesh = box(Vec3::Constant(0.005))});
  engine::Simulation sim(std::move(scene));
  Hand hand(sim,
            std::make_shared<SimulatedGlove>(moves_by(Vec3(0, 0.2, 0), {Vec3(0, -0.03, 0)}, 1.0)));
  Grasping grasping(sim, hand);
  grasping.hold("cube", GraspType::kPower);
  const Transform start = sim.scene().world_pose("cube");
  std::vector<Event> events;
  for (int frame = 0; frame < 120; ++frame) {
    const engine::FrameResult& r = sim.step();
    events.insert(events.end(), r.events.begin(), r.events.end());
  }
  EXPECT_TRUE(same_pose(sim.scene().world_pose("cube"), start));
  for (const Event& e : events) {
    if (e.kind == EventKind::kSlideBegin) {
      EXPECT_FALSE(e.b.empty());
    }
  }
  const bool overstretched = std::any_of(events.begin(), events.end(), [](const Event& e) {
    return e.kind == EventKind::kRelease && e.a == "cube" && e.b == "overstretched";
  });
  EXPECT_TRUE(grasping.held() || overstretched);
}

TEST(SlidingCases, TwoHeldPartsSlideAgainstEachOtherAtOnce) {
  // Two hands carry a cube each toward the other until their targets overlap by 10 mm.
  // Expected: both stop at contact (no penetration), both report sliding on the other,
  // and as the hands then move apart vertically the cubes slide along each other.
  engine::Scene scene;
  scene.add_part({.name = "left_cube",
                  .X_QP = {Mat3::Identity(), Vec3(-0.03, 0, 0)},
                  .render_mesh = box(Vec3::Constant(0.01))});
  scene.add_part({.name = "right_cube",
                  .X_QP = {Mat3::Identity(), Vec3(0.03, 0, 0)},
                  .render_mesh = box(Vec3::Constant(0.01))});
  engine::Simulation sim(std::move(scene));
  HandSettings left_settings, right_settings;
  left_settings.name = "left";
  right_settings.name = "right";
  Hand left(sim,
            std::make_shared<SimulatedGlove>(
                moves_by(Vec3(-0.03, 0.2, 0), {Vec3(0.025, 0, 0), Vec3(0, 0.004, 0)}, 0.8)),
            left_settings);
  Hand right(sim,
             std::make_shared<SimulatedGlove>(
                 moves_by(Vec3(0.03, 0.3, 0), {Vec3(-0.025, 0, 0), Vec3(0, -0.004, 0)}, 0.8)),
             right_settings);
  Grasping left_grasp(sim, left), right_grasp(sim, right);
  left_grasp.hold("left_cube", GraspType::kPower);
  right_grasp.hold("right_cube", GraspType::kPower);
  std::vector<Event> slides;
  sim.events().subscribe(EventKind::kSlideBegin, [&](const Event& e) { slides.push_back(e); });
  Real max_depth = 0;
  for (int frame = 0; frame < 150; ++frame) {
    sim.step();
    max_depth = std::max(max_depth, depth_between(sim, "left_cube", "right_cube"));
  }
  EXPECT_LT(max_depth, 1e-5);
  auto began = [&](const std::string& a, const std::string& b) {
    return std::any_of(slides.begin(), slides.end(),
                       [&](const Event& e) { return e.a == a && e.b == b; });
  };
  EXPECT_TRUE(began("left_cube", "right_cube"));
  EXPECT_TRUE(began("right_cube", "left_cube"));
  const Vec3 l = sim.scene().world_pose("left_cube").t, r = sim.scene().world_pose("right_cube").t;
  EXPECT_NEAR(r.x() - l.x(), 0.02, 1e-4) << "face to face";
  EXPECT_GT(l.y() - r.y(), 0.006) << "slid along each other as the hands parted vertically";
}

/// A 10 mm cube 10 mm above the top face (y = 0.02) of a block, the hand wanting it
/// 5 mm into the block: one step on its own.
struct CubeOverBlock {
  std::shared_ptr<const collision::Mesh> cube_mesh = box(Vec3::Constant(0.005));
  std::shared_ptr<const collision::Mesh> block_mesh = box(Vec3(0.03, 0.02, 0.03));
  std::vector<SlideObstacle> obstacles{{collision::build_model(collision::Method::kObb, block_mesh),
                                        collision::build_distance_model(block_mesh),
                                        Transform::identity(), 0}};

  SlideRequest request() const {
    SlideRequest r;
    r.part = collision::build_model(collision::Method::kObb, cube_mesh);
    r.part_distance = collision::build_distance_model(cube_mesh);
    r.size = 0.0087;
    r.X_WP.t = Vec3(0, 0.035, 0);
    r.X_WP_target.t = Vec3(0, 0.02, 0);
    r.obstacles = obstacles;
    return r;
  }
};

TEST(SlidingCases, BothContactSearchesStopOnTheFaceToTheResolution) {
  const CubeOverBlock scene;
  const SlideRequest request = scene.request();
  for (const bool pair_guided : {false, true}) {
    SCOPED_TRACE(pair_guided ? "pair-guided" : "plain");
    SlidingSettings settings;
    settings.pair_guided = pair_guided;
    const SlideResult r = slide(request, settings);
    EXPECT_NE(r.status, SlideStatus::kReached);
    EXPECT_FALSE(collides(*request.part, r.X_WP, request.obstacles)) << "accepted pose";
    const Real bottom = r.X_WP.t.y() - 0.005;
    EXPECT_GT(bottom, 0.02);
    EXPECT_LT(bottom, 0.02 + settings.resolution_m) << "on the face";
    EXPECT_NEAR(r.X_WP.t.x(), 0, 1e-12);
    ASSERT_FALSE(r.contacts.empty());
    EXPECT_GT(r.contacts.front().n_W.dot(Vec3::UnitY()), 0.9998) << "the face's normal";
  }
}

TEST(SlidingCases, AProofOfAFreePoseCoversOnlyTheObstaclesAtTheirPoses) {
  const CubeOverBlock scene;
  SlideRequest request = scene.request();
  const SlideResult first = slide(request);
  ASSERT_TRUE(first.proof.part);
  // Resting where the last step left it, among the same obstacles: no query to start with.
  request.X_WP = first.X_WP;
  const SlideResult without = slide(request);
  request.start_proof = &first.proof;
  const SlideResult with = slide(request);
  EXPECT_EQ(with.collision_queries, without.collision_queries - 1);
  EXPECT_TRUE(same_pose(with.X_WP, without.X_WP));
  // The block moved up into the cube: the old proof no longer holds.
  std::vector<SlideObstacle> moved = scene.obstacles;
  moved[0].X_WO.t.y() += 0.001;
  request.obstacles = moved;
  EXPECT_EQ(slide(request).status, SlideStatus::kBlocked);
  // A pose a hair's breadth off the proved one is not covered either.
  request.obstacles = scene.obstacles;
  request.X_WP.t.y() = std::nextafter(first.X_WP.t.y(), Real{0});
  const SlideResult off = slide(request);
  EXPECT_EQ(off.collision_queries, without.collision_queries);
}

TEST(SlidingCases, FrontsChangeTheWorkNotThePath) {
  // The cube pressed onto the block and dragged across it, step after step,
  // once with the part's fronts kept between queries and once without.
  const CubeOverBlock scene;
  SlideRequest with = scene.request(), without = scene.request();
  without.part = with.part;  // one part model for both, as a held part has
  SlideFronts fronts;
  with.fronts = &fronts;
  SlideResult last_with, last_without;
  for (int step = 0; step < 40; ++step) {
    const Transform target{Mat3::Identity(), Vec3(0.0005 * step, 0.02, 0.0002 * step)};
    with.X_WP_target = without.X_WP_target = target;
    const SlideResult a = slide(with);
    const SlideResult b = slide(without);
    ASSERT_TRUE(same_pose(a.X_WP, b.X_WP)) << "step " << step;
    ASSERT_EQ(a.status, b.status) << "step " << step;
    ASSERT_EQ(a.contacts.size(), b.contacts.size()) << "step " << step;
    ASSERT_EQ(a.collision_queries, b.collision_queries) << "step " << step;
    // As a held part goes on: from where the step left it, against its contacts.
    last_with = a;
    last_without = b;
    with.X_WP = a.X_WP;
    without.X_WP = b.X_WP;
    with.previous_contacts = last_with.contacts;
    without.previous_contacts = last_without.contacts;
  }
  EXPECT_NE(last_with.status, SlideStatus::kReached) << "pressed onto the face";
  EXPECT_GT(with.X_WP.t.x(), 0.015) << "dragged across the face";
  EXPECT_EQ(fronts.size(), 1U);
  // A step among other obstacles forgets the fronts of those no longer there.
  with.obstacles = {};
  slide(with);
  EXPECT_EQ(fronts.size(), 0U);
}

}  // namespace
}  // namespace dovetail::interaction
