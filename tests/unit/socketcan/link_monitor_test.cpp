// LinkMonitor::feed on hand-built rtnetlink link messages: each up -> down
// transition of the watched interface counts once, whatever else the kernel
// announces (other interfaces, repeated states, the deletion after a close).
#include <linux/netlink.h>
#include <linux/rtnetlink.h>
#include <net/if.h>

#include <cstring>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "drivers/socketcan/link_monitor.h"

namespace resolver {
namespace {

/// Appends one RTM_NEWLINK/RTM_DELLINK message for `name` with `flags`.
void append_link(std::vector<unsigned char>& buf, std::uint16_t type, const std::string& name, unsigned flags) {
  const std::size_t attr_len = RTA_LENGTH(name.size() + 1);
  const std::size_t len = NLMSG_LENGTH(sizeof(ifinfomsg)) + RTA_ALIGN(attr_len);
  const std::size_t at = buf.size();
  buf.resize(at + NLMSG_ALIGN(len), 0);
  auto* h = reinterpret_cast<nlmsghdr*>(buf.data() + at);
  h->nlmsg_len = static_cast<std::uint32_t>(len);
  h->nlmsg_type = type;
  auto* info = static_cast<ifinfomsg*>(NLMSG_DATA(h));
  info->ifi_flags = flags;
  auto* a = IFLA_RTA(info);
  a->rta_type = IFLA_IFNAME;
  a->rta_len = static_cast<std::uint16_t>(attr_len);
  std::memcpy(RTA_DATA(a), name.c_str(), name.size() + 1);
}

int feed(LinkMonitor& m, const std::vector<unsigned char>& buf) { return m.feed(buf.data(), buf.size()); }

TEST(LinkMonitor, EachOutageOfTheWatchedInterfaceCountsOnce) {
  auto monitor = LinkMonitor::open("vcan0");
  if (!monitor) GTEST_SKIP() << "no rtnetlink socket here";
  std::vector<unsigned char> buf;
  append_link(buf, RTM_NEWLINK, "vcan0", IFF_UP | IFF_RUNNING);
  append_link(buf, RTM_NEWLINK, "vcan0", 0);       // down: 1
  append_link(buf, RTM_NEWLINK, "vcan0", 0);       // still down (another attribute changed)
  append_link(buf, RTM_NEWLINK, "vcan1", 0);       // not ours
  append_link(buf, RTM_NEWLINK, "vcan0", IFF_UP);  // up again
  append_link(buf, RTM_NEWLINK, "vcan0", 0);       // down: 2, in the same buffer
  EXPECT_EQ(feed(*monitor, buf), 2);
  EXPECT_TRUE(monitor->down());
  buf.clear();
  append_link(buf, RTM_DELLINK, "vcan0", 0);  // deleted after the close: already counted
  EXPECT_EQ(feed(*monitor, buf), 0);
  buf.clear();
  append_link(buf, RTM_NEWLINK, "vcan0", IFF_UP);
  append_link(buf, RTM_DELLINK, "vcan0", IFF_UP);  // gone while up: an outage too
  EXPECT_EQ(feed(*monitor, buf), 1);
}

TEST(LinkMonitor, APrefixOfTheNameIsAnotherInterface) {
  auto monitor = LinkMonitor::open("vcan0");
  if (!monitor) GTEST_SKIP() << "no rtnetlink socket here";
  std::vector<unsigned char> buf;
  append_link(buf, RTM_NEWLINK, "vcan", 0);
  append_link(buf, RTM_NEWLINK, "vcan00", 0);
  EXPECT_EQ(feed(*monitor, buf), 0);
  EXPECT_FALSE(monitor->down());
}

TEST(LinkMonitor, ATruncatedMessageIsIgnored) {
  auto monitor = LinkMonitor::open("vcan0");
  if (!monitor) GTEST_SKIP() << "no rtnetlink socket here";
  std::vector<unsigned char> buf;
  append_link(buf, RTM_NEWLINK, "vcan0", 0);
  buf.resize(NLMSG_HDRLEN + 4);  // cut inside the ifinfomsg
  reinterpret_cast<nlmsghdr*>(buf.data())->nlmsg_len = static_cast<std::uint32_t>(buf.size());
  EXPECT_EQ(feed(*monitor, buf), 0);
}

}  // namespace
}  // namespace resolver
