/// \file pipeline_command.cpp
/// `dovetail pipeline --scene FILE ...`: the whole collision pipeline (object
/// level, convex level, polygon level, on worker threads) on a scene from
/// files, frame by frame: which parts' meshes intersect.

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <map>
#include <memory>
#include <optional>
#include <span>
#include <string>
#include <vector>

#include "cli.h"
#include "commands.h"
#include "dovetail/collision/broadphase.h"
#include "dovetail/collision/collision_world.h"
#include "dovetail/collision/model.h"
#include "dovetail/collision/pose_sampling.h"
#include "dovetail/engine/mesh_import.h"
#include "line_reader.h"

namespace dovetail::cli {

namespace {

constexpr const char* kHelp =
    R"(usage: dovetail pipeline --scene FILE [--broadphase M] [--method M] [--threads N]
                         [--out PAIRS]

Runs the whole collision pipeline (object level, convex level, polygon level)
on a scene from files and reports, frame by frame, which parts' meshes
intersect (touching counts).

  --scene FILE    text: a first line `N F` (parts, frames); then N lines, each a
                  mesh path relative to FILE's folder; then F frames of N lines
                  `tx ty tz qw qx qy qz`, the pose of part i in the world (the
                  quaternion is normalized; blank lines and `#` lines skipped)
  --broadphase M  sap (default), grid, octree, mbp, brute
  --method M      polygon level: obb (default), boxtree, dop6, dop14, dop18,
                  dop26, aabb, brute
  --threads N     worker threads (default 1; 0 = one per core); the pairs do
                  not depend on it
  --out PAIRS     write the pairs there: per frame a line `frame K count C` (K
                  from 0), then the C intersecting pairs `i j`, i < j, sorted
                  (default: standard output, before the summary)

Prints a one-line JSON summary on standard output: parts, frames, build_ms
(the meshes' hulls and hierarchies), ms_per_frame_median (the frames after
the first, without reading the file or building) and pairs_total. A bad line
stops the run with an error naming file and line; the pairs of the frames
before it are still written.
)";

/// Pose `index` of frame `frame`: `tx ty tz qw qx qy qz`.
collision::Transform read_pose(LineReader& reader, std::uint64_t frame, std::uint64_t index,
                               std::uint64_t parts) {
  const std::optional<std::vector<std::string_view>> fields = reader.next();
  if (!fields) {
    reader.fail("file ends in frame " + std::to_string(frame) + " after " + std::to_string(index) +
                " of " + std::to_string(parts) + " poses");
  }
  if (fields->size() != 7) {
    reader.fail("expected 7 numbers `tx ty tz qw qx qy qz`, got " + fields_text(fields->size()));
  }
  double v[7];
  for (std::size_t k = 0; k < 7; ++k) v[k] = reader.number((*fields)[k]);
  // As pose lists have it (pose_list.h): coordinates within 1e30, any
  // quaternion but zero, scaled before it is normalised.
  for (std::size_t k = 0; k < 3; ++k) {
    if (!(std::abs(v[k]) <= 1e30)) reader.fail("a translation beyond the coordinate limit of 1e30");
  }
  double w = v[3], x = v[4], y = v[5], z = v[6];
  const double largest = std::max({std::abs(w), std::abs(x), std::abs(y), std::abs(z)});
  if (largest == 0) reader.fail("the quaternion is zero");
  if (const double squared = w * w + x * x + y * y + z * z;
      !std::isfinite(squared) || squared < 1e-150) {
    w /= largest;  // so that normalising neither overflows nor underflows
    x /= largest;
    y /= largest;
    z /= largest;
  }
  collision::Transform X;
  X.R = collision::rotation_from_quaternion(w, x, y, z);
  X.t = collision::Vec3(v[0], v[1], v[2]);
  return X;
}

/// The value of `option` parsed by `parse`, or `fallback` when absent; an
/// unknown name is a usage error listing `valid`.
template <typename Parse, typename T>
T named_option(const Args& args, const char* option, Parse parse, T fallback,
               const std::string& valid) {
  const std::optional<std::string> text = args.value(option);
  if (!text) return fallback;
  if (const std::optional<T> m = parse(*text)) return *m;
  throw UsageError("pipeline: unknown --" + std::string(option) + " '" + *text +
                   "'; valid: " + valid);
}

/// What a run of the scene measured, kept when an input error stops it.
struct PipelineRun {
  std::uint64_t parts = 0, frames = 0, frames_done = 0, pairs_total = 0;
  double build_ms = 0;
  std::vector<double> frame_ms;
};

/// Reads the N mesh paths (each file imported once, however many parts use
/// it) and adds one part per path to the world.
std::vector<collision::PartId> add_parts(LineReader& reader, const std::filesystem::path& folder,
                                         std::uint64_t parts, collision::CollisionWorld& world,
                                         const FramePairsOutput& output) {
  std::map<std::string, std::shared_ptr<const collision::Mesh>> meshes;
  std::vector<collision::PartId> ids;
  for (std::uint64_t i = 0; i < parts; ++i) {
    if (!reader.next()) {
      reader.fail("file ends after " + std::to_string(i) + " of " + std::to_string(parts) +
                  " mesh paths");
    }
    std::string name = reader.text();
    name.erase(0, name.find_first_not_of(" \t"));
    name.erase(name.find_last_not_of(" \t") + 1);
    std::shared_ptr<const collision::Mesh>& mesh = meshes[name];
    if (!mesh) {
      engine::ImportReport report;
      try {
        report = engine::import_file(folder / name);
      } catch (const std::exception& e) {
        reader.fail("mesh of part " + std::to_string(i) + ": " + e.what());
      }
      output.refuse(report.files);  // the pairs must not overwrite a mesh
      mesh = std::make_shared<const collision::Mesh>(std::move(report.parts.front().mesh));
    }
    ids.push_back(world.add_part({.mesh = mesh,
                                  .X_WP = collision::Transform{},
                                  .movable = true,
                                  .level = collision::LevelOfDetail::kExact,
                                  .name = std::to_string(i)}));
  }
  return ids;
}

/// Reads and steps every frame, writing its colliding pairs (i < j, sorted).
void run_frames(LineReader& reader, collision::CollisionWorld& world,
                const std::vector<collision::PartId>& ids, PipelineRun& run,
                FramePairsOutput& output) {
  std::vector<collision::Transform> poses;
  std::vector<std::pair<std::uint64_t, std::uint64_t>> pairs;
  for (std::uint64_t f = 0; f < run.frames; ++f) {
    poses.clear();
    for (std::uint64_t i = 0; i < run.parts; ++i) {
      poses.push_back(read_pose(reader, f, i, run.parts));
    }
    const auto start = std::chrono::steady_clock::now();
    for (std::size_t i = 0; i < ids.size(); ++i) world.set_pose(ids[i], poses[i]);
    const collision::StepResult& step = world.step();
    run.frame_ms.push_back(ms_since(start));
    pairs.clear();
    for (const collision::PartPair& p : step.colliding) {
      const std::uint64_t i = p.a.index, j = p.b.index;
      pairs.emplace_back(std::min(i, j), std::max(i, j));
    }
    std::sort(pairs.begin(), pairs.end());
    ++run.frames_done;
    run.pairs_total += pairs.size();
    output.frame(f, pairs.size());
    for (const auto& [i, j] : pairs) output.pair(i, j);
  }
}

/// Parses the scene and runs it; the first input error, if any.
std::optional<std::string> run_scene(const std::string& scene_path,
                                     collision::CollisionWorld& world, PipelineRun& run,
                                     FramePairsOutput& output) {
  LineReader reader(scene_path);
  try {
    const FrameCounts counts = read_frame_counts(reader, "part");
    run.parts = counts.items;
    run.frames = counts.frames;
    if (run.parts > 1'000'000) reader.fail("more than 1,000,000 parts");
    const std::vector<collision::PartId> ids = add_parts(
        reader, std::filesystem::path(scene_path).parent_path(), run.parts, world, output);
    const auto build_start = std::chrono::steady_clock::now();
    world.prepare();
    run.build_ms = ms_since(build_start);
    run_frames(reader, world, ids, run, output);
    expect_end(reader, counts);
  } catch (const LineError& e) {
    return e.message;
  }
  return std::nullopt;
}

}  // namespace

int pipeline_command(std::span<const std::string> argv) {
  const Args args("pipeline", argv, {"scene", "broadphase", "method", "threads", "out"}, {});
  if (args.help()) {
    std::fputs(kHelp, stdout);
    return kExitOk;
  }
  args.expect_positional(0, "no positional arguments");
  const std::string scene_path = args.required("scene");
  const collision::BroadphaseMethod broadphase =
      named_option(args, "broadphase", collision::parse_broadphase,
                   collision::BroadphaseMethod::kSweepAndPrune, broadphase_list());
  const collision::Method method =
      named_option(args, "method", collision::parse_method, collision::Method::kObb, method_list());
  const int threads = static_cast<int>(args.integer("threads", 0, 1024).value_or(1));

  const std::string inputs[] = {scene_path};
  FramePairsOutput output("pipeline", args.value("out"), inputs);
  collision::CollisionWorld world({.method = method,
                                   .broadphase = broadphase,
                                   .convex_level = true,
                                   .threads = threads,
                                   .contacts = collision::ContactDetail::kPairs,
                                   .capture = nullptr,
                                   .cross_check = std::nullopt});
  PipelineRun run;
  const std::optional<std::string> error = run_scene(scene_path, world, run, output);
  output.close(error.has_value());

  const std::vector<double> after_first(run.frame_ms.begin() + (run.frame_ms.empty() ? 0 : 1),
                                        run.frame_ms.end());
  JsonLine json;
  json.add("scene", scene_path)
      .add("broadphase", collision::broadphase_name(broadphase))
      .add("method", collision::method_name(method))
      .add("threads", threads)
      .add("parts", run.parts)
      .add("frames", run.frames_done)
      .add("build_ms", round_ms(run.build_ms))
      .add("ms_per_frame_median", round_ms(median(after_first)))
      .add("pairs_total", run.pairs_total);
  if (error) json.add("error", *error);
  std::fputs((json.str() + "\n").c_str(), stdout);

  if (error) throw InputError(*error);
  return kExitOk;
}

}  // namespace dovetail::cli
