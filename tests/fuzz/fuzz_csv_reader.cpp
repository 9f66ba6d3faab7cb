// Fuzz target: a CSV / scope export through the CSV reader (drivers/csv/),
// the row decoder (daemon/decode/row_decoder.h) and the sample stream, as
// resolverd --replay FILE.csv runs them. The first input byte picks the
// layout: separator (auto, ',', ';', tab, spaces), decimal mark, header
// handling, time column and unit; the rest is the file (in a memfd).
// Properties: never throws on bad content, every bad row names a reason and
// a column inside the line, every good row becomes one sample, sample time
// never goes back, unwrapped-and-divided angles stay in [0, 2pi).
#include <cstddef>
#include <cstdint>
#include <string>

#include "daemon/core/angles.h"
#include "daemon/decode/row_decoder.h"
#include "daemon/decode/sample_stream.h"
#include "drivers/csv/csv_reader.h"
#include "tests/fuzz/fuzz_bench_decoder.h"
#include "tests/fuzz/fuzz_support.h"

namespace {

/// Layout from the selector byte: bits 0-2 separator, bit 3 decimal comma,
/// bit 4 skip until numbers (else 1 header line), bit 5 column names,
/// bit 6 a time column (unit from bit 7: s or filetime), else rows at 100 Hz.
void choose(std::uint8_t sel, resolver::CsvFormat& format, resolver::RowMap& map) {
  using D = resolver::CsvFormat::Delimiter;
  constexpr D kDelims[] = {D::kAuto, D::kComma, D::kSemicolon, D::kTab, D::kSpace};
  format.delimiter = kDelims[(sel & 7U) % 5U];
  format.decimal = (sel & 8U) != 0 ? ',' : '.';
  if (format.decimal == ',' && format.delimiter == D::kComma) format.delimiter = D::kSemicolon;
  format.skip_until_numbers = (sel & 16U) != 0;
  format.header_lines = format.skip_until_numbers ? 0 : 1;
  format.column_names = (sel & 32U) != 0;
  auto role = [&](resolver::Role r, int column, double to_unit, double divide) {
    resolver::RowRole rr;
    rr.column = format.column_names ? resolver::ColumnRef{"c" + std::to_string(column), 0}
                                    : resolver::ColumnRef{"", column};
    rr.to_role_unit = to_unit;
    rr.divide = divide;
    map.roles[static_cast<std::size_t>(r)] = rr;
  };
  if ((sel & 64U) != 0) {
    map.time = format.column_names ? resolver::ColumnRef{"c1", 0} : resolver::ColumnRef{"", 1};
    map.time_unit = (sel & 128U) != 0 ? resolver::TimeUnit::kFiletime : resolver::TimeUnit::kSeconds;
  } else {
    map.row_rate_hz = 100.0;
  }
  role(resolver::Role::kRdAngle, 2, resolver::kPi / 180.0, 1.0);
  role(resolver::Role::kRefAngle, 3, resolver::kTwoPi / 65536.0, 21.0);
  role(resolver::Role::kSin, 4, 1.0, 1.0);
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  if (size < 1) return 0;
  resolver::CsvFormat format;
  resolver::RowMap map;
  choose(data[0], format, map);
  const resolver::fuzz::MemFile file(data + 1, size - 1);
  if (file.path().empty()) return 0;  // no memfd: nothing to test
  resolver::SampleStreamConfig sc;
  sc.row_rate_hz = map.row_rate_hz;
  std::int64_t samples = 0;
  double last_t = -1.0;
  resolver::SampleStream stream(
      resolver::fuzz::bench_decoder(), sc,
      resolver::SampleStream::Callbacks{[&](const resolver::Sample& s, std::uint8_t) {
                                          FUZZ_CHECK(s.t >= last_t, "sample time went back");
                                          FUZZ_CHECK(!s.has_ref || (s.theta_m_ref >= 0.0 && s.theta_m_ref < resolver::kTwoPi),
                                                     "reference angle outside [0, 2pi)");
                                          last_t = s.t;
                                          ++samples;
                                        },
                                        nullptr, nullptr});
  resolver::CsvReader reader(file.path(), format, resolver::LineReader::min_buffer_bytes(resolver::CsvReader::kMaxLineLength));
  resolver::RowDecoder decoder(map);
  bool bound = false;
  resolver::CsvRow row;
  resolver::RowSample sample;
  std::int64_t good = 0;
  std::size_t calls = 0;
  for (;;) {
    FUZZ_CHECK(calls++ <= size + 2, "reader does not reach the end of its input");
    const auto status = reader.next(row);
    if (status == resolver::CsvReader::Status::kEnd) break;
    if (!bound) {
      bound = true;
      try {
        decoder.bind(reader.column_names());
      } catch (const resolver::InputError& e) {  // a config error in resolverd: nothing more to read
        FUZZ_CHECK(e.fault() == resolver::Fault::kUsage, "a missing column is not a usage error");
        break;
      }
    }
    if (status == resolver::CsvReader::Status::kBadLine) continue;
    FUZZ_CHECK(row.fields.size() == row.columns.size(), "fields and columns differ in number");
    if (const auto problem = decoder.decode(row, format.decimal, sample)) {
      FUZZ_CHECK(!problem->reason.empty() && !problem->message.empty(), "bad row without a reason or message");
      FUZZ_CHECK(problem->column >= 1 && problem->column <= row.end_column, "column outside the row");
      continue;
    }
    stream.feed_row(sample, reader.line_number());
    ++good;
  }
  stream.flush();
  FUZZ_CHECK(samples == good, "a good row did not become exactly one sample");
  return 0;
}
