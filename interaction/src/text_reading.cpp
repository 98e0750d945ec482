#include "text_reading.h"

#include <cerrno>
#include <charconv>
#include <cstdlib>
#include <cstring>
#include <system_error>

#include "dovetail/engine/pose_list.h"
#include "dovetail/interaction/glove_trace.h"

namespace dovetail::interaction {

namespace fs = std::filesystem;

namespace {

bool is_blank(char c) { return c == ' ' || c == '\t'; }

}  // namespace

// Room for the longest line, a '\r' and the NUL that getline stores.
LineReader::LineReader(std::istream& in, std::string_view name)
    : in_(in), name_(name), buffer_(kMaxTraceLineBytes + 2) {}

std::optional<std::string_view> LineReader::next() {
  in_.getline(buffer_.data(), static_cast<std::streamsize>(buffer_.size()));
  const std::size_t extracted = static_cast<std::size_t>(in_.gcount());
  if (in_.bad() || (in_.fail() && extracted == 0 && !in_.eof())) {
    throw TraceError(name_ + ": read error after line " + std::to_string(line_));
  }
  if (in_.fail() && extracted == 0) {
    unended_ = false;  // past the end: no line of it is broken
    return std::nullopt;
  }
  ++line_;
  // failbit with characters extracted: the buffer filled before the line ended.
  if (in_.fail()) fail("line longer than " + std::to_string(kMaxTraceLineBytes) + " bytes");
  const bool ended_by_newline = !in_.eof();
  unended_ = !ended_by_newline;
  std::size_t length = ended_by_newline ? extracted - 1 : extracted;
  if (length > 0 && buffer_[length - 1] == '\r') --length;
  if (length > kMaxTraceLineBytes) {
    fail("line longer than " + std::to_string(kMaxTraceLineBytes) + " bytes");
  }
  std::string_view text(buffer_.data(), length);
  if (text.find('\r') != std::string_view::npos) {
    fail(
        "a carriage return within the line: lines end with \\n or \\r\\n, not a lone \\r "
        "(the line endings of old Mac files)");
  }
  // A UTF-8 byte-order mark, as some editors and spreadsheets write, is not text.
  if (line_ == 1 && text.starts_with("\xEF\xBB\xBF")) text.remove_prefix(3);
  return text;
}

std::optional<std::string_view> LineReader::next_content() {
  while (std::optional<std::string_view> text = next()) {
    if (!is_blank_or_comment(*text)) return text;
  }
  return std::nullopt;
}

void LineReader::fail(const std::string& what) const {
  throw TraceError(name_ + ":" + std::to_string(line_) + ": " + what);
}

void LineReader::fail_row(const std::string& what) const {
  // A broken last line without a line end: most likely a file cut short.
  if (!unended_) fail(what);
  fail(what +
       " (the file's last line has no line end: was the file cut short while it was written? "
       "Without that line the rest can be read)");
}

bool is_blank_or_comment(std::string_view line) {
  const std::string_view content = trim_blanks(line);
  return content.empty() || content.front() == '#';
}

std::string_view trim_blanks(std::string_view text) {
  while (!text.empty() && is_blank(text.front())) text.remove_prefix(1);
  while (!text.empty() && is_blank(text.back())) text.remove_suffix(1);
  return text;
}

void split_commas(std::string_view line, std::vector<std::string_view>& fields) {
  fields.clear();
  while (true) {
    const std::size_t comma = line.find(',');
    fields.push_back(trim_blanks(line.substr(0, comma)));
    if (comma == std::string_view::npos) return;
    line.remove_prefix(comma + 1);
  }
}

std::optional<Real> parse_number(std::string_view token) { return engine::parse_real(token); }

std::string quoted(std::string_view token) {
  std::string text = "'";
  text += engine::shown_token(token);
  text += '\'';
  return text;
}

void append_number(std::string& out, Real value) {
  char buffer[32];
  const auto [end, ec] = std::to_chars(buffer, buffer + sizeof buffer, value);
  out.append(buffer, end);
}

std::string format_number(Real value) {
  std::string text;
  append_number(text, value);
  return text;
}

std::ifstream open_for_reading(const fs::path& path) {
  std::error_code ec;
  const fs::file_status status = fs::status(path, ec);
  if (!fs::exists(status)) throw TraceError(path.string() + ": file not found");
  if (fs::is_directory(status)) throw TraceError(path.string() + ": is a directory");
  std::ifstream in(path, std::ios::binary);
  if (!in) throw TraceError(path.string() + ": cannot be opened: " + std::strerror(errno));
  return in;
}

}  // namespace dovetail::interaction
