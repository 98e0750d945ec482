#include <chrono>
#include <cmath>
#include <cstdio>
#include <memory>
#include <string>
#include <vector>

#include "cli.h"
#include "commands.h"
#include "dovetail/collision/pose_sampling.h"
#include "dovetail/collision/primitives.h"
#include "dovetail/engine/pose_list.h"
#include "pose_queries.h"

namespace dovetail::cli {

namespace {

constexpr const char* kHelp =
    R"(usage: dovetail bench [--directions N] [--seed S] [--threads N]

Checks every collision method against brute force: a peg (closed cylinder, radius 30 mm, 120 mm long)
against a ring (torus, 50 mm ring radius, 15 mm tube, so a 35 mm hole).
Contact-distance poses are generated with the boxtree method, then every
method answers the same poses and its verdicts are compared with brute force,
the exhaustive reference. Prints a table per method and a one-line JSON
summary; exits with 3 when any method disagrees with brute force.

  --directions N   contact-distance samples (default 100; 7 poses each)
  --seed S         random seed (default 1)
  --threads N      worker threads for the queries (default 1; 0 = all cores)
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

}  // namespace

int bench_command(std::span<const std::string> argv) {
  const Args args("bench", argv, {"directions", "seed", "threads"}, {});
  if (args.help()) {
    std::fputs(kHelp, stdout);
    return kExitOk;
  }
  args.expect_positional(0, "no arguments");
  collision::ContactPoseSettings settings;
  settings.directions = static_cast<int>(args.integer("directions", 1, 100000).value_or(100));
  settings.seed = args.unsigned_integer("seed").value_or(1);
  const int threads = static_cast<int>(args.integer("threads", 0, 1024).value_or(1));
  const bool terminal = stderr_is_terminal();

  auto ring = std::make_shared<const collision::Mesh>(
      collision::make_torus(kRingMajor, kRingMinor, kRingRings, kRingSides));
  auto peg = std::make_shared<const collision::Mesh>(
      collision::make_cylinder(kPegRadius, kPegLength, kPegSides));

  if (terminal) std::fputs("generating poses...", stderr);
  const auto start = std::chrono::steady_clock::now();
  const BuiltModel ring_boxtree = build_timed(collision::Method::kBoxtree, ring);
  const BuiltModel peg_boxtree = build_timed(collision::Method::kBoxtree, peg);
  std::vector<collision::Transform> poses;
  for (const collision::SampledPose& p :
       collision::contact_distance_poses(*ring_boxtree.model, *peg_boxtree.model, settings)) {
    poses.push_back(p.X_AB);
  }
  const double generate_ms = ms_since(start);
  if (terminal) std::fputs("\r                   \r", stderr);

  std::printf("built-in job: peg (cylinder, %zu triangles) against ring (torus, %zu triangles)\n",
              peg->triangle_count(), ring->triangle_count());
  std::printf("%zu contact-distance poses (%d directions, %zu gaps, seed %llu)\n\n", poses.size(),
              settings.directions, settings.gaps.size(),
              static_cast<unsigned long long>(settings.seed));

  // Brute force first: it is the reference every other method is held to.
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
    const BuiltModel a = build_timed(m, ring);
    const BuiltModel b = build_timed(m, peg);
    const PoseQueryResult result = run_pose_queries(*a.model, *b.model, poses, {}, threads);
    MethodOutcome outcome;
    outcome.method = m;
    outcome.build_ms = a.build_ms + b.build_ms;
    outcome.query_ms = result.wall_ms;
    outcome.colliding = result.colliding_count;
    const collision::ModelInfo info_a = a.model->info();
    const collision::ModelInfo info_b = b.model->info();
    outcome.bytes_per_triangle =
        static_cast<double>(info_a.bytes + info_b.bytes) /
        static_cast<double>(ring->triangle_count() + peg->triangle_count());
    if (m == collision::Method::kBrute) {
      reference = result.colliding;
    } else {
      for (std::size_t i = 0; i < poses.size(); ++i) {
        if (result.colliding[i] != reference[i]) {
          if (outcome.disagreements == 0) outcome.first_disagreement = i;
          ++outcome.disagreements;
        }
      }
    }
    outcomes.push_back(outcome);
  }
  if (terminal) std::fputs("\r                   \r", stderr);

  std::printf("%-8s %10s %10s %10s %10s  %s\n", "method", "build ms", "query ms", "colliding",
              "bytes/tri", "verdicts");
  bool all_agree = true;
  std::vector<std::string> method_items;
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
    all_agree = all_agree && o.disagreements == 0;
    JsonLine item;
    item.add("method", name)
        .add("build_ms", round_ms(o.build_ms))
        .add("query_ms", round_ms(o.query_ms))
        .add("colliding", o.colliding)
        .add("bytes_per_triangle", o.bytes_per_triangle)
        .add("disagreements", o.disagreements);
    method_items.push_back(item.str());
  }
  std::printf("\n");

  JsonLine json;
  json.add("job", "peg-in-ring")
      .add("triangles_a", std::uint64_t{ring->triangle_count()})
      .add("triangles_b", std::uint64_t{peg->triangle_count()})
      .add("poses", std::uint64_t{poses.size()})
      .add("seed", settings.seed)
      .add("generate_ms", round_ms(generate_ms))
      .add("threads", threads)
      .add("agree", all_agree)
      .add_raw("methods", json_array(method_items));
  std::fputs((json.str() + "\n").c_str(), stdout);

  if (!all_agree) {
    for (const MethodOutcome& o : outcomes) {
      if (o.disagreements == 0) continue;
      std::fprintf(stderr,
                   "dovetail: run: %s disagrees with brute force on %llu of %zu poses (first: "
                   "pose %zu: %s)\n",
                   std::string(collision::method_name(o.method)).c_str(),
                   static_cast<unsigned long long>(o.disagreements), poses.size(),
                   o.first_disagreement, engine::format_pose(poses[o.first_disagreement]).c_str());
    }
    return kExitCheckFailed;
  }
  return kExitOk;
}

}  // namespace dovetail::cli
