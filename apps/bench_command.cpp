#include <chrono>
#include <cmath>
#include <cstdio>
#include <functional>
#include <initializer_list>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "cli.h"
#include "commands.h"
#include "dovetail/collision/pose_sampling.h"
#include "dovetail/collision/primitives.h"
#include "dovetail/engine/pose_list.h"
#include "harness.h"
#include "pose_queries.h"

namespace dovetail::cli {

namespace {

constexpr const char* kHelp =
    R"(usage: dovetail bench [--directions N] [--seed S] [--threads N]
       dovetail bench --protocol tumble [A [B]] [--turns N] [--distances D0:D1:STEP] [--table FILE]
       dovetail bench --protocol poses [A [B]] [--directions N] [--seed S] [--gaps LIST]
                      [--runs R] [--table FILE]

Without --protocol: checks every collision method against brute force on a
peg (closed cylinder, radius 30 mm, 120 mm long) against a ring (torus, 50 mm
ring radius, 15 mm tube, so a 35 mm hole). Contact-distance poses are
generated with the boxtree method, then every method answers the same poses
and its verdicts are compared with brute force, the exhaustive reference.
Prints a table per method and a one-line JSON summary; exits with 3 when any
method disagrees with brute force.

  --directions N   contact-distance samples (default 100; 7 poses each)
  --seed S         random seed (default 1)
  --threads N      worker threads for the queries (default 1; 0 = all cores)

With --protocol, a speed benchmark of one pair of meshes A and B (one file:
the mesh against itself; none: the peg and the ring), every hierarchy of the
polygon level and the convex level on the same poses, queries on one thread:

  tumble   Zachmann's protocol: both meshes scaled into [-1, 1]^3; at each
           distance of their centres B turns through a full rotation. Per
           method the mean and maximum µs per query, colliding and free apart,
           and the volume and triangle tests.
    --turns N              rotation steps per distance (default 360)
    --distances D0:D1:STEP the centre distances (default 0:3:0.1)
  poses    Trenkel, Weller and Zachmann's contact-distance poses, as `poses`
           makes them; every exact hierarchy and every approximate setting
           (root volumes, hierarchies cut at a depth, hulls, the
           separating-plane search capped): µs per query (median over runs),
           false positives and negatives against the exact answer, per gap.
    --directions N, --seed S, --gaps LIST  as for `poses` (default 100, 1, the 7 gaps)
    --runs R               timed runs (default 5)
  --table FILE   the table behind the chart (as bench/tumble_bench and
                 bench/accuracy_bench write it, which add the peers)

Exits with 3 when an exact hierarchy differs from the reference.
)";

constexpr double kRingMajor = 0.05;
constexpr double kRingMinor = 0.015;
constexpr int kRingRings = 64;
constexpr int kRingSides = 32;
constexpr double kPegRadius = 0.03;
constexpr double kPegLength = 0.12;
constexpr int kPegSides = 64;

struct MethodOutcome {
  collision::Method method;
  double build_ms = 0;
  double query_ms = 0;
  std::uint64_t colliding = 0;
  double bytes_per_triangle = 0;
  std::uint64_t disagreements = 0;
  std::size_t first_disagreement = 0;
};

struct PegAndRing {
  bench::MeshPtr ring, peg;
};

PegAndRing peg_and_ring() {
  return {std::make_shared<const collision::Mesh>(
              collision::make_torus(kRingMajor, kRingMinor, kRingRings, kRingSides)),
          std::make_shared<const collision::Mesh>(
              collision::make_cylinder(kPegRadius, kPegLength, kPegSides))};
}

/// UsageError when one of `options` is given: they belong to another mode.
void refuse_options(const Args& args, std::initializer_list<const char*> options,
                    std::string_view mode) {
  for (const char* option : options) {
    if (args.value(option)) {
      throw UsageError("--" + std::string(option) + " does not apply " + std::string(mode));
    }
  }
}

/// Every method (brute force first, the reference) on the poses.
std::vector<MethodOutcome> check_methods(const PegAndRing& job,
                                         const std::vector<collision::Transform>& poses,
                                         int threads, bool terminal) {
  std::vector<collision::Method> order{collision::Method::kBrute};
  for (collision::Method m : collision::all_methods()) {
    if (m != collision::Method::kBrute) order.push_back(m);
  }
  std::vector<std::uint8_t> reference;
  std::vector<MethodOutcome> outcomes;
  for (std::size_t k = 0; k < order.size(); ++k) {
    const collision::Method m = order[k];
    if (terminal) {
      std::fprintf(stderr, "\r[%zu/%zu] %-8s", k + 1, order.size(),
                   std::string(collision::method_name(m)).c_str());
    }
    const BuiltModel a = build_timed(m, job.ring);
    const BuiltModel b = build_timed(m, job.peg);
    const PoseQueryResult result = run_pose_queries(*a.model, *b.model, poses, {}, threads);
    MethodOutcome outcome{.method = m,
                          .build_ms = a.build_ms + b.build_ms,
                          .query_ms = result.wall_ms,
                          .colliding = result.colliding_count};
    outcome.bytes_per_triangle =
        static_cast<double>(a.model->info().bytes + b.model->info().bytes) /
        static_cast<double>(job.ring->triangle_count() + job.peg->triangle_count());
    if (m == collision::Method::kBrute) reference = result.colliding;
    for (std::size_t i = 0; i < poses.size() && m != collision::Method::kBrute; ++i) {
      if (result.colliding[i] == reference[i]) continue;
      if (outcome.disagreements == 0) outcome.first_disagreement = i;
      ++outcome.disagreements;
    }
    outcomes.push_back(outcome);
  }
  if (terminal) std::fputs("\r                   \r", stderr);
  return outcomes;
}

/// The table of the built-in check; the methods' JSON items.
std::vector<std::string> print_outcomes(const std::vector<MethodOutcome>& outcomes) {
  std::printf("%-8s %10s %10s %10s %10s  %s\n", "method", "build ms", "query ms", "colliding",
              "bytes/tri", "verdicts");
  std::vector<std::string> items;
  for (const MethodOutcome& o : outcomes) {
    const std::string name(collision::method_name(o.method));
    const std::string verdicts =
        o.method == collision::Method::kBrute
            ? std::string("reference")
            : (o.disagreements == 0 ? std::string("agree")
                                    : std::to_string(o.disagreements) + " differ");
    std::printf("%-8s %10.3f %10.3f %10llu %10.2f  %s\n", name.c_str(), o.build_ms, o.query_ms,
                static_cast<unsigned long long>(o.colliding), o.bytes_per_triangle,
                verdicts.c_str());
    JsonLine item;
    item.add("method", name)
        .add("build_ms", round_ms(o.build_ms))
        .add("query_ms", round_ms(o.query_ms))
        .add("colliding", o.colliding)
        .add("bytes_per_triangle", o.bytes_per_triangle)
        .add("disagreements", o.disagreements);
    items.push_back(item.str());
  }
  std::printf("\n");
  return items;
}

/// The built-in job: every method against brute force on the peg and the ring.
int builtin_check(const Args& args) {
  refuse_options(args, {"turns", "distances", "runs", "table", "gaps"}, "without --protocol");
  args.expect_positional(0, "no arguments");
  collision::ContactPoseSettings settings;
  settings.directions = static_cast<int>(args.integer("directions", 1, 100000).value_or(100));
  settings.seed = args.unsigned_integer("seed").value_or(1);
  const int threads = static_cast<int>(args.integer("threads", 0, 1024).value_or(1));
  const bool terminal = stderr_is_terminal();
  const PegAndRing job = peg_and_ring();

  if (terminal) std::fputs("generating poses...", stderr);
  const auto start = std::chrono::steady_clock::now();
  const BuiltModel ring_boxtree = build_timed(collision::Method::kBoxtree, job.ring);
  const BuiltModel peg_boxtree = build_timed(collision::Method::kBoxtree, job.peg);
  std::vector<collision::Transform> poses;
  for (const collision::SampledPose& p :
       collision::contact_distance_poses(*ring_boxtree.model, *peg_boxtree.model, settings)) {
    poses.push_back(p.X_AB);
  }
  const double generate_ms = ms_since(start);
  if (terminal) std::fputs("\r                   \r", stderr);
  std::printf("built-in job: peg (cylinder, %zu triangles) against ring (torus, %zu triangles)\n",
              job.peg->triangle_count(), job.ring->triangle_count());
  std::printf("%zu contact-distance poses (%d directions, %zu gaps, seed %llu)\n\n", poses.size(),
              settings.directions, settings.gaps.size(),
              static_cast<unsigned long long>(settings.seed));

  const std::vector<MethodOutcome> outcomes = check_methods(job, poses, threads, terminal);
  const std::vector<std::string> items = print_outcomes(outcomes);
  bool all_agree = true;
  for (const MethodOutcome& o : outcomes) all_agree = all_agree && o.disagreements == 0;
  JsonLine json;
  json.add("job", "peg-in-ring")
      .add("triangles_a", std::uint64_t{job.ring->triangle_count()})
      .add("triangles_b", std::uint64_t{job.peg->triangle_count()})
      .add("poses", std::uint64_t{poses.size()})
      .add("seed", settings.seed)
      .add("generate_ms", round_ms(generate_ms))
      .add("threads", threads)
      .add("agree", all_agree)
      .add_raw("methods", json_array(items));
  std::fputs((json.str() + "\n").c_str(), stdout);
  for (const MethodOutcome& o : outcomes) {
    if (o.disagreements == 0) continue;
    std::fprintf(stderr,
                 "dovetail: bench: %s disagrees with brute force on %llu of %zu poses (first: "
                 "pose %zu: %s)\n",
                 std::string(collision::method_name(o.method)).c_str(),
                 static_cast<unsigned long long>(o.disagreements), poses.size(),
                 o.first_disagreement, engine::format_pose(poses[o.first_disagreement]).c_str());
  }
  return all_agree ? kExitOk : kExitCheckFailed;
}

/// The protocol's pair: the positional files (one: against itself), or the
/// peg and the ring; each passed through `prepare`.
struct ProtocolPair {
  bench::MeshPtr a, b;
};

ProtocolPair protocol_pair(const Args& args,
                           const std::function<collision::Mesh(collision::Mesh)>& prepare) {
  const std::vector<std::string>& files = args.positional();
  if (files.size() > 2) throw UsageError("at most two meshes, A and B");
  const auto prepared = [&prepare](const bench::MeshPtr& mesh) {
    return std::make_shared<const collision::Mesh>(prepare(*mesh));
  };
  ProtocolPair pair;
  if (files.empty()) {
    const PegAndRing job = peg_and_ring();
    pair = {prepared(job.ring), prepared(job.peg)};
  } else {
    // The table is not a file the meshes refer to either (a glTF buffer).
    const auto load = [&args](const std::string& file) {
      LoadedMesh loaded = load_mesh(file);
      if (const std::optional<std::string> table = args.value("table")) {
        refuse_overwriting_input("bench", *table, loaded.report.files);
      }
      return loaded.mesh;
    };
    pair.a = prepared(load(files[0]));
    pair.b = files.size() == 1 || files[1] == files[0] ? pair.a : prepared(load(files[1]));
  }
  std::printf("A: %s (%zu triangles)\nB: %s (%zu triangles)\n",
              files.empty() ? "ring (torus)" : files[0].c_str(), pair.a->triangle_count(),
              files.empty() ? "peg (cylinder)" : files.back().c_str(), pair.b->triangle_count());
  return pair;
}

/// Prints "[done/total] what" on a terminal.
bench::Progress terminal_progress(const char* what) {
  if (!stderr_is_terminal()) return {};
  return [what](std::size_t done, std::size_t total) {
    std::fprintf(stderr, "\r%s %zu/%zu", what, done, total);
    if (done == total) std::fputs("\r                                        \r", stderr);
  };
}

/// InputError when --table names a file that cannot be written, UsageError
/// when it names a mesh: checked before the protocol runs, so that no run is
/// lost to it, and without touching an existing file.
void check_table(const Args& args) {
  const std::optional<std::string> path = args.value("table");
  if (!path) return;
  refuse_overwriting_input("bench", *path, args.positional());
  check_writable(*path);
}

/// Writes the table when --table is given; InputError when it cannot be.
void write_table(const Args& args, const std::function<bool(const std::string&)>& write) {
  const std::optional<std::string> path = args.value("table");
  if (path && !write(*path)) throw InputError(*path + ": cannot be written");
}

int tumble_protocol(const Args& args) {
  refuse_options(args, {"directions", "seed", "gaps", "runs", "threads"}, "to --protocol tumble");
  collision::TumbleSettings settings;
  settings.turns = static_cast<int>(args.integer("turns", 1, 100000).value_or(360));
  if (const auto d = args.value("distances")) {
    char end = 0;
    if (std::sscanf(d->c_str(), "%lf:%lf:%lf%c", &settings.first_distance, &settings.last_distance,
                    &settings.distance_step, &end) != 3 ||
        !(settings.distance_step > 0) || !(settings.last_distance >= settings.first_distance) ||
        !std::isfinite(settings.distance_step) || !(std::abs(settings.first_distance) <= 1e30) ||
        !(std::abs(settings.last_distance) <= 1e30) ||
        (settings.last_distance - settings.first_distance) / settings.distance_step > 1e5) {
      throw UsageError(
          "--distances needs D0:D1:STEP with D0 <= D1 within 1e30, a finite STEP > 0 and at most "
          "100,000 distances, not '" +
          *d + "'");
    }
  }
  check_table(args);
  const ProtocolPair pair = protocol_pair(args, bench::normalized);
  const std::vector<bench::Contender> contenders = bench::tumble_contenders(pair.a, pair.b);
  const bench::TumbleResult result =
      bench::run_tumble(contenders, settings, terminal_progress("tumbling"));
  bench::print_tumble(stdout, contenders, result);

  std::vector<std::string> items;
  std::size_t disagreements = 0;
  for (std::size_t c = 0; c < contenders.size(); ++c) {
    const bench::TumbleCell all = bench::total(result.cells[c]);
    JsonLine item;
    item.add("method", contenders[c].name)
        .add("exact", contenders[c].exact)
        .add("colliding", all.colliding)
        .add("mean_us_colliding", all.colliding ? all.sum_us_colliding / all.colliding : 0.0)
        .add("mean_us_free", all.free ? all.sum_us_free / all.free : 0.0)
        .add("disagreements", std::uint64_t{result.disagreements[c]});
    items.push_back(item.str());
    disagreements += result.disagreements[c];
  }
  JsonLine json;
  json.add("protocol", "tumble")
      .add("distances", std::uint64_t{result.distances.size()})
      .add("turns", result.turns)
      .add("agree", disagreements == 0)
      .add_raw("methods", json_array(items));
  std::fputs((json.str() + "\n").c_str(), stdout);
  write_table(args, [&](const std::string& path) {
    return bench::write_tumble_table(path, contenders, result);
  });
  return disagreements == 0 ? kExitOk : kExitCheckFailed;
}

int poses_protocol(const Args& args) {
  refuse_options(args, {"turns", "distances", "threads"}, "to --protocol poses");
  collision::ContactPoseSettings settings;
  settings.directions = static_cast<int>(args.integer("directions", 1, 100000).value_or(100));
  settings.seed = args.unsigned_integer("seed").value_or(1);
  if (const auto gaps = contact_gaps(args)) settings.gaps.assign(gaps->begin(), gaps->end());
  const int runs = static_cast<int>(args.integer("runs", 1, 1000).value_or(5));
  check_table(args);
  const ProtocolPair pair = protocol_pair(args, [](collision::Mesh m) { return m; });
  const std::vector<collision::SampledPose> poses = bench::contact_poses(pair.a, pair.b, settings);
  const std::vector<bench::Contender> contenders = bench::contact_pose_contenders(pair.a, pair.b);
  const bench::PoseResult result =
      bench::run_contact_poses(contenders, poses, settings.gaps, runs, terminal_progress("timing"));
  bench::print_contact_poses(stdout, contenders, result);

  std::vector<std::string> items;
  for (std::size_t c = 0; c < contenders.size(); ++c) {
    const bench::PoseRow& row = result.rows[c];
    JsonLine item;
    item.add("setting", contenders[c].name)
        .add("family", contenders[c].family)
        .add("us_per_query", row.us_per_query)
        .add("x_best_exact", row.us_per_query / result.best_exact_us)
        .add("false_positives", std::uint64_t{row.false_positives})
        .add("false_negatives", std::uint64_t{row.false_negatives});
    items.push_back(item.str());
  }
  const std::string wrong = bench::exact_contenders_wrong(contenders, result);
  JsonLine json;
  json.add("protocol", "poses")
      .add("poses", std::uint64_t{result.poses})
      .add("colliding", std::uint64_t{result.colliding})
      .add("runs", runs)
      .add("best_exact_us", result.best_exact_us)
      .add("agree", wrong.empty())
      .add_raw("settings", json_array(items));
  std::fputs((json.str() + "\n").c_str(), stdout);
  write_table(args, [&](const std::string& path) {
    return bench::write_contact_pose_table(path, contenders, result);
  });
  if (!wrong.empty())
    std::fprintf(stderr, "dovetail: bench: exact methods differ: %s\n", wrong.c_str());
  return wrong.empty() ? kExitOk : kExitCheckFailed;
}

}  // namespace

int bench_command(std::span<const std::string> argv) {
  const Args args(
      "bench", argv,
      {"directions", "seed", "threads", "protocol", "turns", "distances", "gaps", "runs", "table"},
      {});
  if (args.help()) {
    std::fputs(kHelp, stdout);
    return kExitOk;
  }
  const std::optional<std::string> protocol = args.value("protocol");
  if (!protocol) return builtin_check(args);
  if (*protocol == "tumble") return tumble_protocol(args);
  if (*protocol == "poses") return poses_protocol(args);
  throw UsageError("--protocol must be tumble or poses, not '" + *protocol + "'");
}

}  // namespace dovetail::cli
