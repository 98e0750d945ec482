#include "dovetail/interaction/glove_trace.h"

#include <algorithm>
#include <array>
#include <cerrno>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <fstream>
#include <numbers>
#include <optional>
#include <vector>

#include "text_reading.h"

namespace dovetail::interaction {

namespace fs = std::filesystem;

namespace {

constexpr std::size_t kColumnCount = 8 + kJointCount;
constexpr std::size_t kFirstJointColumn = 8;

const std::array<std::string_view, kColumnCount>& column_names() {
  static const std::array<std::string_view, kColumnCount> names = [] {
    std::array<std::string_view, kColumnCount> all = {"t", "x", "y", "z", "qw", "qx", "qy", "qz"};
    for (std::size_t k = 0; k < kJointCount; ++k) {
      all[kFirstJointColumn + k] = joint_name(static_cast<Joint>(k));
    }
    return all;
  }();
  return names;
}

std::optional<std::size_t> column_index(std::string_view name) {
  const auto& names = column_names();
  for (std::size_t i = 0; i < names.size(); ++i) {
    if (names[i] == name) return i;
  }
  return std::nullopt;
}

/// For each field of the header, the canonical column it holds.
std::vector<std::size_t> parse_header(const LineReader& reader, std::string_view line) {
  std::vector<std::string_view> fields;
  split_commas(line, fields);
  for (std::size_t f = 0; f < fields.size(); ++f) {
    if (parse_number(fields[f])) {
      reader.fail("expected a header row naming the columns, found the number " +
                  quoted(fields[f]) + " in field " + std::to_string(f + 1));
    }
  }
  std::array<std::size_t, kColumnCount> field_of_column{};  // 1-based; 0 = not seen
  std::vector<std::size_t> column_of_field;
  for (std::size_t f = 0; f < fields.size(); ++f) {
    const std::optional<std::size_t> column = column_index(fields[f]);
    if (!column) {
      if (fields[f].empty()) reader.fail("field " + std::to_string(f + 1) + " names no column");
      // A header that is one field holding tabs or semicolons: another separator.
      const bool other_separator =
          fields.size() == 1 && fields[f].find_first_of("\t;") != std::string_view::npos;
      reader.fail("unknown column " + quoted(fields[f]) + " (field " + std::to_string(f + 1) + ")" +
                  (other_separator ? "; the fields of a trace are separated by commas" : ""));
    }
    if (field_of_column[*column] != 0) {
      reader.fail("duplicated column " + quoted(fields[f]) + " (fields " +
                  std::to_string(field_of_column[*column]) + " and " + std::to_string(f + 1) + ")");
    }
    field_of_column[*column] = f + 1;
    column_of_field.push_back(*column);
  }
  std::string missing;
  for (std::size_t c = 0; c < kColumnCount; ++c) {
    if (field_of_column[c] != 0) continue;
    if (!missing.empty()) missing += ", ";
    missing += column_names()[c];
  }
  if (!missing.empty()) reader.fail("missing columns: " + missing);
  return column_of_field;
}

GloveSample parse_row(const LineReader& reader, std::string_view line,
                      const std::vector<std::size_t>& column_of_field,
                      std::vector<std::string_view>& fields) {
  split_commas(line, fields);
  if (fields.size() != kColumnCount) {
    reader.fail_row("expected " + std::to_string(kColumnCount) + " fields, found " +
                    std::to_string(fields.size()));
  }
  std::array<Real, kColumnCount> values{};
  for (std::size_t f = 0; f < fields.size(); ++f) {
    const auto where = [&] {
      return "column " + std::string(column_names()[column_of_field[f]]) + " (field " +
             std::to_string(f + 1) + ")";
    };
    const std::optional<Real> value = parse_number(fields[f]);
    if (!value) {
      if (fields[f].empty()) reader.fail_row(where() + " is empty");
      reader.fail_row(where() + ": " + quoted(fields[f]) + " is not a number");
    }
    if (!std::isfinite(*value)) reader.fail(where() + ": " + quoted(fields[f]) + " is not finite");
    values[column_of_field[f]] = *value;
  }
  GloveSample sample;
  sample.t = values[0];
  sample.p_WH = Vec3(values[1], values[2], values[3]);
  sample.q_WH = {values[4], values[5], values[6], values[7]};
  for (std::size_t k = 0; k < kJointCount; ++k) sample.joints[k] = values[kFirstJointColumn + k];
  if (sample.q_WH.w == 0 && sample.q_WH.x == 0 && sample.q_WH.y == 0 && sample.q_WH.z == 0) {
    reader.fail("quaternion (qw qx qy qz) is zero");
  }
  return sample;
}

}  // namespace

std::span<const std::string_view> trace_columns() { return column_names(); }

std::vector<GloveSample> read_trace(std::istream& in, std::string_view name) {
  LineReader reader(in, name);
  const std::optional<std::string_view> header = reader.next_content();
  if (!header) throw TraceError(std::string(name) + ": empty, no header");
  const std::size_t header_line = reader.line();
  const std::vector<std::size_t> column_of_field = parse_header(reader, *header);

  std::vector<GloveSample> samples;
  std::vector<std::string_view> fields;
  std::size_t previous_line = 0;
  while (const std::optional<std::string_view> line = reader.next_content()) {
    GloveSample sample = parse_row(reader, *line, column_of_field, fields);
    if (!samples.empty() && !(sample.t > samples.back().t)) {
      // A device that sends a sample twice repeats its time: said so, since a
      // replay cannot choose between the two.
      reader.fail("time does not increase: t = " + format_number(sample.t) + " after t = " +
                  format_number(samples.back().t) + " on line " + std::to_string(previous_line) +
                  (sample.t == samples.back().t
                       ? " (a sample repeated, as devices send some twice: keep one of the two)"
                       : ""));
    }
    previous_line = reader.line();
    samples.push_back(sample);
  }
  if (samples.empty()) {
    throw TraceError(std::string(name) + ":" + std::to_string(header_line) +
                     ": header but no samples");
  }
  return samples;
}

TraceGaps trace_gaps(std::span<const GloveSample> samples) {
  TraceGaps g;
  if (samples.size() < 2) return g;
  std::vector<Real> gaps;
  for (std::size_t i = 1; i < samples.size(); ++i) {
    const Real gap = samples[i].t - samples[i - 1].t;
    gaps.push_back(gap);
    if (gap > g.widest) g.widest = gap, g.widest_after = samples[i - 1].t;
  }
  std::nth_element(gaps.begin(), gaps.begin() + static_cast<std::ptrdiff_t>(gaps.size() / 2),
                   gaps.end());
  g.median = gaps[gaps.size() / 2];
  return g;
}

std::optional<std::string> sparse_samples(std::span<const GloveSample> samples) {
  // Gloves sample 30 to 200 times a second; under 10 is another time unit,
  // unless the take would then last under a second: a trace keyed by hand
  // (a pose every second or so, the hand moving straight between them).
  if (samples.size() < 3) return std::nullopt;
  const Real median = trace_gaps(samples).median;
  constexpr Real kSparse = 0.1;  // seconds
  constexpr Real kShortestTake = 1000;  // "seconds": a second in milliseconds
  if (!(median > kSparse) || !(samples.back().t - samples.front().t >= kShortestTake)) {
    return std::nullopt;
  }
  char text[200];
  std::snprintf(text, sizeof text,
                "its samples are %.4g s apart (the median), %.3g samples a second, where gloves "
                "sample 30 to 200 times a second: are its times in milliseconds?",
                median, 1 / median);
  return std::string(text);
}

std::optional<std::string> radian_angles(std::span<const GloveSample> samples) {
  // A hand that moves at all bends some joint by tens of degrees; angles
  // in radians stay within pi. Under 0.2 everywhere is a still, flat hand.
  const GloveSample* widest = nullptr;
  std::size_t joint = 0;
  for (const GloveSample& g : samples) {
    for (std::size_t j = 0; j < kJointCount; ++j) {
      if (!widest || std::abs(g.joints[j]) > std::abs(widest->joints[joint]))
        widest = &g, joint = j;
    }
  }
  if (!widest) return std::nullopt;
  const Real largest = std::abs(widest->joints[joint]);
  if (largest < 0.2 || largest > std::numbers::pi + 0.01) return std::nullopt;
  char text[300];
  std::snprintf(text, sizeof text,
                "no joint angle is beyond +-%.3g over the whole take (the largest, %s, is %.4g "
                "at t=%.6g s), where a closing hand bends its joints by tens of degrees: are the "
                "angles in radians? Dovetail reads degrees",
                std::numbers::pi, std::string(joint_name(static_cast<Joint>(joint))).c_str(),
                widest->joints[joint], widest->t);
  return std::string(text);
}

std::optional<std::string> dropped_samples(std::span<const GloveSample> samples) {
  // A gap of many samples: the hand moves in a straight line across it.
  if (samples.size() < 3) return std::nullopt;
  const auto [median, widest, after] = trace_gaps(samples);
  constexpr Real kDropped = 5;  // times the median gap
  if (!(widest > kDropped * median)) return std::nullopt;
  char text[300];
  std::snprintf(text, sizeof text,
                "no sample for %.6g s after t=%.6g s, %.0f times the median gap of %.6g s: "
                "were samples dropped? The hand moves in a straight line across the gap",
                widest, after, widest / median, median);
  return std::string(text);
}

std::vector<std::string> trace_doubts(const fs::path& path, std::span<const GloveSample> samples) {
  std::vector<std::string> doubts;
  if (std::optional<std::string> sparse = sparse_samples(samples)) doubts.push_back(*sparse);
  if (std::optional<std::string> dropped = dropped_samples(samples)) doubts.push_back(*dropped);
  if (std::optional<std::string> radians = radian_angles(samples)) doubts.push_back(*radians);
  std::ifstream in(path, std::ios::binary | std::ios::ate);
  if (in && in.tellg() > 0) {
    in.seekg(-1, std::ios::end);
    const int last = in.get();
    if (last != '\n' && last != '\r') {
      doubts.emplace_back(
          "its last line has no line end: if the file was cut short while written, its last "
          "sample may be cut too (traces written by Dovetail end every line)");
    }
  }
  return doubts;
}

std::vector<GloveSample> read_trace(const fs::path& path) {
  std::ifstream in = open_for_reading(path);
  return read_trace(in, path.string());
}

std::string format_trace(std::span<const GloveSample> samples) {
  std::string text;
  // Up to 24 characters a number and a separator.
  text.reserve((samples.size() + 1) * kColumnCount * 25);
  for (std::size_t c = 0; c < kColumnCount; ++c) {
    text += column_names()[c];
    text += c + 1 < kColumnCount ? ',' : '\n';
  }
  for (const GloveSample& sample : samples) {
    for (Real value : {sample.t, sample.p_WH.x(), sample.p_WH.y(), sample.p_WH.z(), sample.q_WH.w,
                       sample.q_WH.x, sample.q_WH.y, sample.q_WH.z}) {
      append_number(text, value);
      text += ',';
    }
    for (std::size_t k = 0; k < kJointCount; ++k) {
      append_number(text, sample.joints[k]);
      text += k + 1 < kJointCount ? ',' : '\n';
    }
  }
  return text;
}

void write_trace(const fs::path& path, std::span<const GloveSample> samples) {
  const std::string text = format_trace(samples);
  const auto cannot_be_written = [&] {
    const std::string reason = errno != 0 ? std::strerror(errno) : "write failed";
    return TraceError(path.string() + ": cannot be written: " + reason);
  };
  errno = 0;
  std::ofstream out(path, std::ios::binary | std::ios::trunc);
  if (!out) throw cannot_be_written();
  out.write(text.data(), static_cast<std::streamsize>(text.size()));
  out.close();
  if (!out) throw cannot_be_written();
}

}  // namespace dovetail::interaction
