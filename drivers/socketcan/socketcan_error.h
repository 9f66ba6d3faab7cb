// The one exception type the SocketCAN driver throws for system-call failures.
//
// what() reads "<operation> on <iface>: <strerror> (errno N); <hint>", where the
// hint says what to do for the errnos a bench engineer actually meets
// (no CAN in the kernel, missing interface, interface down, full tx queue).
// A std::system_error (code() is the errno): every program exits 3, an I/O
// error, for it (daemon/service/program_errors.h).
#pragma once

#include <string>
#include <system_error>

namespace resolver {

class SocketCanError : public std::system_error {
 public:
  /// `operation` names the call that failed ("bind", "setsockopt(CAN_RAW_FILTER)"),
  /// `iface` the interface, `err` the errno; the hint is chosen from `err`.
  SocketCanError(std::string operation, std::string iface, int err);
  /// Same, with an explicit hint (used when the errno alone says too little).
  SocketCanError(std::string operation, std::string iface, int err, std::string hint);

  /// "<operation> on <iface>: <strerror> (errno N); <hint>"
  [[nodiscard]] const char* what() const noexcept override { return message_.c_str(); }
  [[nodiscard]] int error_code() const { return err_; }
  [[nodiscard]] const std::string& operation() const { return operation_; }
  [[nodiscard]] const std::string& iface() const { return iface_; }

 private:
  std::string message_;
  std::string operation_;
  std::string iface_;
  int err_;
};

/// The advice printed after the errno text; empty when there is none.
/// `operation` and `iface` make hints concrete ("ip link set can0 up").
[[nodiscard]] std::string socketcan_error_hint(int err, const std::string& operation,
                                               const std::string& iface);

}  // namespace resolver
