/// \file capture_command.cpp
/// `dovetail capture FILE...`: replays failure-capture files written by
/// `run --capture DIR` (collision/capture.h) and says whether each suspect
/// outcome happens again.

#include <algorithm>
#include <cstdio>
#include <filesystem>
#include <string>
#include <vector>

#include "cli.h"
#include "commands.h"
#include "dovetail/collision/capture.h"

namespace dovetail::cli {

namespace {

constexpr const char* kCaptureHelp =
    R"(usage: dovetail capture FILE|DIR...

Replays failure-capture files written by 'dovetail run --capture DIR' (a
folder: its .capture files, in name order): reads
each query's inputs (two meshes and their relative pose, hexadecimal floats)
and runs it again: every polygon-level method and the convex level against
brute force for a disagreement, GJK and the separating-plane search for an
iteration cap, every method for a value that is not finite. Prints one line
per file: "reproduced" or "not reproduced" and what the replay saw.
Exits 0 when none reproduces, 3 when one does, 1 when a file cannot be read
(the others are replayed all the same).
)";

}  // namespace

int capture_command(std::span<const std::string> argv) {
  const Args args("capture", argv, {}, {});
  if (args.help()) {
    std::fputs(kCaptureHelp, stdout);
    return kExitOk;
  }
  if (args.positional().empty()) throw UsageError("capture: give one or more capture files");
  // A folder stands for its capture files, in name order.
  std::vector<std::string> files;
  bool empty_folder = false;
  for (const std::string& given : args.positional()) {
    std::error_code ec;
    if (!std::filesystem::is_directory(given, ec)) {
      files.push_back(given);
      continue;
    }
    std::vector<std::string> inside;
    for (const auto& entry : std::filesystem::directory_iterator(given, ec)) {
      if (entry.path().extension() == ".capture") inside.push_back(entry.path().string());
    }
    std::sort(inside.begin(), inside.end());
    if (inside.empty()) {
      std::fprintf(stderr, "dovetail: %s: no .capture files in this folder\n", given.c_str());
      empty_folder = true;
    }
    files.insert(files.end(), inside.begin(), inside.end());
  }
  int exit_code = kExitOk;
  bool unreadable = empty_folder;
  for (const std::string& file : files) {
    collision::Capture capture;
    try {
      capture = collision::read_capture(file);
    } catch (const collision::CaptureError& e) {
      // Said, and the other files replayed all the same.
      std::fflush(stdout);
      std::fprintf(stderr, "dovetail: %s\n", e.what());
      unreadable = true;
      continue;
    }
    const collision::CaptureReplay replay = collision::replay_capture(capture);
    std::printf("%s: %s %s: %s (%s)\n", file.c_str(),
                std::string(collision::capture_kind_name(capture.kind)).c_str(),
                replay.reproduced ? "reproduced" : "not reproduced", replay.what.c_str(),
                capture.context.c_str());
    if (replay.reproduced) exit_code = kExitCheckFailed;
  }
  // A file that cannot be read is an input error, whatever the others did.
  return unreadable ? kExitInputError : exit_code;
}

}  // namespace dovetail::cli
