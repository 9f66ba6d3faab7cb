// Event logs written by LCM's own file:// provider, read back by our reader,
// by the library and by the resolver-echo binary.
#include <gtest/gtest.h>

#include <algorithm>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <string>
#include <system_error>
#include <sys/wait.h>
#include <unistd.h>

#include <lcm/eventlog.h>
#include <lcm/lcm-cpp.hpp>
#include <resolver/angle_t.hpp>
#include <resolver/estimate_t.hpp>
#include <resolver/health_t.hpp>

#include "echo_test_util.h"
#include "json_test_parser.h"
#include "tools/echo/echo_output.h"
#include "tools/echo/lcm_eventlog_reader.h"

namespace resolver {
namespace {

using echo_test_support::parse_json;
namespace fs = std::filesystem;

const std::string kEchoBinary = RESOLVER_BINARY_DIR "/bin/resolver-echo";

struct CommandResult {
  int exit_code = -1;
  std::string out;
};

// Runs a shell command, capturing stdout (and stderr when asked via 2>&1).
CommandResult run(const std::string& command) {
  CommandResult r;
  FILE* pipe = popen(command.c_str(), "r");
  if (pipe == nullptr) return r;
  char buf[4096];
  std::size_t n = 0;
  while ((n = std::fread(buf, 1, sizeof buf, pipe)) > 0) r.out.append(buf, n);
  const int status = pclose(pipe);
  r.exit_code = WIFEXITED(status) ? WEXITSTATUS(status) : -1;
  return r;
}

std::vector<std::string> split_lines(const std::string& text) {
  std::vector<std::string> lines;
  std::size_t start = 0;
  while (start < text.size()) {
    const std::size_t end = text.find('\n', start);
    lines.push_back(text.substr(start, end - start));
    if (end == std::string::npos) break;
    start = end + 1;
  }
  return lines;
}

class EchoLog : public ::testing::Test {
 protected:
  void SetUp() override {
    dir_ = fs::temp_directory_path() / ("resolver_echo_test_" + std::to_string(::getpid()) + "_" +
                                        ::testing::UnitTest::GetInstance()->current_test_info()->name());
    fs::create_directories(dir_);
    log_ = (dir_ / "test.lcmlog").string();
    write_log();
  }
  void TearDown() override { fs::remove_all(dir_); }

  // Several messages of several types, plus bytes no type matches.
  void write_log() {
    lcm::LCM lcm("file://" + log_ + "?mode=w");
    ASSERT_TRUE(lcm.good());
    for (int i = 0; i < 5; ++i) {
      resolver::angle_t a{};
      a.utime = 1000 + i;
      a.sample_index = i;
      a.counter = static_cast<int16_t>(i);
      a.theta_rd = 0.5 * i;
      lcm.publish("RESOLVER_ANGLE", &a);
      ++published_;
    }
    resolver::estimate_t e{};
    e.utime = 2000;
    e.method = "hwang_integral";
    e.num_params = 1;
    e.param_name = {"amplitude_imbalance.alpha"};
    e.value = {0.02};
    e.std_error = {0.001};
    lcm.publish("RESOLVER_ESTIMATE", &e);
    ++published_;
    resolver::health_t h{};
    h.utime = 3000;
    h.num_reasons = 2;
    h.reject_reason = {"crc", "counter_gap"};
    h.reject_count = {3, 4};
    lcm.publish("RESOLVER_HEALTH", &h);
    ++published_;
    const std::uint8_t junk[12] = {1, 2, 3, 4, 5, 6, 7, 8, 9, 10, 11, 12};
    lcm.publish("OTHER", junk, sizeof junk);
    ++published_;
  }

  fs::path dir_;
  std::string log_;
  int published_ = 0;
};

TEST_F(EchoLog, ReaderAgreesWithLcmsOwnEventlogReader) {
  lcm_eventlog_t* theirs = lcm_eventlog_create(log_.c_str(), "r");
  ASSERT_NE(theirs, nullptr);
  EventLogReader ours(log_);
  int events = 0;
  while (lcm_eventlog_event_t* ev = lcm_eventlog_read_next_event(theirs)) {
    const auto mine = ours.next();
    ASSERT_TRUE(mine.has_value());
    EXPECT_EQ(mine->event_number, ev->eventnum);
    EXPECT_EQ(mine->timestamp_us, ev->timestamp);
    EXPECT_EQ(mine->channel, std::string(ev->channel, static_cast<std::size_t>(ev->channellen)));
    ASSERT_EQ(mine->data.size(), static_cast<std::size_t>(ev->datalen));
    EXPECT_EQ(std::memcmp(mine->data.data(), ev->data, mine->data.size()), 0);
    lcm_eventlog_free_event(ev);
    ++events;
  }
  lcm_eventlog_destroy(theirs);
  EXPECT_FALSE(ours.next().has_value());
  EXPECT_EQ(events, published_);
}

TEST_F(EchoLog, LibraryDecodesEveryMessage) {
  const auto lines = read_log_as_json_lines(log_, LcmTypeRegistry::with_embedded_types());
  ASSERT_EQ(lines.size(), static_cast<std::size_t>(published_));
  for (int i = 0; i < 5; ++i) {
    const auto j = parse_json(lines[static_cast<std::size_t>(i)]);
    EXPECT_EQ(j["channel"].text, "RESOLVER_ANGLE");
    EXPECT_EQ(j["type"].text, "resolver.angle_t");
    EXPECT_EQ(j["utime"].integer(), 1000 + i);
    EXPECT_EQ(j["sample_index"].integer(), i);
    EXPECT_EQ(j["theta_rd"].number(), 0.5 * i);
  }
  const auto e = parse_json(lines[5]);
  EXPECT_EQ(e["type"].text, "resolver.estimate_t");
  EXPECT_EQ(e["method"].text, "hwang_integral");
  EXPECT_EQ(e["value"][0].number(), 0.02);
  const auto h = parse_json(lines[6]);
  EXPECT_EQ(h["reject_reason"][1].text, "counter_gap");
  EXPECT_EQ(h["reject_count"][1].integer(), 4);
  const auto junk = parse_json(lines[7]);
  EXPECT_EQ(junk["channel"].text, "OTHER");
  EXPECT_TRUE(junk["type"].is_null());
  EXPECT_TRUE(junk["utime"].is_null());
  EXPECT_EQ(junk["size"].integer(), 12);
  EXPECT_EQ(junk["error"].text, "unknown fingerprint 0x0102030405060708");
}

TEST_F(EchoLog, FiltersAndLimit) {
  const auto registry = LcmTypeRegistry::with_embedded_types();
  EXPECT_EQ(read_log_as_json_lines(log_, registry, make_echo_filter("RESOLVER_.*", "")).size(), 7u);
  EXPECT_EQ(read_log_as_json_lines(log_, registry, make_echo_filter("RESOLVER", "")).size(), 0u)
      << "the regex must match the whole channel name";
  EXPECT_EQ(read_log_as_json_lines(log_, registry, make_echo_filter("", "angle_t")).size(), 5u);
  EXPECT_EQ(read_log_as_json_lines(log_, registry, make_echo_filter("", "resolver.health_t")).size(), 1u);
  const LcmJsonDecoder decoder(registry);
  std::vector<std::string> got;
  EXPECT_EQ(echo_log_file(log_, decoder, EchoFilter{}, 3, [&](const std::string& l) { got.push_back(l); }), 3);
  EXPECT_EQ(got.size(), 3u);
  EXPECT_THROW(make_echo_filter("(unclosed", ""), std::invalid_argument);
}

TEST_F(EchoLog, BinaryPrintsTheSameLinesAsTheLibrary) {
  const auto expected = read_log_as_json_lines(log_, LcmTypeRegistry::with_embedded_types());
  const auto all = run(kEchoBinary + " --log " + log_);
  EXPECT_EQ(all.exit_code, 0);
  EXPECT_EQ(split_lines(all.out), expected);

  const auto some = run(kEchoBinary + " --log " + log_ + " --channel 'RESOLVER_(ANGLE|HEALTH)' --limit 2");
  EXPECT_EQ(some.exit_code, 0);
  EXPECT_EQ(split_lines(some.out), std::vector<std::string>(expected.begin(), expected.begin() + 2));

  const auto typed = run(kEchoBinary + " --log " + log_ + " --type estimate_t");
  EXPECT_EQ(split_lines(typed.out), std::vector<std::string>{expected[5]});
}

TEST_F(EchoLog, BinaryHelpAndUsageErrors) {
  const auto help = run(kEchoBinary + " --help");
  EXPECT_EQ(help.exit_code, 0);
  EXPECT_NE(help.out.find("\nExamples:\n"), std::string::npos);
  EXPECT_NE(help.out.find("unknown fingerprint"), std::string::npos);
  EXPECT_EQ(run(kEchoBinary + " 2>&1").exit_code, 2);
  EXPECT_EQ(run(kEchoBinary + " --log " + log_ + " --lcm memq:// 2>&1").exit_code, 2);
  EXPECT_EQ(run(kEchoBinary + " --log " + log_ + " --count 3 2>&1").exit_code, 2) << "--count is for --lcm";
  const auto bad_type = run(kEchoBinary + " --log " + log_ + " --type nope_t 2>&1");
  EXPECT_EQ(bad_type.exit_code, 2) << "a usage error";
  EXPECT_NE(bad_type.out.find("--type nope_t"), std::string::npos) << bad_type.out;
  const auto bad_regex = run(kEchoBinary + " --log " + log_ + " --channel '(' 2>&1");
  EXPECT_EQ(bad_regex.exit_code, 2) << "a usage error";
  EXPECT_NE(bad_regex.out.find("--channel"), std::string::npos) << bad_regex.out;
  const auto missing = run(kEchoBinary + " --log " + log_ + ".missing 2>&1");
  EXPECT_EQ(missing.exit_code, 3) << "an I/O error, not CLI11's 105";
  EXPECT_NE(missing.out.find("cannot read --log " + log_ + ".missing: No such file or directory"), std::string::npos)
      << missing.out;
}

TEST_F(EchoLog, BinaryLoadsExtraTypes) {
  // Without the type the message is unknown; with --types it decodes.
  const std::string extra = (dir_ / "types").string();
  fs::create_directories(extra);
  std::ofstream(extra + "/pair_t.lcm") << "package extra; struct pair_t { int32_t x; string y; }";
  {
    lcm::LCM lcm("file://" + (dir_ / "extra.lcmlog").string() + "?mode=w");
    // Hand-encoded extra.pair_t: fingerprint from --list-types, x = 7, y = "hi".
    const auto list = run(kEchoBinary + " --types " + extra + " --list-types");
    const auto pos = list.out.find("  extra.pair_t");
    ASSERT_NE(pos, std::string::npos) << list.out;
    const std::uint64_t fp = std::stoull(list.out.substr(pos - 18, 18), nullptr, 16);
    std::vector<std::uint8_t> msg;
    for (int s = 56; s >= 0; s -= 8) msg.push_back(static_cast<std::uint8_t>(fp >> s));
    const std::uint8_t body[] = {0, 0, 0, 7, 0, 0, 0, 3, 'h', 'i', 0};
    msg.insert(msg.end(), std::begin(body), std::end(body));
    lcm.publish("PAIR", msg.data(), static_cast<unsigned>(msg.size()));
  }
  const std::string extra_log = (dir_ / "extra.lcmlog").string();
  const auto plain = run(kEchoBinary + " --log " + extra_log).out;
  const auto without = parse_json(plain.substr(0, plain.find('\n')));
  EXPECT_TRUE(without["type"].is_null());
  const auto out = run(kEchoBinary + " --types " + extra + " --log " + extra_log).out;
  const auto with = parse_json(out.substr(0, out.find('\n')));
  EXPECT_EQ(with["type"].text, "extra.pair_t");
  EXPECT_EQ(with["x"].integer(), 7);
  EXPECT_EQ(with["y"].text, "hi");
}

// --- malformed logs -------------------------------------------------------

std::vector<char> read_all(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  return {std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>()};
}

void write_all(const std::string& path, const std::vector<char>& bytes) {
  std::ofstream(path, std::ios::binary).write(bytes.data(), static_cast<std::streamsize>(bytes.size()));
}

TEST_F(EchoLog, EveryTruncationGivesFileAndOffsetNeverACrash) {
  const auto bytes = read_all(log_);
  // Offsets where events start: a cut exactly there is a clean, shorter log.
  std::vector<std::uint64_t> starts;
  {
    EventLogReader r(log_);
    while (auto ev = r.next()) starts.push_back(ev->file_offset);
  }
  const std::string cut_path = (dir_ / "cut.lcmlog").string();
  const auto registry = LcmTypeRegistry::with_embedded_types();
  for (std::size_t len = 0; len < bytes.size(); ++len) {
    write_all(cut_path, std::vector<char>(bytes.begin(), bytes.begin() + static_cast<std::ptrdiff_t>(len)));
    std::size_t whole_events = 0;
    while (whole_events < starts.size() && starts[whole_events] < len) ++whole_events;
    const bool clean_cut = len == 0 || std::find(starts.begin(), starts.end(), len) != starts.end();
    std::vector<std::string> lines;
    const LcmJsonDecoder decoder(registry);
    try {
      echo_log_file(cut_path, decoder, EchoFilter{}, std::nullopt, [&](const std::string& l) { lines.push_back(l); });
      EXPECT_TRUE(clean_cut) << "no error for a log cut at " << len;
      EXPECT_EQ(lines.size(), whole_events);
    } catch (const EventLogError& e) {
      EXPECT_FALSE(clean_cut) << e.what();
      const std::string msg = e.what();
      const std::uint64_t bad_event = starts[whole_events - 1];
      EXPECT_NE(msg.find(cut_path), std::string::npos) << msg;
      EXPECT_NE(msg.find("byte offset " + std::to_string(bad_event)), std::string::npos) << msg;
      EXPECT_NE(msg.find("truncated"), std::string::npos) << msg;
      EXPECT_EQ(lines.size(), whole_events - 1) << "events before the damage still print";
    }
  }
}

TEST_F(EchoLog, CorruptSyncWordAndLengths) {
  auto bytes = read_all(log_);
  std::uint64_t second = 0;
  {
    EventLogReader r(log_);
    r.next();
    second = r.next()->file_offset;
  }
  const std::string bad = (dir_ / "bad.lcmlog").string();
  auto corrupt = bytes;
  corrupt[second + 1] = 0;
  write_all(bad, corrupt);
  try {
    read_log_as_json_lines(bad, LcmTypeRegistry::with_embedded_types());
    FAIL() << "no error";
  } catch (const EventLogError& e) {
    const std::string msg = e.what();
    EXPECT_NE(msg.find(bad + ": byte offset " + std::to_string(second) + " (event #2"), std::string::npos) << msg;
    EXPECT_NE(msg.find("sync word"), std::string::npos) << msg;
  }
  // Negative data length in the first header (bytes 24..27).
  corrupt = bytes;
  corrupt[24] = static_cast<char>(0xFF);
  write_all(bad, corrupt);
  EXPECT_THROW(read_log_as_json_lines(bad, LcmTypeRegistry::with_embedded_types()), EventLogError);
  // Not a log at all.
  std::ofstream(bad) << "hello, this is text\n and more text to fill a header";
  try {
    read_log_as_json_lines(bad, LcmTypeRegistry::with_embedded_types());
    FAIL() << "no error";
  } catch (const EventLogError& e) {
    EXPECT_NE(std::string(e.what()).find("not an LCM event log"), std::string::npos) << e.what();
  }
  // Too short for a header and not starting with the sync word: also not a log.
  std::ofstream(bad, std::ios::trunc) << "abc";
  try {
    read_log_as_json_lines(bad, LcmTypeRegistry::with_embedded_types());
    FAIL() << "no error";
  } catch (const EventLogError& e) {
    EXPECT_NE(std::string(e.what()).find("not an LCM event log"), std::string::npos) << e.what();
  }
  EXPECT_THROW(EventLogReader((dir_ / "missing.lcmlog").string()), std::system_error);  // an I/O error: exit 3
}

TEST_F(EchoLog, BinaryReportsTruncationOnStderrAfterGoodLines) {
  auto bytes = read_all(log_);
  ASSERT_GT(bytes.size(), 3U);
  bytes.erase(bytes.end() - 3, bytes.end());
  const std::string cut = (dir_ / "cut.lcmlog").string();
  write_all(cut, bytes);
  const auto stdout_only = run(kEchoBinary + " --log " + cut + " 2>/dev/null");
  EXPECT_EQ(stdout_only.exit_code, 1);
  EXPECT_EQ(split_lines(stdout_only.out).size(), static_cast<std::size_t>(published_ - 1));
  const auto stderr_only = run(kEchoBinary + " --log " + cut + " 2>&1 >/dev/null");
  EXPECT_NE(stderr_only.out.find(cut + ": byte offset"), std::string::npos) << stderr_only.out;
}

}  // namespace
}  // namespace resolver
