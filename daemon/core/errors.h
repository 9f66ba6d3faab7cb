// The typed errors every layer throws (docs/ARCHITECTURE.md §2 and §9): the one
// header all layers may include, so the DBC reader, the decoders, the drivers,
// the service and the programs report a fault the same way. It says whose fault
// it is (the data read, or how the program was called and configured) and where
// (file, line, option, signal); which exit code that is, and the one line a
// program prints for it, is decided once, above every library, in
// daemon/service/program_errors.h (exit_code_for, run_program).
//
// The standard library only: no project include, no I/O.
#pragma once

#include <cstdint>
#include <stdexcept>
#include <string>
#include <system_error>
#include <utility>

namespace resolver {

/// Whose fault an InputError is: the data read, or how the program was called / configured.
enum class Fault { kData, kUsage };

/// Where the fault is; every part optional (empty / 0 = not known).
struct Where {
  std::string file;             ///< the file read (log, config, DBC, table)
  std::uint64_t line = 0;       ///< 1-based line in `file`
  std::uint64_t last_line = 0;  ///< the last line when the fault spans lines from `line` (0: one line)
  std::string option;           ///< the command-line option or config key ("--effects", "[model] effects")
  std::string signal;           ///< the CAN / DBC signal or CSV column concerned

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

  /// "FILE:LINE[-LAST]: OPTION: signal 'SIGNAL': " with the parts known ("" when none is).
  [[nodiscard]] std::string prefix() const {
    std::string out;
    if (!file.empty()) {
      out += file;
      if (line > 0) out += ":" + std::to_string(line);
      if (line > 0 && last_line > line) out += "-" + std::to_string(last_line);
      out += ": ";
    }
    if (!option.empty()) out += option + ": ";
    if (!signal.empty()) out += "signal '" + signal + "': ";
    return out;
  }
};

/// A fault of the input data (exit 1) or of the usage or configuration (exit 2).
/// what() is "FILE:LINE: OPTION: signal 'SIGNAL': MESSAGE", with the parts known.
class InputError : public std::runtime_error {
 public:
  InputError(Fault fault, const std::string& message, Where where = {})
      : std::runtime_error(where.prefix() + message), fault_(fault), where_(std::move(where)), message_(message) {}

  [[nodiscard]] Fault fault() const noexcept { return fault_; }
  [[nodiscard]] const Where& where() const noexcept { return where_; }
  /// What went wrong and what to do, without the where.
  [[nodiscard]] const std::string& message() const noexcept { return message_; }

 private:
  Fault fault_;
  Where where_;
  std::string message_;
};

/// An I/O failure (exit 3) whose text is already written: a library such as LCM or
/// matio said no, or a check (access(2), flock(2)) put errno's text in the message.
/// A std::system_error whose what() is "WHERE: MESSAGE" alone, with no category text.
class IoError : public std::system_error {
 public:
  explicit IoError(const std::string& message, const Where& where = {})
      : std::system_error(std::make_error_code(std::errc::io_error)), message_(where.prefix() + message) {}
  [[nodiscard]] const char* what() const noexcept override { return message_.c_str(); }

 private:
  std::string message_;
};

}  // namespace resolver
