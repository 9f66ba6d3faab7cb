// CSV / scope exports: numbers as exports write them, the reader's header
// handling and field splitting, and the column map's units.
#include <gtest/gtest.h>

#include <unistd.h>

#include <cstdio>
#include <optional>
#include <fstream>
#include <string>
#include <vector>

#include "daemon/core/angles.h"
#include "daemon/decode/row_decoder.h"
#include "drivers/csv/csv_number.h"
#include "drivers/csv/csv_reader.h"

namespace resolver {
namespace {

class TempFile {
 public:
  explicit TempFile(const std::string& text) {
    path_ = std::string(RESOLVER_BINARY_DIR) + "/row_decoder_test_" + std::to_string(::getpid()) + "_" +
            std::to_string(counter_++) + ".csv";
    std::ofstream(path_, std::ios::binary) << text;
  }
  ~TempFile() { std::remove(path_.c_str()); }
  TempFile(const TempFile&) = delete;
  TempFile& operator=(const TempFile&) = delete;
  [[nodiscard]] const std::string& path() const { return path_; }

 private:
  static inline int counter_ = 0;
  std::string path_;
};

TEST(CsvNumber, DecimalMarksAndExponents) {
  EXPECT_DOUBLE_EQ(*parse_csv_number("1.25", '.'), 1.25);
  EXPECT_DOUBLE_EQ(*parse_csv_number(" -1,25 ", ','), -1.25);
  EXPECT_DOUBLE_EQ(*parse_csv_number("1.260000000000000182e-02", '.'), 1.260000000000000182e-02);
  EXPECT_DOUBLE_EQ(*parse_csv_number("+3", '.'), 3.0);
  EXPECT_DOUBLE_EQ(*parse_csv_number("5.", '.'), 5.0);
  EXPECT_FALSE(parse_csv_number("1,25", '.'));  // a comma is not the mark here
  EXPECT_FALSE(parse_csv_number("1.2.3", '.'));
  EXPECT_FALSE(parse_csv_number("", '.'));
  EXPECT_FALSE(parse_csv_number("abc", '.'));
  EXPECT_FALSE(parse_csv_number("nan", '.'));
  EXPECT_FALSE(parse_csv_number("1e999", '.'));
}

TEST(CsvNumber, ScaledIntegersAreExact) {
  // A FILETIME needs 18 digits: a double would round it to 16 ticks (1.6 us).
  EXPECT_EQ(parse_csv_scaled_integer("133485408001234567", '.', -1), 13348540800123456);
  EXPECT_EQ(parse_csv_scaled_integer("0,000501", ',', 6), 501);
  EXPECT_EQ(parse_csv_scaled_integer("1700000000.1234567", '.', 6), 1700000000123456);  // truncated, never rounded up
  EXPECT_EQ(parse_csv_scaled_integer("-0.0000015", '.', 6), -2);                        // toward minus infinity
  EXPECT_EQ(parse_csv_scaled_integer("1.5e3", '.', 3), 1'500'000);
  EXPECT_FALSE(parse_csv_scaled_integer("1e30", '.', 6));  // past int64
  EXPECT_FALSE(parse_csv_scaled_integer("x", '.', 6));
}

TEST(CsvReader, ScopeExportWithHeaderLinesNamesAndSemicolons) {
  TempFile f("\xEF\xBB\xBF" "Scope XY-123\nDate;24.11.2025\n\nSamples;3\nUnit;deg\n"
             "Time;Resolver;\"Encoder\"\n"
             "133485408000000000;1,5;2,25\n"
             "133485408000100000; 3,0 ;4\n"
             "\n"
             "133485408000200000;x;5\n");
  CsvFormat fmt;
  fmt.decimal = ',';
  fmt.header_lines = 4;  // blank lines are not counted
  CsvReader reader(f.path(), fmt);
  CsvRow row;
  ASSERT_EQ(reader.next(row), CsvReader::Status::kRow);
  EXPECT_EQ(reader.column_names(), (std::vector<std::string>{"Time", "Resolver", "Encoder"}));
  EXPECT_EQ(reader.names_line(), 6U);
  EXPECT_EQ(reader.delimiter(), CsvFormat::Delimiter::kSemicolon);
  EXPECT_EQ(reader.line_number(), 7U);
  ASSERT_EQ(row.fields.size(), 3U);
  EXPECT_EQ(row.fields[1], "1,5");
  ASSERT_EQ(reader.next(row), CsvReader::Status::kRow);
  EXPECT_EQ(row.fields[1], "3,0");
  EXPECT_EQ(row.columns[1], 21U);  // after the space: where "3,0" starts
  ASSERT_EQ(reader.next(row), CsvReader::Status::kRow);
  EXPECT_EQ(reader.line_number(), 10U);
  EXPECT_EQ(reader.next(row), CsvReader::Status::kEnd);
}

TEST(CsvReader, SkipUntilNumbersFindsTheNamesAndSpaceRuns) {
  TempFile f("# exported by a tool\n  t   A    B\n  0.0  1.0  2.0\n  0.1  3.0  4.0\n");
  CsvFormat fmt;
  fmt.skip_until_numbers = true;
  CsvReader reader(f.path(), fmt);
  CsvRow row;
  ASSERT_EQ(reader.next(row), CsvReader::Status::kRow);
  EXPECT_EQ(reader.column_names(), (std::vector<std::string>{"t", "A", "B"}));
  EXPECT_EQ(reader.delimiter(), CsvFormat::Delimiter::kSpace);
  ASSERT_EQ(row.fields.size(), 3U);
  EXPECT_EQ(row.fields[2], "2.0");
  EXPECT_EQ(row.columns[0], 3U);
}

RowMap degree_map() {
  RowMap m;
  m.time = ColumnRef{"Time", 0};
  m.time_unit = TimeUnit::kFiletime;
  RowRole rd;
  rd.column = ColumnRef{"Resolver", 0};
  rd.unit = "deg";
  rd.to_role_unit = kPi / 180.0;
  m.roles[static_cast<std::size_t>(Role::kRdAngle)] = rd;
  RowRole ref = rd;
  ref.column = ColumnRef{"", 3};
  m.roles[static_cast<std::size_t>(Role::kRefAngle)] = ref;
  return m;
}

CsvRow row_of(const std::string& line) {
  static std::vector<std::string> keep;  // the views must outlive the row
  keep.push_back(line);
  CsvRow row;
  split_csv_line(keep.back(), CsvFormat::Delimiter::kSemicolon, row);
  return row;
}

TEST(RowDecoder, FiletimeAndDegrees) {
  RowDecoder d(degree_map());
  ASSERT_NO_THROW(d.bind({"Time", "Resolver", "Encoder"}));
  RowSample s;
  ASSERT_FALSE(d.decode(row_of("133485408000000000;450,0;-90"), ',', s));
  EXPECT_TRUE(s.has_time);
  // 133485408000000000 ticks of 100 ns since 1601 = 1704067200 s since 1970 (2024-01-01 00:00:00 UTC).
  EXPECT_EQ(s.time_us, 1'704'067'200'000'000);
  EXPECT_EQ(s.sequence, 0);
  EXPECT_NEAR(s.values[static_cast<std::size_t>(Role::kRdAngle)], kPi / 2.0, 1e-12);       // 450 deg wraps to 90
  EXPECT_NEAR(s.values[static_cast<std::size_t>(Role::kRefAngle)], 1.5 * kPi, 1e-12);      // -90 deg wraps to 270
  EXPECT_EQ(s.roles, role_bit(Role::kRdAngle) | role_bit(Role::kRefAngle));
}

TEST(RowDecoder, BadRowsNameTheColumnAndKeepTheSequence) {
  RowDecoder d(degree_map());
  ASSERT_NO_THROW(d.bind({"Time", "Resolver", "Encoder"}));
  RowSample s;
  const auto bad = d.decode(row_of("133485408000000000;4x5;1"), ',', s);
  ASSERT_TRUE(bad);
  EXPECT_EQ(bad->reason, "bad_number");
  EXPECT_EQ(bad->column, 20U);
  EXPECT_NE(bad->message.find("column 'Resolver' (rd_angle)"), std::string::npos) << bad->message;
  const auto missing = d.decode(row_of("133485408000000000;45"), ',', s);
  ASSERT_TRUE(missing);
  EXPECT_EQ(missing->reason, "missing_column");
  EXPECT_NE(missing->message.find("column 3"), std::string::npos) << missing->message;
  ASSERT_FALSE(d.decode(row_of("133485408000100000;1;2"), ',', s));
  EXPECT_EQ(s.sequence, 2);  // the two bad rows still count
}

// Issue 25: a European export's decimal commas split at a ',' delimiter read as
// other numbers ("0,001,359,9" as 0 s, 1 deg, 359 deg); the row must be refused.
TEST(RowDecoder, DecimalCommasSplitAtACommaAreRefusedNotMisread) {
  RowMap m;
  m.time = ColumnRef{"t", 0};
  RowRole rd;
  rd.column = ColumnRef{"rd", 0};
  rd.unit = "deg";
  rd.to_role_unit = kPi / 180.0;
  m.roles[static_cast<std::size_t>(Role::kRdAngle)] = rd;
  RowRole ref = rd;
  ref.column = ColumnRef{"ref", 0};
  m.roles[static_cast<std::size_t>(Role::kRefAngle)] = ref;
  RowDecoder d(m);
  ASSERT_NO_THROW(d.bind({"t", "rd", "ref"}));
  RowSample s;
  CsvRow row;
  split_csv_line("0,001,359,9451,0,5", CsvFormat::Delimiter::kComma, row);
  const auto p = d.decode(row, '.', s, CsvFormat::Delimiter::kComma);
  ASSERT_TRUE(p);
  EXPECT_EQ(p->reason, "extra_fields");
  EXPECT_EQ(p->column, 11U);  // where the fourth field, "9451", starts
  EXPECT_NE(p->message.find("the row has 6 fields, the column-name line has 3"), std::string::npos) << p->message;
  EXPECT_NE(p->message.find("decimal comma"), std::string::npos) << p->message;
  EXPECT_EQ(s.roles, 0U);
  // Control: the same values with '.' decimals, and a trailing delimiter, read.
  split_csv_line("0.001,359.9451,0.5,", CsvFormat::Delimiter::kComma, row);
  ASSERT_FALSE(d.decode(row, '.', s, CsvFormat::Delimiter::kComma));
  EXPECT_EQ(s.time_us, 1000);
  EXPECT_NEAR(s.values[static_cast<std::size_t>(Role::kRefAngle)], 0.5 * kPi / 180.0, 1e-12);
}

TEST(RowDecoder, WithoutNamesTheFirstRowSetsTheFieldCount) {
  RowMap m;
  RowRole rd;
  rd.column = ColumnRef{"", 2};
  rd.unit = "rad";
  m.roles[static_cast<std::size_t>(Role::kRdAngle)] = rd;
  m.row_rate_hz = 1000.0;
  RowDecoder d(m);
  ASSERT_NO_THROW(d.bind({}));
  RowSample s;
  CsvRow row;
  split_csv_line("0,1", CsvFormat::Delimiter::kComma, row);
  ASSERT_FALSE(d.decode(row, '.', s, CsvFormat::Delimiter::kComma));
  split_csv_line("0,1,5", CsvFormat::Delimiter::kComma, row);  // 1,5 meant 1.5
  const auto p = d.decode(row, '.', s, CsvFormat::Delimiter::kComma);
  ASSERT_TRUE(p);
  EXPECT_EQ(p->reason, "extra_fields");
  EXPECT_NE(p->message.find("the first data row has 2"), std::string::npos) << p->message;
}

TEST(RowDecoder, ADecimalCommaWhereAPointIsExpectedSaysSo) {
  RowDecoder d(degree_map());
  ASSERT_NO_THROW(d.bind({"Time", "Resolver", "Encoder"}));
  RowSample s;
  const auto p = d.decode(row_of("133485408000000000;1,5;2"), '.', s);
  ASSERT_TRUE(p);
  EXPECT_EQ(p->reason, "bad_number");
  EXPECT_NE(p->message.find("set [input.csv] decimal = \",\""), std::string::npos) << p->message;
}

// Issue 25: 1e300 deg is a finite double, yet no angle at all once wrapped.
TEST(RowDecoder, AbsurdValuesAreRefusedNamingTheColumn) {
  RowDecoder d(degree_map());
  ASSERT_NO_THROW(d.bind({"Time", "Resolver", "Encoder"}));
  RowSample s;
  const auto p = d.decode(row_of("133485408000000000;1e300;2"), ',', s);
  ASSERT_TRUE(p);
  EXPECT_EQ(p->reason, "absurd_value");
  EXPECT_EQ(p->column, 20U);
  EXPECT_NE(p->message.find("column 'Resolver' (rd_angle): '1e300'"), std::string::npos) << p->message;
  EXPECT_EQ(s.roles, 0U);
  const auto q = d.decode(row_of("133485408000000000;1;-1e20"), ',', s);
  ASSERT_TRUE(q);
  EXPECT_EQ(q->reason, "absurd_value");
  EXPECT_NE(q->message.find("column 3 (ref_angle)"), std::string::npos) << q->message;
  // A scale that overflows to inf is caught too.
  RowMap m = degree_map();
  m.roles[static_cast<std::size_t>(Role::kRdAngle)]->scale = 1e300;
  RowDecoder big(m);
  ASSERT_NO_THROW(big.bind({"Time", "Resolver", "Encoder"}));
  const auto r = big.decode(row_of("133485408000000000;1e10;2"), ',', s);
  ASSERT_TRUE(r);
  EXPECT_EQ(r->reason, "absurd_value");
  // Control: a large but real multi-turn angle (1e6 revolutions) reads.
  ASSERT_FALSE(d.decode(row_of("133485408000000000;360000000;2"), ',', s));
}

/// What check_time_resolution throws for rows of "rows.csv" from line 2 to `line`, nullopt when it does not.
std::optional<std::string> time_refusal(RowDecoder& d, bool at_end, std::uint64_t line) {
  try {
    d.check_time_resolution(at_end, "rows.csv", 2, line);
  } catch (const InputError& e) {
    EXPECT_EQ(e.fault(), Fault::kUsage);
    EXPECT_EQ(std::string(e.what()).rfind("rows.csv:2-" + std::to_string(line) + ": ", 0), 0U) << e.what();
    return e.message();
  }
  return std::nullopt;
}

// Issue 25: a time column rounded to 0.01 s at 1 kHz gives ten rows one time;
// read as it is, the rotor never moves ("0 moving"). It must be named.
std::optional<std::string> time_check_of(double rate_hz, const char* time_format, int rows, bool at_end) {
  RowMap m;
  m.time = ColumnRef{"t", 0};
  RowRole rd;
  rd.column = ColumnRef{"rd", 0};
  rd.unit = "rad";
  m.roles[static_cast<std::size_t>(Role::kRdAngle)] = rd;
  RowDecoder d(m);
  EXPECT_NO_THROW(d.bind({"t", "rd"}));
  RowSample s;
  for (int k = 0; k < rows; ++k) {
    char line[64];
    std::snprintf(line, sizeof line, time_format, k / rate_hz);
    const std::string text = std::string(line) + ";1";
    CsvRow row;
    split_csv_line(text, CsvFormat::Delimiter::kSemicolon, row);
    EXPECT_FALSE(d.decode(row, '.', s));
    if (auto why = time_refusal(d, false, k + 2)) return why;
  }
  return time_refusal(d, at_end, rows + 1);
}

TEST(RowDecoder, ATimeColumnCoarserThanTheRowsIsNamed) {
  const auto why = time_check_of(1000.0, "%.2f", 1000, false);
  ASSERT_TRUE(why);
  EXPECT_NE(why->find("column 't' (time): 180 of the first 201 rows repeat the previous row's time"), std::string::npos)
      << *why;
  EXPECT_NE(why->find("resolves only 0.01 s"), std::string::npos) << *why;
  EXPECT_NE(why->find("about 1000 Hz"), std::string::npos) << *why;
  EXPECT_NE(why->find("row_rate_hz"), std::string::npos) << *why;
  // A short export is checked at its end.
  EXPECT_TRUE(time_check_of(1000.0, "%.2f", 50, true));
  EXPECT_FALSE(time_check_of(1000.0, "%.2f", 50, false));
  // Controls: the same rows timed to 1 us, and 0.01 s at 50 Hz, are fine.
  EXPECT_FALSE(time_check_of(1000.0, "%.6f", 1000, true));
  EXPECT_FALSE(time_check_of(50.0, "%.2f", 1000, true));
}

TEST(RowDecoder, AColumnTheExportLacksIsNamed) {
  RowDecoder d(degree_map());
  std::optional<std::string> msg;
  try {
    d.bind({"time", "resolver"}, Where::at_file("scope.csv", 1));
  } catch (const InputError& e) {
    msg = e.what();
    EXPECT_EQ(e.fault(), Fault::kUsage);
    EXPECT_EQ(e.where().option, "[input.csv.columns]");
    EXPECT_EQ(msg->rfind("scope.csv:1: [input.csv.columns]: ", 0), 0U) << *msg;
  }
  ASSERT_TRUE(msg);
  EXPECT_NE(msg->find("time_column: no column named 'Time'"), std::string::npos) << *msg;
  EXPECT_NE(msg->find("rd_angle: no column named 'Resolver'"), std::string::npos) << *msg;
  EXPECT_NE(msg->find("the columns are 'time', 'resolver'"), std::string::npos) << *msg;
}

TEST(RowDecoder, CountsUnwrappedAndDividedGiveTheMechanicalAngle) {
  // moteus-style: phase_cmd is the electrical angle of a 21-pole-pair motor in
  // u16 counts (65536 = 2 pi electrical), stepping 1300 counts per row.
  RowMap m;
  RowRole ref;
  ref.column = ColumnRef{"", 1};
  ref.unit = "counts";
  ref.to_role_unit = kTwoPi / 65536.0;
  ref.divide = 21.0;
  m.roles[static_cast<std::size_t>(Role::kRefAngle)] = ref;
  m.row_rate_hz = 100.0;
  RowDecoder d(m);
  ASSERT_NO_THROW(d.bind({}));
  RowSample s;
  double first = 0.0;
  const int rows = 21 * 65536 / 1300 + 1;  // one mechanical revolution
  for (int k = 0; k <= rows; ++k) {
    const std::string text = std::to_string((1300 * k) % 65536);
    CsvRow row;
    split_csv_line(text, CsvFormat::Delimiter::kComma, row);
    ASSERT_FALSE(d.decode(row, '.', s));
    const double want = wrap_2pi(kTwoPi * 1300.0 * k / 65536.0 / 21.0);
    if (k == 0) first = s.values[static_cast<std::size_t>(Role::kRefAngle)];
    EXPECT_NEAR(wrap_pi(s.values[static_cast<std::size_t>(Role::kRefAngle)] - want), 0.0, 1e-9) << k;
  }
  EXPECT_EQ(first, 0.0);
  EXPECT_FALSE(s.has_time);
}

}  // namespace
}  // namespace resolver
