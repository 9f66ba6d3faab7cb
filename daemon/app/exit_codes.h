// The command-line side of the exit codes (daemon/service/program_errors.h has
// the codes, their --help paragraph and the exception -> code rule): CLI11's
// parse errors, and what is checked before anything is read: unreadable files
// (IoError) and a --to before --from (InputError, usage), both of
// daemon/core/errors.h, which the one rule maps.
//
// CLI11's own codes (105 for a missing --config file, 106 for a missing
// option, ...) never leave a program: parse_command_line() maps them.
#pragma once

#include <sys/stat.h>
#include <unistd.h>

#include <cerrno>
#include <cstring>
#include <iostream>
#include <optional>
#include <string>

#include <CLI/CLI.hpp>
#include <fmt/format.h>

#include "daemon/decode/sample_slice.h"
#include "daemon/service/program_errors.h"

namespace resolver::exit_code {

/// Parses the command line. Returns nullopt to go on, or the code to exit with:
/// 0 after --help (printed), kUsage after printing CLI11's message.
[[nodiscard]] inline std::optional<int> parse_command_line(CLI::App& app, int argc, const char* const* argv) {
  try {
    app.parse(argc, argv);
  } catch (const CLI::ParseError& e) {
    const int cli = app.exit(e);  // prints --help, or the error and "Run with --help"
    return cli == 0 ? kDone : kUsage;
  }
  return std::nullopt;
}

/// Returns when `path` exists, may be read and is not a directory; else throws IoError
/// (exit 3) "[WHERE: ]cannot read <option> <path>: <strerror>" or "...: it is a
/// directory, not a file" (a directory opens and reads as an empty file: a config would
/// silently be all defaults). `where` names what named the path (the config file of a
/// [layout] dbc). access(2) and stat(2), not open(2): opening a FIFO would briefly be
/// its reader and let a waiting writer write into a pipe nobody reads.
inline void require_readable(const std::string& option, const std::string& path, const Where& where = {}) {
  if (::access(path.c_str(), R_OK) != 0) {
    throw IoError("cannot read " + option + " " + path + ": " + std::strerror(errno), where);
  }
  struct stat st {};
  if (::stat(path.c_str(), &st) == 0 && S_ISDIR(st.st_mode)) {
    throw IoError("cannot read " + option + " " + path + ": it is a directory, not a file", where);
  }
}

/// Returns when --to is not before --from; else throws InputError (usage, option
/// --to) "--to: T s is before --from F s" (exit 2).
inline void require_slice(const SampleSlice& slice) {
  if (slice.to_s < slice.from_s) {
    throw InputError(Fault::kUsage, fmt::format("{:g} s is before --from {:g} s", slice.to_s, slice.from_s),
                     Where::at_option("--to"));
  }
}

}  // namespace resolver::exit_code
