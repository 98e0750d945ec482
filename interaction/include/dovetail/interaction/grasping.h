#pragma once
/// \file grasping.h
/// Natural grasping, rubber-band sliding and mates for one hand in a
/// simulation (frame step 3, docs/engine.md "One frame, in order").
///
/// Why: the glove says how far the user closes the hand, not what the hand
/// touches. Each frame the fingers close from their last free posture toward
/// the glove's, each stopping at its first contact with a part; the contacts
/// within a small gap are analysed, and when they oppose each other for a
/// few frames while the hand closes, the part is grasped (precision, 3-point
/// pinch or power) and keeps its pose in the hand, X_HO. It then follows the
/// hand through a rubber band (sliding.h) and is released when the fingers
/// open several degrees past where they were at the grasp. A released part
/// near a declared mate snaps into place. Everything is kinematic, exact and
/// deterministic: the same trace gives the same bits at any thread count.

#include <cstdint>
#include <deque>
#include <map>
#include <memory>
#include <optional>
#include <span>
#include <string>
#include <string_view>
#include <vector>

#include "dovetail/engine/simulation.h"
#include "dovetail/interaction/hand.h"
#include "dovetail/interaction/sliding.h"

namespace dovetail::interaction {

/// The grasp types of Cutkosky's taxonomy that the contact analysis tells apart.
enum class GraspType : std::uint8_t {
  kPrecision,  ///< thumb tip opposing the index or middle tip
  kTripod,     ///< 3-point pinch: thumb tip opposing both index and middle tips
  kPower,      ///< palm and at least two fingers around the part, a finger opposing the palm
};
/// "precision", "tripod", "power": the `b` of a grasp event.
std::string_view grasp_type_name(GraspType type);

/// A hand segment within the contact gap of a part.
struct GraspContact {
  Segment segment = Segment::kPalm;
  Vec3 p_W = Vec3::Zero();   ///< the contact point on the part
  Vec3 n_W = Vec3::UnitY();  ///< the part's outward unit normal there
};

/// The grasp that contacts on one part form, or nullopt (the rules of
/// docs/interaction.md, "Contact analysis"): power (palm and two finger
/// segments, one opposing the palm, or one of the palm's contacts: the palm
/// may touch in several places), tripod (thumb, index and middle tips, the
/// thumb opposing index and middle as one virtual finger), precision (the thumb
/// tip opposing the index or middle tip), in that order. Two contacts oppose
/// when the line between them lies inside both friction cones, half-angle
/// atan(friction). A pure function of its arguments.
std::optional<GraspType> classify_grasp(std::span<const GraspContact> contacts, Real friction);

/// When a grasp begins and ends (defaults: notes/grasping.md).
struct GraspSettings {
  Real contact_gap = 0.0002;  ///< a segment within this of a part touches it (GraspIt!'s 0.2 mm)
  /// The palm within this of a part touches it: its pads give by millimetres
  /// under a grip (the proxy is rigid), and the fingers wrapping round a
  /// handle draw it in.
  Real palm_gap = 0.002;
  Real friction = 0.5;   ///< mu: contacts oppose inside cones of half-angle atan(mu)
  int onset_frames = 3;  ///< the grasp must hold this many frames while the hand closes
  /// A grasping digit opened this far past its flexion at the grasp releases
  /// (or half of what it closed while the grasp built up, when that is less,
  /// once it has closed this far past its flexion at the grasp).
  Real release_open_deg = 8;
  Real release_time_s = 0.05;       ///< ... for this long releases the part
  int finger_bisection_steps = 12;  ///< halvings toward a finger's first contact (0.02 deg)
};

/// A declared fit between a feature of one part and a feature of another:
/// a point and an axis in each part's frame.
///
/// Guidance: while `part` is carried with its target's feature point within
/// the position tolerance of the other's axis line, the axes within the
/// angle tolerance, and the two parts' spans along the axis (of their
/// bounding boxes) overlapping, the other's widened by the position
/// tolerance, the band pulls it onto the axis: the target turned by the least
/// rotation onto the other's axis and moved onto the line (a peg held a
/// little off a hole's axis is drawn in as it reaches the hole, as a chamfer
/// would draw it, not left on the rim; held above the hole it keeps its
/// misalignment). Once drawn, it stays drawn until three times the
/// tolerances away.
/// Snap: when `part` is released with its point within the position
/// tolerance of the other's point and the axes within the angle tolerance,
/// its axis turns onto the other's (the least turn), its point onto the
/// other's point, and a mate event fires.
struct Mate {
  std::string name{};
  std::string part{};           ///< the part that is carried and snaps
  Vec3 p_PF = Vec3::Zero();     ///< its feature point, in its frame
  Vec3 axis_P = Vec3::UnitY();  ///< its feature axis, in its frame
  std::string other{};          ///< the part it fits onto
  Vec3 p_OF = Vec3::Zero();
  Vec3 axis_O = Vec3::UnitY();
  Real position_tolerance = 0.002;  ///< metres
  Real angle_tolerance_deg = 5;
  /// Whether the carried part is drawn onto the axis (guidance); false keeps
  /// its misalignment, as a fit without a chamfer would, and it only snaps.
  bool guide = true;
};

/// How far a mate's part is from its place: the distance between the two
/// feature points (metres) and the angle between the two axes (degrees).
struct MateOffset {
  Real distance_m = 0;
  Real angle_deg = 0;
  /// The distance split along the other part's axis (positive: the part's
  /// point is still out along it, short of its place) and across it.
  Real along_m = 0;
  Real across_m = 0;
};
/// The offset with the part at X_WP and the other at X_WO.
MateOffset mate_offset(const Mate& mate, const Transform& X_WP, const Transform& X_WO);
/// Whether the part at X_WP is within the mate's tolerances: released now, it would snap.
bool within_tolerance(const Mate& mate, const Transform& X_WP, const Transform& X_WO);
/// The part's pose in place: X_WP turned by the least rotation that brings its
/// axis onto the other's (half a turn about an axis normal to both when they
/// are opposite), then moved so the two feature points meet.
Transform mate_pose(const Mate& mate, const Transform& X_WP, const Transform& X_WO);

/// A released part that was within a mate's tolerances but was not snapped:
/// in place it would overlap another part (a screw head in the way, a bore
/// too small), which no real part can do.
struct RefusedSnap {
  std::string mate{};
  std::string part{};     ///< the mate's part: the released part, or one of its sub-assembly
  std::string blocker{};  ///< the part it would overlap most deeply
  /// The part that would overlap it: a part of the moved sub-assembly.
  std::string overlapping{};
  Real depth_m = 0;  ///< how deep (OverlapGauge, as max_penetration measures)
  Real time = 0;     ///< when it was released
};

/// A part in place may touch others; it is refused a snap only when it
/// would overlap one deeper than this (metres).
inline constexpr Real kSnapOverlap = 1e-6;

/// What the interaction of one hand does, and its settings.
struct InteractionSettings {
  GraspSettings grasp{};
  SlidingSettings sliding{};
};

/// Per-frame work counters.
struct InteractionStats {
  std::uint64_t finger_queries = 0;   ///< collision tests while closing fingers
  std::uint64_t contact_queries = 0;  ///< tolerance tests of the contact analysis
  std::uint64_t slide_queries = 0;    ///< collision tests and contact queries of sliding
  Real max_stretch_m = 0;             ///< largest band stretch of the run
  /// Wall-clock milliseconds of the last frame's interaction work (closing the
  /// fingers, contact analysis, sliding); for benchmarks, never in a report.
  double frame_ms = 0;
};

/// Grasping, sliding and mates for one Hand in one Simulation.
class Grasping {
 public:
  /// Installs a finger limiter on the hand, a frame hook (after the hand's)
  /// and an event filter on the simulation. Both must outlive their use.
  Grasping(engine::Simulation& simulation, Hand& hand, const InteractionSettings& settings);
  Grasping(engine::Simulation& simulation, Hand& hand);
  ~Grasping();
  Grasping(const Grasping&) = delete;
  Grasping& operator=(const Grasping&) = delete;

  /// Declares a mate; throws engine::SceneError for an unknown part.
  void add_mate(const Mate& mate);
  /// Makes the hand hold `part` from now on with grasp `type`, as if grasped
  /// (for scenarios that start with a part in hand). Throws engine::SceneError
  /// for an unknown part or one without a collision mesh.
  void hold(const std::string& part, GraspType type);

  /// The part held, if any.
  const std::optional<std::string>& held() const { return held_; }
  std::optional<GraspType> grasp_type() const {
    return held_ ? std::optional(type_) : std::nullopt;
  }
  /// The part the hand carries: the held part, or the part it is attached to
  /// (through any number of parts) that is attached to none; the whole
  /// sub-assembly under it moves with the hand.
  const std::optional<std::string>& carried() const { return carried_; }
  /// X_HO of the part carried.
  const Transform& X_HO() const { return X_HO_; }
  /// The last sliding step of the part held.
  const SlideResult& last_slide() const { return last_slide_; }
  const InteractionStats& stats() const { return stats_; }
  /// Every snap refused so far, in order.
  const std::vector<RefusedSnap>& refused_snaps() const { return refused_snaps_; }
  /// Why the hand never grasped `part`, for a report: its closest try (the
  /// frame in which most of its segments touched the part while it held
  /// nothing and closed, or, when it never touched it closing, while it held
  /// nothing), what touched and what the grasp lacked, or that it never
  /// touched it.
  std::string why_not_grasped(const std::string& part) const;
  /// The time of why_not_grasped's try at the part, if the hand touched it.
  std::optional<Real> closest_try_time(const std::string& part) const {
    const auto it = attempts_.find(part);
    return it == attempts_.end() ? std::nullopt : std::optional<Real>(it->second.time);
  }

 private:
  struct Models;
  void limit_fingers(const HandModel& model, const Transform& X_WH, const JointAngles& previous,
                     JointAngles& angles);
  void update(engine::Simulation& simulation, std::uint64_t frame, Real t);
  std::vector<engine::PartId> candidates(const engine::Scene& scene, const Transform& X_WH,
                                         Real reach) const;
  std::vector<GraspContact> touches(const engine::Scene& scene, engine::PartId part);
  /// The held part and the parts attached to it, which move with it.
  struct MovingBodies {
    std::vector<engine::PartId> parts;      ///< the part, then its attachments (SlideContact::body)
    std::vector<SlideAttachment> attached;  ///< the attachments, in the part's frame
    collision::Bounds local;                ///< a box around all of them, in the part's frame
  };
  MovingBodies moving_bodies(const engine::Scene& scene, engine::PartId part);
  void carry(engine::Simulation& simulation);
  /// slide_begin and slide_end for the pairs (moving body, obstacle) whose contacts
  /// appeared or went in the last slide, `bodies` and `handles` naming its indices.
  void report_sliding(const engine::Scene& scene, std::span<const engine::PartId> bodies,
                      std::span<const engine::PartId> handles, std::uint64_t frame, Real t);
  /// The part carried when `part` is held: the top of its sub-assembly.
  static engine::PartId carried_root(const engine::Scene& scene, engine::PartId part);
  /// `part`'s pose in the frame of `root`, which it descends from, from the
  /// chain of local poses (the same bits every frame).
  static Transform pose_in(const engine::Scene& scene, engine::PartId root, engine::PartId part);
  /// A mate's part and other when its part is in `root`'s sub-assembly and its
  /// other is outside it (a mate inside it moves with it); nullopt otherwise.
  static std::optional<std::pair<engine::PartId, engine::PartId>> outward_mate(
      const engine::Scene& scene, const Mate& mate, engine::PartId root);
  /// The pose of `root` that puts `part`, which descends from it, at X_WP.
  static Transform root_pose_for(const engine::Scene& scene, engine::PartId root,
                                 engine::PartId part, const Transform& X_WP);
  /// Where the hand at X_WH puts `part`: the carried sub-assembly's parts by
  /// the grasp, the others where they are.
  Transform carried_pose(const engine::Scene& scene, engine::PartId part,
                         const Transform& X_WH) const;
  /// The carried part's target, moved so that the first guiding mate of a part
  /// of its sub-assembly whose capture region the move reaches draws that part
  /// onto its axis.
  Transform guided(const engine::Scene& scene, engine::PartId root, const Transform& X_WR_target);
  /// Where `part` at X_WP lies along a mate's axis: the least and the
  /// greatest b_W . (x - q_W) over the corners of its world bounding box.
  std::pair<Real, Real> extent_along(const engine::Scene& scene, engine::PartId part,
                                     const Transform& X_WP, const Vec3& q_W, const Vec3& b_W);
  void release(engine::Simulation& simulation, const std::string& reason);
  /// Seats the sub-assembly of the released `part` by the first of its mates
  /// within tolerance whose seat overlaps nothing.
  void snap(engine::Simulation& simulation, const std::string& part);
  /// The deepest overlap of `part` at X_WP, or of a part attached to it and
  /// moved with it, with another part (none of them counted).
  struct Overlap {
    std::string overlapping;  ///< `part` or the attached part that overlaps
    std::string blocker;      ///< the part it overlaps
    Real depth = 0;           ///< how deep; 0 when nothing overlaps
  };
  Overlap deepest_overlap(const engine::Scene& scene, engine::PartId part, const Transform& X_WP);

  engine::Simulation* simulation_;
  Hand* hand_;
  InteractionSettings settings_;
  std::unique_ptr<Models> models_;
  std::vector<Mate> mates_;
  std::vector<engine::Event> pending_;

  std::optional<std::string> held_;
  std::optional<std::string> carried_;  ///< see carried()
  GraspType type_ = GraspType::kPrecision;
  Transform X_HO_{};
  std::array<Real, kDigitCount> flexion_at_grasp_{};
  /// How far below flexion_at_grasp_ a grasping digit that closed
  /// release_open_deg past it since may open to release: half of what it
  /// closed while the grasp built up, at most release_open_deg.
  std::array<Real, kDigitCount> release_opening_{};
  /// Each digit's largest glove flexion since the grasp.
  std::array<Real, kDigitCount> peak_flexion_{};
  std::array<bool, kDigitCount> grasping_digit_{};
  Real opened_since_ = -1;  ///< time the release condition began to hold; < 0: not holding
  std::string candidate_;   ///< part whose grasp is building up
  GraspType candidate_type_ = GraspType::kPrecision;
  int candidate_frames_ = 0;
  int candidate_misses_ = 0;          ///< frames in a row the candidate's grasp was not found
  Real candidate_start_flexion_ = 0;  ///< total glove flexion the frame before the candidate
  /// Each digit's glove flexion the frame before the candidate.
  std::array<Real, kDigitCount> candidate_start_digits_{};
  Real last_flexion_ = 0;
  std::array<Real, kDigitCount> last_digit_flexion_{};
  /// When the part was grasped: for a moment after, each digit's flexion at
  /// the grasp follows the glove down, so that a grasp taken from one noisy
  /// sample (`holding`'s first) does not sit above the closed hand.
  Real grasped_at_ = 0;
  std::array<Real, kDigitCount>
      settle_floor_{};  ///< the lowest the flexion at the grasp settles to
  /// The total glove flexion low-passed, and its values over the last
  /// moments (time, value): how much the hand closed lately, which the
  /// noise of 15 joints does not fake, decides a grasp's onset.
  Real smoothed_flexion_ = 0;
  Real last_time_ = 0;
  bool smoothed_started_ = false;
  std::deque<std::pair<Real, Real>> smoothed_window_;
  Real candidate_start_smoothed_ = 0;  ///< smoothed_flexion_ the frame before the candidate
  Real last_smoothed_ = 0;
  Real candidate_closing_ = 0;  ///< the most the hand closed lately while the candidate built up
  std::optional<std::size_t> guiding_;  ///< the mate drawing the held part onto its axis
  /// What slides on what, sorted: (the held part or a part attached to it, the part it
  /// has a contact with), as the last slide_begin events said.
  std::vector<std::pair<std::string, std::string>> sliding_pairs_;
  SlideResult last_slide_{};
  SlideFronts fronts_;                          ///< of the held part, against each obstacle
  std::vector<engine::PartId> contact_parts_;   ///< the parts of last_slide_'s obstacle ids
  std::vector<engine::PartId> contact_bodies_;  ///< and of its moving bodies (SlideContact::body)
  InteractionStats stats_{};
  std::vector<RefusedSnap> refused_snaps_;
  /// Per part: the frame in which most hand segments touched it while the
  /// hand held nothing, for why_not_grasped; one while the hand was closing
  /// comes before any while it was not (which could grasp nothing).
  struct Attempt {
    Real time = 0;
    std::vector<Segment> touching;
    std::optional<GraspType> type;  ///< the grasp the contacts made, if any
    bool closing = false;           ///< the hand had closed enough lately to grasp
  };
  std::map<std::string, Attempt> attempts_;
};

}  // namespace dovetail::interaction
