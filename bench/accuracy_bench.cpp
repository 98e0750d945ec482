// Speed against accuracy: every approximate level of the collision pipeline
// against the exact answer, on one contact-distance pose list (Trenkel,
// Weller, Zachmann), in one run.
//
//   accuracy_bench [A B] [--directions N] [--runs R] [--seed S] [--table FILE]
//
// Without meshes it uses a generated sphere and torus. Settings:
//   exact METHOD          every polygon-level hierarchy, exact (the reference)
//   METHOD volume         the root volumes alone (aabb: the bounding box; obb:
//                         the oriented box; dopK: each k-DOP), that is a
//                         hierarchy cut at depth 0
//   METHOD depth D        time-critical detection: the hierarchy cut D levels
//                         below the roots (CollideRequest::max_depth)
//   hull                  the convex hulls alone (GJK, intersecting or not)
//   plane cap N           the separating-plane search stopped after N
//                         iterations; giving up counts as colliding
// Per setting: the median over runs of the mean query time, false positives
// and false negatives against the exact answer (in % of all poses), and the time
// relative to the fastest exact method. With --table, the same as a
// whitespace-separated table for the charts (scripts/charts.sh).

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <fstream>
#include <functional>
#include <memory>
#include <string>
#include <vector>

#include "bench_util.h"
#include "dovetail/collision/convex.h"
#include "dovetail/collision/model.h"
#include "dovetail/collision/pose_sampling.h"
#include "dovetail/collision/primitives.h"
#include "dovetail/engine/mesh_import.h"
#include "mesh_pair.h"

namespace {

using dovetail::bench::median;

using namespace dovetail;
using collision::Method;
using Clock = std::chrono::steady_clock;

struct Options {
  std::string mesh_a, mesh_b;
  int directions = 100;
  int runs = 5;
  std::uint64_t seed = 1;
  std::string table;
};

/// One setting: a name, its family (for the chart) and the query.
struct Setting {
  std::string name;
  std::string family;  ///< exact, volume, depth-obb, depth-dop18, depth-aabb, hull, plane
  std::function<bool(const collision::Transform&)> query;
  std::vector<double> run_us;  ///< mean µs per query, per run
  int false_positives = 0, false_negatives = 0;
};

[[noreturn]] void usage(const std::string& why) {
  std::fprintf(stderr,
               "accuracy_bench: %s\nusage: accuracy_bench [A B] [--directions N] [--runs R] "
               "[--seed S] [--table FILE]\n",
               why.c_str());
  std::exit(2);
}

Options parse(int argc, char** argv) {
  Options o;
  std::vector<std::string> meshes;
  for (int i = 1; i < argc; ++i) {
    const std::string arg = argv[i];
    const bool has_value = i + 1 < argc;
    if (arg == "--directions" && has_value) {
      o.directions = static_cast<int>(
          dovetail::bench::whole("accuracy_bench", "--directions", argv[++i], 1, 1000000));
    } else if (arg == "--runs" && has_value) {
      o.runs =
          static_cast<int>(dovetail::bench::whole("accuracy_bench", "--runs", argv[++i], 1, 1000));
    } else if (arg == "--seed" && has_value) {
      o.seed = static_cast<std::uint64_t>(
          dovetail::bench::whole("accuracy_bench", "--seed", argv[++i], 0, 1LL << 62));
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

int run(const Options& options) {
  const bench::MeshPair pair = bench::mesh_pair(options.mesh_a, options.mesh_b);
  const std::shared_ptr<const collision::Mesh>& a = pair.a;
  const std::shared_ptr<const collision::Mesh>& b = pair.b;

  collision::ContactPoseSettings pose_settings;
  pose_settings.directions = options.directions;
  pose_settings.seed = options.seed;
  const auto pose_a = collision::build_model(Method::kObb, a);
  const auto pose_b = a == b ? pose_a : collision::build_model(Method::kObb, b);
  const std::vector<collision::SampledPose> poses =
      collision::contact_distance_poses(*pose_a, *pose_b, pose_settings);
  // The exact answer: the OBB tree's exact query (every exact method agrees
  // with brute force, tests/collision/hierarchy_test.cpp; brute force itself
  // would take minutes on large meshes). The exact settings below are checked
  // against it too.
  std::vector<char> truth;
  int colliding = 0;
  for (const collision::SampledPose& p : poses) {
    truth.push_back(pose_a->collide(*pose_b, p.X_AB).colliding);
    colliding += truth.back();
  }
  std::printf("poses: %zu (%d directions x %zu gaps), %d colliding\n\n", poses.size(),
              options.directions, pose_settings.gaps.size(), colliding);

  std::vector<Setting> settings;
  const Method hierarchies[] = {Method::kBoxtree, Method::kDop6, Method::kDop14, Method::kDop18,
                                Method::kDop26,   Method::kAabb, Method::kObb};
  std::vector<std::pair<std::shared_ptr<const collision::CollisionModel>,
                        std::shared_ptr<const collision::CollisionModel>>>
      models;
  for (const Method m : hierarchies) {
    const auto ma = collision::build_model(m, a);
    const auto mb = a == b ? ma : collision::build_model(m, b);
    models.emplace_back(ma, mb);
    const std::string name(collision::method_name(m));
    settings.push_back(
        {"exact " + name,
         "exact",
         [ma, mb](const collision::Transform& X) { return ma->collide(*mb, X).colliding; },
         {}});
    if (m == Method::kBoxtree) continue;  // its own traversal has no depth cut
    settings.push_back({name + " volume",
                        "volume",
                        [ma, mb](const collision::Transform& X) {
                          return ma->collide(*mb, X, {.max_depth = 0}).colliding;
                        },
                        {}});
    if (m != Method::kObb && m != Method::kDop18 && m != Method::kAabb) continue;
    for (const int depth : {2, 4, 8, 12, 16, 20, 24, 28, 32, 36, 40, 48}) {
      settings.push_back({name + " depth " + std::to_string(depth),
                          "depth-" + name,
                          [ma, mb, depth](const collision::Transform& X) {
                            return ma->collide(*mb, X, {.max_depth = depth}).colliding;
                          },
                          {}});
    }
  }
  const auto hull_a = std::make_shared<const collision::ConvexHull>(
      collision::compute_convex_hull(a->vertices, a->source));
  const auto hull_b = a == b ? hull_a
                             : std::make_shared<const collision::ConvexHull>(
                                   collision::compute_convex_hull(b->vertices, b->source));
  settings.push_back({"hull",
                      "hull",
                      [hull_a, hull_b](const collision::Transform& X) {
                        return collision::gjk(*hull_a, *hull_b, X).intersecting;
                      },
                      {}});
  for (const int cap : {1, 2, 4, 8, 16, 64}) {
    settings.push_back({"plane cap " + std::to_string(cap),
                        "plane",
                        [hull_a, hull_b, cap](const collision::Transform& X) {
                          collision::SeparatingPlaneCache cache;
                          return !collision::separating_plane_test(*hull_a, *hull_b, X, cache,
                                                                   {.max_iterations = cap})
                                      .separated;
                        },
                        {}});
  }

  // Verdicts once, then the timed runs, settings interleaved within each run.
  for (Setting& s : settings) {
    for (std::size_t p = 0; p < poses.size(); ++p) {
      const bool v = s.query(poses[p].X_AB);
      s.false_positives += v && !truth[p];
      s.false_negatives += !v && truth[p];
    }
  }
  int sink = 0;
  for (int r = 0; r < options.runs; ++r) {
    for (Setting& s : settings) {
      const auto t0 = Clock::now();
      for (const collision::SampledPose& p : poses) sink += s.query(p.X_AB);
      s.run_us.push_back(std::chrono::duration<double, std::micro>(Clock::now() - t0).count() /
                         static_cast<double>(poses.size()));
    }
  }
  double best_exact = 1e300;
  for (const Setting& s : settings) {
    if (s.family == "exact") best_exact = std::min(best_exact, median(s.run_us));
  }
  const double n = static_cast<double>(poses.size());
  std::printf("%-20s %10s %9s %8s %8s\n", "setting", "us/query", "x best", "FP %", "FN %");
  std::FILE* table = options.table.empty() ? nullptr : std::fopen(options.table.c_str(), "w");
  if (!options.table.empty() && table == nullptr) {
    std::fprintf(stderr, "accuracy_bench: %s cannot be written\n", options.table.c_str());
    return 1;
  }
  if (table)
    std::fprintf(table, "# family setting us_per_query x_best_exact fp_percent fn_percent\n");
  for (const Setting& s : settings) {
    const double us = median(s.run_us);
    const double fp = 100.0 * s.false_positives / n, fn = 100.0 * s.false_negatives / n;
    std::printf("%-20s %10.3f %9.3f %8.3f %8.3f\n", s.name.c_str(), us, us / best_exact, fp, fn);
    if (table) {
      std::string name = s.name;
      std::replace(name.begin(), name.end(), ' ', '_');
      std::fprintf(table, "%s %s %.4f %.4f %.4f %.4f\n", s.family.c_str(), name.c_str(), us,
                   us / best_exact, fp, fn);
    }
  }
  if (table) std::fclose(table);
  std::printf("\n(checksum %d; %d runs, median of the per-run mean)\n", sink, options.runs);
  return 0;
}

}  // namespace

int main(int argc, char** argv) {
  try {
    return run(parse(argc, argv));
  } catch (const std::exception& e) {
    std::fprintf(stderr, "accuracy_bench: %s\n", e.what());
    return 1;
  }
}
