#pragma once
/// \file hand.h
/// The hand in a simulation: each frame it reads its glove source, limits
/// the joint angles, runs the forward kinematics and poses one scene part per
/// segment, the "invisible hand" the collision pipeline checks against the
/// parts in the same frame; contacts of its segments become hand_contact
/// events that name the segment's part (`hand.index_distal`); every sample it
/// used is recorded.
///
/// Why: frame steps 1 and 2 (input, hand; docs/engine.md) belong together
/// and to nobody else. The segments are ordinary scene parts (named
/// `<name>.<segment>`, tagged `hand`, in one collision group so they are never
/// tested against each other, drawn in the hand's colour), so the pipeline,
/// the state hash, reports and renders treat them like any other part.

#include <array>
#include <cstdint>
#include <functional>
#include <map>
#include <memory>
#include <string>
#include <vector>

#include "dovetail/engine/render.h"
#include "dovetail/engine/simulation.h"
#include "dovetail/interaction/glove_source.h"
#include "dovetail/interaction/hand_model.h"

namespace dovetail::interaction {

/// The colour of the hand in renders (a light skin tone, unlike every
/// palette colour and the highlight).
inline constexpr std::array<float, 3> kHandColor = {0.96F, 0.76F, 0.62F};

/// The hand of one glove sample as render items, one per segment named
/// `<name>.<segment>` in kHandColor, the angles clamped to their limits: for
/// drawing the hand without a simulation (`dovetail render --trace`).
std::vector<engine::RenderItem> hand_render_items(const HandModel& model, const GloveSample& sample,
                                                  const std::string& name = "hand");

/// The name of a hand unless it is given another.
inline constexpr const char* kDefaultHandName = "hand";

/// How to put a hand into a simulation.
struct HandSettings {
  HandDef model{};
  /// Prefix of the segment parts' names, their collision group.
  std::string name = kDefaultHandName;
  /// Keep every sample used, for recorded() and write_trace.
  bool record = true;
};

/// A glove-driven hand attached to one simulation.
class Hand {
 public:
  /// Adds the segment parts to the simulation's scene at the pose of the
  /// source's sample at the simulation's current time, and installs a frame
  /// hook and an event filter on the simulation. The Hand must outlive the
  /// simulation's use of them (it is neither copied nor moved). Throws
  /// engine::SceneError when a segment's name is taken, std::invalid_argument
  /// for a null source or a bad hand definition; then nothing was added. A
  /// segment later removed from the scene is no longer posed.
  Hand(engine::Simulation& simulation, std::shared_ptr<const GloveSource> source,
       const HandSettings& settings);
  /// A hand with the default settings.
  Hand(engine::Simulation& simulation, std::shared_ptr<const GloveSource> source);
  Hand(const Hand&) = delete;
  Hand& operator=(const Hand&) = delete;

  const HandModel& model() const { return model_; }
  const GloveSource& source() const { return *source_; }
  /// The sample of the last frame as the source gave it.
  const GloveSample& sample() const { return sample_; }
  /// Its joint angles within limits: what the glove asks for.
  const JointAngles& glove_angles() const { return glove_angles_; }
  /// The angles the hand shows and collides with: the glove's, unless a
  /// finger limiter (natural grasping) stopped a finger at its first contact.
  const JointAngles& angles() const { return angles_; }

  /// Called each frame after the glove is read and before the kinematics,
  /// with the hand pose X_WH, the angles shown in the last frame and the
  /// glove's angles within limits, which it may change (never past the limits).
  using FingerLimiter = std::function<void(const HandModel& model, const Transform& X_WH,
                                           const JointAngles& previous, JointAngles& angles)>;
  void set_finger_limiter(FingerLimiter limiter) { limiter_ = std::move(limiter); }
  /// Its segment poses in H, and X_WH.
  const HandPose& pose() const { return pose_; }
  const Transform& X_WH() const { return X_WH_; }
  /// The scene part of a segment.
  engine::PartId part(Segment segment) const { return parts_[static_cast<std::size_t>(segment)]; }
  /// The segment of a part name of this hand, or nullopt.
  std::optional<Segment> segment_of(const std::string& part_name) const;

  /// Every sample used, one per frame in frame order (when recording).
  const std::vector<GloveSample>& recorded() const { return recorded_; }
  /// Frames in which each joint was clamped to its limit.
  const std::array<std::uint64_t, kJointCount>& clamped_frames() const { return clamped_frames_; }

 private:
  void update(engine::Simulation& simulation, std::uint64_t frame, Real t);
  void filter(const engine::Scene& scene, std::vector<engine::Event>& events);
  /// Turns the segments' region events into the hand's: it enters a region
  /// as its first segment does and leaves it as its last one does.
  void merge_region_events(std::vector<engine::Event>& events);
  void pose_parts(engine::Scene& scene) const;

  HandModel model_;
  std::shared_ptr<const GloveSource> source_;
  HandSettings settings_;
  std::array<engine::PartId, kSegmentCount> parts_{};
  std::map<std::string, Segment, std::less<>> segment_by_part_;
  GloveSample sample_{};
  JointAngles glove_angles_{};
  JointAngles angles_{};
  FingerLimiter limiter_;
  HandPose pose_{};
  Transform X_WH_{};
  std::vector<GloveSample> recorded_;
  std::array<std::uint64_t, kJointCount> clamped_frames_{};
  /// Per region: how many of its segments are inside.
  std::map<std::string, std::size_t, std::less<>> segments_inside_;
};

}  // namespace dovetail::interaction
