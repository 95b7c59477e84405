#include "mcap_export.hpp"

#include <lcm/lcm-cpp.hpp>
#include <sys/stat.h>

#include <chrono>
#include <unordered_map>
#include <vector>

#include "dlslot/cpu_clock.hpp"
#include "dlslot/input_error.hpp"
#include "dlslot/lcm_log.hpp"
#include "dlslot/node.hpp"
#include "foxglove_convert.hpp"
#include "mcap_writer.hpp"

namespace dlslot::foxglove {

ExportStats exportMcap(const std::string& log_path, const std::string& mcap_path, const Channels& channels,
                       const std::function<void(int64_t, int64_t)>& progress) {
  ExportStats stats;
  const auto wall0 = std::chrono::steady_clock::now();
  const double cpu0 = threadCpuMs();
  struct stat st {};
  if (stat(log_path.c_str(), &st) != 0) throw InputError(log_path, 0, "cannot open (expected an LCM log)");
  lcm::LogFile log(log_path, "r");
  if (!log.good()) throw InputError(log_path, 0, "cannot open (expected an LCM log)");

  mcap::Writer writer(mcap_path);
  Converter conv(channels);
  std::vector<uint16_t> channel_of_topic;  // MCAP channel id per converter topic, 0 = not yet
  std::map<const SchemaText*, uint16_t> schema_ids;
  std::unordered_map<int64_t, uint64_t> scan_time;  // utime -> log_time (ns) of its first message
  std::vector<Output> out;
  int64_t since_progress = 0;
  // Each event's authentication envelope is checked as a live node would (lcm_log.hpp); what does
  // not verify is counted below with the other refusals.
  LogEnvelopes envelopes(log_path);
  ProcessStatus unverified("export");
  while (const lcm::LogEvent* raw = nextLogEvent(log, log_path)) {
    ++stats.events;
    const lcm::LogEvent* ev = envelopes.open(*raw, unverified, log_path + ": ");
    if (!ev) continue;
    const std::string channel = ev->channel;
    if (channel == channels.scan) ++stats.scans;
    out.clear();
    if (Refusal why = conv.convert(channel, ev->data, ev->datalen, out)) {
      ++stats.refused[channel + ": " + why.reason];
      continue;
    }
    const uint64_t event_ns = static_cast<uint64_t>(ev->timestamp < 0 ? 0 : ev->timestamp) * 1000;
    for (Output& o : out) {
      if (channel_of_topic.size() <= o.topic) channel_of_topic.resize(o.topic + 1, 0);
      uint16_t& id = channel_of_topic[o.topic];
      if (id == 0) {
        const Topic& t = conv.topics()[o.topic];
        uint16_t& schema = schema_ids[t.schema];
        if (schema == 0) schema = writer.addSchema(t.schema->name, t.schema->schema_encoding, t.schema->text);
        id = writer.addChannel(schema, t.name, t.schema->message_encoding, {{"lcm_channel", t.channel}});
      }
      uint64_t log_time = event_ns;
      if (o.utime >= 0) log_time = scan_time.emplace(o.utime, event_ns).first->second;
      writer.write(id, log_time, event_ns, o.bytes);
      ++stats.messages[conv.topics()[o.topic].name];
    }
    if (progress && ++since_progress >= 64) {
      since_progress = 0;
      progress(static_cast<int64_t>(std::ftell(log.getFilePtr())), static_cast<int64_t>(st.st_size));
    }
  }
  for (const auto& [key, n] : unverified.refusals()) {  // "CHANNEL.REASON"
    const size_t dot = key.rfind('.');
    stats.refused[key.substr(0, dot) + ": " + key.substr(dot + 1)] += n;
  }
  writer.close();
  stats.bytes = static_cast<int64_t>(writer.bytesWritten());
  stats.wall_s = std::chrono::duration<double>(std::chrono::steady_clock::now() - wall0).count();
  stats.cpu_s = (threadCpuMs() - cpu0) / 1e3;
  if (progress) progress(static_cast<int64_t>(st.st_size), static_cast<int64_t>(st.st_size));
  return stats;
}

}  // namespace dlslot::foxglove
