// SocketCAN frame source: one CAN_RAW socket bound to one interface.
//
// Data flow:  kernel CAN_RAW socket --recvmsg--> byte image + cmsgs
//             --decode_wire_frame / parse_receive_cmsgs--> CanFrame (+ stats)
//
// Threading: none inside. One thread calls read() in a loop; read() waits at
// most read_timeout so the caller can check signals and its watchdog between
// calls. Not thread-safe; give each thread its own source.
//
// Failure model: setup problems throw SocketCanError (what, where, what to do).
// While reading, conditions a bench meets in normal operation come back as a
// ReadStatus (timeout, EINTR, interface down, interface removed, malformed
// read); only unexpected errno values throw. After kDeviceGone the socket is
// unbound by the kernel: destroy the source and open() again once the
// interface is back. After kNetworkDown the same socket keeps working once
// the interface is up again.
#pragma once

#include <chrono>
#include <cstdint>
#include <optional>
#include <string>
#include <vector>

#include "drivers/can_frame.h"
#include "drivers/socketcan/can_filter.h"
#include "drivers/socketcan/socketcan_error.h"
#include "drivers/socketcan/unique_fd.h"

namespace resolver {

struct SocketCanOptions {
  std::string iface;                            ///< "can0", "vcan0"
  bool enable_fd = true;                        ///< CAN_RAW_FD_FRAMES: also receive CAN FD frames
  bool receive_error_frames = true;             ///< CAN_RAW_ERR_FILTER = CAN_ERR_MASK
  std::vector<CanIdFilter> filters;             ///< CAN_RAW_FILTER; empty = receive all
  /// CAN_RAW_JOIN_FILTERS: a frame must pass every filter, not just one
  /// (how "every ID but these" is said with inverted filters). Linux >= 4.1.
  bool join_filters = false;
  /// [ms] longest a read() waits, so the caller's loop can check signals/watchdog.
  /// Negative = wait forever.
  std::chrono::milliseconds read_timeout{100};
  int receive_buffer_bytes = 0;                 ///< [bytes] SO_RCVBUF(FORCE) if > 0
  /// Ask the adapter for hardware receive timestamps (SO_TIMESTAMPING); falls
  /// back to software stamps on adapters without them.
  bool hardware_timestamps = false;
};

enum class ReadStatus {
  kFrame,        ///< `frame` holds a new frame (data, remote, or error frame)
  kTimeout,      ///< nothing arrived within read_timeout
  kInterrupted,  ///< a signal interrupted the wait (EINTR); check flags, call again
  kNetworkDown,  ///< interface went down (ENETDOWN); socket stays usable
  kDeviceGone,   ///< interface removed (ENODEV/ENXIO) or peer closed; reopen
  kTruncated,    ///< the read was not a whole can_frame / canfd_frame; dropped
};

struct SocketCanStats {
  std::uint64_t frames = 0;        ///< every kFrame result (includes FD and error frames)
  std::uint64_t fd_frames = 0;     ///< of which CAN FD
  std::uint64_t error_frames = 0;  ///< of which error frames
  std::uint64_t kernel_drops = 0;  ///< frames the kernel dropped (socket queue full; SO_RXQ_OVFL)
  std::uint64_t truncated = 0;     ///< kTruncated results
  std::uint64_t timeouts = 0;      ///< kTimeout results
  std::uint64_t network_down = 0;  ///< kNetworkDown results
};

class SocketCanSource {
 public:
  /// Creates, configures and binds a CAN_RAW socket. Throws SocketCanError
  /// naming the failed step and the interface, e.g. on a kernel without CAN:
  /// "socket(PF_CAN, SOCK_RAW, CAN_RAW) on can0: ... ; kernel has no CAN support: ...".
  static SocketCanSource open(const SocketCanOptions& options);

  /// Takes ownership of an already-open datagram socket (tests, socket
  /// activation). Socket options are left as they are: enable SO_TIMESTAMPNS
  /// and SO_RXQ_OVFL on the fd beforehand to get kernel timestamps and drop
  /// counts. read() sets SO_RCVTIMEO on it, and O_NONBLOCK is cleared here so
  /// that read() can wait in recvmsg. Throws SocketCanError (EBADF) if fd < 0.
  static SocketCanSource adopt(int fd, std::string iface_name);

  SocketCanSource(SocketCanSource&&) noexcept = default;
  SocketCanSource& operator=(SocketCanSource&&) noexcept = default;
  SocketCanSource(const SocketCanSource&) = delete;
  SocketCanSource& operator=(const SocketCanSource&) = delete;
  ~SocketCanSource() = default;

  /// Reads one frame, waiting up to read_timeout: one recvmsg bounded by
  /// SO_RCVTIMEO (set on the socket, also on an adopted one); a zero timeout
  /// does not wait, a negative one waits until a frame, error or signal.
  /// On kFrame: timestamp_us comes from the kernel stamp (SO_TIMESTAMPING
  /// hardware, SO_TIMESTAMPNS, SO_TIMESTAMP; else CLOCK_REALTIME at read
  /// time), iface is this source's name, fd from the read size. The frame is
  /// untouched for every other status. Kernel drop counts (SO_RXQ_OVFL) are
  /// added to stats().kernel_drops. Throws SocketCanError for errno values
  /// not listed in ReadStatus.
  ReadStatus read(CanFrame& frame);

  /// Replaces the receive filters of a CAN_RAW socket while it is in use
  /// (frames already queued stay): `filters` as SocketCanOptions::filters,
  /// empty = every frame; `join` = CAN_RAW_JOIN_FILTERS. Throws SocketCanError.
  void set_filters(const std::vector<CanIdFilter>& filters, bool join = false);
  /// From now on the socket receives no frame, error frames included (what
  /// is queued can still be read). Throws SocketCanError.
  void receive_nothing();

  /// Sends one frame (tools and tests). Waits up to read_timeout while the
  /// transmit queue is full (ENOBUFS), then throws SocketCanError; throws
  /// std::invalid_argument for a frame that cannot be encoded (see can_wire.h).
  void write(const CanFrame& frame);

  [[nodiscard]] const SocketCanStats& stats() const { return stats_; }
  /// Brings stats().kernel_drops up to date without waiting for a frame to
  /// carry the count (SO_MEMINFO; a no-op where the kernel lacks it). Cheap
  /// enough for once a second; at the end of a run it counts the last drops.
  void refresh_kernel_drops();
  /// [ns] receive stamp of the frame the last kFrame read returned (its
  /// timestamp_us at full resolution).
  [[nodiscard]] std::int64_t last_stamp_ns() const { return last_stamp_ns_; }
  [[nodiscard]] int fd() const { return fd_.get(); }
  [[nodiscard]] const std::string& iface() const { return iface_; }
  [[nodiscard]] std::chrono::milliseconds read_timeout() const { return read_timeout_; }
  void set_read_timeout(std::chrono::milliseconds timeout) { read_timeout_ = timeout; }

 private:
  SocketCanSource(UniqueFd fd, std::string iface, std::chrono::milliseconds read_timeout);
  /// Sets SO_RCVTIMEO when read_timeout changed since the last read.
  void apply_receive_timeout();
  /// Adds the drops the cumulative kernel counter shows beyond the last one.
  void note_drop_counter(std::uint32_t counter);
  /// True when the socket reports POLLHUP (adopted stream/seqpacket fds).
  [[nodiscard]] bool peer_hung_up() const;

  UniqueFd fd_;
  std::string iface_;
  std::chrono::milliseconds read_timeout_;
  std::optional<std::chrono::milliseconds> applied_timeout_;  ///< SO_RCVTIMEO now on the socket
  SocketCanStats stats_;
  std::uint32_t last_drop_counter_ = 0;  ///< last SO_RXQ_OVFL value seen (cumulative)
  std::int64_t last_stamp_ns_ = 0;
};

}  // namespace resolver
