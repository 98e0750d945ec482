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

/// `count` uniformly random rotations with translations uniform in the box
/// [-extent, extent]^3, from a seeded generator (identical on every platform).
std::vector<Transform> random_poses(std::size_t count, Real extent, std::uint64_t seed);

/// A rotation from a unit quaternion (w, x, y, z); the quaternion is normalised first.
Mat3 rotation_from_quaternion(Real w, Real x, Real y, Real z);

}  // namespace dovetail::collision
