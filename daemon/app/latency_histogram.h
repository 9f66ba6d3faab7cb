// Latency percentiles without storing samples: 1 us bins up to 10 ms, one
// overflow bin. p50/p99 resolve to 1 us, max is exact.
#pragma once

#include <algorithm>
#include <array>
#include <cstdint>

namespace resolver {

class LatencyHistogram {
 public:
  static constexpr std::size_t kBins = 10000;  // [us]

  void add(double us) {
    const auto bin = us <= 0.0 ? std::size_t{0} : std::min(static_cast<std::size_t>(us), kBins);
    ++bins_[bin];
    ++count_;
    max_ = std::max(max_, us);
  }
  /// q in [0,1]; returns the bin's upper edge [us], 0 when empty.
  [[nodiscard]] double percentile(double q) const {
    if (count_ == 0) return 0.0;
    const auto target = static_cast<std::uint64_t>(q * static_cast<double>(count_ - 1)) + 1;
    std::uint64_t seen = 0;
    for (std::size_t i = 0; i <= kBins; ++i) {
      seen += bins_[i];
      if (seen >= target) return static_cast<double>(i + 1);
    }
    return max_;
  }
  [[nodiscard]] double max() const { return max_; }
  [[nodiscard]] std::uint64_t count() const { return count_; }
  void clear() { *this = LatencyHistogram{}; }

 private:
  std::array<std::uint32_t, kBins + 1> bins_{};
  std::uint64_t count_ = 0;
  double max_ = 0.0;
};

}  // namespace resolver
