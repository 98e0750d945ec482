// Hand benchmark: what the glove-driven hand costs per frame.
//
//   hand_bench [--runs R] [--detail pairs|triangles|both]
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

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <memory>
#include <string>
#include <vector>

#include "dovetail/collision/primitives.h"
#include "dovetail/engine/scene.h"
#include "dovetail/engine/simulation.h"
#include "dovetail/interaction/glove_source.h"
#include "dovetail/interaction/hand.h"
#include "dovetail/interaction/postures.h"

namespace {

using namespace dovetail;
using collision::Mat3;
using collision::Real;
using collision::Transform;
using collision::Vec3;
using interaction::GlovePlan;
using interaction::PlanStep;
using Clock = std::chrono::steady_clock;

double percentile(std::vector<double> v, double p) {
  std::sort(v.begin(), v.end());
  const auto i = static_cast<std::size_t>(std::llround(p * static_cast<double>(v.size() - 1)));
  return v[i];
}

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
        {.name = "part", .X_PC = scene.X_WP, .movable = false, .render_mesh = scene.mesh});
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

}  // namespace

int main(int argc, char** argv) {
  int runs = 5;
  std::string detail = "both";
  for (int i = 1; i < argc; ++i) {
    const std::string arg = argv[i];
    if (arg == "--runs" && i + 1 < argc) {
      runs = std::max(1, std::atoi(argv[++i]));
    } else if (arg == "--detail" && i + 1 < argc) {
      detail = argv[++i];
    } else {
      std::fprintf(stderr, "usage: hand_bench [--runs R] [--detail pairs|triangles|both]\n");
      return 2;
    }
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
  return 0;
}
