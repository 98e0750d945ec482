// Collision-pipeline benchmarks.
//
//   pipeline_bench icollide [--n N] [--frames F] [--density D] [--runs R]
//       The I-COLLIDE scene: N convex polytopes (50+ faces each) moving and
//       tumbling in a box, every pair decided exactly; ms per frame and frames
//       per second on one core.
//   pipeline_bench scaling [--frames F] [--runs R]
//       The same scene for N = 250 ... 8000 at constant density, and for
//       N = 1000 at densities 1x ... 8x: cost per frame against N and density.
//   pipeline_bench threads [--frames F] [--runs R]
//       A scene dominated by polygon-level pairs, at 1, 2, 4 and 8 threads:
//       throughput and speed-up, with a check that every thread count gives
//       the same contacts.
//   pipeline_bench scene engine|polytopes DIR [--frames F] [--n N] [--assembly FILE]
//       Writes a scene for `dovetail pipeline` to DIR/scene.txt, its meshes
//       as OBJ files beside it: the engine assembly with its four largest
//       parts sweeping through it (engine_bench's scene, at 90 Hz), or the
//       I-COLLIDE scene's N polytopes (their motion, bounces included).

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <map>
#include <memory>
#include <numbers>
#include <random>
#include <stdexcept>
#include <string>
#include <vector>

#include "bench_util.h"
#include "dovetail/collision/collision_world.h"
#include "dovetail/collision/convex.h"
#include "dovetail/collision/pose_sampling.h"
#include "dovetail/collision/primitives.h"
#include "dovetail/engine/pose_list.h"
#include "engine_sweep.h"

namespace {

using dovetail::bench::median;

using namespace dovetail::collision;
using Clock = std::chrono::steady_clock;

double ms_since(Clock::time_point t0) {
  return std::chrono::duration<double, std::milli>(Clock::now() - t0).count();
}

/// A random convex polytope: the hull of `points` random points on a sphere
/// of radius `radius` (about 2 * points - 4 faces).
Mesh random_polytope(std::mt19937_64& rng, int points, Real radius) {
  std::vector<Vec3> p;
  auto uniform = [&] { return static_cast<Real>(rng() >> 11) * 0x1.0p-53; };
  for (int i = 0; i < points; ++i) {
    const Real z = 2 * uniform() - 1, phi = 2 * std::numbers::pi * uniform();
    const Real r = std::sqrt(1 - z * z);
    p.emplace_back(radius * r * std::cos(phi), radius * r * std::sin(phi), radius * z);
  }
  const ConvexHull hull = compute_convex_hull(p, "polytope");
  return make_mesh(hull.vertices, hull.faces, "random polytope");
}

/// N bodies bouncing in a cube, each with a velocity and a spin.
struct Bodies {
  std::vector<Transform> pose;
  std::vector<Vec3> velocity;
  std::vector<Mat3> spin;  ///< rotation per frame
  Real half = 1;

  /// `separated`: start on a jittered grid, bodies of radius 1 apart;
  /// otherwise at random positions.
  Bodies(std::size_t n, Real half_size, Real speed, Real spin_angle, std::uint64_t seed,
         bool separated = false)
      : half(half_size) {
    pose = random_poses(n, half_size, seed);
    if (separated) {
      const int side = static_cast<int>(std::ceil(std::cbrt(static_cast<double>(n))));
      const Real spacing = 2 * half_size / side;
      const Real jitter = std::max<Real>(0, (spacing - 2.0) / 2);
      const std::vector<Transform> offsets = random_poses(n, 1.0, seed + 2);
      for (std::size_t i = 0; i < n; ++i) {
        const Vec3 cell(static_cast<Real>(i % side), static_cast<Real>((i / side) % side),
                        static_cast<Real>(i / (side * side)));
        pose[i].t =
            Vec3::Constant(-half_size + spacing / 2) + spacing * cell + jitter * offsets[i].t;
      }
    }
    const std::vector<Transform> m = random_poses(n, speed, seed + 1);
    for (std::size_t i = 0; i < n; ++i) {
      velocity.push_back(m[i].t);
      const Eigen::AngleAxisd aa(m[i].R);
      spin.push_back(Eigen::AngleAxisd(spin_angle * aa.angle() / std::numbers::pi, aa.axis())
                         .toRotationMatrix());
    }
  }

  /// Elastic bounce of two equal masses in contact that still approach each
  /// other: their velocity components along the line of centres are exchanged.
  void bounce(std::size_t a, std::size_t b) {
    const Vec3 n = (pose[b].t - pose[a].t).normalized();
    const Real approach = (velocity[a] - velocity[b]).dot(n);
    if (!(approach > 0)) return;
    velocity[a] -= approach * n;
    velocity[b] += approach * n;
  }

  void advance() {
    for (std::size_t i = 0; i < pose.size(); ++i) {
      pose[i].t += velocity[i];
      for (int k = 0; k < 3; ++k) {
        if (std::abs(pose[i].t[k]) > half) velocity[i][k] = -velocity[i][k];
      }
      pose[i].R = spin[i] * pose[i].R;
    }
  }
};

struct SceneResult {
  double ms_per_frame = 0;
  double box_pairs = 0, colliding = 0, polygon_pairs = 0, cached = 0;
};

/// The I-COLLIDE scene's 20 polytope shapes (radius 1, about 56 faces), body
/// i taking shape i mod 20.
std::vector<std::shared_ptr<const Mesh>> icollide_shapes() {
  std::mt19937_64 rng(42);
  std::vector<std::shared_ptr<const Mesh>> shapes;
  for (int s = 0; s < 20; ++s)
    shapes.push_back(std::make_shared<const Mesh>(random_polytope(rng, 30, 1.0)));
  return shapes;
}

/// Half the edge of the cube that n bodies' unit spheres fill to `density`.
Real icollide_half_size(std::size_t n, double density) {
  const Real sphere_volume = 4.0 / 3.0 * std::numbers::pi;
  const Real half = 0.5 * std::cbrt(n * sphere_volume / density);
  if (2 * half / std::ceil(std::cbrt(static_cast<double>(n))) < 2.0) {
    throw std::invalid_argument("density too high to start the bodies apart");
  }
  return half;
}

/// Runs the I-COLLIDE scene: `n` polytopes of radius 1 in a cube sized for
/// `density` (fraction of the cube's volume the polytopes' spheres fill),
/// bouncing off the walls and off each other (velocities exchanged along the
/// line of centres when a pair is in contact and approaching).
SceneResult icollide_scene(std::size_t n, double density, int frames, int runs) {
  const std::vector<std::shared_ptr<const Mesh>> shapes = icollide_shapes();
  const Real half = icollide_half_size(n, density);
  std::vector<double> run_ms;
  SceneResult out;
  for (int r = 0; r < runs; ++r) {
    Bodies bodies(n, half, 0.02, 0.05, 7, /*separated=*/true);
    CollisionWorld world({.method = Method::kObb, .threads = 1});
    std::vector<PartId> ids;
    for (std::size_t i = 0; i < n; ++i)
      ids.push_back(world.add_part({.mesh = shapes[i % shapes.size()], .X_WP = bodies.pose[i]}));
    world.step();  // first frame: builds and fills the broad phase
    std::vector<double> frame_ms;
    double box_pairs = 0, colliding = 0, polygon = 0, cached = 0;
    for (int f = 0; f < frames; ++f) {
      bodies.advance();
      const auto t0 = Clock::now();
      for (std::size_t i = 0; i < n; ++i) world.set_pose(ids[i], bodies.pose[i]);
      const StepResult& s = world.step();
      frame_ms.push_back(ms_since(t0));
      // Bodies bounce off each other, as in the I-COLLIDE demonstration.
      for (const PartPair& p : s.colliding) bodies.bounce(p.a.index, p.b.index);
      box_pairs += s.stats.box_pairs;
      colliding += s.stats.colliding_pairs;
      polygon += s.stats.polygon_pairs;
      cached += s.stats.cached_planes;
    }
    run_ms.push_back(median(frame_ms));
    out.box_pairs = box_pairs / frames;
    out.colliding = colliding / frames;
    out.polygon_pairs = polygon / frames;
    out.cached = cached / frames;
  }
  out.ms_per_frame = median(run_ms);
  return out;
}

int icollide(std::size_t n, double density, int frames, int runs) {
  const SceneResult r = icollide_scene(n, density, frames, runs);
  std::printf(
      "I-COLLIDE scene: %zu polytopes (about 56 faces), density %.3f, %d frames, median of %d "
      "runs\n",
      n, density, frames, runs);
  std::printf(
      "ms/frame %.3f  (%.0f frames/s)  box pairs %.1f  polygon-level pairs %.1f  colliding %.1f  "
      "cached planes %.1f\n",
      r.ms_per_frame, 1000.0 / r.ms_per_frame, r.box_pairs, r.polygon_pairs, r.colliding, r.cached);
  return 0;
}

int scaling(int frames, int runs) {
  std::printf("%8s %8s %12s %12s %12s %12s\n", "n", "density", "ms/frame", "us/object", "box_pairs",
              "colliding");
  for (std::size_t n : {250, 500, 1000, 2000, 4000, 8000}) {
    const SceneResult r = icollide_scene(n, 0.05, frames, runs);
    std::printf("%8zu %8.3f %12.3f %12.3f %12.1f %12.1f\n", n, 0.05, r.ms_per_frame,
                1000 * r.ms_per_frame / n, r.box_pairs, r.colliding);
  }
  for (double density : {0.025, 0.05, 0.1, 0.2, 0.4}) {
    const SceneResult r = icollide_scene(1000, density, frames, runs);
    std::printf("%8d %8.3f %12.3f %12.3f %12.1f %12.1f\n", 1000, density, r.ms_per_frame,
                r.ms_per_frame, r.box_pairs, r.colliding);
  }
  return 0;
}

int threads(int frames, int runs) {
  // Heavy parts pressed into each other: most of the time goes to the polygon level.
  const auto sphere = std::make_shared<const Mesh>(make_sphere(0.5, 5));  // 20,480 triangles
  const auto torus = std::make_shared<const Mesh>(make_torus(0.5, 0.2, 128, 64));  // 16,384
  const std::size_t n = 24;
  std::printf(
      "threads scene: %zu parts (spheres of 20,480 and tori of 16,384 triangles), %d frames, "
      "median of %d runs\n",
      n, frames, runs);
  std::printf("(this machine has 2 cores: 4 and 8 threads oversubscribe it)\n");
  std::printf("%8s %12s %12s %10s %14s %10s\n", "threads", "ms/frame", "frames/s", "speed-up",
              "contacts/frame", "same");
  double base = 0;
  std::vector<std::size_t> reference;
  for (int t : {1, 2, 4, 8}) {
    std::vector<double> run_ms;
    std::vector<std::size_t> contacts;
    for (int r = 0; r < runs; ++r) {
      Bodies bodies(n, 0.9, 0.01, 0.03, 3);
      CollisionWorld world({.method = Method::kObb, .threads = t});
      std::vector<PartId> ids;
      for (std::size_t i = 0; i < n; ++i)
        ids.push_back(world.add_part({.mesh = i % 2 ? torus : sphere, .X_WP = bodies.pose[i]}));
      world.step();
      contacts.clear();
      const auto t0 = Clock::now();
      for (int f = 0; f < frames; ++f) {
        bodies.advance();
        for (std::size_t i = 0; i < n; ++i) world.set_pose(ids[i], bodies.pose[i]);
        contacts.push_back(world.step().contacts.size());
      }
      run_ms.push_back(ms_since(t0) / frames);
    }
    const double ms = median(run_ms);
    if (t == 1) base = ms, reference = contacts;
    double mean_contacts = 0;
    for (std::size_t c : contacts) mean_contacts += c;
    std::printf("%8d %12.3f %12.1f %9.2fx %14.0f %10s\n", t, ms, 1000 / ms, base / ms,
                mean_contacts / frames, contacts == reference ? "yes" : "NO");
  }
  return 0;
}

/// A `dovetail pipeline` scene being written: the meshes as OBJ files, then
/// the frames of poses.
class SceneWriter {
 public:
  SceneWriter(const std::filesystem::path& dir, std::size_t parts, std::size_t frames) : dir_(dir) {
    std::filesystem::create_directories(dir);
    scene_.open(dir / "scene.txt");
    if (!scene_) throw std::runtime_error("cannot write " + (dir / "scene.txt").string());
    scene_ << parts << ' ' << frames << '\n';
  }

  /// The mesh of the next part, written once per distinct mesh.
  void part(const std::shared_ptr<const Mesh>& mesh) {
    auto [it, added] =
        files_.try_emplace(mesh.get(), "mesh_" + std::to_string(files_.size()) + ".obj");
    if (added) write_obj(*mesh, dir_ / it->second);
    scene_ << it->second << '\n';
  }

  void pose(const Transform& X_WP) { scene_ << dovetail::engine::format_pose(X_WP) << '\n'; }

  void close() {
    scene_.close();
    if (!scene_) throw std::runtime_error("cannot write " + (dir_ / "scene.txt").string());
  }

 private:
  static void write_obj(const Mesh& mesh, const std::filesystem::path& path) {
    std::ofstream out(path);
    char line[128];
    for (const Vec3& v : mesh.vertices) {
      std::snprintf(line, sizeof line, "v %.17g %.17g %.17g\n", v.x(), v.y(), v.z());
      out << line;
    }
    for (const auto& t : mesh.triangles)
      out << "f " << t[0] + 1 << ' ' << t[1] + 1 << ' ' << t[2] + 1 << '\n';
    if (!out) throw std::runtime_error("cannot write " + path.string());
  }

  std::filesystem::path dir_;
  std::ofstream scene_;
  std::map<const Mesh*, std::string> files_;
};

/// The engine scene of engine_bench, `frames` frames at 90 Hz from t = 0.
void engine_scene(const std::string& assembly, const std::filesystem::path& dir, int frames) {
  dovetail::bench::EngineSweep sweep = dovetail::bench::load_engine_sweep(assembly);
  SceneWriter writer(dir, sweep.with_mesh.size(), static_cast<std::size_t>(frames));
  for (auto p : sweep.with_mesh) writer.part(sweep.scene.collision_mesh(p));
  for (int f = 0; f < frames; ++f) {
    sweep.pose_at(sweep.scene, f / 90.0);
    for (auto p : sweep.with_mesh) writer.pose(sweep.scene.world_pose(p));
  }
  writer.close();
  std::printf("%s: the engine assembly, %zu parts (4 moving), %d frames\n",
              (dir / "scene.txt").c_str(), sweep.with_mesh.size(), frames);
}

/// The I-COLLIDE scene of icollide_scene: n polytopes, `frames` frames.
void polytope_scene(std::size_t n, const std::filesystem::path& dir, int frames) {
  const std::vector<std::shared_ptr<const Mesh>> shapes = icollide_shapes();
  Bodies bodies(n, icollide_half_size(n, 0.05), 0.02, 0.05, 7, /*separated=*/true);
  CollisionWorld world({.method = Method::kObb, .threads = 1});
  SceneWriter writer(dir, n, static_cast<std::size_t>(frames));
  std::vector<PartId> ids;
  for (std::size_t i = 0; i < n; ++i) {
    ids.push_back(world.add_part({.mesh = shapes[i % shapes.size()], .X_WP = bodies.pose[i]}));
    writer.part(shapes[i % shapes.size()]);
  }
  for (int f = 0; f < frames; ++f) {
    for (std::size_t i = 0; i < n; ++i) {
      world.set_pose(ids[i], bodies.pose[i]);
      writer.pose(bodies.pose[i]);
    }
    for (const PartPair& p : world.step().colliding) bodies.bounce(p.a.index, p.b.index);
    bodies.advance();
  }
  writer.close();
  std::printf("%s: %zu polytopes (about 56 faces), %d frames\n", (dir / "scene.txt").c_str(), n,
              frames);
}

}  // namespace

int main(int argc, char** argv) {
  if (argc < 2 || std::strcmp(argv[1], "--help") == 0) {
    std::printf(
        "usage: pipeline_bench icollide|scaling|threads [--n N] [--density D] [--frames F] [--runs "
        "R]\n"
        "       pipeline_bench scene engine|polytopes DIR [--frames F] [--n N] [--assembly "
        "FILE]\n");
    return argc < 2 ? 2 : 0;
  }
  const std::string mode = argv[1];
  std::size_t n = 1000;
  double density = 0.05;
  int frames = 100, runs = 3;
  std::string assembly = dovetail::bench::kEngineAssembly;
  const int first_option = mode == "scene" ? 4 : 2;  // scene KIND DIR
  if (mode == "scene" && (argc < 4 || (std::strcmp(argv[2], "engine") != 0 &&
                                       std::strcmp(argv[2], "polytopes") != 0))) {
    std::fprintf(stderr, "pipeline_bench: scene needs engine|polytopes and a folder\n");
    return 2;
  }
  if ((argc - first_option) % 2 != 0) {
    std::fprintf(stderr, "pipeline_bench: %s needs a value\n", argv[argc - 1]);
    return 2;
  }
  for (int i = first_option; i + 1 < argc; i += 2) {
    const std::string arg = argv[i];
    if (arg == "--n")
      n = static_cast<std::size_t>(
          dovetail::bench::whole("pipeline_bench", "--n", argv[i + 1], 2, 10000000));
    else if (arg == "--density")
      density = dovetail::bench::real("pipeline_bench", "--density", argv[i + 1], 0);
    else if (arg == "--frames")
      frames = static_cast<int>(
          dovetail::bench::whole("pipeline_bench", "--frames", argv[i + 1], 1, 1000000));
    else if (arg == "--runs")
      runs = static_cast<int>(
          dovetail::bench::whole("pipeline_bench", "--runs", argv[i + 1], 1, 1000));
    else if (arg == "--assembly")
      assembly = argv[i + 1];
    else {
      std::fprintf(stderr, "pipeline_bench: unknown option %s\n", arg.c_str());
      return 2;
    }
  }
  try {
    if (mode == "icollide") return icollide(n, density, frames, runs);
    if (mode == "scaling") return scaling(frames, runs);
    if (mode == "threads") return threads(frames, runs);
    if (mode == "scene" && std::strcmp(argv[2], "engine") == 0)
      return engine_scene(assembly, argv[3], frames), 0;
    if (mode == "scene" && std::strcmp(argv[2], "polytopes") == 0)
      return polytope_scene(n, argv[3], frames), 0;
  } catch (const std::exception& e) {
    std::fprintf(stderr, "pipeline_bench: %s\n", e.what());
    return 1;
  }
  std::fprintf(stderr, "pipeline_bench: unknown mode %s\n", mode.c_str());
  return 2;
}
