// resolver-echo --csv DIR: one table per channel. Oracles: messages encoded by
// lcm-gen's own C++ code and written by LCM's own event-log writer (with chosen
// receive times); the tables are read back with a plain comma split and every
// field compared with the value that was encoded.
#include <gtest/gtest.h>

#include <sys/wait.h>
#include <unistd.h>

#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <limits>
#include <map>
#include <string>
#include <vector>

#include <echo_test/leaf_t.hpp>
#include <echo_test/node_t.hpp>
#include <lcm/eventlog.h>
#include <resolver/angle_t.hpp>
#include <resolver/estimate_t.hpp>

#include "echo_test_util.h"
#include "tools/echo/csv_export.h"
#include "tools/echo/lcm_eventlog_reader.h"

namespace resolver {
namespace {

namespace fs = std::filesystem;
using echo_test_support::encode;

const std::string kEchoBinary = RESOLVER_BINARY_DIR "/bin/resolver-echo";

/// A CSV file as a header and rows of fields (no quoting: the tables hold numbers only).
struct Table {
  std::vector<std::string> header;
  std::vector<std::vector<std::string>> rows;

  [[nodiscard]] std::size_t column(const std::string& name) const {
    for (std::size_t i = 0; i < header.size(); ++i) {
      if (header[i] == name) return i;
    }
    ADD_FAILURE() << "no column " << name;
    return 0;
  }
  [[nodiscard]] const std::string& at(std::size_t row, const std::string& name) const {
    return rows.at(row).at(column(name));
  }
  [[nodiscard]] double number(std::size_t row, const std::string& name) const {
    const std::string& text = at(row, name);
    char* end = nullptr;
    const double v = std::strtod(text.c_str(), &end);
    EXPECT_TRUE(!text.empty() && *end == '\0') << name << " row " << row << ": '" << text << "'";
    return v;
  }
};

std::vector<std::string> split(const std::string& line) {
  std::vector<std::string> out(1);
  for (const char c : line) {
    if (c == ',') out.emplace_back();
    else out.back().push_back(c);
  }
  return out;
}

Table read_table(const fs::path& path) {
  std::ifstream in(path);
  EXPECT_TRUE(in.good()) << path;
  Table t;
  std::string line;
  if (std::getline(in, line)) t.header = split(line);
  while (std::getline(in, line)) {
    t.rows.push_back(split(line));
    EXPECT_EQ(t.rows.back().size(), t.header.size()) << path << " row " << t.rows.size() - 1;
  }
  return t;
}

int run_status(const std::string& command) {
  const int status = std::system(command.c_str());
  return WIFEXITED(status) ? WEXITSTATUS(status) : -1;
}

class EchoCsv : public ::testing::Test {
 protected:
  void SetUp() override {
    dir_ = fs::temp_directory_path() / ("resolver_echo_csv_" + std::to_string(::getpid()) + "_" +
                                        ::testing::UnitTest::GetInstance()->current_test_info()->name());
    fs::remove_all(dir_);
    fs::create_directories(dir_);
    log_path_ = (dir_ / "test.lcmlog").string();
    log_ = lcm_eventlog_create(log_path_.c_str(), "w");
    ASSERT_NE(log_, nullptr);
  }
  void TearDown() override {
    close_log();
    fs::remove_all(dir_);
  }

  /// One event with LCM's own writer, received at `receive_utime` [us].
  void write(const std::string& channel, const std::vector<std::uint8_t>& data, std::int64_t receive_utime) {
    lcm_eventlog_event_t ev{};
    ev.eventnum = events_++;
    ev.timestamp = receive_utime;
    ev.channellen = static_cast<std::int32_t>(channel.size());
    ev.datalen = static_cast<std::int32_t>(data.size());
    ev.channel = const_cast<char*>(channel.c_str());
    ev.data = const_cast<std::uint8_t*>(data.data());
    ASSERT_EQ(lcm_eventlog_write_event(log_, &ev), 0);
  }
  void close_log() {
    if (log_ != nullptr) lcm_eventlog_destroy(log_);
    log_ = nullptr;
  }
  CsvExportResult export_csv(const EchoFilter& filter = {}, std::optional<std::int64_t> limit = std::nullopt) {
    close_log();
    registry_ = LcmTypeRegistry::with_embedded_types();
    registry_.add_directory(RESOLVER_SOURCE_DIR "/tests/unit/echo/lcm/echo_test");
    const LcmJsonDecoder decoder(registry_);
    return export_log_csv(log_path_, decoder, filter, limit, (dir_ / "csv").string());
  }

  static resolver::angle_t angle(std::int64_t utime, double theta) {
    resolver::angle_t a{};
    a.utime = utime;
    a.sample_index = utime / 500;
    a.counter = 7;
    a.theta_rd = theta;
    a.theta_sincos = theta + 1e-3;
    a.theta_comp = -theta;
    a.theta_ref = 1.0 / 3.0;
    a.speed_mech_rad_s = 20.94395102393195;
    a.eps_hat = 1e-300;
    a.eps_ref = -0.0;
    return a;
  }

  fs::path dir_;
  std::string log_path_;
  lcm_eventlog_t* log_ = nullptr;
  std::int64_t events_ = 0;
  LcmTypeRegistry registry_;
};

TEST_F(EchoCsv, OneTablePerChannelWithUtimeInSecondsAndEveryNumericMember) {
  // utime 1700000000123456 us: more digits than a double holds after the point at
  // that magnitude; the table must still read back to the microsecond.
  const std::vector<std::int64_t> utimes = {1700000000123456, 1700000000123957, 1700000000124457};
  for (std::size_t i = 0; i < utimes.size(); ++i) {
    write("RESOLVER_ANGLE", encode(angle(utimes[i], 0.25 * static_cast<double>(i))), 5);  // log time ignored
  }
  const CsvExportResult r = export_csv();
  ASSERT_EQ(r.files.size(), 1U);
  EXPECT_EQ(r.files[0].channel, "RESOLVER_ANGLE");
  EXPECT_EQ(r.files[0].rows, 3);
  EXPECT_EQ(r.files[0].types, std::vector<std::string>{"resolver.angle_t"});
  const Table t = read_table(dir_ / "csv" / "RESOLVER_ANGLE.csv");
  EXPECT_EQ(t.header, (std::vector<std::string>{"utime_s", "sample_index", "counter", "theta_rd", "theta_sincos",
                                                "theta_comp", "theta_ref", "speed_mech_rad_s", "eps_hat", "eps_ref"}));
  EXPECT_EQ(r.files[0].columns, t.header.size());
  ASSERT_EQ(t.rows.size(), 3U);
  for (std::size_t i = 0; i < utimes.size(); ++i) {
    const resolver::angle_t a = angle(utimes[i], 0.25 * static_cast<double>(i));
    // Seconds to the microsecond, as text: integer seconds '.' six digits.
    const std::string& s = t.at(i, "utime_s");
    EXPECT_EQ(std::stoll(s.substr(0, s.find('.'))) * 1000000 + std::stoll(s.substr(s.find('.') + 1)), a.utime) << s;
    EXPECT_EQ(std::stoll(t.at(i, "sample_index")), a.sample_index);
    EXPECT_EQ(t.at(i, "counter"), "7");
    // Doubles read back bit for bit.
    EXPECT_EQ(t.number(i, "theta_rd"), a.theta_rd);
    EXPECT_EQ(t.number(i, "theta_sincos"), a.theta_sincos);
    EXPECT_EQ(t.number(i, "theta_comp"), a.theta_comp);
    EXPECT_EQ(t.number(i, "theta_ref"), a.theta_ref);
    EXPECT_EQ(t.number(i, "speed_mech_rad_s"), a.speed_mech_rad_s);
    EXPECT_EQ(t.number(i, "eps_hat"), a.eps_hat);
  }
}

TEST_F(EchoCsv, ArraysAreNumberedAndAGrowingArrayWidensTheTable) {
  resolver::estimate_t one{};
  one.utime = 2000000;
  one.method = "model";
  one.num_params = 1;
  one.param_name = {"amplitude_imbalance.alpha"};
  one.value = {0.003};
  one.std_error = {1e-6};
  one.converged = true;
  resolver::estimate_t three = one;
  three.utime = 3500000;
  three.num_params = 3;
  three.param_name = {"a", "b", "c"};
  three.value = {0.1, 0.2, std::numeric_limits<double>::quiet_NaN()};
  three.std_error = {1.0, std::numeric_limits<double>::infinity(), -std::numeric_limits<double>::infinity()};
  three.converged = false;
  write("RESOLVER_ESTIMATE", encode(one), 0);
  write("RESOLVER_ESTIMATE", encode(three), 0);
  export_csv();
  const Table t = read_table(dir_ / "csv" / "RESOLVER_ESTIMATE.csv");
  // Strings (method, param_name) are text, not numbers: left out.
  EXPECT_EQ(t.header, (std::vector<std::string>{"utime_s", "sample_index", "counter", "num_params", "value_0",
                                                "std_error_0", "samples_used", "revolutions_used", "converged",
                                                "value_1", "value_2", "std_error_1", "std_error_2"}));
  ASSERT_EQ(t.rows.size(), 2U);
  EXPECT_EQ(t.at(0, "utime_s"), "2.000000");
  EXPECT_EQ(t.at(1, "utime_s"), "3.500000");
  EXPECT_EQ(t.number(0, "value_0"), 0.003);
  EXPECT_EQ(t.at(0, "value_1"), "");  // the first message has one parameter
  EXPECT_EQ(t.at(0, "std_error_2"), "");
  EXPECT_EQ(t.at(0, "converged"), "1");
  EXPECT_EQ(t.at(1, "converged"), "0");
  EXPECT_EQ(t.number(1, "value_1"), 0.2);
  EXPECT_EQ(t.at(1, "value_2"), "NaN");
  EXPECT_EQ(t.at(1, "std_error_1"), "Inf");
  EXPECT_EQ(t.at(1, "std_error_2"), "-Inf");
  EXPECT_EQ(t.number(1, "num_params"), 3.0);
}

TEST_F(EchoCsv, NestedStructsAndMultiDimensionalArraysFlatten) {
  echo_test::node_t n{};
  n.utime = 42;
  n.first.a = -8;
  n.first.b = -1600;
  n.first.c = 320000;
  n.first.d = -(std::int64_t{1} << 53) - 1;  // not a double: the table keeps it exact
  n.first.f = 0.1F;
  n.first.g = -2.5e-7;
  n.first.s = "text";
  n.first.flag = true;
  n.first.raw = 200;
  n.first.rows = 2;
  n.first.cols = 3;
  n.first.grid = {{1, 2, 3}, {4, 5, 6}};
  n.first.fixed[1][2] = 77;
  n.first.blob = {9, 8, 7};
  n.first.names[0] = "x";
  n.first.names[1] = "y";
  n.n = 0;
  n.tree.value = 1;
  n.tree.num_children = 2;
  n.tree.children.resize(2);
  n.tree.children[0].value = 10;
  n.tree.children[1].value = 11;
  n.pair[1].c = 5;
  write("NODE", encode(n), 0);
  export_csv();
  const Table t = read_table(dir_ / "csv" / "NODE.csv");
  EXPECT_EQ(t.at(0, "utime_s"), "0.000042");
  EXPECT_EQ(t.at(0, "first_a"), "-8");
  EXPECT_EQ(t.at(0, "first_b"), "-1600");
  EXPECT_EQ(t.at(0, "first_c"), "320000");
  EXPECT_EQ(t.at(0, "first_d"), "-9007199254740993");
  EXPECT_EQ(static_cast<float>(t.number(0, "first_f")), 0.1F);
  EXPECT_EQ(t.number(0, "first_g"), -2.5e-7);
  EXPECT_EQ(t.at(0, "first_flag"), "1");
  EXPECT_EQ(t.at(0, "first_raw"), "200");
  for (int i = 0; i < 2; ++i) {
    for (int j = 0; j < 3; ++j) {
      EXPECT_EQ(t.number(0, "first_grid_" + std::to_string(i) + "_" + std::to_string(j)), n.first.grid[i][j]);
      EXPECT_EQ(t.number(0, "first_fixed_" + std::to_string(i) + "_" + std::to_string(j)), n.first.fixed[i][j]);
    }
  }
  EXPECT_EQ(t.at(0, "first_blob_2"), "7");
  EXPECT_EQ(t.at(0, "tree_num_children"), "2");
  EXPECT_EQ(t.at(0, "tree_children_0_value"), "10");
  EXPECT_EQ(t.at(0, "tree_children_1_num_children"), "0");
  EXPECT_EQ(t.at(0, "pair_1_c"), "5");
  for (const std::string& name : t.header) {
    EXPECT_NE(name, "first_s");
    EXPECT_EQ(name.rfind("first_names", 0), std::string::npos) << "strings are left out: " << name;
  }
  // Every numeric leaf: 4 scalars a..d, f, g, flag, raw, rows, cols; 6 grid, 6 fixed,
  // 3 blob; n; tree: value, num_children and 2 x (value, num_children); pair: 2 x
  // the 10 scalars + fixed 6 (empty grid and blob); plus utime_s.
  EXPECT_EQ(t.header.size(), 1U + (10 + 6 + 6 + 3) + 1 + (2 + 2 * 2) + 2 * (10 + 6));
}

TEST_F(EchoCsv, ATypeWithoutUtimeTakesTheLogsTime) {
  echo_test::leaf_t leaf{};
  leaf.c = 3;
  write("LEAF", encode(leaf), 1234567);
  write("LEAF", encode(leaf), -1500000);  // before the epoch: still exact
  export_csv();
  const Table t = read_table(dir_ / "csv" / "LEAF.csv");
  EXPECT_EQ(t.at(0, "utime_s"), "1.234567");
  EXPECT_EQ(t.at(1, "utime_s"), "-1.500000");
  EXPECT_EQ(t.at(0, "c"), "3");
}

TEST_F(EchoCsv, UndecodableMessagesAreCountedNotWritten) {
  write("RESOLVER_ANGLE", encode(angle(1000, 1.0)), 0);
  write("JUNK", {1, 2, 3, 4, 5, 6, 7, 8, 9, 10, 11, 12}, 0);
  const CsvExportResult r = export_csv();
  ASSERT_EQ(r.files.size(), 1U);
  EXPECT_EQ(r.undecoded, 1);
  EXPECT_NE(r.first_undecoded_error.find("unknown fingerprint"), std::string::npos) << r.first_undecoded_error;
  EXPECT_NE(r.first_undecoded_error.find("JUNK"), std::string::npos) << r.first_undecoded_error;
  EXPECT_FALSE(fs::exists(dir_ / "csv" / "JUNK.csv"));
}

TEST_F(EchoCsv, ChannelFilterAndLimit) {
  for (int i = 0; i < 4; ++i) write("RESOLVER_ANGLE", encode(angle(1000 + i, 0.0)), 0);
  resolver::estimate_t e{};
  write("RESOLVER_ESTIMATE", encode(e), 0);
  const CsvExportResult r = export_csv(make_echo_filter("RESOLVER_A.*", ""), 2);
  ASSERT_EQ(r.files.size(), 1U);
  EXPECT_EQ(r.files[0].rows, 2);
  EXPECT_EQ(read_table(dir_ / "csv" / "RESOLVER_ANGLE.csv").rows.size(), 2U);
  EXPECT_FALSE(fs::exists(dir_ / "csv" / "RESOLVER_ESTIMATE.csv"));
}

TEST_F(EchoCsv, ChannelNamesBecomeSafeDistinctFileNames) {
  EXPECT_EQ(csv_file_name("RESOLVER_ANGLE"), "RESOLVER_ANGLE.csv");
  EXPECT_EQ(csv_file_name("bench/left arm"), "bench_left_arm.csv");
  EXPECT_EQ(csv_file_name(".."), "_..csv");
  EXPECT_EQ(csv_file_name(""), "_.csv");
  write("A/B", encode(angle(1, 0.0)), 0);
  write("A_B", encode(angle(2, 0.0)), 0);
  const CsvExportResult r = export_csv();
  ASSERT_EQ(r.files.size(), 2U);
  EXPECT_EQ(fs::path(r.files[0].path).filename(), "A_B.csv");
  EXPECT_EQ(fs::path(r.files[1].path).filename(), "A_B-2.csv");
  EXPECT_EQ(read_table(r.files[1].path).at(0, "utime_s"), "0.000002");
}

TEST_F(EchoCsv, MalformedLogWritesNothing) {
  write("RESOLVER_ANGLE", encode(angle(1, 0.0)), 0);
  close_log();
  {
    std::ofstream junk(log_path_, std::ios::app | std::ios::binary);
    junk << "not an event";
  }
  EXPECT_THROW(export_csv(), EventLogError);
  EXPECT_FALSE(fs::exists(dir_ / "csv" / "RESOLVER_ANGLE.csv"));
}

TEST_F(EchoCsv, CommandLine) {
  write("RESOLVER_ANGLE", encode(angle(1000, 1.0)), 0);
  close_log();
  const std::string out = (dir_ / "out.txt").string();
  const std::string csv = (dir_ / "cli").string();
  EXPECT_EQ(run_status(kEchoBinary + " --log " + log_path_ + " --csv " + csv + " > " + out), 0);
  std::ifstream printed(out);
  std::string line;
  std::getline(printed, line);
  EXPECT_EQ(line, "wrote " + csv + "/RESOLVER_ANGLE.csv: 1 rows x 10 columns (resolver.angle_t on channel "
                  "RESOLVER_ANGLE)");
  EXPECT_EQ(read_table(csv + "/RESOLVER_ANGLE.csv").number(0, "theta_rd"), 1.0);
  // --csv is for a log; a file where the directory should be is an I/O error;
  // nothing matching the filter is no usable data.
  EXPECT_EQ(run_status(kEchoBinary + " --lcm memq:// --csv " + csv + " 2>/dev/null"), 2);
  EXPECT_EQ(run_status(kEchoBinary + " --log " + log_path_ + " --csv " + out + " 2>/dev/null"), 3);
  EXPECT_EQ(run_status(kEchoBinary + " --log " + log_path_ + " --channel NONE --csv " + csv + " 2>/dev/null"), 1);
}

}  // namespace
}  // namespace resolver
