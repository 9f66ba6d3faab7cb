// Which DBC signals carry which physical quantity ("roles"), so a user's own
// inverter layout needs a DBC file and a few config lines, not a recompile.
//
// Units per role are fixed (the DBC's factor/offset must produce them):
//   sin, cos      any consistent unit (ADC counts in the default layout)
//   rd_angle      [rad] resolver electrical angle
//   i_a, i_b, i_c [A]
//   ref_angle     [rad] mechanical reference angle
// Every message that carries a role must also carry the sample counter signal
// (frames of one control period share it); the CRC signal is optional.
#pragma once

#include <array>
#include <cstdint>
#include <optional>
#include <string>
#include <string_view>

namespace resolver {

enum class Role : std::uint8_t { kSin, kCos, kRdAngle, kIA, kIB, kIC, kRefAngle };
inline constexpr std::size_t kRoleCount = 7;

/// Config-file name of each role ("sin", "rd_angle", ...).
[[nodiscard]] std::string_view role_name(Role role);
[[nodiscard]] std::optional<Role> role_from_name(std::string_view name);
[[nodiscard]] constexpr std::uint16_t role_bit(Role role) {
  return static_cast<std::uint16_t>(1U << static_cast<unsigned>(role));
}

enum class CrcAlgorithm : std::uint8_t {
  kNone,
  /// CRC-8 SAE J1850 over bytes 0..6 then the low byte of the CAN ID (docs/ARCHITECTURE.md §4).
  kBenchJ1850,
};

struct SignalRef {
  std::string message;  ///< DBC message name
  std::string signal;   ///< DBC signal name
};

struct SignalMap {
  std::array<std::optional<SignalRef>, kRoleCount> roles;
  /// Name of the counter signal in every mapped message.
  std::string counter_signal = "counter";
  /// Name of the CRC signal in every mapped message ("" = none).
  std::string crc_signal = "crc";
  CrcAlgorithm crc = CrcAlgorithm::kBenchJ1850;
  /// Message carrying p_r, p, rd_bits, sample_rate_hz, layout_version ("" = none).
  std::string bench_info_message = "BENCH_INFO";

  /// The default bench layout of docs/ARCHITECTURE.md §4 / proto/resolver_bench.dbc.
  static SignalMap bench_default();
};

}  // namespace resolver
