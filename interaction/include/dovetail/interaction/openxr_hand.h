#pragma once
/// \file openxr_hand.h
/// Importing hand-tracking recordings in the form of OpenXR's
/// `XR_EXT_hand_tracking`: the poses of 26 hand joints per frame.
///
/// A joint's frame follows OpenXR: it sits at the base of its bone, -Z points
/// along the bone toward the fingertip, +Y out of the back of the hand; the
/// wrist joint's frame is the hand frame H of hand_model.h. The conversion
/// reads the tracker pose from the wrist and every angle from the relative
/// orientation of neighbouring joints (positions other than the wrist's are
/// checked but not used: the user's bones are not the model's):
/// flexion about the parent's X axis, a finger's abduction about its
/// metacarpal's Y axis relative to the middle finger's, the thumb's roll and
/// abduction from its metacarpal's orientation in H, the palm arch from the
/// little finger's metacarpal. Twist about a bone, which no glove sensor
/// measures, is dropped. The wrist angles are 0 (no forearm is tracked).
///
/// File: CSV with a header row; column `t` (s) and, for each joint J of
/// openxr_joint_name(), `J_px J_py J_pz` (m) and `J_qx J_qy J_qz J_qw` (the
/// order of XrPosef's fields), in any order. Errors name the file and line.

#include <array>
#include <filesystem>
#include <iosfwd>
#include <optional>
#include <span>
#include <string>
#include <string_view>
#include <vector>

#include "dovetail/interaction/glove_sample.h"
#include "dovetail/interaction/hand_model.h"

namespace dovetail::interaction {

/// The joints of XrHandJointEXT, in its order.
enum class XrJoint : std::uint8_t {
  kPalm,
  kWrist,
  kThumbMetacarpal,
  kThumbProximal,
  kThumbDistal,
  kThumbTip,
  kIndexMetacarpal,
  kIndexProximal,
  kIndexIntermediate,
  kIndexDistal,
  kIndexTip,
  kMiddleMetacarpal,
  kMiddleProximal,
  kMiddleIntermediate,
  kMiddleDistal,
  kMiddleTip,
  kRingMetacarpal,
  kRingProximal,
  kRingIntermediate,
  kRingDistal,
  kRingTip,
  kLittleMetacarpal,
  kLittleProximal,
  kLittleIntermediate,
  kLittleDistal,
  kLittleTip,
};
inline constexpr std::size_t kXrJointCount = 26;

/// "palm", "wrist", "thumb_metacarpal", ..., "little_tip" (OpenXR's names).
std::string_view openxr_joint_name(XrJoint joint);

/// One frame of joint poses in the world, by XrJoint.
struct XrHandFrame {
  Real t = 0;
  std::array<Transform, kXrJointCount> X_WJ{};
};

/// The joint poses of `model` at `angles` (within limits) and hand pose X_WH:
/// the hand's own forward kinematics in OpenXR's form.
XrHandFrame openxr_frame(const HandModel& model, const JointAngles& angles, const Transform& X_WH,
                         Real t);

/// The glove sample of one frame of joint poses (see the file comment).
GloveSample sample_from_openxr(const XrHandFrame& frame);

/// The CSV text of frames (header and one row per frame), numbers in
/// shortest round-trip form.
std::string format_openxr(std::span<const XrHandFrame> frames);
/// Reads an OpenXR joint recording and converts every frame; throws
/// TraceError (`name:line: ...`) for a bad file, like read_trace.
std::vector<GloveSample> read_openxr(std::istream& in, std::string_view name);
std::vector<GloveSample> read_openxr(const std::filesystem::path& path);

}  // namespace dovetail::interaction
