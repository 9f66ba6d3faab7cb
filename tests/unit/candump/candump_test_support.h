// Helpers shared by the candump tests: temporary files and random frames.
#pragma once

#include <unistd.h>

#include <array>
#include <cstdint>
#include <cstdlib>
#include <fstream>
#include <random>
#include <sstream>
#include <stdexcept>
#include <string>
#include <vector>

#include "drivers/can_frame.h"

namespace resolver::candump_test {

/// A fresh file path in the test temp directory; the file is removed when
/// the object goes out of scope.
class TempPath {
 public:
  explicit TempPath(const std::string& suffix = ".log") {
    const char* dir = std::getenv("TMPDIR");
    std::string pattern = std::string(dir != nullptr && *dir != '\0' ? dir : "/tmp") + "/candump_test_XXXXXX" + suffix;
    const int fd = ::mkstemps(pattern.data(), static_cast<int>(suffix.size()));
    if (fd < 0) throw std::runtime_error("mkstemps failed for " + pattern);
    ::close(fd);
    path_ = pattern;
  }
  ~TempPath() { ::unlink(path_.c_str()); }
  TempPath(const TempPath&) = delete;
  TempPath& operator=(const TempPath&) = delete;
  [[nodiscard]] const std::string& str() const { return path_; }

 private:
  std::string path_;
};

inline void write_text(const std::string& path, const std::string& text) {
  std::ofstream out(path, std::ios::binary | std::ios::trunc);
  out << text;
  if (!out) throw std::runtime_error("cannot write " + path);
}

inline std::string read_text(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  std::ostringstream ss;
  ss << in.rdbuf();
  return ss.str();
}

inline constexpr std::array<std::uint8_t, 15> kFdLengths{0, 1, 2, 3, 4, 5, 6, 7, 8, 12, 16, 20, 24, 32, 48};

/// A random frame every field of which survives a candump line: classic,
/// extended, RTR, CAN FD (with BRS/ESI) and error frames. `time_us` advances
/// by 0..2000 us (0 on purpose: equal timestamps are legal).
inline CanFrame random_frame(std::mt19937_64& rng, std::int64_t& time_us) {
  auto pick = [&rng](std::uint64_t n) { return static_cast<std::uint32_t>(rng() % n); };
  CanFrame f;
  time_us += pick(2001);
  f.timestamp_us = time_us;
  static const char* const kIfaces[] = {"can0", "can1", "vcan0", "vcan10", "canfd_bench0"};
  f.set_iface(kIfaces[pick(5)]);
  const std::uint32_t kind = pick(10);
  f.extended = pick(2) == 1;
  f.id = f.extended ? pick(0x20000000U) : pick(0x800U);
  if (kind == 0) {  // error frame: class bits, 8 data bytes like the kernel sends
    f.extended = false;
    f.error = true;
    f.id = pick(0x200U) | 0x80U;  // always CAN_ERR_BUSERROR so python-can sees it as an error too
    f.len = 8;
  } else if (kind == 1) {
    f.rtr = true;
    f.len = static_cast<std::uint8_t>(pick(9));
  } else if (kind <= 4) {
    f.fd = true;
    f.fd_flags = static_cast<std::uint8_t>(pick(4));
    f.len = pick(8) == 0 ? std::uint8_t{64} : kFdLengths[pick(kFdLengths.size())];
  } else {
    f.len = static_cast<std::uint8_t>(pick(9));
  }
  if (!f.rtr) {
    for (std::size_t i = 0; i < f.len; ++i) f.data[i] = static_cast<std::uint8_t>(pick(256));
  }
  return f;
}

/// Field-by-field description for failure messages.
inline std::string describe(const CanFrame& f) {
  std::ostringstream s;
  s << "t=" << f.timestamp_us << " if=" << f.iface_name() << " id=0x" << std::hex << f.id << std::dec
    << " ext=" << f.extended << " rtr=" << f.rtr << " err=" << f.error << " fd=" << f.fd
    << " flags=" << int{f.fd_flags} << " len=" << int{f.len} << " data=";
  for (std::size_t i = 0; i < f.data.size(); ++i) s << std::hex << int{f.data[i]} << (i + 1 < f.data.size() ? "." : "");
  return s.str();
}

/// True when every field, all 64 data bytes included, is the same.
inline bool same_frame(const CanFrame& a, const CanFrame& b) {
  return a.timestamp_us == b.timestamp_us && a.iface_name() == b.iface_name() && a.id == b.id &&
         a.extended == b.extended && a.rtr == b.rtr && a.error == b.error && a.fd == b.fd &&
         a.fd_flags == b.fd_flags && a.len == b.len && a.data == b.data;
}

}  // namespace resolver::candump_test
