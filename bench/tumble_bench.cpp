// Zachmann's protocol for a pair of objects: both scaled into [-1, 1]^3; at
// each distance between their centres the moving one tumbles through a full
// rotation in small steps. Every polygon-level method, the convex level and
// the installed peers (FCL's OBBRSS, Bullet's GImpact, libccd's GJK on the
// hulls) on the same poses, in one run; `dovetail bench --protocol tumble`
// runs the same without the peers.
//
//   tumble_bench [A B] [--steps N] [--distances D0:D1:STEP] [--table FILE]
//
// Per method and distance: mean and maximum query time, separately for
// colliding and non-colliding queries, and the mean volume and triangle tests.
// The table (--table) has one line per method and distance for the charts
// (scripts/charts.sh). Exit 1 when one of Dovetail's exact methods differs
// from the reference (the peers' differences are printed, not failed).

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
  collision::TumbleSettings tumble;
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
      o.tumble.turns =
          static_cast<int>(dovetail::bench::whole("tumble_bench", "--steps", argv[++i], 1, 100000));
    } else if (arg == "--distances" && has_value) {
      collision::TumbleSettings& t = o.tumble;
      if (std::sscanf(argv[++i], "%lf:%lf:%lf", &t.first_distance, &t.last_distance,
                      &t.distance_step) != 3 ||
          !(t.distance_step > 0) || !(t.last_distance >= t.first_distance)) {
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

int run(const Options& options) {
  const bench::MeshPair pair = bench::mesh_pair(options.mesh_a, options.mesh_b, bench::normalized);
  std::vector<bench::Contender> contenders = bench::tumble_contenders(pair.a, pair.b);
  for (bench::Contender& peer : bench::peer_contenders(pair.a, pair.b, true)) {
    contenders.push_back(std::move(peer));
  }
  const bench::TumbleResult result = bench::run_tumble(contenders, options.tumble);
  std::printf("\n");
  bench::print_tumble(stdout, contenders, result);
  if (!bench::missing_peers().empty()) {
    std::printf("peers not installed: %s\n", bench::missing_peers().c_str());
  }
  if (!options.table.empty() && !bench::write_tumble_table(options.table, contenders, result)) {
    std::fprintf(stderr, "tumble_bench: %s cannot be written\n", options.table.c_str());
    return 1;
  }
  std::size_t own_disagreements = 0;
  for (std::size_t c = 0; c < contenders.size(); ++c) {
    if (contenders[c].family == "exact") own_disagreements += result.disagreements[c];
  }
  return own_disagreements == 0 ? 0 : 1;
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
