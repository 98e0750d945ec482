// Polygon-level benchmark: every Dovetail method and FCL's OBBRSS on the same
// contact-distance pose list (Trenkel, Weller, Zachmann), in one run.
//
//   polygon_bench [A B] [--directions N] [--runs R] [--seed S] [--json FILE]
//
// Without meshes it uses two generated parts. Prints, per method, build time,
// bytes per triangle, the median over runs of the mean query time (overall and
// per gap), work counters, verdict agreement with brute force or FCL, and
// the ratio to FCL's time.

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <cstring>
#include <fstream>
#include <map>
#include <memory>
#include <string>
#include <vector>

#include "bench_util.h"
#include "dovetail/collision/model.h"
#include "dovetail/collision/pose_sampling.h"
#include "dovetail/collision/primitives.h"
#include "dovetail/engine/mesh_import.h"
#include "fcl_peer.h"
#include "mesh_pair.h"

namespace {

using dovetail::bench::median;

using namespace dovetail;
using collision::Method;
using Clock = std::chrono::steady_clock;

double ms_since(Clock::time_point start) {
  return std::chrono::duration<double, std::milli>(Clock::now() - start).count();
}

struct Options {
  std::string mesh_a, mesh_b;
  int directions = 100;
  int runs = 5;
  std::uint64_t seed = 1;
  std::string json;
  bool with_brute = false;
  std::vector<std::string> methods;  ///< empty: all but brute
};

/// Results of one contender over all runs.
struct Contender {
  std::string name;
  double build_ms = 0;
  double bytes_per_triangle = 0;
  std::vector<double> run_ms;                    ///< total query time per run
  std::map<double, std::vector<double>> gap_ms;  ///< per gap, per run
  std::vector<char> verdicts;
  double volume_tests = 0, triangle_tests = 0;  ///< per query
};

#ifdef DOVETAIL_HAVE_FCL
using bench::fcl_model;
using bench::fcl_transform;

struct FclPair {
  std::shared_ptr<fcl::BVHModel<fcl::OBBRSSd>> a, b;
};
#endif

int run(const Options& options) {
  const bench::MeshPair pair = bench::mesh_pair(options.mesh_a, options.mesh_b);
  const std::shared_ptr<const collision::Mesh>& a = pair.a;
  const std::shared_ptr<const collision::Mesh>& b = pair.b;

  // Pose list: contact-distance poses found by bisection with the boxtree.
  collision::ContactPoseSettings settings;
  settings.directions = options.directions;
  settings.seed = options.seed;
  const auto t_poses = Clock::now();
  const auto pose_a = collision::build_model(Method::kBoxtree, a);
  const auto pose_b = a == b ? pose_a : collision::build_model(Method::kBoxtree, b);
  const std::vector<collision::SampledPose> poses =
      collision::contact_distance_poses(*pose_a, *pose_b, settings);
  std::printf("poses: %zu (%d directions x %zu gaps), generated in %.0f ms\n\n", poses.size(),
              options.directions, settings.gaps.size(), ms_since(t_poses));

  std::vector<Contender> contenders;
  std::vector<Method> methods;
  for (Method m : collision::all_methods()) {
    const std::string name(collision::method_name(m));
    const bool listed =
        std::find(options.methods.begin(), options.methods.end(), name) != options.methods.end();
    if (options.methods.empty() ? (m != Method::kBrute || options.with_brute) : listed)
      methods.push_back(m);
  }
  std::vector<std::pair<std::shared_ptr<const collision::CollisionModel>,
                        std::shared_ptr<const collision::CollisionModel>>>
      models;
  for (Method m : methods) {
    Contender c;
    c.name = std::string(collision::method_name(m));
    std::vector<double> builds;
    std::shared_ptr<const collision::CollisionModel> ma, mb;
    for (int r = 0; r < 3; ++r) {
      const auto t0 = Clock::now();
      ma = collision::build_model(m, a);
      builds.push_back(ms_since(t0));
    }
    mb = a == b ? ma : collision::build_model(m, b);
    c.build_ms = median(builds);
    c.bytes_per_triangle = ma->info().bytes_per_triangle;
    models.emplace_back(ma, mb);
    contenders.push_back(std::move(c));
  }

#ifdef DOVETAIL_HAVE_FCL
  FclPair fcl_pair;
  {
    Contender c;
    c.name = "fcl-obbrss";
    std::vector<double> builds;
    for (int r = 0; r < 3; ++r) {
      const auto t0 = Clock::now();
      fcl_pair.a = fcl_model(*a);
      builds.push_back(ms_since(t0));
    }
    fcl_pair.b = a == b ? fcl_pair.a : fcl_model(*b);
    c.build_ms = median(builds);
    const double hierarchy_bytes = fcl_pair.a->getNumBVs() * sizeof(fcl::BVNode<fcl::OBBRSSd>) +
                                   a->triangle_count() * sizeof(unsigned int);
    c.bytes_per_triangle = hierarchy_bytes / a->triangle_count();
    std::printf("FCL OBBRSS hierarchy: %d nodes of %zu bytes plus %zu primitive indices\n",
                fcl_pair.a->getNumBVs(), sizeof(fcl::BVNode<fcl::OBBRSSd>), a->triangle_count());
    contenders.push_back(std::move(c));
  }
#endif

  // Runs interleave the contenders so machine noise spreads over all of them.
  for (int r = 0; r < options.runs; ++r) {
    for (std::size_t i = 0; i < contenders.size(); ++i) {
      Contender& c = contenders[i];
      std::map<double, double> gap_ms;
      std::vector<char> verdicts(poses.size());
      double volume_tests = 0, triangle_tests = 0;
      const auto t0 = Clock::now();
      for (std::size_t p = 0; p < poses.size(); ++p) {
        const auto tq = Clock::now();
        bool hit;
        if (i < models.size()) {
          const collision::CollideResult res =
              models[i].first->collide(*models[i].second, poses[p].X_AB);
          hit = res.colliding;
          volume_tests += res.stats.volume_tests;
          triangle_tests += res.stats.triangle_tests;
        } else {
#ifdef DOVETAIL_HAVE_FCL
          fcl::CollisionRequestd request;
          fcl::CollisionResultd result;
          fcl::collide(fcl_pair.a.get(), fcl::Transform3d::Identity(), fcl_pair.b.get(),
                       fcl_transform(poses[p].X_AB), request, result);
          hit = result.isCollision();
#else
          hit = false;
#endif
        }
        gap_ms[poses[p].gap] += ms_since(tq);
        verdicts[p] = hit;
      }
      c.run_ms.push_back(ms_since(t0));
      for (const auto& [gap, ms] : gap_ms) c.gap_ms[gap].push_back(ms);
      c.verdicts = verdicts;
      c.volume_tests = volume_tests / poses.size();
      c.triangle_tests = triangle_tests / poses.size();
    }
  }

  const std::vector<char>& reference = contenders.back().verdicts;
  const double reference_ms = median(contenders.back().run_ms);
  const char* reference_name = contenders.back().name.c_str();
  std::printf("\n%-11s %9s %9s %11s %9s %12s %11s %12s\n", "method", "build_ms", "bytes/tri",
              "us/query", "vs_last", "volume_tests", "tri_tests", "disagree");
  for (const Contender& c : contenders) {
    int disagreements = 0;
    for (std::size_t p = 0; p < poses.size(); ++p) disagreements += c.verdicts[p] != reference[p];
    const double ms = median(c.run_ms);
    std::printf("%-11s %9.1f %9.1f %11.2f %8.3fx %12.0f %11.0f %12d\n", c.name.c_str(), c.build_ms,
                c.bytes_per_triangle, 1000.0 * ms / poses.size(), ms / reference_ms, c.volume_tests,
                c.triangle_tests, disagreements);
  }
  std::printf("(vs_last and disagree are relative to %s; medians over %d runs)\n\n", reference_name,
              options.runs);

  std::printf("%-11s", "us/query by gap:");
  for (const auto& [gap, runs] : contenders.front().gap_ms) std::printf(" %9.1f%%", 100 * gap);
  std::printf("\n");
  for (const Contender& c : contenders) {
    std::printf("%-16s", c.name.c_str());
    for (const auto& [gap, runs] : c.gap_ms) {
      std::printf(" %10.2f", 1000.0 * median(runs) / (poses.size() / c.gap_ms.size()));
    }
    std::printf("\n");
  }

  if (!options.json.empty()) {
    std::ofstream out(options.json);
    for (const Contender& c : contenders) {
      out << "{\"method\":\"" << c.name << "\",\"build_ms\":" << c.build_ms
          << ",\"bytes_per_triangle\":" << c.bytes_per_triangle
          << ",\"us_per_query\":" << 1000.0 * median(c.run_ms) / poses.size() << ",\"ratio_to_"
          << reference_name << "\":" << median(c.run_ms) / reference_ms
          << ",\"volume_tests\":" << c.volume_tests << ",\"triangle_tests\":" << c.triangle_tests
          << ",\"queries\":" << poses.size() << ",\"runs\":" << options.runs << "}\n";
    }
  }
  return 0;
}

}  // namespace

int main(int argc, char** argv) {
  Options options;
  std::vector<std::string> positional;
  for (int i = 1; i < argc; ++i) {
    const std::string arg = argv[i];
    auto value = [&]() -> std::string {
      if (i + 1 >= argc) {
        std::fprintf(stderr, "polygon_bench: %s needs a value\n", arg.c_str());
        std::exit(2);
      }
      return argv[++i];
    };
    if (arg == "--directions")
      options.directions = static_cast<int>(
          dovetail::bench::whole("polygon_bench", "--directions", value().c_str(), 1, 1000000));
    else if (arg == "--runs")
      options.runs = static_cast<int>(
          dovetail::bench::whole("polygon_bench", "--runs", value().c_str(), 1, 1000));
    else if (arg == "--seed")
      options.seed = static_cast<std::uint64_t>(
          dovetail::bench::whole("polygon_bench", "--seed", value().c_str(), 0, 1LL << 62));
    else if (arg == "--json")
      options.json = value();
    else if (arg == "--with-brute")
      options.with_brute = true;
    else if (arg == "--methods") {
      for (std::string& name : dovetail::bench::comma_list(value())) {
        options.methods.push_back(std::move(name));
      }
    } else if (arg == "--help") {
      std::printf(
          "usage: polygon_bench [A B] [--directions N] [--runs R] [--seed S] [--json FILE] "
          "[--with-brute] [--methods m1,m2,...]\n");
      return 0;
    } else if (!arg.empty() && arg[0] == '-') {
      std::fprintf(stderr, "polygon_bench: unknown option %s\n", arg.c_str());
      return 2;
    } else
      positional.push_back(arg);
  }
  if (positional.size() == 1) positional.push_back(positional[0]);
  if (positional.size() == 2) options.mesh_a = positional[0], options.mesh_b = positional[1];
  try {
    return run(options);
  } catch (const std::exception& e) {
    std::fprintf(stderr, "polygon_bench: %s\n", e.what());
    return 1;
  }
}
