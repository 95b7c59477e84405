// Writes the message seeds of the fuzz corpus (tests/fuzz/corpus) from a recorded simulator run:
// the first two events of each channel that pass the guard, scans cut to 16 points, and a small
// LCM log of one such event per channel for the log reader. See make_corpus.sh.
//   make_seeds RUN.lcmlog CORPUS_DIR
#include <lcm/lcm-cpp.hpp>

#include <filesystem>
#include <fstream>
#include <iostream>
#include <map>
#include <vector>

#include "dlslot/config.hpp"
#include "dlslot/lcm_log.hpp"
#include "dlslot/message_guard.hpp"
#include "dlslot/node.hpp"

using namespace dlslot;
namespace fs = std::filesystem;
using Bytes = std::vector<uint8_t>;

namespace {

template <class Msg>
bool accepted(const lcm::LogEvent& ev, Bytes* out) {
  Msg m;
  if (decodeChecked(ev.data, static_cast<size_t>(ev.datalen), &m)) return false;
  if constexpr (std::is_same_v<Msg, point_cloud_t>) {  // a scan of 16 points is seed enough
    const size_t n = std::min<size_t>(16, m.x.size());
    for (auto* v : {&m.x, &m.y, &m.z, &m.intensity}) v->resize(n);
    m.num_points = static_cast<int32_t>(n);
  }
  out->resize(m.getEncodedSize());
  m.encode(out->data(), 0, static_cast<int>(out->size()));
  return true;
}

}  // namespace

int main(int argc, char** argv) {
  if (argc != 3) {
    std::cerr << "usage: make_seeds RUN.lcmlog CORPUS_DIR\n";
    return 2;
  }
  lcm::LogFile in(argv[1], "r");
  if (!in.good()) return 1;
  const fs::path dir = argv[2];
  const Channels ch;
  const std::map<std::string, std::string> target = {
      {ch.scan, "point_cloud_t"},   {ch.detections, "detections_t"},     {ch.ground_truth, "ground_truth_t"},
      {ch.odometry, "odometry_t"},  {ch.associations, "associations_t"}, {ch.slot_state, "slot_state_t"},
      {ch.status, "process_status_t"}, {ch.run_event, "run_event_t"}, {ch.map_state, "map_state_t"}};
  std::map<std::string, int> written;
  lcm::LogFile log((dir / "fuzz_file_run_log" / "run.lcmlog").string(), "w");
  int64_t n = 0;
  LogEnvelopes envelopes(argv[1]);  // a run's log holds authenticated envelopes: their messages are the seeds
  ProcessStatus refused("make_seeds");
  while (const lcm::LogEvent* raw = in.readNextEvent()) {
    const lcm::LogEvent* ev = envelopes.open(*raw, refused, "");
    if (!ev) continue;
    const auto t = target.find(ev->channel);
    if (t == target.end() || written[t->second] >= 2) continue;
    Bytes b;
    const std::string& type = t->second;
    const bool ok = type == "point_cloud_t"      ? accepted<point_cloud_t>(*ev, &b)
                    : type == "detections_t"     ? accepted<detections_t>(*ev, &b)
                    : type == "ground_truth_t"   ? accepted<ground_truth_t>(*ev, &b)
                    : type == "odometry_t"       ? accepted<odometry_t>(*ev, &b)
                    : type == "associations_t"   ? accepted<associations_t>(*ev, &b)
                    : type == "slot_state_t"     ? accepted<slot_state_t>(*ev, &b)
                    : type == "run_event_t"      ? accepted<run_event_t>(*ev, &b)
                    : type == "map_state_t"      ? accepted<map_state_t>(*ev, &b)
                                                 : accepted<process_status_t>(*ev, &b);
    if (!ok) continue;
    const fs::path out = dir / ("fuzz_msg_" + type) / ("sim-" + std::to_string(written[type]++));
    std::ofstream(out, std::ios::binary).write(reinterpret_cast<const char*>(b.data()), b.size());
    if (written[type] == 1) {
      lcm::LogEvent e = *ev;
      e.eventnum = n++;
      e.data = b.data();
      e.datalen = static_cast<int32_t>(b.size());
      log.writeEvent(&e);
    }
  }
  for (const auto& [type, count] : written) std::cout << type << ": " << count << " seeds\n";
  return 0;
}
