#pragma once
/// \file cyberglove.h
/// Importing recordings of a CyberGlove in its native sensor order and raw
/// counts, with a linear calibration.
///
/// The CyberGlove sends its 22 sensors with each abduction after the finger
/// it follows (native index 10 = index-middle, 14 = middle-ring, 18 =
/// ring-pinky); Dovetail's order puts the three after the pinky:
/// `dovetail[k] = native[kNativeOfJoint[k]]`.
///
/// Both files: lines end in '\n' or "\r\n", blank lines and `#` comment lines
/// are skipped, fields are separated by a comma (blanks around it allowed) or
/// by blanks, and no line may be longer than kMaxTraceLineBytes.
///
/// Calibration file: exactly 22 rows, row i for native sensor i, either
/// `GAIN OFFSET` (angle_i = GAIN * raw_i + OFFSET) or 23 numbers, a full row
/// of A then b (angle_i = sum_j A_ij raw_j + b_i, for calibrations that mix
/// sensors, such as the thumb's). Angles in degrees.
///
/// Raw file: each row `t` then the 22 raw counts in native order, optionally
/// followed by the tracker `x y z qw qx qy qz` (a non-zero quaternion); every
/// row has as many fields as the first. Raw counts are 8-bit: numbers in
/// [0, 255]. Without tracker columns the hand stays at the origin (p_WH = 0,
/// q_WH = identity). Time must increase from row to row, and a recording
/// needs at least one row. Errors name the file and the line.

#include <Eigen/Core>
#include <array>
#include <cstddef>
#include <filesystem>
#include <iosfwd>
#include <string_view>
#include <vector>

#include "dovetail/interaction/glove_sample.h"
#include "dovetail/interaction/glove_trace.h"

namespace dovetail::interaction {

/// Native sensor index of each Dovetail joint.
inline constexpr std::array<std::size_t, kJointCount> kNativeOfJoint = {
    0, 1, 2, 3, 4, 5, 6, 7, 8, 9, 11, 12, 13, 15, 16, 17, 10, 14, 18, 19, 20, 21};

/// angle (native order) = A * raw (native order) + b.
struct CyberGloveCalibration {
  Eigen::Matrix<Real, 22, 22> A = Eigen::Matrix<Real, 22, 22>::Identity();
  Eigen::Matrix<Real, 22, 1> b = Eigen::Matrix<Real, 22, 1>::Zero();
};

/// Parses a calibration; throws TraceError (`name:line: ...`). Sensors given
/// as `GAIN OFFSET` keep zeros off the diagonal of their row of A.
CyberGloveCalibration read_calibration(std::istream& in, std::string_view name);
CyberGloveCalibration read_calibration(const std::filesystem::path& path);

/// Joint angles in Dovetail order from 22 raw counts in native order; each
/// native angle sums A_ij * raw_j for j = 0..21 in order, then adds b_i.
JointAngles calibrate(const CyberGloveCalibration& calibration,
                      const std::array<Real, kJointCount>& raw_native);

/// Parses a raw recording into samples; throws TraceError (`name:line: ...`)
/// for a bad row, a count outside [0, 255], or time that does not increase.
std::vector<GloveSample> read_cyberglove_raw(std::istream& in, std::string_view name,
                                             const CyberGloveCalibration& calibration);
std::vector<GloveSample> read_cyberglove_raw(const std::filesystem::path& path,
                                             const CyberGloveCalibration& calibration);

}  // namespace dovetail::interaction
