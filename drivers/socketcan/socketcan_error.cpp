#include "drivers/socketcan/socketcan_error.h"

#include <cerrno>
#include <system_error>
#include <utility>

namespace resolver {
namespace {

std::string format_message(const std::string& operation, const std::string& iface, int err,
                           const std::string& hint) {
  // std::system_category().message() is the thread-safe strerror().
  std::string text = operation + " on " + (iface.empty() ? std::string("<no interface>") : iface) +
                     ": " + std::system_category().message(err) + " (errno " +
                     std::to_string(err) + ")";
  if (!hint.empty()) text += "; " + hint;
  return text;
}

}  // namespace

std::string socketcan_error_hint(int err, const std::string& operation, const std::string& iface) {
  switch (err) {
    case EAFNOSUPPORT:
    case EPROTONOSUPPORT:
      return "kernel has no CAN support: modprobe can_raw (and modprobe vcan for a virtual bus)";
    case ENODEV:
    case ENXIO:
      return "no such interface: ip link add dev vcan0 type vcan / check the name with ip -br link";
    case ENETDOWN:
      return "interface is down: ip link set " + iface + " up";
    case ENOBUFS:
      return "transmit queue full: ip link set " + iface +
             " txqueuelen 1000, check the bus is connected and terminated, or slow the sender";
    case ENOPROTOOPT:
      return "kernel lacks this CAN_RAW option (CAN FD needs Linux >= 3.6): set enable_fd = false";
    case EINVAL:
      if (operation.rfind("write", 0) == 0) {
        return "the interface refused the frame: a CAN FD frame needs an FD-capable interface "
               "(ip link set " + iface + " mtu 72 for vcan) and enable_fd = true";
      }
      return {};
    case EPERM:
    case EACCES:
      return "permission denied: run with the capabilities the operation needs "
             "(CAP_NET_ADMIN for SO_RCVBUFFORCE)";
    case EBADF:
    case ENOTSOCK:
      return "the file descriptor is not an open socket: check the fd handed to adopt()";
    default:
      return {};
  }
}

SocketCanError::SocketCanError(std::string operation, std::string iface, int err)
    : SocketCanError(operation, iface, err, socketcan_error_hint(err, operation, iface)) {}

SocketCanError::SocketCanError(std::string operation, std::string iface, int err, std::string hint)
    : std::system_error(err, std::system_category()),
      message_(format_message(operation, iface, err, hint)),
      operation_(std::move(operation)),
      iface_(std::move(iface)),
      err_(err) {}

}  // namespace resolver
