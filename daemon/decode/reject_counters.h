// Named counters of everything rejected, and why. Names are stable snake_case
// strings (they appear in health_t and in the report), so counters from the
// log reader, the frame decoder and the counter checks share one table.
#pragma once

#include <cstdint>
#include <map>
#include <string>
#include <string_view>

namespace resolver {

class RejectCounters {
 public:
  /// Adds `n` to the counter `reason`; returns the new count.
  std::int64_t add(std::string_view reason, std::int64_t n = 1) {
    auto it = counts_.find(reason);
    if (it == counts_.end()) it = counts_.emplace(std::string(reason), 0).first;
    it->second += n;
    return it->second;
  }
  [[nodiscard]] std::int64_t get(std::string_view reason) const {
    auto it = counts_.find(reason);
    return it == counts_.end() ? 0 : it->second;
  }
  [[nodiscard]] std::int64_t total() const {
    std::int64_t sum = 0;
    for (const auto& [name, n] : counts_) sum += n;
    return sum;
  }
  [[nodiscard]] const std::map<std::string, std::int64_t, std::less<>>& all() const { return counts_; }

 private:
  std::map<std::string, std::int64_t, std::less<>> counts_;
};

}  // namespace resolver
