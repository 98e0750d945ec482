// Hand benchmark: what the glove-driven hand costs per frame.
//
//   hand_bench [--runs R] [--detail pairs|triangles|both] [--pictures DIR] [--slow MS]
//              [--sweep TABLE] [--grasping]
// --slow MS lists the sliding frames slower than MS milliseconds, with their
// sub-steps, collision queries and contacts. --sweep TABLE runs only the
// sliding scene along the wall (below), with the contact search's resolution
// and sub-step budget varied, measuring the deepest overlap of peg and block
// every frame and their distance in the frames in contact, and writes the
// table behind the sliding chart (scripts/charts.sh). --grasping runs only
// the grasping scenes (below).
//
// One collision thread. Each scene is a 10,000-triangle part and the hand,
// driven by the simulated glove through a plan that approaches, closes
// around or through the part, slides along it, opens and leaves, so most
// frames have several segments in contact. Per frame: the whole simulation
// step (glove sample, joint limits, forward kinematics, the 16 proxies'
// poses, the collision pipeline hand-against-part, events, state hash),
// and of it the collision pipeline. Reported: median, 95th percentile and
// worst frame over all frames of all runs, and the median of the per-run
// medians with its spread. Scenes:
//   torus  a ring of 100 x 50 quads (concave), the hand wrapping its rim;
//   plate  a 1 mm plate of two 50 x 50 grids (thin), the closing fingers
//          passing through it;
//   far    the torus scene 2.3 km from the origin.
// Plus forward kinematics and proxy poses alone, 10^5 times.
//
// Sliding: the interaction step (closing the fingers, contact analysis, the
// rubber band and their collision queries, Grasping::stats().frame_ms) while
// the hand carries a 10,240-triangle peg (20 mm, 256 sides in 19 bands) 1.5 mm off the
// axis and tilted 2 degrees into a hole of 20.5 mm in a block, down to the
// bottom and 20 mm past it (the peg resting there, the band stretched), then
// opens: median, 95th percentile and worst frame while the peg is held and
// in contact. The same peg also slides down the hole's wall: upright, 5 mm
// into the hole, the hand moves 0.5 mm sideways (the hole leaves 0.25 mm) and
// then down past the bottom, with no mate to draw the peg off the wall, so it
// slides 35 mm in contact. Each scene three times, side by side: the plain
// search (a whole-part collision query per halving toward each contact pose,
// the contact patches analysed at every hit), the one guided by the colliding
// triangle pair without separation fronts, and the default (guided, fronts).
//
// Grasping: the interaction step while the open hand closes on a
// 10,240-triangle bar and holds it (grasping(), below).

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <memory>
#include <numbers>
#include <string>
#include <vector>

#include "bench_util.h"
#include "dovetail/collision/contacts.h"
#include "dovetail/collision/distance.h"
#include "dovetail/collision/model.h"
#include "dovetail/collision/primitives.h"
#include "dovetail/engine/render.h"
#include "dovetail/engine/scene.h"
#include "dovetail/engine/scene_render.h"
#include "dovetail/engine/simulation.h"
#include "dovetail/interaction/glove_source.h"
#include "dovetail/interaction/grasping.h"
#include "dovetail/interaction/hand.h"
#include "dovetail/interaction/postures.h"

namespace {

using dovetail::bench::percentile;

using namespace dovetail;
using collision::Mat3;
using collision::Real;
using collision::Transform;
using collision::Vec3;
using interaction::GlovePlan;
using interaction::PlanStep;
using Clock = std::chrono::steady_clock;

/// Two grids of n x n quads, 1 mm apart, plus four side walls.
collision::Mesh plate(Real size, int n) {
  std::vector<Vec3> v;
  std::vector<collision::TriangleIndices> t;
  for (const Real y : {-0.0005, 0.0005}) {
    const auto base = static_cast<std::uint32_t>(v.size());
    for (int i = 0; i <= n; ++i) {
      for (int j = 0; j <= n; ++j)
        v.emplace_back(size * (i / Real(n) - 0.5), y, size * (j / Real(n) - 0.5));
    }
    auto at = [&](int i, int j) { return base + static_cast<std::uint32_t>(i * (n + 1) + j); };
    for (int i = 0; i < n; ++i) {
      for (int j = 0; j < n; ++j) {
        if (y > 0) {
          t.push_back({at(i, j), at(i, j + 1), at(i + 1, j + 1)});
          t.push_back({at(i, j), at(i + 1, j + 1), at(i + 1, j)});
        } else {
          t.push_back({at(i, j), at(i + 1, j + 1), at(i, j + 1)});
          t.push_back({at(i, j), at(i + 1, j), at(i + 1, j + 1)});
        }
      }
    }
  }
  const auto top = static_cast<std::uint32_t>((n + 1) * (n + 1));
  const std::uint32_t corners[4] = {0, static_cast<std::uint32_t>(n),
                                    static_cast<std::uint32_t>((n + 1) * (n + 1) - 1),
                                    static_cast<std::uint32_t>(n * (n + 1))};
  for (int k = 0; k < 4; ++k) {
    const std::uint32_t a = corners[k], b = corners[(k + 1) % 4];
    t.push_back({a, b, b + top});
    t.push_back({a, b + top, a + top});
  }
  return collision::make_mesh(std::move(v), std::move(t), "bench:plate");
}

PlanStep reach(Real duration, const Vec3& p_WH) {
  PlanStep s;
  s.kind = PlanStep::Kind::kReach;
  s.duration = duration;
  s.poses = {{p_WH, {}}};
  return s;
}

PlanStep close(Real duration, const char* posture) {
  PlanStep s;
  s.kind = PlanStep::Kind::kClose;
  s.duration = duration;
  s.posture = *interaction::named_posture(posture);
  return s;
}

/// Approach from above, close, slide along x, open, leave; everything offset by `o`.
GlovePlan plan(const Vec3& o, Real low_y, const char* posture) {
  GlovePlan p;
  p.start.p_WH = o + Vec3(0, 0.12, 0.10);
  p.steps = {reach(1.0, o + Vec3(0, low_y, 0.10)),
             close(0.5, posture),
             reach(1.5, o + Vec3(0.05, low_y, 0.09)),
             reach(1.5, o + Vec3(-0.05, low_y, 0.09)),
             close(0.5, "open"),
             reach(1.0, o + Vec3(0, 0.12, 0.10))};
  return p;
}

struct Scene {
  const char* name;
  std::shared_ptr<const collision::Mesh> mesh;
  Transform X_WP;
  GlovePlan plan;
};

struct Frames {
  std::vector<double> step_ms, collision_ms;
  std::vector<double> run_median_step_ms;
  double contact_frames = 0, frames = 0, segments_in_contact = 0;
  std::uint64_t state_hash = 0;
  bool same_hash = true;
};

Frames measure(const Scene& scene, collision::ContactDetail detail, int runs) {
  Frames out;
  for (int run = 0; run < runs; ++run) {
    engine::Scene parts;
    parts.add_part(
        {.name = "part", .X_QP = scene.X_WP, .movable = false, .render_mesh = scene.mesh});
    engine::Simulation sim(std::move(parts), {.collision_threads = 1, .contacts = detail});
    interaction::Hand hand(sim, std::make_shared<interaction::SimulatedGlove>(scene.plan));
    sim.prepare();
    sim.step();  // the hand's parts join the collision world in the first frame: built there
    sim.prepare();
    const auto frames = static_cast<std::uint64_t>(std::llround(scene.plan.duration() * 90));
    std::vector<double> steps;
    for (std::uint64_t f = 0; f < frames; ++f) {
      const auto t0 = Clock::now();
      const engine::FrameResult& r = sim.step();
      steps.push_back(std::chrono::duration<double, std::milli>(Clock::now() - t0).count());
      out.collision_ms.push_back(sim.report().timings.back().collision_ms);
      if (run == 0) {
        out.frames += 1;
        out.contact_frames += r.collision.colliding_pairs > 0;
        out.segments_in_contact += static_cast<double>(r.collision.colliding_pairs);
      }
    }
    out.step_ms.insert(out.step_ms.end(), steps.begin(), steps.end());
    out.run_median_step_ms.push_back(percentile(steps, 0.5));
    if (run == 0) out.state_hash = sim.state_hash();
    out.same_hash = out.same_hash && sim.state_hash() == out.state_hash;
  }
  return out;
}

void fk_only() {
  const interaction::HandModel model;
  const interaction::JointAngles fist = *interaction::named_posture("fist");
  Transform X_WH;
  X_WH.t = Vec3(0.1, 0.2, 0.3);
  constexpr int kCount = 100000;
  double sink = 0;
  const auto t0 = Clock::now();
  for (int i = 0; i < kCount; ++i) {
    interaction::JointAngles q = fist;
    q[5] = 0.001 * (i % 1000);
    const interaction::HandPose pose = model.forward_kinematics(interaction::clamp_to_limits(q));
    for (const Transform& X_HS : pose.X_HS) sink += engine::compose(X_WH, X_HS).t.x();
  }
  const double us = std::chrono::duration<double, std::micro>(Clock::now() - t0).count() / kCount;
  std::printf("forward kinematics + 16 proxy poses: %.2f us per frame (checksum %.3f)\n", us, sink);
}

/// A closed cylinder along z from 0 to `length`: `sides` around, the side cut into
/// `rings` bands, caps fanned from their centres.
collision::Mesh banded_cylinder(Real radius, Real length, int sides, int rings) {
  std::vector<Vec3> v;
  std::vector<collision::TriangleIndices> t;
  for (int r = 0; r <= rings; ++r) {
    for (int s = 0; s < sides; ++s) {
      const Real a = 2 * std::numbers::pi * s / sides;
      v.emplace_back(radius * std::cos(a), radius * std::sin(a), length * r / rings);
    }
  }
  auto at = [&](int r, int s) { return static_cast<std::uint32_t>(r * sides + (s % sides)); };
  for (int r = 0; r < rings; ++r) {
    for (int s = 0; s < sides; ++s) {
      t.push_back({at(r, s), at(r, s + 1), at(r + 1, s + 1)});
      t.push_back({at(r, s), at(r + 1, s + 1), at(r + 1, s)});
    }
  }
  const auto bottom = static_cast<std::uint32_t>(v.size());
  v.emplace_back(0, 0, 0);
  const auto top = static_cast<std::uint32_t>(v.size());
  v.emplace_back(0, 0, length);
  for (int s = 0; s < sides; ++s) {
    t.push_back({bottom, at(0, s + 1), at(0, s)});
    t.push_back({top, at(rings, s), at(rings, s + 1)});
  }
  return collision::make_mesh(std::move(v), std::move(t), "bench:banded cylinder");
}

/// A picture of the power grasp of a bar (the scene of the grasp tests), lifted.
void grasp_picture(const std::string& pictures) {
  engine::Scene scene;
  Transform X_bar;
  X_bar.R << 0, 0, 1, 0, 1, 0, -1, 0, 0;  // the cylinder's z axis along x
  X_bar.t = Vec3(0.02 - 0.04, -0.0105 - 0.022 - 0.0001, -0.06);
  scene.add_part({.name = "bar",
                  .X_QP = X_bar,
                  .render_mesh = std::make_shared<const collision::Mesh>(
                      collision::make_cylinder(0.022, 0.08, 48))});
  engine::Simulation sim(std::move(scene));
  GlovePlan p;
  p.steps = {close(0.5, "power"), reach(0.5, Vec3(0, 0.05, 0))};
  interaction::Hand hand(sim, std::make_shared<interaction::SimulatedGlove>(p));
  interaction::Grasping grasping(sim, hand);
  sim.run(90);
  engine::RenderSettings settings{.width = 480, .height = 360, .camera = "iso"};
  engine::write_png(engine::render(engine::render_scene(sim.scene()), settings),
                    pictures + "/power-grasp.png");
  std::printf("picture: power grasp, %s\n",
              grasping.grasp_type()
                  ? std::string(interaction::grasp_type_name(*grasping.grasp_type())).c_str()
                  : "no grasp");
}

/// What the sliding scene gave over all runs.
struct SlidingRuns {
  std::vector<double> contact_ms;       ///< interaction step per frame in contact, all runs
  std::vector<double> querying_ms;      ///< ... of those frames that made collision queries
  std::vector<double> run_medians;      ///< median of each run
  std::uint64_t frames_in_contact = 0;  ///< of the first run
  std::uint64_t mated = 0;
  std::size_t triangles = 0;
  /// Height of the peg's tip over the hole's bottom at the end, the highest of all runs.
  Real tip_over_bottom_m = -1;
  std::uint64_t at_bottom = 0;  ///< runs that ended with the tip within 0.01 mm of the bottom
  /// Deepest overlap of peg and block over every frame of every run (the
  /// collision layer's contact depth), when measured.
  Real max_penetration = 0;
  /// The gap between peg and block over the frames in contact, when measured:
  /// how close to the surfaces the contact search brings the part.
  std::vector<double> contact_gap_m;
};

/// How the hand carries the peg.
enum class Carry {
  /// 1.5 mm off the hole's axis and tilted 2 degrees, straight down to 20 mm past the
  /// bottom; the mate draws the peg onto the axis (Mate::position_tolerance).
  kIntoHole,
  /// Upright on the axis until its tip is 5 mm into the hole, 0.5 mm sideways (twice the
  /// 0.25 mm the hole leaves), then down to 10 mm past the bottom: the peg slides 35 mm down
  /// pressed against the wall. No mate, so nothing draws it off the wall.
  kAlongWall,
};

/// The peg carried into the hole `runs` times with these sliding settings.
SlidingRuns sliding_runs(int runs, const std::string& pictures,
                         const interaction::SlidingSettings& sliding_settings, double slow_ms,
                         bool measure_penetration, Carry carry = Carry::kIntoHole) {
  constexpr Real kTop = 0.03, kDepth = 0.04, kLength = 0.06;
  const auto block = std::make_shared<const collision::Mesh>(
      collision::make_block_with_hole(Vec3(0.04, kTop, 0.04), 0.01025, kDepth, 64));
  const auto peg = std::make_shared<const collision::Mesh>(banded_cylinder(0.01, kLength, 256, 19));
  SlidingRuns out;
  out.triangles = peg->triangle_count();
  // The measuring models, built only when measuring.
  std::shared_ptr<const collision::CollisionModel> block_model, peg_model;
  std::shared_ptr<const collision::DistanceModel> block_distance, peg_distance;
  if (measure_penetration) {
    block_model = collision::build_model(collision::Method::kObb, block);
    peg_model = collision::build_model(collision::Method::kObb, peg);
    block_distance = collision::build_distance_model(block);
    peg_distance = collision::build_distance_model(peg);
  }
  const bool wall = carry == Carry::kAlongWall;
  const Real tilt_deg = wall ? 0 : -2;
  constexpr Real kBottom = kTop - kDepth;  // the hole's bottom, y in the world
  for (int run = 0; run < runs; ++run) {
    Transform X_WPeg;
    X_WPeg.R = interaction::rotation_z_deg(tilt_deg) * interaction::rotation_x_deg(90);
    X_WPeg.t = Vec3(wall ? 0 : 0.0015, kTop + 0.01 + kLength, 0);
    engine::Scene scene;
    scene.add_part({.name = "block", .movable = false, .render_mesh = block});
    scene.add_part({.name = "peg", .X_QP = X_WPeg, .render_mesh = peg});
    engine::Simulation sim(std::move(scene), {.collision_threads = 1});
    GlovePlan p;
    p.start.p_WH = X_WPeg.t + Vec3(0, 0.05, 0.09);
    p.start.q_WH = engine::quaternion_from_rotation(interaction::rotation_z_deg(tilt_deg));
    p.start_posture = *interaction::named_posture("power");
    if (wall) {
      PlanStep enter = reach(0.5, p.start.p_WH - Vec3(0, 0.015, 0));
      PlanStep aside = reach(0.2, p.start.p_WH - Vec3(-0.0005, 0.015, 0));
      PlanStep down = reach(1.5, p.start.p_WH - Vec3(-0.0005, 0.065, 0));
      enter.poses[0].q_WH = aside.poses[0].q_WH = down.poses[0].q_WH = p.start.q_WH;
      p.steps = {enter, aside, down, close(0.3, "power"), close(0.3, "open")};
    } else {
      PlanStep down = reach(2.0, p.start.p_WH - Vec3(0, 0.09, 0));
      down.poses[0].q_WH = p.start.q_WH;
      p.steps = {down, close(0.3, "power"), close(0.3, "open")};
    }
    interaction::Hand hand(sim, std::make_shared<interaction::SimulatedGlove>(p));
    interaction::InteractionSettings interaction_settings;
    interaction_settings.sliding = sliding_settings;
    interaction::Grasping grasping(sim, hand, interaction_settings);
    if (!wall) {
      grasping.add_mate({.name = "peg_in_hole",
                         .part = "peg",
                         .p_PF = Vec3(0, 0, kLength),
                         .axis_P = Vec3::UnitZ(),
                         .other = "block",
                         .p_OF = Vec3(0, kBottom, 0),
                         .axis_O = -Vec3::UnitY()});
    }
    grasping.hold("peg", interaction::GraspType::kPower);
    sim.prepare();
    std::vector<double> in_contact;
    for (int frame = 0; frame < 260; ++frame) {
      const engine::FrameResult& r = sim.step();
      if (grasping.held() && grasping.last_slide().status != interaction::SlideStatus::kReached) {
        in_contact.push_back(grasping.stats().frame_ms);
        if (grasping.last_slide().collision_queries > 0) {
          out.querying_ms.push_back(grasping.stats().frame_ms);
        }
        if (slow_ms > 0 && grasping.stats().frame_ms > slow_ms) {
          const interaction::SlideResult& s = grasping.last_slide();
          std::printf(
              "  slow frame %d: %.3f ms, %d sub-steps, %d queries, %d new contacts of %zu\n", frame,
              grasping.stats().frame_ms, s.substeps, s.collision_queries, s.new_contacts,
              s.contacts.size());
        }
      }
      for (const engine::Event& e : r.events) out.mated += e.kind == engine::EventKind::kMate;
      if (measure_penetration) {
        const Transform X_WB = sim.scene().world_pose("block");
        const Transform X_WP = sim.scene().world_pose("peg");
        const Transform X_BP{X_WB.R.transpose() * X_WP.R, X_WB.R.transpose() * (X_WP.t - X_WB.t)};
        for (const collision::ContactPatch& patch :
             collision::compute_contacts(*block_model, *peg_model, X_BP)) {
          out.max_penetration = std::max(out.max_penetration, patch.depth);
        }
        if (grasping.held() && grasping.last_slide().status != interaction::SlideStatus::kReached) {
          out.contact_gap_m.push_back(
              collision::distance(*block_distance, *peg_distance, X_BP).distance);
        }
      }
      if (run == 0 && !pictures.empty() && (frame == 30 || frame == 100)) {
        engine::RenderSettings settings{.width = 480, .height = 360, .camera = "iso"};
        engine::write_png(engine::render(engine::render_scene(sim.scene()), settings),
                          pictures + "/peg-frame-" + std::to_string(frame) + ".png");
      }
    }
    if (run == 0) out.frames_in_contact = in_contact.size();
    const Real tip_over_bottom =
        sim.scene().world_pose("peg").apply(Vec3(0, 0, kLength)).y() - kBottom;
    out.tip_over_bottom_m = std::max(out.tip_over_bottom_m, tip_over_bottom);
    out.at_bottom += tip_over_bottom < 1e-5;
    out.contact_ms.insert(out.contact_ms.end(), in_contact.begin(), in_contact.end());
    out.run_medians.push_back(percentile(in_contact, 0.5));
  }
  return out;
}

void sliding(int runs, const std::string& pictures, bool pair_guided, bool fronts, double slow_ms,
             Carry carry) {
  interaction::SlidingSettings settings;
  settings.pair_guided = pair_guided;
  settings.separation_fronts = fronts;
  const SlidingRuns r = sliding_runs(runs, pictures, settings, slow_ms, false, carry);
  const std::vector<double>& contact_ms = r.contact_ms;
  const std::vector<double>& run_medians = r.run_medians;
  std::printf(
      "sliding (%s%s%s): %zu-triangle peg into a hole, %llu frames in contact per run, mated in "
      "%llu of %d runs, tip %.4f mm over the bottom at the end (highest run)\n",
      pair_guided ? "pair-guided" : "plain", fronts ? "" : ", no fronts",
      carry == Carry::kAlongWall ? ", along the wall" : "", r.triangles,
      static_cast<unsigned long long>(r.frames_in_contact),
      static_cast<unsigned long long>(r.mated), runs, 1000 * r.tip_over_bottom_m);
  std::printf(
      "  interaction step ms per frame in contact: median %.4f  p95 %.4f  worst %.4f  "
      "run medians %.4f (%.4f..%.4f)\n",
      percentile(contact_ms, 0.5), percentile(contact_ms, 0.95), percentile(contact_ms, 1.0),
      percentile(run_medians, 0.5), *std::min_element(run_medians.begin(), run_medians.end()),
      *std::max_element(run_medians.begin(), run_medians.end()));
  std::printf("  of them the %.0f a run that made collision queries: median %.4f  p95 %.4f\n",
              static_cast<double>(r.querying_ms.size()) / runs, percentile(r.querying_ms, 0.5),
              percentile(r.querying_ms, 0.95));
}

/// Sliding accuracy against its cost: the peg slid down the hole's wall with the contact
/// search's resolution and sub-step budget varied, the deepest overlap of peg and block
/// measured every frame. One line per setting on stdout and in `table`.
void sliding_sweep(int runs, const std::string& table_path) {
  struct Variant {
    std::string name;
    interaction::SlidingSettings settings;
  };
  std::vector<Variant> variants;
  for (const Real resolution : {1e-7, 1e-6, 1e-5, 1e-4, 1e-3}) {
    interaction::SlidingSettings s;
    s.resolution_m = resolution;
    char name[64];
    std::snprintf(name, sizeof name, "resolution_%gm", resolution);
    variants.push_back({name, s});
  }
  for (const int substeps : {1, 2, 8}) {
    interaction::SlidingSettings s;
    s.substeps = substeps;
    variants.push_back({"substeps_" + std::to_string(substeps), s});
  }
  {
    interaction::SlidingSettings s;
    s.pair_guided = false;
    variants.push_back({"plain_search", s});
  }
  std::FILE* table = table_path.empty() ? nullptr : std::fopen(table_path.c_str(), "w");
  if (table) {
    std::fprintf(table,
                 "# setting median_ms p95_ms worst_ms max_penetration_mm median_gap_um "
                 "p95_gap_um bottom_runs runs\n");
  }
  std::printf(
      "sliding sweep: %d runs each; ms per frame in contact; deepest overlap over all frames\n",
      runs);
  std::printf("%-18s %9s %9s %9s %15s %14s %11s %6s %10s\n", "setting", "median", "p95", "worst",
              "penetration mm", "gap median um", "gap p95 um", "bottom", "tip mm");
  for (const Variant& v : variants) {
    const SlidingRuns r = sliding_runs(runs, "", v.settings, 0, true, Carry::kAlongWall);
    const double median = percentile(r.contact_ms, 0.5), p95 = percentile(r.contact_ms, 0.95),
                 worst = percentile(r.contact_ms, 1.0);
    const double gap_median = 1e6 * percentile(r.contact_gap_m, 0.5);
    const double gap_p95 = 1e6 * percentile(r.contact_gap_m, 0.95);
    std::printf("%-18s %9.4f %9.4f %9.4f %15.6f %14.3f %11.3f %3llu/%d %10.4f\n", v.name.c_str(),
                median, p95, worst, 1000 * r.max_penetration, gap_median, gap_p95,
                static_cast<unsigned long long>(r.at_bottom), runs, 1000 * r.tip_over_bottom_m);
    if (table) {
      std::fprintf(table, "%s %.5f %.5f %.5f %.7f %.4f %.4f %llu %d\n", v.name.c_str(), median, p95,
                   worst, 1000 * r.max_penetration, gap_median, gap_p95,
                   static_cast<unsigned long long>(r.at_bottom), runs);
    }
  }
  if (table) std::fclose(table);
}

/// Grasping: the interaction step (closing the fingers joint by joint onto
/// the part, the contact analysis of every touching segment and the palm's
/// strips) while the open hand closes to `fist` on a 10,240-triangle bar of
/// 30, 40 and 50 mm lying along x, the wrist 60 mm behind its axis, and then
/// holds it. With the palm on the bar it grasps; 2.5 mm above it, it never
/// does, and every frame of the close tries to (the worst case).
void grasping(int runs) {
  std::printf(
      "grasping: open hand closing to fist for 0.5 s on a 10,240-triangle bar, then 0.2 s "
      "still; ms per frame of the interaction step: the first frame (it builds the bar's "
      "distance model) apart, then the other 62; collision queries a frame\n");
  std::printf("%-6s %-9s %9s %9s %9s %9s %9s %8s %9s %s\n", "bar mm", "palm", "grasped", "first",
              "median", "p95", "worst", "frames", "queries", "run medians (min..max)");
  for (const Real diameter : {0.030, 0.040, 0.050}) {
    const auto bar =
        std::make_shared<const collision::Mesh>(banded_cylinder(diameter / 2, 0.12, 256, 19));
    Transform X_bar;
    X_bar.R = interaction::rotation_y_deg(90);  // its z axis along x
    X_bar.t = Vec3(-0.06, 0, 0);
    for (const Real above : {0.0, 0.0025}) {
      std::vector<double> frame_ms, run_medians, first_ms;
      std::uint64_t grasped = 0, queries = 0, frames = 0;
      for (int run = 0; run < runs; ++run) {
        engine::Scene scene;
        scene.add_part({.name = "bar", .X_QP = X_bar, .render_mesh = bar});
        engine::Simulation sim(std::move(scene), {.collision_threads = 1});
        GlovePlan p;
        // The palm's face lies 10.45 mm below the wrist for the default hand.
        p.start.p_WH = Vec3(0, diameter / 2 + 0.01045 + above, 0.06);
        p.start_posture = *interaction::named_posture("open");
        PlanStep wait;
        wait.duration = 0.2;
        p.steps = {close(0.5, "fist"), wait};
        interaction::Hand hand(sim, std::make_shared<interaction::SimulatedGlove>(p));
        interaction::Grasping g(sim, hand);
        sim.prepare();
        std::vector<double> run_ms;
        for (int frame = 0; frame < 63; ++frame) {
          sim.step();
          // The first frame builds the bar's distance model: apart.
          (frame == 0 ? first_ms : run_ms).push_back(g.stats().frame_ms);
        }
        grasped += g.held().has_value();
        queries += g.stats().finger_queries + g.stats().contact_queries + g.stats().slide_queries;
        frames += run_ms.size();
        frame_ms.insert(frame_ms.end(), run_ms.begin(), run_ms.end());
        run_medians.push_back(percentile(run_ms, 0.5));
      }
      std::printf("%-6.0f %-9s %5llu/%-3d %9.2f %9.4f %9.4f %9.4f %8llu %9.1f %.4f (%.4f..%.4f)\n",
                  1000 * diameter, above > 0 ? "2.5 above" : "on it",
                  static_cast<unsigned long long>(grasped), runs, percentile(first_ms, 0.5),
                  percentile(frame_ms, 0.5), percentile(frame_ms, 0.95), percentile(frame_ms, 1.0),
                  static_cast<unsigned long long>(frames / runs),
                  static_cast<double>(queries) / static_cast<double>(frames + first_ms.size()),
                  percentile(run_medians, 0.5),
                  *std::min_element(run_medians.begin(), run_medians.end()),
                  *std::max_element(run_medians.begin(), run_medians.end()));
    }
  }
}

}  // namespace

int main(int argc, char** argv) {
  int runs = 5;
  std::string detail = "both";
  double slow_ms = 0;    // list sliding frames slower than this (0: none)
  std::string sweep;     // sliding accuracy against cost: the table, then stop
  std::string pictures;  // folder for PNGs of the sliding peg
  bool grasping_only = false;
  for (int i = 1; i < argc; ++i) {
    const std::string arg = argv[i];
    if (arg == "--runs" && i + 1 < argc) {
      runs = static_cast<int>(dovetail::bench::whole("hand_bench", "--runs", argv[++i], 1, 1000));
    } else if (arg == "--pictures" && i + 1 < argc) {
      pictures = argv[++i];
    } else if (arg == "--slow" && i + 1 < argc) {
      slow_ms = dovetail::bench::real("hand_bench", "--slow", argv[++i], 0);
    } else if (arg == "--sweep" && i + 1 < argc) {
      sweep = argv[++i];
    } else if (arg == "--grasping") {
      grasping_only = true;
    } else if (arg == "--detail" && i + 1 < argc) {
      detail = argv[++i];
    } else {
      std::fprintf(stderr,
                   "usage: hand_bench [--runs R] [--detail pairs|triangles|both] [--pictures DIR] "
                   "[--slow MS] [--sweep TABLE] [--grasping]\n");
      return 2;
    }
  }
  if (grasping_only) {
    grasping(runs);
    return 0;
  }
  if (!sweep.empty()) {
    sliding_sweep(runs, sweep);
    return 0;
  }
  const auto torus =
      std::make_shared<const collision::Mesh>(collision::make_torus(0.06, 0.02, 100, 50));
  const auto thin = std::make_shared<const collision::Mesh>(plate(0.2, 50));
  // The torus lies flat (its axis along y); the hand wraps the rim that runs along x at z = 0.06.
  Transform X_flat;
  X_flat.R << 1, 0, 0, 0, 0, 1, 0, -1, 0;
  const Vec3 far(1000, -2000, 500);
  Transform X_far = X_flat;
  X_far.t = far;
  const Scene scenes[] = {
      {"torus", torus, X_flat, plan(Vec3::Zero(), 0.032, "power")},
      {"plate", thin, Transform::identity(), plan(Vec3::Zero(), 0.02, "fist")},
      {"far", torus, X_far, plan(far, 0.032, "power")},
  };
  std::printf("hand_bench: %d runs, one collision thread, 90 Hz; times in ms per frame\n", runs);
  std::printf("%-6s %-9s %9s %7s %8s %8s %8s %9s %10s %10s %s\n", "scene", "detail", "triangles",
              "frames", "contact", "pairs", "median", "p95", "worst", "collision",
              "run medians (min..max)");
  for (const Scene& scene : scenes) {
    for (const auto d : {collision::ContactDetail::kPairs, collision::ContactDetail::kTriangles}) {
      const bool pairs = d == collision::ContactDetail::kPairs;
      if ((detail == "pairs" && !pairs) || (detail == "triangles" && pairs)) continue;
      const Frames f = measure(scene, d, runs);
      std::printf(
          "%-6s %-9s %9zu %7.0f %7.0f%% %8.2f %8.4f %9.4f %10.4f %10.4f %.4f (%.4f..%.4f)%s\n",
          scene.name, pairs ? "pairs" : "triangles", scene.mesh->triangle_count(), f.frames,
          100 * f.contact_frames / f.frames, f.segments_in_contact / f.frames,
          percentile(f.step_ms, 0.5), percentile(f.step_ms, 0.95), percentile(f.step_ms, 1.0),
          percentile(f.collision_ms, 0.5), percentile(f.run_median_step_ms, 0.5),
          *std::min_element(f.run_median_step_ms.begin(), f.run_median_step_ms.end()),
          *std::max_element(f.run_median_step_ms.begin(), f.run_median_step_ms.end()),
          f.same_hash ? "" : "  STATE HASH DIFFERS BETWEEN RUNS");
    }
  }
  fk_only();
  for (const Carry carry : {Carry::kIntoHole, Carry::kAlongWall}) {
    const std::string shots = carry == Carry::kIntoHole ? pictures : std::string();
    sliding(runs, "", false, true, slow_ms, carry);
    sliding(runs, "", true, false, slow_ms, carry);
    sliding(runs, shots, true, true, slow_ms, carry);
  }
  grasping(runs);
  if (!pictures.empty()) grasp_picture(pictures);
  return 0;
}
