#include "dovetail/interaction/glove_source.h"

#include <algorithm>
#include <cmath>
#include <numbers>
#include <stdexcept>
#include <string>
#include <utility>

#include "dovetail/interaction/postures.h"

namespace dovetail::interaction {

namespace {

/// (1 - s) a + s b: exact at s = 0 and 1, and never past max(|a|, |b|) (a + s (b - a) overflows
/// for a = -1e308, b = 1e308).
Real lerp(Real a, Real b, Real s) { return (1 - s) * a + s * b; }

/// Minimum-jerk profile s(u) = 10u^3 - 15u^4 + 6u^5 in Horner form: exact at
/// u = 0, 1/2 and 1.
Real minimum_jerk(Real u) { return u * u * u * (10 + u * (6 * u - 15)); }

/// From a (s = 0) to b (s = 1), each end as given, bit for bit.
TrackerPose blend(const TrackerPose& a, const TrackerPose& b, Real s) {
  if (s <= 0) return a;
  if (s >= 1) return b;
  TrackerPose pose;
  for (int i = 0; i < 3; ++i) pose.p_WH[i] = lerp(a.p_WH[i], b.p_WH[i], s);
  pose.q_WH = slerp(normalized(a.q_WH), normalized(b.q_WH), s);
  return pose;
}

JointAngles blend(const JointAngles& a, const JointAngles& b, Real s) {
  if (s <= 0) return a;
  if (s >= 1) return b;
  JointAngles angles;
  for (std::size_t j = 0; j < kJointCount; ++j) angles[j] = lerp(a[j], b[j], s);
  return angles;
}

/// The finaliser of splitmix64: a counter in, 64 well-mixed bits out.
std::uint64_t splitmix64(std::uint64_t z) {
  z += 0x9E3779B97F4A7C15ull;
  z = (z ^ (z >> 30)) * 0xBF58476D1CE4E5B9ull;
  z = (z ^ (z >> 27)) * 0x94D049BB133111EBull;
  return z ^ (z >> 31);
}

/// Uniform in (0, 1], so that its logarithm is finite.
Real uniform_open_closed(std::uint64_t bits) {
  return static_cast<Real>((bits >> 11) + 1) * 0x1.0p-53;
}

/// A standard normal number that depends only on (seed, reading, channel):
/// Box-Muller on two uniforms hashed from them.
Real gaussian(std::uint64_t seed, std::uint64_t reading, std::uint64_t channel) {
  const std::uint64_t key = splitmix64(splitmix64(seed) ^ reading);
  const Real u1 = uniform_open_closed(splitmix64(key ^ (2 * channel)));
  const Real u2 = uniform_open_closed(splitmix64(key ^ (2 * channel + 1)));
  return std::sqrt(-2 * std::log(u1)) * std::cos(2 * std::numbers::pi * u2);
}

/// The noise channels of one reading; the donning offsets use reading 0.
constexpr std::uint64_t kJointChannel = 0;
constexpr std::uint64_t kPositionChannel = kJointChannel + kJointCount;
constexpr std::uint64_t kOrientationChannel = kPositionChannel + 3;
constexpr std::uint64_t kDonningChannel = kOrientationChannel + 3;

/// Reading indices stop here, where k / rate_hz is still exact in k.
constexpr std::uint64_t kMaxReading = std::uint64_t{1} << 52;

/// The rotation by |r| radians about r.
Quaternion rotation_vector_quaternion(const Vec3& r) {
  const Real angle = std::sqrt(r.x() * r.x() + r.y() * r.y() + r.z() * r.z());
  if (angle == 0) return {};
  const Real k = std::sin(angle / 2) / angle;
  return {std::cos(angle / 2), k * r.x(), k * r.y(), k * r.z()};
}

/// The Hamilton product a b: first b, then a.
Quaternion multiply(const Quaternion& a, const Quaternion& b) {
  return {
      a.w * b.w - a.x * b.x - a.y * b.y - a.z * b.z, a.w * b.x + a.x * b.w + a.y * b.z - a.z * b.y,
      a.w * b.y - a.x * b.z + a.y * b.w + a.z * b.x, a.w * b.z + a.x * b.y - a.y * b.x + a.z * b.w};
}

void check_not_negative(Real value, const char* name) {
  if (!std::isfinite(value) || value < 0) {
    throw std::invalid_argument(std::string("NoisyGlove: ") + name +
                                " must be finite and >= 0, got " + std::to_string(value));
  }
}

}  // namespace

// ---------------------------------------------------------------------------
// TraceSource

TraceSource::TraceSource(std::vector<GloveSample> samples) : samples_(std::move(samples)) {
  if (samples_.empty()) throw std::invalid_argument("TraceSource: empty trace");
  for (std::size_t i = 0; i < samples_.size(); ++i) {
    if (!std::isfinite(samples_[i].t)) {
      throw std::invalid_argument("TraceSource: sample " + std::to_string(i) +
                                  " has a non-finite time");
    }
    if (i > 0 && !(samples_[i - 1].t < samples_[i].t)) {
      throw std::invalid_argument("TraceSource: time does not increase at sample " +
                                  std::to_string(i));
    }
  }
}

GloveSample TraceSource::sample(Real t) const {
  const auto after = std::upper_bound(samples_.begin(), samples_.end(), t,
                                      [](Real time, const GloveSample& s) { return time < s.t; });
  GloveSample out;
  if (after == samples_.begin()) {
    out = samples_.front();
  } else if (after == samples_.end()) {
    out = samples_.back();
  } else {
    const GloveSample& a = *(after - 1);
    const GloveSample& b = *after;
    if (a.t == t) {
      out = a;
    } else {
      const Real alpha = (t - a.t) / (b.t - a.t);
      for (int i = 0; i < 3; ++i) out.p_WH[i] = lerp(a.p_WH[i], b.p_WH[i], alpha);
      out.q_WH = slerp(normalized(a.q_WH), normalized(b.q_WH), alpha);
      for (std::size_t j = 0; j < kJointCount; ++j) {
        out.joints[j] = lerp(a.joints[j], b.joints[j], alpha);
      }
    }
  }
  out.t = t;
  return out;
}

Real TraceSource::end_time() const { return samples_.back().t; }

// ---------------------------------------------------------------------------
// SimulatedGlove

SimulatedGlove::SimulatedGlove(GlovePlan plan) : plan_(std::move(plan)) {
  const std::size_t n = plan_.steps.size();
  step_start_.reserve(n + 1);
  start_pose_.reserve(n + 1);
  start_posture_.reserve(n + 1);
  Real t = 0;
  TrackerPose pose = plan_.start;
  JointAngles posture = plan_.start_posture;
  for (std::size_t i = 0; i < n; ++i) {
    const PlanStep& step = plan_.steps[i];
    const std::string where = "SimulatedGlove: step " + std::to_string(i) + ": ";
    if (!std::isfinite(step.duration) || step.duration < 0) {
      throw std::invalid_argument(where + "duration must be finite and >= 0");
    }
    step_start_.push_back(t);
    start_pose_.push_back(pose);
    start_posture_.push_back(posture);
    t += step.duration;
    if (!std::isfinite(t)) throw std::invalid_argument(where + "the plan's duration overflows");
    switch (step.kind) {
      case PlanStep::Kind::kReach:
        if (step.poses.size() != 1) throw std::invalid_argument(where + "reach needs one pose");
        pose = step.poses.front();
        break;
      case PlanStep::Kind::kPath:
        if (step.poses.empty()) throw std::invalid_argument(where + "path needs a pose");
        pose = step.poses.back();
        break;
      case PlanStep::Kind::kClose:
        posture = step.posture;
        break;
      case PlanStep::Kind::kOpen:
        posture = *named_posture("open");
        break;
      case PlanStep::Kind::kWait:
        break;
    }
  }
  step_start_.push_back(t);
  start_pose_.push_back(pose);
  start_posture_.push_back(posture);
}

GloveSample SimulatedGlove::sample(Real t) const {
  GloveSample out;
  out.t = t;
  // The last entry with start <= t; a zero-duration step shares its start with
  // the next entry and so is never the one found.
  const std::size_t found = static_cast<std::size_t>(
      std::upper_bound(step_start_.begin(), step_start_.end(), t) - step_start_.begin());
  const std::size_t end = plan_.steps.size();
  if (found == 0 || found > end) {
    const std::size_t held = found == 0 ? 0 : end;  // before t = 0, after the end (or t NaN)
    out.p_WH = start_pose_[held].p_WH;
    out.q_WH = start_pose_[held].q_WH;
    out.joints = start_posture_[held];
    return out;
  }
  const std::size_t i = found - 1;
  const PlanStep& step = plan_.steps[i];
  const Real t0 = step_start_[i];
  const Real t1 = step_start_[i + 1];
  TrackerPose pose = start_pose_[i];
  JointAngles joints = start_posture_[i];
  const Real u = std::min<Real>((t - t0) / (t1 - t0), 1);
  switch (step.kind) {
    case PlanStep::Kind::kReach:
      pose = blend(pose, start_pose_[i + 1], minimum_jerk(u));
      break;
    case PlanStep::Kind::kPath: {
      // Leg l runs from leg_start(l) to leg_start(l + 1); the guess from u is
      // corrected so that a waypoint is reached exactly at its leg_start.
      const std::size_t m = step.poses.size();
      const auto leg_start = [&](std::size_t l) {
        return l == m ? t1 : t0 + step.duration * static_cast<Real>(l) / static_cast<Real>(m);
      };
      std::size_t l = std::min(m - 1, static_cast<std::size_t>(u * static_cast<Real>(m)));
      while (l + 1 < m && leg_start(l + 1) <= t) ++l;
      while (l > 0 && leg_start(l) > t) --l;
      const Real l0 = leg_start(l);
      const Real v = std::min<Real>((t - l0) / (leg_start(l + 1) - l0), 1);
      pose = blend(l == 0 ? start_pose_[i] : step.poses[l - 1], step.poses[l], minimum_jerk(v));
      break;
    }
    case PlanStep::Kind::kClose:
    case PlanStep::Kind::kOpen:
      joints = blend(joints, start_posture_[i + 1], minimum_jerk(u));
      break;
    case PlanStep::Kind::kWait:
      break;
  }
  out.p_WH = pose.p_WH;
  out.q_WH = pose.q_WH;
  out.joints = joints;
  return out;
}

Real SimulatedGlove::end_time() const { return step_start_.back(); }

// ---------------------------------------------------------------------------
// NoisyGlove

namespace {

/// When reading k reaches the simulation.
Real arrival(const GloveNoise& noise, std::uint64_t k) {
  return static_cast<Real>(k) / noise.rate_hz + noise.latency_s;
}

/// The newest reading that has arrived at t (reading 0 before any has).
std::uint64_t reading_at(const GloveNoise& noise, Real t) {
  const Real x = (t - noise.latency_s) * noise.rate_hz;
  std::uint64_t k = 0;
  if (x >= static_cast<Real>(kMaxReading)) {
    k = kMaxReading;
  } else if (x > 0) {
    k = static_cast<std::uint64_t>(std::floor(x));
  }
  // floor((t - latency) * rate) can be one off at an arrival time (the
  // product rounds below k, or the subtraction above it); the arrival times
  // themselves decide.
  while (k < kMaxReading && arrival(noise, k + 1) <= t) ++k;
  while (k > 0 && arrival(noise, k) > t) --k;
  return k;
}

}  // namespace

NoisyGlove::NoisyGlove(std::shared_ptr<const GloveSource> inner, const GloveNoise& noise)
    : inner_(std::move(inner)), noise_(noise) {
  if (!inner_) throw std::invalid_argument("NoisyGlove: no inner source");
  if (!std::isfinite(noise_.rate_hz) || noise_.rate_hz <= 0) {
    throw std::invalid_argument("NoisyGlove: rate_hz must be finite and > 0, got " +
                                std::to_string(noise_.rate_hz));
  }
  check_not_negative(noise_.joint_sigma_deg, "joint_sigma_deg");
  check_not_negative(noise_.donning_sigma_deg, "donning_sigma_deg");
  check_not_negative(noise_.degrees_per_count, "degrees_per_count");
  check_not_negative(noise_.position_sigma_m, "position_sigma_m");
  check_not_negative(noise_.orientation_sigma_deg, "orientation_sigma_deg");
  check_not_negative(noise_.latency_s, "latency_s");
  // Bounds that keep reading indices and arrival times exact in a double.
  if (noise_.rate_hz > 1e6) throw std::invalid_argument("NoisyGlove: rate_hz must be <= 1e6");
  if (noise_.latency_s > 3600) throw std::invalid_argument("NoisyGlove: latency_s must be <= 3600");
  if (noise_.degrees_per_count != 0 && noise_.degrees_per_count < 1e-6) {
    throw std::invalid_argument("NoisyGlove: degrees_per_count must be 0 or >= 1e-6");
  }
  if (noise_.donning_sigma_deg > 0) {
    for (std::size_t j = 0; j < kJointCount; ++j) {
      donning_offset_[j] = noise_.donning_sigma_deg * gaussian(noise_.seed, 0, kDonningChannel + j);
    }
  }
}

GloveSample NoisyGlove::sample(Real t) const {
  const std::uint64_t k = reading_at(noise_, t);
  GloveSample out = inner_->sample(static_cast<Real>(k) / noise_.rate_hz);
  for (std::size_t j = 0; j < kJointCount; ++j) {
    Real angle = out.joints[j];
    if (noise_.donning_sigma_deg > 0) angle += donning_offset_[j];
    if (noise_.joint_sigma_deg > 0) {
      angle += noise_.joint_sigma_deg * gaussian(noise_.seed, k, kJointChannel + j);
    }
    if (noise_.degrees_per_count > 0) {
      angle = std::round(angle / noise_.degrees_per_count) * noise_.degrees_per_count;
    }
    out.joints[j] = angle;
  }
  if (noise_.position_sigma_m > 0) {
    for (int i = 0; i < 3; ++i) {
      out.p_WH[i] += noise_.position_sigma_m *
                     gaussian(noise_.seed, k, kPositionChannel + static_cast<std::uint64_t>(i));
    }
  }
  if (noise_.orientation_sigma_deg > 0) {
    const Real sigma_rad = noise_.orientation_sigma_deg * (std::numbers::pi / 180);
    const Vec3 r_W(sigma_rad * gaussian(noise_.seed, k, kOrientationChannel),
                   sigma_rad * gaussian(noise_.seed, k, kOrientationChannel + 1),
                   sigma_rad * gaussian(noise_.seed, k, kOrientationChannel + 2));
    out.q_WH = multiply(rotation_vector_quaternion(r_W), out.q_WH);
  }
  out.t = t;
  return out;
}

Real NoisyGlove::end_time() const {
  const Real inner_end = inner_->end_time();
  // The first reading k with k / rate_hz >= inner_end.
  const Real x = inner_end * noise_.rate_hz;
  std::uint64_t k = 0;
  if (!(x < static_cast<Real>(kMaxReading))) {
    k = kMaxReading;
  } else if (x > 0) {
    k = static_cast<std::uint64_t>(std::ceil(x));
  }
  const auto taken = [&](std::uint64_t i) { return static_cast<Real>(i) / noise_.rate_hz; };
  while (k > 0 && taken(k - 1) >= inner_end) --k;
  while (k < kMaxReading && taken(k) < inner_end) ++k;
  return arrival(noise_, k);
}

}  // namespace dovetail::interaction
