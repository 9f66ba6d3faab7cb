// CAN frame -> typed part of a bench sample, through a DBC and a SignalMap.
//
// Each DBC message that carries at least one role is a "slot". Decoding a
// frame checks, in order: error/remote frames, known ID, length against the
// DBC's DLC, CRC; then extracts the counter (when the layout has one) and
// every role the slot carries, converted from the signal's DBC unit to the
// role's unit (signal_units.h: angles to radians in [0, 2pi), currents to A).
// A frame that fails a check is rejected with a reason and never touches a
// sample.
//
// Multiplexed messages (one `M` switch, `m<value>` signals): a signal the
// decoder reads is taken only from frames whose switch selects its page.
// Elsewhere the role is absent from that frame (DecodedPart::roles_absent,
// counted by the intake as mux_role_absent), never decoded from another page's
// bits; a frame whose page carries none of what the decoder reads from the
// message (or not its counter) is rejected as mux_page_unmapped. Extended
// multiplexing (m<n>M, SG_MUL_VAL_) of a signal the decoder reads is refused
// when the decoder is built.
#pragma once

#include <array>
#include <cstdint>
#include <functional>
#include <memory>
#include <string>
#include <unordered_map>
#include <vector>

#include "daemon/core/errors.h"
#include "daemon/dbc/dbc_types.h"
#include "daemon/decode/signal_map.h"
#include "drivers/can_frame.h"

namespace resolver {

/// Stable reasons for rejecting a frame; their names are health_t counter names.
enum class FrameReject : std::uint8_t {
  kUnknownId,       ///< no DBC message with that ID is mapped
  kWrongDlc,        ///< length differs from the DBC's DLC
  kCrc,             ///< CRC mismatch
  kRemoteFrame,     ///< RTR frame with a mapped ID
  kBenchInfoVersion, ///< BENCH_INFO with an unsupported layout version
  kMuxPageUnmapped   ///< the multiplexor selects a page without any role (or without the counter) the slot reads
};
[[nodiscard]] std::string_view to_string(FrameReject reject);

/// One decoded frame that belongs to a sample.
struct DecodedPart {
  int slot = 0;                       ///< index into FrameDecoder::slots()
  bool has_counter = false;           ///< the layout has a counter signal
  std::uint8_t counter = 0;
  std::uint16_t roles = 0;            ///< role_bit() mask of what `values` holds
  std::uint16_t roles_absent = 0;     ///< roles of this slot that the frame's multiplexor page does not carry
  std::uint64_t mux_value = 0;        ///< raw multiplexor value (slots with multiplexed signals only)
  std::array<double, kRoleCount> values{};
  std::int64_t timestamp_us = 0;
};

struct BenchInfo {
  int layout_version = 0;
  int p_r = 0;                 ///< resolver pole pairs
  int p = 0;                   ///< motor pole pairs
  int rd_bits = 0;             ///< R/D converter resolution [bits]
  double sample_rate_hz = 0.0; ///< control/sample rate [Hz]
};

enum class DecodeStatus : std::uint8_t { kPart, kBenchInfo, kRejected };

struct DecodeResult {
  DecodeStatus status = DecodeStatus::kRejected;
  FrameReject reject = FrameReject::kUnknownId;
  std::uint64_t mux_value = 0;  ///< for kMuxPageUnmapped: the multiplexor's raw value
};

class FrameDecoder {
 public:
  struct RoleSignal {
    Role role = Role::kSin;
    const dbc::Signal* signal = nullptr;
    double to_role_unit = 1.0;  ///< DBC physical value * this = the role's unit (rad, A)
    bool wrap = false;          ///< an angle: wrapped to [0, 2pi)
  };
  struct Slot {
    const dbc::Message* message = nullptr;
    const dbc::Signal* counter = nullptr;  ///< nullptr when the layout has no counter
    const dbc::Signal* crc = nullptr;
    /// The message's multiplexor when a signal the slot reads is multiplexed, else nullptr.
    const dbc::Signal* mux = nullptr;
    std::vector<RoleSignal> roles;
  };

  /// Builds the decoder. When `map` does not fit the DBC, throws InputError
  /// (Fault::kUsage: the config's map; `map_at` is the config file, option
  /// "[layout]") "signal map does not fit the DBC <db's source>:" listing every
  /// problem (unknown message or signal names, missing counter, a signal it reads
  /// overlapping another signal of its message, an angle or current signal whose
  /// unit is missing or unknown, a signal it reads under extended multiplexing).
  FrameDecoder(std::shared_ptr<const dbc::Database> db, const SignalMap& map, const Where& map_at = {});

  /// Decodes one frame. Cannot fail beyond returning kRejected with a reason.
  DecodeResult decode(const CanFrame& frame, DecodedPart& part, BenchInfo& info) const;

  [[nodiscard]] const std::vector<Slot>& slots() const { return slots_; }
  /// The slot a frame's ID maps to, nullptr when none.
  [[nodiscard]] const Slot* slot_for(const CanFrame& frame) const {
    const auto it = slot_by_id_.find(key(frame.id, frame.extended));
    return it == slot_by_id_.end() ? nullptr : &slots_[static_cast<std::size_t>(it->second)];
  }
  [[nodiscard]] std::uint16_t mapped_roles() const { return mapped_roles_; }
  /// Non-fatal findings: overlapping signals in a mapped message that the decoder
  /// does not read (a DBC may describe the same bytes twice; decoding is unaffected).
  [[nodiscard]] const std::vector<std::string>& warnings() const { return warnings_; }
  /// False for a layout without a counter ([layout] counter_signal = ""): frames
  /// then join by message order and time (leading_frame_joiner.h).
  [[nodiscard]] bool has_counter() const { return !map_.counter_signal.empty(); }
  /// The DBC the decoder reads (its warnings are the caller's to print).
  [[nodiscard]] const dbc::Database& database() const { return *db_; }
  /// What messages say about the layout in use, e.g.
  /// "RESOLVER_FB 0x123 (sin = SinEnv, cos = CosEnv), CURRENTS 0x124 (i_a = Ia, ...)".
  [[nodiscard]] std::string describe_layout() const;

 private:
  /// Overlaps in a slot's message: an error when a signal the decoder reads is
  /// involved (reported through `problem`), else a warning.
  void check_overlaps(const Slot& slot, const std::function<void(const std::string&)>& problem);
  /// Sets slot.mux; a signal read under extended multiplexing is a problem.
  void check_multiplexing(Slot& slot, const std::function<void(const std::string&)>& problem) const;
  static std::uint32_t key(std::uint32_t id, bool extended) { return extended ? (id | 0x80000000U) : id; }

  std::shared_ptr<const dbc::Database> db_;
  SignalMap map_;
  std::vector<Slot> slots_;
  std::unordered_map<std::uint32_t, int> slot_by_id_;  ///< key(id) -> slot
  const dbc::Message* bench_info_ = nullptr;
  std::uint16_t mapped_roles_ = 0;
  std::vector<std::string> warnings_;
};

}  // namespace resolver
