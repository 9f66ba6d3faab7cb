// Fuzz target: the Vector ASC reader (drivers/asc/) over a whole file in a
// memfd, its frames through the sample stream (daemon/decode/sample_stream.h)
// with the bench DBC, as resolverd --replay FILE.asc runs them.
// Properties: never throws on bad content, line numbers only grow, every bad
// line names a reason and a column inside the line, every frame is counted
// once, sample time never goes back (odd stamps are re-anchored), every
// clock event has a reason and a message.
#include <cstddef>
#include <cstdint>
#include <string>

#include "daemon/decode/sample_stream.h"
#include "drivers/asc/asc_reader.h"
#include "tests/fuzz/fuzz_bench_decoder.h"
#include "tests/fuzz/fuzz_support.h"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const resolver::fuzz::MemFile file(data, size);
  if (file.path().empty()) return 0;  // no memfd: nothing to test
  double last_t = -1.0;
  resolver::SampleStream stream(
      resolver::fuzz::bench_decoder(), resolver::SampleStreamConfig{},
      resolver::SampleStream::Callbacks{[&](const resolver::Sample& s, std::uint8_t) {
                                          FUZZ_CHECK(s.t >= last_t, "sample time went back");
                                          last_t = s.t;
                                        },
                                        nullptr,
                                        [](std::string_view reason, const std::string& message) {
                                          FUZZ_CHECK(!reason.empty() && !message.empty(),
                                                     "problem without a reason or message");
                                        }});
  // The smallest buffer: refills and over-long lines happen within -max_len.
  resolver::AscReader reader(file.path(), resolver::LineReader::min_buffer_bytes(resolver::AscReader::kMaxLineLength));
  resolver::CanFrame frame;
  std::uint64_t last_line = 0;
  std::int64_t fed = 0;
  std::size_t calls = 0;
  for (;;) {
    FUZZ_CHECK(calls++ <= size + 2, "reader does not reach the end of its input");
    const auto status = reader.next(frame);
    if (status == resolver::AscReader::Status::kEnd) break;
    FUZZ_CHECK(reader.line_number() > last_line, "line number did not advance");
    last_line = reader.line_number();
    if (status == resolver::AscReader::Status::kBadLine) {
      const resolver::TextProblem& p = reader.problem();
      FUZZ_CHECK(!p.reason.empty() && !p.message.empty(), "bad line without a reason or message");
      FUZZ_CHECK(p.column >= 1 && p.column <= resolver::AscReader::kMaxLineLength + 1, "column outside the line");
      continue;
    }
    FUZZ_CHECK(frame.len <= (frame.fd ? 64 : 8), "frame longer than CAN allows");
    stream.feed(frame, reader.line_number());
    ++fed;
  }
  stream.flush();
  FUZZ_CHECK(stream.intake().stats().frames_seen == fed, "frames_seen differs from frames fed");
  FUZZ_CHECK(reader.next(frame) == resolver::AscReader::Status::kEnd, "kEnd does not repeat");
  return 0;
}
