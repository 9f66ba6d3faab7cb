// One line of a Vector ASC log (CANoe/CANalyzer's text log, also written by
// python-can's ASCWriter), parsed in the context of the lines before it.
//
//   date Wed Jan 10 10:47:09.123 am 2024         header: start of measurement (read as UTC;
//                                                the first Begin Triggerblock's date wins)
//   base hex  timestamps absolute                header: number base of IDs/data; times
//                                                absolute (since the start) or relative
//                                                (since the previous event)
//   internal events logged | // comment | Begin Triggerblock ... | End TriggerBlock
//      0.000000 Start of measurement
//      0.001234 1  100             Rx   d 8 01 02 03 04 05 06 07 08  Length = 0 BitCount = 0 ID = 256
//      0.001500 2  18FF0001x       Tx   d 2 0A 0B                  extended ID: 'x' suffix
//      0.001600 1  100             Rx   r 8                        remote frame (DLC in hex)
//      0.001700 1  100             Rx   d 40 00 01 ... 3F          python-can's ASCWriter for a message
//                                                                  not flagged FD with 64 bytes: the byte
//                                                                  count in hex; read as an FD frame
//      0.002000 1  ErrorFrame                                      error frame
//      0.003000 CANFD   1 Rx  100  [name]  1 0 8  8 01 02 ... <duration> <length> <flags> ...
//                      channel dir id [symbolic name] BRS ESI DLC(hex) data-length(dec) data...;
//                      flags bit 12 (EDL) clear: a classic frame logged on an FD channel
//
// Anything else with a timestamp (statistics, chip status, J1939, system
// variables, TxRq) is an unsupported event; anything else without one an
// unknown line: both are problems with a column, never fatal. Data bytes past
// the DLC's count and the trailing fields are ignored. Pure: no I/O.
#pragma once

#include <cstdint>
#include <optional>
#include <string_view>

#include "drivers/can_frame.h"
#include "drivers/text/text_problem.h"

namespace resolver {

class AscLineParser {
 public:
  enum class Kind { kFrame, kNone, kProblem };
  struct Result {
    Kind kind = Kind::kNone;
    TextProblem problem;  ///< kProblem
  };

  /// Parses one line (without '\n'). kFrame: `frame` holds it (timestamp in us
  /// since the epoch when a date header was read, else since the start of
  /// measurement). kNone: a header, comment or a known event that carries no
  /// frame. Never throws except std::bad_alloc.
  Result parse(std::string_view line, CanFrame& frame);

  [[nodiscard]] bool decimal_base() const { return base_ == 10; }
  [[nodiscard]] bool relative_timestamps() const { return relative_; }
  /// [us since the epoch] of the date header, if one was read.
  [[nodiscard]] std::optional<std::int64_t> start_us() const { return start_us_; }

 private:
  int base_ = 16;
  bool relative_ = false;
  std::optional<std::int64_t> start_us_;
  bool block_seen_ = false;
  std::int64_t last_event_us_ = 0;  ///< [us] since the start, for relative timestamps
};

/// Parses the "date" header's text ("Wed Jan 10 10:47:09.123 am 2024", English or
/// German month names, 12 or 24 h) to [us since the epoch], read as UTC.
[[nodiscard]] std::optional<std::int64_t> parse_asc_date(std::string_view text);

}  // namespace resolver
