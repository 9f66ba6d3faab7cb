// Which CAN frame completes each sample: the frame whose arrival made the
// joiner emit it. That is the one frame per sample the daemon must wake up
// for ([can] wake_ids); the run report names it, and a sample completed by a
// frame outside wake_ids (it waited in the quiet socket) is counted.
#pragma once

#include <array>
#include <cstdint>
#include <utility>

namespace resolver {

class CompletingFrames {
 public:
  static constexpr std::size_t kMaxIds = 8;  ///< distinct IDs tallied; more go to other()

  void add(std::uint32_t id) {
    ++total_;
    for (std::size_t i = 0; i < used_; ++i) {
      if (ids_[i].first == id) {
        ++ids_[i].second;
        return;
      }
    }
    if (used_ < kMaxIds) {
      ids_[used_++] = {id, 1};
    } else {
      ++other_;
    }
  }
  /// (ID, samples it completed), in order of first appearance.
  [[nodiscard]] std::size_t size() const { return used_; }
  [[nodiscard]] const std::pair<std::uint32_t, std::int64_t>& at(std::size_t i) const { return ids_[i]; }
  [[nodiscard]] std::int64_t other() const { return other_; }
  [[nodiscard]] std::int64_t total() const { return total_; }

 private:
  std::array<std::pair<std::uint32_t, std::int64_t>, kMaxIds> ids_{};
  std::size_t used_ = 0;
  std::int64_t other_ = 0;
  std::int64_t total_ = 0;
};

}  // namespace resolver
