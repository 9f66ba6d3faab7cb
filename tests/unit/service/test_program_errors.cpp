// The one exception -> exit code rule of every program (daemon/service/program_errors.h).
#include "daemon/service/program_errors.h"

#include <gtest/gtest.h>

#include <filesystem>
#include <new>
#include <sstream>
#include <stdexcept>
#include <string>
#include <system_error>

namespace resolver {
namespace {

template <class E>
std::pair<int, std::string> mapped(const E& error) {
  std::string message;
  const int code = exit_code_for(std::make_exception_ptr(error), message);
  return {code, message};
}

TEST(ProgramErrors, InputErrorSaysWhoseFaultAndWhere) {
  Where w = Where::at_file("bench.log", 12);
  w.option = "--effects";
  w.signal = "sin";
  const auto [code, message] = mapped(InputError(Fault::kData, "clipped", w));
  EXPECT_EQ(code, exit_code::kNoUsableData);
  EXPECT_EQ(message, "bench.log:12: --effects: signal 'sin': clipped");
  EXPECT_EQ(mapped(InputError(Fault::kUsage, "bad", Where::at_option("--to"))),
            std::make_pair(exit_code::kUsage, std::string("--to: bad")));
  EXPECT_EQ(mapped(InputError(Fault::kUsage, "no where")).second, "no where");
}

TEST(ProgramErrors, WhereSpansLinesAndTheMessageStandsAlone) {
  Where rows = Where::at_file("scope.csv", 2);
  rows.last_line = 202;
  const InputError e(Fault::kUsage, "time column too coarse", rows);
  EXPECT_STREQ(e.what(), "scope.csv:2-202: time column too coarse");
  EXPECT_EQ(e.message(), "time column too coarse");
  EXPECT_EQ(e.where().last_line, 202U);
  rows.last_line = 2;  // one line: no range
  EXPECT_STREQ(InputError(Fault::kUsage, "x", rows).what(), "scope.csv:2: x");
  const auto [code, message] = mapped(IoError("cannot read [layout] dbc a.dbc: gone", Where::at_file("b.toml")));
  EXPECT_EQ(code, exit_code::kIo);
  EXPECT_EQ(message, "b.toml: cannot read [layout] dbc a.dbc: gone");
}

TEST(ProgramErrors, LibraryArgumentCheckIsUsage) {
  EXPECT_EQ(mapped(std::invalid_argument("'x' is not an effect")),
            std::make_pair(exit_code::kUsage, std::string("'x' is not an effect")));
}

TEST(ProgramErrors, SystemAndFilesystemErrorsAreIo) {
  const auto [code, message] = mapped(std::system_error(ENOENT, std::generic_category(), "cannot open a.log"));
  EXPECT_EQ(code, exit_code::kIo);
  EXPECT_EQ(message, "cannot open a.log: No such file or directory");
  EXPECT_EQ(mapped(std::filesystem::filesystem_error("copy", std::make_error_code(std::errc::permission_denied))).first,
            exit_code::kIo);
  EXPECT_EQ(mapped(IoError("cannot write x.mat: matio failed")),
            std::make_pair(exit_code::kIo, std::string("cannot write x.mat: matio failed")));
}

TEST(ProgramErrors, OutOfMemoryHasItsOwnCodeAndSaysSo) {
  const auto [code, message] = mapped(std::bad_alloc());
  EXPECT_EQ(code, exit_code::kOutOfMemory);
  EXPECT_NE(message.find("out of memory"), std::string::npos) << message;
  EXPECT_EQ(message.find("bad_alloc"), std::string::npos) << "no bare std::bad_alloc: " << message;
}

TEST(ProgramErrors, AnythingElseIsInternal) {
  const auto [code, message] = mapped(std::runtime_error("vector::_M_range_check"));
  EXPECT_EQ(code, exit_code::kInternal);
  EXPECT_EQ(message.rfind("internal error: vector::_M_range_check", 0), 0U) << message;
  EXPECT_EQ(mapped(42).first, exit_code::kInternal);
}

TEST(ProgramErrors, RunProgramPrintsOneLineWithTheProgramName) {
  std::ostringstream err;
  EXPECT_EQ(report_exception("resolver-model", std::make_exception_ptr(InputError(Fault::kData, "too few samples",
                                                                                  Where::at_file("a.log"))),
                             err),
            exit_code::kNoUsableData);
  EXPECT_EQ(err.str(), "resolver-model: a.log: too few samples\n");
  EXPECT_EQ(run_program("p", [] { return 7; }), 7);
  testing::internal::CaptureStderr();
  EXPECT_EQ(run_program("p", []() -> int { throw std::bad_alloc(); }), exit_code::kOutOfMemory);
  const std::string printed = testing::internal::GetCapturedStderr();
  EXPECT_EQ(printed.rfind("p: out of memory", 0), 0U) << printed;
  EXPECT_EQ(printed.find('\n'), printed.size() - 1) << "one line: " << printed;
}

}  // namespace
}  // namespace resolver
