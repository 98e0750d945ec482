#include "dovetail/collision/task_system.h"

#include <oneapi/tbb/blocked_range.h>
#include <oneapi/tbb/global_control.h>
#include <oneapi/tbb/info.h>
#include <oneapi/tbb/parallel_for.h>
#include <oneapi/tbb/task_arena.h>

#include <algorithm>
#include <stdexcept>

namespace dovetail::collision {

namespace {

class SerialTaskSystem final : public TaskSystem {
 public:
  int thread_count() const override { return 1; }
  void parallel_for(std::size_t count, std::size_t grain,
                    const std::function<void(std::size_t, std::size_t)>& body) override {
    grain = std::max<std::size_t>(grain, 1);
    for (std::size_t begin = 0; begin < count; begin += grain) body(begin, std::min(count, begin + grain));
  }
};

/// oneTBB in an arena of its own, so the thread count is exactly what was
/// asked for; the global limit is raised while it lives, so that more threads
/// than cores (oversubscription) are really used when asked for.
class TbbTaskSystem final : public TaskSystem {
 public:
  explicit TbbTaskSystem(int threads)
      : limit_(tbb::global_control::max_allowed_parallelism, static_cast<std::size_t>(threads)),
        arena_(threads),
        threads_(threads) {}
  int thread_count() const override { return threads_; }
  void parallel_for(std::size_t count, std::size_t grain,
                    const std::function<void(std::size_t, std::size_t)>& body) override {
    grain = std::max<std::size_t>(grain, 1);
    arena_.execute([&] {
      tbb::parallel_for(
          tbb::blocked_range<std::size_t>(0, count, grain),
          [&](const tbb::blocked_range<std::size_t>& r) { body(r.begin(), r.end()); },
          tbb::simple_partitioner());
    });
  }

 private:
  tbb::global_control limit_;
  tbb::task_arena arena_;
  int threads_;
};

}  // namespace

std::unique_ptr<TaskSystem> make_task_system(int threads) {
  if (threads < 0) throw std::invalid_argument("task system: thread count must be >= 0");
  if (threads == 0) threads = std::max(1, tbb::info::default_concurrency());
  if (threads == 1) return std::make_unique<SerialTaskSystem>();
  return std::make_unique<TbbTaskSystem>(threads);
}

}  // namespace dovetail::collision
