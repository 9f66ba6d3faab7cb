#include "drivers/socketcan/can_error_frame.h"

#include <linux/can.h>
#include <linux/can/error.h>

#include <cstdio>
#include <utility>
#include <vector>

namespace resolver {
namespace {

// Byte positions in an error frame's payload (linux/can/error.h).
constexpr std::size_t kLostArbByte = 0;
constexpr std::size_t kControllerByte = 1;
constexpr std::size_t kProtocolTypeByte = 2;
constexpr std::size_t kProtocolLocationByte = 3;
constexpr std::size_t kTransceiverByte = 4;
constexpr std::size_t kTxCounterByte = 6;
constexpr std::size_t kRxCounterByte = 7;

// Class bits not covered by CanErrorClass but understood here.
constexpr std::uint32_t kKnownInfoBits = CAN_ERR_CNT;

struct FlagName {
  std::uint8_t bit;
  const char* name;
};

constexpr std::array<FlagName, 7> kControllerFlags{{
    {CAN_ERR_CRTL_RX_OVERFLOW, "rx overflow"},
    {CAN_ERR_CRTL_TX_OVERFLOW, "tx overflow"},
    {CAN_ERR_CRTL_RX_WARNING, "rx error warning"},
    {CAN_ERR_CRTL_TX_WARNING, "tx error warning"},
    {CAN_ERR_CRTL_RX_PASSIVE, "rx error passive"},
    {CAN_ERR_CRTL_TX_PASSIVE, "tx error passive"},
    {CAN_ERR_CRTL_ACTIVE, "back to error active"},
}};

constexpr std::array<FlagName, 8> kProtocolFlags{{
    {CAN_ERR_PROT_BIT, "single bit error"},
    {CAN_ERR_PROT_FORM, "frame format error"},
    {CAN_ERR_PROT_STUFF, "bit stuffing error"},
    {CAN_ERR_PROT_BIT0, "unable to send dominant bit"},
    {CAN_ERR_PROT_BIT1, "unable to send recessive bit"},
    {CAN_ERR_PROT_OVERLOAD, "bus overload"},
    {CAN_ERR_PROT_ACTIVE, "active error announcement"},
    {CAN_ERR_PROT_TX, "on transmission"},
}};

constexpr std::array<FlagName, 19> kProtocolLocations{{
    {CAN_ERR_PROT_LOC_SOF, "start of frame"},
    {CAN_ERR_PROT_LOC_ID28_21, "ID bits 28-21"},
    {CAN_ERR_PROT_LOC_ID20_18, "ID bits 20-18"},
    {CAN_ERR_PROT_LOC_SRTR, "substitute RTR"},
    {CAN_ERR_PROT_LOC_IDE, "identifier extension"},
    {CAN_ERR_PROT_LOC_ID17_13, "ID bits 17-13"},
    {CAN_ERR_PROT_LOC_ID12_05, "ID bits 12-5"},
    {CAN_ERR_PROT_LOC_ID04_00, "ID bits 4-0"},
    {CAN_ERR_PROT_LOC_RTR, "RTR bit"},
    {CAN_ERR_PROT_LOC_RES1, "reserved bit 1"},
    {CAN_ERR_PROT_LOC_RES0, "reserved bit 0"},
    {CAN_ERR_PROT_LOC_DLC, "data length code"},
    {CAN_ERR_PROT_LOC_DATA, "data field"},
    {CAN_ERR_PROT_LOC_CRC_SEQ, "CRC sequence"},
    {CAN_ERR_PROT_LOC_CRC_DEL, "CRC delimiter"},
    {CAN_ERR_PROT_LOC_ACK, "ACK slot"},
    {CAN_ERR_PROT_LOC_ACK_DEL, "ACK delimiter"},
    {CAN_ERR_PROT_LOC_EOF, "end of frame"},
    {CAN_ERR_PROT_LOC_INTERM, "intermission"},
}};

// Transceiver status: low nibble describes CANH, high nibble CANL.
constexpr std::array<FlagName, 4> kCanhStates{{
    {CAN_ERR_TRX_CANH_NO_WIRE, "CANH no wire"},
    {CAN_ERR_TRX_CANH_SHORT_TO_BAT, "CANH short to battery"},
    {CAN_ERR_TRX_CANH_SHORT_TO_VCC, "CANH short to VCC"},
    {CAN_ERR_TRX_CANH_SHORT_TO_GND, "CANH short to ground"},
}};
constexpr std::array<FlagName, 5> kCanlStates{{
    {CAN_ERR_TRX_CANL_NO_WIRE, "CANL no wire"},
    {CAN_ERR_TRX_CANL_SHORT_TO_BAT, "CANL short to battery"},
    {CAN_ERR_TRX_CANL_SHORT_TO_VCC, "CANL short to VCC"},
    {CAN_ERR_TRX_CANL_SHORT_TO_GND, "CANL short to ground"},
    {CAN_ERR_TRX_CANL_SHORT_TO_CANH, "CANL short to CANH"},
}};

std::string hex(std::uint32_t value) {
  std::array<char, 16> text{};
  std::snprintf(text.data(), text.size(), "0x%X", value);
  return text.data();
}

template <std::size_t N>
std::string flag_list(std::uint8_t bits, const std::array<FlagName, N>& names) {
  std::string out;
  std::uint8_t unknown = bits;
  for (const auto& [bit, name] : names) {
    if ((bits & bit) == 0) continue;
    if (!out.empty()) out += ", ";
    out += name;
    unknown = static_cast<std::uint8_t>(unknown & ~bit);
  }
  if (unknown != 0) out += (out.empty() ? "" : ", ") + std::string("unknown flags ") + hex(unknown);
  return out.empty() ? "unspecified" : out;
}

template <std::size_t N>
const char* value_name(std::uint8_t value, const std::array<FlagName, N>& names) {
  for (const auto& [code, name] : names) {
    if (code == value) return name;
  }
  return nullptr;
}

std::string describe_transceiver(std::uint8_t status) {
  if (status == CAN_ERR_TRX_UNSPEC) return "transceiver problem: unspecified";
  std::string out = "transceiver problem: ";
  const auto canh = static_cast<std::uint8_t>(status & 0x0FU);
  const auto canl = static_cast<std::uint8_t>(status & 0xF0U);
  std::vector<std::string> parts;
  if (canh != 0) {
    const char* name = value_name(canh, kCanhStates);
    parts.emplace_back(name != nullptr ? name : "CANH status " + hex(canh));
  }
  if (canl != 0) {
    const char* name = value_name(canl, kCanlStates);
    parts.emplace_back(name != nullptr ? name : "CANL status " + hex(canl));
  }
  for (std::size_t i = 0; i < parts.size(); ++i) out += (i == 0 ? "" : ", ") + parts[i];
  return out;
}

std::string describe_protocol(const CanFrame& frame) {
  std::string out = "protocol violation: " + flag_list(frame.data[kProtocolTypeByte], kProtocolFlags);
  const std::uint8_t location = frame.data[kProtocolLocationByte];
  if (location != CAN_ERR_PROT_LOC_UNSPEC) {
    const char* name = value_name(location, kProtocolLocations);
    out += ", at ";
    out += name != nullptr ? std::string(name) : "location " + hex(location);
  }
  return out;
}

}  // namespace

std::string_view error_class_name(CanErrorClass error_class) {
  switch (error_class) {
    case CanErrorClass::kTxTimeout: return "tx_timeout";
    case CanErrorClass::kLostArbitration: return "lost_arbitration";
    case CanErrorClass::kController: return "controller";
    case CanErrorClass::kProtocol: return "protocol";
    case CanErrorClass::kTransceiver: return "transceiver";
    case CanErrorClass::kAck: return "ack";
    case CanErrorClass::kBusOff: return "bus_off";
    case CanErrorClass::kBusError: return "bus_error";
    case CanErrorClass::kRestarted: return "restarted";
  }
  return "unknown";
}

std::uint32_t error_class_mask(CanErrorClass error_class) {
  switch (error_class) {
    case CanErrorClass::kTxTimeout: return CAN_ERR_TX_TIMEOUT;
    case CanErrorClass::kLostArbitration: return CAN_ERR_LOSTARB;
    case CanErrorClass::kController: return CAN_ERR_CRTL;
    case CanErrorClass::kProtocol: return CAN_ERR_PROT;
    case CanErrorClass::kTransceiver: return CAN_ERR_TRX;
    case CanErrorClass::kAck: return CAN_ERR_ACK;
    case CanErrorClass::kBusOff: return CAN_ERR_BUSOFF;
    case CanErrorClass::kBusError: return CAN_ERR_BUSERROR;
    case CanErrorClass::kRestarted: return CAN_ERR_RESTARTED;
  }
  return 0;
}

CanErrorClassSet error_classes(const CanFrame& frame) {
  CanErrorClassSet set;
  if (!frame.error) return set;
  for (const CanErrorClass c : kAllCanErrorClasses) {
    if ((frame.id & error_class_mask(c)) != 0U) set.set(static_cast<std::size_t>(c));
  }
  return set;
}

std::optional<CanErrorCounters> error_counters(const CanFrame& frame) {
  if (!frame.error || (frame.id & CAN_ERR_CNT) == 0U) return std::nullopt;
  return CanErrorCounters{frame.data[kTxCounterByte], frame.data[kRxCounterByte]};
}

std::string describe_error_frame(const CanFrame& frame) {
  if (!frame.error) return "not an error frame";
  std::vector<std::string> parts;
  const CanErrorClassSet set = error_classes(frame);
  std::uint32_t known = kKnownInfoBits;
  for (const CanErrorClass c : kAllCanErrorClasses) {
    known |= error_class_mask(c);
    if (!has_error_class(set, c)) continue;
    switch (c) {
      case CanErrorClass::kTxTimeout: parts.emplace_back("tx timeout"); break;
      case CanErrorClass::kLostArbitration: {
        const std::uint8_t bit = frame.data[kLostArbByte];
        parts.emplace_back(bit == CAN_ERR_LOSTARB_UNSPEC
                               ? std::string("lost arbitration (bit unspecified)")
                               : "lost arbitration at bit " + std::to_string(bit));
        break;
      }
      case CanErrorClass::kController:
        parts.emplace_back("controller problem: " +
                           flag_list(frame.data[kControllerByte], kControllerFlags));
        break;
      case CanErrorClass::kProtocol: parts.emplace_back(describe_protocol(frame)); break;
      case CanErrorClass::kTransceiver:
        parts.emplace_back(describe_transceiver(frame.data[kTransceiverByte]));
        break;
      case CanErrorClass::kAck: parts.emplace_back("ack error (no node acknowledged)"); break;
      case CanErrorClass::kBusOff: parts.emplace_back("bus-off"); break;
      case CanErrorClass::kBusError: parts.emplace_back("bus error"); break;
      case CanErrorClass::kRestarted: parts.emplace_back("restarted"); break;
    }
  }
  if (const auto counters = error_counters(frame)) {
    parts.emplace_back("error counters tx=" + std::to_string(counters->tx) +
                       " rx=" + std::to_string(counters->rx));
  }
  if (const std::uint32_t unknown = frame.id & ~known; unknown != 0U) {
    parts.emplace_back("unknown error class bits " + hex(unknown));
  }
  if (parts.empty()) return "error frame with no class bits";
  std::string out;
  for (std::size_t i = 0; i < parts.size(); ++i) out += (i == 0 ? "" : "; ") + parts[i];
  return out;
}

}  // namespace resolver
