// The MCAP writer, Foxglove's JSON messages and the exporter. The writer's records are parsed
// back here byte by byte (CRCs, indexes, summary); the exported file is read by @mcap/core, a
// reader that is not ours (tests/js/mcap_check.cjs under node), and every channel's schema,
// message count and timestamps compared with the LCM log it came from.
#include <gtest/gtest.h>
#include <lcm/lcm-cpp.hpp>
#include <yaml-cpp/yaml.h>

#include <cmath>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <map>
#include <set>
#include <sstream>
#include <string>
#include <vector>

#include "foxglove_convert.hpp"
#include "json_text.hpp"
#include "mcap_export.hpp"
#include "mcap_writer.hpp"
#include "text_file.hpp"

using namespace dlslot;
using dlslot::test::readText;
namespace fs = std::filesystem;

namespace {

std::string scratch(const std::string& name) {
  const std::string dir = std::string(DLSLOT_BIN_DIR) + "/../test-scratch/foxglove_mcap";
  fs::create_directories(dir);
  return dir + "/" + name;
}

// A little-endian cursor over MCAP bytes (test-side reader, independent of the writer's Bytes).
struct Cursor {
  const std::string& s;
  size_t at;
  uint64_t le(int n) {
    if (at + n > s.size()) throw std::out_of_range("read past the end at " + std::to_string(at));
    uint64_t v = 0;
    for (int i = n - 1; i >= 0; --i) v = (v << 8) | static_cast<unsigned char>(s[at + i]);
    at += n;
    return v;
  }
  std::string str() {
    const uint64_t n = le(4);
    std::string v = s.substr(at, n);
    at += n;
    return v;
  }
};

struct Record {
  uint8_t op;
  size_t start, content, end;  // record start, content start, one past the end
};

std::vector<Record> records(const std::string& s, size_t from, size_t to) {
  std::vector<Record> out;
  Cursor c{s, from};
  while (c.at < to) {
    Record r;
    r.start = c.at;
    r.op = static_cast<uint8_t>(c.le(1));
    const uint64_t len = c.le(8);
    r.content = c.at;
    r.end = c.at + len;
    out.push_back(r);
    c.at = r.end;
  }
  EXPECT_EQ(c.at, to) << "records overrun their section";
  return out;
}

TEST(Base64, Rfc4648Vectors) {
  const std::pair<const char*, const char*> cases[] = {{"", ""},         {"f", "Zg=="},         {"fo", "Zm8="},
                                                       {"foo", "Zm9v"},  {"foob", "Zm9vYg=="},  {"fooba", "Zm9vYmE="},
                                                       {"foobar", "Zm9vYmFy"}};
  for (const auto& [in, want] : cases) {
    std::string out;
    foxglove::appendBase64(out, in, std::strlen(in));
    EXPECT_EQ(out, want) << in;
  }
}

TEST(JsonText, EscapesStringsAndWritesNumbersThatRoundTrip) {
  foxglove::JsonText j;
  j.beginObject().field("a\"b", std::string("x\\y\n\x01")).field("n", 0.1).field("i", int64_t{-3}).field("nan", NAN);
  j.key("l").beginArray().value(1.5).value(true).endArray().endObject();
  EXPECT_EQ(j.str(), R"({"a\"b":"x\\y\n\u0001","n":0.1,"i":-3,"nan":null,"l":[1.5,true]})");
  const YAML::Node parsed = YAML::Load(j.str());
  EXPECT_EQ(parsed["n"].as<double>(), 0.1);
}

TEST(McapWriter, RecordsIndexesCrcsAndSummaryFollowTheSpecification) {
  const std::string path = scratch("writer.mcap");
  {
    mcap::WriterOptions opt;
    opt.chunk_size = 200;  // a few messages a chunk: several chunks
    mcap::Writer w(path, opt);
    const uint16_t s = w.addSchema("test.Thing", "jsonschema", R"({"type":"object"})");
    const uint16_t a = w.addChannel(s, "/a", "json", {{"k", "v"}});
    const uint16_t b = w.addChannel(s, "/b", "json");
    const uint16_t unused = w.addChannel(s, "/unused", "json");
    EXPECT_EQ(unused, 3);
    for (int i = 0; i < 10; ++i) w.write(i % 3 == 2 ? b : a, 1000 + 10 * i, 5 + i, "{\"i\":" + std::to_string(i) + "}");
    EXPECT_EQ(w.messageCount(), 10u);
    w.close();
  }
  const std::string f = readText(path);
  ASSERT_GT(f.size(), 16u);
  EXPECT_EQ(f.substr(0, 8), std::string(mcap::kMagic, 8));
  EXPECT_EQ(f.substr(f.size() - 8), std::string(mcap::kMagic, 8));
  // Footer: the last record before the closing magic.
  const size_t footer_at = f.size() - 8 - (1 + 8 + 20);
  Cursor fc{f, footer_at};
  ASSERT_EQ(fc.le(1), mcap::kFooter);
  ASSERT_EQ(fc.le(8), 20u);
  const uint64_t summary_start = fc.le(8), summary_offset_start = fc.le(8);
  const uint32_t summary_crc = static_cast<uint32_t>(fc.le(4));
  EXPECT_EQ(summary_crc, mcap::crc32(0, f.data() + summary_start, footer_at + 1 + 8 + 16 - summary_start));
  // Data section: Header first, Data End last with the CRC of everything before it.
  const auto data = records(f, 8, summary_start);
  ASSERT_GE(data.size(), 3u);
  EXPECT_EQ(data.front().op, mcap::kHeader);
  ASSERT_EQ(data.back().op, mcap::kDataEnd);
  EXPECT_EQ((Cursor{f, data.back().content}.le(4)), mcap::crc32(0, f.data(), data.back().start));
  // Chunks: CRC of their records, and the message index after each pointing at its messages.
  std::vector<std::pair<uint64_t, uint64_t>> chunks;  // offset, length
  int messages = 0;
  std::map<uint64_t, size_t> chunk_records;           // file offset of a chunk's records
  for (size_t i = 0; i < data.size(); ++i) {
    if (data[i].op != mcap::kChunk) continue;
    Cursor c{f, data[i].content};
    const uint64_t t0 = c.le(8), t1 = c.le(8), size = c.le(8);
    const uint32_t crc = static_cast<uint32_t>(c.le(4));
    EXPECT_EQ(c.str(), "");
    ASSERT_EQ(c.le(8), size);
    EXPECT_EQ(crc, mcap::crc32(0, f.data() + c.at, size));
    chunks.emplace_back(data[i].start, data[i].end - data[i].start);
    std::map<size_t, uint64_t> msg_time;  // offset in chunk -> log time
    for (const Record& r : records(f, c.at, c.at + size)) {
      if (r.op != mcap::kMessage) continue;
      Cursor m{f, r.content};
      m.le(2);
      m.le(4);
      const uint64_t t = m.le(8);
      EXPECT_GE(t, t0);
      EXPECT_LE(t, t1);
      msg_time[r.start - c.at] = t;
      ++messages;
    }
    size_t indexed = 0;
    for (size_t k = i + 1; k < data.size() && data[k].op == mcap::kMessageIndex; ++k) {
      Cursor m{f, data[k].content};
      m.le(2);
      const uint64_t bytes = m.le(4);
      for (uint64_t e = 0; e < bytes / 16; ++e) {
        const uint64_t t = m.le(8), off = m.le(8);
        ASSERT_TRUE(msg_time.count(off)) << "message index offset " << off << " is no message";
        EXPECT_EQ(msg_time[off], t);
        ++indexed;
      }
    }
    EXPECT_EQ(indexed, msg_time.size());
  }
  EXPECT_EQ(messages, 10);
  EXPECT_GE(chunks.size(), 3u);
  // Summary: grouped by opcode (schema, channels, statistics, chunk indexes), then offsets.
  const auto summary = records(f, summary_start, summary_offset_start);
  std::map<uint8_t, int> count;
  size_t chunk_no = 0;
  for (const Record& r : summary) {
    ++count[r.op];
    if (r.op == mcap::kStatistics) {
      Cursor c{f, r.content};
      EXPECT_EQ(c.le(8), 10u);  // messages
      EXPECT_EQ(c.le(2), 1u);   // schemas
      EXPECT_EQ(c.le(4), 3u);   // channels
      c.le(4);
      c.le(4);
      EXPECT_EQ(c.le(4), chunks.size());
      EXPECT_EQ(c.le(8), 1000u);
      EXPECT_EQ(c.le(8), 1090u);
      EXPECT_EQ(c.le(4), 3u * 10);  // three (channel, count) pairs
      std::map<uint64_t, uint64_t> per;
      for (int k = 0; k < 3; ++k) {
        const uint64_t id = c.le(2);
        per[id] = c.le(8);
      }
      const std::map<uint64_t, uint64_t> want_counts = {{1, 7}, {2, 3}, {3, 0}};
      EXPECT_EQ(per, want_counts);
    }
    if (r.op == mcap::kChunkIndex) {
      Cursor c{f, r.content};
      c.le(8);
      c.le(8);
      ASSERT_LT(chunk_no, chunks.size());
      EXPECT_EQ(c.le(8), chunks[chunk_no].first);
      EXPECT_EQ(c.le(8), chunks[chunk_no].second);
      const uint64_t map_bytes = c.le(4);
      for (uint64_t e = 0; e < map_bytes / 10; ++e) {
        c.le(2);
        const uint64_t off = c.le(8);
        EXPECT_EQ(static_cast<uint8_t>(f[off]), mcap::kMessageIndex);
      }
      ++chunk_no;
    }
  }
  EXPECT_EQ(count[mcap::kSchema], 1);
  EXPECT_EQ(count[mcap::kChannel], 3);
  EXPECT_EQ(count[mcap::kStatistics], 1);
  EXPECT_EQ(count[mcap::kChunkIndex], static_cast<int>(chunks.size()));
  // Summary offsets: one per group, each covering exactly that group's records.
  const auto offsets = records(f, summary_offset_start, footer_at);
  EXPECT_EQ(offsets.size(), 4u);
  for (const Record& r : offsets) {
    ASSERT_EQ(r.op, mcap::kSummaryOffset);
    Cursor c{f, r.content};
    const uint8_t op = static_cast<uint8_t>(c.le(1));
    const uint64_t start = c.le(8), len = c.le(8);
    int n = 0;
    for (const Record& g : records(f, start, start + len)) {
      EXPECT_EQ(g.op, op);
      ++n;
    }
    EXPECT_EQ(n, count[op]);
  }
}

TEST(McapWriter, AnEmptyFileIsValid) {
  const std::string path = scratch("empty.mcap");
  { mcap::Writer w(path); }  // closed by the destructor
  const std::string f = readText(path);
  const auto data = records(f, 8, f.size() - 8);
  ASSERT_GE(data.size(), 3u);
  EXPECT_EQ(data.front().op, mcap::kHeader);
  EXPECT_EQ(data.back().op, mcap::kFooter);
}

TEST(McapWriter, AnUnwritablePathIsAClearError) {
  try {
    mcap::Writer w("/nonexistent-dir/x.mcap");
    FAIL() << "no error";
  } catch (const std::runtime_error& e) {
    EXPECT_NE(std::string(e.what()).find("/nonexistent-dir/x.mcap"), std::string::npos);
  }
}

// ---- messages of a small synthetic run ----

point_cloud_t scan(int frame, int n) {
  point_cloud_t m{};
  m.utime = 1'000'000'000 + 100'000 * int64_t{frame};
  m.frame = frame;
  m.sequence = "0000";
  m.num_points = n;
  for (int i = 0; i < n; ++i) {
    m.x.push_back(1.5f + i);
    m.y.push_back(-2.0f);
    m.z.push_back(0.25f * frame);
    m.intensity.push_back(0.5f);
  }
  return m;
}

pose_t poseAt(double x, double yaw) {
  pose_t p{};
  p.position[0] = x;
  p.orientation[0] = std::cos(yaw / 2);
  p.orientation[3] = std::sin(yaw / 2);
  return p;
}

box_t box(const std::string& type, int id, double x) {
  box_t b{};
  b.type = type;
  b.id = id;
  b.score = 0.9;
  b.center[0] = x;
  b.size[0] = 4, b.size[1] = 1.8, b.size[2] = 1.5;
  return b;
}

slot_state_t slotState(int frame, const std::vector<int>& ids) {
  slot_state_t m{};
  m.utime = scan(frame, 0).utime;
  m.frame = frame;
  m.mode = "slot";
  m.ego_pose = poseAt(frame, 0.1);
  for (int id : ids) {
    track_t t{};
    t.id = id;
    t.type = "Car";
    t.pose = poseAt(10 + frame + id, 0);
    t.size[0] = 4, t.size[1] = 2, t.size[2] = 1.5;
    t.velocity[0] = 3, t.velocity[1] = 4;
    t.velocity_covariance[0] = t.velocity_covariance[4] = 0.04;  // 0.2 m/s along any direction
    t.velocity_covariance[8] = 0.01;
    t.is_dynamic = true;
    t.status = track_t::STATUS_CONFIRMED;
    m.tracks.push_back(t);
  }
  m.num_tracks = static_cast<int>(m.tracks.size());
  return m;
}

TEST(FoxgloveConvert, ScanIsAPackedFloat32PointCloudInTheLidarFrame) {
  foxglove::Converter conv;
  std::vector<foxglove::Output> out;
  conv.add(scan(2, 2), out);
  ASSERT_EQ(out.size(), 1u);
  EXPECT_EQ(conv.topics()[out[0].topic].name, "/lidar/points");
  const YAML::Node j = YAML::Load(out[0].bytes);
  EXPECT_EQ(j["frame_id"].as<std::string>(), "lidar");
  EXPECT_EQ(j["point_stride"].as<int>(), 16);
  EXPECT_EQ(j["timestamp"]["sec"].as<int64_t>(), 1000);
  EXPECT_EQ(j["timestamp"]["nsec"].as<int64_t>(), 200'000'000);
  const float want[8] = {1.5f, -2.0f, 0.5f, 0.5f, 2.5f, -2.0f, 0.5f, 0.5f};
  std::string b64;
  foxglove::appendBase64(b64, want, sizeof want);
  EXPECT_EQ(j["data"].as<std::string>(), b64);
}

TEST(FoxgloveConvert, SlotStateGivesTransformPathAndTracksWithRecentPaths) {
  foxglove::ConverterOptions opt;
  opt.track_path_frames = 3;
  foxglove::Converter conv(Channels(), opt);
  std::vector<foxglove::Output> out;
  for (int f = 0; f < 5; ++f) {
    out.clear();
    conv.add(slotState(f, f < 4 ? std::vector<int>{1, 2} : std::vector<int>{2}), out);
  }
  ASSERT_EQ(out.size(), 3u);
  std::map<std::string, YAML::Node> by;
  for (const auto& o : out) by[conv.topics()[o.topic].name] = YAML::Load(o.bytes);
  // world -> lidar, quaternion (w, x, y, z) written as x y z w.
  const YAML::Node tf = by["/tf"];
  EXPECT_EQ(tf["parent_frame_id"].as<std::string>(), "world");
  EXPECT_EQ(tf["child_frame_id"].as<std::string>(), "lidar");
  EXPECT_DOUBLE_EQ(tf["translation"]["x"].as<double>(), 4);
  EXPECT_NEAR(tf["rotation"]["z"].as<double>(), std::sin(0.05), 1e-12);
  EXPECT_NEAR(tf["rotation"]["w"].as<double>(), std::cos(0.05), 1e-12);
  EXPECT_EQ(by["/slot/path"]["poses"].size(), 5u);
  const YAML::Node tracks = by["/slot/tracks"];
  ASSERT_EQ(tracks["entities"].size(), 1u);  // track 1 ended
  const YAML::Node e = tracks["entities"][0];
  EXPECT_EQ(e["id"].as<std::string>(), "track/2");
  EXPECT_EQ(e["texts"][0]["text"].as<std::string>(), "2 Car 5.0±0.2 m/s");
  ASSERT_EQ(e["lines"].size(), 1u);
  EXPECT_EQ(e["lines"][0]["points"].size(), 3u);  // the last 3 positions
  EXPECT_DOUBLE_EQ(e["lines"][0]["points"][2]["x"].as<double>(), 16);
  EXPECT_EQ(tracks["deletions"][0]["type"].as<int>(), 1);  // replaces the previous frame's boxes
}

TEST(FoxgloveConvert, UnwantedTopicsAreNotBuiltButStateIsKept) {
  foxglove::Converter conv;
  conv.setWanted([](size_t t) { return t == foxglove::Converter::kSlotPath; });
  std::vector<foxglove::Output> out;
  conv.add(scan(0, 10), out);
  conv.add(slotState(0, {1}), out);
  conv.add(slotState(1, {1}), out);
  ASSERT_EQ(out.size(), 2u);
  EXPECT_EQ(YAML::Load(out[1].bytes)["poses"].size(), 2u);
}

TEST(FoxgloveLayout, TheShippedLayoutShowsTopicsTheConverterWrites) {
  const YAML::Node layout = YAML::LoadFile(std::string(DLSLOT_SOURCE_DIR) + "/config/foxglove-layout.json");
  std::set<std::string> topics;
  const foxglove::Converter conv;
  for (const auto& t : conv.topics()) topics.insert(t.name);
  const YAML::Node panel = layout["configById"]["3D!dlslot"];
  ASSERT_TRUE(panel.IsMap());
  EXPECT_EQ(panel["followTf"].as<std::string>(), foxglove::kLidarFrame);
  EXPECT_EQ(panel["layers"]["grid"]["frameId"].as<std::string>(), foxglove::kWorldFrame);
  int shown = 0;
  for (const auto& kv : panel["topics"]) {
    EXPECT_TRUE(topics.count(kv.first.as<std::string>())) << kv.first.as<std::string>();
    shown += kv.second["visible"].as<bool>();
  }
  EXPECT_GE(shown, 4);
  EXPECT_TRUE(topics.count(layout["configById"]["RawMessages!dlslotstatus"]["topicPath"].as<std::string>()));
}

// ---- the exporter, read back by @mcap/core ----

std::string nodeModules() { return std::string(DLSLOT_BIN_DIR) + "/../npm/node_modules"; }

// Runs tests/js/mcap_check.cjs on `mcap` and returns its JSON report, parsed.
YAML::Node independentRead(const std::string& mcap) {
  if (!fs::exists(nodeModules() + "/@mcap/core/package.json"))
    ADD_FAILURE() << "@mcap/core is not installed in " << nodeModules() << ": run ./dlslot setup";
  const std::string cmd = "NODE_PATH=" + nodeModules() + " node " + std::string(DLSLOT_SOURCE_DIR) +
                          "/tests/js/mcap_check.cjs " + mcap + " 2>&1";
  std::FILE* p = popen(cmd.c_str(), "r");
  EXPECT_NE(p, nullptr);
  std::string text;
  char buf[65536];
  for (size_t n; p && (n = std::fread(buf, 1, sizeof buf, p)) > 0;) text.append(buf, n);
  const int rc = p ? pclose(p) : -1;
  EXPECT_EQ(rc, 0) << text.substr(0, 2000);
  try {
    return YAML::Load(text);
  } catch (const std::exception& e) {
    ADD_FAILURE() << "mcap_check printed no JSON: " << text.substr(0, 2000);
    return YAML::Node();
  }
}

struct SyntheticRun {
  std::map<std::string, std::vector<int64_t>> utimes;  // channel -> utime of each valid message
  int statuses = 0, raw = 0, corrupt = 0;
};

// Every channel of a run, 12 frames, plus a channel without a converter and a corrupt message.
SyntheticRun writeLog(const std::string& path) {
  SyntheticRun run;
  lcm::LogFile log(path, "w");
  int64_t t = 1'700'000'000'000'000;  // recording time, microseconds
  auto put = [&](const std::string& channel, const auto& msg) {
    std::vector<uint8_t> b(msg.getEncodedSize());
    msg.encode(b.data(), 0, static_cast<int>(b.size()));
    lcm::LogEvent ev{};
    ev.timestamp = t += 1000;
    ev.channel = channel;
    ev.datalen = static_cast<int32_t>(b.size());
    ev.data = b.data();
    log.writeEvent(&ev);
  };
  for (int f = 0; f < 12; ++f) {
    const point_cloud_t s = scan(f, 50 + f);
    put("LIDAR_SCAN", s);
    run.utimes["LIDAR_SCAN"].push_back(s.utime);
    detections_t d{};
    d.utime = s.utime, d.frame = f, d.source = "files";
    d.boxes = {box("Car", -1, 10), box("Pedestrian", -1, 5)};
    d.num_boxes = 2;
    put("DETECTIONS", d);
    run.utimes["DETECTIONS"].push_back(s.utime);
    ground_truth_t g{};
    g.utime = s.utime, g.frame = f, g.has_pose = true, g.pose = poseAt(f, 0);
    g.boxes = {box("Car", 7, 10)};
    g.num_boxes = 1;
    put("GROUND_TRUTH", g);
    run.utimes["GROUND_TRUTH"].push_back(s.utime);
    odometry_t o{};
    o.utime = s.utime, o.frame = f, o.pose = poseAt(f * 1.01, 0), o.delta = poseAt(1, 0);
    put("ODOMETRY", o);
    run.utimes["ODOMETRY"].push_back(s.utime);
    if (f == 5) {  // a corrupt event: the guard refuses it, the exporter counts it and goes on
      lcm::LogEvent ev{};
      uint8_t junk[12] = {1, 2, 3};
      ev.timestamp = t += 1000;
      ev.channel = "ODOMETRY";
      ev.datalen = sizeof junk;
      ev.data = junk;
      log.writeEvent(&ev);
      ++run.corrupt;
    }
    associations_t a{};
    a.utime = s.utime, a.frame = f, a.ego_pose = poseAt(f, 0), a.ego_pose_source = "slot";
    association_t as{};
    as.track_id = 3;
    as.box_lidar = as.box_world = box("Car", 3, 10 + f);
    a.associations = {as};
    a.num_associations = 1;
    put("ASSOCIATIONS", a);
    run.utimes["ASSOCIATIONS"].push_back(s.utime);
    const slot_state_t st = slotState(f, {3, 4});
    put("SLOT_STATE", st);
    run.utimes["SLOT_STATE"].push_back(s.utime);
    if (f % 4 == 0) {
      process_status_t ps{};
      ps.utime = t, ps.name = "odometry", ps.pid = 42, ps.last_frame = f;
      ps.counter_names = {"dropped"};
      ps.counter_values = {0};
      ps.num_counters = 1;
      put("PROCESS_STATUS", ps);
      run.utimes["PROCESS_STATUS"].push_back(ps.utime);
      ++run.statuses;
    }
    // The mapper's state: the correction 0.5 m in x from frame 6 on, and at the last frame a loop
    // from it back to frame 1 (accepted) and one refused.
    map_state_t ms{};
    ms.utime = s.utime, ms.frame = f;
    ms.map_from_world = poseAt(f >= 6 ? 0.5 : 0.0, 0);
    ms.map_pose = poseAt(f + (f >= 6 ? 0.5 : 0.0), 0);
    if (f == 11) {
      loop_event_t e{};
      e.query_frame = 11, e.match_frame = 1, e.relative = poseAt(0.2, 0), e.accepted = true;
      loop_event_t refused = e;
      refused.match_frame = 2, refused.accepted = false, refused.reason = "overlap";
      ms.loops = {e, refused};
      ms.num_loops = 2;
    }
    put("MAP_STATE", ms);
    run.utimes["MAP_STATE"].push_back(s.utime);
    if (f % 3 == 0) {
      lcm::LogEvent ev{};
      uint8_t bytes[20] = {0xde, 0xad, 0xbe, 0xef};
      ev.timestamp = t += 1000;
      ev.channel = "USER_NOTES";
      ev.datalen = sizeof bytes;
      ev.data = bytes;
      log.writeEvent(&ev);
      ++run.raw;
    }
  }
  return run;
}

TEST(McapExport, EveryChannelReadsBackInAnIndependentReaderWithTheLogsCountsAndTimestamps) {
  const std::string log = scratch("run.lcmlog"), out = scratch("run.mcap");
  const SyntheticRun run = writeLog(log);
  const auto stats = foxglove::exportMcap(log, out, Channels());
  EXPECT_EQ(stats.scans, 12);
  EXPECT_EQ(stats.refused.size(), 1u);
  EXPECT_EQ(stats.refused.begin()->second, run.corrupt);

  const YAML::Node r = independentRead(out);
  ASSERT_TRUE(r.IsMap());
  EXPECT_EQ(r["errors"].size(), 0u) << YAML::Dump(r["errors"]);
  EXPECT_TRUE(r["dataCrcOk"].as<bool>());
  EXPECT_TRUE(r["summaryCrcOk"].as<bool>());
  EXPECT_EQ(r["header"]["library"].as<std::string>(), "dlslot-mcap");
  // topic -> (schema, source channel)
  const std::map<std::string, std::pair<std::string, std::string>> expected = {
      {"/lidar/points", {"foxglove.PointCloud", "LIDAR_SCAN"}},
      {"/detections", {"foxglove.SceneUpdate", "DETECTIONS"}},
      {"/ground_truth/boxes", {"foxglove.SceneUpdate", "GROUND_TRUTH"}},
      {"/ground_truth/path", {"foxglove.PosesInFrame", "GROUND_TRUTH"}},
      {"/odometry/path", {"foxglove.PosesInFrame", "ODOMETRY"}},
      {"/tracker/associations", {"foxglove.SceneUpdate", "ASSOCIATIONS"}},
      {"/tf", {"foxglove.FrameTransform", "SLOT_STATE"}},
      {"/slot/path", {"foxglove.PosesInFrame", "SLOT_STATE"}},
      {"/slot/tracks", {"foxglove.SceneUpdate", "SLOT_STATE"}},
      {"/map/tf", {"foxglove.FrameTransform", "MAP_STATE"}},
      {"/map/path", {"foxglove.PosesInFrame", "MAP_STATE"}},
      {"/map/loops", {"foxglove.SceneUpdate", "MAP_STATE"}},
      {"/process_status", {"dlslot.ProcessStatus", "PROCESS_STATUS"}},
  };
  const YAML::Node topics = r["topics"];
  EXPECT_EQ(topics.size(), expected.size() + 1);  // + /lcm/USER_NOTES
  int64_t total = 0;
  for (const auto& [topic, want] : expected) {
    SCOPED_TRACE(topic);
    const YAML::Node t = topics[topic];
    ASSERT_TRUE(t.IsMap());
    const auto& utimes = run.utimes.at(want.second);
    EXPECT_EQ(t["schemaName"].as<std::string>(), want.first);
    EXPECT_EQ(t["schemaTitle"].as<std::string>(), want.first);
    EXPECT_EQ(t["schemaEncoding"].as<std::string>(), "jsonschema");
    EXPECT_EQ(t["messageEncoding"].as<std::string>(), "json");
    EXPECT_EQ(t["streamed"].as<size_t>(), utimes.size());
    EXPECT_EQ(t["indexed"].as<size_t>(), utimes.size());
    EXPECT_EQ(r["channelCounts"][topic].as<size_t>(), utimes.size());
    total += static_cast<int64_t>(utimes.size());
    // Each message's own timestamp is its LCM message's utime, in log order.
    ASSERT_EQ(t["timestamps"].size(), utimes.size());
    for (size_t i = 0; i < utimes.size(); ++i)
      EXPECT_EQ(t["timestamps"][i].as<std::string>(), std::to_string(utimes[i] * 1000)) << "message " << i;
  }
  EXPECT_EQ(topics["/lcm/USER_NOTES"]["streamed"].as<int>(), run.raw);
  EXPECT_EQ(topics["/lcm/USER_NOTES"]["schemaName"].as<std::string>(), "dlslot.LcmMessage");
  EXPECT_EQ(r["messageCount"].as<int64_t>(), total + run.raw);
  // Every message of a scan shares that scan's log time: the scan's points, boxes and poses
  // show together when Foxglove scrubs.
  for (const char* topic : {"/detections", "/slot/tracks", "/tf"})
    for (size_t i = 0; i < 12; ++i)
      EXPECT_EQ(topics[topic]["logTimes"][i].as<std::string>(), topics["/lidar/points"]["logTimes"][i].as<std::string>());
  // Content as the reader decoded it.
  EXPECT_EQ(topics["/lidar/points"]["details"][3]["points"].as<int>(), 53);
  EXPECT_FLOAT_EQ(topics["/lidar/points"]["details"][3]["first"][2].as<float>(), 0.75f);
  EXPECT_EQ(topics["/slot/tracks"]["details"][11]["entities"].as<int>(), 2);
  EXPECT_EQ(topics["/slot/tracks"]["details"][11]["lines"].as<int>(), 2);
  EXPECT_EQ(topics["/ground_truth/path"]["details"][11]["poses"].as<int>(), 12);
  EXPECT_EQ(topics["/tf"]["details"][0]["child"].as<std::string>(), "lidar");
  // The mapper's frame: "world" placed in "map" by the correction, the loop-closed path in "map",
  // and the accepted loop (not the refused one) as a line once it is there.
  EXPECT_EQ(topics["/map/tf"]["details"][11]["parent"].as<std::string>(), "map");
  EXPECT_EQ(topics["/map/tf"]["details"][11]["child"].as<std::string>(), "world");
  EXPECT_DOUBLE_EQ(topics["/map/tf"]["details"][5]["t"][0].as<double>(), 0.0);
  EXPECT_DOUBLE_EQ(topics["/map/tf"]["details"][6]["t"][0].as<double>(), 0.5);
  EXPECT_EQ(topics["/map/path"]["details"][11]["poses"].as<int>(), 12);
  EXPECT_EQ(topics["/map/path"]["details"][11]["frame"].as<std::string>(), "map");
  EXPECT_EQ(topics["/map/loops"]["details"][10]["entities"].as<int>(), 0);
  EXPECT_EQ(topics["/map/loops"]["details"][11]["entities"].as<int>(), 1);
  EXPECT_EQ(topics["/map/loops"]["details"][11]["lines"].as<int>(), 1);
  EXPECT_EQ(topics["/map/loops"]["details"][11]["texts"][0].as<std::string>(), "loop 11 -> 1");
}

TEST(McapExport, ACorruptLogIsAnErrorNamingTheFile) {
  const std::string log = scratch("corrupt.lcmlog");
  {
    std::ofstream f(log, std::ios::binary);
    f << "this is not an LCM log at all, not even close";
  }
  try {
    foxglove::exportMcap(log, scratch("corrupt.mcap"), Channels());
    FAIL() << "no error";
  } catch (const std::exception& e) {
    EXPECT_NE(std::string(e.what()).find(log), std::string::npos) << e.what();
  }
}

TEST(McapExport, TheCommandLineToolExportsAndReportsCounts) {
  const std::string log = scratch("cli.lcmlog"), out = scratch("cli.mcap");
  writeLog(log);
  const std::string cmd = std::string(DLSLOT_BIN_DIR) + "/dlslot-export --quiet --log " + log + " --mcap " + out + " 2>&1";
  std::FILE* p = popen(cmd.c_str(), "r");
  ASSERT_NE(p, nullptr);
  std::string text;
  char buf[4096];
  for (size_t n; (n = std::fread(buf, 1, sizeof buf, p)) > 0;) text.append(buf, n);
  EXPECT_EQ(pclose(p), 0) << text;
  std::istringstream lines(text);
  bool counted = false;
  for (std::string line; std::getline(lines, line);) {
    std::istringstream words(line);
    std::string topic;
    int n = 0;
    if (words >> topic >> n && topic == "/lidar/points") counted = n == 12;
  }
  EXPECT_TRUE(counted) << text;
  EXPECT_NE(text.find("refused (not written): ODOMETRY"), std::string::npos) << text;
  EXPECT_NE(text.find("frames/s"), std::string::npos) << text;
  EXPECT_TRUE(fs::exists(out));
}

}  // namespace
