// Guarded decoding of every DL-SLOT message, the one place live nodes (Node::subscribe) and
// offline log readers (dlslot-eval, the backend's and the renderer's --log modes) decode through.
//
// lcm-gen's C++ decoders size vectors and strings from the message's own counts before checking
// them against the bytes received, so one message with a count of INT32_MAX or a string length
// of 0 or -1 throws (bad_alloc, length_error) or exhausts memory. decodeChecked() therefore
//   1. walks the encoded bytes first (layout): fingerprint, every count >= 0 and its elements
//      within the bytes left, every string length >= 1 and within them, nothing left over;
//   2. decodes with lcm-gen's decoder, catching anything it throws;
//   3. validates the content: finite values, unit quaternions, sizes > 0, enums in range, frame
//      numbers in [0, kMaxFrame] (so `frame + 1` and gap counts never overflow).
// Boxes are checked like every other field: a DETECTIONS or ASSOCIATIONS message with a box that
// is not finite or has a size <= 0 is refused whole, before any of it reaches a node's state (no
// process of the pipeline publishes such a box, so such a message is not the pipeline's: one with
// a NaN box and frame 500 must not become a node's newest frame). FrameOrder adds the per-channel
// check that a frame is new and near the last one.
#pragma once

#include <cstddef>
#include <cstdint>
#include <string>

#include "dlslot/associations_t.hpp"
#include "dlslot/detections_t.hpp"
#include "dlslot/ground_truth_t.hpp"
#include "dlslot/map_state_t.hpp"
#include "dlslot/odometry_t.hpp"
#include "dlslot/point_cloud_t.hpp"
#include "dlslot/process_status_t.hpp"
#include "dlslot/run_event_t.hpp"
#include "dlslot/slot_state_t.hpp"

namespace dlslot {

// KITTI names scans by six digits (000000.bin): no sequence has a frame beyond this.
constexpr int kMaxFrame = 999999;
// A frame more than this ahead of the last one on its channel is refused (100 s at 10 Hz).
constexpr int kMaxFrameJump = 1000;

// Why a message was refused: `reason` is a short key for counters ("bad_count", "non_finite",
// ...), `detail` says which field and what was expected. Empty reason: accepted.
struct Refusal {
  std::string reason, detail;
  explicit operator bool() const { return !reason.empty(); }
};

// Step 1 for each type: the encoded bytes are a well-formed message of this type.
Refusal checkLayout(const point_cloud_t*, const void* data, size_t size);
Refusal checkLayout(const detections_t*, const void* data, size_t size);
Refusal checkLayout(const ground_truth_t*, const void* data, size_t size);
Refusal checkLayout(const odometry_t*, const void* data, size_t size);
Refusal checkLayout(const associations_t*, const void* data, size_t size);
Refusal checkLayout(const slot_state_t*, const void* data, size_t size);
Refusal checkLayout(const process_status_t*, const void* data, size_t size);
Refusal checkLayout(const run_event_t*, const void* data, size_t size);
Refusal checkLayout(const map_state_t*, const void* data, size_t size);

// Step 3 for each type: the decoded values make sense.
Refusal checkContent(const point_cloud_t& m);
Refusal checkContent(const detections_t& m);
Refusal checkContent(const ground_truth_t& m);
Refusal checkContent(const odometry_t& m);
Refusal checkContent(const associations_t& m);
Refusal checkContent(const slot_state_t& m);
Refusal checkContent(const process_status_t& m);
Refusal checkContent(const run_event_t& m);
Refusal checkContent(const map_state_t& m);

// All three steps; `out` is only meaningful when the result is empty.
template <class Msg>
Refusal decodeChecked(const void* data, size_t size, Msg* out) {
  if (Refusal r = checkLayout(static_cast<const Msg*>(nullptr), data, size)) return r;
  try {
    if (out->decode(data, 0, static_cast<int>(size)) < 0) return {"decode", "lcm-gen's decoder refused it"};
  } catch (const std::exception& e) {
    return {"decode_exception", e.what()};
  } catch (...) {
    return {"decode_exception", "unknown exception"};
  }
  return checkContent(*out);
}

// The frames accepted on one channel: each new (no duplicate, none older than the last) and at
// most kMaxFrameJump ahead. No number of refused frames makes a channel follow a new numbering
// (anyone who can publish could then steer it); a new numbering begins only with the player's
// explicit start event (Node::onRestart), which calls reset().
class FrameOrder {
 public:
  Refusal accept(int frame);
  int last() const { return last_; }  // -1 before the first
  void reset() { last_ = -1; }

 private:
  int last_ = -1;
};

}  // namespace dlslot
