#pragma once
/// \file glove_plan.h
/// A plan for the simulated glove: timed targets for the tracker and the
/// fingers, and its text format.
///
/// Each step lasts `duration` seconds and starts where the previous one
/// ended. `reach` moves the tracker to a pose along a minimum-jerk profile
/// (position linearly and orientation by slerp in s(u) = 10u^3 - 15u^4 +
/// 6u^5); `path` goes through its poses one after another in equal shares of
/// the duration, each leg with the same profile; `close` moves every joint to
/// a posture with the same profile; `open` is `close` to the open hand;
/// `wait` holds. The fingers and the tracker move independently: `reach`
/// and `path` keep the posture, `close` and `open` keep the pose.
///
/// Text format, one step per line; `#` starts a comment that runs to the end
/// of the line, and blank lines are skipped:
///
///     start X Y Z QW QX QY QZ [POSTURE]    # optional, first: the pose at t = 0
///     reach DURATION X Y Z QW QX QY QZ
///     path DURATION X Y Z QW QX QY QZ [X Y Z QW QX QY QZ ...]
///     close DURATION POSTURE               # a name of named_posture()
///     close DURATION A1 ... A22            # or 22 angles in degrees
///     open DURATION
///     wait DURATION
///
/// The POSTURE of `start` is a name or 22 angles, as for `close`; without it
/// the hand starts open. Without `start` the hand starts at the origin with
/// the identity orientation. Quaternions are normalised on reading.
///
/// Positions in metres, durations in seconds (>= 0, finite). Errors name the
/// file and the line (`plan.txt:3: ...`): an unknown keyword, a wrong number
/// of fields, a field that is not a number or not finite, a negative
/// duration, a zero quaternion, an unknown posture, a `start` that is not the
/// first step or comes twice; a plan without steps is refused
/// (`plan.txt: plan has no steps`).

#include <filesystem>
#include <iosfwd>
#include <stdexcept>
#include <string_view>
#include <vector>

#include "dovetail/interaction/glove_sample.h"

namespace dovetail::interaction {

/// Thrown for a plan that cannot be read; what() starts with `file:line: `.
class PlanError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

/// A tracker pose as it is written: position and quaternion.
struct TrackerPose {
  Vec3 p_WH = Vec3::Zero();
  Quaternion q_WH{};
};

/// One step of a plan.
struct PlanStep {
  enum class Kind { kReach, kPath, kClose, kOpen, kWait };
  Kind kind = Kind::kWait;
  Real duration = 0;                 ///< seconds, >= 0
  std::vector<TrackerPose> poses{};  ///< reach: one; path: one or more
  JointAngles posture{};             ///< close: the target angles
};

/// What the simulated glove does, from t = 0.
struct GlovePlan {
  TrackerPose start{};          ///< the pose at t = 0
  JointAngles start_posture{};  ///< the angles at t = 0 (the open hand)
  std::vector<PlanStep> steps{};
  /// Sum of the steps' durations.
  Real duration() const;
};

/// Parses a plan; `name` is the file name used in messages.
GlovePlan read_plan(std::istream& in, std::string_view name);
/// Reads the plan file at `path`; throws PlanError when it is missing or bad.
GlovePlan read_plan(const std::filesystem::path& path);

}  // namespace dovetail::interaction
