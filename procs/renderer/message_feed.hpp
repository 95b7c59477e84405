// Decoded messages -> RunState: the one place the renderer converts LCM types, used by the live
// subscriptions and by the offline log reader alike. Malformed content (non-finite poses, bad
// boxes) is counted in the process status and skipped, never drawn and never fatal.
#pragma once

#include <map>
#include <string>

#include "dlslot/associations_t.hpp"
#include "dlslot/config.hpp"
#include "dlslot/detections_t.hpp"
#include "dlslot/ground_truth_t.hpp"
#include "dlslot/message_guard.hpp"
#include "dlslot/node.hpp"
#include "dlslot/odometry_t.hpp"
#include "dlslot/point_cloud_t.hpp"
#include "dlslot/slot_state_t.hpp"
#include "run_state.hpp"

namespace dlslot::renderer {

class MessageFeed {
 public:
  MessageFeed(RunState& state, ProcessStatus& status, Channels channels);

  void onScan(const point_cloud_t& m);
  void onDetections(const detections_t& m);
  void onGroundTruth(const ground_truth_t& m);
  void onOdometry(const odometry_t& m);
  void onAssociations(const associations_t& m);
  void onSlotState(const slot_state_t& m);

  // Offline: decodes a logged event by its channel through the guard (message_guard.hpp, with the
  // same frame-order check as a live node) and feeds it; other channels are ignored.
  void handle(const std::string& channel, const void* data, int size);

 private:
  template <class Msg>
  void decodeAndFeed(const std::string& channel, const void* data, int size, void (MessageFeed::*feed)(const Msg&));
  bool validFrame(const std::string& channel, int frame);
  std::vector<Box> boxes(const std::string& channel, const std::vector<box_t>& in);
  void late(bool accepted, const std::string& channel);

  RunState& state_;
  ProcessStatus& status_;
  Channels channels_;
  std::map<std::string, FrameOrder> order_;  // offline only: live, the Node checks the order
};

}  // namespace dlslot::renderer
