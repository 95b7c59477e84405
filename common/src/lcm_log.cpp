#include "dlslot/lcm_log.hpp"

#include <sys/stat.h>

#include <algorithm>
#include <cstdint>
#include <cstdio>

#include <cstdlib>
#include <filesystem>

#include "dlslot/input_error.hpp"
#include "dlslot/node.hpp"

namespace dlslot {
namespace {

// An event: sync word, event number, timestamp, channel length, data length (big-endian), then
// the channel name and the data.
constexpr int64_t kHeaderBytes = 4 + 8 + 8 + 4 + 4;
constexpr uint32_t kSync = 0xEDA1DA01u;
constexpr int32_t kMaxChannelLength = 1000;  // LCM's own limit

uint32_t bigEndian32(const unsigned char* p) {
  return (uint32_t{p[0]} << 24) | (uint32_t{p[1]} << 16) | (uint32_t{p[2]} << 8) | uint32_t{p[3]};
}

}  // namespace

const lcm::LogEvent* nextLogEvent(lcm::LogFile& log, const std::string& path) {
  std::FILE* f = log.getFilePtr();
  struct stat st {};
  const long at = f ? std::ftell(f) : -1;
  if (at < 0 || fstat(fileno(f), &st) != 0) throw InputError(path, 0, "cannot read the log");
  if (!S_ISREG(st.st_mode)) throw InputError(path, 0, "is not a file (expected an LCM log)");
  const int64_t left = static_cast<int64_t>(st.st_size) - at;
  if (left <= 0) return nullptr;
  const std::string where = " at offset " + std::to_string(at);
  unsigned char h[kHeaderBytes];
  if (left < kHeaderBytes || std::fread(h, 1, kHeaderBytes, f) != static_cast<size_t>(kHeaderBytes))
    throw InputError(path, 0, "truncated or corrupt log: " + std::to_string(left) + " bytes" + where +
                                  " do not hold an event header (" + std::to_string(kHeaderBytes) + " bytes)");
  if (std::fseek(f, at, SEEK_SET) != 0) throw InputError(path, 0, "cannot read the log");
  if (bigEndian32(h) != kSync) throw InputError(path, 0, "corrupt log: no event starts" + where);
  const int32_t channel = static_cast<int32_t>(bigEndian32(h + 20)), data = static_cast<int32_t>(bigEndian32(h + 24));
  if (channel <= 0 || channel >= kMaxChannelLength || data < 0 ||
      int64_t{channel} + data > left - kHeaderBytes)
    throw InputError(path, 0, "truncated or corrupt log: the event" + where + " claims a " + std::to_string(channel) +
                                  "-byte channel and " + std::to_string(data) + " data bytes, " +
                                  std::to_string(left - kHeaderBytes) + " bytes remain");
  // The header fits the file, so LCM reads the whole event; it then also checks that a sync word
  // follows ("Invalid header after log data") and gives nothing when garbage does.
  const lcm::LogEvent* event = log.readNextEvent();
  if (!event) throw InputError(path, 0, "corrupt log: no event follows the one" + where);
  return event;
}

LogEnvelopes::LogEnvelopes(const std::string& log_path) {
  if (const char* env = std::getenv(kKeyFileEnv); env && *env) {
    key_path_ = env;
  } else {
    const std::filesystem::path beside = std::filesystem::path(log_path).parent_path() / kRunKeyFile;
    if (std::filesystem::exists(beside)) key_path_ = beside.string();
  }
  if (!key_path_.empty()) auth_ = MessageAuth(readKeyFile(key_path_));
}

const lcm::LogEvent* LogEnvelopes::open(const lcm::LogEvent& ev, ProcessStatus& status, const std::string& where) {
  // LCM's own self-test message, which every LCM instance (the logger's too) sends to itself when
  // it starts: not the pipeline's, read by nobody, so neither verified nor counted.
  if (ev.channel == "LCM_SELF_TEST") return &ev;
  const uint8_t* payload = nullptr;
  size_t size = 0;
  if (const Refusal why = auth_.open(ev.channel, ev.data, static_cast<size_t>(std::max(ev.datalen, 0)), &payload, &size)) {
    status.refused(ev.channel, why, where);
    return nullptr;
  }
  event_.eventnum = ev.eventnum;
  event_.timestamp = ev.timestamp;
  event_.channel = ev.channel;
  event_.datalen = static_cast<int32_t>(size);
  event_.data = const_cast<uint8_t*>(payload);
  return &event_;
}

}  // namespace dlslot
