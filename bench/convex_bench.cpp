// Convex-level benchmark: pairs of random convex polytopes in coherent motion
// (tumbling, approaching, passing through each other and separating), one
// query per pair and frame, timed for
//   (a) the separating-plane test with its per-pair cached plane,
//   (b) GJK warm-started from its per-pair cache,
//   (c) GJK from a cold start,
//   (d) libccd's GJK intersection test (when libccd is installed).
//
//   convex_bench [--pairs N] [--frames F] [--vertices V] [--speed K] [--runs R] [--seed S]
//                [--hull-build] [--help]
//
// --speed multiplies every angular and swing velocity (less coherence).
// --hull-build instead times compute_convex_hull on generated point sets.
//
// Prints, per contender, the median over runs of the mean time per query,
// the fastest and slowest run, mean iterations, and the verdicts against
// warm-started GJK; then GJK's iterations warm against cold (mean, largest,
// calls that hit kGjkMaxIterations).

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <random>
#include <string>
#include <vector>

#include "bench_util.h"
#include "convex/convex_internal.h"
#include "dovetail/collision/convex.h"
#include "dovetail/collision/primitives.h"

#ifdef DOVETAIL_HAVE_CCD
#include <ccd/ccd.h>
#endif

namespace {

using dovetail::bench::median;

using namespace dovetail::collision;
using Clock = std::chrono::steady_clock;

constexpr double kPi = 3.14159265358979323846;

struct Options {
  int pairs = 64;
  int frames = 1000;
  int vertices = 48;
  double speed = 1;
  int runs = 7;
  std::uint64_t seed = 1;
};

class Random {
 public:
  explicit Random(std::uint64_t seed) : engine_(seed) {}
  double unit() { return static_cast<double>(engine_() >> 11) * 0x1p-53; }
  double uniform(double lo, double hi) { return lo + (hi - lo) * unit(); }
  double normal() {
    const double u = 1 - unit(), v = unit();
    return std::sqrt(-2 * std::log(u)) * std::cos(2 * kPi * v);
  }
  Vec3 direction() {
    const Vec3 d(normal(), normal(), normal());
    return d.norm() > 1e-9 ? Vec3(d.normalized()) : Vec3(Vec3::UnitX());
  }
  Mat3 rotation() {
    Eigen::Quaternion<double> q(normal(), normal(), normal(), normal());
    q.normalize();
    return q.toRotationMatrix();
  }

 private:
  std::mt19937_64 engine_;
};

/// A random polytope: points on an ellipsoid, some of them flattened onto
/// box faces, so the hull mixes smooth parts and larger flat faces.
ConvexHull random_polytope(Random& r, int vertices) {
  const Vec3 axes(r.uniform(0.4, 1.5), r.uniform(0.4, 1.5), r.uniform(0.2, 1.5));
  const double clip = r.uniform(0.6, 1.0);
  std::vector<Vec3> p;
  for (int i = 0; i < vertices; ++i) {
    Vec3 q = r.direction().cwiseProduct(axes);
    for (int k = 0; k < 3; ++k) q[k] = std::clamp(q[k], -clip * axes[k], clip * axes[k]);
    p.push_back(q);
  }
  return compute_convex_hull(p, "random polytope");
}

/// One pair in motion: B tumbles at a constant angular velocity while its
/// centre swings along a fixed axis through A and out again.
struct Pair {
  ConvexHull a, b;
  std::vector<Transform> poses;  ///< X_AB per frame
};

std::vector<Pair> make_scene(const Options& o) {
  Random r(o.seed);
  std::vector<Pair> pairs(static_cast<std::size_t>(o.pairs));
  for (Pair& pair : pairs) {
    pair.a = random_polytope(r, o.vertices);
    pair.b = random_polytope(r, o.vertices);
    const Vec3 axis = r.direction(), spin = r.direction();
    const Mat3 R0 = r.rotation();
    const double omega = o.speed * r.uniform(0.5, 2.0);  // rad/s
    const double swing = o.speed * r.uniform(0.2, 0.5);  // rad/s of the approach cycle
    const double phase = r.uniform(0, 2 * kPi);
    const double reach = pair.a.radius + pair.b.radius;
    for (int f = 0; f < o.frames; ++f) {
      const double t = f / 90.0;  // 90 Hz
      Transform X;
      X.R = Eigen::AngleAxis<double>(omega * t, spin).toRotationMatrix() * R0;
      const double gap = 0.35 + 0.95 * std::abs(std::cos(swing * t + phase));
      X.t = pair.a.center + axis * reach * gap - X.R * pair.b.center;
      pair.poses.push_back(X);
    }
  }
  return pairs;
}

#ifdef DOVETAIL_HAVE_CCD
/// A hull at a pose, for libccd's support callback (warm-started hill climb).
struct CcdObject {
  const ConvexHull* hull;
  Transform X;  ///< pose in A's frame
  mutable std::uint32_t last = 0;
};

void ccd_support(const void* object, const ccd_vec3_t* dir, ccd_vec3_t* out) {
  const auto* o = static_cast<const CcdObject*>(object);
  const Vec3 d_A(dir->v[0], dir->v[1], dir->v[2]);
  o->last = o->hull->support(o->X.R.transpose() * d_A, o->last);
  const Vec3 p = o->X.apply(o->hull->vertices[o->last]);
  ccdVec3Set(out, p.x(), p.y(), p.z());
}

void ccd_first_direction(const void* a, const void* b, ccd_vec3_t* dir) {
  const auto* oa = static_cast<const CcdObject*>(a);
  const auto* ob = static_cast<const CcdObject*>(b);
  const Vec3 d = ob->X.apply(ob->hull->center) - oa->X.apply(oa->hull->center);
  ccdVec3Set(dir, d.x(), d.y(), d.z());
}
#endif

/// Times compute_convex_hull (median of runs) on generated point sets:
/// smooth (every point a hull vertex), rounded coplanar, and interior-heavy;
/// small sets also on each path (qhull, and the exact incremental hull
/// without it), side by side.
void hull_build_times(int runs) {
  const Mat3 R = Eigen::Quaternion<double>(0.9, 0.2, 0.3, 0.1).normalized().toRotationMatrix();
  auto turned = [&](std::vector<Vec3> p) {
    for (Vec3& v : p) v = R * v;
    return p;
  };
  auto grid_box = [&](int n) {
    std::vector<Vec3> p;
    for (int i = 0; i <= n; ++i) {
      for (int j = 0; j <= n; ++j) {
        const double u = -1 + 2.0 * i / n, v = -1 + 2.0 * j / n;
        for (double s : {-1.0, 1.0}) {
          p.push_back(R * Vec3(u, v, s));
          p.push_back(R * Vec3(u, s, v));
          p.push_back(R * Vec3(s, u, v));
        }
      }
    }
    return p;
  };
  // A capsule of the hand's model: two rings of 16 and the two pole points.
  auto capsule = [&] {
    std::vector<Vec3> p = {R * Vec3(0, 0, -0.008), R * Vec3(0, 0, 0.048)};
    for (int i = 0; i < 16; ++i) {
      const double a = 2 * M_PI * i / 16;
      p.push_back(R * Vec3(0.008 * std::cos(a), 0.008 * std::sin(a), 0));
      p.push_back(R * Vec3(0.008 * std::cos(a), 0.008 * std::sin(a), 0.04));
    }
    return p;
  };
  std::vector<std::pair<std::string, std::vector<Vec3>>> small;
  small.emplace_back("box, 8 corners", turned(make_box(Vec3(1, 2, 3)).vertices));
  small.emplace_back("capsule, 34 points", capsule());
  small.emplace_back("sphere, 1 subdivision", turned(make_sphere(1, 1).vertices));
  small.emplace_back("box, 2 x 2 grid per face", grid_box(2));
  small.emplace_back("sphere, 2 subdivisions", turned(make_sphere(1, 2).vertices));
  small.emplace_back("box, 6 x 6 grid per face", grid_box(6));
  std::printf("Small sets, each path (`kDirectHullPoints` = %zu):\n\n", detail::kDirectHullPoints);
  std::printf(
      "| point set | points | hull vertices | qhull us (median) | direct us (median) | "
      "qhull / direct |\n");
  std::printf("|---|---:|---:|---:|---:|---:|\n");
  for (const auto& [name, points] : small) {
    std::vector<double> qhull_us, direct_us;
    ConvexHull hull;
    // Many builds per run: one takes microseconds.
    constexpr int kBuilds = 200;
    for (int k = 0; k < runs; ++k) {
      for (const detail::HullPath path : {detail::HullPath::kQhull, detail::HullPath::kDirect}) {
        const auto start = Clock::now();
        for (int b = 0; b < kBuilds; ++b)
          hull = detail::build_convex_hull(points, name, nullptr, path);
        const double us =
            std::chrono::duration<double, std::micro>(Clock::now() - start).count() / kBuilds;
        (path == detail::HullPath::kQhull ? qhull_us : direct_us).push_back(us);
      }
    }
    std::printf("| %s | %zu | %zu | %.1f | %.1f | %.1f |\n", name.c_str(), points.size(),
                hull.vertices.size(), median(qhull_us), median(direct_us),
                median(qhull_us) / median(direct_us));
  }
  std::printf("\nLarger sets, compute_convex_hull:\n\n");

  std::vector<std::pair<std::string, std::vector<Vec3>>> sets;
  sets.emplace_back("sphere, 4 subdivisions", turned(make_sphere(1, 4).vertices));
  sets.emplace_back("sphere, 6 subdivisions", turned(make_sphere(1, 6).vertices));
  sets.emplace_back("torus 64 x 32", turned(make_torus(1, 0.3, 64, 32).vertices));
  sets.emplace_back("cylinder, 1024 sides", turned(make_cylinder(1, 2, 1024).vertices));
  sets.emplace_back("box, 60 x 60 grid per face", grid_box(60));
  sets.emplace_back("cloud, 200,000 points in a cube", [] {
    Random r(7);
    std::vector<Vec3> p;
    for (int i = 0; i < 200000; ++i) p.emplace_back(r.unit(), r.unit(), r.unit());
    return p;
  }());
  std::printf("| point set | points | hull vertices | hull faces | build ms (median) |\n");
  std::printf("|---|---:|---:|---:|---:|\n");
  for (const auto& [name, points] : sets) {
    std::vector<double> ms;
    ConvexHull hull;
    for (int k = 0; k < runs; ++k) {
      const auto start = Clock::now();
      hull = compute_convex_hull(points, name);
      ms.push_back(std::chrono::duration<double, std::milli>(Clock::now() - start).count());
    }
    std::printf("| %s | %zu | %zu | %zu | %.1f |\n", name.c_str(), points.size(),
                hull.vertices.size(), hull.faces.size(), median(ms));
  }
}

/// What one contender answered on every query of one run.
struct Pass {
  double ns_per_query = 0;
  long iterations = 0;
  int max_iterations = 0;     ///< largest iteration count of one query
  long capped = 0;            ///< GJK calls that hit kGjkMaxIterations
  std::vector<char> verdict;  ///< 1: colliding / maybe colliding
};

enum class Contender { kPlane, kGjkWarm, kGjkCold, kCcd };

Pass run(Contender c, const std::vector<Pair>& pairs) {
  Pass pass;
  std::size_t queries = 0;
  for (const Pair& p : pairs) queries += p.poses.size();
  pass.verdict.reserve(queries);
  const auto start = Clock::now();
  for (const Pair& p : pairs) {
    SeparatingPlaneCache plane;
    GjkCache cache;
#ifdef DOVETAIL_HAVE_CCD
    CcdObject oa{&p.a, Transform::identity()}, ob{&p.b, Transform::identity()};
    ccd_t ccd;
    CCD_INIT(&ccd);
    ccd.support1 = ccd_support;
    ccd.support2 = ccd_support;
    ccd.first_dir = ccd_first_direction;
    ccd.max_iterations = 128;
#endif
    for (const Transform& X : p.poses) {
      switch (c) {
        case Contender::kPlane: {
          const SeparatingPlaneResult r = separating_plane_test(p.a, p.b, X, plane);
          pass.iterations += r.iterations;
          pass.verdict.push_back(!r.separated);
          break;
        }
        case Contender::kGjkWarm: {
          const GjkResult r = gjk(p.a, p.b, X, &cache);
          pass.iterations += r.iterations;
          pass.max_iterations = std::max(pass.max_iterations, r.iterations);
          pass.capped += r.hit_iteration_cap;
          pass.verdict.push_back(r.intersecting);
          break;
        }
        case Contender::kGjkCold: {
          const GjkResult r = gjk(p.a, p.b, X);
          pass.iterations += r.iterations;
          pass.max_iterations = std::max(pass.max_iterations, r.iterations);
          pass.capped += r.hit_iteration_cap;
          pass.verdict.push_back(r.intersecting);
          break;
        }
        case Contender::kCcd: {
#ifdef DOVETAIL_HAVE_CCD
          ob.X = X;
          pass.verdict.push_back(ccdGJKIntersect(&oa, &ob, &ccd) != 0);
#endif
          break;
        }
      }
    }
  }
  pass.ns_per_query =
      std::chrono::duration<double, std::nano>(Clock::now() - start).count() / queries;
  return pass;
}

}  // namespace

int main(int argc, char** argv) {
  Options o;
  bool hull_build = false;
  for (int i = 1; i < argc; ++i) {
    if (std::strcmp(argv[i], "--hull-build") == 0) {
      hull_build = true;
      continue;
    }
    if (std::strcmp(argv[i], "--help") == 0 || std::strcmp(argv[i], "-h") == 0) {
      std::printf(
          "usage: convex_bench [--pairs N] [--frames F] [--vertices V] [--speed K] [--runs R] "
          "[--seed S] [--hull-build]\n"
          "  pairs of random polytopes (V points each) in coherent motion, N pairs x F frames "
          "at 90 Hz\n"
          "  (defaults 64 x 1000, V = 48), one query per pair and frame: separating plane "
          "(cached),\n"
          "  GJK warm-started, GJK cold, libccd when available; median over R runs (7).\n"
          "  --speed K   multiplies every angular and swing velocity (less coherence)\n"
          "  --seed S    scene seed (1)\n"
          "  --hull-build  time compute_convex_hull on generated point sets instead\n"
          "Prints a table per contender (ns/query, iterations/query, verdicts) and GJK's\n"
          "iterations warm against cold (mean, largest, calls at kGjkMaxIterations).\n");
      return 0;
    }
    auto value = [&](const char* name) -> const char* {
      if (std::strcmp(argv[i], name) != 0 || i + 1 >= argc) return nullptr;
      return argv[++i];
    };
    if (const char* v = value("--pairs")) {
      o.pairs = static_cast<int>(dovetail::bench::whole("convex_bench", "--pairs", v, 1, 10000000));
    } else if (const char* v2 = value("--frames")) {
      o.frames =
          static_cast<int>(dovetail::bench::whole("convex_bench", "--frames", v2, 1, 1000000));
    } else if (const char* v3 = value("--vertices")) {
      o.vertices =
          static_cast<int>(dovetail::bench::whole("convex_bench", "--vertices", v3, 4, 10000000));
    } else if (const char* v6 = value("--speed")) {
      o.speed = dovetail::bench::real("convex_bench", "--speed", v6, 0);
    } else if (const char* v4 = value("--runs")) {
      o.runs = static_cast<int>(dovetail::bench::whole("convex_bench", "--runs", v4, 1, 1000));
    } else if (const char* v5 = value("--seed")) {
      o.seed = static_cast<std::uint64_t>(
          dovetail::bench::whole("convex_bench", "--seed", v5, 0, 1LL << 62));
    } else {
      std::fprintf(stderr,
                   "usage: convex_bench [--pairs N] [--frames F] [--vertices V] [--speed K] "
                   "[--runs R] [--seed S] [--hull-build]\n");
      return 2;
    }
  }
  if (o.pairs < 1 || o.frames < 1 || o.vertices < 4 || o.runs < 1 || !(o.speed > 0)) {
    std::fprintf(stderr,
                 "convex_bench: pairs, frames, runs, speed must be positive, vertices >= 4\n");
    return 2;
  }

  if (hull_build) {
    hull_build_times(o.runs);
    return 0;
  }

  const std::vector<Pair> pairs = make_scene(o);
  double faces = 0;
  for (const Pair& p : pairs)
    faces += 0.5 * static_cast<double>(p.a.faces.size() + p.b.faces.size());
  faces /= static_cast<double>(pairs.size());

  struct Row {
    const char* name;
    Contender c;
    std::vector<Pass> passes;
  };
  std::vector<Row> rows = {{"separating plane, cached", Contender::kPlane, {}},
                           {"GJK, warm-started", Contender::kGjkWarm, {}},
                           {"GJK, cold", Contender::kGjkCold, {}}};
#ifdef DOVETAIL_HAVE_CCD
  rows.push_back({"libccd ccdGJKIntersect", Contender::kCcd, {}});
#endif
  // Runs interleave the contenders, each in a rotated order.
  for (int r = 0; r < o.runs; ++r) {
    for (std::size_t k = 0; k < rows.size(); ++k) {
      Row& row = rows[(k + static_cast<std::size_t>(r)) % rows.size()];
      row.passes.push_back(run(row.c, pairs));
    }
  }

  const std::vector<char>& reference = rows[1].passes.front().verdict;  // warm GJK
  const std::size_t queries = reference.size();
  long colliding = 0;
  for (char v : reference) colliding += v;
  std::printf(
      "convex_bench: %d pairs x %d frames = %zu queries, %d points per polytope (mean %.1f hull "
      "faces), speed x%g, %ld colliding (%.1f%%) by warm GJK, %d runs\n\n",
      o.pairs, o.frames, queries, o.vertices, faces, o.speed, colliding,
      100.0 * static_cast<double>(colliding) / static_cast<double>(queries), o.runs);
  std::printf(
      "| method | ns/query (median) | fastest run | slowest run | iterations/query | "
      "says colliding | differs from warm GJK |\n");
  std::printf("|---|---:|---:|---:|---:|---:|---:|\n");
  for (const Row& row : rows) {
    std::vector<double> ns;
    for (const Pass& p : row.passes) ns.push_back(p.ns_per_query);
    const Pass& first = row.passes.front();
    long says = 0, differs = 0;
    for (std::size_t i = 0; i < queries; ++i) {
      says += first.verdict[i];
      differs += first.verdict[i] != reference[i];
    }
    char iterations[32] = "-";
    if (row.c != Contender::kCcd) {
      std::snprintf(iterations, sizeof iterations, "%.2f",
                    static_cast<double>(first.iterations) / static_cast<double>(queries));
    }
    std::printf("| %s | %.1f | %.1f | %.1f | %s | %ld | %ld |\n", row.name, median(ns),
                *std::min_element(ns.begin(), ns.end()), *std::max_element(ns.begin(), ns.end()),
                iterations, says, differs);
  }
  // GJK iterations, warm-started against cold, on the same coherent poses.
  const Pass& warm = rows[1].passes.front();
  const Pass& cold = rows[2].passes.front();
  std::printf(
      "\nGJK iterations (support-query pairs) per query: warm-started %.2f (largest %d), cold "
      "%.2f (largest %d), %.1fx fewer warm; calls at the cap of %d: %ld warm, %ld cold\n",
      static_cast<double>(warm.iterations) / static_cast<double>(queries), warm.max_iterations,
      static_cast<double>(cold.iterations) / static_cast<double>(queries), cold.max_iterations,
      static_cast<double>(cold.iterations) / static_cast<double>(std::max(1L, warm.iterations)),
      kGjkMaxIterations, warm.capped, cold.capped);
  // The separating plane's "maybe colliding" on pairs GJK finds apart, and the
  // pairs it proved apart that GJK finds touching (must be none).
  const std::vector<char>& plane = rows[0].passes.front().verdict;
  long conservative = 0, wrong = 0;
  for (std::size_t i = 0; i < queries; ++i) {
    conservative += plane[i] && !reference[i];
    wrong += !plane[i] && reference[i];
  }
  std::printf(
      "\nseparating plane: %ld queries answered \"maybe colliding\" where GJK finds the hulls "
      "apart; %ld proved apart where GJK finds them touching\n",
      conservative, wrong);
#ifndef DOVETAIL_HAVE_CCD
  std::printf("libccd not found (libccd-dev): its row is missing\n");
#endif
  return wrong == 0 && warm.capped == 0 && cold.capped == 0 ? 0 : 1;
}
