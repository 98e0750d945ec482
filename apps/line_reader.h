#pragma once
/// \file line_reader.h
/// Line-based text inputs of the command line (box files, pipeline scenes):
/// blank and `#` lines skipped, fields split on blanks, and every error
/// naming the file and the line; and the per-frame pair lists written for
/// them.

#include <cstdint>
#include <fstream>
#include <optional>
#include <span>
#include <string>
#include <string_view>
#include <vector>

namespace dovetail::cli {

/// A bad line: the message starts with "FILE:LINE: ".
struct LineError {
  std::string message;
};

/// `field` in single quotes, for messages.
std::string quote(std::string_view field);
/// "1 field", "5 fields".
std::string fields_text(std::size_t n);

/// Reads a text file line by line, skipping blank and `#` lines.
class LineReader {
 public:
  /// Throws InputError when the file is missing, a directory or unreadable.
  explicit LineReader(const std::string& path);

  const std::string& path() const { return path_; }
  std::size_t line() const { return line_; }
  /// The next line that holds data, split into fields; nullopt at the end.
  std::optional<std::vector<std::string_view>> next();
  /// The text of the line next() returned last, without its line ending.
  const std::string& text() const { return text_; }

  [[noreturn]] void fail(const std::string& what) const;
  /// A non-negative whole number; `what` names it in the error.
  std::uint64_t count(std::string_view field, const char* what) const;
  /// A finite number.
  double number(std::string_view field) const;

 private:
  std::string path_;
  std::ifstream in_;
  std::string text_;
  std::vector<std::string_view> fields_;
  std::size_t line_ = 0;
};

/// The first line `N F` of a frame file: N items over F frames.
struct FrameCounts {
  std::uint64_t items = 0;
  std::uint64_t frames = 0;
};

/// Reads the first line `N F`; `item` names what N counts ("object", "part").
/// N = 0 with F > 0 is an error: frames of nothing take no lines, so nothing
/// in the file would bound F.
FrameCounts read_frame_counts(LineReader& reader, const std::string& item);

/// After the last frame: an error when any data follows.
void expect_end(LineReader& reader, const FrameCounts& counts);

/// Where `broadphase` and `pipeline` write their pairs: the file `path`, or
/// standard output when there is none. Per frame a line `frame K count C`,
/// then the C pairs `i j`, buffered.
class FramePairsOutput {
 public:
  /// Checks the file at once, so that an unwritable destination fails before
  /// any work, and refuses to overwrite one of `inputs` (usage error). An
  /// existing file is replaced only when the first frame is written.
  FramePairsOutput(const std::string& command, const std::optional<std::string>& path,
                   std::span<const std::string> inputs);
  /// Refuses, as the constructor does, inputs known only later (a scene's meshes).
  void refuse(std::span<const std::string> inputs) const;
  void frame(std::uint64_t k, std::size_t count);
  void pair(std::uint64_t i, std::uint64_t j);
  /// Writes what is buffered; throws InputError when writing the file failed.
  /// A run that `failed` before its first frame leaves an existing file as it was.
  void close(bool failed);

 private:
  void flush();
  std::string command_;
  std::optional<std::string> path_;
  std::ofstream out_;
  std::string text_;
};

}  // namespace dovetail::cli
