// Which CAN frames wake resolverd's live reader ([can] wake_ids).
//
// A sample of the bench spans several frames and only the one that completes
// it makes resolverd publish, so only that one needs to wake the reader; the
// others can wait in a second socket (drivers/socketcan/split_wake_source.h).
// Which frame that is depends on the bench (the firmware's send order, whether
// a reference encoder is fitted), so by default ("auto") the planner learns it:
//   - every frame wakes the reader until kLearnSamples samples in a row were
//     completed by the same frame ID; then only that ID does;
//   - when kFallbackSamples samples in a row were completed by a frame that
//     does not wake the reader (the order changed: such a sample waited for
//     the next wake-up), or when no waking frame came for a read timeout
//     while other frames did (e.g. the reference encoder was unplugged),
//     every frame wakes it again, and it learns anew.
// With a fixed list (wake_ids = [...] in the config, or [] for every frame)
// it never changes. Pure logic: run_live switches the sockets.
#pragma once

#include <cstdint>
#include <optional>
#include <string>
#include <vector>

namespace resolver {

class WakePlanner {
 public:
  static constexpr int kLearnSamples = 256;
  static constexpr int kFallbackSamples = 8;

  /// auto_mode: learn as above, starting with every frame; else `fixed` always.
  WakePlanner(bool auto_mode, std::vector<std::uint32_t> fixed);

  /// The IDs that wake the reader now (empty = every frame).
  [[nodiscard]] const std::vector<std::uint32_t>& wake_ids() const { return current_; }
  [[nodiscard]] bool auto_mode() const { return auto_mode_; }

  /// Call with the ID of the frame that completed a sample. Returns the wake
  /// set to switch to when it should change; the caller switches its sockets
  /// and then calls switched(), or keeps the old ones (nothing changes).
  [[nodiscard]] std::optional<std::vector<std::uint32_t>> on_sample_completed_by(std::uint32_t id);
  /// Call when the waking frames stopped while others kept coming
  /// (SplitWakeSource::waking_silences grew). Returns the wake set to switch to.
  [[nodiscard]] std::optional<std::vector<std::uint32_t>> on_waking_silence();
  void switched(std::vector<std::uint32_t> ids);

  /// "0x102", "0x101, 0x102" or "every frame".
  [[nodiscard]] static std::string describe(const std::vector<std::uint32_t>& ids);

 private:
  [[nodiscard]] bool wakes(std::uint32_t id) const;

  bool auto_mode_;
  std::vector<std::uint32_t> current_;
  std::uint32_t streak_id_ = 0;
  int streak_ = 0;        ///< samples in a row completed by streak_id_
  int not_waking_ = 0;    ///< samples in a row completed by a frame that does not wake the reader
};

}  // namespace resolver
