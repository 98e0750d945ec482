// Speed against accuracy: every approximate level of the collision pipeline
// against the exact answer, on one contact-distance pose list (Trenkel,
// Weller, Zachmann), in one run, with the installed peers alongside (FCL's
// OBBRSS and Bullet's GImpact exact, libccd's GJK on the hulls);
// `dovetail bench --protocol poses` runs the same without the peers.
//
//   accuracy_bench [A B] [--directions N] [--runs R] [--seed S] [--table FILE]
//
// Without meshes it uses a generated sphere and torus. Settings:
//   METHOD                every polygon-level hierarchy, exact (the first,
//                         the Boxtree, gives the exact answer the others are
//                         held to; every exact method agrees with brute force,
//                         tests/collision/hierarchy_test.cpp)
//   METHOD volume         the root volumes alone (aabb: the bounding box; obb:
//                         the oriented box; dopK: each k-DOP), that is a
//                         hierarchy cut at depth 0
//   METHOD depth D        time-critical detection: the hierarchy cut D levels
//                         below the roots (CollideRequest::max_depth)
//   hull                  the convex hulls alone (GJK, intersecting or not)
//   plane cap N           the separating-plane search stopped after N
//                         iterations; giving up counts as colliding
// Per setting: the median over runs of the mean query time, overall and per
// gap, false positives and false negatives against the exact answer (in % of
// all poses), and the time relative to the fastest exact method. With
// --table, the same as a whitespace-separated table for the charts
// (scripts/charts.sh). Exit 1 when one of Dovetail's exact methods is wrong.

#include <cstdio>
#include <cstdlib>
#include <string>
#include <vector>

#include "bench_util.h"
#include "harness.h"
#include "mesh_pair.h"
#include "peers.h"

namespace {

using namespace dovetail;

struct Options {
  std::string mesh_a, mesh_b;
  int directions = 100;
  int runs = 5;
  std::uint64_t seed = 1;
  std::string table;
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
  collision::ContactPoseSettings pose_settings;
  pose_settings.directions = options.directions;
  pose_settings.seed = options.seed;
  const std::vector<collision::SampledPose> poses =
      bench::contact_poses(pair.a, pair.b, pose_settings);
  std::vector<bench::Contender> contenders = bench::contact_pose_contenders(pair.a, pair.b);
  for (bench::Contender& peer : bench::peer_contenders(pair.a, pair.b, true)) {
    contenders.push_back(std::move(peer));
  }
  std::printf("poses: %zu (%d directions x %zu gaps)\n", poses.size(), options.directions,
              pose_settings.gaps.size());
  const bench::PoseResult result =
      bench::run_contact_poses(contenders, poses, pose_settings.gaps, options.runs);
  bench::print_contact_poses(stdout, contenders, result);
  if (!bench::missing_peers().empty()) {
    std::printf("peers not installed: %s\n", bench::missing_peers().c_str());
  }
  if (!options.table.empty() &&
      !bench::write_contact_pose_table(options.table, contenders, result)) {
    std::fprintf(stderr, "accuracy_bench: %s cannot be written\n", options.table.c_str());
    return 1;
  }
  const std::string wrong = bench::exact_contenders_wrong(contenders, result);
  if (!wrong.empty()) {
    std::fprintf(stderr, "accuracy_bench: exact methods differ from the exact answer: %s\n",
                 wrong.c_str());
    return 1;
  }
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
