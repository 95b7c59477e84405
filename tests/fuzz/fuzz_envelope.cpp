// libFuzzer target: the authentication envelope (message_auth.hpp). Whatever the bytes, open()
// returns a refusal or a payload that lies inside them; the bytes sealed under the key open again
// to the same payload, and a plain message never opens.
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <vector>

#include "dlslot/message_auth.hpp"

namespace {

dlslot::RunKey fixedKey() {
  dlslot::RunKey k = dlslot::makeRunKey();  // random run id and secret: what matters is that it is fixed
  return k;
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  static const dlslot::RunKey key = fixedKey();
  dlslot::MessageAuth rx(key);
  const uint8_t* payload = nullptr;
  size_t n = 0;
  if (!rx.open("CHANNEL", data, size, &payload, &n)) {
    // Only a message sealed with the key opens; random bytes never carry a valid tag.
    if (payload < data || payload + n > data + size) std::abort();
    std::fprintf(stderr, "random bytes verified\n");
    std::abort();
  }
  dlslot::MessageAuth tx(key);
  const std::vector<uint8_t> sealed = tx.sealCopy("CHANNEL", data, size);
  if (rx.open("CHANNEL", sealed.data(), sealed.size(), &payload, &n) || n != size ||
      (size && std::memcmp(payload, data, size) != 0)) {
    std::fprintf(stderr, "a sealed message does not open to its payload\n");
    std::abort();
  }
  return 0;
}
