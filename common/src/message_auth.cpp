#include "dlslot/message_auth.hpp"

#include <fcntl.h>
#include <sodium.h>
#include <sys/stat.h>
#include <unistd.h>

#include <cerrno>
#include <cstdlib>
#include <cstring>
#include <fstream>
#include <sstream>
#include <stdexcept>

#include "dlslot/input_error.hpp"

namespace dlslot {
namespace {

constexpr uint8_t kMagic[4] = {'D', 'L', 'A', '1'};
constexpr const char* kKeyFileTag = "dlslot-run-key-v1";

void initSodium() {
  if (sodium_init() < 0) throw std::runtime_error("libsodium could not be initialised");
}

std::string hex(const uint8_t* b, size_t n) {
  static const char* d = "0123456789abcdef";
  std::string s;
  for (size_t i = 0; i < n; ++i) {
    s += d[b[i] >> 4];
    s += d[b[i] & 15];
  }
  return s;
}

RunKey fromSecret(const std::array<uint8_t, 32>& secret) {
  RunKey k;
  k.secret = secret;
  // The run id is public (it travels in every envelope): a keyed-by-nothing hash of the secret,
  // with its own context so it says nothing usable about the MAC key.
  static const uint8_t ctx[] = "dlslot run id";
  crypto_generichash(k.run_id.data(), k.run_id.size(), secret.data(), secret.size(), ctx, sizeof ctx - 1);
  return k;
}

void putU64(uint8_t* p, uint64_t v) {
  for (int i = 7; i >= 0; --i, v >>= 8) p[i] = static_cast<uint8_t>(v);
}
uint64_t getU64(const uint8_t* p) {
  uint64_t v = 0;
  for (int i = 0; i < 8; ++i) v = (v << 8) | p[i];
  return v;
}

// The nonce: a hash of the channel, the publisher and its sequence number. (publisher, sequence)
// is unique under the key, so no nonce repeats; the channel in it binds the tag to the channel,
// so a message moved to another channel does not verify.
void nonceFor(const std::string& channel, const uint8_t* header, uint8_t nonce[24]) {
  crypto_generichash_state st;
  crypto_generichash_init(&st, nullptr, 0, 24);
  crypto_generichash_update(&st, reinterpret_cast<const uint8_t*>(channel.data()), channel.size());
  crypto_generichash_update(&st, header + 12, 24);
  crypto_generichash_final(&st, nonce, 24);
}

}  // namespace

std::string RunKey::runIdHex() const { return hex(run_id.data(), run_id.size()); }

RunKey makeRunKey() {
  initSodium();
  std::array<uint8_t, 32> s{};
  randombytes_buf(s.data(), s.size());
  return fromSecret(s);
}

void writeKeyFile(const std::string& path, const RunKey& key) {
  ::unlink(path.c_str());  // a new file, so the mode below is the one it gets
  const int fd = ::open(path.c_str(), O_WRONLY | O_CREAT | O_EXCL | O_CLOEXEC, 0600);
  if (fd < 0) throw InputError(path, 0, std::string("cannot create the key file: ") + std::strerror(errno));
  const std::string text = std::string(kKeyFileTag) + " " + hex(key.secret.data(), key.secret.size()) + "\n";
  const bool ok = ::write(fd, text.data(), text.size()) == static_cast<ssize_t>(text.size());
  ::close(fd);
  if (!ok) throw InputError(path, 0, "cannot write the key file");
}

RunKey readKeyFile(const std::string& path) {
  initSodium();
  struct stat st {};
  if (::stat(path.c_str(), &st) != 0) throw InputError(path, 0, "key file not found (" + std::string(std::strerror(errno)) + ")");
  if (!S_ISREG(st.st_mode)) throw InputError(path, 0, "the key file is not a regular file");
  if (st.st_mode & 077) {
    char mode[8];
    std::snprintf(mode, sizeof mode, "%04o", static_cast<unsigned>(st.st_mode & 0777));
    throw InputError(path, 0, std::string("the key file may be read by others (mode ") + mode + "); chmod 600 " + path);
  }
  std::ifstream in(path);
  std::string tag, value, extra;
  in >> tag >> value >> extra;
  if (tag != kKeyFileTag || value.size() != 64 || !extra.empty())
    throw InputError(path, 1, std::string("expected '") + kKeyFileTag + " <64 hex digits>' (make one with dlslot-run --make-key FILE)");
  std::array<uint8_t, 32> s{};
  size_t got = 0;
  if (sodium_hex2bin(s.data(), s.size(), value.c_str(), value.size(), nullptr, &got, nullptr) != 0 || got != 32)
    throw InputError(path, 1, "the key is not 64 hex digits");
  return fromSecret(s);
}

std::optional<RunKey> keyFromEnvironment() {
  const char* p = std::getenv(kKeyFileEnv);
  if (!p || !*p) return std::nullopt;
  return readKeyFile(p);
}

bool isEnvelope(const void* data, size_t size) {
  return size >= kEnvelopeHeader + kEnvelopeTag && std::memcmp(data, kMagic, 4) == 0;
}

MessageAuth::MessageAuth() = default;

MessageAuth::MessageAuth(const RunKey& key) : key_(key) {
  initSodium();
  randombytes_buf(publisher_.data(), publisher_.size());
}

void MessageAuth::seal(const std::string& channel, uint8_t* buf, size_t payload_size) {
  if (!key_) return;
  std::memcpy(buf, kMagic, 4);
  std::memcpy(buf + 4, key_->run_id.data(), 8);
  std::memcpy(buf + 12, publisher_.data(), 16);
  putU64(buf + 28, ++sequence_);
  uint8_t nonce[24];
  nonceFor(channel, buf, nonce);
  unsigned long long tag_len = 0;
  uint8_t no_ciphertext = 0;  // the plaintext is empty: everything is authenticated data
  crypto_aead_xchacha20poly1305_ietf_encrypt_detached(&no_ciphertext, buf + kEnvelopeHeader + payload_size, &tag_len,
                                                      nullptr, 0, buf, kEnvelopeHeader + payload_size, nullptr, nonce,
                                                      key_->secret.data());
}

std::vector<uint8_t> MessageAuth::sealCopy(const std::string& channel, const void* payload, size_t size) {
  std::vector<uint8_t> out(headerBytes() + size + tagBytes());
  if (size) std::memcpy(out.data() + headerBytes(), payload, size);
  seal(channel, out.data(), size);
  return out;
}

Refusal MessageAuth::open(const std::string& channel, const void* data, size_t size, const uint8_t** payload,
                          size_t* payload_size) {
  const auto* b = static_cast<const uint8_t*>(data);
  const bool enveloped = size >= 4 && std::memcmp(b, kMagic, 4) == 0;
  if (!key_) {  // open mode: take anything; an envelope is opened unverified
    if (enveloped && size >= kEnvelopeHeader + kEnvelopeTag) {
      *payload = b + kEnvelopeHeader;
      *payload_size = size - kEnvelopeHeader - kEnvelopeTag;
    } else {
      *payload = b;
      *payload_size = size;
    }
    return {};
  }
  if (!enveloped) return {"unauthenticated", "no authentication envelope (a plain LCM message: no run key)"};
  if (size < kEnvelopeHeader + kEnvelopeTag)
    return {"bad_envelope", std::to_string(size) + " bytes, an envelope needs at least " +
                                std::to_string(kEnvelopeHeader + kEnvelopeTag)};
  if (std::memcmp(b + 4, key_->run_id.data(), 8) != 0)
    return {"other_run", "run id " + hex(b + 4, 8) + ", this run is " + key_->runIdHex() +
                             " (another run on this LCM URL, or an old log played)"};
  const size_t n = size - kEnvelopeHeader - kEnvelopeTag;
  uint8_t nonce[24];
  nonceFor(channel, b, nonce);
  const uint8_t no_ciphertext = 0;  // the plaintext is empty: everything is authenticated data
  if (crypto_aead_xchacha20poly1305_ietf_decrypt_detached(nullptr, nullptr, &no_ciphertext, 0, b + kEnvelopeHeader + n, b,
                                                          kEnvelopeHeader + n, nonce, key_->secret.data()) != 0)
    return {"bad_mac", "the message's MAC does not verify with this run's key"};
  std::array<uint8_t, 16> publisher;
  std::memcpy(publisher.data(), b + 12, 16);
  const uint64_t seq = getU64(b + 28);
  uint64_t& last = last_[{publisher, channel}];
  if (seq <= last)
    return {"replayed", "sequence " + std::to_string(seq) + " of publisher " + hex(publisher.data(), 4) +
                            " after " + std::to_string(last)};
  last = seq;
  *payload = b + kEnvelopeHeader;
  *payload_size = n;
  return {};
}

}  // namespace dlslot
