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

namespace dlslot {

// The next event of `log`, or nullptr at the end of the file: a log read to its end holds
// nothing but whole events. Throws InputError(path, ...) for a path that is not a regular file
// and when the bytes at the read position are not an event LCM can read: no sync word there
// (garbage between events), a header cut off, a channel length outside 1..999, a negative data
// length, or lengths that run past the end of the file.
const lcm::LogEvent* nextLogEvent(lcm::LogFile& log, const std::string& path);

}  // namespace dlslot
