#include <cerrno>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <fstream>
#include <optional>
#include <string>
#include <vector>

#include "cli.h"
#include "commands.h"
#include "dovetail/engine/pose_list.h"
#include "pose_queries.h"

namespace dovetail::cli {

namespace {

constexpr const char* kHelp =
    R"(usage: dovetail query A B --poses FILE [--method M] [--out FLAGS] [--all-pairs] [--threads N]

Tests mesh B against mesh A at every pose of a pose list.

  A, B           mesh files (any format assimp reads), each merged into one mesh
  --poses FILE   pose list: one pose of B in A's frame per line, `tx ty tz qw qx qy qz`
                 (extra columns ignored, `#` lines and blank lines skipped)
  --method M     boxtree (default), dop6, dop14, dop18, dop26, aabb, obb, brute
  --out FLAGS    write the verdicts there, one line per pose: 1 colliding, 0 not
                 (default: standard output, before the summary)
  --all-pairs    find every intersecting triangle pair, not just the first
                 (the verdicts are the same; the summary adds pairs_total)
  --threads N    worker threads for the queries (default 1; 0 = all cores)

Prints a one-line JSON summary on standard output. A bad pose line stops the
run with an error naming file and line; the verdicts of the poses before it
are still written.
)";

double round_ms(double ms) { return std::round(ms * 1000.0) / 1000.0; }

void print_notes(const std::string& path, const LoadedMesh& loaded) {
  for (const std::string& note : loaded.report.notes) {
    std::fprintf(stderr, "dovetail: note: %s: %s\n", path.c_str(), note.c_str());
  }
  if (loaded.validation.degenerate_removed > 0) {
    std::fprintf(stderr, "dovetail: note: %s: removed %zu degenerate triangles\n", path.c_str(),
                 loaded.validation.degenerate_removed);
  }
}

}  // namespace

int query_command(std::span<const std::string> argv) {
  const Args args("query", argv, {"poses", "method", "out", "threads"}, {"all-pairs"});
  if (args.help()) {
    std::fputs(kHelp, stdout);
    return kExitOk;
  }
  args.expect_positional(2, "two mesh files A and B");
  const std::string poses_path = args.required("poses");
  const collision::Method method = args.method(collision::Method::kBoxtree);
  const int threads = static_cast<int>(args.integer("threads", 0, 1024).value_or(1));
  const std::optional<std::string> out_path = args.value("out");
  collision::CollideRequest request;
  request.all_pairs = args.flag("all-pairs");

  // Open the output first: an unwritable destination should fail before any work.
  std::ofstream out;
  if (out_path) {
    const std::string inputs[] = {args.positional()[0], args.positional()[1], poses_path};
    refuse_overwriting_input("query", *out_path, inputs);
    out.open(*out_path, std::ios::binary | std::ios::trunc);
    if (!out) throw InputError(*out_path + ": cannot be written: " + std::strerror(errno));
  }

  std::optional<engine::PoseListReader> reader;
  try {
    reader.emplace(poses_path);
  } catch (const engine::PoseListError& e) {
    throw InputError(e.what());
  }

  const std::string& path_a = args.positional()[0];
  const std::string& path_b = args.positional()[1];
  const LoadedMesh a = load_mesh(path_a);
  const LoadedMesh b = load_mesh(path_b);
  print_notes(path_a, a);
  print_notes(path_b, b);

  // Every good pose up to the first bad line; the error is reported after the
  // verdicts of those poses are written.
  std::vector<collision::Transform> poses;
  std::optional<std::string> pose_error;
  try {
    while (std::optional<engine::PoseEntry> pose = reader->next()) poses.push_back(pose->X_AB);
  } catch (const engine::PoseListError& e) {
    pose_error = e.what();
  }

  const BuiltModel model_a = build_timed(method, a.mesh);
  const BuiltModel model_b = build_timed(method, b.mesh);
  const PoseQueryResult result =
      run_pose_queries(*model_a.model, *model_b.model, poses, request, threads);

  std::string flags;
  flags.reserve(2 * poses.size());
  for (std::uint8_t c : result.colliding) flags += c != 0 ? "1\n" : "0\n";
  if (out_path) {
    out.write(flags.data(), static_cast<std::streamsize>(flags.size()));
    out.close();
    if (!out) throw InputError(*out_path + ": write failed: " + std::strerror(errno));
  } else {
    std::fwrite(flags.data(), 1, flags.size(), stdout);
  }

  const collision::ModelInfo info_a = model_a.model->info();
  const collision::ModelInfo info_b = model_b.model->info();
  JsonLine json;
  json.add("method", collision::method_name(method))
      .add("a", path_a)
      .add("b", path_b)
      .add("triangles_a", std::uint64_t{a.mesh->triangle_count()})
      .add("triangles_b", std::uint64_t{b.mesh->triangle_count()})
      .add("build_ms", round_ms(model_a.build_ms + model_b.build_ms))
      .add("build_ms_a", round_ms(model_a.build_ms))
      .add("build_ms_b", round_ms(model_b.build_ms))
      .add("queries", std::uint64_t{poses.size()})
      .add("query_ms_total", round_ms(result.wall_ms))
      .add("colliding", result.colliding_count)
      .add("model_bytes", std::uint64_t{info_a.bytes + info_b.bytes})
      .add("model_bytes_a", std::uint64_t{info_a.bytes})
      .add("model_bytes_b", std::uint64_t{info_b.bytes})
      .add("volume_tests", result.stats.volume_tests)
      .add("triangle_tests", result.stats.triangle_tests)
      .add("threads", threads);
  if (request.all_pairs) json.add("pairs_total", result.pairs_total);
  if (pose_error) json.add("error", *pose_error);
  std::fputs((json.str() + "\n").c_str(), stdout);

  if (pose_error) throw InputError(*pose_error);
  return kExitOk;
}

}  // namespace dovetail::cli
