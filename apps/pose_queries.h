#pragma once
/// \file pose_queries.h
/// Running one model pair over a list of poses, serially or on worker threads,
/// with results in pose order whatever the thread count: collision verdicts,
/// distances, tolerance verdicts and contact patches.

#include <cstddef>
#include <cstdint>
#include <functional>
#include <span>
#include <string>
#include <vector>

#include "dovetail/collision/contacts.h"
#include "dovetail/collision/distance.h"
#include "dovetail/collision/model.h"

namespace dovetail::cli {

/// Runs `one(i)` for every i in [0, n): on the calling thread when `threads`
/// is 1 (or n < 2), otherwise on that many workers (0: all cores). Distinct
/// indices may run concurrently. Returns the wall-clock time in ms.
double for_each_pose(std::size_t n, int threads, const std::function<void(std::size_t)>& one);

/// Verdicts and work of a pose list.
struct PoseQueryResult {
  std::vector<std::uint8_t> colliding;  ///< 1/0 per pose, in pose order
  std::uint64_t colliding_count = 0;
  std::uint64_t pairs_total = 0;  ///< intersecting triangle pairs reported
  collision::CollideStats stats;  ///< summed over all poses
  double wall_ms = 0;             ///< wall-clock time of all queries
};

/// Queries `a` against `b` at every X_AB in `poses`; `threads` 1 runs on the
/// calling thread, more uses that many workers, 0 all cores.
PoseQueryResult run_pose_queries(const collision::CollisionModel& a,
                                 const collision::CollisionModel& b,
                                 std::span<const collision::Transform> poses,
                                 const collision::CollideRequest& request, int threads);

/// What the distance and tolerance queries run on: both meshes, and either
/// both distance models (the RSS hierarchies) or none (brute force: every
/// triangle pair).
struct DistanceInputs {
  const collision::Mesh* mesh_a = nullptr;
  const collision::Mesh* mesh_b = nullptr;
  const collision::DistanceModel* model_a = nullptr;  ///< null: brute force
  const collision::DistanceModel* model_b = nullptr;  ///< null: brute force
};

/// Minimum distances of a pose list.
struct DistanceQueryResult {
  std::vector<double> distances;      ///< per pose, in pose order; 0 exactly when colliding
  std::uint64_t colliding_count = 0;  ///< poses at distance 0
  double distance_min = 0;            ///< smallest distance; infinity for no poses
  double distance_max = 0;            ///< largest distance; -infinity for no poses
  collision::CollideStats stats;      ///< volume pair bounds and triangle pair distances, summed
  double wall_ms = 0;
};

/// distance() (or distance_brute() without models) at every pose.
DistanceQueryResult run_distance_queries(const DistanceInputs& inputs,
                                         std::span<const collision::Transform> poses, int threads);

/// Tolerance verdicts of a pose list.
struct ToleranceQueryResult {
  std::vector<std::uint8_t> within;  ///< 1 when the distance is at most the tolerance
  std::uint64_t within_count = 0;
  collision::CollideStats stats;  ///< summed over all poses
  double wall_ms = 0;
};

/// within_tolerance() (or within_tolerance_brute() without models) at every
/// pose; `tolerance` must be finite and >= 0.
ToleranceQueryResult run_tolerance_queries(const DistanceInputs& inputs,
                                           std::span<const collision::Transform> poses,
                                           double tolerance, int threads);

/// Contact patches of a pose list, already written as JSON lines.
struct ContactQueryResult {
  std::vector<std::string> lines;  ///< contact_line_json of each pose, in pose order
  std::uint64_t colliding_count = 0;
  std::uint64_t pairs_total = 0;    ///< intersecting triangle pairs of the all-pairs queries
  std::uint64_t patches_total = 0;  ///< patches of every kind
  std::uint64_t face_patches = 0;
  std::uint64_t curve_patches = 0;
  std::uint64_t point_patches = 0;
  std::uint64_t penetrating_patches = 0;
  collision::CollideStats stats;  ///< of the all-pairs queries, summed
  double wall_ms = 0;             ///< all-pairs queries and patches together
};

/// At every pose: the all-pairs query of `a` against `b`, then
/// compute_contacts() on its pairs with `request`.
ContactQueryResult run_contact_queries(const collision::CollisionModel& a,
                                       const collision::CollisionModel& b,
                                       std::span<const collision::Transform> poses,
                                       const collision::ContactRequest& request, int threads);

/// A distance as written per pose: `%.17g`, so it reads back bit for bit.
std::string format_distance(double distance);

/// One pose's contacts as one line of JSON (no newline):
/// `{"pose":i,"colliding":..,"patches":[{"kind":..,"point":[x,y,z],"normal":[x,y,z],
/// "area":..,"length":..,"depth":..,"penetrating":..,"pairs":N},...]}`.
std::string contact_line_json(std::size_t pose, bool colliding,
                              std::span<const collision::ContactPatch> patches);

}  // namespace dovetail::cli
