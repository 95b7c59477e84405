// Authenticated pipeline messages. LCM has no authentication: anything that reaches the
// multicast group may publish on every channel. With a run key, every message a Node publishes
// travels in an envelope
//
//   "DLA1" | run id (8) | publisher (16) | sequence (8, big-endian) | payload | tag (16)
//
// where payload is the LCM-encoded message and tag is a Poly1305 MAC (XChaCha20-Poly1305 with
// an empty plaintext, libsodium) over the channel name, the header and the payload, keyed by
// the run's 32-byte secret with the nonce publisher|sequence. The publisher is random per
// process, the sequence counts its messages, so a nonce is never used twice under one key.
// A receiver refuses, by reason:
//   unauthenticated  no envelope (a plain LCM message);
//   bad_envelope     too short to hold one;
//   other_run        another run id (another run on the same LCM URL, or an old log replayed);
//   bad_mac          the tag does not verify (forged, altered, another channel, wrong key);
//   replayed         a sequence number this publisher already used on this channel.
// Without a key (open mode, --insecure) messages go out plain and anything is accepted; an
// envelope received then is opened without verification.
//
// The key reaches a process without its command line: a 0600 key file named by --key FILE or
// $DLSLOT_KEY_FILE (the launcher makes one per run, run.key in the run folder).
#pragma once

#include <array>
#include <cstddef>
#include <cstdint>
#include <map>
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include "dlslot/message_guard.hpp"

namespace dlslot {

// The environment variable naming a process's key file.
inline constexpr const char* kKeyFileEnv = "DLSLOT_KEY_FILE";
// The key file the launcher keeps in a run folder (offline readers look for it beside a log).
inline constexpr const char* kRunKeyFile = "run.key";

struct RunKey {
  std::array<uint8_t, 32> secret{};
  std::array<uint8_t, 8> run_id{};  // a hash of the secret: public, names the run in envelopes
  std::string runIdHex() const;
};

// A fresh random key.
RunKey makeRunKey();
// Writes `key` to `path` as one line of hex, mode 0600 (replacing any file there).
void writeKeyFile(const std::string& path, const RunKey& key);
// Reads a key file. Throws InputError naming the file for a missing or unreadable file, one
// that group or others may read ("chmod 600"), or contents that are not a key.
RunKey readKeyFile(const std::string& path);
// The key of this process: $DLSLOT_KEY_FILE when set (read with readKeyFile), else none.
std::optional<RunKey> keyFromEnvironment();

inline constexpr size_t kEnvelopeHeader = 4 + 8 + 16 + 8;
inline constexpr size_t kEnvelopeTag = 16;

// True when the bytes start with the envelope's magic and can hold one.
bool isEnvelope(const void* data, size_t size);

class MessageAuth {
 public:
  MessageAuth();  // open mode
  explicit MessageAuth(const RunKey& key);
  bool enabled() const { return key_.has_value(); }
  const std::optional<RunKey>& key() const { return key_; }

  // Bytes before and after the payload in a published buffer (0 in open mode).
  size_t headerBytes() const { return enabled() ? kEnvelopeHeader : 0; }
  size_t tagBytes() const { return enabled() ? kEnvelopeTag : 0; }
  // `buf` holds headerBytes(), the payload, then tagBytes(): writes the header and the tag.
  void seal(const std::string& channel, uint8_t* buf, size_t payload_size);
  // Copies `payload` into an envelope (or as it is, open mode).
  std::vector<uint8_t> sealCopy(const std::string& channel, const void* payload, size_t size);

  // Checks a received message; on success points `payload` at the LCM-encoded bytes inside.
  Refusal open(const std::string& channel, const void* data, size_t size, const uint8_t** payload,
               size_t* payload_size);

 private:
  std::optional<RunKey> key_;
  std::array<uint8_t, 16> publisher_{};
  uint64_t sequence_ = 0;
  // The last sequence number accepted per publisher and channel (verified publishers only).
  std::map<std::pair<std::array<uint8_t, 16>, std::string>, uint64_t> last_;
};

}  // namespace dlslot
