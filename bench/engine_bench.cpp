// Engine benchmarks: headless simulation speed against real time.
//
//   engine_bench [--seconds S] [--runs R] [--assembly FILE] [--only engine|synthetic]
//                [--broadphase sap|grid|octree|mbp|brute] [--threads N]
//
// 1. The 2-cylinder engine assembly (Debian's assimp-testmodels) simulated
//    for S seconds at 90 Hz, four of its parts moving through and against the
//    others, everything else fixed, every pair decided exactly, one collision
//    thread (--threads N: N).
// 2. A synthetic scene of 1,000 moving parts (convex polytopes of about 56
//    faces tumbling in a box), the same way.
// Reports wall time, frames per second and the real-time factor (simulated
// seconds per wall second), median over runs, and the slowest and fastest
// run's factor: on a shared machine the spread is part of the figure.

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <numbers>
#include <random>
#include <string>
#include <vector>

#include "bench_util.h"
#include "dovetail/collision/broadphase.h"
#include "dovetail/collision/convex.h"
#include "dovetail/collision/pose_sampling.h"
#include "dovetail/engine/scene.h"
#include "dovetail/engine/simulation.h"
#include "engine_sweep.h"

namespace {

/// The object level of both scenes (--broadphase).
dovetail::collision::BroadphaseMethod g_broadphase =
    dovetail::collision::BroadphaseMethod::kSweepAndPrune;
/// Collision worker threads of both scenes (--threads).
int g_threads = 1;

using dovetail::bench::EngineSweep;
using dovetail::bench::load_engine_sweep;
using dovetail::bench::median;

using namespace dovetail;
using collision::Real;
using collision::Transform;
using collision::Vec3;
using Clock = std::chrono::steady_clock;

struct RunResult {
  double box_pairs = 0, convex_tests = 0, cached_planes = 0;        ///< per frame
  double polygon_pairs = 0, colliding_pairs = 0, volume_tests = 0;  ///< per frame
  double triangle_volume_tests = 0;                                 ///< per frame
  double wall_s = 0;                                                ///< the stepping loop
  double prepare_s = 0;    ///< building hulls and hierarchies before the loop
  double collision_s = 0;  ///< of wall_s, in the collision pipeline
  std::uint64_t frames = 0;
  std::size_t contact_events = 0;
  std::uint64_t state_hash = 0;
};

/// Runs `sim` for `seconds` of simulated time, `move(frame, time)` setting poses each frame.
template <typename Move>
RunResult run(engine::Simulation& sim, double seconds, Move&& move) {
  const auto frames = static_cast<std::uint64_t>(std::llround(seconds / sim.settings().time_step));
  sim.set_frame_hook(
      [&](engine::Simulation&, std::uint64_t frame, double time) { move(frame, time); });
  RunResult r;
  const auto tp = Clock::now();
  sim.prepare();
  r.prepare_s = std::chrono::duration<double>(Clock::now() - tp).count();
  const auto t0 = Clock::now();
  for (std::uint64_t f = 0; f < frames; ++f) {
    const engine::FrameResult& fr = sim.step();
    r.box_pairs += static_cast<double>(fr.collision.box_pairs) / frames;
    r.convex_tests += static_cast<double>(fr.collision.convex_tests) / frames;
    r.cached_planes += static_cast<double>(fr.collision.cached_planes) / frames;
    r.polygon_pairs += static_cast<double>(fr.collision.polygon_pairs) / frames;
    r.colliding_pairs += static_cast<double>(fr.collision.colliding_pairs) / frames;
    r.volume_tests += static_cast<double>(fr.collision.polygon.volume_tests) / frames;
    r.triangle_volume_tests +=
        static_cast<double>(fr.collision.polygon.triangle_volume_tests) / frames;
    for (const engine::Event& e : fr.events) {
      r.contact_events +=
          e.kind == engine::EventKind::kContactBegin || e.kind == engine::EventKind::kContactEnd;
    }
  }
  r.wall_s = std::chrono::duration<double>(Clock::now() - t0).count();
  r.frames = frames;
  for (const engine::FrameTiming& t : sim.report().timings) r.collision_s += t.collision_ms * 1e-3;
  r.state_hash = sim.state_hash();
  return r;
}

void print(const char* name, std::size_t parts, double seconds,
           const std::vector<RunResult>& runs) {
  std::vector<double> walls, prepares, collisions;
  for (const RunResult& r : runs) {
    walls.push_back(r.wall_s);
    prepares.push_back(r.prepare_s);
    collisions.push_back(r.collision_s);
  }
  const double wall = median(walls);
  const auto [fastest, slowest] = std::minmax_element(walls.begin(), walls.end());
  std::printf(
      "%-28s %6zu parts  %5.1f s simulated  %8.3f s wall  %8.0f frames/s  %7.1fx real time  %5zu "
      "contact events  hash %016llx\n",
      name, parts, seconds, wall, runs[0].frames / wall, seconds / wall, runs[0].contact_events,
      static_cast<unsigned long long>(runs[0].state_hash));
  if (runs.size() > 1) {
    std::printf("%-28s real time over the %zu runs: median %.1fx, slowest %.1fx, fastest %.1fx\n",
                "", runs.size(), seconds / wall, seconds / *slowest, seconds / *fastest);
  }
  std::printf(
      "%-28s per frame: %.1f overlapping boxes, %.1f separating-plane tests (%.1f settled by last "
      "frame's plane), %.1f polygon-level pairs, %.1f in contact, %.0f volume tests (and %.0f of "
      "a contact's triangle against a volume)\n",
      "", runs[0].box_pairs, runs[0].convex_tests, runs[0].cached_planes, runs[0].polygon_pairs,
      runs[0].colliding_pairs, runs[0].volume_tests, runs[0].triangle_volume_tests);
  std::printf(
      "%-28s collision pipeline %.3f s of the wall time; set-up before the loop (hulls and "
      "hierarchies) %.3f s\n",
      "", median(collisions), median(prepares));
}

void engine_assembly(const std::string& path, double seconds, int runs) {
  std::vector<RunResult> results;
  std::size_t parts = 0;
  for (int r = 0; r < runs; ++r) {
    EngineSweep sweep = load_engine_sweep(path);
    parts = sweep.with_mesh.size();
    engine::Simulation sim(std::move(sweep.scene),
                           {.collision_threads = g_threads, .broadphase = g_broadphase});
    results.push_back(
        run(sim, seconds, [&](std::uint64_t, double t) { sweep.pose_at(sim.scene(), t); }));
  }
  print("engine assembly, 4 moving", parts, seconds, results);
}

void synthetic(std::size_t n, double seconds, int runs) {
  std::mt19937_64 rng(42);
  auto uniform = [&] { return static_cast<Real>(rng() >> 11) * 0x1.0p-53; };
  std::vector<std::shared_ptr<const collision::Mesh>> shapes;
  for (int s = 0; s < 20; ++s) {
    std::vector<Vec3> p;
    for (int i = 0; i < 30; ++i) {
      const Real z = 2 * uniform() - 1, phi = 2 * std::numbers::pi * uniform(),
                 r = std::sqrt(1 - z * z);
      p.emplace_back(0.05 * r * std::cos(phi), 0.05 * r * std::sin(phi), 0.05 * z);
    }
    const collision::ConvexHull hull = collision::compute_convex_hull(p, "polytope");
    shapes.push_back(std::make_shared<const collision::Mesh>(
        collision::make_mesh(hull.vertices, hull.faces, "polytope")));
  }
  // Parts of radius 0.05 m filling 5% of a cube, on a jittered grid, moving at 0.5 m/s.
  const Real half = 0.5 * std::cbrt(n * (4.0 / 3.0 * std::numbers::pi * 0.05 * 0.05 * 0.05) / 0.05);
  const int side = static_cast<int>(std::ceil(std::cbrt(static_cast<double>(n))));
  std::vector<RunResult> results;
  for (int r = 0; r < runs; ++r) {
    engine::Scene scene;
    const std::vector<Transform> starts = collision::random_poses(n, 1.0, 5);
    const std::vector<Transform> motion = collision::random_poses(n, 0.5, 6);
    std::vector<Transform> pose(n);
    std::vector<Vec3> velocity(n);
    std::vector<engine::PartId> handles;
    for (std::size_t i = 0; i < n; ++i) {
      const Vec3 cell(static_cast<Real>(i % side), static_cast<Real>((i / side) % side),
                      static_cast<Real>(i / (side * side)));
      pose[i] = starts[i];
      pose[i].t = Vec3::Constant(-half) + (2 * half / side) * (cell + Vec3::Constant(0.5));
      velocity[i] = motion[i].t;
      std::string name = "p";
      name += std::to_string(i);
      handles.push_back(scene.add_part(
          {.name = name, .X_QP = pose[i], .render_mesh = shapes[i % shapes.size()]}));
    }
    engine::Simulation sim(std::move(scene),
                           {.collision_threads = g_threads, .broadphase = g_broadphase});
    const Real dt = sim.settings().time_step;
    results.push_back(run(sim, seconds, [&](std::uint64_t, double) {
      for (std::size_t i = 0; i < n; ++i) {
        pose[i].t += dt * velocity[i];
        for (int k = 0; k < 3; ++k) {
          if (std::abs(pose[i].t[k]) > half) velocity[i][k] = -velocity[i][k];
        }
        // Tumbling at one radian per second about a fixed axis of its own.
        pose[i].R = Eigen::AngleAxisd(dt, motion[i].R.col(0)).toRotationMatrix() * pose[i].R;
        sim.scene().set_local_pose(handles[i], pose[i]);
      }
    }));
  }
  print("synthetic, 1000 moving", n, seconds, results);
}

}  // namespace

int main(int argc, char** argv) {
  double seconds = 10;
  int runs = 3;
  std::string assembly = dovetail::bench::kEngineAssembly;
  std::string only;  // "engine" or "synthetic": run one scene
  for (int i = 1; i + 1 < argc; i += 2) {
    const std::string arg = argv[i];
    if (arg == "--seconds")
      seconds = dovetail::bench::real("engine_bench", "--seconds", argv[i + 1], 0);
    else if (arg == "--runs")
      runs =
          static_cast<int>(dovetail::bench::whole("engine_bench", "--runs", argv[i + 1], 1, 1000));
    else if (arg == "--threads")
      g_threads = static_cast<int>(
          dovetail::bench::whole("engine_bench", "--threads", argv[i + 1], 1, 256));
    else if (arg == "--assembly")
      assembly = argv[i + 1];
    else if (arg == "--broadphase") {
      const auto method = dovetail::collision::parse_broadphase(argv[i + 1]);
      if (!method) {
        std::fprintf(stderr,
                     "engine_bench: unknown broad phase %s (brute, sap, grid, octree, mbp)\n",
                     argv[i + 1]);
        return 2;
      }
      g_broadphase = *method;
    } else if (arg == "--only")
      only = argv[i + 1];
    else {
      std::fprintf(stderr, "engine_bench: unknown option %s\n", arg.c_str());
      return 2;
    }
  }
  try {
    if (only.empty() || only == "engine") engine_assembly(assembly, seconds, runs);
    if (only.empty() || only == "synthetic") synthetic(1000, seconds, runs);
  } catch (const std::exception& e) {
    std::fprintf(stderr, "engine_bench: %s\n", e.what());
    return 1;
  }
  return 0;
}
