// SocketCanSource::open(): create, configure and bind a CAN_RAW socket.
// Order follows Documentation/networking/can.rst: options first, bind last,
// so no frame is delivered before the filters are in place.
#include <linux/can.h>
#include <linux/can/raw.h>
#include <linux/net_tstamp.h>
#include <net/if.h>
#include <sys/socket.h>

#include <cerrno>
#include <stdexcept>
#include <string>
#include <utility>
#include <vector>

#include "drivers/socketcan/socketcan_source.h"

namespace resolver {
namespace {

void set_option(int fd, int level, int name, const void* value, socklen_t size,
                const char* option_name, const std::string& iface) {
  if (::setsockopt(fd, level, name, value, size) < 0) {
    throw SocketCanError(std::string("setsockopt(") + option_name + ")", iface, errno);
  }
}

void set_flag(int fd, int level, int name, const char* option_name, const std::string& iface) {
  const int on = 1;
  set_option(fd, level, name, &on, sizeof on, option_name, iface);
}

// Pure validation first, so configuration mistakes are reported even on a
// machine without CAN support.
void check_iface_name(const std::string& iface) {
  if (iface.empty() || iface.size() >= IFNAMSIZ) {
    throw SocketCanError("check interface name", iface, iface.empty() ? EINVAL : ENAMETOOLONG,
                         "interface names are 1 to 15 characters, e.g. can0 or vcan0");
  }
}

std::vector<can_filter> kernel_filters(const std::vector<CanIdFilter>& filters, const std::string& iface) {
  if (filters.size() > CAN_RAW_FILTER_MAX) {
    throw SocketCanError("setsockopt(CAN_RAW_FILTER)", iface, EINVAL,
                         "at most 512 filters per socket: merge IDs with masks");
  }
  std::vector<can_filter> out;
  out.reserve(filters.size());
  for (const CanIdFilter& filter : filters) {
    try {
      const KernelCanFilter k = to_kernel_filter(filter);
      out.push_back(can_filter{k.can_id, k.can_mask});
    } catch (const std::invalid_argument& e) {
      throw SocketCanError("setsockopt(CAN_RAW_FILTER)", iface, EINVAL, std::string("fix the filter: ") + e.what());
    }
  }
  return out;
}

/// CAN_RAW_FILTER (and CAN_RAW_JOIN_FILTERS when `join` and there is more
/// than one filter); an empty list leaves the socket's filter as it is.
void apply_filters(int fd, const std::vector<can_filter>& filters, bool join, const std::string& iface) {
  if (filters.empty()) return;
  set_option(fd, SOL_CAN_RAW, CAN_RAW_FILTER, filters.data(), static_cast<socklen_t>(filters.size() * sizeof(can_filter)),
             "CAN_RAW_FILTER", iface);
  if (join && filters.size() > 1) set_flag(fd, SOL_CAN_RAW, CAN_RAW_JOIN_FILTERS, "CAN_RAW_JOIN_FILTERS", iface);
}

}  // namespace

void SocketCanSource::set_filters(const std::vector<CanIdFilter>& filters, bool join) {
  std::vector<can_filter> kernel = kernel_filters(filters, iface_);
  if (kernel.empty()) kernel.push_back(can_filter{0, 0});  // every frame, as a new socket
  apply_filters(fd_.get(), kernel, join, iface_);
}

void SocketCanSource::receive_nothing() {
  // No filter at all: the socket matches no frame (can.rst, "RAW socket option CAN_RAW_FILTER").
  set_option(fd_.get(), SOL_CAN_RAW, CAN_RAW_FILTER, nullptr, 0, "CAN_RAW_FILTER", iface_);
  const can_err_mask_t none = 0;
  set_option(fd_.get(), SOL_CAN_RAW, CAN_RAW_ERR_FILTER, &none, sizeof none, "CAN_RAW_ERR_FILTER", iface_);
}

SocketCanSource SocketCanSource::open(const SocketCanOptions& options) {
  const std::string& iface = options.iface;
  check_iface_name(iface);
  const std::vector<can_filter> filters = kernel_filters(options.filters, iface);

  UniqueFd fd(::socket(PF_CAN, SOCK_RAW | SOCK_CLOEXEC, CAN_RAW));
  if (!fd.valid()) throw SocketCanError("socket(PF_CAN, SOCK_RAW, CAN_RAW)", iface, errno);

  const unsigned int index = ::if_nametoindex(iface.c_str());
  if (index == 0) throw SocketCanError("if_nametoindex", iface, errno);

  apply_filters(fd.get(), filters, options.join_filters, iface);
  const can_err_mask_t error_mask = options.receive_error_frames ? CAN_ERR_MASK : 0U;
  set_option(fd.get(), SOL_CAN_RAW, CAN_RAW_ERR_FILTER, &error_mask, sizeof error_mask,
             "CAN_RAW_ERR_FILTER", iface);
  if (options.enable_fd) set_flag(fd.get(), SOL_CAN_RAW, CAN_RAW_FD_FRAMES, "CAN_RAW_FD_FRAMES", iface);

  if (options.receive_buffer_bytes > 0) {
    // SO_RCVBUFFORCE may exceed net.core.rmem_max but needs CAP_NET_ADMIN;
    // without it, SO_RCVBUF still works, capped at rmem_max.
    const int bytes = options.receive_buffer_bytes;
    if (::setsockopt(fd.get(), SOL_SOCKET, SO_RCVBUFFORCE, &bytes, sizeof bytes) < 0) {
      set_option(fd.get(), SOL_SOCKET, SO_RCVBUF, &bytes, sizeof bytes, "SO_RCVBUF", iface);
    }
  }

  set_flag(fd.get(), SOL_SOCKET, SO_TIMESTAMPNS, "SO_TIMESTAMPNS", iface);
  if (options.hardware_timestamps) {
    const int flags = SOF_TIMESTAMPING_RX_HARDWARE | SOF_TIMESTAMPING_RAW_HARDWARE |
                      SOF_TIMESTAMPING_RX_SOFTWARE | SOF_TIMESTAMPING_SOFTWARE;
    set_option(fd.get(), SOL_SOCKET, SO_TIMESTAMPING, &flags, sizeof flags, "SO_TIMESTAMPING",
               iface);
  }
  set_flag(fd.get(), SOL_SOCKET, SO_RXQ_OVFL, "SO_RXQ_OVFL", iface);

  sockaddr_can address{};
  address.can_family = AF_CAN;
  address.can_ifindex = static_cast<int>(index);
  if (::bind(fd.get(), reinterpret_cast<const sockaddr*>(&address), sizeof address) < 0) {
    throw SocketCanError("bind", iface, errno);
  }
  return SocketCanSource(std::move(fd), iface, options.read_timeout);
}

}  // namespace resolver
