#include "dovetail/collision/task_system.h"

#include <gtest/gtest.h>

#include <atomic>
#include <vector>

namespace dovetail::collision {
namespace {

TEST(TaskSystem, EveryIndexExactlyOnceAtAnyThreadCount) {
  for (int threads : {1, 2, 3, 8}) {
    const auto tasks = make_task_system(threads);
    EXPECT_EQ(tasks->thread_count(), threads);
    for (std::size_t count : {0u, 1u, 7u, 1000u}) {
      for (std::size_t grain : {1u, 3u, 64u}) {
        std::vector<std::atomic<int>> hits(count);
        tasks->parallel_for(count, grain, [&](std::size_t begin, std::size_t end) {
          EXPECT_LE(end - begin, grain);
          for (std::size_t i = begin; i < end; ++i) hits[i].fetch_add(1);
        });
        for (std::size_t i = 0; i < count; ++i)
          ASSERT_EQ(hits[i].load(), 1) << threads << " " << count;
      }
    }
  }
}

TEST(TaskSystem, ZeroMeansHardwareThreadsAndNegativeIsRejected) {
  EXPECT_GE(make_task_system(0)->thread_count(), 1);
  EXPECT_THROW(make_task_system(-1), std::invalid_argument);
}

}  // namespace
}  // namespace dovetail::collision
