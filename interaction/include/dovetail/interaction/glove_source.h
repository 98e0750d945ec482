#pragma once
/// \file glove_source.h
/// Where the hand's input comes from: one interface that yields the glove
/// sample for a simulation time, with three implementations (a recorded
/// trace, the simulated glove, and a noise and latency model on top of
/// either).
///
/// Why: a run, a replay and a test differ only in their source. A source is
/// a pure function of time: the same t gives the same bits whatever was asked
/// before, so a run replays exactly and sources can be sampled at any rate.

#include <cstdint>
#include <memory>
#include <vector>

#include "dovetail/interaction/glove_plan.h"
#include "dovetail/interaction/glove_sample.h"

namespace dovetail::interaction {

/// Yields the sample for simulation time t (seconds).
class GloveSource {
 public:
  virtual ~GloveSource() = default;
  /// The sample at time t; its `t` is t. A pure function of t.
  virtual GloveSample sample(Real t) const = 0;
  /// The time after which the source does not change any more (the end of
  /// a trace or a plan; NoisyGlove: only its noise changes after it).
  virtual Real end_time() const = 0;
};

/// A recorded trace. Between two samples the joints and the position are
/// interpolated linearly and the orientation by slerp; at a sample's own time
/// the sample is returned bit for bit; before the first sample the first is
/// held, after the last the last.
class TraceSource final : public GloveSource {
 public:
  /// Throws std::invalid_argument for an empty trace or times that do not
  /// increase (read_trace already refuses both).
  explicit TraceSource(std::vector<GloveSample> samples);
  GloveSample sample(Real t) const override;
  Real end_time() const override;
  const std::vector<GloveSample>& samples() const { return samples_; }

 private:
  std::vector<GloveSample> samples_;
};

/// The simulated glove: a GlovePlan turned into samples (see glove_plan.h
/// for how each step moves the hand). Before t = 0 the start is held, after
/// the plan's end its final state. At a step's start the pose and the angles
/// are those the previous steps ended on, bit for bit; a step of zero duration
/// jumps. Quaternions need not be unit length: they are normalised for slerp,
/// and the ends of a move keep them as given.
class SimulatedGlove final : public GloveSource {
 public:
  /// Throws std::invalid_argument for a negative or non-finite duration (or a
  /// total that overflows), a reach without exactly one pose or a path without poses.
  explicit SimulatedGlove(GlovePlan plan);
  GloveSample sample(Real t) const override;
  /// The plan's duration.
  Real end_time() const override;
  const GlovePlan& plan() const { return plan_; }

 private:
  GlovePlan plan_;
  // Entry i is where step i starts; entry steps.size() is the end of the plan,
  // so sample(t) finds its step by binary search and needs no earlier step.
  std::vector<Real> step_start_;            ///< start time of each step, then the end
  std::vector<TrackerPose> start_pose_;     ///< the pose at each of those times
  std::vector<JointAngles> start_posture_;  ///< the angles at each of those times
};

/// How a real glove and tracker distort what the hand does. The defaults are
/// typical of a CyberGlove with a magnetic tracker (see docs/interaction.md).
struct GloveNoise {
  std::uint64_t seed = 1;
  Real joint_sigma_deg = 0.5;         ///< white noise per joint and reading
  Real donning_sigma_deg = 3.0;       ///< offset per joint, drawn once (glove put on)
  Real degrees_per_count = 1.0;       ///< 8-bit quantisation step; 0: none
  Real position_sigma_m = 0.001;      ///< tracker position noise per axis
  Real orientation_sigma_deg = 0.15;  ///< tracker orientation noise (rotation vector per axis)
  Real rate_hz = 120;                 ///< the glove's own reading rate; held between readings
  Real latency_s = 0.005;             ///< a reading reaches the simulation this much later
};

/// A source seen through a real glove: the inner source is read at the
/// glove's own rate (reading k at time k / rate_hz), each reading is delayed
/// by the latency and held until the next one arrives, and noise is added.
/// The noise of reading k depends only on (seed, k, channel), never on the
/// order of calls, so the source stays a pure function of time.
///
/// At time t the output is reading k, the largest k >= 0 with
/// k / rate_hz + latency_s <= t, both sides evaluated in double exactly as
/// written (so at t = k / rate_hz + latency_s reading k has arrived, even
/// where (t - latency_s) * rate_hz rounds below k); before reading 0 arrives
/// it is shown all the same. Each joint is the inner angle plus its donning
/// offset plus white noise, then rounded to the nearest multiple of
/// degrees_per_count; the position gets noise per axis; the orientation is
/// turned by a small rotation in the world frame (q_WH becomes dq * q_WH)
/// whose rotation vector has the noise per axis. A sigma of 0 leaves its
/// field's bits alone. Gaussians come from splitmix64 and Box-Muller, the same
/// numbers wherever the C library's log, cos and sin agree.
class NoisyGlove final : public GloveSource {
 public:
  /// Throws std::invalid_argument for a null source, a rate <= 0 or above
  /// 10^6 Hz, a negative or non-finite sigma, a latency that is negative or
  /// above an hour, a quantisation step between 0 and 1e-6 degrees.
  NoisyGlove(std::shared_ptr<const GloveSource> inner, const GloveNoise& noise = {});
  GloveSample sample(Real t) const override;
  /// When the first reading taken at or after the inner source's end arrives;
  /// later readings see a hand that no longer moves, but their noise differs.
  Real end_time() const override;

 private:
  std::shared_ptr<const GloveSource> inner_;
  GloveNoise noise_;
  JointAngles donning_offset_{};
};

}  // namespace dovetail::interaction
