#include <algorithm>
#include <charconv>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <memory>
#include <optional>
#include <span>
#include <string>
#include <string_view>
#include <vector>

#include "cli.h"
#include "commands.h"
#include "dovetail/collision/broadphase.h"
#include "line_reader.h"

namespace dovetail::cli {

namespace {

constexpr const char* kHelp =
    R"(usage: dovetail broadphase --boxes FILE [--method M] [--out PAIRS]

Finds, frame by frame, every pair of overlapping axis-aligned boxes.

  --boxes FILE   text: a first line `N F` (objects, frames), then F frames of N
                 lines `minx miny minz maxx maxy maxz`, box i of a frame on its
                 i-th line (blank lines and `#` lines are skipped)
  --method M     grid (default), sap, octree, mbp (multi-box pruning: best on
                 crowded scenes), brute
  --out PAIRS    write the pairs there: per frame a line `frame K count C`
                 (K from 0), then the C overlapping pairs `i j`, i < j, sorted
                 (default: standard output, before the summary)

Boxes are closed: boxes that only touch overlap. Prints a one-line JSON summary
on standard output (method, objects, frames, ms_per_frame_median over the
frames after the first, without reading the file, and pairs_total). A bad line
stops the run with an error naming file and line; the pairs of the frames
before it are still written.
)";

/// Limits of the box file.
constexpr std::uint64_t kMaxObjects = 0xffffffffu;

/// Reads box `index` of frame `frame`.
collision::Aabb read_box(LineReader& reader, std::uint64_t frame, std::uint64_t index,
                         std::uint64_t objects) {
  const std::optional<std::vector<std::string_view>> fields = reader.next();
  if (!fields) {
    reader.fail("file ends in frame " + std::to_string(frame) + " after " + std::to_string(index) +
                " of " + std::to_string(objects) + " boxes");
  }
  if (fields->size() != 6) {
    reader.fail("expected 6 numbers `minx miny minz maxx maxy maxz`, got " +
                fields_text(fields->size()));
  }
  collision::Aabb box;
  for (int k = 0; k < 3; ++k) {
    box.min[k] = reader.number((*fields)[static_cast<std::size_t>(k)]);
    box.max[k] = reader.number((*fields)[static_cast<std::size_t>(k) + 3]);
  }
  for (int k = 0; k < 3; ++k) {
    if (box.min[k] > box.max[k]) {
      reader.fail(std::string("min > max on axis ") + "xyz"[k]);
    }
  }
  return box;
}

/// What a run of the boxes file measured, kept when an input error stops it.
struct BoxesRun {
  std::uint64_t objects = 0, frames_done = 0, pairs_total = 0;
  std::vector<double> frame_ms;
};

/// Frame by frame: reads every box, then updates and queries the broad phase
/// and writes the pairs; the first input error, if any.
std::optional<std::string> run_boxes(LineReader& reader, collision::Broadphase& broadphase,
                                     BoxesRun& run, FramePairsOutput& output) {
  try {
    const FrameCounts counts = read_frame_counts(reader, "object");
    run.objects = counts.items;
    if (run.objects > kMaxObjects) reader.fail("more than 2^32 - 1 objects");
    std::vector<collision::Aabb> boxes;
    std::vector<collision::ProxyPair> pairs;
    for (std::uint64_t f = 0; f < counts.frames; ++f) {
      boxes.clear();
      for (std::uint64_t i = 0; i < run.objects; ++i) {
        boxes.push_back(read_box(reader, f, i, run.objects));
      }
      const auto start = std::chrono::steady_clock::now();
      for (std::size_t i = 0; i < boxes.size(); ++i) {
        const auto id = static_cast<collision::ProxyId>(i);
        if (f == 0) {
          broadphase.add(id, boxes[i]);
        } else {
          broadphase.move(id, boxes[i]);
        }
      }
      broadphase.pairs(pairs);
      run.frame_ms.push_back(ms_since(start));
      ++run.frames_done;
      run.pairs_total += pairs.size();
      output.frame(f, pairs.size());
      for (const collision::ProxyPair& p : pairs) output.pair(p.a, p.b);
    }
    expect_end(reader, counts);
  } catch (const LineError& e) {
    return e.message;
  }
  return std::nullopt;
}

}  // namespace

int broadphase_command(std::span<const std::string> argv) {
  const Args args("broadphase", argv, {"boxes", "method", "out"}, {});
  if (args.help()) {
    std::fputs(kHelp, stdout);
    return kExitOk;
  }
  args.expect_positional(0, "no positional arguments");
  const std::string boxes_path = args.required("boxes");
  collision::BroadphaseMethod method = collision::BroadphaseMethod::kGrid;
  if (const std::optional<std::string> name = args.value("method")) {
    const std::optional<collision::BroadphaseMethod> m = collision::parse_broadphase(*name);
    if (!m) {
      throw UsageError("broadphase: unknown method '" + *name +
                       "'; valid methods: " + broadphase_list());
    }
    method = *m;
  }
  const std::optional<std::string> out_path = args.value("out");

  const std::string inputs[] = {boxes_path};
  FramePairsOutput output("broadphase", out_path, inputs);

  LineReader reader(boxes_path);
  const std::unique_ptr<collision::Broadphase> broadphase = collision::make_broadphase(method);
  BoxesRun run;
  const std::optional<std::string> error = run_boxes(reader, *broadphase, run, output);
  output.close(error.has_value());

  const std::vector<double>& ms = run.frame_ms;
  const std::vector<double> after_first(ms.begin() + (ms.empty() ? 0 : 1), ms.end());
  JsonLine json;
  json.add("method", collision::broadphase_name(method))
      .add("boxes", boxes_path)
      .add("objects", run.objects)
      .add("frames", run.frames_done)
      .add("ms_per_frame_median", round_ms(median(after_first)))
      .add("ms_first_frame", ms.empty() ? std::nan("") : round_ms(ms.front()))
      .add("pairs_total", run.pairs_total);
  if (error) json.add("error", *error);
  std::fputs((json.str() + "\n").c_str(), stdout);

  if (error) throw InputError(*error);
  return kExitOk;
}

}  // namespace dovetail::cli
