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
  --method M     grid (default), sap, octree, brute
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
  std::unique_ptr<collision::Broadphase> broadphase = collision::make_broadphase(method);
  std::uint64_t objects = 0, frames = 0, frames_done = 0, pairs_total = 0;
  std::vector<double> frame_ms;
  std::optional<std::string> error;
  try {
    const FrameCounts counts = read_frame_counts(reader, "object");
    objects = counts.items;
    frames = counts.frames;
    if (objects > kMaxObjects) reader.fail("more than 2^32 - 1 objects");

    // Frame by frame: read every box, then update and query the broad phase.
    std::vector<collision::Aabb> boxes;
    std::vector<collision::ProxyPair> pairs;
    for (std::uint64_t f = 0; f < frames; ++f) {
      boxes.clear();
      for (std::uint64_t i = 0; i < objects; ++i) boxes.push_back(read_box(reader, f, i, objects));
      const auto start = std::chrono::steady_clock::now();
      for (std::size_t i = 0; i < boxes.size(); ++i) {
        const auto id = static_cast<collision::ProxyId>(i);
        if (f == 0) {
          broadphase->add(id, boxes[i]);
        } else {
          broadphase->move(id, boxes[i]);
        }
      }
      broadphase->pairs(pairs);
      frame_ms.push_back(ms_since(start));
      ++frames_done;
      pairs_total += pairs.size();
      output.frame(f, pairs.size());
      for (const collision::ProxyPair& p : pairs) output.pair(p.a, p.b);
    }
    expect_end(reader, counts);
  } catch (const LineError& e) {
    error = e.message;
  }
  output.close();

  const std::vector<double> after_first(frame_ms.begin() + (frame_ms.empty() ? 0 : 1),
                                        frame_ms.end());
  JsonLine json;
  json.add("method", collision::broadphase_name(method))
      .add("boxes", boxes_path)
      .add("objects", objects)
      .add("frames", frames_done)
      .add("ms_per_frame_median", round_ms(median(after_first)))
      .add("ms_first_frame", frame_ms.empty() ? std::nan("") : round_ms(frame_ms.front()))
      .add("pairs_total", pairs_total);
  if (error) json.add("error", *error);
  std::fputs((json.str() + "\n").c_str(), stdout);

  if (error) throw InputError(*error);
  return kExitOk;
}

}  // namespace dovetail::cli
