#pragma once
/// \file pose_sampling.h
/// Pose lists for benchmarks and tests.
///
/// Contact-distance poses (Trenkel, Weller, Zachmann): for a random
/// orientation of B and a random direction, B's centre is placed along the
/// direction from A's centre; bisection finds the distance at which the two
/// meshes just touch; poses are then generated at gaps of a fraction of the
/// object size (the larger bounding-box diagonal) from that contact distance,
/// negative gaps pushing B into A.

#include <cstddef>
#include <cstdint>
#include <vector>

#include "dovetail/collision/model.h"
#include "dovetail/collision/types.h"

namespace dovetail::collision {

/// Settings of a contact-distance pose list.
struct ContactPoseSettings {
  int directions = 100;  ///< random (orientation, direction) samples
  std::vector<Real> gaps = {-0.05, -0.01, -0.001, 0.001, 0.01, 0.05, 0.20};
  std::uint64_t seed = 1;
  int bisection_steps = 40;
};

/// One generated pose with the gap it was generated for.
struct SampledPose {
  Transform X_AB;
  Real gap = 0;  ///< fraction of object size; < 0 means pushed into contact
};

/// Contact-distance poses of B relative to A, using `a`/`b` (any method) for
/// the bisection. Order: for each direction, one pose per gap.
std::vector<SampledPose> contact_distance_poses(const CollisionModel& a, const CollisionModel& b,
                                                const ContactPoseSettings& settings);

/// Zachmann's tumbling protocol: B's centre at distances along A's x axis
/// from A's centre, and at each distance B turned through a full rotation in
/// `turns` steps, about the oblique axis (1, 2, 3) and, twice as fast, about
/// z. Meant for objects scaled into [-1, 1]^3, where distances 0 to 3 go
/// from deep overlap to free.
struct TumbleSettings {
  Real first_distance = 0;
  Real last_distance = 3;
  Real distance_step = 0.1;
  int turns = 360;
};

/// One pose of a tumble and the index of its distance in tumble_distances().
struct TumblePose {
  Transform X_AB;
  std::size_t distance_index = 0;
};

/// first_distance + k * distance_step for k = 0, 1, ... up to last_distance
/// (within a millionth of a step). Throws std::invalid_argument unless the
/// step is > 0, last >= first and there are at most a million distances.
std::vector<Real> tumble_distances(const TumbleSettings& settings);

/// Every pose of the tumble, distance-major: for each distance, `turns`
/// rotations. Throws std::invalid_argument as tumble_distances() does, or
/// when turns < 1.
std::vector<TumblePose> tumble_poses(const TumbleSettings& settings);

/// `count` uniformly random rotations with translations uniform in the box
/// [-extent, extent]^3, from a seeded generator (identical on every platform).
std::vector<Transform> random_poses(std::size_t count, Real extent, std::uint64_t seed);

/// A rotation from a unit quaternion (w, x, y, z); the quaternion is normalised first.
Mat3 rotation_from_quaternion(Real w, Real x, Real y, Real z);

}  // namespace dovetail::collision
