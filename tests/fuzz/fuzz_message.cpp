// libFuzzer target: one message type's guarded decoder and validator (message_guard.hpp), built
// once per type with DLSLOT_FUZZ_MESSAGE set to it. Whatever the bytes, decodeChecked must return
// (never throw, never allocate from an unchecked count), and a message it accepts must still be
// accepted, unchanged, after encoding it again (lcm-gen's encoder normalises booleans and cuts
// strings at a NUL, so the input bytes themselves need not come back).
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <vector>

#include "dlslot/message_guard.hpp"

using Msg = dlslot::DLSLOT_FUZZ_MESSAGE;

namespace {

std::vector<uint8_t> encoded(const Msg& m) {
  std::vector<uint8_t> b(static_cast<size_t>(m.getEncodedSize()));
  if (m.encode(b.data(), 0, static_cast<int>(b.size())) != static_cast<int>(b.size())) {
    std::fprintf(stderr, "an accepted %s does not encode\n", Msg::getTypeName());
    std::abort();
  }
  return b;
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  Msg m;
  if (dlslot::decodeChecked(data, size, &m)) return 0;
  const std::vector<uint8_t> once = encoded(m);
  Msg again;
  if (const dlslot::Refusal r = dlslot::decodeChecked(once.data(), once.size(), &again)) {
    std::fprintf(stderr, "an accepted %s is refused once encoded again: %s: %s\n", Msg::getTypeName(),
                 r.reason.c_str(), r.detail.c_str());
    std::abort();
  }
  if (encoded(again) != once) {
    std::fprintf(stderr, "an accepted %s changes when decoded and encoded again\n", Msg::getTypeName());
    std::abort();
  }
  return 0;
}
