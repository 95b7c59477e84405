// The kernel receive buffer of LCM's multicast socket. A 2 MB scan leaves the player as a burst
// of ~32 datagrams of 64 kB, and every LCM socket bound to the port (each process's, the
// logger's) must hold the whole burst until LCM's reader thread drains it; what does not fit is
// dropped by the kernel without a word. LCM asks for `recv_buf_size` with SO_RCVBUF, which the
// kernel caps at net.core.rmem_max; a private network namespace inherits the host's value and
// cannot raise it. SO_RCVBUFFORCE passes the cap where the process may (CAP_NET_ADMIN, i.e.
// root); where it may not, the capped size is what there is, and it is reported.
#pragma once

#include <cstdint>
#include <string>
#include <vector>

namespace dlslot {

// The recv_buf_size=N parameter of a udpm:// LCM URL; 0 when absent or not udpm.
int64_t requestedReceiveBuffer(const std::string& lcm_url);
// The port of a udpm:// LCM URL (LCM's default 7667 when not given); 0 when not udpm.
int lcmPort(const std::string& lcm_url);

struct ReceiveBuffer {
  int fd = -1;            // LCM's receive socket (-1: none found)
  int64_t requested = 0;  // bytes asked for
  int64_t granted = 0;    // what the kernel accounts datagrams against (SO_RCVBUF read back)
  bool forced = false;    // SO_RCVBUFFORCE was allowed
  std::string note;       // one line saying what was asked and what was granted, and how
};

// Every open UDP socket of this process bound to `port`, in fd order. It may hold sockets that
// another process made (descriptors inherited across fork and exec: dlslot-run's children hold
// the launcher's): Node tells its own by the socket that appears when LCM makes it.
std::vector<int> udpSocketsOnPort(int port);

// Asks for `bytes` of kernel receive buffer on socket `fd`: SO_RCVBUFFORCE, else SO_RCVBUF.
ReceiveBuffer enlargeReceiveBuffer(int fd, int64_t bytes);
// The same on the first UDP socket of this process bound to `port` (LCM's receive socket when it
// is the process's only one: create it first, e.g. with lcm::LCM::getFileno(); LCM's sending
// socket is not bound to the port).
ReceiveBuffer enlargeLcmReceiveBuffer(int port, int64_t bytes);

// Datagrams the kernel dropped on socket `fd` since it was opened (/proc/net/udp, the "drops"
// column of this network namespace); -1 when unknown.
int64_t udpDrops(int fd);

// UDP datagrams dropped for a full receive buffer in this network namespace (/proc/net/snmp,
// Udp: RcvbufErrors); -1 when unknown.
int64_t udpReceiveBufferErrors();

}  // namespace dlslot
