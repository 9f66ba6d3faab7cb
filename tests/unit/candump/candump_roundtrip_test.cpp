// CandumpWriter -> CandumpReader: randomized frames of every kind come back
// identical; the writer's error paths.
#include <gtest/gtest.h>

#include <random>
#include <stdexcept>
#include <string>
#include <vector>

#include "drivers/candump/candump_line.h"
#include "drivers/candump/candump_reader.h"
#include "drivers/candump/candump_writer.h"
#include "tests/unit/candump/candump_test_support.h"

namespace resolver {
namespace {

using candump_test::TempPath;

TEST(CandumpRoundTrip, RandomFramesComeBackIdentical) {
  constexpr std::size_t kFrames = 20000;  // > one 64 KiB writer flush, many reader lines
  std::mt19937_64 rng(20240601);
  std::int64_t t = 1'699'999'999'000'000;
  std::vector<CanFrame> frames;
  frames.reserve(kFrames);
  std::size_t kinds[5] = {};  // classic std, classic ext, rtr, fd, error
  for (std::size_t i = 0; i < kFrames; ++i) {
    frames.push_back(candump_test::random_frame(rng, t));
    const CanFrame& f = frames.back();
    ++kinds[f.error ? 4 : f.fd ? 3 : f.rtr ? 2 : f.extended ? 1 : 0];
  }
  for (const std::size_t k : kinds) ASSERT_GT(k, 500U) << "the generator must cover every kind";

  TempPath tmp;
  {
    CandumpWriter writer(tmp.str());
    for (const CanFrame& f : frames) writer.write(f);
    EXPECT_EQ(writer.frames_written(), kFrames);
    writer.close();
  }

  CandumpReader reader(tmp.str());
  CanFrame back;
  std::size_t i = 0;
  for (CandumpReader::Status s; (s = reader.next(back)) != CandumpReader::Status::kEnd; ++i) {
    ASSERT_EQ(s, CandumpReader::Status::kFrame)
        << tmp.str() << ":" << reader.line_number() << ":" << reader.problem().column << ": "
        << reader.problem().message;
    ASSERT_LT(i, frames.size());
    ASSERT_TRUE(candump_test::same_frame(back, frames[i]))
        << "frame " << i << "\n got  " << candump_test::describe(back) << "\n want "
        << candump_test::describe(frames[i]);
  }
  EXPECT_EQ(i, kFrames);
}

TEST(CandumpRoundTrip, DestructorFlushes) {
  TempPath tmp;
  CanFrame f;
  f.set_iface("can0");
  f.id = 0x42;
  {
    CandumpWriter writer(tmp.str());
    writer.write(f);
  }
  EXPECT_EQ(candump_test::read_text(tmp.str()), "(0000000000.000000) can0 042#\n");
}

TEST(CandumpWriter, RejectsUnloggableFrameAndWritesNothing) {
  TempPath tmp;
  CandumpWriter writer(tmp.str());
  CanFrame bad;
  bad.set_iface("can0");
  bad.len = 9;  // classic frames hold at most 8 bytes
  try {
    writer.write(bad);
    ADD_FAILURE() << "expected InputError";
  } catch (const InputError& e) {  // the caller's frame: a usage error (exit 2), at the line it would take
    EXPECT_EQ(e.fault(), Fault::kUsage);
    EXPECT_EQ(std::string(e.what()), tmp.str() + ":1: cannot log this frame: classic CAN length 9 exceeds 8 bytes");
  }
  EXPECT_EQ(writer.frames_written(), 0U);
  writer.close();
  EXPECT_EQ(candump_test::read_text(tmp.str()), "");
  EXPECT_NO_THROW(writer.close());  // a second close does nothing
  CanFrame good;
  good.set_iface("can0");
  EXPECT_THROW(writer.write(good), std::runtime_error);  // after close()
}

TEST(CandumpWriter, UncreatableFileThrowsNamingPathAndReason) {
  const std::string path = "/nonexistent-dir/out.log";
  try {
    CandumpWriter writer(path);
    FAIL() << "expected std::runtime_error";
  } catch (const std::runtime_error& e) {
    const std::string what = e.what();
    EXPECT_NE(what.find(path), std::string::npos) << what;
    EXPECT_NE(what.find("No such file or directory"), std::string::npos) << what;
  }
}

TEST(CandumpWriter, FullDiskIsReportedByClose) {
  if (::access("/dev/full", W_OK) != 0) GTEST_SKIP() << "/dev/full is not available";
  CandumpWriter writer("/dev/full");
  CanFrame f;
  f.set_iface("can0");
  writer.write(f);
  try {
    writer.close();
    FAIL() << "expected std::runtime_error from writing to /dev/full";
  } catch (const std::runtime_error& e) {
    EXPECT_NE(std::string(e.what()).find("/dev/full"), std::string::npos) << e.what();
  }
}

}  // namespace
}  // namespace resolver
