#include "tools/model/json_text.h"

#include <fmt/format.h>

#include <cmath>

namespace resolver::json {

std::string str(std::string_view s) {
  std::string o = "\"";
  o.reserve(s.size() + 2);
  for (const char ch : s) {
    switch (ch) {
      case '"': o += "\\\""; break;
      case '\\': o += "\\\\"; break;
      case '\n': o += "\\n"; break;
      case '\t': o += "\\t"; break;
      case '<': o += "\\u003c"; break;
      case '>': o += "\\u003e"; break;
      case '&': o += "\\u0026"; break;
      default:
        if (static_cast<unsigned char>(ch) < 0x20) o += fmt::format("\\u{:04x}", static_cast<int>(ch));
        else o += ch;
    }
  }
  return o + "\"";
}

std::string num(double v, int digits) { return std::isfinite(v) ? fmt::format("{:.{}g}", v, digits) : "null"; }

std::string array(const std::vector<double>& v, int digits) {
  std::string o = "[";
  o.reserve(v.size() * 9 + 2);
  for (std::size_t i = 0; i < v.size(); ++i) {
    if (i > 0) o += ',';
    o += num(v[i], digits);
  }
  return o + "]";
}

}  // namespace resolver::json
