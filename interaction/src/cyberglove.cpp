#include "dovetail/interaction/cyberglove.h"

#include <cmath>
#include <fstream>
#include <optional>
#include <string>

#include "text_reading.h"

namespace dovetail::interaction {

namespace fs = std::filesystem;

namespace {

constexpr std::size_t kSensorCount = 22;
constexpr std::size_t kRawFields = 1 + kSensorCount;
constexpr std::size_t kRawFieldsWithTracker = kRawFields + 7;
constexpr Real kMaxCount = 255;

/// The fields of `line`, separated by a comma (with blanks around it or not)
/// or by blanks; two commas in a row leave an empty field.
void split_fields(std::string_view line, std::vector<std::string_view>& fields) {
  fields.clear();
  const auto blank = [](char c) { return c == ' ' || c == '\t'; };
  std::size_t i = 0;
  const auto skip_blanks = [&] {
    while (i < line.size() && blank(line[i])) ++i;
  };
  skip_blanks();
  while (i < line.size()) {
    const std::size_t start = i;
    while (i < line.size() && !blank(line[i]) && line[i] != ',') ++i;
    fields.push_back(line.substr(start, i - start));
    skip_blanks();
    if (i < line.size() && line[i] == ',') {
      ++i;
      skip_blanks();
      if (i == line.size()) fields.push_back({});
    }
  }
}

/// Field `f` (0-based) as a finite number; `what` names it in messages.
Real finite_field(const LineReader& reader, std::string_view token, std::size_t f,
                  std::string_view what) {
  const auto where = [&] { return std::string(what) + " (field " + std::to_string(f + 1) + ")"; };
  const std::optional<Real> value = parse_number(token);
  if (!value) {
    if (token.empty()) reader.fail_row(where() + " is empty");
    reader.fail_row(where() + ": " + quoted(token) + " is not a number");
  }
  if (!std::isfinite(*value)) reader.fail(where() + ": " + quoted(token) + " is not finite");
  return *value;
}

std::string sensor(std::size_t i) { return "native sensor " + std::to_string(i); }

GloveSample parse_raw_row(const LineReader& reader, const std::vector<std::string_view>& fields,
                          const CyberGloveCalibration& calibration) {
  GloveSample sample;
  sample.t = finite_field(reader, fields[0], 0, "time");
  std::array<Real, kSensorCount> raw{};
  for (std::size_t i = 0; i < kSensorCount; ++i) {
    const std::size_t f = 1 + i;
    raw[i] = finite_field(reader, fields[f], f, sensor(i));
    if (!(raw[i] >= 0 && raw[i] <= kMaxCount)) {
      reader.fail(sensor(i) + " (field " + std::to_string(f + 1) + "): count " + quoted(fields[f]) +
                  " is outside [0, 255]");
    }
  }
  sample.joints = calibrate(calibration, raw);
  for (std::size_t k = 0; k < kJointCount; ++k) {
    if (!std::isfinite(sample.joints[k])) {
      reader.fail("the calibrated angle of " + std::string(joint_name(static_cast<Joint>(k))) +
                  " (native sensor " + std::to_string(kNativeOfJoint[k]) + ") is not finite");
    }
  }
  if (fields.size() == kRawFieldsWithTracker) {
    constexpr std::array<std::string_view, 7> kTracker = {"x", "y", "z", "qw", "qx", "qy", "qz"};
    std::array<Real, 7> v{};
    for (std::size_t c = 0; c < v.size(); ++c) {
      const std::size_t f = kRawFields + c;
      v[c] = finite_field(reader, fields[f], f, "tracker " + std::string(kTracker[c]));
    }
    sample.p_WH = Vec3(v[0], v[1], v[2]);
    sample.q_WH = {v[3], v[4], v[5], v[6]};
    if (v[3] == 0 && v[4] == 0 && v[5] == 0 && v[6] == 0) {
      reader.fail("quaternion (qw qx qy qz) is zero");
    }
  }
  return sample;
}

}  // namespace

CyberGloveCalibration read_calibration(std::istream& in, std::string_view name) {
  LineReader reader(in, name);
  CyberGloveCalibration calibration;
  std::vector<std::string_view> fields;
  std::size_t rows = 0;
  while (const std::optional<std::string_view> line = reader.next_content()) {
    if (rows == kSensorCount) {
      reader.fail("more than 22 calibration rows (one per native sensor)");
    }
    split_fields(*line, fields);
    if (fields.size() != 2 && fields.size() != kSensorCount + 1) {
      reader.fail("expected 2 numbers (GAIN OFFSET) or 23 (a row of A, then b) for " +
                  sensor(rows) + ", found " + std::to_string(fields.size()));
    }
    const std::size_t i = rows;
    const auto number = [&](std::size_t f) {
      return finite_field(reader, fields[f], f, "calibration of " + sensor(i));
    };
    if (fields.size() == 2) {
      calibration.A(i, i) = number(0);
      calibration.b(i) = number(1);
    } else {
      for (std::size_t j = 0; j < kSensorCount; ++j) calibration.A(i, j) = number(j);
      calibration.b(i) = number(kSensorCount);
    }
    ++rows;
  }
  if (rows == 0) {
    throw TraceError(std::string(name) + ": empty, expected 22 calibration rows");
  }
  if (rows < kSensorCount) {
    throw TraceError(std::string(name) + ":" + std::to_string(reader.line()) +
                     ": file ends after " + std::to_string(rows) +
                     " calibration rows, expected 22 (one per native sensor)");
  }
  return calibration;
}

CyberGloveCalibration read_calibration(const fs::path& path) {
  std::ifstream in = open_for_reading(path);
  return read_calibration(in, path.string());
}

JointAngles calibrate(const CyberGloveCalibration& calibration,
                      const std::array<Real, kJointCount>& raw_native) {
  std::array<Real, kSensorCount> native{};
  for (std::size_t i = 0; i < kSensorCount; ++i) {
    Real sum = 0;
    for (std::size_t j = 0; j < kSensorCount; ++j) sum += calibration.A(i, j) * raw_native[j];
    native[i] = sum + calibration.b(i);
  }
  JointAngles angles{};
  for (std::size_t k = 0; k < kJointCount; ++k) angles[k] = native[kNativeOfJoint[k]];
  return angles;
}

std::vector<GloveSample> read_cyberglove_raw(std::istream& in, std::string_view name,
                                             const CyberGloveCalibration& calibration) {
  LineReader reader(in, name);
  std::vector<GloveSample> samples;
  std::vector<std::string_view> fields;
  std::size_t first_line = 0;
  std::size_t first_field_count = 0;
  std::size_t previous_line = 0;
  while (const std::optional<std::string_view> line = reader.next_content()) {
    split_fields(*line, fields);
    if (fields.size() != kRawFields && fields.size() != kRawFieldsWithTracker) {
      reader.fail(
          "expected 23 fields (t and 22 counts) or 30 (then tracker x y z qw qx qy qz), "
          "found " +
          std::to_string(fields.size()));
    }
    if (samples.empty()) {
      first_line = reader.line();
      first_field_count = fields.size();
    } else if (fields.size() != first_field_count) {
      reader.fail_row("found " + std::to_string(fields.size()) +
                      " fields, but the first row (line " + std::to_string(first_line) + ") has " +
                      std::to_string(first_field_count));
    }
    GloveSample sample = parse_raw_row(reader, fields, calibration);
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
  if (samples.empty()) throw TraceError(std::string(name) + ": no samples");
  return samples;
}

std::vector<GloveSample> read_cyberglove_raw(const fs::path& path,
                                             const CyberGloveCalibration& calibration) {
  std::ifstream in = open_for_reading(path);
  return read_cyberglove_raw(in, path.string(), calibration);
}

}  // namespace dovetail::interaction
