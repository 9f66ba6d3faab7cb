#include "drivers/socketcan/can_cmsg.h"

#include <sys/time.h>
#include <time.h>
// After <time.h>: errqueue.h uses struct timespec without including it.
#include <linux/errqueue.h>
#include <linux/time_types.h>

#include <cstring>
#include <ctime>

namespace resolver {
namespace {

constexpr std::int64_t kNsPerSecond = 1'000'000'000;
constexpr std::int64_t kNsPerUs = 1'000;

template <typename T>
bool copy_payload(const cmsghdr& cmsg, T& out) {
  // CMSG_DATA is not guaranteed to be aligned for T: copy, do not cast.
  if (cmsg.cmsg_len < CMSG_LEN(sizeof(T))) return false;
  std::memcpy(&out, CMSG_DATA(&cmsg), sizeof(T));
  return true;
}

/// [ns] since the epoch.
std::int64_t from_seconds_nanos(std::int64_t sec, std::int64_t nsec) { return sec * kNsPerSecond + nsec; }
std::int64_t from_seconds_micros(std::int64_t sec, std::int64_t usec) {
  return sec * kNsPerSecond + usec * kNsPerUs;
}

void offer(ReceiveMetadata& meta, TimestampKind kind, std::int64_t ns) {
  if (static_cast<int>(kind) > static_cast<int>(meta.timestamp_kind)) {
    meta.timestamp_kind = kind;
    meta.timestamp_ns = ns;
    meta.timestamp_us = ns / kNsPerUs;
  }
}

template <typename Timestamping>
void offer_timestamping(ReceiveMetadata& meta, const Timestamping& stamps) {
  // ts[2] is the raw hardware stamp, ts[0] the software one; a zero entry
  // means "not provided" (Documentation/networking/timestamping.rst).
  const auto& hw = stamps.ts[2];
  const auto& sw = stamps.ts[0];
  if (hw.tv_sec != 0 || hw.tv_nsec != 0) {
    offer(meta, TimestampKind::kHardware, from_seconds_nanos(hw.tv_sec, hw.tv_nsec));
  } else if (sw.tv_sec != 0 || sw.tv_nsec != 0) {
    offer(meta, TimestampKind::kSoftwareNano, from_seconds_nanos(sw.tv_sec, sw.tv_nsec));
  }
}

void parse_one(const cmsghdr& cmsg, ReceiveMetadata& meta) {
  if (cmsg.cmsg_level != SOL_SOCKET) return;
  switch (cmsg.cmsg_type) {
    case SO_TIMESTAMPNS_OLD: {
      timespec ts{};
      if (copy_payload(cmsg, ts)) offer(meta, TimestampKind::kSoftwareNano, from_seconds_nanos(ts.tv_sec, ts.tv_nsec));
      break;
    }
    case SO_TIMESTAMP_OLD: {
      timeval tv{};
      if (copy_payload(cmsg, tv)) offer(meta, TimestampKind::kSoftwareMicro, from_seconds_micros(tv.tv_sec, tv.tv_usec));
      break;
    }
    case SO_TIMESTAMPING_OLD: {
      scm_timestamping stamps{};
      if (copy_payload(cmsg, stamps)) offer_timestamping(meta, stamps);
      break;
    }
#if defined(SO_TIMESTAMPNS_NEW) && SO_TIMESTAMPNS_NEW != SO_TIMESTAMPNS_OLD
    case SO_TIMESTAMPNS_NEW: {
      __kernel_timespec ts{};
      if (copy_payload(cmsg, ts)) offer(meta, TimestampKind::kSoftwareNano, from_seconds_nanos(ts.tv_sec, ts.tv_nsec));
      break;
    }
    case SO_TIMESTAMP_NEW: {
      __kernel_sock_timeval tv{};
      if (copy_payload(cmsg, tv)) offer(meta, TimestampKind::kSoftwareMicro, from_seconds_micros(tv.tv_sec, tv.tv_usec));
      break;
    }
    case SO_TIMESTAMPING_NEW: {
      scm_timestamping64 stamps{};
      if (copy_payload(cmsg, stamps)) offer_timestamping(meta, stamps);
      break;
    }
#endif
    case SO_RXQ_OVFL: {
      std::uint32_t drops = 0;
      if (copy_payload(cmsg, drops)) meta.drop_counter = drops;
      break;
    }
    default:
      break;
  }
}

}  // namespace

ReceiveMetadata parse_receive_cmsgs(const msghdr& msg) {
  ReceiveMetadata meta;
  // CMSG_FIRSTHDR/CMSG_NXTHDR take a non-const msghdr but only read it.
  auto& mutable_msg = const_cast<msghdr&>(msg);
  for (cmsghdr* cmsg = CMSG_FIRSTHDR(&mutable_msg); cmsg != nullptr;
       cmsg = CMSG_NXTHDR(&mutable_msg, cmsg)) {
    parse_one(*cmsg, meta);
  }
  return meta;
}

}  // namespace resolver
