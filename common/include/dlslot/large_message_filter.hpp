// A kernel filter on LCM's multicast receive socket that keeps the point clouds away from the
// processes that do not take them. Every LCM socket on the port receives every datagram, and
// LCM 1.3.1 copies each fragment of a message into a reassembly buffer (a fresh malloc of the
// whole message) before it looks for a subscriber: the tracker, the backend, the player (its own
// scans come back to it) and the launcher each paid for a 2 MB scan per frame that they threw
// away, about 60 % of the tracker's CPU. The filter cuts each datagram of a large fragmented
// message down to 4 bytes of payload, which LCM discards as too short to be LCM; nothing is
// counted as a kernel drop (the datagram is delivered, trimmed), so the frame accounting's UDP
// drops still mean "receive buffer full".
#pragma once

#include <cstdint>

namespace dlslot {

// Messages of at least this many encoded bytes are point clouds (a KITTI scan is ~1.9 MB);
// every other pipeline message is far smaller (a SLOT_STATE of 100 tracks with covariances is
// ~40 kB). Node::publish reports a non-scan message this large as an error.
constexpr uint32_t kLargeMessageBytes = 1u << 20;

// Attaches the filter to socket `fd` (LCM's receive socket): each datagram of an LCM fragmented
// message (magic "LC03") whose whole message is >= min_bytes reaches the socket cut to 4 bytes.
// Short messages and smaller fragmented ones pass untouched. Returns false (errno set) when the
// kernel refuses it.
bool attachLargeMessageFilter(int fd, uint32_t min_bytes = kLargeMessageBytes);
// Removes it (a process that subscribes to the point clouds after all).
bool detachLargeMessageFilter(int fd);

}  // namespace dlslot
