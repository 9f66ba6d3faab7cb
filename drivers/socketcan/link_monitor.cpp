#include "drivers/socketcan/link_monitor.h"

#include <linux/netlink.h>
#include <linux/rtnetlink.h>
#include <net/if.h>
#include <sys/socket.h>

#include <array>
#include <cerrno>
#include <cstring>

namespace resolver {
namespace {

/// IFLA_IFNAME of a link message, or empty.
std::string link_name(const nlmsghdr* h) {
  const auto* info = static_cast<const ifinfomsg*>(NLMSG_DATA(h));
  int left = static_cast<int>(IFLA_PAYLOAD(h));
  // The rtattr macros cast away const; the attributes are only read.
  for (auto* a = IFLA_RTA(const_cast<ifinfomsg*>(info)); RTA_OK(a, left); a = RTA_NEXT(a, left)) {
    if (a->rta_type == IFLA_IFNAME) {
      const auto* name = static_cast<const char*>(RTA_DATA(a));
      return std::string(name, ::strnlen(name, RTA_PAYLOAD(a)));
    }
  }
  return {};
}

}  // namespace

std::optional<LinkMonitor> LinkMonitor::open(std::string iface) {
  UniqueFd fd(::socket(AF_NETLINK, SOCK_RAW | SOCK_CLOEXEC | SOCK_NONBLOCK, NETLINK_ROUTE));
  if (!fd.valid()) return std::nullopt;
  sockaddr_nl addr{};
  addr.nl_family = AF_NETLINK;
  addr.nl_groups = RTMGRP_LINK;
  if (::bind(fd.get(), reinterpret_cast<const sockaddr*>(&addr), sizeof addr) != 0) return std::nullopt;
  return LinkMonitor(std::move(fd), std::move(iface));
}

int LinkMonitor::feed(const unsigned char* data, std::size_t size) {
  int downs = 0;
  auto left = static_cast<unsigned int>(size);
  // NLMSG_OK/NLMSG_NEXT walk the buffer; the macros need a mutable pointer.
  for (auto* h = reinterpret_cast<nlmsghdr*>(const_cast<unsigned char*>(data)); NLMSG_OK(h, left);
       h = NLMSG_NEXT(h, left)) {
    if (h->nlmsg_type != RTM_NEWLINK && h->nlmsg_type != RTM_DELLINK) continue;
    if (h->nlmsg_len < NLMSG_LENGTH(sizeof(ifinfomsg)) || link_name(h) != iface_) continue;
    const auto* info = static_cast<const ifinfomsg*>(NLMSG_DATA(h));
    // A deleted interface is closed first (a NEWLINK without IFF_UP), so
    // DELLINK only confirms what is already counted.
    const bool down = h->nlmsg_type == RTM_DELLINK || (info->ifi_flags & IFF_UP) == 0;
    if (down && !down_) ++downs;
    down_ = down;
  }
  return downs;
}

int LinkMonitor::poll_downs() {
  int downs = 0;
  alignas(nlmsghdr) std::array<unsigned char, 8192> buffer{};
  for (;;) {
    const ssize_t n = ::recv(fd_.get(), buffer.data(), buffer.size(), MSG_DONTWAIT);
    if (n > 0) {
      downs += feed(buffer.data(), static_cast<std::size_t>(n));
      continue;
    }
    if (n < 0 && errno == ENOBUFS) {  // the queue overflowed: events lost, read on
      ++overruns_;
      continue;
    }
    return downs;  // EAGAIN: nothing more queued (or an error: no events)
  }
}

}  // namespace resolver
