#pragma once
/// \file pose_queries.h
/// Running one model pair over a list of poses, serially or on worker threads,
/// with results in pose order whatever the thread count.

#include <cstdint>
#include <span>
#include <vector>

#include "dovetail/collision/model.h"

namespace dovetail::cli {

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

}  // namespace dovetail::cli
