// The persisted calibration: exact round trip, atomic replacement, and every
// kind of bad file rejected with its reason (never loaded, never a crash).
#include <gtest/gtest.h>

#include <sys/stat.h>
#include <unistd.h>

#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <limits>
#include <optional>
#include <random>
#include <sstream>
#include <string>

#include "daemon/service/calibration_store.h"
#include "daemon/service/program_errors.h"
#include "daemon/service/state_dir_lock.h"

namespace resolver {
namespace {

namespace fs = std::filesystem;
using Status = LoadResult::Status;

class TempDir {
 public:
  TempDir() {
    char tmpl[] = "/tmp/resolverd-cal.XXXXXX";
    const char* dir = ::mkdtemp(tmpl);
    EXPECT_NE(dir, nullptr);
    path_ = dir != nullptr ? dir : "/tmp/resolverd-cal-failed";
  }
  ~TempDir() {
    ::chmod(path_.c_str(), 0700);
    std::error_code ec;
    fs::remove_all(path_, ec);
  }
  TempDir(const TempDir&) = delete;
  TempDir& operator=(const TempDir&) = delete;
  [[nodiscard]] const std::string& path() const { return path_; }

 private:
  std::string path_;
};

std::string read_file(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  std::ostringstream s;
  s << in.rdbuf();
  return s.str();
}

void write_file(const std::string& path, const std::string& text) {
  std::ofstream out(path, std::ios::binary | std::ios::trunc);
  out << text;
  ASSERT_TRUE(out.good()) << path;
}

/// A persisted parameter: the file keeps name, value and standard error.
ModelParameter param(std::string name, double value, double std_error) {
  return ModelParameter{.name = std::move(name), .value = value, .std_error = std_error, .unit = ""};
}

Calibration sample_calibration() {
  Calibration c;
  c.p_r = 1;
  c.p = 4;
  c.method = "hwang_integral";
  c.samples = 1'234'567;
  // Values whose decimal form is not short: the round trip must be bit-exact.
  c.params = {param("amplitude_imbalance.alpha", 1.0 / 3.0, 2.5e-5),
              param("quadrature.beta", -0.0123456789012345678, 1e-300),
              param("offsets.o_s", 5e-324, 0.0),
              param("offsets.o_c", -std::numeric_limits<double>::max(), std::numeric_limits<double>::max())};
  return c;
}

std::string formatted(const Calibration& c) { return format_calibration(c); }

/// What `f` threw as an E ("" and a test failure when it threw nothing).
template <class E, class F>
std::string thrown(F f) {
  try {
    f();
  } catch (const E& e) {
    return e.what();
  }
  ADD_FAILURE() << "nothing thrown";
  return "";
}

/// Replaces the checksum line so a hand-edited text is internally consistent.
std::string with_fresh_checksum(const std::string& text) {
  const auto crc_at = text.rfind("crc32 ");
  const std::string body = text.substr(0, crc_at);
  char crc[16];
  std::snprintf(crc, sizeof crc, "%08x", static_cast<unsigned>(crc32_ieee(body)));
  return body + "crc32 " + crc + "\n";
}

std::string replace_once(std::string text, const std::string& from, const std::string& to) {
  const auto at = text.find(from);
  EXPECT_NE(at, std::string::npos) << from;
  if (at != std::string::npos) text.replace(at, from.size(), to);
  return text;
}

LoadResult load_text(const TempDir& dir, const std::string& text) {
  write_file(calibration_path(dir.path()), text);
  return load_calibration(dir.path());
}

void expect_rejected(const LoadResult& r, const std::string& reason_part) {
  EXPECT_EQ(r.status, Status::kRejected);
  EXPECT_FALSE(r.calibration.has_value());
  EXPECT_NE(r.problem.find(reason_part), std::string::npos) << "problem: " << r.problem;
  EXPECT_NE(r.problem.find("calibration.txt"), std::string::npos) << "problem names no file: " << r.problem;
}

TEST(Crc32, CheckValue) {
  EXPECT_EQ(crc32_ieee("123456789"), 0xCBF43926U);  // the CRC-32 catalogue check value
  EXPECT_EQ(crc32_ieee(""), 0U);
}

TEST(CalibrationStore, RoundTripIsExact) {
  TempDir dir;
  const Calibration c = sample_calibration();
  ASSERT_NO_THROW(save_calibration(dir.path(), c));
  const LoadResult r = load_calibration(dir.path());
  ASSERT_EQ(r.status, Status::kLoaded) << r.problem;
  ASSERT_TRUE(r.calibration);
  EXPECT_TRUE(r.problem.empty());
  EXPECT_EQ(*r.calibration, c);
  // Bitwise, not just ==: -0.0 == 0.0 would hide a sign loss.
  for (std::size_t i = 0; i < c.params.size(); ++i) {
    EXPECT_EQ(std::signbit(r.calibration->params[i].value), std::signbit(c.params[i].value));
  }
}

TEST(CalibrationStore, RandomizedRoundTrip) {
  TempDir dir;
  std::mt19937_64 rng(20240611);
  std::uniform_real_distribution<double> mantissa(-1.0, 1.0);
  std::uniform_int_distribution<int> exponent(-300, 300);
  std::uniform_int_distribution<int> count(0, 12);
  std::uniform_int_distribution<int> poles(1, 255);
  for (int trial = 0; trial < 200; ++trial) {
    Calibration c;
    c.p_r = poles(rng);
    c.p = poles(rng);
    c.method = trial % 3 == 0 ? "" : "fourier fit #" + std::to_string(trial);
    c.samples = static_cast<std::int64_t>(rng() >> 2);
    const int n = count(rng);
    for (int i = 0; i < n; ++i) {
      c.params.push_back(param("effect_" + std::to_string(i) + ".k", std::ldexp(mantissa(rng), exponent(rng)),
                               std::fabs(std::ldexp(mantissa(rng), exponent(rng)))));
    }
    ASSERT_NO_THROW(save_calibration(dir.path(), c));
    const LoadResult r = load_calibration(dir.path());
    ASSERT_EQ(r.status, Status::kLoaded) << r.problem;
    ASSERT_EQ(*r.calibration, c) << "trial " << trial;
  }
}

TEST(CalibrationStore, FileLayout) {
  const std::string text = formatted(sample_calibration());
  EXPECT_EQ(text.substr(0, text.find('\n')), "resolverd-calibration");
  EXPECT_NE(text.find("\nformat 3\n"), std::string::npos);
  EXPECT_NE(text.find("\np_r 1\np 4\nmethod hwang_integral\nsamples 1234567\n"), std::string::npos) << text;
  EXPECT_NE(text.find("\nparam amplitude_imbalance.alpha 0.3333333333333333 2.5e-05\n"), std::string::npos) << text;
  const auto last = text.rfind("crc32 ");
  ASSERT_NE(last, std::string::npos);
  EXPECT_EQ(text.size() - last, std::string("crc32 01234567\n").size());
}

TEST(CalibrationStore, MissingFileIsNotAnError) {
  TempDir dir;
  const LoadResult r = load_calibration(dir.path());
  EXPECT_EQ(r.status, Status::kMissing);
  EXPECT_FALSE(r.calibration);
  EXPECT_NE(r.problem.find(calibration_path(dir.path())), std::string::npos) << r.problem;
}

TEST(CalibrationStore, LeftoverTempFileIsIgnoredAndReplaced) {
  TempDir dir;
  const Calibration old_cal = sample_calibration();
  ASSERT_NO_THROW(save_calibration(dir.path(), old_cal));
  // A crash between writing the temp file and the rename leaves this behind.
  Calibration newer = old_cal;
  newer.params[0].value = 0.5;
  const std::string temp = calibration_path(dir.path()) + ".tmp";
  write_file(temp, formatted(newer).substr(0, 40));  // half-written
  LoadResult r = load_calibration(dir.path());
  ASSERT_EQ(r.status, Status::kLoaded) << r.problem;
  EXPECT_EQ(*r.calibration, old_cal);
  // The next save overwrites the stale temp file and leaves none behind.
  ASSERT_NO_THROW(save_calibration(dir.path(), newer));
  EXPECT_FALSE(fs::exists(temp));
  r = load_calibration(dir.path());
  ASSERT_EQ(r.status, Status::kLoaded) << r.problem;
  EXPECT_EQ(*r.calibration, newer);
  std::size_t files = 0;
  for ([[maybe_unused]] const auto& entry : fs::directory_iterator(dir.path())) ++files;
  EXPECT_EQ(files, 1U);
}

TEST(CalibrationStore, RefusedSaveKeepsThePreviousFile) {
  TempDir dir;
  const Calibration good = sample_calibration();
  ASSERT_NO_THROW(save_calibration(dir.path(), good));
  const std::string before = read_file(calibration_path(dir.path()));
  Calibration bad = good;
  bad.params[1].value = std::nan("");
  const std::string err = thrown<InputError>([&] { save_calibration(dir.path(), bad); });
  EXPECT_NE(err.find("quadrature.beta"), std::string::npos) << err;
  EXPECT_NE(err.find("finite"), std::string::npos) << err;
  EXPECT_EQ(read_file(calibration_path(dir.path())), before);
}

TEST(CalibrationStore, InvalidCalibrationsAreRefusedWithReason) {
  Calibration c = sample_calibration();
  c.p_r = 0;
  EXPECT_NE(thrown<InputError>([&] { (void)format_calibration(c); }).find("p_r=0"), std::string::npos);
  c = sample_calibration();
  c.params[0].name = "has space";
  EXPECT_NE(thrown<InputError>([&] { (void)format_calibration(c); }).find("has space"), std::string::npos);
  c = sample_calibration();
  c.params[1].name = c.params[0].name;
  EXPECT_NE(thrown<InputError>([&] { (void)format_calibration(c); }).find("twice"), std::string::npos);
  c = sample_calibration();
  c.params[0].std_error = -1.0;
  EXPECT_THROW((void)format_calibration(c), InputError);
  c = sample_calibration();
  c.method = "two\nlines";
  EXPECT_THROW((void)format_calibration(c), InputError);
  c = sample_calibration();
  c.samples = -1;
  EXPECT_THROW((void)format_calibration(c), InputError);
}

TEST(CalibrationStore, CorruptFileRejected) {
  TempDir dir;
  const std::string good = formatted(sample_calibration());
  // One changed digit in a value: only the checksum can notice.
  const LoadResult r = load_text(dir, replace_once(good, "0.3333333333333333", "0.3333333333333334"));
  expect_rejected(r, "checksum mismatch");
}

TEST(CalibrationStore, EverySingleByteFlipIsRejected) {
  TempDir dir;
  const std::string good = formatted(sample_calibration());
  for (std::size_t i = 0; i < good.size(); ++i) {
    std::string bad = good;
    bad[i] = static_cast<char>(bad[i] ^ 0x04);
    const LoadResult r = load_text(dir, bad);
    ASSERT_EQ(r.status, Status::kRejected) << "flip at byte " << i << " was accepted";
    ASSERT_FALSE(r.problem.empty());
  }
}

TEST(CalibrationStore, TruncatedFileRejected) {
  TempDir dir;
  const std::string good = formatted(sample_calibration());
  expect_rejected(load_text(dir, good.substr(0, good.size() / 2)), "truncated");
  expect_rejected(load_text(dir, good.substr(0, good.size() - 1)), "truncated");
  expect_rejected(load_text(dir, good.substr(0, 10)), "truncated");
  expect_rejected(load_text(dir, ""), "empty");
  // No prefix at all is ever accepted.
  for (std::size_t n = 0; n < good.size(); ++n) {
    const LoadResult r = load_text(dir, good.substr(0, n));
    ASSERT_EQ(r.status, Status::kRejected) << "prefix of " << n << " bytes was accepted";
  }
}

TEST(CalibrationStore, ForeignFileRejected) {
  TempDir dir;
  expect_rejected(load_text(dir, "{\"alpha\": 0.01}\n"), "not a resolverd calibration file");
  expect_rejected(load_text(dir, "[calibration]\nalpha = 0.01\n"), "'[calibration]'");
  std::string binary(300, '\0');
  for (std::size_t i = 0; i < binary.size(); ++i) binary[i] = static_cast<char>(i * 37);
  expect_rejected(load_text(dir, binary), "not a resolverd calibration file");
}

TEST(CalibrationStore, WrongVersionRejected) {
  TempDir dir;
  // A self-consistent future file: right magic, valid checksum, version 4.
  const std::string v4 = with_fresh_checksum(replace_once(formatted(sample_calibration()), "\nformat 3\n", "\nformat 4\n"));
  const LoadResult r = load_text(dir, v4);
  expect_rejected(r, "format version 4");
  EXPECT_NE(r.problem.find("only versions 3, 2 and 1"), std::string::npos) << r.problem;
  // Version is checked before the checksum, so the reason is the version.
  expect_rejected(load_text(dir, replace_once(formatted(sample_calibration()), "\nformat 3\n", "\nformat 7\n")),
                  "format version 7");
}

TEST(CalibrationStore, VersionOneFilesAreStillRead) {
  TempDir dir;
  // What the previous release wrote: no model line.
  const std::string v1 = with_fresh_checksum(replace_once(formatted(sample_calibration()), "\nformat 3\n", "\nformat 1\n"));
  const LoadResult r = load_text(dir, v1);
  ASSERT_EQ(r.status, Status::kLoaded) << r.problem;
  EXPECT_EQ(*r.calibration, sample_calibration());
}

TEST(CalibrationStore, TheWholeModelRoundTrips) {
  TempDir dir;
  Calibration c = sample_calibration();
  c.method = "model";
  c.model = {"amplitude_imbalance", "harmonics(k5,k3_opp)", "drift"};
  c.custom = {{"drift", "position_error", {"t", "t*sin(2*theta)"}}};
  c.params.push_back(param("harmonics.k5", 1e-4, std::nan("")));  // not identifiable: kept as nan
  ASSERT_NO_THROW(save_calibration(dir.path(), c));
  const LoadResult r = load_calibration(dir.path());
  ASSERT_EQ(r.status, Status::kLoaded) << r.problem;
  EXPECT_EQ(r.calibration->model, c.model);
  EXPECT_EQ(r.calibration->custom, c.custom);
  ASSERT_EQ(r.calibration->params.size(), c.params.size());
  EXPECT_TRUE(std::isnan(r.calibration->params.back().std_error));
  c.model = {"bad reference"};
  EXPECT_THROW(save_calibration(dir.path(), c), InputError);
}

TEST(CalibrationStore, ConsistentButInvalidContentRejected) {
  TempDir dir;
  const std::string good = formatted(sample_calibration());
  expect_rejected(load_text(dir, with_fresh_checksum(replace_once(good, "\np 4\n", "\np 0\n"))), "pole-pair");
  expect_rejected(load_text(dir, with_fresh_checksum(replace_once(good, "\np 4\n", "\n"))), "missing p)");
  expect_rejected(load_text(dir, with_fresh_checksum(replace_once(good, "2.5e-05", "inf"))),
                  "not 'param NAME VALUE STD_ERROR'");
  expect_rejected(load_text(dir, with_fresh_checksum(replace_once(good, "quadrature.beta", "amplitude_imbalance.alpha"))),
                  "appears twice");
  expect_rejected(load_text(dir, with_fresh_checksum(replace_once(good, "\nsamples ", "\nwhatever 1\nsamples "))),
                  "unknown key 'whatever'");
}

TEST(CalibrationStore, OversizedAndNonRegularFilesRejected) {
  TempDir dir;
  std::string huge = "resolverd-calibration\n";
  huge.resize(2u << 20, '#');
  expect_rejected(load_text(dir, huge), "far larger");
  fs::remove(calibration_path(dir.path()));
  fs::create_directory(calibration_path(dir.path()));
  expect_rejected(load_calibration(dir.path()), "not a regular file");
}

TEST(CalibrationStore, AFifoInPlaceOfTheFileDoesNotBlock) {
  // Opening a FIFO for reading waits for a writer; the load must refuse it at once.
  TempDir dir;
  ASSERT_EQ(::mkfifo(calibration_path(dir.path()).c_str(), 0644), 0);
  const LoadResult r = load_calibration(dir.path());
  expect_rejected(r, "not a regular file (a FIFO)");
  // The next save replaces it with a file.
  ASSERT_NO_THROW(save_calibration(dir.path(), sample_calibration()));
  EXPECT_EQ(load_calibration(dir.path()).status, Status::kLoaded);
}

TEST(CalibrationStore, ProvenanceRoundTripsOnOneLineEach) {
  TempDir dir;
  Calibration c = sample_calibration();
  c.provenance = {"/etc/resolverd/bench 2.toml", "5e1f00aa", "0badcafe", "the default bench layout (x: y = z)",
                  "/var/log/run.log", "2026-11-26T01:44:32Z", "resolverd 0.1.0 (git 7d43eb5)"};
  ASSERT_NO_THROW(save_calibration(dir.path(), c));
  const LoadResult r = load_calibration(dir.path());
  ASSERT_EQ(r.status, Status::kLoaded) << r.problem;
  EXPECT_EQ(r.calibration->provenance, c.provenance);
  // A line break in a path cannot split the record: it is saved as '?'.
  c.provenance.source = "/tmp/odd\nname.log";
  ASSERT_NO_THROW(save_calibration(dir.path(), c));
  const LoadResult odd = load_calibration(dir.path());
  ASSERT_EQ(odd.status, Status::kLoaded) << odd.problem;
  EXPECT_EQ(odd.calibration->provenance.source, "/tmp/odd?name.log");
}

TEST(CalibrationStore, SetAsideKeepsTheFileUnderANewName) {
  TempDir dir;
  ASSERT_NO_THROW(save_calibration(dir.path(), sample_calibration()));
  std::string moved;
  ASSERT_NO_THROW(moved = set_calibration_aside(dir.path(), "refused-x"));
  EXPECT_EQ(moved, calibration_path(dir.path()) + ".refused-x");
  EXPECT_TRUE(fs::exists(moved));
  EXPECT_EQ(load_calibration(dir.path()).status, Status::kMissing);
  const std::string err = thrown<IoError>([&] { (void)set_calibration_aside(dir.path(), "again"); });
  EXPECT_NE(err.find("No such file"), std::string::npos) << err;
}

TEST(StateDirLock, SecondHolderIsRefusedNamingThePid) {
  TempDir dir;
  std::optional<StateDirLock> first;
  ASSERT_NO_THROW(first = StateDirLock::acquire(dir.path()));
  // flock locks belong to the open file description: a second open in this process
  // conflicts just as another process would.
  const std::string problem = thrown<IoError>([&] { (void)StateDirLock::acquire(dir.path()); });
  EXPECT_NE(problem.find("in use by another resolverd, pid " + std::to_string(::getpid())), std::string::npos)
      << problem;
  EXPECT_NE(problem.find(dir.path() + "/resolverd.lock"), std::string::npos) << problem;
  first.reset();  // released: the next one gets it
  EXPECT_NO_THROW((void)StateDirLock::acquire(dir.path()));
}

TEST(StateDirLock, MissingDirectoryAndFifoAreRefusedWithoutBlocking) {
  TempDir dir;
  std::string problem = thrown<IoError>([&] { (void)StateDirLock::acquire(dir.path() + "/nope"); });
  EXPECT_NE(problem.find("No such file or directory"), std::string::npos) << problem;
  ASSERT_EQ(::mkfifo((dir.path() + "/resolverd.lock").c_str(), 0644), 0);
  problem = thrown<IoError>([&] { (void)StateDirLock::acquire(dir.path()); });
  EXPECT_NE(problem.find("not a regular file"), std::string::npos) << problem;
}

TEST(CalibrationStore, MissingDirectoryErrorSaysWhatAndWhatToDo) {
  TempDir dir;
  const std::string missing = dir.path() + "/no-such-dir";
  const std::string err = thrown<IoError>([&] { save_calibration(missing, sample_calibration()); });
  EXPECT_NE(err.find(missing + "/calibration.txt.tmp"), std::string::npos) << err;
  EXPECT_NE(err.find("No such file or directory"), std::string::npos) << err;
  EXPECT_NE(err.find("--state-dir"), std::string::npos) << err;
}

TEST(CalibrationStore, DirectoryThatIsAFileErrors) {
  TempDir dir;
  const std::string file = dir.path() + "/plain-file";
  write_file(file, "x");
  const std::string err = thrown<IoError>([&] { save_calibration(file, sample_calibration()); });
  EXPECT_NE(err.find("Not a directory"), std::string::npos) << err;
}

TEST(CalibrationStore, ReadOnlyDirectoryErrors) {
  if (::geteuid() == 0) GTEST_SKIP() << "running as root: directory permissions do not stop root from writing";
  TempDir dir;
  ASSERT_EQ(::chmod(dir.path().c_str(), 0500), 0);
  const std::string err = thrown<IoError>([&] { save_calibration(dir.path(), sample_calibration()); });
  EXPECT_NE(err.find("Permission denied"), std::string::npos) << err;
  EXPECT_NE(err.find("writable"), std::string::npos) << err;
}

TEST(CalibrationStore, TrailingSlashInDirectory) {
  TempDir dir;
  ASSERT_NO_THROW(save_calibration(dir.path() + "/", sample_calibration()));
  EXPECT_EQ(load_calibration(dir.path()).status, Status::kLoaded);
}

}  // namespace
}  // namespace resolver
