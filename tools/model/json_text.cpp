#include "tools/model/json_text.h"

#include <fmt/format.h>

#include <cmath>

#include "drivers/text/json_string.h"

namespace resolver::json {

std::string str(std::string_view s) { return text::json_string(s, text::JsonEscape::script_safe); }

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
