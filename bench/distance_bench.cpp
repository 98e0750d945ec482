// Distance benchmark: Dovetail's distance and tolerance queries and FCL's
// distance (OBBRSS and RSS hierarchies, nearest points on) on the same
// contact-distance poses with positive gaps only, in one run.
//
//   distance_bench [MESH [MESH_B]] [--directions N] [--runs R] [--seed S] [--leaf L] [--json FILE]
//
// MESH defaults to /work/shared/data/stanford-bunny.obj, used as both A and B.
// Prints build time, bytes per triangle, the median over runs of the mean
// query time, work counters, the ratio to FCL, the largest difference from
// FCL's distance relative to the object size, and the tolerance query's time
// at a tolerance equal to the median distance.

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <fstream>
#include <memory>
#include <string>
#include <vector>

#include "bench_util.h"
#include "dovetail/collision/distance.h"
#include "dovetail/collision/model.h"
#include "dovetail/collision/pose_sampling.h"
#include "dovetail/engine/mesh_import.h"

#ifdef DOVETAIL_HAVE_FCL
#include <fcl/fcl.h>
#endif

namespace {

using dovetail::bench::median;

using namespace dovetail;
using Clock = std::chrono::steady_clock;

double ms_since(Clock::time_point start) {
  return std::chrono::duration<double, std::milli>(Clock::now() - start).count();
}

struct Options {
  std::string mesh_a = "/work/shared/data/stanford-bunny.obj";
  std::string mesh_b;
  int directions = 50;
  int runs = 5;
  std::uint64_t seed = 1;
  int leaf = 1;
  std::string json;
};

/// One contender: per-run total times, the last run's per-pose answers.
struct Contender {
  std::string name;
  double build_ms = 0;
  double bytes_per_triangle = 0;
  std::vector<double> run_ms;
  std::vector<double> distances;
  double volume_tests = 0, triangle_tests = 0;  ///< per query
};

#ifdef DOVETAIL_HAVE_FCL
template <typename BV>
std::shared_ptr<fcl::BVHModel<BV>> fcl_model(const collision::Mesh& mesh) {
  auto model = std::make_shared<fcl::BVHModel<BV>>();
  std::vector<fcl::Vector3d> v(mesh.vertices.begin(), mesh.vertices.end());
  std::vector<fcl::Triangle> t;
  for (const auto& tri : mesh.triangles) t.emplace_back(tri[0], tri[1], tri[2]);
  model->beginModel(static_cast<int>(t.size()), static_cast<int>(v.size()));
  model->addSubModel(v, t);
  model->endModel();
  return model;
}

fcl::Transform3d fcl_transform(const collision::Transform& X) {
  fcl::Transform3d T = fcl::Transform3d::Identity();
  T.linear() = X.R;
  T.translation() = X.t;
  return T;
}

/// An FCL hierarchy of one BV type as a contender.
template <typename BV>
struct FclContender {
  std::shared_ptr<fcl::BVHModel<BV>> a, b;

  Contender build(const std::string& name, const collision::Mesh& mesh_a,
                  const collision::Mesh& mesh_b, bool same) {
    Contender c;
    c.name = name;
    std::vector<double> builds;
    for (int r = 0; r < 3; ++r) {
      const auto t0 = Clock::now();
      a = fcl_model<BV>(mesh_a);
      builds.push_back(ms_since(t0));
    }
    b = same ? a : fcl_model<BV>(mesh_b);
    c.build_ms = median(builds);
    c.bytes_per_triangle = (a->getNumBVs() * sizeof(fcl::BVNode<BV>) +
                            mesh_a.triangle_count() * sizeof(unsigned int)) /
                           static_cast<double>(mesh_a.triangle_count());
    return c;
  }

  double query(const collision::Transform& X_AB) const {
    fcl::DistanceRequestd request(true);
    fcl::DistanceResultd result;
    fcl::distance(a.get(), fcl::Transform3d::Identity(), b.get(), fcl_transform(X_AB), request,
                  result);
    return result.min_distance;
  }
};
#endif

int run(const Options& options) {
  const auto a = std::make_shared<const collision::Mesh>(engine::import_mesh(options.mesh_a));
  const auto b = options.mesh_b.empty() || options.mesh_b == options.mesh_a
                     ? a
                     : std::make_shared<const collision::Mesh>(engine::import_mesh(options.mesh_b));
  std::printf("A: %s (%zu triangles)\nB: %s (%zu triangles)\n", a->source.c_str(),
              a->triangle_count(), b->source.c_str(), b->triangle_count());
  const collision::Bounds bounds = collision::mesh_bounds(*a);
  const double size = (bounds.max - bounds.min).norm();

  // Contact-distance poses with positive gaps only (bisection by the boxtree).
  collision::ContactPoseSettings settings;
  settings.directions = options.directions;
  settings.seed = options.seed;
  settings.gaps = {0.01, 0.02, 0.05, 0.10, 0.20};
  const auto pose_a = collision::build_model(collision::Method::kBoxtree, a);
  const auto pose_b = a == b ? pose_a : collision::build_model(collision::Method::kBoxtree, b);
  const std::vector<collision::SampledPose> poses =
      collision::contact_distance_poses(*pose_a, *pose_b, settings);
  std::printf("poses: %zu (%d directions x gaps 1%%, 2%%, 5%%, 10%%, 20%% of size %.4g)\n",
              poses.size(), options.directions, size);

  // Our model.
  Contender ours;
  ours.name = "dovetail-rss";
  std::shared_ptr<const collision::DistanceModel> da, db;
  {
    std::vector<double> builds;
    for (int r = 0; r < 3; ++r) {
      const auto t0 = Clock::now();
      da = collision::build_distance_model(a, {.max_leaf_size = options.leaf});
      builds.push_back(ms_since(t0));
    }
    db = a == b ? da : collision::build_distance_model(b, {.max_leaf_size = options.leaf});
    ours.build_ms = median(builds);
    ours.bytes_per_triangle = da->info().bytes_per_triangle;
  }
  Contender tolerance;
  tolerance.name = "dovetail-tol";
  tolerance.build_ms = ours.build_ms;
  tolerance.bytes_per_triangle = ours.bytes_per_triangle;

#ifdef DOVETAIL_HAVE_FCL
  FclContender<fcl::OBBRSSd> fcl_obbrss;
  FclContender<fcl::RSSd> fcl_rss;
  std::vector<Contender> peers;
  peers.push_back(fcl_obbrss.build("fcl-obbrss", *a, *b, a == b));
  peers.push_back(fcl_rss.build("fcl-rss", *a, *b, a == b));
#endif

  // Tolerance: the median distance over the poses.
  std::vector<double> exact;
  for (const auto& p : poses) exact.push_back(collision::distance(*da, *db, p.X_AB).distance);
  const double eps = median(exact);
  std::printf("tolerance query at eps = median distance = %.6g (%.3f%% of size)\n\n", eps,
              100 * eps / size);

  int within = 0;
  for (int r = 0; r < options.runs; ++r) {
    // Ours: distance.
    {
      ours.distances.assign(poses.size(), 0);
      double vt = 0, tt = 0;
      const auto t0 = Clock::now();
      for (std::size_t p = 0; p < poses.size(); ++p) {
        const collision::DistanceResult res = collision::distance(*da, *db, poses[p].X_AB);
        ours.distances[p] = res.distance;
        vt += res.stats.volume_tests;
        tt += res.stats.triangle_tests;
      }
      ours.run_ms.push_back(ms_since(t0));
      ours.volume_tests = vt / poses.size();
      ours.triangle_tests = tt / poses.size();
    }
    // Ours: tolerance.
    {
      double vt = 0, tt = 0;
      within = 0;
      const auto t0 = Clock::now();
      for (std::size_t p = 0; p < poses.size(); ++p) {
        const collision::ToleranceResult res =
            collision::within_tolerance(*da, *db, poses[p].X_AB, eps);
        within += res.within;
        vt += res.stats.volume_tests;
        tt += res.stats.triangle_tests;
      }
      tolerance.run_ms.push_back(ms_since(t0));
      tolerance.volume_tests = vt / poses.size();
      tolerance.triangle_tests = tt / poses.size();
    }
#ifdef DOVETAIL_HAVE_FCL
    for (std::size_t i = 0; i < peers.size(); ++i) {
      Contender& c = peers[i];
      c.distances.assign(poses.size(), 0);
      const auto t0 = Clock::now();
      for (std::size_t p = 0; p < poses.size(); ++p) {
        c.distances[p] = i == 0 ? fcl_obbrss.query(poses[p].X_AB) : fcl_rss.query(poses[p].X_AB);
      }
      c.run_ms.push_back(ms_since(t0));
    }
#endif
  }

  // Verdicts of the tolerance query against the distances.
  int verdict_errors = 0;
  for (std::size_t p = 0; p < poses.size(); ++p) {
    verdict_errors += collision::within_tolerance(*da, *db, poses[p].X_AB, eps).within !=
                      (ours.distances[p] <= eps);
  }

  std::vector<Contender> all = {ours, tolerance};
#ifdef DOVETAIL_HAVE_FCL
  all.insert(all.end(), peers.begin(), peers.end());
#endif
  const double ours_ms = median(ours.run_ms);
  std::printf("%-13s %9s %9s %10s %12s %10s %16s\n", "method", "build_ms", "bytes/tri", "us/query",
              "volume_tests", "tri_tests", "dist_time/this");
  for (const Contender& c : all) {
    const double ms = median(c.run_ms);
    std::printf("%-13s %9.1f %9.1f %10.2f %12.0f %10.0f %15.3fx\n", c.name.c_str(), c.build_ms,
                c.bytes_per_triangle, 1000.0 * ms / poses.size(), c.volume_tests, c.triangle_tests,
                ours_ms / ms);
  }
  std::printf(
      "(medians over %d runs of %zu queries; dist_time/this: our distance query's time over this "
      "row's; FCL does not report work counters)\n",
      options.runs, poses.size());
  std::printf("tolerance: %d of %zu poses within eps, %d verdicts differ from distance <= eps\n",
              within, poses.size(), verdict_errors);
  std::printf("distance / tolerance time: %.2fx\n", ours_ms / median(tolerance.run_ms));

  std::ofstream json;
  if (!options.json.empty()) json.open(options.json);
#ifdef DOVETAIL_HAVE_FCL
  for (const Contender& c : peers) {
    double worst = 0;
    for (std::size_t p = 0; p < poses.size(); ++p)
      worst = std::max(worst, std::abs(ours.distances[p] - c.distances[p]) / size);
    const double ratio = ours_ms / median(c.run_ms);
    std::printf("vs %-10s: time ratio ours/%s = %.3f, max |ours - %s| / size = %.3g\n",
                c.name.c_str(), c.name.c_str(), ratio, c.name.c_str(), worst);
    if (json.is_open()) {
      json << "{\"peer\":\"" << c.name << "\",\"ratio\":" << ratio << ",\"max_rel_diff\":" << worst
           << ",\"peer_us_per_query\":" << 1000.0 * median(c.run_ms) / poses.size() << "}\n";
    }
  }
#endif
  if (json.is_open()) {
    json << "{\"distance_us_per_query\":" << 1000.0 * ours_ms / poses.size()
         << ",\"tolerance_us_per_query\":" << 1000.0 * median(tolerance.run_ms) / poses.size()
         << ",\"build_ms\":" << ours.build_ms
         << ",\"bytes_per_triangle\":" << ours.bytes_per_triangle << ",\"queries\":" << poses.size()
         << ",\"runs\":" << options.runs << "}\n";
  }
  return verdict_errors == 0 ? 0 : 1;
}

}  // namespace

int main(int argc, char** argv) {
  Options options;
  std::vector<std::string> positional;
  for (int i = 1; i < argc; ++i) {
    const std::string arg = argv[i];
    auto value = [&]() -> std::string {
      if (i + 1 >= argc) {
        std::fprintf(stderr, "distance_bench: %s needs a value\n", arg.c_str());
        std::exit(2);
      }
      return argv[++i];
    };
    if (arg == "--directions")
      options.directions = static_cast<int>(
          dovetail::bench::whole("distance_bench", "--directions", value().c_str(), 1, 1000000));
    else if (arg == "--runs")
      options.runs = static_cast<int>(
          dovetail::bench::whole("distance_bench", "--runs", value().c_str(), 1, 1000));
    else if (arg == "--seed")
      options.seed = static_cast<std::uint64_t>(
          dovetail::bench::whole("distance_bench", "--seed", value().c_str(), 0, 1LL << 62));
    else if (arg == "--leaf")
      options.leaf = static_cast<int>(
          dovetail::bench::whole("distance_bench", "--leaf", value().c_str(), 1, 64));
    else if (arg == "--json")
      options.json = value();
    else if (arg == "--help") {
      std::printf(
          "usage: distance_bench [MESH [MESH_B]] [--directions N] [--runs R] [--seed S] "
          "[--leaf L] [--json FILE]\n");
      return 0;
    } else if (!arg.empty() && arg[0] == '-') {
      std::fprintf(stderr, "distance_bench: unknown option %s\n", arg.c_str());
      return 2;
    } else
      positional.push_back(arg);
  }
  if (!positional.empty()) options.mesh_a = positional[0];
  if (positional.size() > 1) options.mesh_b = positional[1];
  try {
    return run(options);
  } catch (const std::exception& e) {
    std::fprintf(stderr, "distance_bench: %s\n", e.what());
    return 1;
  }
}
