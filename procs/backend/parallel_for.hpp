// A fixed set of worker threads for the backend's loops over independent items (the objects'
// eliminations, the factors' linearizations): the calling thread works too, so `threads` = 2
// uses one worker. Items are claimed one at a time (objects differ in size), each thread from
// its own share first (see Job); results go to per-item slots that the caller then sums in item order, so the outcome does not depend on
// the number of threads or on which thread ran what.
#pragma once

#include <atomic>
#include <condition_variable>
#include <exception>
#include <functional>
#include <memory>
#include <mutex>
#include <thread>
#include <vector>

namespace dlslot::backend {

class ParallelFor {
 public:
  explicit ParallelFor(int threads = 1);
  ~ParallelFor();
  ParallelFor(const ParallelFor&) = delete;
  ParallelFor& operator=(const ParallelFor&) = delete;

  int threads() const { return static_cast<int>(workers_.size()) + 1; }

  // Calls task(i) for every i in [0, n) and returns when all calls have returned. The first
  // exception a task throws is rethrown here (the other items still run).
  void operator()(int n, const std::function<void(int)>& task);

 private:
  // The items are cut into one contiguous segment per thread. A thread runs its own segment
  // first, then helps with the others: the same thread tends to get the same items in the
  // solver's successive loops over the objects, whose matrices then stay in its core's cache.
  struct Job {
    const std::function<void(int)>* task = nullptr;
    int n = 0, segments = 1;
    std::unique_ptr<std::atomic<int>[]> next;  // per segment: items claimed
    std::atomic<int> done{0};
    std::mutex error_mutex;
    std::exception_ptr error;
    Job(const std::function<void(int)>* task, int n, int segments);
    void work(int thread);  // claims and runs items until none is left
  };
  void workerLoop(int thread);

  std::vector<std::thread> workers_;
  std::mutex mutex_;
  std::condition_variable wake_;
  std::shared_ptr<Job> job_;            // the current job; a late worker keeps it alive
  std::atomic<unsigned> generation_{0};  // bumped per job: workers spin on it before sleeping
  int sleeping_ = 0;
  bool stop_ = false;
};

// task(i) for i in [0, n) on `pool`'s threads, or in order on this thread without a pool.
inline void parallelFor(ParallelFor* pool, int n, const std::function<void(int)>& task) {
  if (pool) {
    (*pool)(n, task);
  } else {
    for (int i = 0; i < n; ++i) task(i);
  }
}

}  // namespace dlslot::backend
