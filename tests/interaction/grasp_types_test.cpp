// Natural grasping: designed glove plans grasp a bar with a power grasp, a pin
// between the thumb's and index's tips with a precision grasp and a washer-sized
// disc between the thumb and two fingertips with a 3-point pinch; each is held
// while the hand moves and released when the hand opens. An open hand brushing
// past a part grasps nothing.

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <functional>

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
engine::PartDef cylinder_part(const std::string& name, Real radius, Real length, const Vec3& p_W,
                              const Vec3& axis) {
  Transform X;
  X.R =
      Eigen::Quaternion<Real>::FromTwoVectors(Vec3::UnitZ(), axis.normalized()).toRotationMatrix();
  X.t = p_W - X.R * Vec3(0, 0, length / 2);
  return {.name = name,
          .X_QP = X,
          .render_mesh = std::make_shared<const collision::Mesh>(
              collision::make_cylinder(radius, length, 48))};
}

struct GraspRun {
  std::vector<Event> events;
  Vec3 moved = Vec3::Zero();  ///< how far the part moved
  std::optional<GraspType> type_while_moving;
  Real off_X_HO = 0;  ///< largest distance of the held part from its grasp pose in the hand
  int frames_held = 0;
  std::vector<GloveSample> recorded;
  std::uint64_t state_hash = 0;
};

/// The hand open at the origin closes to `posture` in 0.5 s, waits, lifts 50 mm in
/// 0.5 s, opens in 0.4 s and waits.
GraspRun run_grasp(engine::PartDef part, const JointAngles& posture,
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
    if (grasping.held() == name) {
      // The part's pose in the hand against the X_HO frozen at the grasp (points of a
      // 50 mm part move by the translation plus 25 mm times the turn).
      const Transform X_HO = engine::compose(hand.X_WH().inverse(), sim.scene().world_pose(name));
      const Real turn = Eigen::AngleAxis<Real>(X_HO.R * grasping.X_HO().R.transpose()).angle();
      run.off_X_HO = std::max(run.off_X_HO, (X_HO.t - grasping.X_HO().t).norm() + 0.025 * turn);
      ++run.frames_held;
    }
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
  EXPECT_GT(run.frames_held, 45) << "held through the lift";
  EXPECT_LT(run.off_X_HO, 1e-6) << "the part kept its pose in the hand";
}

/// A posture with every angle scaled by s: the open hand at 0, the posture at 1,
/// and between them the path of the simulated glove's close step.
JointAngles part_way(const JointAngles& posture, Real s) {
  JointAngles q = posture;
  for (Real& angle : q) angle *= s;
  return q;
}

/// The first s at which `gap` (decreasing while the hand closes) comes down to `target`
/// on the way from the open hand to `posture`, by bisection.
Real closed_to(const HandModel& hand, const JointAngles& posture, Real target,
               const std::function<Real(const HandPose&)>& gap) {
  Real open = 0, closed = 1;
  for (int i = 0; i < 60; ++i) {
    const Real mid = (open + closed) / 2;
    (gap(hand.forward_kinematics(part_way(posture, mid))) > target ? open : closed) = mid;
  }
  return open;
}

const Transform& pose_of(const HandPose& pose, Segment segment) {
  return pose.X_HS[static_cast<std::size_t>(segment)];
}

TEST(GraspTypes, ABarAcrossThePalmIsAPowerGrasp) {
  const GraspRun run = run_grasp(
      cylinder_part("bar", 0.022, 0.08, Vec3(0.02, -0.0105 - 0.022 - 0.0001, -0.06), Vec3::UnitX()),
      *named_posture("power"));
  expect_carried(run, "bar", "power");
}

TEST(GraspTypes, APinBetweenTheThumbAndIndexTipsIsAPrecisionGrasp) {
  // On the way to the pinch posture the thumb's and index's tips come 6 mm apart (the
  // ends of their bones are the bones' closest points there); a pin 6 mm across and 40 mm
  // long lies between them, across the index's fingertip. The glove closes to the pinch,
  // and each digit stops on the pin.
  const HandModel hand;
  const JointAngles pinch = *named_posture("pinch");
  const Real r_thumb = hand.radius(Segment::kThumbDistal);
  const Real r_index = hand.radius(Segment::kIndexDistal);
  const Real s = closed_to(hand, pinch, 0.006, [&](const HandPose& pose) {
    return (pose.p_HTip[1] - pose.p_HTip[0]).norm() - r_thumb - r_index;
  });
  const HandPose pose = hand.forward_kinematics(part_way(pinch, s));
  const Vec3 u = (pose.p_HTip[1] - pose.p_HTip[0]).normalized();
  const Vec3 across = pose_of(pose, Segment::kIndexDistal).R.col(0);
  const GraspRun run =
      run_grasp(cylinder_part("pin", 0.003, 0.04, pose.p_HTip[0] + u * (r_thumb + 0.003),
                              across - u * u.dot(across)),
                pinch);
  expect_carried(run, "pin", "precision");
}

TEST(GraspTypes, AWasherSizedDiscBetweenTheThumbAndTwoFingertipsIsATripod) {
  // A disc the size of an M12 washer, 24 mm across and 3 mm thick; solid, because the
  // thumb's pad meets it below the middle of the index and middle pads (about 16 mm apart),
  // where a washer has its 13 mm hole. On the way to the tripod posture the thumb's tip
  // comes 3 mm from the plane that touches the index and middle tips; the disc lies
  // between, centred on the thumb's tip, its faces parallel to the line between the index
  // and middle tips.
  const HandModel hand;
  const JointAngles tripod = *named_posture("tripod");
  const Real r_thumb = hand.radius(Segment::kThumbDistal);
  const Real r_finger = hand.radius(Segment::kIndexDistal);
  ASSERT_EQ(hand.radius(Segment::kMiddleDistal), r_finger);
  // The disc's normal: from the thumb's tip toward the middle of the two fingertips,
  // square to the line between them.
  auto normal = [](const HandPose& pose) {
    const Vec3 across = (pose.p_HTip[2] - pose.p_HTip[1]).normalized();
    const Vec3 to_pair = (pose.p_HTip[1] + pose.p_HTip[2]) / 2 - pose.p_HTip[0];
    return Vec3((to_pair - across * across.dot(to_pair)).normalized());
  };
  const Real s = closed_to(hand, tripod, 0.003, [&](const HandPose& pose) {
    return ((pose.p_HTip[1] + pose.p_HTip[2]) / 2 - pose.p_HTip[0]).dot(normal(pose)) - r_thumb -
           r_finger;
  });
  const HandPose pose = hand.forward_kinematics(part_way(tripod, s));
  const Vec3 n = normal(pose);
  const GraspRun run = run_grasp(
      cylinder_part("disc", 0.012, 0.003, pose.p_HTip[0] + n * (r_thumb + 0.0015), n), tripod);
  expect_carried(run, "disc", "tripod");
}

TEST(GraspTypes, AGraspRecordedAndReplayedFromItsTraceIsTheSameRun) {
  const engine::PartDef bar =
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

TEST(GraspTypes, AFingerThatStartsInsideAFixedPartClosesNoFurther) {
  // The palm 5 mm above a fixed table: the thumb's metacarpal, which hangs
  // below the palm, starts inside it. Once, a digit that collided where it
  // was took the glove's angles: the closing thumb went through the 10 mm
  // table and wrapped under whatever lay on it. It now keeps its angles
  // until the hand moves it free; the free fingers stop on the table.
  constexpr Real kPalmFace = 0.01045;  // below the wrist, for the default hand
  constexpr Real kTop = -kPalmFace - 0.005, kThick = 0.01;
  engine::Scene scene;
  Transform X_table;
  X_table.t = Vec3(0, kTop - kThick / 2, -0.05);
  scene.add_part({.name = "table",
                  .X_QP = X_table,
                  .movable = false,
                  .render_mesh = std::make_shared<const collision::Mesh>(
                      collision::make_box(Vec3(0.2, kThick / 2, 0.1)))});
  engine::Simulation sim(std::move(scene));
  GlovePlan plan;
  PlanStep close{.kind = PlanStep::Kind::kClose, .duration = 0.5};
  close.posture = *named_posture("fist");
  PlanStep wait{.kind = PlanStep::Kind::kWait, .duration = 0.3};
  plan.steps = {close, wait};
  Hand hand(sim, std::make_shared<SimulatedGlove>(plan));
  Grasping grasping(sim, hand);
  sim.step();
  const JointAngles start = hand.angles();
  for (int frame = 1; frame < 80; ++frame) sim.step();
  for (const Joint j : {Joint::kThumbRoll, Joint::kThumbMcp, Joint::kThumbIp, Joint::kThumbAbd}) {
    const auto i = static_cast<std::size_t>(j);
    EXPECT_EQ(hand.angles()[i], start[i]) << joint_name(j) << " closed inside the table";
  }
  // Every segment's origin is above the table's underside: none went through it.
  for (std::size_t i = 0; i < kSegmentCount; ++i) {
    const Vec3 p_W = engine::compose(hand.X_WH(), hand.pose().X_HS[i]).t;
    EXPECT_GT(p_W.y(), kTop - kThick) << segment_name(static_cast<Segment>(i));
  }
  const auto index_mcp = static_cast<std::size_t>(Joint::kIndexMcp);
  EXPECT_GT(hand.angles()[index_mcp], start[index_mcp] + 1)
      << "the index finger closed until it met the table";
}

TEST(GraspTypes, AnOpenHandBrushingPastGraspsNothing) {
  // The open hand sweeps sideways across a block so that its fingers run through its top.
  engine::Scene scene;
  scene.add_part({.name = "block",
                  .X_QP = {Mat3::Identity(), Vec3(0, -0.02, -0.15)},
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
