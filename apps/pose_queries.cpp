#include "pose_queries.h"

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>
#include <tbb/task_arena.h>

#include <chrono>

namespace dovetail::cli {

PoseQueryResult run_pose_queries(const collision::CollisionModel& a,
                                 const collision::CollisionModel& b,
                                 std::span<const collision::Transform> poses,
                                 const collision::CollideRequest& request, int threads) {
  const std::size_t n = poses.size();
  PoseQueryResult result;
  result.colliding.assign(n, 0);
  std::vector<collision::CollideStats> stats(n);
  std::vector<std::uint64_t> pairs(n, 0);

  auto one = [&](std::size_t i) {
    const collision::CollideResult r = a.collide(b, poses[i], request);
    result.colliding[i] = r.colliding ? 1 : 0;
    stats[i] = r.stats;
    pairs[i] = r.pairs.size();
  };

  const auto start = std::chrono::steady_clock::now();
  if (threads == 1 || n < 2) {
    for (std::size_t i = 0; i < n; ++i) one(i);
  } else {
    tbb::task_arena arena(threads > 0 ? threads : tbb::task_arena::automatic);
    arena.execute([&] {
      tbb::parallel_for(tbb::blocked_range<std::size_t>(0, n),
                        [&](const tbb::blocked_range<std::size_t>& range) {
                          for (std::size_t i = range.begin(); i != range.end(); ++i) one(i);
                        });
    });
  }
  result.wall_ms =
      std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start).count();

  // Summed in pose order, so the totals do not depend on scheduling.
  for (std::size_t i = 0; i < n; ++i) {
    result.colliding_count += result.colliding[i];
    result.pairs_total += pairs[i];
    result.stats.volume_tests += stats[i].volume_tests;
    result.stats.triangle_tests += stats[i].triangle_tests;
  }
  return result;
}

}  // namespace dovetail::cli
