#include "line_reader.h"

#include <cerrno>
#include <charconv>
#include <cmath>
#include <cstring>
#include <filesystem>

#include "cli.h"
#include "dovetail/engine/pose_list.h"

namespace dovetail::cli {

/// The field in quotes, a control byte (a NUL, say) written as \xNN so that
/// the message shows it and is not cut short by it.
std::string quote(std::string_view field) {
  std::string quoted = "'";
  quoted += engine::escape_control_bytes(field);
  quoted += '\'';
  return quoted;
}

std::string fields_text(std::size_t n) {
  return std::to_string(n) + (n == 1 ? " field" : " fields");
}

LineReader::LineReader(const std::string& path) : path_(path) {
  namespace fs = std::filesystem;
  std::error_code ec;
  const fs::file_status status = fs::status(path, ec);
  if (!fs::exists(status)) throw InputError(path + ": file not found");
  if (fs::is_directory(status)) throw InputError(path + ": is a directory");
  in_.open(path, std::ios::binary);
  if (!in_) throw InputError(path + ": cannot be opened: " + std::strerror(errno));
}

std::optional<std::vector<std::string_view>> LineReader::next() {
  while (std::getline(in_, text_)) {
    ++line_;
    if (!text_.empty() && text_.back() == '\r') text_.pop_back();
    if (line_ == 1 && text_.starts_with("\xEF\xBB\xBF")) text_.erase(0, 3);  // a byte-order mark
    fields_.clear();
    std::size_t i = 0;
    while (i < text_.size()) {
      while (i < text_.size() && (text_[i] == ' ' || text_[i] == '\t')) ++i;
      const std::size_t start = i;
      while (i < text_.size() && text_[i] != ' ' && text_[i] != '\t') ++i;
      if (i > start) fields_.emplace_back(text_.data() + start, i - start);
    }
    if (fields_.empty() || fields_[0][0] == '#') continue;
    return fields_;
  }
  if (in_.bad()) fail("read error");
  ++line_;  // errors about missing data name the line after the last one
  return std::nullopt;
}

void LineReader::fail(const std::string& what) const {
  throw LineError{path_ + ":" + std::to_string(line_) + ": " + what};
}

std::uint64_t LineReader::count(std::string_view field, const char* what) const {
  std::uint64_t v = 0;
  const auto [ptr, ec] = std::from_chars(field.data(), field.data() + field.size(), v);
  if (ec != std::errc() || ptr != field.data() + field.size()) {
    fail(std::string(what) + " must be a non-negative integer, not " + quote(field));
  }
  return v;
}

double LineReader::number(std::string_view field) const {
  std::string_view digits = field;
  if (digits.size() > 1 && digits[0] == '+') digits.remove_prefix(1);
  double v = 0;
  const auto [ptr, ec] = std::from_chars(digits.data(), digits.data() + digits.size(), v);
  if (ec == std::errc::result_out_of_range) fail(quote(field) + " is out of range");
  if (ec != std::errc() || ptr != digits.data() + digits.size()) {
    fail(quote(field) + " is not a number");
  }
  if (!std::isfinite(v)) fail(quote(field) + " is not finite");
  return v;
}

FrameCounts read_frame_counts(LineReader& reader, const std::string& item) {
  const std::string expected = "a first line `N F` (" + item + "s, frames)";
  const std::optional<std::vector<std::string_view>> header = reader.next();
  if (!header) reader.fail("empty file, expected " + expected);
  if (header->size() != 2)
    reader.fail("expected " + expected + ", got " + fields_text(header->size()));
  const std::string n_name = "the " + item + " count N";
  FrameCounts counts;
  counts.items = reader.count((*header)[0], n_name.c_str());
  counts.frames = reader.count((*header)[1], "the frame count F");
  if (counts.items == 0 && counts.frames > 0) {
    reader.fail("no " + item + "s (N = 0) but F > 0 frames");
  }
  return counts;
}

void expect_end(LineReader& reader, const FrameCounts& counts) {
  if (reader.next()) {
    reader.fail("more data than the first line declares (N F = " + std::to_string(counts.items) +
                " " + std::to_string(counts.frames) + ")");
  }
}

FramePairsOutput::FramePairsOutput(const std::string& command,
                                   const std::optional<std::string>& path,
                                   std::span<const std::string> inputs)
    : command_(command), path_(path) {
  if (!path_) return;
  refuse(inputs);
  check_writable(*path_);
}

void FramePairsOutput::refuse(std::span<const std::string> inputs) const {
  if (path_) refuse_overwriting_input(command_, *path_, inputs);
}

void FramePairsOutput::frame(std::uint64_t k, std::size_t count) {
  if (text_.size() > (std::size_t{1} << 20)) flush();
  text_ += "frame " + std::to_string(k) + " count " + std::to_string(count) + "\n";
}

void FramePairsOutput::pair(std::uint64_t i, std::uint64_t j) {
  text_ += std::to_string(i);
  text_ += ' ';
  text_ += std::to_string(j);
  text_ += '\n';
}

void FramePairsOutput::flush() {
  if (path_) {
    if (!out_.is_open()) {
      out_.open(*path_, std::ios::binary | std::ios::trunc);
      if (!out_) throw InputError(*path_ + ": cannot be written: " + std::strerror(errno));
    }
    out_.write(text_.data(), static_cast<std::streamsize>(text_.size()));
  } else {
    std::fwrite(text_.data(), 1, text_.size(), stdout);
  }
  text_.clear();
}

void FramePairsOutput::close(bool failed) {
  if (failed && text_.empty() && !out_.is_open()) return;  // no frame yet
  flush();
  if (!path_) return;
  out_.close();
  if (!out_) throw InputError(*path_ + ": write failed: " + std::strerror(errno));
}

}  // namespace dovetail::cli
