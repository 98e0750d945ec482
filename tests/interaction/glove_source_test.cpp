#include "dovetail/interaction/glove_source.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <limits>
#include <memory>
#include <numbers>
#include <stdexcept>
#include <utility>
#include <vector>

#include "dovetail/interaction/postures.h"

namespace dovetail::interaction {
namespace {

constexpr Real kPi = std::numbers::pi;
constexpr Real kTraceRateHz = 120;

// ---------------------------------------------------------------------------
// Helpers

/// Joint j of the linear trace, in degrees: a_j + b_j t.
Real linear_angle(std::size_t j, Real t) {
  const Real a = 5.0 + 3.0 * static_cast<Real>(j);
  const Real b = -20.0 + 7.5 * static_cast<Real>(j);
  return a + b * t;
}

/// Position of the linear trace, in metres.
Vec3 linear_position(Real t) { return Vec3(0.1 + 0.25 * t, -0.3 + 0.5 * t, 1.2 - 0.125 * t); }

/// Samples at i / rate_hz, i = 0 .. count - 1, of the linear joints and
/// position, with a fixed orientation.
std::vector<GloveSample> linear_trace(Real rate_hz, int count) {
  std::vector<GloveSample> samples(static_cast<std::size_t>(count));
  for (int i = 0; i < count; ++i) {
    GloveSample& s = samples[static_cast<std::size_t>(i)];
    s.t = i / rate_hz;
    s.p_WH = linear_position(s.t);
    s.q_WH = normalized({0.9, 0.1, -0.3, 0.2});
    for (std::size_t j = 0; j < kJointCount; ++j) s.joints[j] = linear_angle(j, s.t);
  }
  return samples;
}

/// Rotation by omega t about the unit axis n.
Quaternion turning(Real omega, const Vec3& n, Real t) {
  const Real half = omega * t / 2;
  const Real s = std::sin(half);
  return {std::cos(half), s * n.x(), s * n.y(), s * n.z()};
}

/// `sample` with its time replaced by t.
GloveSample at_time(GloveSample sample, Real t) {
  sample.t = t;
  return sample;
}

/// splitmix64, for a shuffle that is the same on every platform.
std::uint64_t next_random(std::uint64_t& state) {
  std::uint64_t z = (state += 0x9E3779B97F4A7C15ull);
  z = (z ^ (z >> 30)) * 0xBF58476D1CE4E5B9ull;
  z = (z ^ (z >> 27)) * 0x94D049BB133111EBull;
  return z ^ (z >> 31);
}

/// Samples `source` at `times` in forward, backward and shuffled order and
/// expects the same bits for each time whatever came before.
void expect_pure(const GloveSource& source, const std::vector<Real>& times) {
  std::vector<GloveSample> forward;
  for (Real t : times) forward.push_back(source.sample(t));

  for (std::size_t i = times.size(); i-- > 0;) {
    ASSERT_TRUE(same_bits(source.sample(times[i]), forward[i])) << "backward, t = " << times[i];
  }

  std::vector<std::size_t> order(times.size());
  for (std::size_t i = 0; i < order.size(); ++i) order[i] = i;
  std::uint64_t state = 12345;
  for (std::size_t i = order.size(); i > 1; --i) {
    std::swap(order[i - 1], order[next_random(state) % i]);
  }
  for (std::size_t i : order) {
    ASSERT_TRUE(same_bits(source.sample(times[i]), forward[i])) << "shuffled, t = " << times[i];
  }
}

/// Times before, on and between the samples of a 120 Hz trace of 1 s, and after it.
std::vector<Real> probe_times() {
  std::vector<Real> times = {-1.0, -0.0, 0.0, 1.0, 1.5, 1e9};
  for (int k = 0; k <= 300; ++k) times.push_back(k / 250.0);
  for (int i = 0; i <= 120; ++i) times.push_back(i / kTraceRateHz);
  return times;
}

Vec3 p(Real x, Real y, Real z) { return Vec3(x, y, z); }

TrackerPose pose(const Vec3& p_WH, const Quaternion& q_WH) {
  TrackerPose X;
  X.p_WH = p_WH;
  X.q_WH = q_WH;
  return X;
}

/// Bitwise equality of a sample's pose with a plan pose.
bool same_pose(const GloveSample& s, const TrackerPose& X) {
  GloveSample a = s;
  GloveSample b = s;
  b.p_WH = X.p_WH;
  b.q_WH = X.q_WH;
  return same_bits(a, b);
}

bool same_joints(const GloveSample& s, const JointAngles& angles) {
  GloveSample b = s;
  b.joints = angles;
  return same_bits(s, b);
}

Real minimum_jerk_reference(Real u) {
  return 10 * std::pow(u, 3) - 15 * std::pow(u, 4) + 6 * std::pow(u, 5);
}

// ---------------------------------------------------------------------------
// TraceSource

TEST(TraceSource, LinearTraceResampledAt90HzGivesTheLine) {
  const std::vector<GloveSample> trace = linear_trace(kTraceRateHz, 241);  // 2 s
  const TraceSource source(trace);
  // The stored samples are the line rounded to double and interpolation adds
  // a few roundings of values below 100, so agreement is to ~1e-13, not exact;
  // 1e-9 leaves room while still catching any wrong weight or interval.
  constexpr Real kTolerance = 1e-9;
  for (int k = 0; k <= 180; ++k) {
    const Real t = k / 90.0;
    const GloveSample s = source.sample(t);
    ASSERT_EQ(s.t, t);
    for (std::size_t j = 0; j < kJointCount; ++j) {
      ASSERT_NEAR(s.joints[j], linear_angle(j, t), kTolerance) << "k = " << k << ", joint " << j;
    }
    const Vec3 expected = linear_position(t);
    for (int i = 0; i < 3; ++i) ASSERT_NEAR(s.p_WH[i], expected[i], kTolerance) << "k = " << k;
    // k / 90 and 4m / 120 round the same real m / 30, so every third time is a sample's own.
    if (k % 3 == 0) {
      EXPECT_TRUE(same_bits(s, trace[static_cast<std::size_t>(k / 3 * 4)])) << "k = " << k;
    }
  }
}

TEST(TraceSource, AtASamplesOwnTimeGivesTheSampleBitForBit) {
  std::vector<GloveSample> trace = linear_trace(kTraceRateHz, 121);
  trace[7].q_WH = {2, 0, 0, 0};  // not unit: kept as given
  trace[8].joints[3] = -0.0;
  const TraceSource source(trace);
  for (const GloveSample& stored : trace) {
    EXPECT_TRUE(same_bits(source.sample(stored.t), stored)) << "t = " << stored.t;
  }
}

TEST(TraceSource, ConstantAngularVelocitySlerpsToTheAnalyticRotation) {
  // From a slow turn (0.05 rad/s: 4e-4 rad between samples, where an acos of
  // the dot product would lose half the digits) through hand speeds to a fast
  // flick of 12 rad/s (0.1 rad between samples).
  for (const Real omega : {0.05, 1.0, 5.0, 12.0}) {
    const Vec3 n = Vec3(1, 2, 2) / 3;
    std::vector<GloveSample> trace(121);
    for (std::size_t i = 0; i < trace.size(); ++i) {
      trace[i].t = static_cast<Real>(i) / kTraceRateHz;
      trace[i].q_WH = turning(omega, n, trace[i].t);
    }
    const TraceSource source(trace);
    for (int k = 0; k <= 90; ++k) {
      const Real t = k / 90.0;
      const Quaternion q = source.sample(t).q_WH;
      const Quaternion expected = turning(omega, n, t);
      EXPECT_NEAR(q.w, expected.w, 1e-12) << "omega " << omega << " t = " << t;
      EXPECT_NEAR(q.x, expected.x, 1e-12) << "omega " << omega << " t = " << t;
      EXPECT_NEAR(q.y, expected.y, 1e-12) << "omega " << omega << " t = " << t;
      EXPECT_NEAR(q.z, expected.z, 1e-12) << "omega " << omega << " t = " << t;
    }
  }
}

TEST(TraceSource, InterpolatingHugePositionsDoesNotOverflow) {
  std::vector<GloveSample> trace(2);
  trace[0].p_WH.x() = -1e308;
  trace[1].t = 1;
  trace[1].p_WH.x() = 1e308;
  const TraceSource source(trace);
  EXPECT_TRUE(std::isfinite(source.sample(0.5).p_WH.x()));
  EXPECT_EQ(source.sample(0.5).p_WH.x(), 0);
}

TEST(TraceSource, HoldsTheEndsOutsideTheTrace) {
  const std::vector<GloveSample> trace = linear_trace(kTraceRateHz, 13);
  const TraceSource source(trace);
  EXPECT_TRUE(same_bits(source.sample(-5), at_time(trace.front(), -5)));
  EXPECT_TRUE(same_bits(source.sample(std::nextafter(0.0, -1.0)),
                        at_time(trace.front(), std::nextafter(0.0, -1.0))));
  EXPECT_TRUE(same_bits(source.sample(0.2), at_time(trace.back(), 0.2)));
  EXPECT_TRUE(same_bits(source.sample(1e300), at_time(trace.back(), 1e300)));
  EXPECT_EQ(source.end_time(), trace.back().t);
}

TEST(TraceSource, OneSampleIsHeldForEver) {
  const std::vector<GloveSample> trace = linear_trace(kTraceRateHz, 1);
  const TraceSource source(trace);
  for (Real t : {-1.0, 0.0, 3.0}) EXPECT_TRUE(same_bits(source.sample(t), at_time(trace[0], t)));
  EXPECT_EQ(source.end_time(), 0.0);
}

TEST(TraceSource, RefusesEmptyOrNonIncreasingTraces) {
  EXPECT_THROW(TraceSource({}), std::invalid_argument);
  std::vector<GloveSample> trace = linear_trace(kTraceRateHz, 5);
  trace[3].t = trace[2].t;
  EXPECT_THROW(TraceSource{trace}, std::invalid_argument);
  trace[3].t = trace[2].t - 0.001;
  EXPECT_THROW(TraceSource{trace}, std::invalid_argument);
  trace[3].t = std::numeric_limits<Real>::quiet_NaN();
  EXPECT_THROW(TraceSource{trace}, std::invalid_argument);
  std::vector<GloveSample> one(1);
  one[0].t = std::numeric_limits<Real>::infinity();
  EXPECT_THROW(TraceSource{one}, std::invalid_argument);
}

TEST(TraceSource, IsAPureFunctionOfTime) {
  const TraceSource source(linear_trace(kTraceRateHz, 121));
  expect_pure(source, probe_times());
}

// ---------------------------------------------------------------------------
// SimulatedGlove

/// The plan of the SimulatedGlove tests; times in the comments.
struct TestPlan {
  TrackerPose A = pose(p(0.1, 0.2, 0.3), {});
  TrackerPose B = pose(p(0.5, -0.1, 0.7), {std::cos(kPi / 4), 0, 0, std::sin(kPi / 4)});
  TrackerPose C = pose(p(0.6, 0.0, 0.7), normalized({1, 0.2, 0, 0}));
  TrackerPose D = pose(p(0.6, 0.1, 0.9), normalized({1, 0.2, 0.3, 0}));
  TrackerPose E = pose(p(0.4, 0.1, 0.9), normalized({1, 0, 0.3, -0.1}));
  TrackerPose F = pose(p(-0.2, 0.3, 0.1), normalized({0, 1, 0, 0}));
  JointAngles custom{};
  GlovePlan plan;

  TestPlan() {
    for (std::size_t j = 0; j < kJointCount; ++j) custom[j] = 1.5 * static_cast<Real>(j) - 4;
    plan.start = A;
    const auto step = [&](PlanStep::Kind kind, Real duration, std::vector<TrackerPose> poses = {},
                          JointAngles posture = {}) {
      PlanStep s;
      s.kind = kind;
      s.duration = duration;
      s.poses = std::move(poses);
      s.posture = posture;
      plan.steps.push_back(std::move(s));
    };
    step(PlanStep::Kind::kReach, 2.0, {B});                         // 0 .. 2
    step(PlanStep::Kind::kClose, 1.0, {}, *named_posture("fist"));  // 2 .. 3
    step(PlanStep::Kind::kWait, 0.5);                               // 3 .. 3.5
    step(PlanStep::Kind::kPath, 1.5, {C, D, E});                    // 3.5 .. 5, legs of 0.5
    step(PlanStep::Kind::kWait, 0.5);                               // 5 .. 5.5
    step(PlanStep::Kind::kOpen, 0.0);                               // 5.5, jumps
    step(PlanStep::Kind::kReach, 0.0, {F});                         // 5.5, jumps
    step(PlanStep::Kind::kClose, 1.0, {}, custom);                  // 5.5 .. 6.5
  }
};

TEST(SimulatedGlove, ReachesEveryTargetExactlyAtItsStepBoundary) {
  const TestPlan test;
  const SimulatedGlove glove(test.plan);
  const JointAngles open = *named_posture("open");
  const JointAngles fist = *named_posture("fist");
  struct Expected {
    Real t;
    const TrackerPose& pose;
    const JointAngles& joints;
  };
  const Expected expected[] = {
      {-1.0, test.A, open},       {0.0, test.A, open},       {2.0, test.B, open},
      {3.0, test.B, fist},        {3.25, test.B, fist},      {3.5, test.B, fist},
      {5.0, test.E, fist},        {5.25, test.E, fist},      {5.5, test.F, open},
      {6.5, test.F, test.custom}, {1e6, test.F, test.custom}};
  for (const Expected& e : expected) {
    const GloveSample s = glove.sample(e.t);
    EXPECT_EQ(s.t, e.t);
    EXPECT_TRUE(same_pose(s, e.pose)) << "t = " << e.t;
    EXPECT_TRUE(same_joints(s, e.joints)) << "t = " << e.t;
  }
  // Just before the jumps at 5.5 the wait still holds E and the fist.
  const GloveSample before = glove.sample(std::nextafter(5.5, 0.0));
  EXPECT_TRUE(same_pose(before, test.E));
  EXPECT_TRUE(same_joints(before, fist));
  EXPECT_EQ(glove.end_time(), 6.5);
  EXPECT_EQ(glove.end_time(), test.plan.duration());
}

TEST(SimulatedGlove, ReachFollowsTheMinimumJerkProfile) {
  const TestPlan test;
  const SimulatedGlove glove(test.plan);
  // Midway (u = 1/2, s = 1/2): the midpoint and half the rotation (45 degrees about z).
  const GloveSample mid = glove.sample(1.0);
  for (int i = 0; i < 3; ++i) {
    EXPECT_NEAR(mid.p_WH[i], (test.A.p_WH[i] + test.B.p_WH[i]) / 2, 1e-15);
  }
  EXPECT_NEAR(mid.q_WH.w, std::cos(kPi / 8), 1e-15);
  EXPECT_NEAR(mid.q_WH.x, 0, 1e-15);
  EXPECT_NEAR(mid.q_WH.y, 0, 1e-15);
  EXPECT_NEAR(mid.q_WH.z, std::sin(kPi / 8), 1e-15);
  // Elsewhere: s(u) = 10u^3 - 15u^4 + 6u^5 of the straight line and of the angle.
  for (int k = 1; k < 20; ++k) {
    const Real u = k / 20.0;
    const Real s = minimum_jerk_reference(u);
    const GloveSample g = glove.sample(2.0 * u);
    for (int i = 0; i < 3; ++i) {
      EXPECT_NEAR(g.p_WH[i], test.A.p_WH[i] + s * (test.B.p_WH[i] - test.A.p_WH[i]), 1e-14)
          << "u = " << u;
    }
    EXPECT_NEAR(g.q_WH.w, std::cos(s * kPi / 4), 1e-14) << "u = " << u;
    EXPECT_NEAR(g.q_WH.z, std::sin(s * kPi / 4), 1e-14) << "u = " << u;
    EXPECT_TRUE(same_joints(g, *named_posture("open")));  // reach keeps the posture
  }
}

TEST(SimulatedGlove, CloseMovesEveryJointToThePostureAndKeepsThePose) {
  const TestPlan test;
  const SimulatedGlove glove(test.plan);
  const JointAngles fist = *named_posture("fist");
  const GloveSample mid = glove.sample(2.5);  // from the open hand (0): exactly half of each angle
  for (std::size_t j = 0; j < kJointCount; ++j) EXPECT_EQ(mid.joints[j], fist[j] / 2);
  EXPECT_TRUE(same_pose(mid, test.B));
  const GloveSample quarter = glove.sample(2.25);
  const Real s = minimum_jerk_reference(0.25);
  for (std::size_t j = 0; j < kJointCount; ++j) EXPECT_NEAR(quarter.joints[j], s * fist[j], 1e-13);
  EXPECT_TRUE(same_joints(glove.sample(3.0), fist));
  // The last close, from the open hand to custom angles, ends on them exactly.
  EXPECT_TRUE(same_joints(glove.sample(6.5), test.custom));
  EXPECT_TRUE(same_joints(glove.sample(7.0), test.custom));
}

TEST(SimulatedGlove, PathPassesThroughEveryWaypointAtItsShareOfTime) {
  const TestPlan test;
  const SimulatedGlove glove(test.plan);
  const TrackerPose* waypoints[] = {&test.B, &test.C, &test.D, &test.E};
  for (int l = 0; l < 4; ++l) {
    const GloveSample s = glove.sample(3.5 + 0.5 * l);
    EXPECT_TRUE(same_pose(s, *waypoints[l])) << "waypoint " << l;
    EXPECT_TRUE(same_joints(s, *named_posture("fist")));
  }
  // Each leg midway: the midpoint of its ends.
  for (int l = 0; l < 3; ++l) {
    const GloveSample s = glove.sample(3.75 + 0.5 * l);
    for (int i = 0; i < 3; ++i) {
      EXPECT_NEAR(s.p_WH[i], (waypoints[l]->p_WH[i] + waypoints[l + 1]->p_WH[i]) / 2, 1e-15);
    }
  }

  // Shares that are not exact in binary: leg l still starts on waypoint l.
  GlovePlan plan;
  PlanStep path;
  path.kind = PlanStep::Kind::kPath;
  path.duration = 1.0;
  path.poses = {test.B, test.C, test.D};
  plan.steps.push_back(path);
  const SimulatedGlove thirds(plan);
  EXPECT_TRUE(same_pose(thirds.sample(1.0 * 1 / 3.0), test.B));
  EXPECT_TRUE(same_pose(thirds.sample(1.0 * 2 / 3.0), test.C));
  EXPECT_TRUE(same_pose(thirds.sample(1.0), test.D));
}

TEST(SimulatedGlove, EndsOfAMoveKeepQuaternionsAsGiven) {
  GlovePlan plan;
  plan.start.q_WH = {2, 0, 0, 0};
  PlanStep reach;
  reach.kind = PlanStep::Kind::kReach;
  reach.duration = 1;
  reach.poses = {pose(p(1, 0, 0), {0, 0, 0, 3})};
  plan.steps.push_back(reach);
  const SimulatedGlove glove(plan);
  EXPECT_TRUE(same_pose(glove.sample(0), plan.start));
  EXPECT_TRUE(same_pose(glove.sample(1), reach.poses[0]));
  const Quaternion mid = glove.sample(0.5).q_WH;  // half of 180 degrees about z
  EXPECT_NEAR(mid.w, std::sqrt(0.5), 1e-15);
  EXPECT_NEAR(mid.z, std::sqrt(0.5), 1e-15);
}

TEST(SimulatedGlove, RefusesBadPlans) {
  const auto plan_with = [](PlanStep step) {
    GlovePlan plan;
    plan.steps.push_back(std::move(step));
    return plan;
  };
  PlanStep step;
  step.kind = PlanStep::Kind::kWait;
  step.duration = -1;
  EXPECT_THROW(SimulatedGlove{plan_with(step)}, std::invalid_argument);
  step.duration = std::numeric_limits<Real>::infinity();
  EXPECT_THROW(SimulatedGlove{plan_with(step)}, std::invalid_argument);
  step.duration = 1;
  step.kind = PlanStep::Kind::kReach;
  EXPECT_THROW(SimulatedGlove{plan_with(step)}, std::invalid_argument);
  step.kind = PlanStep::Kind::kPath;
  EXPECT_THROW(SimulatedGlove{plan_with(step)}, std::invalid_argument);
  step.kind = PlanStep::Kind::kWait;
  step.duration = 1e308;
  GlovePlan overflowing = plan_with(step);
  overflowing.steps.push_back(step);
  EXPECT_THROW(SimulatedGlove{overflowing}, std::invalid_argument);
}

TEST(SimulatedGlove, IsAPureFunctionOfTime) {
  const SimulatedGlove glove(TestPlan().plan);
  std::vector<Real> times = probe_times();
  for (int k = -10; k <= 700; ++k) times.push_back(k / 100.0);
  for (Real t : {2.0, 3.0, 3.5, 5.0, 5.5, 6.5}) {
    times.push_back(std::nextafter(t, 0.0));
    times.push_back(std::nextafter(t, 10.0));
  }
  expect_pure(glove, times);
}

// ---------------------------------------------------------------------------
// NoisyGlove

GloveNoise no_noise(Real rate_hz, Real latency_s) {
  GloveNoise noise;
  noise.joint_sigma_deg = 0;
  noise.donning_sigma_deg = 0;
  noise.degrees_per_count = 0;
  noise.position_sigma_m = 0;
  noise.orientation_sigma_deg = 0;
  noise.rate_hz = rate_hz;
  noise.latency_s = latency_s;
  return noise;
}

std::shared_ptr<const GloveSource> linear_source(int count = 241) {
  return std::make_shared<TraceSource>(linear_trace(kTraceRateHz, count));
}

/// A hand that does not move: one sample.
std::shared_ptr<const GloveSource> still_source() {
  GloveSample s;
  s.p_WH = p(0.1, 0.2, 0.3);
  s.q_WH = normalized({0.8, 0.2, -0.4, 0.1});
  for (std::size_t j = 0; j < kJointCount; ++j) s.joints[j] = 10.25 + static_cast<Real>(j);
  return std::make_shared<TraceSource>(std::vector<GloveSample>{s});
}

struct Moments {
  Real mean = 0;
  Real std = 0;  ///< sample standard deviation
};

Moments moments(const std::vector<Real>& values) {
  Moments m;
  for (Real v : values) m.mean += v;
  m.mean /= static_cast<Real>(values.size());
  Real squares = 0;
  for (Real v : values) squares += (v - m.mean) * (v - m.mean);
  m.std = std::sqrt(squares / static_cast<Real>(values.size() - 1));
  return m;
}

Real correlation(const std::vector<Real>& a, const std::vector<Real>& b) {
  const Moments ma = moments(a);
  const Moments mb = moments(b);
  Real sum = 0;
  for (std::size_t i = 0; i < a.size(); ++i) sum += (a[i] - ma.mean) * (b[i] - mb.mean);
  return sum / static_cast<Real>(a.size() - 1) / (ma.std * mb.std);
}

/// The rotation vector of the unit quaternion q.
Vec3 rotation_vector(const Quaternion& q) {
  const Vec3 v(q.x, q.y, q.z);
  const Real n = v.norm();
  if (n == 0) return Vec3::Zero();
  return v / n * (2 * std::atan2(n, q.w));
}

Quaternion conjugate(const Quaternion& q) { return {q.w, -q.x, -q.y, -q.z}; }

Quaternion product(const Quaternion& a, const Quaternion& b) {
  return {
      a.w * b.w - a.x * b.x - a.y * b.y - a.z * b.z, a.w * b.x + a.x * b.w + a.y * b.z - a.z * b.y,
      a.w * b.y - a.x * b.z + a.y * b.w + a.z * b.x, a.w * b.z + a.x * b.y - a.y * b.x + a.z * b.w};
}

constexpr int kReadings = 20000;

/// The arrival time of reading k with the default rate and latency.
Real default_arrival(int k) {
  const GloveNoise noise;
  return k / noise.rate_hz + noise.latency_s;
}

TEST(NoisyGlove, SameSeedSameBitsOtherSeedOtherNoise) {
  const TestPlan test;
  const auto inner = std::make_shared<SimulatedGlove>(test.plan);
  GloveNoise noise;
  noise.seed = 42;
  const NoisyGlove a(inner, noise);
  const NoisyGlove b(inner, noise);
  noise.seed = 43;
  const NoisyGlove c(inner, noise);
  for (int k = 0; k <= 800; ++k) {
    const Real t = k / 100.0;
    EXPECT_TRUE(same_bits(a.sample(t), b.sample(t))) << "t = " << t;
    EXPECT_FALSE(same_bits(a.sample(t), c.sample(t))) << "t = " << t;
  }
}

TEST(NoisyGlove, WithoutNoiseIsTheInnerSourceDelayedAndHeld) {
  // 8 Hz and 0.25 s: every reading and arrival time is exact in binary.
  const auto inner = linear_source();
  const NoisyGlove glove(inner, no_noise(8, 0.25));
  const auto reading = [&](int k, Real t) { return at_time(inner->sample(k / 8.0), t); };
  // Before reading 0 arrives it is shown all the same.
  for (Real t : {-1.0, 0.0, 0.1, std::nextafter(0.25, 0.0)}) {
    EXPECT_TRUE(same_bits(glove.sample(t), reading(0, t))) << "t = " << t;
  }
  for (int k = 0; k < 16; ++k) {
    const Real arrives = 0.25 + k / 8.0;
    EXPECT_TRUE(same_bits(glove.sample(arrives), reading(k, arrives))) << "k = " << k;
    const Real held = arrives + 0.1;  // until reading k + 1 arrives
    EXPECT_TRUE(same_bits(glove.sample(held), reading(k, held))) << "k = " << k;
    const Real last = std::nextafter(arrives + 0.125, 0.0);
    EXPECT_TRUE(same_bits(glove.sample(last), reading(k, last))) << "k = " << k;
  }
  // The inner trace ends at 2 s: reading 16 is the last that differs, arriving at 2.25 s.
  EXPECT_EQ(glove.end_time(), 2.25);
  EXPECT_TRUE(same_bits(glove.sample(40), reading(16, 40)));
}

TEST(NoisyGlove, EveryReadingArrivesExactlyAtItsArrivalTime) {
  // 120 Hz and 5 ms are not exact in binary: floor((t - latency) * rate) at
  // t = k / rate + latency lands on k - 1 for some k (shown below), the
  // source must not.
  const auto inner = linear_source();
  const NoisyGlove glove(inner, no_noise(120, 0.005));
  int naive_misses = 0;
  for (int k = 0; k <= 240; ++k) {
    const Real t = k / 120.0 + 0.005;
    if (std::floor((t - 0.005) * 120) != k) ++naive_misses;
    EXPECT_TRUE(same_bits(glove.sample(t), at_time(inner->sample(k / 120.0), t))) << "k = " << k;
    if (k > 0) {
      const Real before = std::nextafter(t, 0.0);
      EXPECT_TRUE(same_bits(glove.sample(before), at_time(inner->sample((k - 1) / 120.0), before)))
          << "k = " << k;
    }
  }
  EXPECT_GT(naive_misses, 0);
  EXPECT_EQ(glove.end_time(), 240 / 120.0 + 0.005);
}

TEST(NoisyGlove, WhiteNoiseHasItsSigmaAndNoBias) {
  const auto inner = still_source();
  const GloveSample still = inner->sample(0);
  GloveNoise noise;
  noise.seed = 7;
  noise.donning_sigma_deg = 0;
  noise.degrees_per_count = 0;
  const NoisyGlove glove(inner, noise);
  std::vector<std::vector<Real>> joint(kJointCount), position(3), rotation(3);
  for (int k = 0; k < kReadings; ++k) {
    const GloveSample s = glove.sample(default_arrival(k));
    for (std::size_t j = 0; j < kJointCount; ++j) joint[j].push_back(s.joints[j] - still.joints[j]);
    for (int i = 0; i < 3; ++i) position[i].push_back(s.p_WH[i] - still.p_WH[i]);
    const Vec3 r_W = rotation_vector(product(s.q_WH, conjugate(still.q_WH)));
    for (int i = 0; i < 3; ++i) rotation[i].push_back(r_W[i]);
  }
  // Standard errors: the mean sigma / sqrt(N) (0.7 %), the std sigma / sqrt(2N) (0.5 %).
  const Real mean_bound = 5 / std::sqrt(static_cast<Real>(kReadings));
  for (std::size_t j = 0; j < kJointCount; ++j) {
    const Moments m = moments(joint[j]);
    EXPECT_LT(std::abs(m.mean), mean_bound * noise.joint_sigma_deg) << "joint " << j;
    EXPECT_NEAR(m.std / noise.joint_sigma_deg, 1, 0.05) << "joint " << j;
  }
  const Real orientation_sigma = noise.orientation_sigma_deg * kPi / 180;
  for (int i = 0; i < 3; ++i) {
    const Moments mp = moments(position[i]);
    EXPECT_LT(std::abs(mp.mean), mean_bound * noise.position_sigma_m) << "axis " << i;
    EXPECT_NEAR(mp.std / noise.position_sigma_m, 1, 0.05) << "axis " << i;
    const Moments mr = moments(rotation[i]);
    EXPECT_LT(std::abs(mr.mean), mean_bound * orientation_sigma) << "axis " << i;
    EXPECT_NEAR(mr.std / orientation_sigma, 1, 0.05) << "axis " << i;
  }
  // Channels and consecutive readings are uncorrelated (standard error 0.7 %).
  EXPECT_LT(std::abs(correlation(joint[0], joint[1])), 0.04);
  EXPECT_LT(std::abs(correlation(joint[21], position[0])), 0.04);
  EXPECT_LT(std::abs(correlation(position[2], rotation[0])), 0.04);
  const std::vector<Real> now(joint[5].begin() + 1, joint[5].end());
  const std::vector<Real> before(joint[5].begin(), joint[5].end() - 1);
  EXPECT_LT(std::abs(correlation(now, before)), 0.04);
}

TEST(NoisyGlove, JointNoiseMinusTheDonningOffsetIsWhite) {
  const auto inner = still_source();
  const GloveSample still = inner->sample(0);
  GloveNoise noise;
  noise.seed = 11;
  noise.degrees_per_count = 0;
  const NoisyGlove glove(inner, noise);
  // The same seed without white noise shows the donning offset alone.
  GloveNoise offset_only = noise;
  offset_only.joint_sigma_deg = 0;
  const NoisyGlove donned(inner, offset_only);
  JointAngles offset{};
  for (std::size_t j = 0; j < kJointCount; ++j)
    offset[j] = donned.sample(0).joints[j] - still.joints[j];

  std::vector<std::vector<Real>> white(kJointCount);
  for (int k = 0; k < kReadings; ++k) {
    const Real t = default_arrival(k);
    const GloveSample s = glove.sample(t);
    const GloveSample d = donned.sample(t);
    for (std::size_t j = 0; j < kJointCount; ++j) {
      ASSERT_EQ(d.joints[j] - still.joints[j], offset[j]) << "the offset is drawn once";
      white[j].push_back(s.joints[j] - still.joints[j] - offset[j]);
    }
  }
  const Real mean_bound = 5 / std::sqrt(static_cast<Real>(kReadings)) * noise.joint_sigma_deg;
  for (std::size_t j = 0; j < kJointCount; ++j) {
    const Moments m = moments(white[j]);
    EXPECT_LT(std::abs(m.mean), mean_bound) << "joint " << j;
    EXPECT_NEAR(m.std / noise.joint_sigma_deg, 1, 0.05) << "joint " << j;
  }
}

TEST(NoisyGlove, DonningOffsetsHaveTheirSigmaOverSeeds) {
  const auto inner = still_source();
  const GloveSample still = inner->sample(0);
  GloveNoise noise = no_noise(120, 0.005);
  noise.donning_sigma_deg = 3;
  std::vector<Real> offsets;
  for (std::uint64_t seed = 1; seed <= 300; ++seed) {
    noise.seed = seed;
    const GloveSample s = NoisyGlove(inner, noise).sample(0);
    for (std::size_t j = 0; j < kJointCount; ++j) offsets.push_back(s.joints[j] - still.joints[j]);
  }
  // 6600 offsets: standard errors 0.04 degrees for the mean, 0.9 % for the std.
  const Moments m = moments(offsets);
  EXPECT_LT(std::abs(m.mean), 0.2);
  EXPECT_NEAR(m.std / 3, 1, 0.05);
}

TEST(NoisyGlove, QuantisedAnglesAreWholeCounts) {
  const auto inner = linear_source();
  for (Real per_count : {1.0, 0.25}) {
    GloveNoise noise;
    noise.degrees_per_count = per_count;
    const NoisyGlove glove(inner, noise);
    noise.degrees_per_count = 0;
    const NoisyGlove raw(inner, noise);
    for (int k = 0; k < 2000; ++k) {
      const Real t = k / 1000.0;
      const GloveSample q = glove.sample(t);
      const GloveSample r = raw.sample(t);
      for (std::size_t j = 0; j < kJointCount; ++j) {
        const Real counts = q.joints[j] / per_count;
        ASSERT_EQ(counts, std::round(counts)) << "per count " << per_count << ", joint " << j;
        ASSERT_LE(std::abs(q.joints[j] - r.joints[j]), per_count / 2);
      }
      ASSERT_TRUE(q.p_WH == r.p_WH);  // quantisation touches the joints only
    }
  }
}

TEST(NoisyGlove, RefusesBadSettings) {
  const auto inner = still_source();
  EXPECT_THROW(NoisyGlove(nullptr), std::invalid_argument);
  const Real nan = std::numeric_limits<Real>::quiet_NaN();
  const Real inf = std::numeric_limits<Real>::infinity();
  const auto make = [&](auto change) {
    GloveNoise noise;
    change(noise);
    NoisyGlove glove(inner, noise);
  };
  EXPECT_NO_THROW(make([](GloveNoise&) {}));
  EXPECT_THROW(make([](GloveNoise& n) { n.rate_hz = 0; }), std::invalid_argument);
  EXPECT_THROW(make([](GloveNoise& n) { n.rate_hz = -120; }), std::invalid_argument);
  EXPECT_THROW(make([](GloveNoise& n) { n.rate_hz = 1e7; }), std::invalid_argument);
  EXPECT_THROW(make([](GloveNoise& n) { n.latency_s = 1e30; }), std::invalid_argument);
  EXPECT_THROW(make([](GloveNoise& n) { n.degrees_per_count = 1e-320; }), std::invalid_argument);
  EXPECT_THROW(make([&](GloveNoise& n) { n.rate_hz = inf; }), std::invalid_argument);
  EXPECT_THROW(make([](GloveNoise& n) { n.joint_sigma_deg = -1; }), std::invalid_argument);
  EXPECT_THROW(make([&](GloveNoise& n) { n.donning_sigma_deg = nan; }), std::invalid_argument);
  EXPECT_THROW(make([](GloveNoise& n) { n.degrees_per_count = -1; }), std::invalid_argument);
  EXPECT_THROW(make([&](GloveNoise& n) { n.position_sigma_m = inf; }), std::invalid_argument);
  EXPECT_THROW(make([](GloveNoise& n) { n.orientation_sigma_deg = -0.1; }), std::invalid_argument);
  EXPECT_THROW(make([](GloveNoise& n) { n.latency_s = -0.005; }), std::invalid_argument);
  EXPECT_THROW(make([&](GloveNoise& n) { n.latency_s = nan; }), std::invalid_argument);
}

TEST(NoisyGlove, IsAPureFunctionOfTime) {
  const NoisyGlove glove(std::make_shared<SimulatedGlove>(TestPlan().plan));
  std::vector<Real> times = probe_times();
  for (int k = 0; k <= 900; ++k) {
    times.push_back(k / 120.0 + 0.005);
    times.push_back(std::nextafter(k / 120.0 + 0.005, 0.0));
  }
  expect_pure(glove, times);
}

}  // namespace
}  // namespace dovetail::interaction
