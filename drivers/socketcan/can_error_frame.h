// Error frames: what the CAN controller reports, in words and as counters.
//
// With CAN_RAW_ERR_FILTER set, the kernel delivers bus and controller problems
// as frames with the ERR flag; CanFrame::error is true and CanFrame::id holds
// the class bits (linux/can/error.h). The 8 data bytes give details:
//   data[0] bit position of lost arbitration      (class LOSTARB)
//   data[1] controller status flags               (class CRTL)
//   data[2] protocol violation type, data[3] where (class PROT)
//   data[4] transceiver status                    (class TRX)
//   data[6] tx error counter, data[7] rx error counter (class CNT, else driver-specific)
// Pure functions; no I/O.
#pragma once

#include <array>
#include <bitset>
#include <cstddef>
#include <cstdint>
#include <optional>
#include <string>
#include <string_view>

#include "drivers/can_frame.h"

namespace resolver {

/// One error class each; the order is the bit order in linux/can/error.h.
enum class CanErrorClass : std::uint8_t {
  kTxTimeout,        ///< CAN_ERR_TX_TIMEOUT: the driver's tx timed out
  kLostArbitration,  ///< CAN_ERR_LOSTARB
  kController,       ///< CAN_ERR_CRTL: overflow, error warning/passive, back to active
  kProtocol,         ///< CAN_ERR_PROT: bit/form/stuff errors ...
  kTransceiver,      ///< CAN_ERR_TRX: wiring faults the transceiver detected
  kAck,              ///< CAN_ERR_ACK: nobody acknowledged our frame
  kBusOff,           ///< CAN_ERR_BUSOFF
  kBusError,         ///< CAN_ERR_BUSERROR (may flood)
  kRestarted,        ///< CAN_ERR_RESTARTED: controller restarted after bus-off
};
inline constexpr std::size_t kCanErrorClassCount = 9;
inline constexpr std::array<CanErrorClass, kCanErrorClassCount> kAllCanErrorClasses{
    CanErrorClass::kTxTimeout, CanErrorClass::kLostArbitration, CanErrorClass::kController,
    CanErrorClass::kProtocol,  CanErrorClass::kTransceiver,     CanErrorClass::kAck,
    CanErrorClass::kBusOff,    CanErrorClass::kBusError,        CanErrorClass::kRestarted};

/// Set of classes, indexed by static_cast<std::size_t>(CanErrorClass).
using CanErrorClassSet = std::bitset<kCanErrorClassCount>;

/// Counter name for health reports: "tx_timeout", "lost_arbitration",
/// "controller", "protocol", "transceiver", "ack", "bus_off", "bus_error", "restarted".
[[nodiscard]] std::string_view error_class_name(CanErrorClass error_class);
/// The CAN_ERR_* bit of the class.
[[nodiscard]] std::uint32_t error_class_mask(CanErrorClass error_class);
/// Classes present in an error frame; empty for a frame that is not an error frame.
[[nodiscard]] CanErrorClassSet error_classes(const CanFrame& frame);
[[nodiscard]] inline bool has_error_class(const CanErrorClassSet& set, CanErrorClass c) {
  return set.test(static_cast<std::size_t>(c));
}

/// Transmit / receive error counters (ISO 11898-1 TEC/REC): warning at 96,
/// error passive at 128, bus-off when TEC reaches 256.
struct CanErrorCounters {
  std::uint8_t tx = 0;
  std::uint8_t rx = 0;
};
/// The counters when the frame says they are valid (CAN_ERR_CNT), else empty.
[[nodiscard]] std::optional<CanErrorCounters> error_counters(const CanFrame& frame);

/// One line for a log, classes joined by "; ", e.g.
/// "controller problem: rx error passive; error counters tx=3 rx=130"
/// or "protocol violation: bit stuffing error, on transmission, at data field".
/// Non-error frames give "not an error frame".
[[nodiscard]] std::string describe_error_frame(const CanFrame& frame);

}  // namespace resolver
