#include "dovetail/collision/task_system.h"

#include <oneapi/tbb/blocked_range.h>
#include <oneapi/tbb/global_control.h>
#include <oneapi/tbb/info.h>
#include <oneapi/tbb/parallel_for.h>
#include <oneapi/tbb/task_arena.h>

#include <algorithm>
#include <atomic>
#include <condition_variable>
#include <mutex>
#include <stdexcept>
#include <thread>
#include <vector>

namespace dovetail::collision {

namespace {

class SerialTaskSystem final : public TaskSystem {
 public:
  int thread_count() const override { return 1; }
  void parallel_for(std::size_t count, std::size_t grain,
                    const std::function<void(std::size_t, std::size_t)>& body) override {
    grain = std::max<std::size_t>(grain, 1);
    for (std::size_t begin = 0; begin < count; begin += grain)
      body(begin, std::min(count, begin + grain));
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

/// A plain pool of std::threads: workers and the calling thread take chunks
/// from one atomic counter. Used under ThreadSanitizer, where the packaged
/// oneTBB (not instrumented) hands work between threads invisibly to the
/// sanitizer, so every hand-off would look like a race.
class ThreadPoolTaskSystem final : public TaskSystem {
 public:
  explicit ThreadPoolTaskSystem(int threads) : threads_(threads) {
    for (int i = 1; i < threads; ++i) workers_.emplace_back([this] { work(); });
  }

  ~ThreadPoolTaskSystem() override {
    {
      std::lock_guard lock(mutex_);
      stop_ = true;
    }
    wake_.notify_all();
    for (std::thread& t : workers_) t.join();
  }

  int thread_count() const override { return threads_; }

  void parallel_for(std::size_t count, std::size_t grain,
                    const std::function<void(std::size_t, std::size_t)>& body) override {
    grain = std::max<std::size_t>(grain, 1);
    {
      std::lock_guard lock(mutex_);
      body_ = &body;
      count_ = count;
      grain_ = grain;
      next_.store(0);
      busy_ = static_cast<int>(workers_.size());
      ++round_;
    }
    wake_.notify_all();
    run_chunks();
    std::unique_lock lock(mutex_);
    done_.wait(lock, [this] { return busy_ == 0; });
    body_ = nullptr;
  }

 private:
  void run_chunks() {
    for (;;) {
      const std::size_t begin = next_.fetch_add(grain_);
      if (begin >= count_) return;
      (*body_)(begin, std::min(count_, begin + grain_));
    }
  }

  void work() {
    std::uint64_t seen = 0;
    for (;;) {
      {
        std::unique_lock lock(mutex_);
        wake_.wait(lock, [&] { return stop_ || round_ != seen; });
        if (stop_) return;
        seen = round_;
      }
      run_chunks();
      {
        std::lock_guard lock(mutex_);
        --busy_;
      }
      done_.notify_one();
    }
  }

  int threads_;
  std::vector<std::thread> workers_;
  std::mutex mutex_;
  std::condition_variable wake_, done_;
  const std::function<void(std::size_t, std::size_t)>* body_ = nullptr;
  std::size_t count_ = 0, grain_ = 1;
  std::atomic<std::size_t> next_{0};
  int busy_ = 0;
  std::uint64_t round_ = 0;
  bool stop_ = false;
};

#if defined(__SANITIZE_THREAD__)
constexpr bool kUseThreadPool = true;
#else
constexpr bool kUseThreadPool = false;
#endif

}  // namespace

std::unique_ptr<TaskSystem> make_task_system(int threads) {
  if (threads < 0) throw std::invalid_argument("task system: thread count must be >= 0");
  if (threads == 0) threads = std::max(1, tbb::info::default_concurrency());
  if (threads == 1) return std::make_unique<SerialTaskSystem>();
  if (kUseThreadPool) return std::make_unique<ThreadPoolTaskSystem>(threads);
  return std::make_unique<TbbTaskSystem>(threads);
}

}  // namespace dovetail::collision
