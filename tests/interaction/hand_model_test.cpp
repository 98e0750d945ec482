// Forward kinematics against fingertips worked out by hand, limits, proxies.

#include "dovetail/interaction/hand_model.h"

#include <gtest/gtest.h>

#include <cmath>
#include <map>
#include <numbers>

#include "dovetail/interaction/postures.h"

namespace dovetail::interaction {
namespace {

using P = HandProportions;

constexpr Real kRad = std::numbers::pi / 180;
constexpr Real kTolerance = 1e-12;  // metres: a few roundings of hand-sized numbers

// The hand's conventions written out independently of the model's code:
// flexion by phi turns the bone direction (0, 0, -1) to (0, -sin phi, -cos phi);
// Ry(a) (x, y, z) = (x cos a + z sin a, y, -x sin a + z cos a);
// Rz(a) (x, y, z) = (x cos a - y sin a, x sin a + y cos a, z).
Vec3 bone(Real phi_deg) { return {0, -std::sin(phi_deg * kRad), -std::cos(phi_deg * kRad)}; }
Vec3 ry(Real a_deg, const Vec3& v) {
  const Real c = std::cos(a_deg * kRad), s = std::sin(a_deg * kRad);
  return {v.x() * c + v.z() * s, v.y(), -v.x() * s + v.z() * c};
}
Vec3 rz(Real a_deg, const Vec3& v) {
  const Real c = std::cos(a_deg * kRad), s = std::sin(a_deg * kRad);
  return {v.x() * c - v.y() * s, v.x() * s + v.y() * c, v.z()};
}

/// A finger in its own plane: knuckle, then three bones flexed by the running sums.
Vec3 finger_tip(std::size_t f, Real hl, Real mcp, Real pip, Real dip, Real spread, Real arch_deg) {
  const auto& L = P::kFinger[f];
  const Vec3 knuckle((static_cast<Real>(f) - 1.5) * P::kSpacing * hl, 0, -(P::kCarpal + L[0]) * hl);
  const Vec3 chain =
      L[1] * hl * bone(mcp) + L[2] * hl * bone(mcp + pip) + L[3] * hl * bone(mcp + pip + dip);
  return rz(-arch_deg, knuckle + ry(spread, chain));
}

/// The thumb in its own plane, turned by the metacarpal's pronation about its axis, then by
/// abduction and roll.
Vec3 thumb_tip(Real hl, Real roll, Real abd, Real mcp, Real ip) {
  const Vec3 base(P::kThumbBase[0] * hl, P::kThumbBase[1] * hl, P::kThumbBase[2] * hl);
  const Vec3 chain = P::kThumb[0] * hl * bone(0) + P::kThumb[1] * hl * bone(mcp) +
                     P::kThumb[2] * hl * bone(mcp + ip);
  return base + rz(roll, ry(P::kThumbRestDeg + abd, rz(P::kThumbPronationDeg, chain)));
}

void expect_near(const Vec3& actual, const Vec3& expected, const char* what) {
  EXPECT_NEAR(actual.x(), expected.x(), kTolerance) << what;
  EXPECT_NEAR(actual.y(), expected.y(), kTolerance) << what;
  EXPECT_NEAR(actual.z(), expected.z(), kTolerance) << what;
}

class HandKinematics : public ::testing::TestWithParam<const char*> {};

TEST_P(HandKinematics, FlatHandFingertips) {
  const HandModel hand({.size = GetParam()});
  const Real hl = hand.hand_length();
  const HandPose pose = hand.forward_kinematics(*named_posture("open"));
  // The flat middle fingertip lies exactly one hand length from the wrist.
  expect_near(pose.p_HTip[2], Vec3(-0.5 * P::kSpacing * hl, 0, -hl), "middle");
  const Real index_reach = (0.374 + 0.265 + 0.143 + 0.097 + P::kCarpal) * hl;
  expect_near(pose.p_HTip[1], Vec3(-1.5 * P::kSpacing * hl, 0, -index_reach), "index");
  const Real pinky_reach = (0.295 + 0.206 + 0.117 + 0.093 + P::kCarpal) * hl;
  expect_near(pose.p_HTip[4], Vec3(1.5 * P::kSpacing * hl, 0, -pinky_reach), "pinky");
  const Real thumb_length = (0.251 + 0.196 + 0.158) * hl;
  const Real rest = P::kThumbRestDeg * kRad;
  expect_near(pose.p_HTip[0],
              Vec3(P::kThumbBase[0] * hl - thumb_length * std::sin(rest), P::kThumbBase[1] * hl,
                   P::kThumbBase[2] * hl - thumb_length * std::cos(rest)),
              "thumb");
}

TEST_P(HandKinematics, FistFingertips) {
  const HandModel hand({.size = GetParam()});
  const Real hl = hand.hand_length();
  const JointAngles fist = *named_posture("fist");
  const HandPose pose = hand.forward_kinematics(fist);
  // Fist: MCP 90, PIP 100, DIP 70, no spread, palm arch 10 (ring half of it).
  for (std::size_t f = 0; f < 4; ++f) {
    const Real arch = f == 2 ? 5 : f == 3 ? 10 : 0;
    expect_near(pose.p_HTip[f + 1], finger_tip(f, hl, 90, 100, 70, 0, arch), "finger");
  }
  // The index tip by plain arithmetic: bones point down, then back up and toward the wrist.
  const Real s190 = std::sin(190 * kRad), c190 = std::cos(190 * kRad);
  const Real s260 = std::sin(260 * kRad), c260 = std::cos(260 * kRad);
  const Vec3 index(-1.5 * P::kSpacing * hl, -0.265 * hl - 0.143 * hl * s190 - 0.097 * hl * s260,
                   -(P::kCarpal + 0.374) * hl - 0.143 * hl * c190 - 0.097 * hl * c260);
  expect_near(pose.p_HTip[1], index, "index by arithmetic");
  expect_near(pose.p_HTip[0], thumb_tip(hl, 40, 10, 50, 40), "thumb");
}

/// The angle between two vectors in degrees.
Real angle_deg(const Vec3& a, const Vec3& b) {
  return std::atan2(a.cross(b).norm(), a.dot(b)) / kRad;
}

TEST_P(HandKinematics, PinchFingertips) {
  const HandModel hand({.size = GetParam()});
  const Real hl = hand.hand_length();
  const HandPose pose = hand.forward_kinematics(*named_posture("pinch"));
  expect_near(pose.p_HTip[1], finger_tip(0, hl, 60, 30, 5, 0, 0), "index");
  expect_near(pose.p_HTip[2], finger_tip(1, hl, 10, 10, 5, 0, 0), "middle");
  expect_near(pose.p_HTip[0], thumb_tip(hl, 75, 15, 10, 10), "thumb");
  // The tips' capsules meet: their ends are the closest points of the two bones here, and
  // they are less than half a millimetre apart.
  const Real pads = hand.radius(Segment::kThumbDistal) + hand.radius(Segment::kIndexDistal);
  const Vec3 thumb_to_index = pose.p_HTip[1] - pose.p_HTip[0];
  EXPECT_GT(thumb_to_index.norm(), pads);
  EXPECT_LT(thumb_to_index.norm(), pads + 0.0005);
  // Pad to pad: each pad (-Y of the distal segment) faces the other tip within 50 degrees;
  // the thumb's metacarpal is pronated, so its pad faces the index across the palm.
  const Vec3 thumb_pad = -pose.X_HS[static_cast<std::size_t>(Segment::kThumbDistal)].R.col(1);
  const Vec3 index_pad = -pose.X_HS[static_cast<std::size_t>(Segment::kIndexDistal)].R.col(1);
  EXPECT_LT(angle_deg(thumb_pad, thumb_to_index), 50);
  EXPECT_LT(angle_deg(index_pad, -thumb_to_index), 50);
}

TEST_P(HandKinematics, TripodFingertips) {
  const HandModel hand({.size = GetParam()});
  const Real hl = hand.hand_length();
  const JointAngles tripod = *named_posture("tripod");
  const HandPose pose = hand.forward_kinematics(tripod);
  // The index is drawn 10 degrees toward the middle finger.
  expect_near(pose.p_HTip[1], finger_tip(0, hl, 40, 60, 30, -10, 0), "index");
  expect_near(pose.p_HTip[2], finger_tip(1, hl, 40, 70, 0, 0, 0), "middle");
  expect_near(pose.p_HTip[0], thumb_tip(hl, 85, 15, 10, 15), "thumb");
  // The thumb's tip lies below the middle of the index and middle tips (2 mm off it along
  // the line between them, the tips 17 to 20 mm apart), and its pad faces them.
  const Vec3 across = pose.p_HTip[2] - pose.p_HTip[1];
  const Vec3 to_pair = (pose.p_HTip[1] + pose.p_HTip[2]) / 2 - pose.p_HTip[0];
  EXPECT_LT(std::abs(to_pair.dot(across.normalized())), across.norm() / 6);
  const Vec3 thumb_pad = -pose.X_HS[static_cast<std::size_t>(Segment::kThumbDistal)].R.col(1);
  EXPECT_LT(angle_deg(thumb_pad, to_pair), 50);
}

TEST(HandModel, TheThumbIsPronatedAboutItsMetacarpal) {
  // Flat hand: the metacarpal points 35 degrees away from the index in the palm's plane and
  // is turned 25 degrees about its own axis, so the thumb flexes toward the fingers as well
  // as toward the palm.
  const HandModel hand;
  const HandPose pose = hand.forward_kinematics(JointAngles{});
  const Transform& X_HM = pose.X_HS[static_cast<std::size_t>(Segment::kThumbMetacarpal)];
  const Real rest = P::kThumbRestDeg * kRad;
  const Vec3 axis = -X_HM.R.col(2);
  EXPECT_NEAR((axis - Vec3(-std::sin(rest), 0, -std::cos(rest))).norm(), 0, 1e-14);
  const Vec3 flexion_side = -X_HM.R.col(1);
  const Real pronation = P::kThumbPronationDeg * kRad;
  EXPECT_NEAR((flexion_side - Vec3(std::cos(rest) * std::sin(pronation), -std::cos(pronation),
                                   -std::sin(rest) * std::sin(pronation)))
                  .norm(),
              0, 1e-14);
  EXPECT_GT(flexion_side.x(), 0) << "toward the fingers";
}

TEST_P(HandKinematics, SpreadAndArch) {
  const HandModel hand({.size = GetParam()});
  const Real hl = hand.hand_length();
  JointAngles q{};
  at(q, Joint::kIndexMiddleAbd) = 12;
  at(q, Joint::kMiddleRingAbd) = 7;
  at(q, Joint::kRingPinkyAbd) = 15;
  at(q, Joint::kPalmArch) = 20;
  at(q, Joint::kRingMcp) = 30;
  const HandPose pose = hand.forward_kinematics(q);
  expect_near(pose.p_HTip[1], finger_tip(0, hl, 0, 0, 0, 12, 0), "index spreads toward the thumb");
  expect_near(pose.p_HTip[2], finger_tip(1, hl, 0, 0, 0, 0, 0), "middle is the reference");
  expect_near(pose.p_HTip[3], finger_tip(2, hl, 30, 0, 0, -7, 10), "ring");
  expect_near(pose.p_HTip[4], finger_tip(3, hl, 0, 0, 0, -22, 20), "pinky");
  EXPECT_LT(pose.p_HTip[1].x(), -1.5 * P::kSpacing * hl);
  EXPECT_GT(pose.p_HTip[4].x(), 1.5 * P::kSpacing * hl);
}

INSTANTIATE_TEST_SUITE_P(Sizes, HandKinematics, ::testing::Values("adult_m50", "adult_f05"));

TEST(HandModel, SizesScaleByHandLength) {
  const HandModel m50({.size = "adult_m50"});
  EXPECT_EQ(m50.hand_length(), 0.190);
  const HandModel f05({.size = "adult_f05"});
  EXPECT_EQ(f05.hand_length(), 0.160);
  const HandModel scaled({.size = "adult_m50", .hand_length = 0.2});
  EXPECT_DOUBLE_EQ(scaled.length(Segment::kIndexProximal), 0.265 * 0.2);
  EXPECT_DOUBLE_EQ(scaled.radius(Segment::kIndexDistal), 0.036 * 0.2);
  EXPECT_THROW(HandModel({.size = "giant"}), std::invalid_argument);
  EXPECT_THROW(HandModel({.size = "adult_m50", .hand_length = 2}), std::invalid_argument);
  EXPECT_THROW(HandModel({.size = "adult_m50", .hand_length = -0.1}), std::invalid_argument);
}

TEST(HandModel, LimitsClampAndMark) {
  JointAngles q = *named_posture("fist");
  at(q, Joint::kIndexPip) = 130;
  at(q, Joint::kPinkyMcp) = -50;
  at(q, Joint::kPalmArch) = std::nan("");
  std::bitset<kJointCount> clamped;
  const JointAngles out = clamp_to_limits(q, &clamped);
  EXPECT_EQ(at(out, Joint::kIndexPip),
            joint_limits()[static_cast<std::size_t>(Joint::kIndexPip)].max);
  EXPECT_EQ(at(out, Joint::kPinkyMcp),
            joint_limits()[static_cast<std::size_t>(Joint::kPinkyMcp)].min);
  EXPECT_EQ(at(out, Joint::kPalmArch), 0);
  EXPECT_EQ(clamped.count(), 3U);
  EXPECT_TRUE(clamped[static_cast<std::size_t>(Joint::kIndexPip)]);
  EXPECT_TRUE(clamped[static_cast<std::size_t>(Joint::kPinkyMcp)]);
  EXPECT_TRUE(clamped[static_cast<std::size_t>(Joint::kPalmArch)]);
  // Every named posture is within the limits.
  for (const std::string& name : posture_names()) {
    std::bitset<kJointCount> any;
    clamp_to_limits(*named_posture(name), &any);
    EXPECT_TRUE(any.none()) << name;
  }
}

TEST(HandModel, CapsuleProxyIsClosedAndTight) {
  const collision::Mesh mesh = capsule_mesh(0.03, 0.008);
  EXPECT_EQ(mesh.triangle_count(), 64U);
  const collision::Bounds b = collision::mesh_bounds(mesh);
  EXPECT_EQ(b.min.x(), -0.008);
  EXPECT_EQ(b.max.x(), 0.008);
  EXPECT_EQ(b.min.y(), -0.008);
  EXPECT_EQ(b.max.y(), 0.008);
  EXPECT_EQ(b.max.z(), 0.008);
  EXPECT_DOUBLE_EQ(b.min.z(), -0.038);
  // Closed: every edge is shared by exactly two triangles, in opposite directions.
  std::map<std::pair<std::uint32_t, std::uint32_t>, int> edges;
  for (const auto& t : mesh.triangles) {
    for (int i = 0; i < 3; ++i) ++edges[{t[i], t[(i + 1) % 3]}];
  }
  for (const auto& [edge, count] : edges) {
    EXPECT_EQ(count, 1);
    EXPECT_EQ(edges.count({edge.second, edge.first}), 1U);
  }
  // Outward: the signed volume is positive and below the true capsule's.
  Real volume = 0;
  for (const auto& t : mesh.triangles) {
    volume += mesh.vertices[t[0]].dot(mesh.vertices[t[1]].cross(mesh.vertices[t[2]])) / 6;
  }
  const Real r = 0.008, l = 0.03;
  EXPECT_GT(volume, 0);
  EXPECT_LT(volume, std::numbers::pi * r * r * l + 4.0 / 3.0 * std::numbers::pi * r * r * r);
}

TEST(HandModel, EverySegmentHasAProxyAndAName) {
  const HandModel hand;
  for (std::size_t i = 0; i < kSegmentCount; ++i) {
    const auto s = static_cast<Segment>(i);
    ASSERT_TRUE(hand.proxy(s)) << segment_name(s);
    EXPECT_EQ(segment_from_name(segment_name(s)), s);
  }
  EXPECT_EQ(segment_name(Segment::kIndexDistal), "index_distal");
  EXPECT_EQ(segment_name(Segment::kPalm), "palm");
  EXPECT_FALSE(segment_from_name("elbow"));
}

}  // namespace
}  // namespace dovetail::interaction

namespace dovetail::interaction {
namespace {

TEST(HandModel, TheThumbHasNoFingerKnuckle) {
  const HandModel hand;
  EXPECT_THROW(hand.knuckle(Digit::kThumb, 0), std::invalid_argument);
  EXPECT_THROW(hand.metacarpal_base(Digit::kThumb, 0), std::invalid_argument);
}

TEST(GloveSample, NonFiniteQuaternionsNormaliseToTheIdentity) {
  for (const Quaternion q : {Quaternion{1, std::nan(""), 0, 0}, Quaternion{std::nan(""), 1, 0, 0},
                             Quaternion{1, 0, INFINITY, 0}, Quaternion{0, 0, 0, 0}}) {
    const Quaternion n = normalized(q);
    EXPECT_EQ(n.w, 1);
    EXPECT_EQ(n.x, 0);
    EXPECT_EQ(n.y, 0);
    EXPECT_EQ(n.z, 0);
  }
}

}  // namespace
}  // namespace dovetail::interaction
