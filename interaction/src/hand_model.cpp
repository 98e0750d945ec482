#include "dovetail/interaction/hand_model.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <numbers>
#include <stdexcept>

namespace dovetail::interaction {

namespace {

constexpr std::array<std::string_view, kSegmentCount> kSegmentNames = {
    "palm",          "thumb_metacarpal", "thumb_proximal",
    "thumb_distal",  "index_proximal",   "index_intermediate",
    "index_distal",  "middle_proximal",  "middle_intermediate",
    "middle_distal", "ring_proximal",    "ring_intermediate",
    "ring_distal",   "pinky_proximal",   "pinky_intermediate",
    "pinky_distal"};

constexpr std::array<JointLimit, kJointCount> kLimits = {{
    {-20, 90},   // thumb_roll
    {-10, 90},   // thumb_mcp
    {-20, 100},  // thumb_ip
    {-10, 70},   // thumb_abd
    {-30, 90},   // index_mcp
    {-10, 110},  // index_pip
    {-10, 90},   // index_dip
    {-30, 90},   // middle_mcp
    {-10, 110},  // middle_pip
    {-10, 90},   // middle_dip
    {-30, 90},   // ring_mcp
    {-10, 110},  // ring_pip
    {-10, 90},   // ring_dip
    {-30, 90},   // pinky_mcp
    {-10, 110},  // pinky_pip
    {-10, 90},   // pinky_dip
    {-10, 30},   // index_middle_abd
    {-10, 20},   // middle_ring_abd
    {-10, 40},   // ring_pinky_abd
    {0, 40},     // palm_arch
    {-70, 80},   // wrist_pitch
    {-30, 45},   // wrist_yaw
}};

constexpr std::array<HandSize, 4> kSizes = {{
    {"adult_m50", 0.190},
    {"adult_f50", 0.175},
    {"adult_m95", 0.205},
    {"adult_f05", 0.160},
}};

constexpr Real kDegree = std::numbers::pi / 180;

using P = HandProportions;

/// The three segments of finger `f` (0 = index .. 3 = pinky).
constexpr Segment finger_segment(std::size_t f, std::size_t phalanx) {
  return static_cast<Segment>(static_cast<std::size_t>(Segment::kIndexProximal) + 3 * f + phalanx);
}

std::size_t index_of(Segment s) { return static_cast<std::size_t>(s); }

/// Orients every triangle of a convex mesh so its normal points away from `inside`.
void orient_outward(const std::vector<Vec3>& vertices,
                    std::vector<collision::TriangleIndices>& triangles, const Vec3& inside) {
  for (collision::TriangleIndices& t : triangles) {
    const Vec3& a = vertices[t[0]];
    const Vec3 n = (vertices[t[1]] - a).cross(vertices[t[2]] - a);
    if (n.dot(a - inside) < 0) std::swap(t[1], t[2]);
  }
}

/// The palm, or the part of it between fractions `from` and `to` of its
/// width from the thumb's side.
collision::Mesh palm_mesh(const HandModel& hand, Real from = 0, Real to = 1) {
  const Real hl = hand.hand_length();
  const Vec3 index = hand.knuckle(Digit::kIndex, 0);
  const Vec3 pinky = hand.knuckle(Digit::kPinky, 0);
  const Real x_thumb_side = index.x() - hand.radius(Segment::kIndexProximal);
  const Real x_pinky_side = pinky.x() + hand.radius(Segment::kPinkyProximal);
  const Real y_palmar = -P::kPalmPalmar * hl;
  const Real y_dorsal = P::kPalmDorsal * hl;
  const auto x_at = [&](Real f) { return x_thumb_side + f * (x_pinky_side - x_thumb_side); };
  const auto z_at = [&](Real f) { return index.z() + f * (pinky.z() - index.z()); };
  // A prism over the trapezoid wrist - index knuckle - little knuckle.
  std::vector<Vec3> v;
  for (const Real y : {y_palmar, y_dorsal}) {
    v.emplace_back(x_at(from), y, 0);
    v.emplace_back(x_at(to), y, 0);
    v.emplace_back(x_at(to), y, z_at(to));
    v.emplace_back(x_at(from), y, z_at(from));
  }
  std::vector<collision::TriangleIndices> t = {
      {0, 1, 2}, {0, 2, 3}, {4, 6, 5}, {4, 7, 6},  // palmar, dorsal
      {0, 4, 5}, {0, 5, 1}, {1, 5, 6}, {1, 6, 2},  // wrist, little side
      {2, 6, 7}, {2, 7, 3}, {3, 7, 4}, {3, 4, 0},  // knuckles, thumb side
  };
  Vec3 centre = Vec3::Zero();
  for (const Vec3& p : v) centre += p;
  orient_outward(v, t, centre / static_cast<Real>(v.size()));
  return collision::make_mesh(std::move(v), std::move(t), "hand:palm");
}

}  // namespace

std::string_view segment_name(Segment segment) { return kSegmentNames[index_of(segment)]; }

std::optional<Segment> segment_from_name(std::string_view name) {
  for (std::size_t i = 0; i < kSegmentCount; ++i) {
    if (kSegmentNames[i] == name) return static_cast<Segment>(i);
  }
  return std::nullopt;
}

const std::array<JointLimit, kJointCount>& joint_limits() { return kLimits; }

std::vector<JointExcursion> joints_outside(std::span<const GloveSample> samples, Real margin) {
  std::vector<JointExcursion> out;
  for (std::size_t j = 0; j < kJointCount; ++j) {
    JointExcursion worst{static_cast<Joint>(j)};
    for (const GloveSample& g : samples) {
      const Real a = g.joints[j];
      const Real outside = std::max(kLimits[j].min - a, a - kLimits[j].max);
      if (outside > worst.outside) worst = {worst.joint, a, g.t, outside};
    }
    if (worst.outside > margin) out.push_back(worst);
  }
  return out;
}

std::string describe(const JointExcursion& e) {
  const JointLimit& limit = kLimits[static_cast<std::size_t>(e.joint)];
  char text[160];
  std::snprintf(text, sizeof text,
                "%s reaches %.6g deg at t=%.6g s, outside its range [%.6g, %.6g] by %.3g deg",
                std::string(joint_name(e.joint)).c_str(), e.angle, e.t, limit.min, limit.max,
                e.outside);
  return text;
}

JointAngles clamp_to_limits(const JointAngles& angles, std::bitset<kJointCount>* clamped) {
  JointAngles out = angles;
  for (std::size_t j = 0; j < kJointCount; ++j) {
    Real a = angles[j];
    bool out_of_range = false;
    if (std::isnan(a)) {
      a = 0;
      out_of_range = true;
    }
    if (a < kLimits[j].min) {
      a = kLimits[j].min;
      out_of_range = true;
    } else if (a > kLimits[j].max) {
      a = kLimits[j].max;
      out_of_range = true;
    }
    out[j] = a;
    if (clamped) clamped->set(j, out_of_range);
  }
  return out;
}

std::span<const HandSize> hand_sizes() { return kSizes; }

Mat3 rotation_x_deg(Real degrees) {
  const Real c = std::cos(degrees * kDegree);
  const Real s = std::sin(degrees * kDegree);
  Mat3 R;
  R << 1, 0, 0, 0, c, -s, 0, s, c;
  return R;
}

Mat3 rotation_y_deg(Real degrees) {
  const Real c = std::cos(degrees * kDegree);
  const Real s = std::sin(degrees * kDegree);
  Mat3 R;
  R << c, 0, s, 0, 1, 0, -s, 0, c;
  return R;
}

Mat3 rotation_z_deg(Real degrees) {
  const Real c = std::cos(degrees * kDegree);
  const Real s = std::sin(degrees * kDegree);
  Mat3 R;
  R << c, -s, 0, s, c, 0, 0, 0, 1;
  return R;
}

collision::Mesh capsule_mesh(Real length, Real radius) {
  constexpr int kAround = 8;
  const Real mid = std::sqrt(Real{0.5});  // cos 45 = sin 45
  std::vector<Vec3> v;
  // Rings: 0 proximal equator, 1 distal equator, 2 proximal 45 degrees, 3 distal 45 degrees.
  for (int ring = 0; ring < 4; ++ring) {
    const Real scale = ring < 2 ? 1 : mid;
    const Real z = ring == 0   ? 0
                   : ring == 1 ? -length
                   : ring == 2 ? radius * mid
                               : -length - radius * mid;
    for (int k = 0; k < kAround; ++k) {
      const Real angle = 2 * std::numbers::pi * k / kAround;
      // Exact axis directions at k = 0, 2, 4, 6.
      const Real c = k % 4 == 2 ? 0 : k == 0 ? 1 : k == 4 ? -1 : std::cos(angle);
      const Real s = k % 4 == 0 ? 0 : k == 2 ? 1 : k == 6 ? -1 : std::sin(angle);
      v.emplace_back(radius * scale * c, radius * scale * s, z);
    }
  }
  const auto pole_proximal = static_cast<std::uint32_t>(v.size());
  v.emplace_back(0, 0, radius);
  const auto pole_distal = static_cast<std::uint32_t>(v.size());
  v.emplace_back(0, 0, -length - radius);

  auto at = [](int ring, int k) {
    return static_cast<std::uint32_t>(ring * kAround + (k % kAround));
  };
  std::vector<collision::TriangleIndices> t;
  for (int k = 0; k < kAround; ++k) {
    // Side, then each cap: equator to the 45-degree ring, that ring to the pole.
    t.push_back({at(0, k), at(0, k + 1), at(1, k + 1)});
    t.push_back({at(0, k), at(1, k + 1), at(1, k)});
    t.push_back({at(0, k), at(2, k + 1), at(0, k + 1)});
    t.push_back({at(0, k), at(2, k), at(2, k + 1)});
    t.push_back({at(2, k), pole_proximal, at(2, k + 1)});
    t.push_back({at(1, k), at(1, k + 1), at(3, k + 1)});
    t.push_back({at(1, k), at(3, k + 1), at(3, k)});
    t.push_back({at(3, k), at(3, k + 1), pole_distal});
  }
  orient_outward(v, t, Vec3(0, 0, -length / 2));
  return collision::make_mesh(std::move(v), std::move(t), "hand:capsule");
}

HandModel::HandModel(const HandDef& def) {
  const HandSize* size = nullptr;
  for (const HandSize& s : kSizes) {
    if (s.name == def.size) size = &s;
  }
  if (size == nullptr) {
    std::string names;
    for (const HandSize& s : kSizes) names += (names.empty() ? "" : ", ") + std::string(s.name);
    throw std::invalid_argument("hand: unknown size '" + def.size + "' (sizes: " + names + ")");
  }
  hand_length_ = def.hand_length == 0 ? size->hand_length : def.hand_length;
  if (!(hand_length_ > 0.05 && hand_length_ < 0.5)) {
    throw std::invalid_argument("hand: the hand length must be between 0.05 and 0.5 m");
  }
  size_name_ = std::string(size->name);
  const Real hl = hand_length_;

  length_[index_of(Segment::kPalm)] = (P::kCarpal + P::kFinger[1][0]) * hl;
  radius_[index_of(Segment::kPalm)] = P::kPalmPalmar * hl;
  for (std::size_t i = 0; i < 3; ++i) {
    const auto s = static_cast<Segment>(index_of(Segment::kThumbMetacarpal) + i);
    length_[index_of(s)] = P::kThumb[i] * hl;
    radius_[index_of(s)] = P::kThumbRadius[i] * hl;
  }
  for (std::size_t f = 0; f < 4; ++f) {
    for (std::size_t i = 0; i < 3; ++i) {
      const Segment s = finger_segment(f, i);
      length_[index_of(s)] = P::kFinger[f][i + 1] * hl;
      radius_[index_of(s)] = P::kFingerRadius[i] * hl * (f == 3 ? P::kPinkyRadiusScale : 1);
    }
  }
  for (std::size_t i = 1; i < kSegmentCount; ++i) {
    proxy_[i] = std::make_shared<const collision::Mesh>(capsule_mesh(length_[i], radius_[i]));
  }
  proxy_[0] = std::make_shared<const collision::Mesh>(palm_mesh(*this));
  for (std::size_t i = 0; i < palm_strips_.size(); ++i) {
    const auto n = static_cast<Real>(palm_strips_.size());
    palm_strips_[i] = std::make_shared<const collision::Mesh>(
        palm_mesh(*this, static_cast<Real>(i) / n, static_cast<Real>(i + 1) / n));
  }
}

Vec3 HandModel::knuckle(Digit digit, Real arch_deg) const {
  if (digit == Digit::kThumb) throw std::invalid_argument("hand: the thumb has no knuckle here");
  const auto f = static_cast<std::size_t>(digit) - 1;
  const Real hl = hand_length_;
  const Vec3 p((static_cast<Real>(f) - 1.5) * P::kSpacing * hl, 0,
               -(P::kCarpal + P::kFinger[f][0]) * hl);
  const Real share = digit == Digit::kRing    ? P::kArchRing
                     : digit == Digit::kPinky ? P::kArchPinky
                                              : 0;
  if (share == 0) return p;
  return rotation_z_deg(-share * arch_deg) * p;
}

Vec3 HandModel::metacarpal_base(Digit digit, Real arch_deg) const {
  if (digit == Digit::kThumb) {
    throw std::invalid_argument("hand: the thumb's metacarpal base is its first segment's pose");
  }
  const auto f = static_cast<std::size_t>(digit) - 1;
  const Real hl = hand_length_;
  const Vec3 p((static_cast<Real>(f) - 1.5) * P::kSpacing * hl, 0, -P::kCarpal * hl);
  const Real share = digit == Digit::kRing    ? P::kArchRing
                     : digit == Digit::kPinky ? P::kArchPinky
                                              : 0;
  if (share == 0) return p;
  return rotation_z_deg(-share * arch_deg) * p;
}

HandPose HandModel::forward_kinematics(const JointAngles& q) const {
  HandPose pose;
  const Real hl = hand_length_;
  // Each segment: its frame at its proximal joint; the next one at the end of its bone.
  auto chain = [&](Transform X_HS, Segment first, std::span<const Real> flexion,
                   std::size_t digit) {
    for (std::size_t i = 0; i < flexion.size(); ++i) {
      const auto s = static_cast<Segment>(index_of(first) + i);
      if (i > 0) {
        const Transform& parent = pose.X_HS[index_of(s) - 1];
        X_HS.t = parent.apply(Vec3(0, 0, -length(static_cast<Segment>(index_of(s) - 1))));
        X_HS.R = parent.R * rotation_x_deg(-flexion[i]);
      }
      pose.X_HS[index_of(s)] = X_HS;
    }
    const auto last = static_cast<Segment>(index_of(first) + flexion.size() - 1);
    pose.p_HTip[digit] = pose.X_HS[index_of(last)].apply(Vec3(0, 0, -length(last)));
  };

  pose.X_HS[index_of(Segment::kPalm)] = Transform::identity();

  // Thumb: opposition roll about the palm's long axis, abduction about its normal, the
  // metacarpal's fixed pronation about its own axis.
  Transform X_HT;
  X_HT.t = Vec3(P::kThumbBase[0], P::kThumbBase[1], P::kThumbBase[2]) * hl;
  X_HT.R = rotation_z_deg(at(q, Joint::kThumbRoll)) *
           rotation_y_deg(P::kThumbRestDeg + at(q, Joint::kThumbAbd)) *
           rotation_z_deg(P::kThumbPronationDeg);
  const std::array<Real, 3> thumb = {0, at(q, Joint::kThumbMcp), at(q, Joint::kThumbIp)};
  chain(X_HT, Segment::kThumbMetacarpal, thumb, 0);

  // Fingers: the middle finger is the abduction reference.
  const Real arch = at(q, Joint::kPalmArch);
  const Real im = at(q, Joint::kIndexMiddleAbd);
  const Real mr = at(q, Joint::kMiddleRingAbd);
  const Real rp = at(q, Joint::kRingPinkyAbd);
  const std::array<Real, 4> spread = {im, 0, -mr, -(mr + rp)};
  const std::array<Real, 4> arch_share = {0, 0, P::kArchRing, P::kArchPinky};
  for (std::size_t f = 0; f < 4; ++f) {
    const auto digit = static_cast<Digit>(f + 1);
    const std::size_t j = static_cast<std::size_t>(Joint::kIndexMcp) + 3 * f;
    Transform X_HF;
    X_HF.t = knuckle(digit, arch);
    X_HF.R =
        rotation_z_deg(-arch_share[f] * arch) * rotation_y_deg(spread[f]) * rotation_x_deg(-q[j]);
    const std::array<Real, 3> flexion = {q[j], q[j + 1], q[j + 2]};
    chain(X_HF, finger_segment(f, 0), flexion, f + 1);
  }
  return pose;
}

}  // namespace dovetail::interaction
