// A recorded run (LCM log) as an MCAP file of Foxglove messages: every event through the
// Converter, every topic a channel of the MCAP file.
//
// Time: a message's log_time is when the first message of its scan (same utime) was recorded,
// so all of a scan's messages (points, boxes, tracks, poses) sit at one instant when Foxglove
// scrubs through the run; messages of no scan (status, unknown channels) keep their own recording
// time. publish_time is each event's own recording time.
#pragma once

#include <cstdint>
#include <functional>
#include <map>
#include <string>

#include "dlslot/config.hpp"

namespace dlslot::foxglove {

struct ExportStats {
  int64_t events = 0;                        // events read from the log
  int64_t scans = 0;                         // of them on the scan channel
  std::map<std::string, int64_t> messages;   // written, per topic
  std::map<std::string, int64_t> refused;    // "CHANNEL: reason" -> events that did not decode (not written)
  int64_t bytes = 0;                         // size of the MCAP file
  double wall_s = 0, cpu_s = 0;
};

// Throws InputError naming the log when it cannot be read or is corrupt, std::runtime_error
// when the output cannot be written. `progress(bytes_read, bytes_total)` is called now and then.
ExportStats exportMcap(const std::string& log_path, const std::string& mcap_path, const Channels& channels,
                       const std::function<void(int64_t, int64_t)>& progress = {});

}  // namespace dlslot::foxglove
