// A Foxglove WebSocket protocol server (subprotocol foxglove.websocket.v1) on websocketpp +
// standalone asio, on a thread of its own: serverInfo and advertise on connect, subscribe and
// unsubscribe from clients, binary Message Data (opcode 1, subscription id, receive time,
// payload) to each subscriber through its own drop-oldest queue (client_queue.hpp). publish()
// never blocks on a client: it queues and wakes the server thread. A message's bytes are made
// once for all clients and are not copied on the way to the socket when one client takes them
// (the WebSocket and Message Data headers go out as a separate buffer of the same write).
#pragma once

#include <atomic>
#include <cstdint>
#include <memory>
#include <string>
#include <vector>

namespace dlslot::foxglove {

struct ServerOptions {
  std::string host = "127.0.0.1";  // loopback: a bridge is reachable from elsewhere only when asked
  int port = 8765;                 // Foxglove's default port for its WebSocket connection
  size_t client_queue_bytes = 32u << 20;  // about ten JSON scans of an HDL-64E
  std::string name = "dlslot-foxglove";
  int send_nice = 19;  // the server thread's nice value (it only feeds clients): the pipeline goes first
};

struct AdvertisedChannel {
  uint32_t id;
  std::string topic, schema_name, schema;  // schema: JSON Schema text, or a ROS 1 message definition
  std::string encoding = "json";           // the messages' encoding: "json" or "ros1"
  std::string schema_encoding = "jsonschema";  // "jsonschema" or "ros1msg"
};

struct ServerStats {
  int64_t clients = 0;           // connected now
  int64_t connections = 0;       // ever accepted
  int64_t sent = 0;              // messages handed to the socket
  int64_t dropped = 0;           // dropped from a full client queue (oldest first)
  int64_t bad_requests = 0;      // client messages that were not valid protocol (answered with a status)
};

class Server {
 public:
  // Listens at once; throws std::runtime_error naming host:port when it cannot.
  Server(ServerOptions options, std::vector<AdvertisedChannel> channels);
  ~Server();  // stops the thread and closes every connection
  Server(const Server&) = delete;
  Server& operator=(const Server&) = delete;

  // True when any client subscribes to the channel (so its messages are worth building).
  bool subscribed(uint32_t channel) const;
  // Queues `payload` for every subscriber of `channel`; time_ns is the receive time. The server
  // owns the bytes from then on (the last client to send them may take them over): the caller
  // must not change them.
  void publish(uint32_t channel, uint64_t time_ns, std::shared_ptr<std::string> payload);
  ServerStats stats() const;
  int port() const;  // the bound port (useful with port 0)

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

}  // namespace dlslot::foxglove
