// A one-line progress report on stderr for long offline runs (resolver-model's read
// and fit, resolverd --replay on a terminal):
//
//   reading demo.log: 12.3 of 16.6 MB (74%), 88000 samples, 45.1 MB/s, ETA 0.1 s
//   fitting [###############               ]  50% ETA 3 s
//
// On a terminal the line is rewritten in place and erased at the end; forced onto a
// pipe or file (--progress) each update is a line of its own. It is drawn at most
// every `every` (4 per second) and only once the run has lasted `show_after`
// (short runs stay quiet). update() is cheap but reads the clock: call it every few
// thousand records, not per record.
#pragma once

#include <chrono>
#include <cstdint>
#include <cstdio>
#include <string>
#include <utility>

namespace resolver {

class ProgressMeter {
 public:
  using Clock = std::chrono::steady_clock;

  struct Options {
    bool enabled = false;    ///< false: every call does nothing
    bool in_place = true;    ///< rewrite one line (a terminal) instead of printing lines
    std::chrono::milliseconds show_after{1500};
    std::chrono::milliseconds every{250};
  };

  /// Whether to show progress: `forced` (--progress) or stderr is a terminal;
  /// RESOLVER_PROGRESS=1 forces it too, =0 never. RESOLVER_PROGRESS_AFTER_MS sets
  /// show_after (forced: 0 unless that says otherwise).
  [[nodiscard]] static Options for_stderr(bool forced);

  ProgressMeter(std::FILE* out, std::string label, Options options);
  ~ProgressMeter();
  ProgressMeter(const ProgressMeter&) = delete;
  ProgressMeter& operator=(const ProgressMeter&) = delete;

  /// What bytes() counts besides the bytes: "samples" (the default), "frames".
  void set_items_word(std::string word) { items_word_ = std::move(word); }
  /// Bytes `done` of `total` (0 = not known: a pipe) and `items` (samples) so far.
  /// `last` draws the final state (when shown at all) whatever the time since the last draw.
  void bytes(std::uint64_t done, std::uint64_t total, std::int64_t items, bool last = false);
  /// A fraction 0..1 of the work (a bar with ETA); 1.0 is always drawn when shown.
  void fraction(double f);
  /// Erases the line (in place) and stops drawing; the destructor calls it.
  void finish();

 private:
  /// True when it is time to draw (and notes the time).
  bool due(bool last);
  void draw(const std::string& text);

  std::FILE* out_;
  std::string label_;
  std::string items_word_ = "samples";
  Options options_;
  Clock::time_point start_;
  Clock::time_point last_draw_{};
  bool shown_ = false;
  bool finished_ = false;
  bool drew_whole_ = false;
};

}  // namespace resolver
