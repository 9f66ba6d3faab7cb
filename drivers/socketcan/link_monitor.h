// LinkMonitor: counts an interface's link-down transitions from rtnetlink
// link events (RTMGRP_LINK), independent of any CAN socket's receive queue.
//
// Why: a CAN_RAW socket reports ENETDOWN only once its queue is empty (the
// kernel checks sk_err when there is nothing to read). A reader that is
// behind at a saturated bus may not empty its queue for seconds, and two link
// flaps in that time set the same pending error twice: one ENETDOWN for two
// outages. The link events arrive on their own socket, one per change.
//
// Threading: one thread calls poll_downs().
#pragma once

#include <cstddef>
#include <optional>
#include <string>
#include <utility>

#include "drivers/socketcan/unique_fd.h"

namespace resolver {

class LinkMonitor {
 public:
  /// Subscribes to link events for `iface`; nullopt where rtnetlink cannot be
  /// opened (the caller then counts the sockets' ENETDOWN instead).
  static std::optional<LinkMonitor> open(std::string iface);

  /// Reads every queued link event without waiting; returns how many times
  /// the interface went from up to down since the last call.
  int poll_downs();
  /// The last state an event reported (up until an event says otherwise).
  [[nodiscard]] bool down() const { return down_; }
  /// Events lost to a full netlink queue (ENOBUFS): a flap may be uncounted.
  [[nodiscard]] int overruns() const { return overruns_; }

  /// Feeds one buffer of netlink messages (what recv() returned); returns the
  /// up -> down transitions of the watched interface in it. Public for tests.
  int feed(const unsigned char* data, std::size_t size);

 private:
  LinkMonitor(UniqueFd fd, std::string iface) : fd_(std::move(fd)), iface_(std::move(iface)) {}

  UniqueFd fd_;
  std::string iface_;
  bool down_ = false;
  int overruns_ = 0;
};

}  // namespace resolver
