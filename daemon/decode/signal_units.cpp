#include "daemon/decode/signal_units.h"

#include <array>
#include <cstdio>

#include "daemon/core/angles.h"
#include "drivers/text/text_util.h"

namespace resolver {

namespace {

bool any_of(std::string_view unit, std::initializer_list<std::string_view> names) {
  for (const std::string_view n : names) {
    if (text::iequals(unit, n)) return true;
  }
  return false;
}

}  // namespace

std::optional<double> angle_unit_to_rad(std::string_view unit) {
  unit = text::trim(unit);
  if (any_of(unit, {"rad", "radian", "radians"})) return 1.0;
  // "\xB0": the degree sign in Latin-1 / Windows-1252, the usual DBC encoding.
  if (any_of(unit, {"deg", "degree", "degrees", "\xC2\xB0", "\xB0"})) return kPi / 180.0;
  if (any_of(unit, {"rev", "revs", "revolution", "revolutions", "turn", "turns"})) return kTwoPi;
  return std::nullopt;
}

std::optional<double> current_unit_to_amps(std::string_view unit) {
  unit = text::trim(unit);
  if (unit == "A") return 1.0;
  if (unit == "mA") return 1e-3;
  return std::nullopt;
}

std::string quote_unit(std::string_view unit) {
  std::string out = "\"";
  for (std::size_t i = 0; i < unit.size(); ++i) {
    const auto c = static_cast<unsigned char>(unit[i]);
    // A UTF-8 two-byte sequence (e.g. C2 B0, the degree sign) stays as it is.
    const bool utf8_pair = c >= 0xC2 && c <= 0xDF && i + 1 < unit.size() &&
                           (static_cast<unsigned char>(unit[i + 1]) & 0xC0U) == 0x80U;
    if (utf8_pair) {
      out += unit.substr(i, 2);
      ++i;
    } else if (c >= 0x20 && c < 0x7F && c != '"') {
      out += static_cast<char>(c);
    } else {
      std::array<char, 8> hex{};
      std::snprintf(hex.data(), hex.size(), "\\x%02X", c);
      out += hex.data();
    }
  }
  return out + "\"";
}

}  // namespace resolver
