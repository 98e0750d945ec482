#include <algorithm>
#include <cerrno>
#include <charconv>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <fstream>
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

  // Open the output first: an unwritable destination should fail before any work.
  std::ofstream out;
  if (out_path) {
    const std::string inputs[] = {boxes_path};
    refuse_overwriting_input("broadphase", *out_path, inputs);
    out.open(*out_path, std::ios::binary | std::ios::trunc);
    if (!out) throw InputError(*out_path + ": cannot be written: " + std::strerror(errno));
  }
  std::string text;
  const auto flush = [&] {
    if (out_path) {
      out.write(text.data(), static_cast<std::streamsize>(text.size()));
    } else {
      std::fwrite(text.data(), 1, text.size(), stdout);
    }
    text.clear();
  };

  LineReader reader(boxes_path);
  std::unique_ptr<collision::Broadphase> broadphase = collision::make_broadphase(method);
  std::uint64_t objects = 0, frames = 0, frames_done = 0, pairs_total = 0;
  std::vector<double> frame_ms;
  std::optional<std::string> error;
  try {
    // Header: `N F`.
    const std::optional<std::vector<std::string_view>> header = reader.next();
    if (!header) reader.fail("empty file, expected a first line `N F` (objects, frames)");
    if (header->size() != 2) {
      reader.fail("expected a first line `N F` (objects, frames), got " +
                  fields_text(header->size()));
    }
    objects = reader.count((*header)[0], "the object count N");
    frames = reader.count((*header)[1], "the frame count F");
    if (objects > kMaxObjects) reader.fail("more than 2^32 - 1 objects");
    // Frames of no boxes take no lines, so nothing in the file would bound F.
    if (objects == 0 && frames > 0) reader.fail("no objects (N = 0) but F > 0 frames");

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
      text += "frame " + std::to_string(f) + " count " + std::to_string(pairs.size()) + "\n";
      for (const collision::ProxyPair& p : pairs) {
        text += std::to_string(p.a);
        text += ' ';
        text += std::to_string(p.b);
        text += '\n';
      }
      if (text.size() > (std::size_t{1} << 20)) flush();
    }
    if (reader.next()) {
      reader.fail("more data than the first line declares (N F = " + std::to_string(objects) + " " +
                  std::to_string(frames) + ")");
    }
  } catch (const LineError& e) {
    error = e.message;
  }
  flush();
  if (out_path) {
    out.close();
    if (!out) throw InputError(*out_path + ": write failed: " + std::strerror(errno));
  }

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
