// Fuzz target: CandumpReader (drivers/candump/candump_reader.h) over a whole
// log held in a memfd, the way resolverd --replay reads a file: buffering,
// line splitting, over-long lines, blank lines.
// Properties: never throws on bad content, line numbers only grow, every bad
// line names a column and a reason, accepted timestamps are never negative
// (they may step back: the sample clock handles that, sample_clock.h).
#include <cstddef>
#include <cstdint>
#include <string>

#include "drivers/candump/candump_reader.h"
#include "tests/fuzz/fuzz_support.h"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const resolver::fuzz::MemFile file(data, size);
  if (file.path().empty()) return 0;  // no memfd (old kernel): nothing to test
  // The smallest buffer: refills and over-long lines happen within -max_len,
  // and a run does not pay for the daemon's 1 MiB buffer.
  resolver::CandumpReader reader(file.path(), resolver::CandumpReader::kMinBufferBytes);
  resolver::CanFrame frame;
  std::uint64_t last_line = 0;
  // Every call consumes at least one line, so size + 2 calls must reach kEnd.
  std::size_t calls = 0;
  for (;;) {
    FUZZ_CHECK(calls++ <= size + 2, "reader does not reach the end of its input");
    const auto status = reader.next(frame);
    if (status == resolver::CandumpReader::Status::kEnd) break;
    FUZZ_CHECK(reader.line_number() > last_line, "line number did not advance");
    last_line = reader.line_number();
    FUZZ_CHECK(reader.bytes_read() <= size, "reader consumed more bytes than the file holds");
    if (status == resolver::CandumpReader::Status::kBadLine) {
      FUZZ_CHECK(reader.problem().column >= 1, "bad line without a column");
      FUZZ_CHECK(!reader.problem().message.empty(), "bad line without a message");
      continue;
    }
    FUZZ_CHECK(frame.timestamp_us >= 0, "reader accepted a negative timestamp");
  }
  FUZZ_CHECK(reader.next(frame) == resolver::CandumpReader::Status::kEnd, "kEnd does not repeat");
  return 0;
}
