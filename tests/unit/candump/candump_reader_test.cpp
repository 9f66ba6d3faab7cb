// CandumpReader: a real log, bad lines among good ones, lines across read()
// chunk boundaries, long lines, missing final newline, time going backwards.
#include <gtest/gtest.h>

#include <sys/stat.h>
#include <unistd.h>

#include <atomic>
#include <random>
#include <stdexcept>
#include <string>
#include <vector>

#include "drivers/candump/candump_line.h"
#include "drivers/candump/candump_reader.h"
#include "tests/unit/candump/candump_test_support.h"

namespace resolver {
namespace {

using candump_test::TempPath;
using candump_test::write_text;

struct Outcome {
  CandumpReader::Status status;
  std::uint64_t line;
  CanFrame frame;
  LogLineError kind = LogLineError::kMissingTimestamp;
};

std::vector<Outcome> read_all(const std::string& path,
                              std::size_t buffer_bytes = CandumpReader::kDefaultBufferBytes) {
  CandumpReader reader(path, buffer_bytes);
  std::vector<Outcome> out;
  for (;;) {
    Outcome o{};
    o.status = reader.next(o.frame);
    if (o.status == CandumpReader::Status::kEnd) break;
    o.line = reader.line_number();
    if (o.status == CandumpReader::Status::kBadLine) o.kind = reader.problem().kind;
    out.push_back(o);
  }
  return out;
}

TEST(CandumpReader, SavvycanCorpusParsesCompletely) {
  const std::string path = std::string(RESOLVER_SHARED_DIR) + "/corpus/savvycan/candump.log";
  if (::access(path.c_str(), R_OK) != 0) GTEST_SKIP() << "corpus file " << path << " is absent";
  const std::string text = candump_test::read_text(path);
  std::uint64_t non_blank = 0;
  std::size_t start = 0;
  while (start < text.size()) {
    std::size_t nl = text.find('\n', start);
    if (nl == std::string::npos) nl = text.size();
    if (text.find_first_not_of(" \t\r", start) < nl) ++non_blank;
    start = nl + 1;
  }

  CandumpReader reader(path);
  EXPECT_EQ(reader.total_bytes(), text.size());
  CanFrame f;
  std::uint64_t frames = 0;
  std::uint64_t bad = 0;
  for (CandumpReader::Status s; (s = reader.next(f)) != CandumpReader::Status::kEnd;) {
    if (s == CandumpReader::Status::kFrame) {
      ++frames;
      EXPECT_EQ(f.iface_name(), "vcan0");
    } else {
      ++bad;
      ADD_FAILURE() << path << ":" << reader.line_number() << ":" << reader.problem().column << ": "
                    << reader.problem().message;
    }
  }
  EXPECT_EQ(bad, 0U);
  EXPECT_EQ(frames, non_blank);
  EXPECT_EQ(frames, 12974U);
  EXPECT_EQ(reader.bytes_read(), text.size());
}

TEST(CandumpReader, GoodFramesAroundBadLinesSurvive) {
  TempPath tmp;
  write_text(tmp.str(),
             "(1.000000) can0 100#01\n"        // 1
             "\n"                               // 2 blank, skipped
             "(1.000100) can0 101#ZZ\n"        // 3 bad hex
             "(1.000200) can0 102#0203\r\n"    // 4 good, CRLF
             "garbage\n"                        // 5 missing timestamp
             "   \t\n"                          // 6 blank
             "(1.000300) can0 103#ABC\n"       // 7 odd nibbles
             "(1.000300) can0 104#04\n"        // 8 good, equal timestamp is fine
             "(0.999999) can0 105#05\n"        // 9 goes back in time: passed on (the sample clock's business)
             "(1.000400) can0 106#112233445566778899\n"  // 10 too long
             "(1.000500) can1 107#07");        // 11 good, no final newline
  const auto out = read_all(tmp.str());
  using S = CandumpReader::Status;
  struct Want {
    S status;
    std::uint64_t line;
    std::uint32_t id_or_kind;
  };
  const std::vector<Want> want = {
      {S::kFrame, 1, 0x100},
      {S::kBadLine, 3, static_cast<std::uint32_t>(LogLineError::kBadHex)},
      {S::kFrame, 4, 0x102},
      {S::kBadLine, 5, static_cast<std::uint32_t>(LogLineError::kMissingTimestamp)},
      {S::kBadLine, 7, static_cast<std::uint32_t>(LogLineError::kOddNibbles)},
      {S::kFrame, 8, 0x104},
      {S::kFrame, 9, 0x105},
      {S::kBadLine, 10, static_cast<std::uint32_t>(LogLineError::kTooLong)},
      {S::kFrame, 11, 0x107},
  };
  ASSERT_EQ(out.size(), want.size());
  for (std::size_t i = 0; i < want.size(); ++i) {
    SCOPED_TRACE("outcome " + std::to_string(i));
    EXPECT_EQ(out[i].status, want[i].status);
    EXPECT_EQ(out[i].line, want[i].line);
    if (want[i].status == S::kFrame) {
      EXPECT_EQ(out[i].frame.id, want[i].id_or_kind);
    } else {
      EXPECT_EQ(static_cast<std::uint32_t>(out[i].kind), want[i].id_or_kind) << to_string(out[i].kind);
    }
  }
  // The frames themselves are intact.
  EXPECT_EQ(out[2].frame.len, 2);
  EXPECT_EQ(out[2].frame.data[1], 0x03);
  EXPECT_EQ(out[2].frame.timestamp_us, 1000200);
  EXPECT_EQ(out[8].frame.iface_name(), "can1");
  EXPECT_EQ(out[8].frame.data[0], 0x07);
}

TEST(CandumpReader, TimestampsThatStepBackOrJumpArePassedOnUnchanged) {
  // Issue 16: a step back used to reject every later line (6009 lines lost on a
  // real log); the reader now passes every frame on as logged.
  TempPath tmp;
  write_text(tmp.str(),
             "(10.0) can0 001#\n"
             "(5.0) can0 002#\n"       // back 5 s
             "(7.0) can0 003#\n"       // still before 10.0
             "(86407.0) can0 004#\n"   // +1 day
             "(11.0) can0 005#\n");
  const auto out = read_all(tmp.str());
  ASSERT_EQ(out.size(), 5U);
  const std::int64_t want_us[] = {10'000'000, 5'000'000, 7'000'000, 86'407'000'000, 11'000'000};
  for (std::size_t i = 0; i < out.size(); ++i) {
    EXPECT_EQ(out[i].status, CandumpReader::Status::kFrame) << i;
    EXPECT_EQ(out[i].frame.timestamp_us, want_us[i]) << i;
  }
}

TEST(CandumpReader, OverlongLineIsSkippedToTheNextNewline) {
  TempPath tmp;
  // 3 MiB without a newline: longer than the read buffer, so the reader must
  // discard while it scans instead of growing.
  const std::string huge(3U << 20, 'x');
  write_text(tmp.str(), "(1.0) can0 001#01\n" + huge + "\n(2.0) can0 002#02\n" + std::string(5000, 'y') +
                            "\n(3.0) can0 003#03\n" + huge);
  const auto out = read_all(tmp.str());
  ASSERT_EQ(out.size(), 6U);
  EXPECT_EQ(out[0].frame.id, 1U);
  EXPECT_EQ(out[1].kind, LogLineError::kLineTooLong);
  EXPECT_EQ(out[1].line, 2U);
  EXPECT_EQ(out[2].frame.id, 2U);
  EXPECT_EQ(out[2].line, 3U);
  EXPECT_EQ(out[3].kind, LogLineError::kLineTooLong);
  EXPECT_EQ(out[4].frame.id, 3U);
  EXPECT_EQ(out[4].line, 5U);
  EXPECT_EQ(out[5].kind, LogLineError::kLineTooLong);  // unterminated at end of file
  EXPECT_EQ(out[5].line, 6U);
}

TEST(CandumpReader, SmallestBufferReadsLikeTheDefaultAtTheLengthLimit) {
  // Lines of exactly the longest accepted length and one byte more, around
  // good frames: the smallest buffer (the fuzz target's) must split and drop
  // them exactly as the 1 MiB buffer does, including at the end of the file.
  const std::string at_limit(kMaxCandumpLineLength, 'z');
  const std::string over_limit(kMaxCandumpLineLength + 1, 'z');
  std::string text;
  for (int i = 0; i < 6; ++i) {
    text += "(1.0) can0 001#01\n" + at_limit + "\n(1.5) can0 002#02\n" + over_limit + "\n";
  }
  text += at_limit;  // unterminated, at the limit
  TempPath tmp;
  write_text(tmp.str(), text);
  const auto big = read_all(tmp.str());
  const auto small = read_all(tmp.str(), 1);  // raised to kMinBufferBytes
  ASSERT_EQ(big.size(), 6U * 4U + 1U);
  ASSERT_EQ(small.size(), big.size());
  for (std::size_t i = 0; i < big.size(); ++i) {
    EXPECT_EQ(small[i].status, big[i].status) << "outcome " << i;
    EXPECT_EQ(small[i].line, big[i].line) << "outcome " << i;
    EXPECT_EQ(small[i].kind, big[i].kind) << "outcome " << i;
  }
  EXPECT_EQ(big[1].status, CandumpReader::Status::kBadLine);
  EXPECT_NE(big[1].kind, LogLineError::kLineTooLong);  // at the limit: parsed, and bad for another reason
  EXPECT_EQ(big[3].kind, LogLineError::kLineTooLong);
  EXPECT_NE(big.back().kind, LogLineError::kLineTooLong);
}

TEST(CandumpReader, LinesAcrossChunkBoundariesAreWhole) {
  // ~5 MiB of lines of varying length, so many lines straddle read() chunks.
  std::mt19937_64 rng(7);
  std::int64_t t = 1'600'000'000'000'000;
  std::string text;
  std::vector<CanFrame> frames;
  while (text.size() < (5U << 20)) {
    CanFrame f = candump_test::random_frame(rng, t);
    frames.push_back(f);
    append_candump_line(f, text);
  }
  TempPath tmp;
  write_text(tmp.str(), text);
  CandumpReader reader(tmp.str());
  CanFrame f;
  std::size_t i = 0;
  for (CandumpReader::Status s; (s = reader.next(f)) != CandumpReader::Status::kEnd; ++i) {
    ASSERT_EQ(s, CandumpReader::Status::kFrame) << reader.line_number() << ": " << reader.problem().message;
    ASSERT_LT(i, frames.size());
    ASSERT_TRUE(candump_test::same_frame(f, frames[i]))
        << "line " << reader.line_number() << "\n got  " << candump_test::describe(f) << "\n want "
        << candump_test::describe(frames[i]);
    ASSERT_EQ(reader.line_number(), i + 1);
    ASSERT_LE(reader.bytes_read(), reader.total_bytes());
  }
  EXPECT_EQ(i, frames.size());
  EXPECT_EQ(reader.bytes_read(), text.size());
  EXPECT_EQ(reader.next(f), CandumpReader::Status::kEnd);  // kEnd repeats
}

TEST(CandumpReader, ReadsFromAPipeWithUnknownSize) {
  TempPath tmp;
  write_text(tmp.str(), "(1.0) can0 001#01\n(2.0) can0 002#02\n");
  FILE* pipe = ::popen(("cat " + tmp.str()).c_str(), "r");
  ASSERT_NE(pipe, nullptr);
  CandumpReader reader("/dev/fd/" + std::to_string(::fileno(pipe)));
  EXPECT_EQ(reader.total_bytes(), 0U);
  CanFrame f;
  EXPECT_EQ(reader.next(f), CandumpReader::Status::kFrame);
  EXPECT_EQ(reader.next(f), CandumpReader::Status::kFrame);
  EXPECT_EQ(f.id, 2U);
  EXPECT_EQ(reader.next(f), CandumpReader::Status::kEnd);
  ::pclose(pipe);
}

TEST(CandumpReader, RandomBytesNeverCrashOrStall) {
  // Binary junk with some newlines: every line is reported (good or bad),
  // line numbers only grow, and the reader reaches the end.
  std::mt19937_64 rng(11);
  std::string junk(1U << 20, '\0');
  std::size_t newlines = 0;
  for (char& c : junk) {
    c = static_cast<char>(rng() % 97 == 0 ? '\n' : static_cast<char>(rng()));
    if (c == '\n') ++newlines;
  }
  TempPath tmp;
  write_text(tmp.str(), junk);
  CandumpReader reader(tmp.str());
  CanFrame f;
  std::uint64_t last_line = 0;
  std::uint64_t results = 0;
  for (CandumpReader::Status s; (s = reader.next(f)) != CandumpReader::Status::kEnd;) {
    ASSERT_GT(reader.line_number(), last_line);
    last_line = reader.line_number();
    ASSERT_LE(last_line, newlines + 1);
    if (s == CandumpReader::Status::kBadLine) {
      EXPECT_FALSE(reader.problem().message.empty());
    }
    ++results;
  }
  EXPECT_GT(results, newlines / 2);  // nearly every line is non-blank junk
  EXPECT_EQ(reader.bytes_read(), junk.size());
}

TEST(CandumpReader, EmptyFileEndsAtOnce) {
  TempPath tmp;
  write_text(tmp.str(), "");
  CandumpReader reader(tmp.str());
  CanFrame f;
  EXPECT_EQ(reader.next(f), CandumpReader::Status::kEnd);
  EXPECT_EQ(reader.line_number(), 0U);
}

TEST(CandumpReader, MissingFileThrowsNamingPathAndReason) {
  const std::string path = "/nonexistent-dir/none.log";
  try {
    CandumpReader reader(path);
    FAIL() << "expected std::runtime_error";
  } catch (const std::runtime_error& e) {
    EXPECT_EQ(std::string(e.what()), "cannot open " + path + ": No such file or directory");
  }
}

TEST(CandumpReader, MovedReaderContinuesWhereItWas) {
  TempPath tmp;
  write_text(tmp.str(), "(1.0) can0 001#\n(2.0) can0 002#\n(3.0) can0 003#\n");
  CandumpReader a(tmp.str());
  CanFrame f;
  ASSERT_EQ(a.next(f), CandumpReader::Status::kFrame);
  CandumpReader b(std::move(a));
  ASSERT_EQ(b.next(f), CandumpReader::Status::kFrame);
  EXPECT_EQ(f.id, 2U);
  EXPECT_EQ(b.line_number(), 2U);
  EXPECT_EQ(b.path(), tmp.str());
}

// The stop flag (issue 16): a set flag ends next() with kEnd and stopped() on
// any input, without reading on. No timing: the flag is set before the call, so
// a reader that ignored it would block (FIFO) or never return (/dev/zero) and
// the test would hang instead of passing.
TEST(CandumpReader, StopFlagEndsAnEndlessDevice) {
  std::atomic<bool> stop{false};
  CandumpReader reader("/dev/zero");
  reader.set_stop_flag(&stop);
  stop = true;
  CanFrame f;
  EXPECT_EQ(reader.next(f), CandumpReader::Status::kEnd);
  EXPECT_TRUE(reader.stopped());
}

TEST(CandumpReader, StopFlagEndsAFifoWithoutWriterAndOpeningDoesNotBlock) {
  TempPath fifo(".fifo");
  ::unlink(fifo.str().c_str());
  ASSERT_EQ(::mkfifo(fifo.str().c_str(), 0600), 0);
  std::atomic<bool> stop{true};
  CandumpReader reader(fifo.str());  // no writer: must not block here
  EXPECT_EQ(reader.total_bytes(), 0U);
  reader.set_stop_flag(&stop);
  CanFrame f;
  EXPECT_EQ(reader.next(f), CandumpReader::Status::kEnd);
  EXPECT_TRUE(reader.stopped());
}

TEST(CandumpReader, StopFlagMidFileDropsNoFrameAsBadAndControlReadsToTheEnd) {
  TempPath log;
  std::string text;
  for (int i = 0; i < 100; ++i) text += "(1." + std::to_string(100000 + i) + ") can0 100#00\n";
  write_text(log.str(), text);
  std::atomic<bool> stop{false};
  CandumpReader reader(log.str(), CandumpReader::kMinBufferBytes);
  reader.set_stop_flag(&stop);
  CanFrame f;
  ASSERT_EQ(reader.next(f), CandumpReader::Status::kFrame);
  stop = true;
  // What is already buffered may still come out as frames, never as bad lines.
  CandumpReader::Status s;
  while ((s = reader.next(f)) == CandumpReader::Status::kFrame) {
  }
  EXPECT_EQ(s, CandumpReader::Status::kEnd);
  // Control: without the flag the same file reads to its end, not stopped.
  CandumpReader control(log.str());
  std::atomic<bool> never{false};
  control.set_stop_flag(&never);
  int frames = 0;
  while (control.next(f) == CandumpReader::Status::kFrame) ++frames;
  EXPECT_EQ(frames, 100);
  EXPECT_FALSE(control.stopped());
}

}  // namespace
}  // namespace resolver
