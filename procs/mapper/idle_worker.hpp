// One thread that runs posted jobs in order, for the mapper's work that must never hold the
// pipeline up. The mapper shares two cores with the odometry and the back end, whose frames set
// the lockstep rate; its keyframes and loop closure only have to be done by the end of the run.
// So the thread runs at SCHED_IDLE (Linux): the scheduler gives it a core only when no normal
// thread wants one, and the mapper uses the cores' idle time instead of taking theirs. The queue
// is bounded: post() blocks while `capacity` jobs wait (the caller decides what to do before
// that, see backlog()), and drain() first lifts the thread back to normal priority so that the
// catch-up at the end of a run does not wait for idle time that a busy machine may not have.
// SCHED_IDLE alone does not make the work free: on this kind of machine a thread busy on the other
// core slows the pipeline's even at idle priority (an idle-priority spinner costs the lockstep rate
// 4-13 %, docs/performance.md). So the thread can also be held to a share of one core: after a job
// that took c ms of CPU it rests c x (1/cpu_share - 1) ms, until drain() lifts the limit.
// Inline mode (threaded = false) runs each job in post(): offline rebuilds are reproducible.
#pragma once

#include <condition_variable>
#include <cstddef>
#include <deque>
#include <functional>
#include <mutex>
#include <string>
#include <thread>
#include <vector>

namespace dlslot::mapper {

class IdleWorker {
 public:
  // name: for messages; capacity >= 1: jobs that may wait; idle_priority: SCHED_IDLE for the thread;
  // cpu_share in (0, 1]: the most of one core the thread uses until drain() (1: no limit).
  IdleWorker(std::string name, bool threaded, size_t capacity, bool idle_priority, double cpu_share = 1.0);
  ~IdleWorker();  // runs what is queued, then stops
  IdleWorker(const IdleWorker&) = delete;
  IdleWorker& operator=(const IdleWorker&) = delete;

  // Queues `job` (runs it now when inline); blocks while the queue is full.
  void post(std::function<void()> job);
  // Back to normal priority and no share limit (for the rest of the worker's life).
  void liftLimits();
  // liftLimits(), then waits until every job posted so far has run.
  void drain();
  // Waits until every job posted so far has run, at the priority the thread has.
  void wait();
  // The thread's priority from now on: SCHED_IDLE (true) or normal (false); the share limit stays.
  void setIdlePriority(bool idle) { if (threaded_) setPriority(idle); }
  // Jobs waiting (not counting the one running), and the most that ever waited.
  size_t backlog() const;
  size_t maxBacklog() const;
  size_t capacity() const { return capacity_; }
  // Empty when the thread runs at the priority asked for; else why not (e.g. not permitted).
  std::string priorityError() const;
  // CPU milliseconds the thread has used so far (0 inline).
  double cpuMs() const;
  // What jobs threw (a job's exception is caught on the thread, kept here, and the next job runs).
  std::vector<std::string> takeErrors();

 private:
  void work();
  void setPriority(bool idle);

  std::string name_;
  bool threaded_;
  size_t capacity_;
  double cpu_share_;
  mutable std::mutex mutex_;
  std::condition_variable wake_, space_, idle_;
  std::deque<std::function<void()>> queue_;
  size_t max_backlog_ = 0;
  bool busy_ = false, stop_ = false, unlimited_ = false;
  std::string priority_error_;
  std::vector<std::string> errors_;
  std::thread thread_;
};

}  // namespace dlslot::mapper
