// The hand in a simulation: the invisible hand's contact events, recording
// and replay, determinism across thread counts.

#include "dovetail/interaction/hand.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <set>

#include "../support/temp_dir.h"
#include "dovetail/collision/primitives.h"
#include "dovetail/interaction/glove_trace.h"
#include "dovetail/interaction/postures.h"

namespace dovetail::interaction {
namespace {

using engine::Event;
using engine::EventKind;

constexpr Real kDt = 1.0 / 90.0;

/// An open hand, palm down, going straight down at `speed` from height y0.
class FallingHand final : public GloveSource {
 public:
  FallingHand(Real y0, Real speed) : y0_(y0), speed_(speed) {}
  GloveSample sample(Real t) const override {
    GloveSample s;
    s.t = t;
    s.p_WH = Vec3(0, y_at(t), 0);
    return s;
  }
  Real end_time() const override { return 1; }
  Real y_at(Real t) const { return y0_ - speed_ * t; }

 private:
  Real y0_, speed_;
};

/// A box under the whole hand, 2 mm thick (thinner than every segment, so a
/// segment passing through always crosses its surface: a segment wholly inside
/// a part crosses no surface and has no contact): top face y = 0, bottom y = -0.002.
constexpr Real kSlabBottom = -0.002;
engine::Scene slab_scene() {
  engine::Scene scene;
  scene.add_part({.name = "slab",
                  .X_QP = {collision::Mat3::Identity(), Vec3(0, -0.001, -0.1)},
                  .movable = false,
                  .render_mesh = std::make_shared<const collision::Mesh>(
                      collision::make_box(Vec3(0.2, 0.001, 0.2)))});
  return scene;
}

TEST(InvisibleHand, OpenHandThroughABoxTouchesEachSegmentInTheExpectedFrames) {
  const auto source = std::make_shared<FallingHand>(0.05, 0.2);
  engine::Simulation sim(slab_scene(), {.time_step = kDt});
  Hand hand(sim, source);

  // Expected frames from each proxy's extent below and above the hand frame:
  // contact begins in the first frame whose lowest point reaches the top face
  // (touching counts) and ends in the first whose highest point is below the bottom.
  const HandPose pose = hand.model().forward_kinematics(JointAngles{});
  std::map<std::string, std::pair<std::uint64_t, std::uint64_t>> expected;
  for (std::size_t i = 0; i < kSegmentCount; ++i) {
    const auto segment = static_cast<Segment>(i);
    Real low = INFINITY, high = -INFINITY;
    for (const Vec3& p : hand.model().proxy(segment)->vertices) {
      const Real y = pose.X_HS[i].apply(p).y();
      low = std::min(low, y);
      high = std::max(high, y);
    }
    std::uint64_t begin = 0, end = 0;
    while (source->y_at(static_cast<Real>(begin) * kDt) + low > 0) ++begin;
    while (source->y_at(static_cast<Real>(end) * kDt) + high >= kSlabBottom) ++end;
    // No frame lands within rounding of touching, so the expectation is sharp.
    ASSERT_GT(std::abs(source->y_at(static_cast<Real>(begin) * kDt) + low), 1e-9);
    ASSERT_GT(std::abs(source->y_at(static_cast<Real>(end) * kDt) + high - kSlabBottom), 1e-9);
    expected["hand." + std::string(segment_name(segment))] = {begin, end};
  }

  std::map<std::string, std::pair<std::uint64_t, std::uint64_t>> seen;
  sim.events().subscribe_all([&](const Event& e) {
    ASSERT_NE(e.kind, EventKind::kContactBegin) << e.a << " " << e.b;  // all are the hand's
    if (e.kind == EventKind::kHandContactBegin) {
      EXPECT_EQ(e.b, "slab");
      EXPECT_FALSE(seen.count(e.a)) << e.a << " began twice";
      seen[e.a].first = e.frame;
    } else if (e.kind == EventKind::kHandContactEnd) {
      EXPECT_EQ(e.b, "slab");
      seen[e.a].second = e.frame;
    }
  });
  sim.run(60);
  EXPECT_EQ(seen, expected);
  // The segments were tested against the slab only, never against each other.
  for (const engine::PairContactStats& c : sim.report().contacts) {
    EXPECT_TRUE(c.a == "slab" || c.b == "slab") << c.a << " " << c.b;
  }
  // The thumb's metacarpal, lowest of all, touches first.
  EXPECT_EQ(std::min_element(expected.begin(), expected.end(),
                             [](const auto& x, const auto& y) { return x.second < y.second; })
                ->first,
            "hand.thumb_metacarpal");
}

TEST(InvisibleHand, ClampedJointsLeaveANote) {
  class Overbent final : public GloveSource {
   public:
    GloveSample sample(Real t) const override {
      GloveSample s;
      s.t = t;
      at(s.joints, Joint::kIndexPip) = 100 + 100 * t;  // past 110 from t = 0.1
      return s;
    }
    Real end_time() const override { return 1; }
  };
  engine::Simulation sim(slab_scene(), {.time_step = kDt});
  Hand hand(sim, std::make_shared<Overbent>());
  sim.run(30);
  ASSERT_EQ(sim.report().notes.size(), 1U);
  EXPECT_NE(sim.report().notes[0].find("index_pip"), std::string::npos);
  EXPECT_NE(sim.report().notes[0].find("frame 10"), std::string::npos) << sim.report().notes[0];
  EXPECT_EQ(hand.clamped_frames()[static_cast<std::size_t>(Joint::kIndexPip)], 20U);
  EXPECT_EQ(at(hand.angles(), Joint::kIndexPip), 110);
  EXPECT_NE(sim.report().to_json().find("\"notes\""), std::string::npos);
}

/// A hand that sweeps through three blocks while closing to a fist, seen
/// through a noisy glove.
std::shared_ptr<const GloveSource> sweeping_glove(std::uint64_t seed) {
  GlovePlan plan;
  plan.start.p_WH = Vec3(-0.3, 0.02, 0);
  PlanStep reach;
  reach.kind = PlanStep::Kind::kReach;
  reach.duration = 1.5;
  reach.poses = {{Vec3(0.3, -0.01, 0.02), engine::Quaternion{0.9, 0.1, 0.3, 0.1}}};
  PlanStep close;
  close.kind = PlanStep::Kind::kClose;
  close.duration = 0.5;
  close.posture = *named_posture("fist");
  plan.steps = {reach, close};
  return std::make_shared<NoisyGlove>(std::make_shared<SimulatedGlove>(plan),
                                      GloveNoise{.seed = seed});
}

engine::Scene blocks_scene() {
  engine::Scene scene;
  const auto block =
      std::make_shared<const collision::Mesh>(collision::make_box(Vec3(0.02, 0.03, 0.05)));
  for (int i = 0; i < 3; ++i) {
    scene.add_part({.name = "block" + std::to_string(i),
                    .X_QP = {collision::Mat3::Identity(), Vec3(-0.15 + 0.15 * i, 0, -0.08)},
                    .movable = i == 1,
                    .render_mesh = block});
  }
  return scene;
}

struct RunResult {
  std::uint64_t state_hash = 0;
  std::vector<Event> timeline;
  std::vector<GloveSample> recorded;
};

RunResult run_hand(std::shared_ptr<const GloveSource> source, int threads, Real time_step,
                   std::uint64_t frames) {
  engine::Simulation sim(blocks_scene(), {.time_step = time_step,
                                          .collision_threads = threads,
                                          .contacts = collision::ContactDetail::kTriangles});
  Hand hand(sim, std::move(source));
  sim.run(frames);
  return {sim.state_hash(), sim.report().events, hand.recorded()};
}

TEST(HandReplay, Trace120HzIn90HzSimulationIsTheSameAtAnyThreadCount) {
  // Record the noisy glove at 120 Hz, as a real glove would, through the file format.
  const auto glove = sweeping_glove(7);
  std::vector<GloveSample> samples;
  for (int k = 0; k <= 2 * 120; ++k) samples.push_back(glove->sample(k / 120.0));
  const test::TempDir dir("dovetail_hand");
  write_trace(dir / "glove.csv", samples);
  const auto trace = std::make_shared<TraceSource>(read_trace(dir / "glove.csv"));

  const RunResult first = run_hand(trace, 1, kDt, 180);
  const RunResult again = run_hand(trace, 1, kDt, 180);
  EXPECT_EQ(first.state_hash, again.state_hash);
  EXPECT_EQ(first.timeline, again.timeline);
  std::size_t hand_contacts = 0;
  for (const Event& e : first.timeline) hand_contacts += e.kind == EventKind::kHandContactBegin;
  EXPECT_GT(hand_contacts, 3U) << "the sweep should touch the blocks";
  for (const int threads : {2, 8}) {
    const RunResult other = run_hand(trace, threads, kDt, 180);
    EXPECT_EQ(other.state_hash, first.state_hash) << threads << " threads";
    EXPECT_EQ(other.timeline, first.timeline) << threads << " threads";
  }
}

TEST(HandReplay, ARecordedRunReplaysToTheSameRun) {
  const RunResult original = run_hand(sweeping_glove(11), 1, kDt, 200);
  ASSERT_EQ(original.recorded.size(), 200U);
  const test::TempDir dir("dovetail_hand");
  write_trace(dir / "recorded.csv", original.recorded);
  const RunResult replay =
      run_hand(std::make_shared<TraceSource>(read_trace(dir / "recorded.csv")), 2, kDt, 200);
  EXPECT_EQ(replay.state_hash, original.state_hash);
  EXPECT_EQ(replay.timeline, original.timeline);
  for (std::size_t i = 0; i < original.recorded.size(); ++i) {
    ASSERT_TRUE(same_bits(replay.recorded[i], original.recorded[i])) << "frame " << i;
  }
  // Another noise seed is another run.
  EXPECT_NE(run_hand(sweeping_glove(12), 1, kDt, 200).state_hash, original.state_hash);
}

}  // namespace
}  // namespace dovetail::interaction

namespace dovetail::interaction {
namespace {

TEST(InvisibleHand, ARemovedSegmentIsNoLongerPosedAndTheRunGoesOn) {
  engine::Simulation sim(slab_scene(), {.time_step = kDt});
  Hand hand(sim, std::make_shared<FallingHand>(0.05, 0.2));
  sim.step();
  sim.scene().remove_part(hand.part(Segment::kPinkyDistal));
  EXPECT_NO_THROW(sim.run(40));
  EXPECT_FALSE(sim.scene().find("hand.pinky_distal").valid());
  EXPECT_EQ(sim.scene().part_count(), 16U);
}

TEST(InvisibleHand, ATakenNameAddsNoSegment) {
  engine::Scene scene = slab_scene();
  scene.add_part({.name = "hand.index_proximal"});
  engine::Simulation sim(std::move(scene));
  EXPECT_THROW(Hand(sim, std::make_shared<FallingHand>(0.05, 0.2)), engine::SceneError);
  EXPECT_EQ(sim.scene().part_count(), 2U);
}

TEST(InvisibleHand, TwoHandsKeepTheirEventsApart) {
  engine::Simulation sim(slab_scene(), {.time_step = kDt});
  HandSettings left_settings, right_settings;  // (designated initialisers trip GCC 12's
  left_settings.name = "left";                 // -Wmaybe-uninitialized here)
  right_settings.name = "right";
  Hand left(sim, std::make_shared<FallingHand>(0.05, 0.2), left_settings);
  Hand right(sim, std::make_shared<FallingHand>(0.06, 0.2), right_settings);
  std::set<std::string> touching;
  sim.events().subscribe(EventKind::kHandContactBegin,
                         [&](const Event& e) { EXPECT_TRUE(touching.insert(e.a).second) << e.a; });
  std::size_t hands_touching = 0;
  sim.events().subscribe(EventKind::kContactBegin, [&](const Event& e) {
    EXPECT_TRUE(e.a.starts_with("left.") && e.b.starts_with("right.")) << e.a << " " << e.b;
    ++hands_touching;
  });
  sim.run(40);
  EXPECT_GT(hands_touching, 0U) << "the two hands overlap: their contacts stay contact events";
  EXPECT_TRUE(touching.count("left.palm"));
  EXPECT_TRUE(touching.count("right.palm"));
}

}  // namespace
}  // namespace dovetail::interaction
