// Rubber-band sliding: a peg carried by the simulated glove into a hole with
// 0.25 mm clearance, never penetrating, snapping onto its mate at the bottom.

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <numbers>
#include <optional>

#include "../support/temp_dir.h"
#include "dovetail/collision/contacts.h"
#include "dovetail/collision/primitives.h"
#include "dovetail/interaction/glove_source.h"
#include "dovetail/interaction/glove_trace.h"
#include "dovetail/interaction/grasping.h"
#include "dovetail/interaction/postures.h"

namespace dovetail::interaction {
namespace {

using engine::Event;
using engine::EventKind;

constexpr Real kPegRadius = 0.010;     // 20 mm
constexpr Real kHoleRadius = 0.01025;  // 20.5 mm
constexpr Real kHoleDepth = 0.040;
constexpr Real kPegLength = 0.060;
constexpr Real kBlockTop = 0.03;

/// A box attached to the peg: its half extents and its centre in the peg's
/// frame (z points down the peg, z = 0 at its top).
struct Tab {
  Vec3 half;
  Vec3 p_PT;
};

/// The block (fixed, hole axis along y, opening at y = kBlockTop) and the peg
/// (a cylinder along its z axis from 0 to kPegLength, turned so z points down).
/// With a pebble of height `pebble` (a fixed 8 mm box) on the hole's bottom,
/// and with a box "tab" (attached to the peg by run_peg).
engine::Scene peg_and_block(const Transform& X_WPeg, int sides = 64, Real pebble = 0,
                            const std::optional<Tab>& tab = std::nullopt) {
  engine::Scene scene;
  if (tab) {
    Transform X_PT;
    X_PT.t = tab->p_PT;
    scene.add_part(
        {.name = "tab",
         .X_QP = engine::compose(X_WPeg, X_PT),
         .render_mesh = std::make_shared<const collision::Mesh>(collision::make_box(tab->half))});
  }
  if (pebble > 0) {
    Transform X;
    X.t = Vec3(0, kBlockTop - kHoleDepth + pebble / 2, 0);
    scene.add_part({.name = "pebble",
                    .X_QP = X,
                    .movable = false,
                    .render_mesh = std::make_shared<const collision::Mesh>(
                        collision::make_box(Vec3(0.004, pebble / 2, 0.004)))});
  }
  scene.add_part(
      {.name = "block",
       .movable = false,
       .render_mesh = std::make_shared<const collision::Mesh>(collision::make_block_with_hole(
           Vec3(0.04, kBlockTop, 0.04), kHoleRadius, kHoleDepth, sides))});
  scene.add_part({.name = "peg",
                  .X_QP = X_WPeg,
                  .render_mesh = std::make_shared<const collision::Mesh>(
                      collision::make_cylinder(kPegRadius, kPegLength, 64))});
  return scene;
}

/// The peg 10 mm above the hole, `offset` to the side, tilted by `tilt_deg` about z.
Transform peg_start(Real offset, Real tilt_deg) {
  Transform X;
  X.R = rotation_z_deg(tilt_deg) * rotation_x_deg(90);  // the peg's z axis points down
  X.t = Vec3(offset, kBlockTop + 0.010 + kPegLength, 0);
  return X;
}

struct PegRun {
  std::vector<Event> events;
  Real max_depth = 0;
  bool ever_colliding = false;
  Transform X_WPeg;
  std::vector<Transform> peg_poses;  ///< every frame's
  Transform X_WTab;                  ///< when there is a tab
  std::uint64_t state_hash = 0;
  Real max_stretch = 0;
  std::vector<GloveSample> recorded;  ///< the glove samples the run used
  std::string report;                 ///< the report's JSON
  std::vector<RefusedSnap> refused;
};

struct PegSetup {
  Real offset = 0.0015;  ///< the peg's start off the hole's axis
  Real tilt_deg = -2;    ///< and tilted about z
  bool noise = false;    ///< glove noise
  int threads = 1;
  bool measure_depth = true;  ///< of the peg (and the tab) in the block, every frame
  int sides = 64;             ///< of the hole
  std::shared_ptr<const GloveSource> replay = nullptr;  ///< instead of the simulated glove
  Real pebble = 0;                                      ///< on the hole's bottom
  bool guide = true;                                    ///< the mate's guidance
  std::optional<Tab> tab = std::nullopt;                ///< attached to the peg
  bool flip_axes = false;  ///< the mate's two axes pointing the other way (the same fit)
};

/// The hand holds the peg from the start, carries it 90 mm down along the
/// hole's axis (20 mm past the bottom) in 2 s, waits, and opens.
PegRun run_peg(const PegSetup& setup) {
  const auto& [offset, tilt_deg, noise, threads, measure_depth, sides, replay, pebble, guide, tab,
               flip_axes] = setup;
  const Transform X_WPeg0 = peg_start(offset, tilt_deg);
  engine::Simulation sim(
      peg_and_block(X_WPeg0, sides, pebble, tab),
      {.collision_threads = threads, .contacts = collision::ContactDetail::kPairs});
  // The hand is above the peg, tilted with it, its power posture around nothing.
  GlovePlan plan;
  plan.start.p_WH = X_WPeg0.t + Vec3(0, 0.05, 0.09);
  plan.start.q_WH = engine::quaternion_from_rotation(rotation_z_deg(tilt_deg));
  plan.start_posture = *named_posture("power");
  PlanStep down;
  down.kind = PlanStep::Kind::kReach;
  down.duration = 2.0;
  down.poses = {{plan.start.p_WH - Vec3(0, 0.090, 0), plan.start.q_WH}};
  PlanStep wait;
  wait.kind = PlanStep::Kind::kWait;
  wait.duration = 0.3;
  PlanStep open;
  open.kind = PlanStep::Kind::kOpen;
  open.duration = 0.3;
  plan.steps = {down, wait, open};
  std::shared_ptr<const GloveSource> source = std::make_shared<SimulatedGlove>(plan);
  if (noise) {
    source = std::make_shared<NoisyGlove>(source, GloveNoise{.seed = 3,
                                                             .joint_sigma_deg = 0.5,
                                                             .donning_sigma_deg = 0,
                                                             .position_sigma_m = 0.001,
                                                             .orientation_sigma_deg = 0.5});
  }
  if (tab) sim.scene().set_parent(sim.scene().get("tab"), sim.scene().get("peg"), true);
  Hand hand(sim, replay ? replay : source);
  Grasping grasping(sim, hand);
  grasping.add_mate({.name = "peg_in_hole",
                     .part = "peg",
                     .p_PF = Vec3(0, 0, kPegLength),
                     .axis_P = Vec3(0, 0, flip_axes ? -1 : 1),
                     .other = "block",
                     .p_OF = Vec3(0, kBlockTop - kHoleDepth, 0),
                     .axis_O = Vec3(0, flip_axes ? 1 : -1, 0),
                     .guide = guide});
  grasping.hold("peg", GraspType::kPower);

  const auto block = collision::build_model(collision::Method::kObb,
                                            sim.scene().collision_mesh(sim.scene().get("block")));
  std::vector<std::pair<std::string, std::shared_ptr<const collision::CollisionModel>>> moving;
  for (const char* name : {"peg", "tab"}) {
    const engine::PartId p = sim.scene().find(name);
    if (!p.valid()) continue;
    moving.emplace_back(
        name, collision::build_model(collision::Method::kObb, sim.scene().collision_mesh(p)));
  }
  PegRun run;
  for (int frame = 0; frame < 270; ++frame) {
    const engine::FrameResult& r = sim.step();
    run.events.insert(run.events.end(), r.events.begin(), r.events.end());
    run.peg_poses.push_back(sim.scene().world_pose("peg"));
    if (!measure_depth) continue;
    // Penetration every frame, by the collision layer's contact depth.
    const Transform X_WB = sim.scene().world_pose("block");
    for (const auto& [name, model] : moving) {
      const Transform X_BP = engine::compose(X_WB.inverse(), sim.scene().world_pose(name));
      for (const collision::ContactPatch& patch :
           collision::compute_contacts(*block, *model, X_BP)) {
        run.ever_colliding = true;
        run.max_depth = std::max(run.max_depth, patch.depth);
      }
    }
  }
  run.X_WPeg = sim.scene().world_pose("peg");
  if (tab) run.X_WTab = sim.scene().world_pose("tab");
  run.state_hash = sim.state_hash();
  run.max_stretch = grasping.stats().max_stretch_m;
  run.recorded = hand.recorded();
  run.report = sim.report().to_json();
  run.refused = grasping.refused_snaps();
  return run;
}

bool has(const std::vector<Event>& events, EventKind kind, const std::string& a,
         const std::string& b) {
  return std::any_of(events.begin(), events.end(),
                     [&](const Event& e) { return e.kind == kind && e.a == a && e.b == b; });
}

void expect_in_the_hole(const PegRun& run) {
  EXPECT_TRUE(has(run.events, EventKind::kSlideBegin, "peg", "block"));
  EXPECT_TRUE(has(run.events, EventKind::kRelease, "peg", "opened"));
  EXPECT_TRUE(has(run.events, EventKind::kMate, "peg", "block"));
  EXPECT_LT(run.max_depth, 1e-5) << "penetration along the way";
  // At the bottom, upright, on the hole's axis (after the snap, exactly).
  const Vec3 bottom = run.X_WPeg.apply(Vec3(0, 0, kPegLength));
  EXPECT_NEAR(bottom.y(), kBlockTop - kHoleDepth, 1e-9);
  EXPECT_NEAR(bottom.x(), 0, 1e-9);
  EXPECT_NEAR((run.X_WPeg.R * Vec3::UnitZ()).dot(-Vec3::UnitY()), 1, 1e-12);
}

TEST(PegInHole, SlidesInWithAnOffsetAndATiltAndSnaps) {
  const PegRun run = run_peg({});
  expect_in_the_hole(run);
}

TEST(PegInHole, GoesInWithGloveNoise) {
  const PegRun run = run_peg({.noise = true});
  expect_in_the_hole(run);
}

TEST(PegInHole, ARecordedRunReplaysFromItsTraceIdenticallyAtAnyThreadCount) {
  const PegRun original = run_peg({.noise = true, .measure_depth = false});
  const test::TempDir dir("dovetail_peg");
  write_trace(dir / "peg.csv", original.recorded);
  const auto trace = std::make_shared<TraceSource>(read_trace(dir / "peg.csv"));
  for (const int threads : {1, 2, 8}) {
    const PegRun replay =
        run_peg({.noise = true, .threads = threads, .measure_depth = false, .replay = trace});
    EXPECT_EQ(replay.state_hash, original.state_hash) << threads << " threads";
    EXPECT_EQ(replay.report, original.report) << threads << " threads";
  }
  EXPECT_TRUE(has(original.events, EventKind::kMate, "peg", "block"));
}

TEST(PegInHole, APegFarOffTheHoleIsLeftBehindNotPushedThrough) {
  // 5 mm off the axis, outside the mate's capture: the peg lands on the block's
  // top face and stays there while the hand goes on down, until the band breaks.
  const PegRun run = run_peg({.offset = 0.005, .tilt_deg = 0});
  EXPECT_TRUE(has(run.events, EventKind::kRelease, "peg", "overstretched"));
  EXPECT_FALSE(has(run.events, EventKind::kMate, "peg", "block"));
  EXPECT_LT(run.max_depth, 1e-5);
  const Vec3 bottom = run.X_WPeg.apply(Vec3(0, 0, kPegLength));
  EXPECT_GE(bottom.y(), kBlockTop);
  EXPECT_LT(bottom.y(), kBlockTop + 1e-4);
}

TEST(PegInHole, APegStoppedShortByAPebbleIsNotSnappedThroughIt) {
  // A 1.5 mm pebble on the hole's bottom: the peg stops on it, within the
  // mate's 2 mm tolerance, and is released there. Seated, it would overlap
  // the pebble by 1.5 mm, so it stays where it is and the refusal says why.
  const PegRun run = run_peg({.pebble = 0.0015});
  EXPECT_TRUE(has(run.events, EventKind::kRelease, "peg", "opened"));
  EXPECT_FALSE(has(run.events, EventKind::kMate, "peg", "block"));
  ASSERT_EQ(run.refused.size(), 1u);
  EXPECT_EQ(run.refused[0].mate, "peg_in_hole");
  EXPECT_EQ(run.refused[0].part, "peg");
  EXPECT_EQ(run.refused[0].blocker, "pebble");
  EXPECT_EQ(run.refused[0].overlapping, "peg");
  EXPECT_NEAR(run.refused[0].depth_m, 0.0015, 1e-5);
  const Vec3 bottom = run.X_WPeg.apply(Vec3(0, 0, kPegLength));
  EXPECT_GE(bottom.y(), kBlockTop - kHoleDepth + 0.0015);
  EXPECT_LT(bottom.y(), kBlockTop - kHoleDepth + 0.0015 + 1e-4);
  EXPECT_LT(run.max_depth, 1e-5);
}

TEST(PegInHole, APegIsDrawnOntoTheAxisOnlyAsItReachesTheBlock) {
  // Guidance stands for a chamfer: it draws in a peg whose tip reaches the
  // hole. Held 10 mm above the block the peg keeps its offset and tilt, so a
  // start 0.5 mm further off is another run (it was drawn in at once, and
  // two such starts gave the same report).
  // The mate's axes pointing out of the hole are the same fit, drawn in at
  // the same place (the gate once read "past the block" along the axis only
  // one way, and drew such a peg in from 100 mm up).
  const PegRun run = run_peg({.measure_depth = false});
  for (const bool flip : {false, true}) {
    const PegRun r = flip ? run_peg({.measure_depth = false, .flip_axes = true}) : run;
    bool drawn = false;
    for (const Transform& X : r.peg_poses) {
      const Vec3 tip = X.apply(Vec3(0, 0, kPegLength));
      if (tip.y() > kBlockTop + 0.003) {
        EXPECT_NEAR(X.t.x(), 0.0015, 1e-12)
            << "drawn in with its tip " << tip.y() - kBlockTop << " m above, axes flipped " << flip;
      } else if (tip.y() < kBlockTop - 0.001) {
        EXPECT_NEAR(tip.x(), 0, 1e-5) << "in the hole off its axis";
        drawn = true;
      }
    }
    EXPECT_TRUE(drawn);
  }
  const PegRun further = run_peg({.offset = 0.0019, .measure_depth = false});
  expect_in_the_hole(further);
  EXPECT_NE(further.report, run.report);
}

TEST(PegInHole, WithoutGuidanceAPegOffTheAxisStaysOnTheRim) {
  // The mate's guidance is what draws the peg 1.5 mm off the axis into the
  // hole with 0.25 mm clearance; without it (a hole without a chamfer) the
  // peg lands on the rim and is left behind, never pushed through.
  const PegRun run = run_peg({.guide = false});
  EXPECT_FALSE(has(run.events, EventKind::kMate, "peg", "block"));
  EXPECT_LT(run.max_depth, 1e-5);
  EXPECT_GE(run.X_WPeg.apply(Vec3(0, 0, kPegLength)).y(), kBlockTop - 1e-3);
}

/// A 4 mm box beside the peg, 17 mm off its axis, whose lower face is `short_of_seat` above
/// the block's top face when the peg is seated (negative: in it).
Tab tab_beside(Real short_of_seat) {
  return {Vec3(0.002, 0.002, 0.002),
          Vec3(0.017, 0, kPegLength - kHoleDepth - 0.002 - short_of_seat)};
}

TEST(PegInHole, APartAttachedToThePegStopsItWhereTheAttachedPartMeetsTheBlock) {
  // The tab would end 3 mm deep in the block's top face: it lands on the face
  // and holds the peg 3 mm short of its seat, outside the mate's 2 mm
  // tolerance, so the peg is released there and not snapped.
  const PegRun run = run_peg({.offset = 0, .tilt_deg = 0, .tab = tab_beside(-0.003)});
  EXPECT_TRUE(has(run.events, EventKind::kRelease, "peg", "opened"));
  EXPECT_FALSE(has(run.events, EventKind::kMate, "peg", "block"));
  EXPECT_TRUE(run.refused.empty());
  // The tab slides on the block, and the peg, tilted onto the hole's wall,
  // too: each pair that touches is named, in the order they meet.
  EXPECT_TRUE(has(run.events, EventKind::kSlideBegin, "tab", "block"));
  EXPECT_TRUE(has(run.events, EventKind::kSlideBegin, "peg", "block"));
  const auto first = [&](const std::string& part) {
    return std::find_if(run.events.begin(), run.events.end(), [&](const Event& e) {
      return e.kind == EventKind::kSlideBegin && e.a == part;
    });
  };
  EXPECT_LT(first("tab") - run.events.begin(), first("peg") - run.events.begin());
  EXPECT_LT(run.max_depth, 1e-5) << "the tab or the peg in the block";
  // The tab rests on the face; the peg, held up by it, is about 3 mm short
  // (tilted a little about the tab until it meets the hole's wall).
  Real tab_low = std::numeric_limits<Real>::infinity();
  for (const Vec3& v : collision::make_box(Vec3(0.002, 0.002, 0.002)).vertices) {
    tab_low = std::min(tab_low, run.X_WTab.apply(v).y());
  }
  EXPECT_GE(tab_low, kBlockTop);
  EXPECT_LT(tab_low, kBlockTop + 1e-5);
  const Vec3 bottom = run.X_WPeg.apply(Vec3(0, 0, kPegLength));
  EXPECT_NEAR(bottom.y(), kBlockTop - kHoleDepth + 0.003, 5e-4);
}

TEST(PegInHole, APartAttachedToThePegIsCheckedBeforeTheSnapToo) {
  // The tab would end 1 mm deep in the block's top face: it holds the peg
  // 1 mm short of its seat, within the mate's tolerance; the peg itself would
  // seat cleanly, but the snap, which moves the tab with it, is refused,
  // naming the block.
  const PegRun run = run_peg({.offset = 0, .tilt_deg = 0, .tab = tab_beside(-0.001)});
  EXPECT_TRUE(has(run.events, EventKind::kRelease, "peg", "opened"));
  EXPECT_FALSE(has(run.events, EventKind::kMate, "peg", "block"));
  ASSERT_EQ(run.refused.size(), 1u);
  EXPECT_EQ(run.refused[0].blocker, "block");
  EXPECT_EQ(run.refused[0].overlapping, "tab");
  EXPECT_NEAR(run.refused[0].depth_m, 0.001, 1e-4);
  EXPECT_LT(run.max_depth, 1e-5) << "the tab or the peg in the block";
}

TEST(PegInHole, APartAttachedToThePegAndTouchingItGoesAlong) {
  // A box pressed against the peg's side near its top (touching it, never
  // reaching the block): no obstacle to the peg, which slides in and seats
  // with the box.
  const PegRun run =
      run_peg({.tab = Tab{Vec3(0.002, 0.002, 0.002), Vec3(kPegRadius + 0.002, 0, 0.002)}});
  expect_in_the_hole(run);
}

TEST(PegInHole, ACoarselyTessellatedHoleStillTakesThePeg) {
  // 12 flat walls whose flats lie on the hole's radius (corners 3.5 % further out): the
  // peg, 64 facets inscribed in its radius, fits with the same 0.25 mm clearance at the
  // flats, so it still slides in and mates.
  const PegRun run = run_peg({.sides = 12});
  expect_in_the_hole(run);
}

}  // namespace
}  // namespace dovetail::interaction
