#pragma once
/// \file task_system.h
/// Where the collision pipeline's threads come from.
///
/// Why: threads come from one place. The pipeline is handed this small
/// interface; oneTBB sits behind it by default and a plain loop when one
/// thread is asked for, so a serial run involves no thread at all. Tasks
/// write only their own outputs, so results never depend on how many threads
/// ran them.

#include <cstddef>
#include <functional>
#include <memory>

namespace dovetail::collision {

/// Runs independent chunks of an index range.
class TaskSystem {
 public:
  virtual ~TaskSystem() = default;

  /// Threads this system uses (1 = serial).
  virtual int thread_count() const = 0;

  /// Calls body(begin, end) on disjoint chunks covering [0, count), each at
  /// most `grain` long, possibly in parallel; returns when all are done.
  virtual void parallel_for(std::size_t count, std::size_t grain,
                            const std::function<void(std::size_t, std::size_t)>& body) = 0;
};

/// A task system with `threads` threads: serial for 1, oneTBB otherwise
/// (a plain std::thread pool in ThreadSanitizer builds, which cannot see
/// inside the packaged oneTBB); 0 means one per hardware thread.
std::unique_ptr<TaskSystem> make_task_system(int threads);

}  // namespace dovetail::collision
