// dlslot-foxglove: the live pipeline in Foxglove. Subscribes to DL-SLOT's channels through the
// common node layer (the same decoding, checks and counters as every process) and serves them
// as Foxglove topics (foxglove_convert.hpp) over the Foxglove WebSocket protocol: the scan as
// ROS 1 sensor_msgs/PointCloud2 (binary, ros1_point_cloud.hpp), everything else as JSON. A
// message is built only when a client subscribes to one of its topics, once for all clients;
// each client has its own drop-oldest queue (client_queue.hpp), so a slow viewer loses old
// frames, never slows the pipeline. PROCESS_STATUS counts clients, messages sent and dropped.
#include <chrono>
#include <iostream>

#include "dlslot/cpu_clock.hpp"
#include "dlslot/heap_memory.hpp"
#include "dlslot/node.hpp"
#include "foxglove_convert.hpp"
#include "ws_server.hpp"

using namespace dlslot;

namespace {

uint64_t nowNs() {
  return static_cast<uint64_t>(
      std::chrono::duration_cast<std::chrono::nanoseconds>(std::chrono::system_clock::now().time_since_epoch()).count());
}

int run(int argc, char** argv) {
  NodeOptions node_opts;
  foxglove::ServerOptions server_opts;
  double queue_mb = static_cast<double>(server_opts.client_queue_bytes) / (1 << 20);
  CommandLine cl("dlslot-foxglove",
                 "Serves the live pipeline to Foxglove (WebSocket, foxglove.websocket.v1): points, boxes, tracks, poses.");
  cl.option("--port", &server_opts.port, "TCP port (default 8765, Foxglove's default)");
  cl.option("--host", &server_opts.host, "address to listen on (default 127.0.0.1: this machine only)");
  cl.option("--queue-mb", &queue_mb, "per-client queue in MB; the oldest messages go when it is full (default 32)");
  node_opts.addTo(cl);
  if (!cl.parse(argc, argv)) return 0;
  Channels channels;
  loadPipelineConfig(node_opts.config, channels);
  if (node_opts.check_config) return 0;
  if (server_opts.port < 0 || server_opts.port > 65535) throw std::invalid_argument("--port: expected 0..65535");
  if (!(queue_mb > 0)) throw std::invalid_argument("--queue-mb: expected a positive size");
  server_opts.client_queue_bytes = static_cast<size_t>(queue_mb * (1 << 20));

  retainFreedMemory();  // a scan converted 10-30 times a second (heap_memory.hpp)

  foxglove::ConverterOptions conv_opts;
  conv_opts.scan_encoding = foxglove::ScanEncoding::kRos1;
  foxglove::Converter conv(channels, conv_opts);
  std::vector<foxglove::AdvertisedChannel> advertised;
  for (size_t i = 0; i < conv.topics().size(); ++i) {
    const auto& t = conv.topics()[i];
    advertised.push_back({static_cast<uint32_t>(i + 1), t.name, t.schema->name, t.schema->text,
                          t.schema->message_encoding, t.schema->schema_encoding});
  }
  Node node("foxglove", node_opts.lcm_url, channels);
  foxglove::Server server(server_opts, advertised);
  std::cerr << "dlslot-foxglove: serving " << advertised.size() << " topics on ws://" << server_opts.host << ":"
            << server.port() << " (Foxglove: Open connection -> Foxglove WebSocket)\n";
  conv.setWanted([&](size_t topic) { return server.subscribed(static_cast<uint32_t>(topic + 1)); });

  std::vector<foxglove::Output> out;
  auto publishOut = [&] {
    const uint64_t t = nowNs();
    for (auto& o : out)
      server.publish(static_cast<uint32_t>(o.topic + 1), t, std::make_shared<std::string>(std::move(o.bytes)));
  };
  auto forward = [&](const auto& msg) {
    out.clear();
    conv.add(msg, out);
    publishOut();
  };
  // A frame is handled when its scan is (built and queued, or skipped when nobody watches). The
  // scan's bytes go to the converter as they came (after the node's envelope check): it checks
  // them as the message guard does and writes the PointCloud2 from them in one pass.
  node.subscribeRaw(channels.scan, [&](const lcm::ReceiveBuffer& rb) {
    const double t0 = threadCpuMs();
    out.clear();
    int frame = -1;
    Refusal why;
    try {
      why = conv.addScan(rb.data, rb.data_size, out, &frame);
    } catch (const std::exception& e) {  // counted like a typed subscription's handler exception
      why = {"handler_exception", e.what()};
    }
    if (why) {
      node.status().refused(channels.scan, why);
      return;
    }
    publishOut();
    node.status().frameDone(frame, threadCpuMs() - t0);
  });
  node.subscribe<detections_t>(channels.detections, [&](const detections_t& m) { forward(m); });
  node.subscribe<ground_truth_t>(channels.ground_truth, [&](const ground_truth_t& m) { forward(m); });
  node.subscribe<odometry_t>(channels.odometry, [&](const odometry_t& m) { forward(m); });
  node.subscribe<associations_t>(channels.associations, [&](const associations_t& m) { forward(m); });
  node.subscribe<slot_state_t>(channels.slot_state, [&](const slot_state_t& m) { forward(m); });
  node.subscribe<map_state_t>(channels.map_state, [&](const map_state_t& m) { forward(m); });
  node.subscribe<process_status_t>(channels.status, [&](const process_status_t& m) {
    if (m.name != "foxglove") forward(m);
  });
  installSignalHandlers();
  node.every(1.0, [&] {
    const auto s = server.stats();
    node.status().set("ws_clients", s.clients);
    node.status().set("ws_connections", s.connections);
    node.status().set("ws_sent", s.sent);
    node.status().set("ws_dropped_oldest", s.dropped);
    node.status().set("ws_bad_requests", s.bad_requests);
    node.publishStatus();
  });
  return node.run();
}

}  // namespace

int main(int argc, char** argv) { return runMain("dlslot-foxglove", [&] { return run(argc, argv); }); }
