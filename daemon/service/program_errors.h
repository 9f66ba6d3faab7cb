// The one error rule of every program (resolverd, resolver-model, resolver-sim,
// resolver-echo, resolver-accuracy; resolver-spy, a shell script, keeps the same
// numbers by hand): what an exception means to the person who ran the program,
// and the exit code a script sees for it.
//
//   0  done
//   1  the input had no usable data (nothing decoded, too few samples, a damaged log)
//   2  usage or configuration error (bad option, bad config file or DBC, a misspelt effect)
//   3  I/O error (a file missing or unreadable, a directory for a file, a write that failed,
//      a --state-dir missing, unwritable or locked, a FIFO given where the file is read twice)
//   4  out of memory (std::bad_alloc: the input is larger than the memory the program may use)
//   70 internal error (an unexpected exception: a bug, please report it; sysexits.h EX_SOFTWARE)
//
// Exceptions map to them in one place, exit_code_for():
//   InputError                 its fault(): kData -> 1, kUsage -> 2 (ConfigError is one, kUsage)
//   std::invalid_argument      2: a library function refused an argument the caller passed on
//                              from the command line or config (a program that hands the
//                              library its input data wraps those calls: see InputError)
//   std::bad_alloc             4
//   std::system_error          3 (std::filesystem::filesystem_error and std::ios_base::failure
//                              are system_errors; the readers and writers throw one per failed call)
//   anything else              70
// Every program's main is `return resolver::run_program("NAME", [&] { return run(argc, argv); });`,
// so an exception that nothing else caught prints one line "NAME: ..." and exits with its code.
#pragma once

#include <cstdint>
#include <exception>
#include <iostream>
#include <stdexcept>
#include <string>
#include <string_view>
#include <system_error>
#include <utility>

namespace resolver {

namespace exit_code {

inline constexpr int kDone = 0;
inline constexpr int kNoUsableData = 1;
inline constexpr int kUsage = 2;
inline constexpr int kIo = 3;
inline constexpr int kOutOfMemory = 4;
inline constexpr int kInternal = 70;  // sysexits.h EX_SOFTWARE

/// The paragraph every --help ends with (and README's "Exit codes" table says the same).
inline constexpr const char* kHelpText =
    "Exit codes: 0 done; 1 the input had no usable data; 2 usage or configuration error; "
    "3 I/O error (a file missing or unreadable, a write failed); 4 out of memory; 70 internal error (a bug).";

}  // namespace exit_code

/// Whose fault an InputError is: the data read, or how the program was called / configured.
enum class Fault { kData, kUsage };

/// Where the fault is; every part optional (empty / 0 = not known).
struct Where {
  std::string file;        ///< the file read (log, config, DBC, table)
  std::uint64_t line = 0;  ///< 1-based line in `file`
  std::string option;      ///< the command-line option or config key ("--effects", "[model] effects")
  std::string signal;      ///< the CAN / DBC signal or CSV column concerned

  [[nodiscard]] static Where at_file(std::string file, std::uint64_t line = 0) {
    Where w;
    w.file = std::move(file);
    w.line = line;
    return w;
  }
  [[nodiscard]] static Where at_option(std::string option) {
    Where w;
    w.option = std::move(option);
    return w;
  }
};

/// A fault of the input data (exit 1) or of the usage or configuration (exit 2).
/// what() is "FILE:LINE: OPTION: signal 'SIGNAL': MESSAGE", with the parts known.
class InputError : public std::runtime_error {
 public:
  InputError(Fault fault, const std::string& message, Where where = {})
      : std::runtime_error(compose(message, where)), fault_(fault), where_(std::move(where)) {}

  [[nodiscard]] Fault fault() const noexcept { return fault_; }
  [[nodiscard]] const Where& where() const noexcept { return where_; }

 private:
  static std::string compose(const std::string& message, const Where& w) {
    std::string out;
    if (!w.file.empty()) out += w.file + (w.line > 0 ? ":" + std::to_string(w.line) : std::string()) + ": ";
    if (!w.option.empty()) out += w.option + ": ";
    if (!w.signal.empty()) out += "signal '" + w.signal + "': ";
    return out + message;
  }

  Fault fault_;
  Where where_;
};

/// An I/O failure with no errno to tell (a library such as LCM or matio said no):
/// a std::system_error (exit 3) whose what() is `message` alone.
class IoError : public std::system_error {
 public:
  explicit IoError(const std::string& message) : std::system_error(std::make_error_code(std::errc::io_error)), message_(message) {}
  [[nodiscard]] const char* what() const noexcept override { return message_.c_str(); }

 private:
  std::string message_;
};

/// The exit code for `error` (the table above) and the one line to print after
/// "PROGRAM: ". Never throws; allocates nothing for std::bad_alloc.
[[nodiscard]] int exit_code_for(const std::exception_ptr& error, std::string& message) noexcept;

/// Prints "PROGRAM: MESSAGE" for `error` to `err` and returns its exit code.
int report_exception(std::string_view program, const std::exception_ptr& error, std::ostream& err) noexcept;

/// Runs `body` (a program's main) and maps whatever it throws: every main's last word.
template <class Body>
int run_program(std::string_view program, Body&& body) noexcept {
  try {
    return std::forward<Body>(body)();
  } catch (...) {
    return report_exception(program, std::current_exception(), std::cerr);
  }
}

}  // namespace resolver
