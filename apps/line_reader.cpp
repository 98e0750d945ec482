#include "line_reader.h"

#include <cerrno>
#include <charconv>
#include <cmath>
#include <cstring>
#include <filesystem>

#include "cli.h"

namespace dovetail::cli {

std::string quote(std::string_view field) {
  std::string s;
  s.reserve(field.size() + 2);
  s += '\'';
  s += field;
  s += '\'';
  return s;
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

}  // namespace dovetail::cli
