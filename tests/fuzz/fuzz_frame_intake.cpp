// Fuzz target: FrameIntake + FrameDecoder (daemon/decode/) with the bench DBC
// (proto/resolver_bench.dbc) and the default signal map, as resolverd runs them.
//
// Two input forms, chosen by the first byte:
//   '('   a candump log: each line goes through parse_candump_line; good frames
//         are fed with their line number, bad lines are counted, as --replay does.
//   other binary frame records, so the fuzzer reaches deep states cheaply:
//         byte 0: max_counter_delta selector; then per frame
//           flags   bit0 extended, bit1 rtr, bit2 error, bit3 fd, bit4 seal
//                   (write the bench CRC into byte 7), bits5-7 id choice:
//                   0..3 = 0x100, 0x101, 0x102, 0x1F0; 4..7 = id read from input;
//                   flags == 0xFF restarts the sequence (log loop) instead
//           len     classic: len % 9, FD: len % 65
//           dt      int8 timestamp step [100 us] (negative steps allowed)
//           data    len bytes
// Properties: every frame is counted once in frames_seen; every problem has a
// reason and a message; samples carry only the roles the decoder maps.
#include <cstddef>
#include <cstdint>
#include <memory>
#include <stdexcept>
#include <string>

#include "daemon/dbc/dbc_parser.h"
#include "daemon/decode/crc8_j1850.h"
#include "daemon/decode/frame_intake.h"
#include "drivers/candump/candump_line.h"
#include "tests/fuzz/fuzz_bench_decoder.h"
#include "tests/fuzz/fuzz_support.h"

#ifndef RESOLVER_BENCH_DBC
#error "RESOLVER_BENCH_DBC must name proto/resolver_bench.dbc"
#endif

namespace {

using resolver::CanFrame;

using resolver::fuzz::bench_decoder;

resolver::FrameIntake::Callbacks checking_callbacks(std::uint16_t mapped_roles) {
  resolver::FrameIntake::Callbacks cb;
  cb.on_sample = [mapped_roles](const resolver::BenchSample& s) {
    (void)s.complete();
    for (std::size_t r = 0; r < resolver::kRoleCount; ++r) {
      const auto role = static_cast<resolver::Role>(r);
      if (s.has(role)) FUZZ_CHECK((mapped_roles & resolver::role_bit(role)) != 0, "sample holds an unmapped role");
    }
  };
  cb.on_bench_info = [](const resolver::BenchInfo&) {};
  cb.on_problem = [](std::string_view reason, const std::string& message) {
    FUZZ_CHECK(!reason.empty(), "problem without a reason");
    FUZZ_CHECK(!message.empty(), "problem without a message");
  };
  return cb;
}

void run_text(std::string_view text) {
  const auto decoder = bench_decoder();
  resolver::FrameIntake intake(decoder, 8, checking_callbacks(decoder->mapped_roles()));
  std::int64_t fed = 0;
  resolver::fuzz::for_each_line(text, [&](std::string_view line, std::uint64_t number) {
    CanFrame frame;
    if (const auto problem = resolver::parse_candump_line(line, frame)) {
      intake.count_problem(resolver::to_string(problem->kind), problem->message);
      return;
    }
    intake.feed(frame, number);
    ++fed;
  });
  intake.flush();
  FUZZ_CHECK(intake.stats().frames_seen == fed, "frames_seen differs from frames fed");
}

constexpr std::uint32_t kBenchIds[4] = {0x100, 0x101, 0x102, 0x1F0};

void run_binary(const std::uint8_t* data, std::size_t size) {
  resolver::fuzz::ByteReader in(data, size);
  const int max_delta = 1 + in.u8() % 16;
  const auto decoder = bench_decoder();
  resolver::FrameIntake intake(decoder, max_delta, checking_callbacks(decoder->mapped_roles()));
  std::int64_t fed = 0;
  std::int64_t t_us = 1'700'000'000'000'000;
  while (!in.empty()) {
    const std::uint8_t flags = in.u8();
    if (flags == 0xFF) {
      intake.restart_sequence();
      continue;
    }
    CanFrame f;
    f.extended = (flags & 0x01U) != 0;
    f.rtr = (flags & 0x02U) != 0;
    f.error = (flags & 0x04U) != 0;
    f.fd = (flags & 0x08U) != 0;
    const unsigned choice = flags >> 5U;
    if (choice < 4) {
      f.id = kBenchIds[choice];
    } else {
      f.id = f.extended ? (in.u32() & 0x1FFFFFFFU) : (in.u16() & 0x7FFU);
    }
    const std::uint8_t len_byte = in.u8();
    f.len = static_cast<std::uint8_t>(f.fd ? len_byte % 65U : len_byte % 9U);
    t_us += 100 * static_cast<std::int8_t>(in.u8());
    f.timestamp_us = t_us;
    for (std::size_t i = 0; i < f.len; ++i) f.data[i] = in.u8();
    if ((flags & 0x10U) != 0 && f.len >= 8) f.data[7] = resolver::bench_frame_crc(f.data.data(), f.id);
    f.set_iface("can0");
    intake.feed(f, static_cast<std::uint64_t>(fed + 1));
    ++fed;
  }
  intake.flush();
  FUZZ_CHECK(intake.stats().frames_seen == fed, "frames_seen differs from frames fed");
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  if (size > 0 && data[0] == '(') {
    run_text(resolver::fuzz::as_text(data, size));
  } else {
    run_binary(data, size);
  }
  return 0;
}
