// Reading LCM logs (lcm::LogFile) without trusting their event headers. Debian's LCM 1.3.1
// allocates an event's channel and data from the lengths its header claims, before reading them:
// a 6 KB log whose header claims 0x7fffffff data bytes killed dlslot-eval --log (SIGSEGV: the
// size + 1 overflows, calloc fails, fread writes through NULL), and smaller lies made it allocate
// hundreds of MB (fuzz_file_run_log's slow units). nextLogEvent() checks each header against the
// bytes the file still holds first; every offline reader of logs goes through it (dlslot-eval
// --log, dlslot-backend --offline, dlslot-renderer --log).
#pragma once

#include <lcm/lcm-cpp.hpp>

#include <string>
#include <vector>

#include "dlslot/message_auth.hpp"

namespace dlslot {

class ProcessStatus;

// The next event of `log`, or nullptr at the end of the file: a log read to its end holds
// nothing but whole events. Throws InputError(path, ...) for a path that is not a regular file
// and when the bytes at the read position are not an event LCM can read: no sync word there
// (garbage between events), a header cut off, a channel length outside 1..999, a negative data
// length, or lengths that run past the end of the file.
const lcm::LogEvent* nextLogEvent(lcm::LogFile& log, const std::string& path);

// The authentication envelopes of one run's log (message_auth.hpp). The logger records what
// reached the bus, an attacker's messages included, so an offline reader verifies each event as
// a live node would: with the run's key ($DLSLOT_KEY_FILE, else run.key beside the log) when
// there is one; without a key envelopes are opened unverified and plain events taken as they are.
class LogEnvelopes {
 public:
  explicit LogEnvelopes(const std::string& log_path);
  // `ev` with its envelope opened (valid until the next call), or nullptr when it does not verify:
  // then it is counted in `status` (refused.CHANNEL.REASON) and logged once per reason after `where`.
  const lcm::LogEvent* open(const lcm::LogEvent& ev, ProcessStatus& status, const std::string& where);
  const MessageAuth& auth() const { return auth_; }
  const std::string& keyPath() const { return key_path_; }  // empty: no key, nothing verified

 private:
  MessageAuth auth_;
  std::string key_path_;
  lcm::LogEvent event_;
};

}  // namespace dlslot
