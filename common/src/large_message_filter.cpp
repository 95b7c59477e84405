#include "dlslot/large_message_filter.hpp"

#include <linux/filter.h>
#include <sys/socket.h>

namespace dlslot {

bool attachLargeMessageFilter(int fd, uint32_t min_bytes) {
  // A classic BPF program over the datagram as a UDP socket's filter sees it: the UDP header
  // (8 bytes), then LCM's. LCM's long (fragment) header: magic "LC03", sequence number, size of
  // the whole message, fragment offset, fragment number, fragment count (big-endian).
  constexpr uint32_t kUdpHeader = 8;
  constexpr uint32_t kMagicLong = 0x4c433033;  // "LC03"
  // Kept bytes of a trimmed datagram: the UDP header and 4 bytes, fewer than LCM's 8-byte short
  // header, so LCM's reader discards it as "too short to be LCM" before any copy or allocation.
  constexpr uint32_t kTrimmed = kUdpHeader + 4;
  sock_filter code[] = {
      BPF_STMT(BPF_LD | BPF_W | BPF_ABS, kUdpHeader),          // A = magic (a datagram too short to
                                                               // hold one ends the program: dropped,
                                                               // as LCM would discard it anyway)
      BPF_JUMP(BPF_JMP | BPF_JEQ | BPF_K, kMagicLong, 0, 2),   // not a fragment: keep
      BPF_STMT(BPF_LD | BPF_W | BPF_ABS, kUdpHeader + 8),      // A = size of the whole message
      BPF_JUMP(BPF_JMP | BPF_JGE | BPF_K, min_bytes, 1, 0),    // large: trim
      BPF_STMT(BPF_RET | BPF_K, 0xffffffffu),                  // keep all of it
      BPF_STMT(BPF_RET | BPF_K, kTrimmed),
  };
  const sock_fprog prog{static_cast<unsigned short>(sizeof code / sizeof code[0]), code};
  return setsockopt(fd, SOL_SOCKET, SO_ATTACH_FILTER, &prog, sizeof prog) == 0;
}

bool detachLargeMessageFilter(int fd) {
  int unused = 0;
  return setsockopt(fd, SOL_SOCKET, SO_DETACH_FILTER, &unused, sizeof unused) == 0;
}

}  // namespace dlslot
