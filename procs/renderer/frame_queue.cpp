#include "frame_queue.hpp"

#include <sys/resource.h>
#include <sys/syscall.h>
#include <unistd.h>

#include <chrono>
#include <stdexcept>

namespace dlslot::renderer {

FrameQueue::FrameQueue(FrameWriter& writer, int max_queued, bool skip_when_behind)
    : writer_(writer),
      max_queued_(static_cast<size_t>(std::max(1, max_queued))),
      skip_when_behind_(skip_when_behind),
      thread_([this] { run(); }) {}

FrameQueue::~FrameQueue() {
  try {
    finish();
  } catch (...) {
  }
}

bool FrameQueue::submit(RenderInput in) {
  std::unique_lock<std::mutex> lock(mutex_);
  if (stop_) throw std::logic_error("FrameQueue::submit after finish");
  if (skip_when_behind_ && queue_.size() >= max_queued_) {
    ++skipped_;
    return false;
  }
  // Never skipping, the backlog still has a bound (each frame holds its scan, ~2 MB): past it
  // the receiving thread waits.
  idle_.wait(lock, [this] { return queue_.size() < kMaxBacklog || !error_.empty(); });
  queue_.push_back(std::move(in));
  wake_.notify_one();
  return true;
}

std::vector<FrameQueue::Written> FrameQueue::takeWritten() {
  std::lock_guard<std::mutex> lock(mutex_);
  if (!error_.empty()) throw std::runtime_error(error_);
  std::vector<Written> out;
  out.swap(written_);
  return out;
}

void FrameQueue::finish() {
  {
    std::unique_lock<std::mutex> lock(mutex_);
    idle_.wait(lock, [this] { return (queue_.empty() && !busy_) || !error_.empty(); });
    stop_ = true;
    wake_.notify_one();
  }
  if (thread_.joinable()) thread_.join();
}

int FrameQueue::skipped() const {
  std::lock_guard<std::mutex> lock(mutex_);
  return skipped_;
}

void FrameQueue::run() {
  // The lowest CPU priority (Linux nice is per thread): on a shared machine the estimator's
  // processes get the cores first; the images catch up when they are idle.
  const id_t tid = static_cast<id_t>(syscall(SYS_gettid));
  const int base_nice = getpriority(PRIO_PROCESS, tid);
  setpriority(PRIO_PROCESS, tid, 19);
  bool finishing = false;
  std::unique_lock<std::mutex> lock(mutex_);
  while (true) {
    wake_.wait(lock, [this] { return stop_ || !queue_.empty(); });
    if (queue_.empty()) return;  // stop_
    if (stop_ && !finishing) {
      // The run is over: nothing is left to yield to, and on a loaded machine the backlog at
      // nice 19 could take minutes. Raising a thread's priority back needs CAP_SYS_NICE (or
      // RLIMIT_NICE); without it the backlog is written at 19 all the same.
      finishing = true;
      setpriority(PRIO_PROCESS, tid, base_nice);
    }
    RenderInput in = std::move(queue_.front());
    queue_.pop_front();
    busy_ = true;
    lock.unlock();
    const auto t0 = std::chrono::steady_clock::now();
    std::string error;
    try {
      writer_.write(in);
    } catch (const std::exception& e) {
      error = e.what();
    }
    const double ms = std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count();
    lock.lock();
    busy_ = false;
    if (!error.empty()) {
      error_ = error;
      queue_.clear();
    } else {
      written_.push_back({in.frame, ms, in.has_tracks});
    }
    idle_.notify_all();
  }
}

}  // namespace dlslot::renderer
