// The authentication envelope (message_auth.hpp): a sealed message opens with the run's key and
// nothing else does: no envelope, another run's key, a changed byte anywhere, another channel, a
// sequence number used before. Key files: written 0600, refused when others may read them or
// when they hold no key, each error naming the file.
#include <gtest/gtest.h>
#include <sys/stat.h>

#include <filesystem>
#include <fstream>

#include "dlslot/input_error.hpp"
#include "dlslot/message_auth.hpp"
#include "dlslot/odometry_t.hpp"

using namespace dlslot;
namespace fs = std::filesystem;

namespace {

std::vector<uint8_t> payload(size_t n = 100) {
  std::vector<uint8_t> p(n);
  for (size_t i = 0; i < n; ++i) p[i] = static_cast<uint8_t>(i * 7 + 3);
  return p;
}

std::string reasonOf(MessageAuth& rx, const std::string& channel, const std::vector<uint8_t>& bytes) {
  const uint8_t* p = nullptr;
  size_t n = 0;
  return rx.open(channel, bytes.data(), bytes.size(), &p, &n).reason;
}

std::string tmpPath(const std::string& name) {
  const std::string dir = (fs::temp_directory_path() / ("dlslot-auth-test-" + std::to_string(getpid()))).string();
  fs::create_directories(dir);
  return dir + "/" + name;
}

}  // namespace

TEST(MessageAuth, SealedMessageOpensToItsPayload) {
  const RunKey key = makeRunKey();
  MessageAuth tx(key), rx(key);
  const auto p = payload(1000);
  const auto sealed = tx.sealCopy("ODOMETRY", p.data(), p.size());
  ASSERT_EQ(sealed.size(), p.size() + kEnvelopeHeader + kEnvelopeTag);
  EXPECT_TRUE(isEnvelope(sealed.data(), sealed.size()));
  const uint8_t* out = nullptr;
  size_t n = 0;
  ASSERT_FALSE(rx.open("ODOMETRY", sealed.data(), sealed.size(), &out, &n));
  ASSERT_EQ(n, p.size());
  EXPECT_TRUE(std::equal(p.begin(), p.end(), out));
}

TEST(MessageAuth, RefusesPlainForeignAlteredMovedAndReplayedMessages) {
  const RunKey key = makeRunKey(), other = makeRunKey();
  MessageAuth tx(key), stranger(other), rx(key);
  const auto p = payload();
  // A plain LCM message (what anyone on the segment can send).
  EXPECT_EQ(reasonOf(rx, "ODOMETRY", p), "unauthenticated");
  // Too short to be an envelope, though it starts like one.
  EXPECT_EQ(reasonOf(rx, "ODOMETRY", {'D', 'L', 'A', '1', 0, 0}), "bad_envelope");
  // Another run's key: its run id differs.
  EXPECT_EQ(reasonOf(rx, "ODOMETRY", stranger.sealCopy("ODOMETRY", p.data(), p.size())), "other_run");
  // Every single byte changed, header, payload or tag: the MAC fails (the run id: other_run).
  const auto good = tx.sealCopy("ODOMETRY", p.data(), p.size());
  for (size_t i = 4; i < good.size(); ++i) {
    auto bad = good;
    bad[i] ^= 0x01;
    const std::string r = reasonOf(rx, "ODOMETRY", bad);
    EXPECT_EQ(r, i < 12 ? "other_run" : "bad_mac") << "byte " << i;
  }
  // The same bytes on another channel.
  EXPECT_EQ(reasonOf(rx, "SLOT_STATE", good), "bad_mac");
  // Accepted once, then refused as a replay; a later message of the publisher is accepted.
  EXPECT_EQ(reasonOf(rx, "ODOMETRY", good), "");
  EXPECT_EQ(reasonOf(rx, "ODOMETRY", good), "replayed");
  const auto next = tx.sealCopy("ODOMETRY", p.data(), p.size());
  EXPECT_EQ(reasonOf(rx, "ODOMETRY", next), "");
  EXPECT_EQ(reasonOf(rx, "ODOMETRY", good), "replayed");  // older than the last
}

TEST(MessageAuth, OpenModeTakesPlainMessagesAndOpensEnvelopes) {
  MessageAuth open_mode;
  EXPECT_FALSE(open_mode.enabled());
  const auto p = payload();
  EXPECT_EQ(open_mode.sealCopy("X", p.data(), p.size()), p);  // published as it is
  EXPECT_EQ(reasonOf(open_mode, "X", p), "");
  MessageAuth tx(makeRunKey());
  const auto sealed = tx.sealCopy("X", p.data(), p.size());
  const uint8_t* out = nullptr;
  size_t n = 0;
  ASSERT_FALSE(open_mode.open("X", sealed.data(), sealed.size(), &out, &n));
  EXPECT_EQ(n, p.size());
  EXPECT_TRUE(std::equal(p.begin(), p.end(), out));
}

TEST(MessageAuth, KeyFilesRoundTripAndBadOnesAreRefusedByName) {
  const RunKey key = makeRunKey();
  const std::string path = tmpPath("run.key");
  writeKeyFile(path, key);
  struct stat st {};
  ASSERT_EQ(stat(path.c_str(), &st), 0);
  EXPECT_EQ(st.st_mode & 0777, 0600u);
  const RunKey back = readKeyFile(path);
  EXPECT_EQ(back.secret, key.secret);
  EXPECT_EQ(back.run_id, key.run_id);
  EXPECT_EQ(back.runIdHex().size(), 16u);

  auto refusal = [](const std::string& p) {
    try {
      readKeyFile(p);
    } catch (const InputError& e) {
      return std::string(e.what());
    }
    return std::string();
  };
  fs::permissions(path, fs::perms::owner_read | fs::perms::owner_write | fs::perms::group_read);
  std::string e = refusal(path);
  EXPECT_NE(e.find(path), std::string::npos) << e;
  EXPECT_NE(e.find("chmod 600"), std::string::npos) << e;
  const std::string garbage = tmpPath("garbage.key");
  {
    std::ofstream(garbage) << "not a key\n";
  }
  fs::permissions(garbage, fs::perms::owner_read | fs::perms::owner_write);
  e = refusal(garbage);
  EXPECT_NE(e.find(garbage), std::string::npos) << e;
  EXPECT_NE(e.find("dlslot-run-key-v1"), std::string::npos) << e;
  e = refusal(tmpPath("missing.key"));
  EXPECT_NE(e.find("not found"), std::string::npos) << e;
  fs::remove_all(fs::path(path).parent_path());
}
