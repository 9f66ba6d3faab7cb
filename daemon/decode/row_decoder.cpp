#include "daemon/decode/row_decoder.h"

#include <algorithm>
#include <cmath>
#include <utility>

#include <fmt/format.h>

#include "drivers/csv/csv_number.h"

namespace resolver {

namespace {

// Windows FILETIME epoch (1601-01-01) to Unix epoch (1970-01-01) [us]: 369 years
// with 89 leap days = 134774 days = 11644473600 s (Microsoft's documented constant).
constexpr std::int64_t kFiletimeToUnixUs = 11'644'473'600'000'000;

int time_scale_exp10(TimeUnit unit) {
  switch (unit) {
    case TimeUnit::kSeconds: return 6;
    case TimeUnit::kMilliseconds: return 3;
    case TimeUnit::kMicroseconds: return 0;
    case TimeUnit::kFiletime: return -1;  // 100 ns ticks
  }
  return 6;
}

bool is_angle(Role r) { return r == Role::kRdAngle || r == Role::kRefAngle; }
bool is_current(Role r) { return r == Role::kIA || r == Role::kIB || r == Role::kIC; }

/// Fields without the empty ones at the end (a trailing delimiter).
std::size_t used_fields(const std::vector<std::string_view>& fields) {
  std::size_t n = fields.size();
  while (n > 0 && fields[n - 1].empty()) --n;
  return n;
}

/// When `text` is a number with the other decimal mark: a hint naming the setting.
std::string decimal_hint(std::string_view text, char decimal) {
  const char other = decimal == ',' ? '.' : ',';
  if (!parse_csv_number(text, other)) return {};
  return fmt::format(" (a '{}' decimal mark: set [input.csv] decimal = \"{}\")", other, other);
}

/// The largest magnitude a value of role `r` may have, in the role's unit, and that unit.
std::pair<double, const char*> role_limit(Role r) {
  if (is_angle(r)) return {RowDecoder::kMaxAngleRad, "rad"};
  if (is_current(r)) return {RowDecoder::kMaxCurrentA, "A"};
  return {RowDecoder::kMaxSinCos, "(the export's unit)"};
}

}  // namespace

std::string ColumnRef::describe() const {
  return name.empty() ? "column " + std::to_string(index) : "column '" + name + "'";
}

bool RowMap::empty() const {
  for (const auto& r : roles) {
    if (r) return false;
  }
  return true;
}

double csv_sincos_full_scale(const RowMap& map) {
  const auto& s = map.roles[static_cast<std::size_t>(Role::kSin)];
  const auto& c = map.roles[static_cast<std::size_t>(Role::kCos)];
  if (!s || !c || !(s->full_scale > 0.0) || !(c->full_scale > 0.0)) return 0.0;
  return std::min(s->full_scale, c->full_scale);
}

void RowDecoder::bind(const std::vector<std::string>& names, const Where& names_at) {
  std::string missing;
  auto resolve = [&](const ColumnRef& ref, const std::string& what) -> std::optional<Bound> {
    if (ref.name.empty()) return Bound{static_cast<std::size_t>(ref.index - 1)};
    for (std::size_t i = 0; i < names.size(); ++i) {
      if (names[i] == ref.name) return Bound{i};
    }
    missing += (missing.empty() ? "" : "; ") + what + ": no column named '" + ref.name + "'";
    return std::nullopt;
  };
  if (map_.time) time_ = resolve(*map_.time, "time_column");
  for (std::size_t r = 0; r < kRoleCount; ++r) {
    if (map_.roles[r]) roles_[r] = resolve(map_.roles[r]->column, std::string(role_name(static_cast<Role>(r))));
  }
  std::vector<std::string_view> views(names.begin(), names.end());
  expected_fields_ = used_fields(views);
  fields_from_names_ = expected_fields_ > 0;
  if (missing.empty()) return;
  std::string have;
  for (const std::string& n : names) have += (have.empty() ? "'" : ", '") + n + "'";
  Where where = names_at;
  where.option = "[input.csv.columns]";
  throw InputError(Fault::kUsage,
                   missing + (names.empty() ? std::string(" (the export has no column-name line: set column_names = "
                                                          "true, or name columns by their 1-based index)")
                                            : " (the columns are " + have + ")"),
                   std::move(where));
}

std::optional<TextProblem> RowDecoder::decode(const CsvRow& row, char decimal, RowSample& out,
                                              CsvFormat::Delimiter delimiter) {
  out = RowSample{};
  out.sequence = sequence_++;
  const std::size_t fields = used_fields(row.fields);
  if (expected_fields_ == 0) expected_fields_ = fields;
  if (fields > expected_fields_) {
    std::string why = fields_from_names_
                          ? fmt::format("the row has {} fields, the column-name line has {}", fields, expected_fields_)
                          : fmt::format("the row has {} fields, the first data row has {}", fields, expected_fields_);
    why += ": its fields do not line up with the columns, so the row is not read";
    if (delimiter == CsvFormat::Delimiter::kComma) {
      why += fmt::format(
          "; the delimiter is ',' and a decimal comma splits a number in two (\"1,5,2,3\" for 1.5 and 2.3 reads as 4 "
          "fields): if the export writes decimal commas, its delimiter is ';' or a tab and [input.csv] needs "
          "decimal = \",\" (with delimiter = \";\" or \"tab\")");
    }
    const std::size_t at = expected_fields_ < row.columns.size() ? row.columns[expected_fields_] : row.end_column;
    return TextProblem{"extra_fields", at, why};
  }
  auto field = [&](const Bound& b, const ColumnRef& ref, std::string_view& text) -> std::optional<TextProblem> {
    if (b.field >= row.fields.size()) {
      return TextProblem{"missing_column", row.end_column,
                         fmt::format("the row has {} fields, {} is field {}", row.fields.size(), ref.describe(),
                                     b.field + 1)};
    }
    text = row.fields[b.field];
    return std::nullopt;
  };
  if (time_) {
    std::string_view text;
    if (auto p = field(*time_, *map_.time, text)) return p;
    const auto t = parse_csv_scaled_integer(text, decimal, time_scale_exp10(map_.time_unit));
    if (!t || (map_.time_unit == TimeUnit::kFiletime && *t < 0)) {
      return TextProblem{"bad_number", row.columns[time_->field],
                         fmt::format("{} (time): expected a number with '{}' as decimal mark, found '{}'{}",
                                     map_.time->describe(), decimal, text.substr(0, 40), decimal_hint(text, decimal))};
    }
    out.has_time = true;
    out.time_us = map_.time_unit == TimeUnit::kFiletime ? *t - kFiletimeToUnixUs : *t;
    if (!time_checked_ && time_steps_ < kTimeCheckSteps) {
      if (have_last_time_) {
        const std::int64_t step = out.time_us - last_time_us_;
        ++time_steps_;
        if (step == 0) ++repeated_times_;
        if (step > 0) {
          if (min_time_step_us_ == 0 || step < min_time_step_us_) min_time_step_us_ = step;
          if (first_change_row_ < 0) {
            first_change_row_ = out.sequence;
            first_change_us_ = out.time_us;
          }
          last_change_row_ = out.sequence;
          last_change_us_ = out.time_us;
        }
      }
      have_last_time_ = true;
      last_time_us_ = out.time_us;
    }
  }
  std::array<double, kRoleCount> raw{};
  for (std::size_t r = 0; r < kRoleCount; ++r) {
    if (!roles_[r]) continue;
    const RowRole& role = *map_.roles[r];
    std::string_view text;
    if (auto p = field(*roles_[r], role.column, text)) return p;
    const auto v = parse_csv_number(text, decimal);
    if (!v) {
      return TextProblem{"bad_number", row.columns[roles_[r]->field],
                         fmt::format("{} ({}): expected a number with '{}' as decimal mark, found '{}'{}",
                                     role.column.describe(), role_name(static_cast<Role>(r)), decimal,
                                     text.substr(0, 40), decimal_hint(text, decimal))};
    }
    raw[r] = (*v * role.scale + role.offset) * role.to_role_unit;
    const auto [limit, unit] = role_limit(static_cast<Role>(r));
    if (!(std::abs(raw[r]) <= limit)) {  // also catches inf and nan
      return TextProblem{"absurd_value", row.columns[roles_[r]->field],
                         fmt::format("{} ({}): '{}' is {:g} {}, past the {:g} {} any bench measures; the row is not read "
                                     "(a wrong unit, scale or column?)",
                                     role.column.describe(), role_name(static_cast<Role>(r)), text.substr(0, 40), raw[r],
                                     unit, limit, unit)};
    }
  }
  // Only a whole row moves the unwrapping state.
  for (std::size_t r = 0; r < kRoleCount; ++r) {
    if (!roles_[r]) continue;
    double value = raw[r];
    if (is_angle(static_cast<Role>(r))) {
      const double divide = map_.roles[r]->divide;
      value = divide != 1.0 ? wrap_2pi(unwrap_[r].update(wrap_2pi(value)) / divide) : wrap_2pi(value);
    }
    out.values[r] = value;
    out.roles = static_cast<std::uint16_t>(out.roles | role_bit(static_cast<Role>(r)));
  }
  return std::nullopt;
}

void RowDecoder::check_time_resolution(bool at_end, const std::string& file, std::uint64_t first_line,
                                       std::uint64_t last_line) {
  if (time_checked_ || !map_.time) return;
  if (time_steps_ < kTimeCheckSteps && !(at_end && time_steps_ >= 16)) return;
  time_checked_ = true;
  if (static_cast<double>(repeated_times_) < kMaxRepeatedTimeShare * time_steps_) return;
  std::string rate;
  if (last_change_row_ > first_change_row_ && last_change_us_ > first_change_us_) {
    const double hz = static_cast<double>(last_change_row_ - first_change_row_) * 1e6 /
                      static_cast<double>(last_change_us_ - first_change_us_);
    rate = fmt::format(" (the rows between its changes come at about {:.4g} Hz)", hz);
  }
  const std::string resolution =
      min_time_step_us_ > 0 ? fmt::format("resolves only {:g} s", static_cast<double>(min_time_step_us_) / 1e6)
                            : std::string("never changes");
  Where where = Where::at_file(file, first_line);
  where.last_line = last_line;
  throw InputError(
      Fault::kUsage,
      fmt::format(
          "{} (time): {} of the first {} rows repeat the previous row's time: the column {}, coarser than the rows "
          "come{}; rows sharing a time have no time between them (the rotor would seem not to move). Export the time "
          "with more digits, or, if the rows are evenly spaced, drop [input.csv] time_column and set row_rate_hz",
          map_.time->describe(), repeated_times_, time_steps_ + 1, resolution, rate),
      std::move(where));
}

}  // namespace resolver
