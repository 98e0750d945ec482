#pragma once
/// \file text_reading.h
/// Reading the line-based text files of the interaction layer (glove traces,
/// CyberGlove recordings and calibrations): bounded lines, exact numbers and
/// errors that name the file and the line.

#include <cstddef>
#include <filesystem>
#include <fstream>
#include <istream>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "dovetail/interaction/glove_sample.h"

namespace dovetail::interaction {

/// Hands out the lines of a stream one at a time. A line longer than
/// kMaxTraceLineBytes is refused once that many bytes have been read, so a
/// huge line is never held in memory.
class LineReader {
 public:
  /// `name` is the file name used in messages.
  LineReader(std::istream& in, std::string_view name);

  /// The next line without its "\n" or "\r\n", valid until the next call, or
  /// nullopt at the end; throws TraceError for a line that is too long or a
  /// read error.
  std::optional<std::string_view> next();
  /// The next line that is neither blank nor a `#` comment, or nullopt.
  std::optional<std::string_view> next_content();

  /// 1-based number of the line last returned; 0 before the first.
  std::size_t line() const { return line_; }
  const std::string& name() const { return name_; }
  /// Throws TraceError `name:line: what` for the line last returned.
  [[noreturn]] void fail(const std::string& what) const;
  /// fail() for a mistake a file cut short makes in its last row (too few
  /// fields, a number cut off): with a hint that it was cut short when that
  /// line is the file's last and has no line end.
  [[noreturn]] void fail_row(const std::string& what) const;

 private:
  std::istream& in_;
  std::string name_;
  std::vector<char> buffer_;
  std::size_t line_ = 0;
  bool unended_ = false;  ///< the line last returned ended the file without a line end
};

/// True for a line that holds only blanks or whose first non-blank is `#`.
bool is_blank_or_comment(std::string_view line);
/// `text` without leading and trailing spaces and tabs.
std::string_view trim_blanks(std::string_view text);
/// The comma-separated fields of `line` into `fields` (cleared first), each
/// without surrounding blanks.
void split_commas(std::string_view line, std::vector<std::string_view>& fields);

/// The whole token as a double (an optional leading '+' allowed, subnormals
/// kept, overflow giving infinity), or nullopt when it is not a number.
std::optional<Real> parse_number(std::string_view token);
/// `token` quoted for a message, cut short when long.
std::string quoted(std::string_view token);
/// The shortest text that reads back to the same bits (std::to_chars).
void append_number(std::string& out, Real value);
/// The shortest text that reads back to the same bits.
std::string format_number(Real value);

/// The file at `path` opened for binary reading; throws TraceError
/// `path: file not found`, `path: is a directory` or `path: cannot be opened: reason`.
std::ifstream open_for_reading(const std::filesystem::path& path);

}  // namespace dovetail::interaction
