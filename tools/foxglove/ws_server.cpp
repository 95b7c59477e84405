#include "ws_server.hpp"

#define ASIO_STANDALONE
#include <websocketpp/config/asio_no_tls.hpp>
#include <websocketpp/server.hpp>
#include <yaml-cpp/yaml.h>

#include <sys/resource.h>
#include <sys/syscall.h>
#include <unistd.h>

#include <chrono>
#include <map>
#include <mutex>
#include <set>
#include <stdexcept>
#include <thread>

#include "client_queue.hpp"
#include "json_text.hpp"

namespace dlslot::foxglove {

namespace {
using WsServer = websocketpp::server<websocketpp::config::asio>;
using Handle = websocketpp::connection_hdl;
constexpr const char* kSubprotocol = "foxglove.websocket.v1";
// A client's socket may hold this much unsent before its queue stops feeding it: enough to keep
// a loopback link busy, small enough that the drop-oldest queue (not the socket) absorbs a slow
// client, so what it finally gets is recent.
constexpr size_t kSocketBacklog = 8u << 20;
}  // namespace

struct Server::Impl {
  struct Client {
    explicit Client(size_t budget) : queue(budget) {}
    ClientQueue queue;
    std::map<uint32_t, uint32_t> subscription_of_channel;  // channel id -> subscription id
    std::map<uint32_t, uint32_t> channel_of_subscription;
  };

  ServerOptions opt;
  std::vector<AdvertisedChannel> channels;
  std::set<uint32_t> channel_ids;
  WsServer ws;
  std::thread thread;
  mutable std::mutex mu;  // guards clients, counts, stats
  std::map<Handle, Client, std::owner_less<Handle>> clients;
  std::map<uint32_t, int> subscribers;  // channel -> subscribing clients
  ServerStats st;
  int64_t dropped_by_gone = 0;  // drops counted in queues of clients since closed
  std::atomic<bool> wake_pending{false};
  std::unique_ptr<asio::steady_timer> timer;
  int bound_port = 0;

  void status(Handle h, int level, const std::string& message) {
    JsonText j;
    j.beginObject().field("op", "status").field("level", level).field("message", message).endObject();
    websocketpp::lib::error_code ec;
    ws.send(h, j.str(), websocketpp::frame::opcode::text, ec);
  }

  void onOpen(Handle h) {
    JsonText info;
    info.beginObject().field("op", "serverInfo").field("name", opt.name).key("capabilities").beginArray().endArray();
    info.key("supportedEncodings").beginArray().endArray().key("metadata").beginObject().endObject();
    info.field("sessionId", std::to_string(std::chrono::system_clock::now().time_since_epoch().count())).endObject();
    JsonText adv;
    adv.beginObject().field("op", "advertise").key("channels").beginArray();
    for (const auto& c : channels)
      adv.beginObject().field("id", int64_t{c.id}).field("topic", c.topic).field("encoding", c.encoding)
          .field("schemaName", c.schema_name).field("schema", c.schema).field("schemaEncoding", c.schema_encoding)
          .endObject();
    adv.endArray().endObject();
    {
      std::lock_guard<std::mutex> lock(mu);
      clients.emplace(h, Client(opt.client_queue_bytes));
      ++st.connections;
    }
    websocketpp::lib::error_code ec;
    ws.send(h, info.str(), websocketpp::frame::opcode::text, ec);
    if (!ec) ws.send(h, adv.str(), websocketpp::frame::opcode::text, ec);
  }

  void onClose(Handle h) {
    std::lock_guard<std::mutex> lock(mu);
    const auto it = clients.find(h);
    if (it == clients.end()) return;
    for (const auto& [channel, sub] : it->second.subscription_of_channel) --subscribers[channel];
    dropped_by_gone += it->second.queue.dropped();
    clients.erase(it);
  }

  // subscribe / unsubscribe; anything else gets an error status (and is counted).
  void onMessage(Handle h, WsServer::message_ptr msg) {
    std::string problem;
    try {
      if (msg->get_opcode() != websocketpp::frame::opcode::text) throw std::runtime_error("binary client messages are not supported");
      const YAML::Node j = YAML::Load(msg->get_payload());
      const std::string op = j["op"] ? j["op"].as<std::string>() : "";
      std::lock_guard<std::mutex> lock(mu);
      auto it = clients.find(h);
      if (it == clients.end()) return;
      Client& c = it->second;
      if (op == "subscribe") {
        for (const auto& s : j["subscriptions"]) {
          const uint32_t id = s["id"].as<uint32_t>(), channel = s["channelId"].as<uint32_t>();
          if (!channel_ids.count(channel)) problem += "unknown channel " + std::to_string(channel) + "; ";
          else if (c.channel_of_subscription.count(id)) problem += "subscription id " + std::to_string(id) + " in use; ";
          else if (c.subscription_of_channel.count(channel)) problem += "channel " + std::to_string(channel) + " already subscribed; ";
          else {
            c.subscription_of_channel[channel] = id;
            c.channel_of_subscription[id] = channel;
            ++subscribers[channel];
          }
        }
      } else if (op == "unsubscribe") {
        for (const auto& s : j["subscriptionIds"]) {
          const uint32_t id = s.as<uint32_t>();
          const auto sub = c.channel_of_subscription.find(id);
          if (sub == c.channel_of_subscription.end()) {
            problem += "no subscription " + std::to_string(id) + "; ";
            continue;
          }
          --subscribers[sub->second];
          c.subscription_of_channel.erase(sub->second);
          c.channel_of_subscription.erase(sub);
        }
      } else {
        problem = "unsupported op '" + op + "'";
      }
    } catch (const std::exception& e) {
      problem = std::string("not a protocol message: ") + e.what();
    }
    if (!problem.empty()) {
      {
        std::lock_guard<std::mutex> lock(mu);
        ++st.bad_requests;
      }
      status(h, 1, problem);
    }
  }

  // Server thread: feeds each client from its queue while its socket backlog is small.
  void pump() {
    wake_pending = false;
    std::vector<std::pair<Handle, QueuedMessage>> ready;
    {
      std::lock_guard<std::mutex> lock(mu);
      for (auto& [h, c] : clients) {
        auto con = ws.get_con_from_hdl(h);
        size_t backlog = con->get_buffered_amount();
        while (!c.queue.empty() && backlog < kSocketBacklog) {
          QueuedMessage m = c.queue.pop();
          backlog += m.payload->size() + 13;
          ready.emplace_back(h, std::move(m));
        }
      }
    }
    for (auto& [h, m] : ready) {
      websocketpp::lib::error_code ec;
      const auto con = ws.get_con_from_hdl(h, ec);
      if (ec || !con) continue;
      // A frame prepared here goes to the socket as it is (websocketpp copies the payload of any
      // other message once more): header (WebSocket frame header, then Message Data's op,
      // subscription id and receive time) and payload are two buffers of one write.
      const auto msg = con->get_message(websocketpp::frame::opcode::binary, 0);
      std::string& body = msg->get_raw_payload();
      if (m.payload.use_count() == 1) body.swap(*m.payload);  // the last holder: take the bytes
      else body = *m.payload;
      const size_t size = 13 + body.size();
      std::string header = websocketpp::frame::prepare_header(
          websocketpp::frame::basic_header(websocketpp::frame::opcode::binary, size, true, false, false),
          websocketpp::frame::extended_header(size));
      char op[13];
      op[0] = 0x01;  // Message Data
      for (int i = 0; i < 4; ++i) op[1 + i] = static_cast<char>((m.subscription >> (8 * i)) & 0xFF);
      for (int i = 0; i < 8; ++i) op[5 + i] = static_cast<char>((m.time_ns >> (8 * i)) & 0xFF);
      header.append(op, sizeof op);
      msg->set_header(header);
      msg->set_prepared(true);
      ec = con->send(msg);
      if (!ec) {
        std::lock_guard<std::mutex> lock(mu);
        ++st.sent;
      }
    }
  }

  void tick() {
    pump();
    timer->expires_after(std::chrono::milliseconds(20));  // sockets drain without telling: look again
    timer->async_wait([this](const asio::error_code& ec) {
      if (!ec) tick();
    });
  }
};

Server::Server(ServerOptions options, std::vector<AdvertisedChannel> channels) : impl_(std::make_unique<Impl>()) {
  Impl& s = *impl_;
  s.opt = std::move(options);
  s.channels = std::move(channels);
  for (const auto& c : s.channels) s.channel_ids.insert(c.id);
  s.ws.clear_access_channels(websocketpp::log::alevel::all);
  s.ws.clear_error_channels(websocketpp::log::elevel::all);
  s.ws.set_error_channels(websocketpp::log::elevel::rerror | websocketpp::log::elevel::fatal);
  s.ws.init_asio();
  s.ws.set_reuse_addr(true);
  s.ws.set_validate_handler([&s](Handle h) {
    auto con = s.ws.get_con_from_hdl(h);
    for (const auto& p : con->get_requested_subprotocols())
      if (p == kSubprotocol) {
        con->select_subprotocol(kSubprotocol);
        return true;
      }
    con->set_status(websocketpp::http::status_code::bad_request, std::string("expected subprotocol ") + kSubprotocol);
    return false;
  });
  s.ws.set_open_handler([&s](Handle h) { s.onOpen(h); });
  s.ws.set_close_handler([&s](Handle h) { s.onClose(h); });
  s.ws.set_fail_handler([&s](Handle h) { s.onClose(h); });
  s.ws.set_message_handler([&s](Handle h, WsServer::message_ptr m) { s.onMessage(h, m); });
  try {
    asio::ip::tcp::endpoint ep(asio::ip::make_address(s.opt.host), static_cast<unsigned short>(s.opt.port));
    s.ws.listen(ep);
    asio::error_code ec;
    s.bound_port = s.ws.get_local_endpoint(ec).port();
    s.ws.start_accept();
  } catch (const std::exception& e) {
    throw std::runtime_error("cannot listen on " + s.opt.host + ":" + std::to_string(s.opt.port) + ": " + e.what());
  }
  s.timer = std::make_unique<asio::steady_timer>(s.ws.get_io_service());
  asio::post(s.ws.get_io_service(), [&s] { s.tick(); });
  s.thread = std::thread([&s] {
    // The lowest CPU priority for the sending (nice is per thread on Linux): on a full machine the
    // pipeline's processes get the cores first and the clients are fed when they are idle, their
    // drop-oldest queues absorbing the wait. The LCM side (receiving, checking, building each
    // message once) keeps the process's priority, so the bridge never loses a message on its socket.
    setpriority(PRIO_PROCESS, static_cast<id_t>(syscall(SYS_gettid)), s.opt.send_nice);
    s.ws.run();
  });
}

Server::~Server() {
  Impl& s = *impl_;
  asio::post(s.ws.get_io_service(), [&s] {
    s.timer->cancel();
    websocketpp::lib::error_code ec;
    s.ws.stop_listening(ec);
    std::vector<Handle> open;
    {
      std::lock_guard<std::mutex> lock(s.mu);
      for (const auto& [h, c] : s.clients) open.push_back(h);
    }
    for (const auto& h : open) s.ws.close(h, websocketpp::close::status::going_away, "server stopping", ec);
  });
  // Closing handshakes get a moment; then the loop stops whatever is left.
  const auto end = std::chrono::steady_clock::now() + std::chrono::milliseconds(500);
  while (std::chrono::steady_clock::now() < end) {
    {
      std::lock_guard<std::mutex> lock(s.mu);
      if (s.clients.empty()) break;
    }
    std::this_thread::sleep_for(std::chrono::milliseconds(10));
  }
  s.ws.stop();
  if (s.thread.joinable()) s.thread.join();
}

bool Server::subscribed(uint32_t channel) const {
  std::lock_guard<std::mutex> lock(impl_->mu);
  const auto it = impl_->subscribers.find(channel);
  return it != impl_->subscribers.end() && it->second > 0;
}

void Server::publish(uint32_t channel, uint64_t time_ns, std::shared_ptr<std::string> payload) {
  Impl& s = *impl_;
  bool any = false;
  {
    std::lock_guard<std::mutex> lock(s.mu);
    // The last subscriber's queue gets the caller's reference itself: once queued, the queues
    // hold every reference, so the client that sends the message last can take its bytes over.
    std::pair<Impl::Client*, uint32_t> last{nullptr, 0};
    for (auto& [h, c] : s.clients) {
      const auto sub = c.subscription_of_channel.find(channel);
      if (sub == c.subscription_of_channel.end()) continue;
      if (last.first) last.first->queue.push({last.second, time_ns, payload});
      last = {&c, sub->second};
    }
    if (last.first) last.first->queue.push({last.second, time_ns, std::move(payload)});
    any = last.first != nullptr;
  }
  if (any && !s.wake_pending.exchange(true)) asio::post(s.ws.get_io_service(), [&s] { s.pump(); });
}

ServerStats Server::stats() const {
  std::lock_guard<std::mutex> lock(impl_->mu);
  ServerStats out = impl_->st;
  out.clients = static_cast<int64_t>(impl_->clients.size());
  out.dropped = impl_->dropped_by_gone;
  for (const auto& [h, c] : impl_->clients) out.dropped += c.queue.dropped();
  return out;
}

int Server::port() const { return impl_->bound_port; }

}  // namespace dlslot::foxglove
