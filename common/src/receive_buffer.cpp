#include "dlslot/receive_buffer.hpp"

#include <arpa/inet.h>
#include <dirent.h>
#include <netinet/in.h>
#include <sys/socket.h>
#include <sys/stat.h>

#include <cstdlib>
#include <fstream>
#include <sstream>
#include <vector>

namespace dlslot {

int64_t requestedReceiveBuffer(const std::string& lcm_url) {
  if (lcm_url.rfind("udpm://", 0) != 0) return 0;
  const std::string key = "recv_buf_size=";
  const size_t q = lcm_url.find('?');
  if (q == std::string::npos) return 0;
  std::stringstream params(lcm_url.substr(q + 1));
  for (std::string p; std::getline(params, p, '&');) {
    if (p.rfind(key, 0) != 0) continue;
    char* end = nullptr;
    const long long v = std::strtoll(p.c_str() + key.size(), &end, 0);
    return (end && *end == '\0' && v > 0) ? v : 0;
  }
  return 0;
}

int lcmPort(const std::string& lcm_url) {
  if (lcm_url.rfind("udpm://", 0) != 0) return 0;
  const std::string rest = lcm_url.substr(7, lcm_url.find('?') == std::string::npos ? std::string::npos
                                                                                     : lcm_url.find('?') - 7);
  const size_t colon = rest.find(':');
  if (colon == std::string::npos) return 7667;
  const long port = std::strtol(rest.c_str() + colon + 1, nullptr, 10);
  return port > 0 && port < 65536 ? static_cast<int>(port) : 0;
}

namespace {

}  // namespace

std::vector<int> udpSocketsOnPort(int port) {
  std::vector<int> out;
  DIR* dir = opendir("/proc/self/fd");
  if (!dir) return out;
  while (const dirent* e = readdir(dir)) {
    char* end = nullptr;
    const long fd = std::strtol(e->d_name, &end, 10);
    if (!end || *end != '\0' || end == e->d_name) continue;
    int type = 0;
    socklen_t len = sizeof type;
    if (getsockopt(static_cast<int>(fd), SOL_SOCKET, SO_TYPE, &type, &len) != 0 || type != SOCK_DGRAM) continue;
    sockaddr_in addr{};
    len = sizeof addr;
    if (getsockname(static_cast<int>(fd), reinterpret_cast<sockaddr*>(&addr), &len) != 0 || addr.sin_family != AF_INET)
      continue;
    if (ntohs(addr.sin_port) == port) out.push_back(static_cast<int>(fd));
  }
  closedir(dir);
  return out;
}

namespace {

int64_t readBuffer(int fd) {
  int v = 0;
  socklen_t len = sizeof v;
  return getsockopt(fd, SOL_SOCKET, SO_RCVBUF, &v, &len) == 0 ? v : 0;
}

std::string mb(int64_t bytes) {
  std::ostringstream os;
  os.precision(3);
  os << bytes / 1048576.0 << " MB";
  return os.str();
}

}  // namespace

ReceiveBuffer enlargeLcmReceiveBuffer(int port, int64_t bytes) {
  const std::vector<int> fds = udpSocketsOnPort(port);
  if (fds.empty()) {
    ReceiveBuffer r;
    r.requested = bytes;
    r.note = "no LCM multicast receive socket found; receive buffer left as it is";
    return r;
  }
  return enlargeReceiveBuffer(fds.front(), bytes);
}

ReceiveBuffer enlargeReceiveBuffer(int fd, int64_t bytes) {
  ReceiveBuffer r;
  r.requested = bytes;
  r.fd = fd;
  const int want = static_cast<int>(std::min<int64_t>(bytes, 1 << 30));
  r.forced = setsockopt(r.fd, SOL_SOCKET, SO_RCVBUFFORCE, &want, sizeof want) == 0;
  if (!r.forced) setsockopt(r.fd, SOL_SOCKET, SO_RCVBUF, &want, sizeof want);
  r.granted = readBuffer(r.fd);
  std::ifstream rmem("/proc/sys/net/core/rmem_max");
  int64_t rmem_max = 0;
  rmem >> rmem_max;
  // The kernel doubles the value asked for (room for its own per-datagram overhead) and reports
  // the doubled value.
  r.note = "LCM receive buffer " + mb(r.granted) + " (asked " + mb(bytes) + ", " +
           (r.forced ? std::string("SO_RCVBUFFORCE")
                     : "SO_RCVBUF capped by net.core.rmem_max " + mb(rmem_max) + "; SO_RCVBUFFORCE needs root") +
           ")";
  return r;
}

int64_t udpDrops(int fd) {
  struct stat st {};
  if (fd < 0 || fstat(fd, &st) != 0) return -1;
  std::ifstream in("/proc/net/udp");
  std::string line;
  std::getline(in, line);  // header
  while (std::getline(in, line)) {
    std::istringstream is(line);
    std::vector<std::string> f;
    for (std::string w; is >> w;) f.push_back(w);
    // sl local rem st tx:rx tr:when retrnsmt uid timeout inode ref pointer drops
    if (f.size() >= 13 && f[9] == std::to_string(st.st_ino)) return std::strtoll(f[12].c_str(), nullptr, 10);
  }
  return -1;
}

int64_t udpReceiveBufferErrors() {
  std::ifstream in("/proc/net/snmp");
  std::string names, values;
  while (std::getline(in, names) && std::getline(in, values)) {
    if (names.rfind("Udp:", 0) != 0) continue;
    std::istringstream n(names), v(values);
    std::string name, value;
    while (n >> name && v >> value)
      if (name == "RcvbufErrors") return std::strtoll(value.c_str(), nullptr, 10);
  }
  return -1;
}

}  // namespace dlslot
