// Helpers shared by the fuzz targets in this folder (test code only).
//
// A target's LLVMFuzzerTestOneInput is built twice: linked with libFuzzer
// (clang, -fsanitize=fuzzer) to search for crashes, and linked with
// replay_main.cpp (any compiler) so ctest replays the checked-in corpus.
// Both treat a failed FUZZ_CHECK as a crash: it prints what broke and aborts.
#pragma once

#include <cstddef>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <string>
#include <string_view>

#include <sys/mman.h>
#include <unistd.h>

namespace resolver::fuzz {

/// Aborts with `what` when a property the code under test promises is broken.
[[noreturn]] inline void property_failed(const char* what, const char* file, int line) {
  std::fprintf(stderr, "%s:%d: fuzz property broken: %s\n", file, line, what);
  std::abort();
}

#define FUZZ_CHECK(cond, what)                                            \
  do {                                                                    \
    if (!(cond)) ::resolver::fuzz::property_failed(what, __FILE__, __LINE__); \
  } while (false)

inline std::string_view as_text(const std::uint8_t* data, std::size_t size) {
  return {reinterpret_cast<const char*>(data), size};
}

/// Calls fn(line, 1-based line number) for each '\n'-separated line (without
/// the '\n'); a last line without '\n' counts too.
template <typename Fn>
void for_each_line(std::string_view text, Fn&& fn) {
  std::uint64_t number = 0;
  while (!text.empty()) {
    const std::size_t nl = text.find('\n');
    const std::string_view line = text.substr(0, nl);
    fn(line, ++number);
    if (nl == std::string_view::npos) break;
    text.remove_prefix(nl + 1);
  }
}

/// The input as a file (a memfd), so readers that open a path read it the way
/// they read a log. Closes it at scope end; path() is empty when no memfd
/// could be made or written (old kernel): the target then has nothing to test.
class MemFile {
 public:
  MemFile(const std::uint8_t* data, std::size_t size) : fd_(::memfd_create("fuzz_input", MFD_CLOEXEC)) {
    std::size_t written = 0;
    while (fd_ >= 0 && written < size) {
      const ssize_t n = ::write(fd_, data + written, size - written);
      if (n <= 0) break;
      written += static_cast<std::size_t>(n);
    }
    ok_ = fd_ >= 0 && written == size;
  }
  ~MemFile() {
    if (fd_ >= 0) ::close(fd_);
  }
  MemFile(const MemFile&) = delete;
  MemFile& operator=(const MemFile&) = delete;
  [[nodiscard]] std::string path() const { return ok_ ? "/proc/self/fd/" + std::to_string(fd_) : std::string(); }

 private:
  int fd_;
  bool ok_ = false;
};

/// Reads bytes off the front of the input; past the end everything reads as 0.
class ByteReader {
 public:
  ByteReader(const std::uint8_t* data, std::size_t size) : data_(data), size_(size) {}
  [[nodiscard]] bool empty() const { return pos_ >= size_; }
  std::uint8_t u8() { return pos_ < size_ ? data_[pos_++] : std::uint8_t{0}; }
  std::uint16_t u16() {
    const auto lo = u8();
    return static_cast<std::uint16_t>(lo | (u8() << 8U));
  }
  std::uint32_t u32() {
    const std::uint32_t lo = u16();
    return lo | (static_cast<std::uint32_t>(u16()) << 16U);
  }

 private:
  const std::uint8_t* data_;
  std::size_t size_;
  std::size_t pos_ = 0;
};

}  // namespace resolver::fuzz
