#pragma once
/// \file hand_model.h
/// The hand as a kinematic chain: the hand frame H from the tracker, then
/// the palm, the thumb and four fingers with their flexion joints and
/// abductions, and the palm arch; one collision proxy per segment.
///
/// Why: the glove gives 22 angles and the tracker one pose; grasping and the
/// invisible hand need the pose of every finger segment. The model is the
/// one place where angles become geometry, so the OpenXR importer inverts
/// exactly this chain and the tests check fingertips against values worked
/// out by hand.
///
/// Frames (the OpenXR convention, right hand): H sits at the wrist, -Z points
/// along the fingers, +Y out of the back of the hand, +X toward the little
/// finger (the thumb is on the -X side). A segment frame S sits at the
/// segment's proximal joint with its bone along -Z and +Y on the back of the
/// finger. Flexion turns a segment toward the palm (-Y), abduction spreads a
/// finger away from the middle finger, palm arch cups the ring and little
/// metacarpals toward the palm. The thumb's metacarpal is pronated about its
/// own axis, so the thumb flexes, and its pad faces, toward the fingers as
/// well as toward the palm. Segment lengths are Buchholz, Armstrong and
/// Goldstein's coefficients times the hand length (wrist crease to the tip
/// of the middle finger). The tracker is on the hand, so the wrist angles
/// are carried and limited but move no segment (the forearm is not modelled).

#include <array>
#include <bitset>
#include <cstdint>
#include <memory>
#include <optional>
#include <span>
#include <string>
#include <string_view>
#include <vector>

#include "dovetail/collision/mesh.h"
#include "dovetail/interaction/glove_sample.h"

namespace dovetail::interaction {

/// The hand's rigid segments, each with a collision proxy.
enum class Segment : std::uint8_t {
  kPalm,
  kThumbMetacarpal,
  kThumbProximal,
  kThumbDistal,
  kIndexProximal,
  kIndexIntermediate,
  kIndexDistal,
  kMiddleProximal,
  kMiddleIntermediate,
  kMiddleDistal,
  kRingProximal,
  kRingIntermediate,
  kRingDistal,
  kPinkyProximal,
  kPinkyIntermediate,
  kPinkyDistal,
};
inline constexpr std::size_t kSegmentCount = 16;

/// "palm", "thumb_metacarpal", "index_distal", ...
std::string_view segment_name(Segment segment);
std::optional<Segment> segment_from_name(std::string_view name);

/// The five digits, thumb first.
enum class Digit : std::uint8_t { kThumb, kIndex, kMiddle, kRing, kPinky };
inline constexpr std::size_t kDigitCount = 5;

/// A joint's range in degrees.
struct JointLimit {
  Real min = 0;
  Real max = 0;
};
/// The range of every joint (see docs/interaction.md for the sources).
const std::array<JointLimit, kJointCount>& joint_limits();

/// Angles clamped to joint_limits(); `clamped` marks the joints that were out
/// of range. A NaN is marked and becomes 0 clamped into the range.
JointAngles clamp_to_limits(const JointAngles& angles, std::bitset<kJointCount>* clamped = nullptr);

/// A joint that samples take outside its range: where it is worst.
struct JointExcursion {
  Joint joint{};
  Real angle = 0;    ///< degrees, at the worst sample
  Real t = 0;        ///< that sample's time
  Real outside = 0;  ///< degrees past the nearer end of the range
};
/// The joints some sample takes more than `margin` degrees outside
/// joint_limits(), in joint order: a glove's noise goes a degree or two past
/// a range, tens of degrees are another unit or a column misnamed.
std::vector<JointExcursion> joints_outside(std::span<const GloveSample> samples, Real margin);
/// The margin past which a trace's excursion is worth a warning (degrees).
inline constexpr Real kFarOutsideRange = 10;
/// "index_mcp reaches 500 deg at t=0.011 s, outside its range [-30, 90] by 410 deg".
std::string describe(const JointExcursion& excursion);

/// A named hand size: its hand length in metres.
struct HandSize {
  std::string_view name;
  Real hand_length = 0;
};
/// The named sizes: adult_m50 (190 mm), adult_f50 (175 mm), adult_m95
/// (205 mm), adult_f05 (160 mm).
std::span<const HandSize> hand_sizes();

/// How to make a hand.
struct HandDef {
  std::string size = "adult_m50";  ///< a name of hand_sizes()
  Real hand_length = 0;            ///< metres; 0: the size's own; otherwise the size scaled to it
};

/// The proportions of a hand, as fractions of the hand length, and its
/// kinematic constants. Public so tests can work fingertips out by hand.
struct HandProportions {
  /// Metacarpal, proximal, intermediate, distal of index..pinky (Buchholz et al. 1992).
  static constexpr std::array<std::array<Real, 4>, 4> kFinger = {{{0.374, 0.265, 0.143, 0.097},
                                                                  {0.373, 0.277, 0.170, 0.108},
                                                                  {0.336, 0.259, 0.165, 0.107},
                                                                  {0.295, 0.206, 0.117, 0.093}}};
  /// Thumb metacarpal, proximal, distal.
  static constexpr std::array<Real, 3> kThumb = {0.251, 0.196, 0.158};
  /// Wrist crease to the carpometacarpal joints: the rest of the hand
  /// length, so the flat middle fingertip lies at exactly one hand length.
  static constexpr Real kCarpal = 1 - (0.373 + 0.277 + 0.170 + 0.108);
  /// Spacing of the fingers across the palm: index..pinky at x = (-1.5,
  /// -0.5, 0.5, 1.5) * kSpacing.
  static constexpr Real kSpacing = 0.11;
  /// Thumb carpometacarpal joint in H: on the palm's radial side (the index
  /// ray is at x = -0.165), at its palmar face (y = -0.055), a little distal
  /// of the fingers' carpometacarpal joints (z = -0.072).
  static constexpr std::array<Real, 3> kThumbBase = {-0.18, -0.05, -0.10};
  /// Thumb metacarpal's rest angle away from the index (degrees, about +Y).
  static constexpr Real kThumbRestDeg = 35;
  /// Pronation of the thumb metacarpal about its own long axis (degrees):
  /// it turns the thumb's flexion plane, and its pad, toward the fingers.
  static constexpr Real kThumbPronationDeg = 25;
  /// Share of palm_arch at the ring and little metacarpals.
  static constexpr Real kArchRing = 0.5;
  static constexpr Real kArchPinky = 1.0;
  /// Capsule radii of proximal, intermediate, distal finger segments and of
  /// the thumb's metacarpal, proximal, distal.
  static constexpr std::array<Real, 3> kFingerRadius = {0.045, 0.040, 0.036};
  static constexpr std::array<Real, 3> kThumbRadius = {0.060, 0.048, 0.043};
  /// The little finger is this much thinner.
  static constexpr Real kPinkyRadiusScale = 0.85;
  /// Palm half-thickness toward the palm (-Y) and toward the back (+Y).
  static constexpr Real kPalmPalmar = 0.055;
  static constexpr Real kPalmDorsal = 0.035;
};

/// The pose of every segment in H, and the fingertips.
struct HandPose {
  std::array<Transform, kSegmentCount> X_HS{};  ///< by Segment
  std::array<Vec3, kDigitCount> p_HTip{};       ///< fingertip of each digit, by Digit
};

/// A hand of one size: segment lengths, proxies, forward kinematics.
class HandModel {
 public:
  /// Throws std::invalid_argument for an unknown size or a hand length that
  /// is not in (0.05, 0.5) metres.
  explicit HandModel(const HandDef& def = {});

  Real hand_length() const { return hand_length_; }
  const std::string& size_name() const { return size_name_; }
  /// Bone length of a segment (the palm: wrist to the middle finger's knuckle).
  Real length(Segment segment) const { return length_[static_cast<std::size_t>(segment)]; }
  /// Capsule radius of a segment (the palm: its half-thickness toward the palm).
  Real radius(Segment segment) const { return radius_[static_cast<std::size_t>(segment)]; }
  /// The collision (and render) proxy of a segment, in the segment's frame.
  const std::shared_ptr<const collision::Mesh>& proxy(Segment segment) const {
    return proxy_[static_cast<std::size_t>(segment)];
  }

  /// The palm cut across its width into four strips, one under each
  /// finger's ray, in the palm's frame: where along a handle the palm
  /// touches it, for the power grasp's opposition.
  const std::array<std::shared_ptr<const collision::Mesh>, 4>& palm_strips() const {
    return palm_strips_;
  }

  /// Segment poses in H for joint angles that are already within limits
  /// (clamp_to_limits); the wrist angles are ignored.
  HandPose forward_kinematics(const JointAngles& angles) const;

  /// The knuckle (metacarpophalangeal joint) of finger `digit` in H with the
  /// palm arch `arch_deg`, and the metacarpal's base; std::invalid_argument
  /// for the thumb.
  Vec3 knuckle(Digit digit, Real arch_deg) const;
  Vec3 metacarpal_base(Digit digit, Real arch_deg) const;

 private:
  std::string size_name_;
  Real hand_length_ = 0;
  std::array<Real, kSegmentCount> length_{};
  std::array<Real, kSegmentCount> radius_{};
  std::array<std::shared_ptr<const collision::Mesh>, 4> palm_strips_{};
  std::array<std::shared_ptr<const collision::Mesh>, kSegmentCount> proxy_{};
};

/// Rotations about the axes by an angle in degrees (the hand's joints).
Mat3 rotation_x_deg(Real degrees);
Mat3 rotation_y_deg(Real degrees);
Mat3 rotation_z_deg(Real degrees);

/// A capsule from (0, 0, 0) to (0, 0, -length) of `radius` as a closed
/// convex triangle mesh: 8 vertices around, two rings per cap, 64 triangles;
/// its vertices lie on the capsule, with ones pointing along +-X and +-Y.
collision::Mesh capsule_mesh(Real length, Real radius);

}  // namespace dovetail::interaction
