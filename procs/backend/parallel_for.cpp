#include "backend/parallel_for.hpp"

#include <algorithm>
#include <chrono>

#if defined(__x86_64__) || defined(__i386__)
#include <immintrin.h>
#define DLSLOT_CPU_RELAX() _mm_pause()
#else
#define DLSLOT_CPU_RELAX() std::this_thread::yield()
#endif

namespace dlslot::backend {
namespace {

// How long an idle worker watches for the next job before it sleeps. A frame's jobs come a
// fraction of a millisecond apart, and waking a sleeping thread costs tens of microseconds,
// about what one object's elimination takes; frames come ~100 ms apart, so between frames the
// worker sleeps.
constexpr auto kSpin = std::chrono::microseconds(100);

}  // namespace

ParallelFor::ParallelFor(int threads) {
  for (int t = 1; t < threads; ++t) workers_.emplace_back([this, t] { workerLoop(t); });
}

ParallelFor::~ParallelFor() {
  {
    std::lock_guard<std::mutex> lock(mutex_);
    stop_ = true;
    ++generation_;
  }
  wake_.notify_all();
  for (std::thread& t : workers_) t.join();
}

ParallelFor::Job::Job(const std::function<void(int)>* task_, int n_, int segments_)
    : task(task_), n(n_), segments(segments_), next(new std::atomic<int>[segments_]) {
  for (int s = 0; s < segments; ++s) next[s] = 0;
}

void ParallelFor::Job::work(int thread) {
  for (int k = 0; k < segments; ++k) {
    const int s = (thread + k) % segments;
    const int begin = static_cast<int>(static_cast<long>(n) * s / segments);
    const int end = static_cast<int>(static_cast<long>(n) * (s + 1) / segments);
    for (int i = begin + next[s].fetch_add(1); i < end; i = begin + next[s].fetch_add(1)) {
      try {
        (*task)(i);
      } catch (...) {
        std::lock_guard<std::mutex> lock(error_mutex);
        if (!error) error = std::current_exception();
      }
      done.fetch_add(1, std::memory_order_release);
    }
  }
}

void ParallelFor::operator()(int n, const std::function<void(int)>& task) {
  if (n <= 0) return;
  const bool share = !workers_.empty() && n > 1;
  auto job = std::make_shared<Job>(&task, n, share ? threads() : 1);
  if (share) {
    bool notify;
    {
      std::lock_guard<std::mutex> lock(mutex_);
      job_ = job;
      ++generation_;
      notify = sleeping_ > 0;
    }
    if (notify) wake_.notify_all();
  }
  job->work(0);
  // The items still running are on workers: wait for them (briefly) rather than sleep.
  while (job->done.load(std::memory_order_acquire) < n) DLSLOT_CPU_RELAX();
  if (job->error) std::rethrow_exception(job->error);
}

void ParallelFor::workerLoop(int thread) {
  unsigned seen = 0;
  for (;;) {
    const auto until = std::chrono::steady_clock::now() + kSpin;
    for (int k = 0; generation_.load(std::memory_order_acquire) == seen; ++k) {
      DLSLOT_CPU_RELAX();
      if (k % 64 == 0 && std::chrono::steady_clock::now() > until) break;
    }
    std::shared_ptr<Job> job;
    {
      std::unique_lock<std::mutex> lock(mutex_);
      ++sleeping_;
      wake_.wait(lock, [&] { return generation_.load() != seen; });
      --sleeping_;
      if (stop_) return;
      seen = generation_.load();
      job = job_;
    }
    job->work(thread);
  }
}

}  // namespace dlslot::backend
