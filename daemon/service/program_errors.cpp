#include "daemon/service/program_errors.h"

#include <new>
#include <system_error>

namespace resolver {

namespace {

constexpr const char* kOutOfMemory =
    "out of memory: the input needs more memory than this process may use (ulimit -v, cgroup limit, the "
    "machine's RAM); give it more, or a shorter input (--from/--to where the program has them; resolver-model "
    "fit, explain and stats --chunk 30 read a log of any length in bounded memory)";

/// The exit code of `error` and, unless it is out of memory, its message.
int classify(const std::exception_ptr& error, std::string* message) {
  try {
    std::rethrow_exception(error);
  } catch (const InputError& e) {
    if (message != nullptr) *message = e.what();
    return e.fault() == Fault::kData ? exit_code::kNoUsableData : exit_code::kUsage;
  } catch (const std::invalid_argument& e) {
    if (message != nullptr) *message = e.what();
    return exit_code::kUsage;
  } catch (const std::bad_alloc&) {
    return exit_code::kOutOfMemory;
  } catch (const std::system_error& e) {
    if (message != nullptr) *message = e.what();
    return exit_code::kIo;
  } catch (const std::exception& e) {
    if (message != nullptr) {
      *message = std::string("internal error: ") + e.what() + " (a bug: please report it with the command line)";
    }
    return exit_code::kInternal;
  } catch (...) {
    if (message != nullptr) *message = "internal error: an exception that is not a std::exception (a bug: please report it)";
    return exit_code::kInternal;
  }
}

}  // namespace

int exit_code_for(const std::exception_ptr& error, std::string& message) noexcept {
  message.clear();
  if (!error) return exit_code::kDone;
  try {
    const int code = classify(error, &message);
    if (code == exit_code::kOutOfMemory) message = kOutOfMemory;
    return code;
  } catch (...) {  // building the message ran out of memory
    return exit_code::kOutOfMemory;
  }
}

int report_exception(std::string_view program, const std::exception_ptr& error, std::ostream& err) noexcept {
  try {
    std::string message;
    const int code = exit_code_for(error, message);
    err << program << ": " << (message.empty() && code == exit_code::kOutOfMemory ? kOutOfMemory : message.c_str())
        << '\n';
    err.flush();
    return code;
  } catch (...) {  // the stream threw (exceptions() set): the code still stands
    std::string ignored;
    return exit_code_for(error, ignored);
  }
}

}  // namespace resolver
