#include "drivers/csv/csv_number.h"

#include "drivers/text/text_util.h"

#include <charconv>
#include <cmath>
#include <limits>
#include <string>

namespace resolver {

namespace {

using text::is_digit;
using text::trim;

/// A number split into its parts: sign, up to 19 significant digits, and a
/// power of ten; nullopt when the text is not a plain decimal number.
struct Decimal {
  bool negative = false;
  std::uint64_t digits = 0;
  int exp10 = 0;
};

std::optional<Decimal> split_decimal(std::string_view s, char decimal) {
  s = trim(s);
  Decimal d;
  std::size_t i = 0;
  if (i < s.size() && (s[i] == '+' || s[i] == '-')) d.negative = s[i++] == '-';
  int significant = 0;
  bool any_digit = false;
  bool seen_mark = false;
  for (; i < s.size(); ++i) {
    const char c = s[i];
    if (is_digit(c)) {
      any_digit = true;
      if (significant < 19) {
        if (d.digits != 0 || c != '0') ++significant;
        d.digits = d.digits * 10 + static_cast<std::uint64_t>(c - '0');
        if (seen_mark) --d.exp10;
      } else if (!seen_mark) {
        ++d.exp10;  // digits beyond 19 significant ones before the mark only scale
      }
    } else if (c == decimal && !seen_mark) {
      seen_mark = true;
    } else {
      break;
    }
  }
  if (!any_digit) return std::nullopt;
  if (i < s.size()) {
    if (s[i] != 'e' && s[i] != 'E') return std::nullopt;
    int exp = 0;
    const auto [end, ec] = std::from_chars(s.data() + i + 1 + (i + 1 < s.size() && s[i + 1] == '+' ? 1 : 0),
                                           s.data() + s.size(), exp);
    if (ec != std::errc() || end != s.data() + s.size() || exp > 400 || exp < -400) return std::nullopt;
    d.exp10 += exp;
  }
  return d;
}

}  // namespace

std::optional<double> parse_csv_number(std::string_view text, char decimal) {
  text = trim(text);
  if (text.empty() || text.size() > 64) return std::nullopt;
  if (!split_decimal(text, decimal)) return std::nullopt;  // the grammar check
  // from_chars is exact (correctly rounded); it wants '.' as the mark.
  std::string buf(text);
  if (decimal != '.') {
    for (char& c : buf) {
      if (c == decimal) c = '.';
    }
  }
  const char* begin = buf.data() + (buf.front() == '+' ? 1 : 0);
  double v = 0.0;
  const auto [end, ec] = std::from_chars(begin, buf.data() + buf.size(), v);
  if (ec != std::errc() || end != buf.data() + buf.size() || !std::isfinite(v)) return std::nullopt;
  return v;
}

std::optional<std::int64_t> parse_csv_scaled_integer(std::string_view text, char decimal, int scale_exp10) {
  const auto d = split_decimal(text, decimal);
  if (!d) return std::nullopt;
  const int exp = d->exp10 + scale_exp10;
  constexpr auto kMax = static_cast<std::uint64_t>(std::numeric_limits<std::int64_t>::max());
  std::uint64_t v = d->digits;  // at most 19 digits: fits
  if (exp >= 0) {
    for (int k = 0; k < exp; ++k) {
      if (v > kMax / 10) return std::nullopt;
      v *= 10;
    }
    if (v > kMax) return std::nullopt;
    return d->negative ? -static_cast<std::int64_t>(v) : static_cast<std::int64_t>(v);
  }
  std::uint64_t q = v;
  bool inexact = false;
  for (int k = 0; k < -exp && (q != 0 || !inexact); ++k) {
    inexact = inexact || q % 10 != 0;
    q /= 10;
    if (q == 0 && v != 0) inexact = true;
  }
  if (d->negative && inexact) ++q;  // toward minus infinity: -1.5 us -> -2 us
  if (q > kMax) return std::nullopt;
  return d->negative ? -static_cast<std::int64_t>(q) : static_cast<std::int64_t>(q);
}

}  // namespace resolver
