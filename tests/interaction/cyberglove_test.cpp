#include "dovetail/interaction/cyberglove.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <bit>
#include <charconv>
#include <cstdint>
#include <fstream>
#include <sstream>
#include <string>
#include <vector>

#include "../support/temp_dir.h"

namespace dovetail::interaction {
namespace {

namespace fs = std::filesystem;

constexpr std::size_t kSensors = 22;
using Raw = std::array<Real, kSensors>;

std::string number(Real value) {
  char buffer[32];
  return std::string(buffer, std::to_chars(buffer, buffer + sizeof buffer, value).ptr);
}

/// Distinct, inexact gains and offsets, one per native sensor.
Real gain(std::size_t i) { return 0.37 * static_cast<Real>(i + 1) - 0.011; }
Real offset(std::size_t i) { return -12.3 + 1.7 * static_cast<Real>(i); }

std::string diagonal_calibration_text() {
  std::string text = "# CyberGlove calibration: GAIN OFFSET per native sensor\n";
  for (std::size_t i = 0; i < kSensors; ++i) {
    text += number(gain(i)) + " " + number(offset(i)) + "\n";
  }
  return text;
}

Real matrix_entry(std::size_t i, std::size_t j) {
  return (i == j ? 0.5 : 0.0) + 0.013 * static_cast<Real>((i * 7 + j * 3) % 11) -
         0.021 * static_cast<Real>(j % 4);
}
Real matrix_offset(std::size_t i) { return 3.1 - 0.77 * static_cast<Real>(i); }

std::string matrix_calibration_text() {
  std::string text;
  for (std::size_t i = 0; i < kSensors; ++i) {
    for (std::size_t j = 0; j < kSensors; ++j) text += number(matrix_entry(i, j)) + " ";
    text += number(matrix_offset(i)) + "\n";
  }
  return text;
}

CyberGloveCalibration parse_calibration(const std::string& text) {
  std::istringstream in(text);
  return read_calibration(in, "glove.cal");
}

/// Known counts, different per sensor and per row.
Raw raw_counts(std::size_t row) {
  Raw raw{};
  for (std::size_t i = 0; i < kSensors; ++i) {
    raw[i] = static_cast<Real>((i * 37 + row * 101 + 11) % 256);
  }
  return raw;
}

std::string raw_row(Real t, const Raw& raw, const std::string& separator = ",") {
  std::string text = number(t);
  for (Real count : raw) text += separator + number(count);
  return text;
}

std::vector<GloveSample> parse_raw(const std::string& text,
                                   const CyberGloveCalibration& calibration) {
  std::istringstream in(text);
  return read_cyberglove_raw(in, "glove.raw", calibration);
}

template <typename Read>
std::string error_of(Read read) {
  try {
    read();
  } catch (const TraceError& e) {
    return e.what();
  }
  ADD_FAILURE() << "no TraceError";
  return {};
}

std::string raw_error(const std::string& text) {
  return error_of([&] { parse_raw(text, parse_calibration(diagonal_calibration_text())); });
}

std::string calibration_error(const std::string& text) {
  return error_of([&] { parse_calibration(text); });
}

void expect_message(const std::string& message, const std::string& prefix,
                    const std::string& part) {
  EXPECT_EQ(message.rfind(prefix, 0), 0u) << message << "\ndoes not start with: " << prefix;
  EXPECT_NE(message.find(part), std::string::npos) << message << "\nlacks: " << part;
}

bool same(Real a, Real b) {
  return std::bit_cast<std::uint64_t>(a) == std::bit_cast<std::uint64_t>(b);
}

TEST(CyberGlove, NativeOrderIsAPermutationMovingAbductionsAfterThePinky) {
  std::array<bool, kSensors> seen{};
  for (std::size_t n : kNativeOfJoint) {
    ASSERT_LT(n, kSensors);
    EXPECT_FALSE(seen[n]) << n;
    seen[n] = true;
  }
  const auto native_of = [](Joint joint) {
    return kNativeOfJoint[static_cast<std::size_t>(joint)];
  };
  EXPECT_EQ(native_of(Joint::kIndexDip), 6u);
  EXPECT_EQ(native_of(Joint::kMiddleDip), 9u);
  EXPECT_EQ(native_of(Joint::kIndexMiddleAbd), 10u);
  EXPECT_EQ(native_of(Joint::kMiddleMcp), 7u);
  EXPECT_EQ(native_of(Joint::kRingMcp), 11u);
  EXPECT_EQ(native_of(Joint::kMiddleRingAbd), 14u);
  EXPECT_EQ(native_of(Joint::kPinkyMcp), 15u);
  EXPECT_EQ(native_of(Joint::kRingPinkyAbd), 18u);
  EXPECT_EQ(native_of(Joint::kPalmArch), 19u);
  EXPECT_EQ(native_of(Joint::kWristYaw), 21u);
}

TEST(CyberGlove, ReadsDiagonalCalibration) {
  const CyberGloveCalibration c = parse_calibration(diagonal_calibration_text());
  for (std::size_t i = 0; i < kSensors; ++i) {
    for (std::size_t j = 0; j < kSensors; ++j) {
      EXPECT_TRUE(same(c.A(i, j), i == j ? gain(i) : 0.0)) << i << "," << j;
    }
    EXPECT_TRUE(same(c.b(i), offset(i))) << i;
  }
}

TEST(CyberGlove, ReadsFullMatrixCalibrationMixedWithGainOffsetRows) {
  std::string text = matrix_calibration_text();
  // Row 5 in the short form.
  std::vector<std::string> rows;
  std::istringstream lines(text);
  for (std::string line; std::getline(lines, line);) rows.push_back(line);
  rows[5] = "2.5, -7";
  text = "# mixed\n";
  for (const std::string& row : rows) text += row + "\r\n";
  const CyberGloveCalibration c = parse_calibration(text);
  for (std::size_t i = 0; i < kSensors; ++i) {
    for (std::size_t j = 0; j < kSensors; ++j) {
      const Real expected = i == 5 ? (j == 5 ? 2.5 : 0.0) : matrix_entry(i, j);
      EXPECT_TRUE(same(c.A(i, j), expected)) << i << "," << j;
    }
    EXPECT_TRUE(same(c.b(i), i == 5 ? -7.0 : matrix_offset(i))) << i;
  }
}

TEST(CyberGlove, DiagonalCalibrationReordersNativeSensors) {
  const CyberGloveCalibration c = parse_calibration(diagonal_calibration_text());
  std::string text = "# t, 22 counts in native order\n";
  for (std::size_t r = 0; r < 3; ++r)
    text += raw_row(0.01 * static_cast<Real>(r), raw_counts(r)) + "\n";
  const std::vector<GloveSample> samples = parse_raw(text, c);
  ASSERT_EQ(samples.size(), 3u);
  for (std::size_t r = 0; r < 3; ++r) {
    const Raw raw = raw_counts(r);
    const GloveSample& s = samples[r];
    EXPECT_TRUE(same(s.t, 0.01 * static_cast<Real>(r)));
    for (std::size_t k = 0; k < kJointCount; ++k) {
      const std::size_t n = kNativeOfJoint[k];
      EXPECT_TRUE(same(s.joints[k], gain(n) * raw[n] + offset(n)))
          << "row " << r << " joint " << joint_name(static_cast<Joint>(k));
    }
    // The three abductions, spelled out from the CyberGlove's native order.
    EXPECT_TRUE(same(at(s.joints, Joint::kIndexMiddleAbd), gain(10) * raw[10] + offset(10)));
    EXPECT_TRUE(same(at(s.joints, Joint::kMiddleRingAbd), gain(14) * raw[14] + offset(14)));
    EXPECT_TRUE(same(at(s.joints, Joint::kRingPinkyAbd), gain(18) * raw[18] + offset(18)));
    EXPECT_TRUE(same(at(s.joints, Joint::kRingMcp), gain(11) * raw[11] + offset(11)));
    EXPECT_TRUE(same(at(s.joints, Joint::kPinkyDip), gain(17) * raw[17] + offset(17)));
    EXPECT_TRUE(same(at(s.joints, Joint::kPalmArch), gain(19) * raw[19] + offset(19)));
    // No tracker columns: the hand at the origin, unrotated.
    EXPECT_TRUE(s.p_WH == Vec3::Zero());
    EXPECT_TRUE(same(s.q_WH.w, 1.0) && same(s.q_WH.x, 0.0) && same(s.q_WH.y, 0.0) &&
                same(s.q_WH.z, 0.0));
  }
}

TEST(CyberGlove, FullMatrixCalibrationMixesSensors) {
  const CyberGloveCalibration c = parse_calibration(matrix_calibration_text());
  const Raw raw = raw_counts(4);
  const std::vector<GloveSample> samples = parse_raw(raw_row(1.25, raw, " \t") + "\n", c);
  ASSERT_EQ(samples.size(), 1u);
  for (std::size_t k = 0; k < kJointCount; ++k) {
    const std::size_t n = kNativeOfJoint[k];
    Real expected = 0;
    for (std::size_t j = 0; j < kSensors; ++j) expected += matrix_entry(n, j) * raw[j];
    expected += matrix_offset(n);
    EXPECT_TRUE(same(samples[0].joints[k], expected)) << joint_name(static_cast<Joint>(k));
  }
  const JointAngles direct = calibrate(c, raw);
  for (std::size_t k = 0; k < kJointCount; ++k) EXPECT_TRUE(same(direct[k], samples[0].joints[k]));
}

TEST(CyberGlove, ReadsTrackerColumns) {
  const CyberGloveCalibration c = parse_calibration(diagonal_calibration_text());
  const std::string text = raw_row(0.5, raw_counts(0), ", ") +
                           ", 0.1, -0.2, 1.5, 0.5, 0.5, -0.5, 0.5\n" +
                           raw_row(0.75, raw_counts(1), " ") + " 0 0 0 0 0 0 2\n";
  const std::vector<GloveSample> samples = parse_raw(text, c);
  ASSERT_EQ(samples.size(), 2u);
  EXPECT_TRUE(same(samples[0].p_WH.x(), 0.1) && same(samples[0].p_WH.y(), -0.2) &&
              same(samples[0].p_WH.z(), 1.5));
  EXPECT_TRUE(same(samples[0].q_WH.w, 0.5) && same(samples[0].q_WH.x, 0.5) &&
              same(samples[0].q_WH.y, -0.5) && same(samples[0].q_WH.z, 0.5));
  EXPECT_TRUE(samples[1].p_WH == Vec3::Zero());
  EXPECT_TRUE(same(samples[1].q_WH.w, 0.0) && same(samples[1].q_WH.z, 2.0));
  EXPECT_TRUE(same(at(samples[1].joints, Joint::kIndexMiddleAbd),
                   gain(10) * raw_counts(1)[10] + offset(10)));
}

TEST(CyberGlove, ReadsFilesFromDisk) {
  test::TempDir dir("dovetail_cyberglove");
  std::ofstream(dir / "glove.cal", std::ios::binary) << diagonal_calibration_text();
  std::ofstream(dir / "glove.raw", std::ios::binary) << raw_row(0, raw_counts(0)) << "\n";
  const CyberGloveCalibration c = read_calibration(dir / "glove.cal");
  const std::vector<GloveSample> samples = read_cyberglove_raw(dir / "glove.raw", c);
  ASSERT_EQ(samples.size(), 1u);
  const std::string missing = (dir / "missing.raw").string();
  EXPECT_EQ(error_of([&] { read_cyberglove_raw(dir / "missing.raw", c); }),
            missing + ": file not found");
  EXPECT_EQ(error_of([&] { read_calibration(dir.path()); }),
            dir.path().string() + ": is a directory");
}

TEST(CyberGlove, RefusesCountAbove255) {
  Raw raw = raw_counts(0);
  raw[7] = 256;
  expect_message(raw_error(raw_row(0, raw_counts(1)) + "\n" + raw_row(1, raw) + "\n"),
                 "glove.raw:2: ", "native sensor 7 (field 9): count '256' is outside [0, 255]");
}

TEST(CyberGlove, RefusesNegativeCount) {
  Raw raw = raw_counts(0);
  raw[0] = -1;
  expect_message(raw_error("# header comment\n" + raw_row(0, raw) + "\n"),
                 "glove.raw:2: ", "native sensor 0 (field 2): count '-1' is outside [0, 255]");
}

TEST(CyberGlove, RefusesWrongFieldCount) {
  std::string row = raw_row(0, raw_counts(0));
  const std::string short_row = row.substr(0, row.rfind(','));
  expect_message(raw_error(short_row + "\n"), "glove.raw:1: ", "expected 23 fields");
  expect_message(raw_error(short_row + "\n"), "glove.raw:1: ", "found 22");
  expect_message(raw_error(row + ",1\n"), "glove.raw:1: ", "found 24");
  expect_message(raw_error(row + "\n" + raw_row(1, raw_counts(1)) + " 0 0 0 1 0 0 0\n"),
                 "glove.raw:2: ", "found 30 fields, but the first row (line 1) has 23");
  expect_message(raw_error(row + ",,\n"), "glove.raw:1: ", "found 25");
}

TEST(CyberGlove, RefusesNonNumbers) {
  std::string row = raw_row(0, raw_counts(0));
  row.replace(row.find(','), 1, ",abc,");
  row.erase(row.rfind(','));
  expect_message(raw_error(row + "\n"),
                 "glove.raw:1: ", "native sensor 0 (field 2): 'abc' is not a number");
  expect_message(raw_error(raw_row(0, raw_counts(0)) + ",0,0,0,1,0,0,nan\n"),
                 "glove.raw:1: ", "tracker qz (field 30): 'nan' is not finite");
  expect_message(raw_error("x" + raw_row(0, raw_counts(0)) + "\n"),
                 "glove.raw:1: ", "time (field 1): 'x0' is not a number");
}

TEST(CyberGlove, RefusesTimeThatDoesNotIncrease) {
  expect_message(raw_error(raw_row(1, raw_counts(0)) + "\n" + raw_row(1, raw_counts(1)) + "\n"),
                 "glove.raw:2: ", "time does not increase: t = 1 after t = 1 on line 1");
}

TEST(CyberGlove, RefusesZeroTrackerQuaternion) {
  expect_message(raw_error(raw_row(1, raw_counts(0)) + " 1 2 3 0 0 -0 0\n"),
                 "glove.raw:1: ", "quaternion (qw qx qy qz) is zero");
}

TEST(CyberGlove, RefusesEmptyRecording) {
  EXPECT_EQ(raw_error("# nothing\n"), "glove.raw: no samples");
}

TEST(CyberGlove, RefusesCalibrationWith21Rows) {
  std::string text = diagonal_calibration_text();
  text.erase(text.rfind('\n', text.size() - 2) + 1);  // drop the last row
  expect_message(calibration_error(text),
                 "glove.cal:22: ", "file ends after 21 calibration rows, expected 22");
}

TEST(CyberGlove, RefusesCalibrationWith23Rows) {
  expect_message(calibration_error(diagonal_calibration_text() + "1 0\n"),
                 "glove.cal:24: ", "more than 22 calibration rows");
}

TEST(CyberGlove, RefusesBadCalibrationRows) {
  std::string text = diagonal_calibration_text();
  std::size_t row3 = 0;  // line 5 holds native sensor 3
  for (int line = 1; line < 5; ++line) row3 = text.find('\n', row3) + 1;
  std::string three = text;
  three.insert(three.find('\n', row3), " 4");
  expect_message(calibration_error(three), "glove.cal:5: ",
                 "expected 2 numbers (GAIN OFFSET) or 23 (a row of A, then b) for native sensor 3, "
                 "found 3");
  std::string word = text;
  word.replace(row3, word.find(' ', row3) - row3, "gain");
  expect_message(calibration_error(word), "glove.cal:5: ",
                 "calibration of native sensor 3 (field 1): 'gain' is not a number");
  std::string infinite = text;
  infinite.replace(row3, infinite.find(' ', row3) - row3, "1e999");
  expect_message(calibration_error(infinite), "glove.cal:5: ", "'1e999' is not finite");
  EXPECT_EQ(calibration_error(""), "glove.cal: empty, expected 22 calibration rows");
}

}  // namespace
}  // namespace dovetail::interaction

namespace dovetail::interaction {
namespace {

TEST(CyberGlove, RefusesACalibrationThatOverflowsTheAngle) {
  std::string text = "1e308 0\n";  // native sensor 0: 1e308 degrees per count
  for (int i = 1; i < 22; ++i) text += "1 0\n";
  const CyberGloveCalibration c = parse_calibration(text);
  const std::string message = error_of(
      [&] { parse_raw("0" + std::string(raw_row(0, raw_counts(0)).substr(1)) + "\n", c); });
  EXPECT_EQ(message.rfind("glove.raw:1: ", 0), 0U) << message;
  EXPECT_NE(message.find("thumb_roll"), std::string::npos) << message;
  EXPECT_NE(message.find("not finite"), std::string::npos) << message;
}

}  // namespace
}  // namespace dovetail::interaction
