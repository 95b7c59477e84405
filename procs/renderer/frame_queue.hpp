// Draws and writes frames on a writer thread, so the renderer's receive path (LCM handlers)
// never waits for drawing or PNG encoding (together ~40 ms a 1000x1000 frame, longer than a
// pipeline frame at 25 frames/s). Frames are written in arrival order.
//
// When the writer falls behind, a frame that arrives while `max_queued` frames wait is skipped
// and counted, if skipping is allowed (rate mode: the images keep up with the data, some
// frames have none). Otherwise every frame is queued and written (lockstep: the pipeline never
// waits for the renderer, and every frame gets its image, later; past kMaxBacklog frames the
// receiving thread waits). The writer thread runs at the lowest CPU priority.
#pragma once

#include <condition_variable>
#include <deque>
#include <mutex>
#include <string>
#include <thread>
#include <vector>

#include "frame_writer.hpp"

namespace dlslot::renderer {

class FrameQueue {
 public:
  struct Written {
    int frame;
    double ms;        // drawing + encoding + writing
    bool has_tracks;  // the frame had its SLOT_STATE
  };

  FrameQueue(FrameWriter& writer, int max_queued, bool skip_when_behind);
  ~FrameQueue();  // finishes the queue
  FrameQueue(const FrameQueue&) = delete;
  FrameQueue& operator=(const FrameQueue&) = delete;

  // Queues a frame; false when it was skipped (the writer is behind and skipping is allowed).
  bool submit(RenderInput in);
  // The frames written since the last call. Throws std::runtime_error when writing failed.
  std::vector<Written> takeWritten();
  // Writes everything queued, then stops the thread (no submit after this).
  void finish();
  int skipped() const;

 private:
  void run();
  static constexpr size_t kMaxBacklog = 256;

  FrameWriter& writer_;
  const size_t max_queued_;
  const bool skip_when_behind_;
  mutable std::mutex mutex_;
  std::condition_variable wake_, idle_;
  std::deque<RenderInput> queue_;
  std::vector<Written> written_;
  std::string error_;
  int skipped_ = 0;
  bool busy_ = false, stop_ = false;
  std::thread thread_;
};

}  // namespace dlslot::renderer
