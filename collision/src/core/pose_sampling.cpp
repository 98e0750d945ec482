#include "dovetail/collision/pose_sampling.h"

#include <cmath>
#include <numbers>
#include <random>
#include <stdexcept>

namespace dovetail::collision {

namespace {

/// Uniform doubles in [0, 1) from raw 64-bit engine output, so sequences are
/// identical on every platform (std distributions are implementation-defined).
class Uniform {
 public:
  explicit Uniform(std::uint64_t seed) : engine_(seed) {}
  Real next() { return static_cast<Real>(engine_() >> 11) * 0x1.0p-53; }
  Real in(Real lo, Real hi) { return lo + (hi - lo) * next(); }

 private:
  std::mt19937_64 engine_;
};

/// Uniformly distributed rotation (Shoemake's subgroup algorithm).
Mat3 random_rotation(Uniform& u) {
  const Real u1 = u.next(), u2 = u.next(), u3 = u.next();
  const Real a = std::sqrt(1 - u1), b = std::sqrt(u1);
  const Real t1 = 2 * std::numbers::pi * u2, t2 = 2 * std::numbers::pi * u3;
  return rotation_from_quaternion(b * std::cos(t2), a * std::sin(t1), a * std::cos(t1),
                                  b * std::sin(t2));
}

Vec3 random_direction(Uniform& u) {
  const Real z = u.in(-1, 1);
  const Real phi = u.in(0, 2 * std::numbers::pi);
  const Real r = std::sqrt(std::max<Real>(0, 1 - z * z));
  return {r * std::cos(phi), r * std::sin(phi), z};
}

Vec3 centre(const Bounds& b) { return (b.min + b.max) * 0.5; }

}  // namespace

Mat3 rotation_from_quaternion(Real w, Real x, Real y, Real z) {
  const Real n = std::sqrt(w * w + x * x + y * y + z * z);
  w /= n;
  x /= n;
  y /= n;
  z /= n;
  Mat3 R;
  R << 1 - 2 * (y * y + z * z), 2 * (x * y - w * z), 2 * (x * z + w * y),  //
      2 * (x * y + w * z), 1 - 2 * (x * x + z * z), 2 * (y * z - w * x),   //
      2 * (x * z - w * y), 2 * (y * z + w * x), 1 - 2 * (x * x + y * y);
  return R;
}

std::vector<Transform> random_poses(std::size_t count, Real extent, std::uint64_t seed) {
  Uniform u(seed);
  std::vector<Transform> poses(count);
  for (Transform& X : poses) {
    X.R = random_rotation(u);
    X.t = Vec3(u.in(-extent, extent), u.in(-extent, extent), u.in(-extent, extent));
  }
  return poses;
}

std::vector<Real> tumble_distances(const TumbleSettings& settings) {
  const Real span = settings.last_distance - settings.first_distance;
  if (!(settings.distance_step > 0) || !(span >= 0) || !std::isfinite(span) ||
      span / settings.distance_step > 1e6) {
    throw std::invalid_argument(
        "tumble distances need a step > 0, last >= first and at most a million distances");
  }
  const auto count = static_cast<std::size_t>(std::floor(span / settings.distance_step + 1e-6)) + 1;
  std::vector<Real> distances(count);
  for (std::size_t k = 0; k < count; ++k) {
    distances[k] = settings.first_distance + static_cast<Real>(k) * settings.distance_step;
  }
  return distances;
}

std::vector<TumblePose> tumble_poses(const TumbleSettings& settings) {
  if (settings.turns < 1) throw std::invalid_argument("a tumble needs at least one turn");
  const std::vector<Real> distances = tumble_distances(settings);
  const Vec3 axis = Vec3(1, 2, 3).normalized();
  std::vector<Mat3> turns(static_cast<std::size_t>(settings.turns));
  for (int k = 0; k < settings.turns; ++k) {
    const Real angle = 2 * std::numbers::pi * k / settings.turns;
    turns[static_cast<std::size_t>(k)] =
        Eigen::AngleAxis<Real>(angle, axis).toRotationMatrix() *
        Eigen::AngleAxis<Real>(2 * angle, Vec3::UnitZ()).toRotationMatrix();
  }
  std::vector<TumblePose> poses;
  poses.reserve(distances.size() * turns.size());
  for (std::size_t d = 0; d < distances.size(); ++d) {
    for (const Mat3& R : turns) {
      TumblePose pose;
      pose.X_AB.R = R;
      pose.X_AB.t = Vec3(distances[d], 0, 0);
      pose.distance_index = d;
      poses.push_back(pose);
    }
  }
  return poses;
}

std::vector<SampledPose> contact_distance_poses(const CollisionModel& a, const CollisionModel& b,
                                                const ContactPoseSettings& settings) {
  const Bounds bounds_a = mesh_bounds(a.mesh());
  const Bounds bounds_b = mesh_bounds(b.mesh());
  const Real diag_a = (bounds_a.max - bounds_a.min).norm();
  const Real diag_b = (bounds_b.max - bounds_b.min).norm();
  const Real size = std::max(diag_a, diag_b);
  const Real far = 0.5 * (diag_a + diag_b) * 1.01;
  const Vec3 c_a = centre(bounds_a);
  const Vec3 c_b = centre(bounds_b);

  Uniform u(settings.seed);
  std::vector<SampledPose> poses;
  // Direction samples that never touch (B passes through a hole of A) are redrawn, a bounded number
  // of times.
  const int max_attempts = settings.directions * 20 + 100;
  int found = 0;
  for (int attempt = 0; attempt < max_attempts && found < settings.directions; ++attempt) {
    const Mat3 R = random_rotation(u);
    const Vec3 d = random_direction(u);
    auto pose_at = [&](Real s) {
      Transform X;
      X.R = R;
      X.t = c_a + s * d - R * c_b;
      return X;
    };
    auto colliding = [&](Real s) { return a.collide(b, pose_at(s)).colliding; };
    // Step inwards from `far` (bounding spheres apart) to the first colliding distance.
    Real lo = -1;
    Real hi = far;
    for (int k = 1; k <= 16; ++k) {
      const Real s = far * (16 - k) / 16.0;
      if (colliding(s)) {
        lo = s;
        break;
      }
      hi = s;
    }
    if (lo < 0) continue;
    for (int step = 0; step < settings.bisection_steps; ++step) {
      const Real mid = 0.5 * (lo + hi);
      (colliding(mid) ? lo : hi) = mid;
    }
    const Real contact = 0.5 * (lo + hi);
    for (Real gap : settings.gaps) poses.push_back({pose_at(contact + gap * size), gap});
    ++found;
  }
  return poses;
}

}  // namespace dovetail::collision
