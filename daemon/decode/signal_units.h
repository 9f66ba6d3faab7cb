// Units of the physical roles, as a DBC signal (or a CSV column map) states them.
//
// Inside, angles are radians wrapped to [0, 2pi) and currents amperes (see
// signal_map.h); the unit a layout states converts to those at the edge:
//   angle roles (rd_angle, ref_angle)  "rad" (radian), "deg" (degree, the degree
//                                      sign in UTF-8 or the Latin-1 byte 0xB0 that
//                                      DBC files written on Windows carry),
//                                      "rev" (turn, revolution)
//   currents (i_a, i_b, i_c)           "A", "mA"
// An angle or current unit outside these is an error naming the signal: a
// layout in degrees read as radians is silently wrong by a factor of 57.
// Letters are matched case-insensitively except A/mA (mA is not MA).
#pragma once

#include <optional>
#include <string>
#include <string_view>

namespace resolver {

/// The accepted angle units, for messages.
inline constexpr std::string_view kAngleUnitList = "rad, deg (degree, \xC2\xB0), rev (turn)";
/// The accepted current units, for messages.
inline constexpr std::string_view kCurrentUnitList = "A, mA";

/// [rad per unit] of an angle unit; nullopt when the unit is empty or unknown.
[[nodiscard]] std::optional<double> angle_unit_to_rad(std::string_view unit);
/// [A per unit] of a current unit; nullopt when the unit is empty or unknown.
[[nodiscard]] std::optional<double> current_unit_to_amps(std::string_view unit);

/// The unit as text a terminal shows: printable ASCII and UTF-8 as they are,
/// other bytes as \xNN (a Latin-1 degree sign prints as \xB0), quoted.
[[nodiscard]] std::string quote_unit(std::string_view unit);

}  // namespace resolver
