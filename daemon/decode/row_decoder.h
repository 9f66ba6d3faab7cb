// A CSV / scope export row -> RowSample, through a column map ([input.csv] in
// resolverd's config): which column holds the time and in which unit, which
// column holds each role and in which unit.
//
//   time      "s", "ms", "us", or "filetime" (Windows: 100 ns ticks since
//             1601-01-01, converted exactly to us since the Unix epoch); no time
//             column: rows are evenly spaced at row_rate_hz
//   angles    "rad", "deg", "rev" (signal_units.h) or "counts" with full_scale
//             counts per revolution; value = (raw * scale + offset) in that unit,
//             then radians in [0, 2pi). `divide = N` unwraps the column first and
//             divides it by N: an electrical angle of an N-pole-pair motor
//             becomes the mechanical one.
//   currents  "A" or "mA", after scale and offset
//   sin, cos  raw * scale + offset, any consistent unit
//
// Every row yields a sample or a problem (bad_number, missing_column,
// extra_fields, absurd_value) naming the column; rows with odd times are the
// sample clock's business (it counts and re-anchors them, sample_clock.h).
// A row with more fields than the column-name line (or, without one, than the
// first data row) is refused whole: its fields do not line up with the names,
// most often because a decimal comma was split at a ',' delimiter ("1,5,2,3"
// for 1.5 and 2.3), which would otherwise read as other, wrong numbers.
// A value past what any bench measures (RowDecoder::kMaxAngleRad, ...) is
// refused as absurd_value: far past that a double keeps no angle at all.
// Pure: no I/O.
#pragma once

#include <array>
#include <cstdint>
#include <optional>
#include <string>
#include <vector>

#include "daemon/core/angles.h"
#include "daemon/core/errors.h"
#include "daemon/decode/row_sample.h"
#include "drivers/csv/csv_reader.h"
#include "drivers/text/text_problem.h"

namespace resolver {

/// A column by name (as the column-name line writes it) or 1-based index.
struct ColumnRef {
  std::string name;  ///< "" = by index
  int index = 0;     ///< 1-based; 0 = by name
  [[nodiscard]] std::string describe() const;
};

enum class TimeUnit : std::uint8_t { kSeconds, kMilliseconds, kMicroseconds, kFiletime };

struct RowRole {
  ColumnRef column;
  std::string unit;            ///< as the config wrote it (messages)
  double scale = 1.0;          ///< raw * scale + offset, in `unit`
  double offset = 0.0;
  double to_role_unit = 1.0;   ///< from `unit` to the role's (rad, A)
  double divide = 1.0;         ///< angles: unwrap, divide by this, wrap
  double full_scale = 0.0;     ///< sin/cos: the largest |value| the ADC reaches (after scale), 0 = unknown
};

struct RowMap {
  std::optional<ColumnRef> time;  ///< nullopt: no time column (rows at row_rate_hz)
  TimeUnit time_unit = TimeUnit::kSeconds;
  double row_rate_hz = 0.0;       ///< [Hz] only without a time column
  std::array<std::optional<RowRole>, kRoleCount> roles;
  [[nodiscard]] bool empty() const;
};

/// The smaller of the sin and cos columns' full_scale, 0 when either is unknown.
[[nodiscard]] double csv_sincos_full_scale(const RowMap& map);

class RowDecoder {
 public:
  /// Largest |angle| [rad] a row may give (after scale and offset, before
  /// wrapping; 1.6e7 revolutions of a multi-turn count): a double still
  /// resolves it to 1.5e-8 rad. Past it the wrapped angle is noise.
  static constexpr double kMaxAngleRad = 1e8;
  /// Largest |current| [A] a row may give.
  static constexpr double kMaxCurrentA = 1e6;
  /// Largest |sin| or |cos| in the export's unit (ADC counts of a 32-bit converter fit).
  static constexpr double kMaxSinCos = 1e12;

  explicit RowDecoder(RowMap map) : map_(std::move(map)) {}

  /// Resolves column names against the export's column-name line (`names`,
  /// empty when it has none; `names_at` is the file and that line). When a column
  /// is not there, throws InputError (Fault::kUsage: the config names it; option
  /// "[input.csv.columns]") naming every missing column and the columns that are.
  void bind(const std::vector<std::string>& names, const Where& names_at = {});

  /// Decodes one data row (after bind()). A problem names the column (reason
  /// bad_number, missing_column or absurd_value) or the field count
  /// (extra_fields); the row still counts as one in the sequence. `delimiter`
  /// only words the extra_fields message. Never throws except std::bad_alloc.
  std::optional<TextProblem> decode(const CsvRow& row, char decimal, RowSample& out,
                                    CsvFormat::Delimiter delimiter = CsvFormat::Delimiter::kAuto);

  [[nodiscard]] const RowMap& map() const { return map_; }

  /// Rows whose time steps decide whether the time column resolves the rows.
  static constexpr int kTimeCheckSteps = 200;
  /// A time column is too coarse when this share of its steps or more are 0
  /// (the same time as the row before): 0.01 s at 1 kHz repeats 9 times in 10.
  static constexpr double kMaxRepeatedTimeShare = 0.25;
  /// Once kTimeCheckSteps rows with a time were decoded (or at the end, `at_end`,
  /// after at least 16): when the time column repeats too often to time the rows,
  /// throws InputError (Fault::kUsage: the fix is in [input.csv]) whose where is
  /// `file`, lines `first_line`-`last_line`, naming the column, its resolution and
  /// the row rate the rows between its changes suggest. Checks once.
  void check_time_resolution(bool at_end, const std::string& file = {}, std::uint64_t first_line = 0,
                             std::uint64_t last_line = 0);

 private:
  struct Bound {
    std::size_t field = 0;  ///< 0-based field index
  };
  RowMap map_;
  std::optional<Bound> time_;
  std::array<std::optional<Bound>, kRoleCount> roles_;
  std::array<AngleUnwrapper, kRoleCount> unwrap_{};
  std::int64_t sequence_ = 0;
  /// Fields a row may have: the column-name line's (bind), else the first row's; 0 = not known yet.
  std::size_t expected_fields_ = 0;
  bool fields_from_names_ = false;
  // The time column's first kTimeCheckSteps steps (check_time_resolution).
  bool time_checked_ = false;
  bool have_last_time_ = false;
  std::int64_t last_time_us_ = 0;
  int time_steps_ = 0;
  int repeated_times_ = 0;
  std::int64_t min_time_step_us_ = 0;  ///< smallest positive step
  std::int64_t first_change_row_ = -1, last_change_row_ = -1;  ///< sequence where the time changed
  std::int64_t first_change_us_ = 0, last_change_us_ = 0;
};

}  // namespace resolver
