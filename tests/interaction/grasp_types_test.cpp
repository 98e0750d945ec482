// Natural grasping: a designed glove plan grasps a bar with a power grasp,
// holds it while the hand moves and releases it when the hand opens; an open
// hand brushing past a part grasps nothing.

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>

#include "dovetail/collision/primitives.h"
#include "dovetail/interaction/glove_source.h"
#include "dovetail/interaction/grasping.h"
#include "dovetail/interaction/postures.h"

namespace dovetail::interaction {
namespace {

using engine::Event;
using engine::EventKind;

/// A cylinder of `radius` and `length` centred at p_H with its axis along `axis` (hand frame
/// at the origin, so H is the world).
engine::PartDesc cylinder_part(const std::string& name, Real radius, Real length, const Vec3& p_W,
                               const Vec3& axis) {
  Transform X;
  X.R =
      Eigen::Quaternion<Real>::FromTwoVectors(Vec3::UnitZ(), axis.normalized()).toRotationMatrix();
  X.t = p_W - X.R * Vec3(0, 0, length / 2);
  return {.name = name,
          .X_PC = X,
          .render_mesh = std::make_shared<const collision::Mesh>(
              collision::make_cylinder(radius, length, 48))};
}

struct GraspRun {
  std::vector<Event> events;
  Vec3 moved = Vec3::Zero();  ///< how far the part moved
  std::optional<GraspType> type_while_moving;
  std::vector<GloveSample> recorded;
  std::uint64_t state_hash = 0;
};

/// The hand open at the origin closes to `posture` in 0.5 s, waits, lifts 50 mm in
/// 0.5 s, opens in 0.4 s and waits.
GraspRun run_grasp(engine::PartDesc part, const JointAngles& posture,
                   std::shared_ptr<const GloveSource> replay = nullptr, int threads = 1) {
  engine::Scene scene;
  const std::string name = part.name;
  scene.add_part(part);
  engine::Simulation sim(std::move(scene), {.collision_threads = threads});
  GlovePlan plan;
  PlanStep close{.kind = PlanStep::Kind::kClose, .duration = 0.5};
  close.posture = posture;
  PlanStep wait{.kind = PlanStep::Kind::kWait, .duration = 0.2};
  PlanStep lift{.kind = PlanStep::Kind::kReach, .duration = 0.5};
  lift.poses = {{Vec3(0, 0.05, 0), Quaternion{}}};
  PlanStep open{.kind = PlanStep::Kind::kOpen, .duration = 0.4};
  plan.steps = {close, wait, lift, open, wait};
  Hand hand(sim, replay ? replay : std::make_shared<SimulatedGlove>(plan));
  Grasping grasping(sim, hand);
  const Vec3 start = sim.scene().world_pose(name).t;
  GraspRun run;
  for (int frame = 0; frame < 170; ++frame) {
    const engine::FrameResult& r = sim.step();
    run.events.insert(run.events.end(), r.events.begin(), r.events.end());
    if (frame == 100) run.type_while_moving = grasping.grasp_type();
  }
  run.moved = sim.scene().world_pose(name).t - start;
  run.recorded = hand.recorded();
  run.state_hash = sim.state_hash();
  return run;
}

std::optional<std::string> grasp_of(const GraspRun& run, const std::string& part) {
  for (const Event& e : run.events) {
    if (e.kind == EventKind::kGrasp && e.a == part) return e.b;
  }
  return std::nullopt;
}

bool released(const GraspRun& run, const std::string& part) {
  return std::any_of(run.events.begin(), run.events.end(), [&](const Event& e) {
    return e.kind == EventKind::kRelease && e.a == part && e.b == "opened";
  });
}

void expect_carried(const GraspRun& run, const std::string& part, const std::string& type) {
  EXPECT_EQ(grasp_of(run, part), type);
  ASSERT_TRUE(run.type_while_moving.has_value()) << "held while the hand moves";
  EXPECT_EQ(std::string(grasp_type_name(*run.type_while_moving)), type);
  EXPECT_TRUE(released(run, part));
  EXPECT_NEAR(run.moved.y(), 0.05, 2e-3) << "the part went up with the hand";
}

TEST(GraspTypes, ABarAcrossThePalmIsAPowerGrasp) {
  const GraspRun run = run_grasp(
      cylinder_part("bar", 0.022, 0.08, Vec3(0.02, -0.0105 - 0.022 - 0.0001, -0.06), Vec3::UnitX()),
      *named_posture("power"));
  expect_carried(run, "bar", "power");
}

TEST(GraspTypes, AGraspRecordedAndReplayedFromItsTraceIsTheSameRun) {
  const engine::PartDesc bar =
      cylinder_part("bar", 0.022, 0.08, Vec3(0.02, -0.0105 - 0.022 - 0.0001, -0.06), Vec3::UnitX());
  const GraspRun original = run_grasp(bar, *named_posture("power"));
  const auto trace = std::make_shared<TraceSource>(original.recorded);
  for (const int threads : {1, 2, 8}) {
    const GraspRun replay = run_grasp(bar, *named_posture("power"), trace, threads);
    EXPECT_EQ(replay.state_hash, original.state_hash) << threads << " threads";
    EXPECT_EQ(replay.events, original.events) << threads << " threads";
  }
  EXPECT_EQ(grasp_of(original, "bar"), "power");
}

TEST(GraspTypes, AnOpenHandBrushingPastGraspsNothing) {
  // The open hand sweeps sideways across a block so that its fingers run through its top.
  engine::Scene scene;
  scene.add_part({.name = "block",
                  .X_PC = {Mat3::Identity(), Vec3(0, -0.02, -0.15)},
                  .render_mesh = std::make_shared<const collision::Mesh>(
                      collision::make_box(Vec3(0.01, 0.0195, 0.01)))});
  engine::Simulation sim(std::move(scene));
  GlovePlan plan;
  plan.start.p_WH = Vec3(-0.12, 0, 0);
  PlanStep sweep{.kind = PlanStep::Kind::kReach, .duration = 1.0};
  sweep.poses = {{Vec3(0.12, 0, 0), Quaternion{}}};
  plan.steps = {sweep};
  Hand hand(sim, std::make_shared<SimulatedGlove>(plan));
  Grasping grasping(sim, hand);
  std::size_t touches = 0;
  sim.events().subscribe(EventKind::kHandContactBegin, [&](const Event&) { ++touches; });
  sim.events().subscribe(EventKind::kGrasp,
                         [&](const Event& e) { ADD_FAILURE() << "grasped " << e.a; });
  sim.run(100);
  EXPECT_GT(touches, 2U) << "the fingers touched the block";
  EXPECT_FALSE(grasping.held());
  EXPECT_EQ(sim.scene().world_pose("block").t, Vec3(0, -0.02, -0.15));
}

}  // namespace
}  // namespace dovetail::interaction

namespace dovetail::interaction {
namespace {

// The contact analysis alone, on contacts made by hand: a part 10 mm thick
// between y = -0.005 and y = 0.005.
GraspContact below(Segment s, Real x) { return {s, Vec3(x, -0.005, 0), -Vec3::UnitY()}; }
GraspContact above(Segment s, Real x) { return {s, Vec3(x, 0.005, 0), Vec3::UnitY()}; }

TEST(GraspAnalysis, ThumbTipOpposingIndexTipIsPrecision) {
  const GraspContact c[] = {below(Segment::kThumbDistal, 0), above(Segment::kIndexDistal, 0.002)};
  EXPECT_EQ(classify_grasp(c, 0.5), GraspType::kPrecision);
  const GraspContact middle[] = {below(Segment::kThumbDistal, 0), above(Segment::kMiddleDistal, 0)};
  EXPECT_EQ(classify_grasp(middle, 0.5), GraspType::kPrecision);
}

TEST(GraspAnalysis, ContactsOutsideTheFrictionConesDoNotOppose) {
  // 10 mm thick, 6 mm apart sideways: 31 degrees off the normal, past atan 0.5 = 26.6
  // degrees; inside atan 1 = 45 degrees.
  const GraspContact c[] = {below(Segment::kThumbDistal, 0), above(Segment::kIndexDistal, 0.006)};
  EXPECT_EQ(classify_grasp(c, 0.5), std::nullopt);
  EXPECT_EQ(classify_grasp(c, 1.0), GraspType::kPrecision);
  // Both on the same side: nothing opposes.
  const GraspContact same[] = {above(Segment::kThumbDistal, 0), above(Segment::kIndexDistal, 0)};
  EXPECT_EQ(classify_grasp(same, 0.5), std::nullopt);
  // Not tips: a thumb's proximal segment and the index's middle one.
  const GraspContact inner[] = {below(Segment::kThumbProximal, 0),
                                above(Segment::kIndexIntermediate, 0)};
  EXPECT_EQ(classify_grasp(inner, 0.5), std::nullopt);
}

TEST(GraspAnalysis, ThumbOpposingIndexAndMiddleAsOneIsATripod) {
  // Index and middle 8 mm either side of the thumb: each alone is 38 degrees off, their
  // middle straight across.
  const GraspContact c[] = {below(Segment::kThumbDistal, 0), above(Segment::kIndexDistal, -0.008),
                            above(Segment::kMiddleDistal, 0.008)};
  EXPECT_EQ(classify_grasp(c, 0.5), GraspType::kTripod);
  // Without the middle finger it is no grasp at all (the index alone is outside the cone).
  EXPECT_EQ(classify_grasp(std::span(c, 2), 0.5), std::nullopt);
}

TEST(GraspAnalysis, PalmAndFingersAroundIsPower) {
  const GraspContact c[] = {above(Segment::kPalm, 0), below(Segment::kIndexIntermediate, 0.001),
                            below(Segment::kMiddleDistal, -0.001),
                            above(Segment::kThumbDistal, 0.03)};
  EXPECT_EQ(classify_grasp(c, 0.5), GraspType::kPower);
  // The palm with one finger only: not power (and no tips oppose).
  EXPECT_EQ(classify_grasp(std::span(c, 2), 0.5), std::nullopt);
}

}  // namespace
}  // namespace dovetail::interaction
