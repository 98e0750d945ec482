// Zachmann's protocol for a pair of objects: both scaled into [-1, 1]^3; at
// each distance between their centres the moving one tumbles through a full
// rotation in small steps. Every polygon-level method, the convex level and
// FCL's OBBRSS (when installed) on the same poses, in one run.
//
//   tumble_bench [A B] [--steps N] [--distances D0:D1:STEP] [--table FILE]
//
// Per method and distance: mean and maximum query time, separately for
// colliding and non-colliding queries, and the mean volume and triangle tests.
// The table (--table) has one line per method and distance for the charts
// (scripts/charts.sh).

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <functional>
#include <limits>
#include <memory>
#include <string>
#include <vector>

#include "bench_util.h"
#include "dovetail/collision/convex.h"
#include "dovetail/collision/model.h"
#include "dovetail/collision/primitives.h"
#include "dovetail/engine/mesh_import.h"
#include "fcl_peer.h"
#include "mesh_pair.h"

namespace {

using namespace dovetail;
using collision::Mat3;
using collision::Method;
using collision::Real;
using collision::Transform;
using collision::Vec3;
using Clock = std::chrono::steady_clock;

struct Options {
  std::string mesh_a, mesh_b;
  int steps = 360;
  Real d0 = 0, d1 = 3, dstep = 0.1;
  std::string table;
};

[[noreturn]] void usage(const std::string& why) {
  std::fprintf(stderr,
               "tumble_bench: %s\nusage: tumble_bench [A B] [--steps N] [--distances D0:D1:STEP] "
               "[--table FILE]\n",
               why.c_str());
  std::exit(2);
}

Options parse(int argc, char** argv) {
  Options o;
  std::vector<std::string> meshes;
  for (int i = 1; i < argc; ++i) {
    const std::string arg = argv[i];
    const bool has_value = i + 1 < argc;
    if (arg == "--steps" && has_value) {
      o.steps =
          static_cast<int>(dovetail::bench::whole("tumble_bench", "--steps", argv[++i], 1, 100000));
    } else if (arg == "--distances" && has_value) {
      if (std::sscanf(argv[++i], "%lf:%lf:%lf", &o.d0, &o.d1, &o.dstep) != 3 || !(o.dstep > 0) ||
          !(o.d1 >= o.d0)) {
        usage("--distances needs D0:D1:STEP with D0 <= D1 and STEP > 0");
      }
    } else if (arg == "--table" && has_value) {
      o.table = argv[++i];
    } else if (arg.rfind("--", 0) == 0) {
      usage("unknown option '" + arg + "'");
    } else {
      meshes.push_back(arg);
    }
  }
  if (meshes.size() == 1) meshes.push_back(meshes[0]);
  if (meshes.size() > 2) usage("at most two meshes");
  if (!meshes.empty()) {
    o.mesh_a = meshes[0];
    o.mesh_b = meshes[1];
  }
  return o;
}

/// The mesh moved and scaled uniformly so that its bounding box fits [-1, 1]^3, centred.
collision::Mesh normalized(collision::Mesh m) {
  Vec3 lo = m.vertices.front(), hi = lo;
  for (const Vec3& v : m.vertices) {
    lo = lo.cwiseMin(v);
    hi = hi.cwiseMax(v);
  }
  const Vec3 centre = (lo + hi) / 2;
  const Real half = ((hi - lo) / 2).maxCoeff();
  for (Vec3& v : m.vertices) v = (v - centre) / half;
  return m;
}

struct Cell {
  int colliding = 0, free = 0;
  double sum_us_colliding = 0, max_us_colliding = 0, sum_us_free = 0, max_us_free = 0;
  double volume_tests = 0, triangle_tests = 0;
};

struct Contender {
  std::string name;
  /// One query: verdict; adds its work to the counters.
  std::function<bool(const Transform&, double&, double&)> query;
  std::vector<Cell> cells;  ///< per distance
};

int run(const Options& options) {
  const bench::MeshPair pair = bench::mesh_pair(options.mesh_a, options.mesh_b, normalized);
  const std::shared_ptr<const collision::Mesh>& a = pair.a;
  const std::shared_ptr<const collision::Mesh>& b = pair.b;

  std::vector<Contender> contenders;
  for (const Method m : collision::all_methods()) {
    if (m == Method::kBrute) continue;
    const auto ma = collision::build_model(m, a);
    const auto mb = a == b ? ma : collision::build_model(m, b);
    contenders.push_back({std::string(collision::method_name(m)),
                          [ma, mb](const Transform& X, double& volumes, double& triangles) {
                            const collision::CollideResult r = ma->collide(*mb, X);
                            volumes += static_cast<double>(r.stats.volume_tests);
                            triangles += static_cast<double>(r.stats.triangle_tests);
                            return r.colliding;
                          },
                          {}});
  }
  // The convex level: the hulls' separating plane (conservative: a give-up counts as colliding).
  const auto hull_a = std::make_shared<const collision::ConvexHull>(
      collision::compute_convex_hull(a->vertices, a->source));
  const auto hull_b = a == b ? hull_a
                             : std::make_shared<const collision::ConvexHull>(
                                   collision::compute_convex_hull(b->vertices, b->source));
  auto cache = std::make_shared<collision::SeparatingPlaneCache>();
  contenders.push_back(
      {"hull-plane",
       [hull_a, hull_b, cache](const Transform& X, double&, double&) {
         return !collision::separating_plane_test(*hull_a, *hull_b, X, *cache).separated;
       },
       {}});
#ifdef DOVETAIL_HAVE_FCL
  const auto fa = bench::fcl_model(*a);
  const auto fb = a == b ? fa : bench::fcl_model(*b);
  contenders.push_back(
      {"fcl-obbrss",
       [fa, fb](const Transform& X, double&, double&) { return bench::fcl_collide(*fa, *fb, X); },
       {}});
#endif

  std::vector<Real> distances;
  for (Real d = options.d0; d <= options.d1 + 1e-9; d += options.dstep) distances.push_back(d);
  const Vec3 axis = Vec3(1, 2, 3).normalized();
  std::vector<Mat3> turns;
  for (int k = 0; k < options.steps; ++k) {
    const Real angle = 2 * 3.14159265358979323846 * k / options.steps;
    turns.push_back(Eigen::AngleAxis<Real>(angle, axis).toRotationMatrix() *
                    Eigen::AngleAxis<Real>(2 * angle, Vec3::UnitZ()).toRotationMatrix());
  }
  for (Contender& c : contenders) c.cells.assign(distances.size(), Cell{});
  int disagreements = 0;
  for (std::size_t di = 0; di < distances.size(); ++di) {
    for (const Mat3& R : turns) {
      Transform X;
      X.R = R;
      X.t = Vec3(distances[di], 0, 0);
      bool first_verdict = false;
      for (std::size_t ci = 0; ci < contenders.size(); ++ci) {
        Contender& c = contenders[ci];
        Cell& cell = c.cells[di];
        double volumes = 0, triangles = 0;
        const auto t0 = Clock::now();
        const bool hit = c.query(X, volumes, triangles);
        const double us = std::chrono::duration<double, std::micro>(Clock::now() - t0).count();
        if (ci == 0) first_verdict = hit;
        if (c.name != "hull-plane" && hit != first_verdict) ++disagreements;
        cell.volume_tests += volumes;
        cell.triangle_tests += triangles;
        if (hit) {
          ++cell.colliding;
          cell.sum_us_colliding += us;
          cell.max_us_colliding = std::max(cell.max_us_colliding, us);
        } else {
          ++cell.free;
          cell.sum_us_free += us;
          cell.max_us_free = std::max(cell.max_us_free, us);
        }
      }
    }
  }

  std::FILE* table = options.table.empty() ? nullptr : std::fopen(options.table.c_str(), "w");
  if (!options.table.empty() && table == nullptr) {
    std::fprintf(stderr, "tumble_bench: %s cannot be written\n", options.table.c_str());
    return 1;
  }
  if (table) {
    std::fprintf(table,
                 "# method distance colliding free mean_us mean_us_colliding max_us_colliding "
                 "mean_us_free max_us_free volume_tests triangle_tests\n");
  }
  std::printf("\n%zu distances x %d turns; mean us per query over all distances (max)\n",
              distances.size(), options.steps);
  std::printf("%-11s %12s %12s %12s %12s\n", "method", "colliding", "(max)", "free", "(max)");
  for (const Contender& c : contenders) {
    Cell all;
    for (std::size_t di = 0; di < distances.size(); ++di) {
      const Cell& x = c.cells[di];
      const int n = x.colliding + x.free;
      if (table) {
        std::fprintf(table, "%s %.3f %d %d %.4f %.4f %.4f %.4f %.4f %.1f %.1f\n", c.name.c_str(),
                     distances[di], x.colliding, x.free, (x.sum_us_colliding + x.sum_us_free) / n,
                     x.colliding ? x.sum_us_colliding / x.colliding : 0, x.max_us_colliding,
                     x.free ? x.sum_us_free / x.free : 0, x.max_us_free, x.volume_tests / n,
                     x.triangle_tests / n);
      }
      all.colliding += x.colliding;
      all.free += x.free;
      all.sum_us_colliding += x.sum_us_colliding;
      all.sum_us_free += x.sum_us_free;
      all.max_us_colliding = std::max(all.max_us_colliding, x.max_us_colliding);
      all.max_us_free = std::max(all.max_us_free, x.max_us_free);
    }
    std::printf("%-11s %12.2f %12.1f %12.2f %12.1f\n", c.name.c_str(),
                all.colliding ? all.sum_us_colliding / all.colliding : 0, all.max_us_colliding,
                all.free ? all.sum_us_free / all.free : 0, all.max_us_free);
  }
  if (table) std::fclose(table);
  std::printf(
      "verdicts differing from %s: %d (the hull-plane level is conservative, not counted)\n",
      contenders.front().name.c_str(), disagreements);
  return disagreements == 0 ? 0 : 1;
}

}  // namespace

int main(int argc, char** argv) {
  try {
    return run(parse(argc, argv));
  } catch (const std::exception& e) {
    std::fprintf(stderr, "tumble_bench: %s\n", e.what());
    return 1;
  }
}
