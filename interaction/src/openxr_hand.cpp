#include "dovetail/interaction/openxr_hand.h"

#include <cmath>
#include <fstream>
#include <numbers>
#include <sstream>

#include "dovetail/engine/pose_list.h"
#include "dovetail/engine/scene.h"
#include "dovetail/interaction/glove_trace.h"
#include "text_reading.h"

namespace dovetail::interaction {

namespace {

constexpr std::array<std::string_view, kXrJointCount> kXrNames = {"palm",
                                                                  "wrist",
                                                                  "thumb_metacarpal",
                                                                  "thumb_proximal",
                                                                  "thumb_distal",
                                                                  "thumb_tip",
                                                                  "index_metacarpal",
                                                                  "index_proximal",
                                                                  "index_intermediate",
                                                                  "index_distal",
                                                                  "index_tip",
                                                                  "middle_metacarpal",
                                                                  "middle_proximal",
                                                                  "middle_intermediate",
                                                                  "middle_distal",
                                                                  "middle_tip",
                                                                  "ring_metacarpal",
                                                                  "ring_proximal",
                                                                  "ring_intermediate",
                                                                  "ring_distal",
                                                                  "ring_tip",
                                                                  "little_metacarpal",
                                                                  "little_proximal",
                                                                  "little_intermediate",
                                                                  "little_distal",
                                                                  "little_tip"};

constexpr Real kDegreesPerRadian = 180 / std::numbers::pi;

std::size_t xr(XrJoint j) { return static_cast<std::size_t>(j); }
std::size_t seg(Segment s) { return static_cast<std::size_t>(s); }

/// R_A^T R_B: the orientation of B in A's frame.
Mat3 relative(const Transform& X_WA, const Transform& X_WB) { return X_WA.R.transpose() * X_WB.R; }

/// The seven columns of a joint: position, then XrPosef's quaternion order.
constexpr std::array<std::string_view, 7> kPoseColumns = {"_px", "_py", "_pz", "_qx",
                                                          "_qy", "_qz", "_qw"};
constexpr std::size_t kColumns = 1 + 7 * kXrJointCount;

/// Angle (degrees) of a rotation about X: M = Rx(angle).
Real angle_about_x(const Mat3& M) { return std::atan2(M(2, 1), M(1, 1)) * kDegreesPerRadian; }

}  // namespace

std::string_view openxr_joint_name(XrJoint joint) { return kXrNames[xr(joint)]; }

XrHandFrame openxr_frame(const HandModel& model, const JointAngles& angles, const Transform& X_WH,
                         Real t) {
  const HandPose pose = model.forward_kinematics(angles);
  XrHandFrame frame;
  frame.t = t;
  auto put = [&](XrJoint j, const Transform& X_HJ) {
    frame.X_WJ[xr(j)] = engine::compose(X_WH, X_HJ);
  };
  auto tip = [&](XrJoint j, Segment distal, Digit digit) {
    Transform X_HJ = pose.X_HS[seg(distal)];
    X_HJ.t = pose.p_HTip[static_cast<std::size_t>(digit)];
    put(j, X_HJ);
  };
  const Real arch = at(angles, Joint::kPalmArch);

  put(XrJoint::kWrist, Transform::identity());
  Transform X_HPalm;
  X_HPalm.t =
      (model.metacarpal_base(Digit::kMiddle, arch) + model.knuckle(Digit::kMiddle, arch)) / 2;
  put(XrJoint::kPalm, X_HPalm);

  put(XrJoint::kThumbMetacarpal, pose.X_HS[seg(Segment::kThumbMetacarpal)]);
  put(XrJoint::kThumbProximal, pose.X_HS[seg(Segment::kThumbProximal)]);
  put(XrJoint::kThumbDistal, pose.X_HS[seg(Segment::kThumbDistal)]);
  tip(XrJoint::kThumbTip, Segment::kThumbDistal, Digit::kThumb);

  const std::array<Real, 4> arch_share = {0, 0, HandProportions::kArchRing,
                                          HandProportions::kArchPinky};
  for (std::size_t f = 0; f < 4; ++f) {
    const auto digit = static_cast<Digit>(f + 1);
    const std::size_t base = xr(XrJoint::kIndexMetacarpal) + 5 * f;
    const std::size_t first = seg(Segment::kIndexProximal) + 3 * f;
    Transform X_HM;
    X_HM.R = rotation_z_deg(-arch_share[f] * arch);
    X_HM.t = model.metacarpal_base(digit, arch);
    put(static_cast<XrJoint>(base), X_HM);
    for (std::size_t i = 0; i < 3; ++i)
      put(static_cast<XrJoint>(base + 1 + i), pose.X_HS[first + i]);
    tip(static_cast<XrJoint>(base + 4), static_cast<Segment>(first + 2), digit);
  }
  return frame;
}

GloveSample sample_from_openxr(const XrHandFrame& frame) {
  const auto& X = frame.X_WJ;
  GloveSample s;
  s.t = frame.t;
  const Transform& X_WH = X[xr(XrJoint::kWrist)];
  s.p_WH = X_WH.t;
  s.q_WH = engine::quaternion_from_rotation(X_WH.R);
  JointAngles& q = s.joints;

  // Thumb: its metacarpal in H is Rz(roll) Ry(rest + abduction) Rz(pronation), so its
  // Z axis, which the twist about the bone leaves alone, is
  // (cos roll sin a, sin roll sin a, cos a) with a = rest + abduction in (0, 180).
  const Mat3 M_thumb = relative(X_WH, X[xr(XrJoint::kThumbMetacarpal)]);
  at(q, Joint::kThumbRoll) = std::atan2(M_thumb(1, 2), M_thumb(0, 2)) * kDegreesPerRadian;
  at(q, Joint::kThumbAbd) =
      std::atan2(std::hypot(M_thumb(0, 2), M_thumb(1, 2)), M_thumb(2, 2)) * kDegreesPerRadian -
      HandProportions::kThumbRestDeg;
  at(q, Joint::kThumbMcp) =
      -angle_about_x(relative(X[xr(XrJoint::kThumbMetacarpal)], X[xr(XrJoint::kThumbProximal)]));
  at(q, Joint::kThumbIp) =
      -angle_about_x(relative(X[xr(XrJoint::kThumbProximal)], X[xr(XrJoint::kThumbDistal)]));

  // Fingers: the proximal phalanx in its metacarpal's frame is Ry(spread) Rx(-mcp).
  std::array<Real, 4> spread{};
  for (std::size_t f = 0; f < 4; ++f) {
    const std::size_t base = xr(XrJoint::kIndexMetacarpal) + 5 * f;
    const Mat3 M = relative(X[base], X[base + 1]);
    spread[f] = std::atan2(-M(2, 0), M(0, 0)) * kDegreesPerRadian;
    const std::size_t j = static_cast<std::size_t>(Joint::kIndexMcp) + 3 * f;
    q[j] = std::atan2(-M(1, 2), M(1, 1)) * kDegreesPerRadian * -1;
    q[j + 1] = -angle_about_x(relative(X[base + 1], X[base + 2]));
    q[j + 2] = -angle_about_x(relative(X[base + 2], X[base + 3]));
  }
  at(q, Joint::kIndexMiddleAbd) = spread[0] - spread[1];
  at(q, Joint::kMiddleRingAbd) = spread[1] - spread[2];
  at(q, Joint::kRingPinkyAbd) = spread[2] - spread[3];

  // Palm arch: the little finger's metacarpal in H is Rz(-arch).
  const Mat3 M_little = relative(X_WH, X[xr(XrJoint::kLittleMetacarpal)]);
  at(q, Joint::kPalmArch) =
      -std::atan2(M_little(1, 0), M_little(0, 0)) * kDegreesPerRadian / HandProportions::kArchPinky;
  return s;
}

std::string format_openxr(std::span<const XrHandFrame> frames) {
  std::string out = "t";
  for (std::size_t j = 0; j < kXrJointCount; ++j) {
    for (std::string_view c : kPoseColumns) {
      out += ',';
      out += kXrNames[j];
      out += c;
    }
  }
  out += '\n';
  for (const XrHandFrame& frame : frames) {
    append_number(out, frame.t);
    for (const Transform& X_WJ : frame.X_WJ) {
      const Quaternion q = engine::quaternion_from_rotation(X_WJ.R);
      for (Real v : {X_WJ.t.x(), X_WJ.t.y(), X_WJ.t.z(), q.x, q.y, q.z, q.w}) {
        out += ',';
        append_number(out, v);
      }
    }
    out += '\n';
  }
  return out;
}

std::vector<GloveSample> read_openxr(std::istream& in, std::string_view name) {
  LineReader reader(in, name);
  const std::optional<std::string_view> header = reader.next_content();
  if (!header) throw TraceError(std::string(name) + ": empty, no header row");
  // Column index of t and of each joint's seven values.
  std::array<std::size_t, kColumns> column_of{};
  std::array<bool, kColumns> seen{};
  std::vector<std::string> names;  // copied: the reader's next line replaces the header's text
  std::vector<std::string_view> fields;
  split_commas(*header, fields);
  for (std::string_view field : fields) names.emplace_back(field);
  for (std::size_t i = 0; i < names.size(); ++i) {
    std::optional<std::size_t> slot;
    if (names[i] == "t") slot = 0;
    for (std::size_t j = 0; j < kXrJointCount && !slot; ++j) {
      for (std::size_t c = 0; c < 7 && !slot; ++c) {
        if (names[i].size() == kXrNames[j].size() + 3 && names[i].starts_with(kXrNames[j]) &&
            names[i].ends_with(kPoseColumns[c])) {
          slot = 1 + 7 * j + c;
        }
      }
    }
    if (!slot) {
      if (parse_number(names[i]))
        reader.fail("expected a header row naming the columns, found numbers");
      reader.fail("unknown column " + interaction::quoted(names[i]));
    }
    if (seen[*slot]) reader.fail("column " + interaction::quoted(names[i]) + " appears twice");
    seen[*slot] = true;
    column_of[*slot] = i;
  }
  for (std::size_t k = 0; k < kColumns; ++k) {
    if (seen[k]) continue;
    const std::string missing =
        k == 0 ? std::string("t")
               : std::string(kXrNames[(k - 1) / 7]) + std::string(kPoseColumns[(k - 1) % 7]);
    reader.fail("missing column " + quoted(std::string_view(missing)));
  }

  std::vector<GloveSample> samples;
  std::array<Real, kColumns> v{};
  while (const std::optional<std::string_view> line = reader.next_content()) {
    split_commas(*line, fields);
    if (fields.size() != names.size()) {
      reader.fail_row("expected " + std::to_string(names.size()) + " fields, found " +
                      std::to_string(fields.size()));
    }
    for (std::size_t k = 0; k < kColumns; ++k) {
      const std::string_view field = fields[column_of[k]];
      const std::optional<Real> number = parse_number(field);
      if (!number)
        reader.fail_row("column " + interaction::quoted(names[column_of[k]]) + ": " +
                        quoted(field) + " is not a number");
      if (!std::isfinite(*number))
        reader.fail_row("column " + interaction::quoted(names[column_of[k]]) + ": " +
                        quoted(field) + " is not finite");
      v[k] = *number;
    }
    XrHandFrame frame;
    frame.t = v[0];
    if (!samples.empty() && !(frame.t > samples.back().t)) {
      reader.fail("time does not increase: t = " + format_number(frame.t) +
                  " after t = " + format_number(samples.back().t));
    }
    for (std::size_t j = 0; j < kXrJointCount; ++j) {
      const Real* p = &v[1 + 7 * j];
      if (p[3] == 0 && p[4] == 0 && p[5] == 0 && p[6] == 0) {
        reader.fail("joint " + std::string(kXrNames[j]) + " has a zero quaternion");
      }
      frame.X_WJ[j].t = Vec3(p[0], p[1], p[2]);
      frame.X_WJ[j].R = rotation(normalized({p[6], p[3], p[4], p[5]}));
    }
    samples.push_back(sample_from_openxr(frame));
  }
  if (samples.empty()) throw TraceError(std::string(name) + ": no frames after the header");
  return samples;
}

std::vector<GloveSample> read_openxr(const std::filesystem::path& path) {
  std::ifstream in = open_for_reading(path);
  return read_openxr(in, path.string());
}

}  // namespace dovetail::interaction
