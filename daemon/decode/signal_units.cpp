#include "daemon/decode/signal_units.h"

#include <array>
#include <cctype>
#include <cstdio>

#include "daemon/core/angles.h"

namespace resolver {

namespace {

std::string_view trim(std::string_view s) {
  while (!s.empty() && (s.front() == ' ' || s.front() == '\t')) s.remove_prefix(1);
  while (!s.empty() && (s.back() == ' ' || s.back() == '\t')) s.remove_suffix(1);
  return s;
}

bool equals_ignoring_case(std::string_view a, std::string_view b) {
  if (a.size() != b.size()) return false;
  for (std::size_t i = 0; i < a.size(); ++i) {
    if (std::tolower(static_cast<unsigned char>(a[i])) != std::tolower(static_cast<unsigned char>(b[i]))) return false;
  }
  return true;
}

bool any_of(std::string_view unit, std::initializer_list<std::string_view> names) {
  for (const std::string_view n : names) {
    if (equals_ignoring_case(unit, n)) return true;
  }
  return false;
}

}  // namespace

std::optional<double> angle_unit_to_rad(std::string_view unit) {
  unit = trim(unit);
  if (any_of(unit, {"rad", "radian", "radians"})) return 1.0;
  // "\xB0": the degree sign in Latin-1 / Windows-1252, the usual DBC encoding.
  if (any_of(unit, {"deg", "degree", "degrees", "\xC2\xB0", "\xB0"})) return kPi / 180.0;
  if (any_of(unit, {"rev", "revs", "revolution", "revolutions", "turn", "turns"})) return kTwoPi;
  return std::nullopt;
}

std::optional<double> current_unit_to_amps(std::string_view unit) {
  unit = trim(unit);
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
