// Fuzz target: the Vector ASC reader (drivers/asc/) over a whole file in a
// memfd, its frames through the sample stream (daemon/decode/sample_stream.h)
// with the bench DBC, as resolverd --replay FILE.asc runs them.
// Properties: never throws on bad content, line numbers only grow, every bad
// line names a reason and a column inside the line, every frame is counted
// once, sample time never goes back (odd stamps are re-anchored), every
// clock event has a reason and a message.
#include <sys/mman.h>
#include <unistd.h>

#include <cstddef>
#include <cstdint>
#include <memory>
#include <stdexcept>
#include <string>
#include <variant>

#include "daemon/dbc/dbc_parser.h"
#include "daemon/decode/sample_stream.h"
#include "drivers/asc/asc_reader.h"
#include "tests/fuzz/fuzz_support.h"

#ifndef RESOLVER_BENCH_DBC
#error "RESOLVER_BENCH_DBC must name proto/resolver_bench.dbc"
#endif

namespace {

std::shared_ptr<const resolver::FrameDecoder> bench_decoder() {
  static const std::shared_ptr<const resolver::FrameDecoder> decoder = [] {
    auto loaded = resolver::dbc::load_dbc_file(RESOLVER_BENCH_DBC);
    if (const auto* error = std::get_if<resolver::dbc::DbcError>(&loaded)) {
      throw std::runtime_error("fuzz_asc_reader: cannot load the bench DBC: " + error->what());
    }
    auto db = std::make_shared<const resolver::dbc::Database>(std::get<resolver::dbc::Database>(std::move(loaded)));
    return std::make_shared<const resolver::FrameDecoder>(db, resolver::SignalMap::bench_default());
  }();
  return decoder;
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const int fd = ::memfd_create("fuzz_asc", MFD_CLOEXEC);
  if (fd < 0) return 0;
  std::size_t written = 0;
  while (written < size) {
    const ssize_t n = ::write(fd, data + written, size - written);
    if (n <= 0) break;
    written += static_cast<std::size_t>(n);
  }
  if (written == size) {
    double last_t = -1.0;
    resolver::SampleStream stream(
        bench_decoder(), resolver::SampleStreamConfig{},
        resolver::SampleStream::Callbacks{[&](const resolver::Sample& s, std::uint8_t) {
                                            FUZZ_CHECK(s.t >= last_t, "sample time went back");
                                            last_t = s.t;
                                          },
                                          nullptr,
                                          [](std::string_view reason, const std::string& message) {
                                            FUZZ_CHECK(!reason.empty() && !message.empty(), "problem without a reason or message");
                                          }});
    // The smallest buffer: refills and over-long lines happen within -max_len.
    resolver::AscReader reader("/proc/self/fd/" + std::to_string(fd),
                               resolver::LineReader::min_buffer_bytes(resolver::AscReader::kMaxLineLength));
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
  }
  ::close(fd);
  return 0;
}
