#include "dovetail/interaction/glove_sample.h"

#include <algorithm>
#include <cmath>
#include <cstring>

#include "dovetail/collision/pose_sampling.h"

namespace dovetail::interaction {

namespace {

constexpr std::array<std::string_view, kJointCount> kJointNames = {
    "thumb_roll",  "thumb_mcp",        "thumb_ip",        "thumb_abd",      "index_mcp",
    "index_pip",   "index_dip",        "middle_mcp",      "middle_pip",     "middle_dip",
    "ring_mcp",    "ring_pip",         "ring_dip",        "pinky_mcp",      "pinky_pip",
    "pinky_dip",   "index_middle_abd", "middle_ring_abd", "ring_pinky_abd", "palm_arch",
    "wrist_pitch", "wrist_yaw"};

bool same_bits(Real a, Real b) { return std::memcmp(&a, &b, sizeof a) == 0; }

}  // namespace

std::string_view joint_name(Joint joint) { return kJointNames[static_cast<std::size_t>(joint)]; }

std::optional<Joint> joint_from_name(std::string_view name) {
  for (std::size_t i = 0; i < kJointCount; ++i) {
    if (kJointNames[i] == name) return static_cast<Joint>(i);
  }
  return std::nullopt;
}

Transform GloveSample::X_WH() const {
  const Quaternion q = normalized(q_WH);
  Transform X;
  X.R = rotation(q);
  X.t = p_WH;
  return X;
}

bool same_bits(const GloveSample& a, const GloveSample& b) {
  if (!same_bits(a.t, b.t)) return false;
  for (int i = 0; i < 3; ++i) {
    if (!same_bits(a.p_WH[i], b.p_WH[i])) return false;
  }
  if (!same_bits(a.q_WH.w, b.q_WH.w) || !same_bits(a.q_WH.x, b.q_WH.x) ||
      !same_bits(a.q_WH.y, b.q_WH.y) || !same_bits(a.q_WH.z, b.q_WH.z)) {
    return false;
  }
  for (std::size_t i = 0; i < kJointCount; ++i) {
    if (!same_bits(a.joints[i], b.joints[i])) return false;
  }
  return true;
}

Quaternion normalized(const Quaternion& q) {
  if (!std::isfinite(q.w) || !std::isfinite(q.x) || !std::isfinite(q.y) || !std::isfinite(q.z)) {
    return {};
  }
  const Real largest = std::max({std::abs(q.w), std::abs(q.x), std::abs(q.y), std::abs(q.z)});
  if (!(largest > 0)) return {};
  // Scale first so the squared norm neither overflows nor underflows.
  const Quaternion s{q.w / largest, q.x / largest, q.y / largest, q.z / largest};
  const Real n = std::sqrt(s.w * s.w + s.x * s.x + s.y * s.y + s.z * s.z);
  return {s.w / n, s.x / n, s.y / n, s.z / n};
}

Quaternion slerp(const Quaternion& a, const Quaternion& b_in, Real s) {
  if (s == 0) return a;
  if (s == 1) return b_in;
  Quaternion b = b_in;
  if (a.w * b.w + a.x * b.x + a.y * b.y + a.z * b.z < 0)
    b = {-b.w, -b.x, -b.y, -b.z};  // shorter arc
  // The angle between a and b as 4-vectors from the chord lengths, accurate
  // for small angles too (acos of the dot product is not).
  const Real diff = std::sqrt((b.w - a.w) * (b.w - a.w) + (b.x - a.x) * (b.x - a.x) +
                              (b.y - a.y) * (b.y - a.y) + (b.z - a.z) * (b.z - a.z));
  const Real sum = std::sqrt((b.w + a.w) * (b.w + a.w) + (b.x + a.x) * (b.x + a.x) +
                             (b.y + a.y) * (b.y + a.y) + (b.z + a.z) * (b.z + a.z));
  const Real angle = 2 * std::atan2(diff, sum);
  if (angle == 0) return a;
  const Real sin_angle = std::sin(angle);
  const Real ka = std::sin((1 - s) * angle) / sin_angle;
  const Real kb = std::sin(s * angle) / sin_angle;
  return normalized(
      {ka * a.w + kb * b.w, ka * a.x + kb * b.x, ka * a.y + kb * b.y, ka * a.z + kb * b.z});
}

Mat3 rotation(const Quaternion& q) {
  return collision::rotation_from_quaternion(q.w, q.x, q.y, q.z);
}

}  // namespace dovetail::interaction
