// ParallelFor: every item runs exactly once whatever the thread count, a task's exception
// reaches the caller, and the pool serves many jobs in a row (the solver's pattern).
#include <gtest/gtest.h>

#include <atomic>
#include <set>
#include <stdexcept>
#include <thread>

#include "backend/parallel_for.hpp"

using dlslot::backend::ParallelFor;

TEST(BackendParallelFor, RunsEveryItemOnceOnEveryThreadCount) {
  for (int threads : {1, 2, 4}) {
    ParallelFor parallel(threads);
    EXPECT_EQ(parallel.threads(), threads);
    for (int job = 0; job < 200; ++job) {
      const int n = job % 7;  // 0 and 1 item too
      std::vector<std::atomic<int>> runs(n);
      parallel(n, [&](int i) { runs[i].fetch_add(1); });
      for (int i = 0; i < n; ++i) ASSERT_EQ(runs[i].load(), 1) << "threads " << threads << " job " << job << " item " << i;
    }
  }
}

TEST(BackendParallelFor, UsesTheWorkers) {
  ParallelFor parallel(2);
  std::mutex mutex;
  std::set<std::thread::id> ids;
  // Items long enough that the caller cannot run them all before the worker wakes up.
  for (int attempt = 0; attempt < 50 && ids.size() < 2; ++attempt)
    parallel(8, [&](int) {
      std::this_thread::sleep_for(std::chrono::milliseconds(1));
      std::lock_guard<std::mutex> lock(mutex);
      ids.insert(std::this_thread::get_id());
    });
  EXPECT_EQ(ids.size(), 2u);
}

TEST(BackendParallelFor, RethrowsATasksExceptionAfterTheOthersRan) {
  ParallelFor parallel(2);
  std::atomic<int> ran{0};
  EXPECT_THROW(parallel(10,
                        [&](int i) {
                          ran.fetch_add(1);
                          if (i == 3) throw std::runtime_error("item 3");
                        }),
               std::runtime_error);
  EXPECT_EQ(ran.load(), 10);
  // Still usable.
  std::atomic<int> after{0};
  parallel(5, [&](int) { after.fetch_add(1); });
  EXPECT_EQ(after.load(), 5);
}
