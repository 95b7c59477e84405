#include "mapper/idle_worker.hpp"

#include <pthread.h>
#include <sched.h>
#include <time.h>

#include <algorithm>
#include <chrono>
#include <cstring>
#include <stdexcept>

#include "dlslot/cpu_clock.hpp"

namespace dlslot::mapper {

IdleWorker::IdleWorker(std::string name, bool threaded, size_t capacity, bool idle_priority, double cpu_share)
    : name_(std::move(name)), threaded_(threaded), capacity_(capacity), cpu_share_(cpu_share) {
  if (capacity_ < 1) throw std::invalid_argument(name_ + ": the queue's capacity must be >= 1");
  if (!(cpu_share_ > 0 && cpu_share_ <= 1))
    throw std::invalid_argument(name_ + ": the share of a core must be in (0, 1], got " + std::to_string(cpu_share_));
  if (!threaded_) return;
  thread_ = std::thread([this] { work(); });
  if (idle_priority) setPriority(true);
}

IdleWorker::~IdleWorker() {
  if (!threaded_) return;
  setPriority(false);  // what is left runs at normal priority: the process is ending
  {
    std::lock_guard<std::mutex> lock(mutex_);
    stop_ = unlimited_ = true;
  }
  wake_.notify_all();
  if (thread_.joinable()) thread_.join();
}

void IdleWorker::setPriority(bool idle) {
  sched_param p{};
  p.sched_priority = 0;
  const int err = pthread_setschedparam(thread_.native_handle(), idle ? SCHED_IDLE : SCHED_OTHER, &p);
  std::lock_guard<std::mutex> lock(mutex_);
  if (err != 0)
    priority_error_ = name_ + ": could not set the thread to " + (idle ? "SCHED_IDLE" : "SCHED_OTHER") + ": " +
                      std::strerror(err);
  else if (idle)
    priority_error_.clear();
}

void IdleWorker::post(std::function<void()> job) {
  if (!threaded_) {
    job();  // inline: an exception reaches the caller
    return;
  }
  {
    std::unique_lock<std::mutex> lock(mutex_);
    space_.wait(lock, [this] { return queue_.size() < capacity_; });
    queue_.push_back(std::move(job));
    max_backlog_ = std::max(max_backlog_, queue_.size());
  }
  wake_.notify_one();
}

void IdleWorker::liftLimits() {
  if (!threaded_) return;
  setPriority(false);
  std::lock_guard<std::mutex> lock(mutex_);
  unlimited_ = true;
  wake_.notify_all();  // ends a rest
}

void IdleWorker::drain() {
  liftLimits();
  wait();
}

void IdleWorker::wait() {
  if (!threaded_) return;
  std::unique_lock<std::mutex> lock(mutex_);
  idle_.wait(lock, [this] { return queue_.empty() && !busy_; });
}

size_t IdleWorker::backlog() const {
  std::lock_guard<std::mutex> lock(mutex_);
  return queue_.size();
}

size_t IdleWorker::maxBacklog() const {
  std::lock_guard<std::mutex> lock(mutex_);
  return max_backlog_;
}

std::string IdleWorker::priorityError() const {
  std::lock_guard<std::mutex> lock(mutex_);
  return priority_error_;
}

double IdleWorker::cpuMs() const {
  if (!threaded_) return 0;
  clockid_t clock;
  timespec ts{};
  if (pthread_getcpuclockid(const_cast<std::thread&>(thread_).native_handle(), &clock) != 0 ||
      clock_gettime(clock, &ts) != 0)
    return 0;
  return 1e3 * static_cast<double>(ts.tv_sec) + 1e-6 * static_cast<double>(ts.tv_nsec);
}

std::vector<std::string> IdleWorker::takeErrors() {
  std::lock_guard<std::mutex> lock(mutex_);
  std::vector<std::string> out;
  out.swap(errors_);
  return out;
}

void IdleWorker::work() {
  for (;;) {
    std::function<void()> job;
    {
      std::unique_lock<std::mutex> lock(mutex_);
      wake_.wait(lock, [this] { return stop_ || !queue_.empty(); });
      if (queue_.empty()) return;  // stopping, nothing left
      job = std::move(queue_.front());
      queue_.pop_front();
      busy_ = true;
    }
    space_.notify_all();
    const double start = threadCpuMs();
    try {
      job();
    } catch (const std::exception& e) {
      std::lock_guard<std::mutex> lock(mutex_);
      errors_.push_back(name_ + ": " + e.what());
    }
    {
      std::unique_lock<std::mutex> lock(mutex_);
      if (cpu_share_ < 1 && !unlimited_) {
        const double rest_ms = (threadCpuMs() - start) * (1 / cpu_share_ - 1);
        wake_.wait_for(lock, std::chrono::duration<double, std::milli>(rest_ms), [this] { return unlimited_; });
      }
      busy_ = false;
    }
    idle_.notify_all();
  }
}

}  // namespace dlslot::mapper
