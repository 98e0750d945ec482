#pragma once
/// \file line_reader.h
/// Line-based text inputs of the command line (box files, pipeline scenes):
/// blank and `#` lines skipped, fields split on blanks, and every error
/// naming the file and the line.

#include <cstdint>
#include <fstream>
#include <optional>
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

}  // namespace dovetail::cli
