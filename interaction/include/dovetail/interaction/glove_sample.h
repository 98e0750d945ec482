#pragma once
/// \file glove_sample.h
/// One reading of a data glove and its tracker: the time, the pose of the
/// hand in the world and the 22 joint angles of the CyberGlove sensor layout.
///
/// Why: everything that drives the hand (a recorded trace, the simulated
/// glove, an importer, the noise model) produces GloveSamples, and the hand
/// consumes nothing else. The tracker orientation is kept as the quaternion
/// it was given, not as a matrix, so a trace written and read back carries
/// the same bits.

#include <array>
#include <cstddef>
#include <cstdint>
#include <optional>
#include <string_view>

#include "dovetail/collision/types.h"
#include "dovetail/engine/pose_list.h"

namespace dovetail::interaction {

using collision::Mat3;
using collision::Real;
using collision::Transform;
using collision::Vec3;
using engine::Quaternion;

/// The 22 joint angles in the order of the glove-trace columns (docs/cli.md)
/// (abductions after the pinky, unlike the CyberGlove's native order).
enum class Joint : std::uint8_t {
  kThumbRoll,
  kThumbMcp,
  kThumbIp,
  kThumbAbd,
  kIndexMcp,
  kIndexPip,
  kIndexDip,
  kMiddleMcp,
  kMiddlePip,
  kMiddleDip,
  kRingMcp,
  kRingPip,
  kRingDip,
  kPinkyMcp,
  kPinkyPip,
  kPinkyDip,
  kIndexMiddleAbd,
  kMiddleRingAbd,
  kRingPinkyAbd,
  kPalmArch,
  kWristPitch,
  kWristYaw,
};

/// Number of joint angles in a sample.
inline constexpr std::size_t kJointCount = 22;

/// Joint angles in degrees, indexed by Joint.
using JointAngles = std::array<Real, kJointCount>;

/// The column name of a joint: "thumb_roll", "index_mcp", ...
std::string_view joint_name(Joint joint);
/// The joint of a column name, or nullopt.
std::optional<Joint> joint_from_name(std::string_view name);

/// Angle of `joint` in `angles`.
inline Real& at(JointAngles& angles, Joint joint) {
  return angles[static_cast<std::size_t>(joint)];
}
inline Real at(const JointAngles& angles, Joint joint) {
  return angles[static_cast<std::size_t>(joint)];
}

/// One glove and tracker reading.
struct GloveSample {
  Real t = 0;                ///< seconds
  Vec3 p_WH = Vec3::Zero();  ///< tracker (hand frame H) position in the world, metres
  Quaternion q_WH{};         ///< tracker orientation; need not be unit length
  JointAngles joints{};      ///< degrees
  /// The hand's pose in the world: the normalised quaternion's rotation and p_WH.
  Transform X_WH() const;
};

/// Bitwise equality of every field (so 0.0 and -0.0 differ, as they do in a trace).
bool same_bits(const GloveSample& a, const GloveSample& b);

/// Unit quaternion (w >= 0 is not enforced) of `q` scaled to length 1; the
/// identity for a zero or non-finite quaternion.
Quaternion normalized(const Quaternion& q);
/// Spherical linear interpolation between unit quaternions a (s = 0) and b
/// (s = 1) along the shorter arc; exactly a at s = 0 and b at s = 1.
Quaternion slerp(const Quaternion& a, const Quaternion& b, Real s);
/// The rotation matrix of a unit quaternion.
Mat3 rotation(const Quaternion& q);

}  // namespace dovetail::interaction
