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
// The error types (InputError with its Fault and Where, IoError) live in
// daemon/core/errors.h, the one header every layer may include; exceptions map to
// the codes here, in one place, exit_code_for():
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

#include <exception>
#include <iostream>
#include <string>
#include <string_view>
#include <utility>

#include "daemon/core/errors.h"

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
