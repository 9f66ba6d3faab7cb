// Interop with python-can's canutils module (CanutilsLogReader/-Writer), run
// through /usr/bin/python3: our logs read there, theirs read here, same frames.
//
// python-can's quirks the expectations account for (can/io/canutils.py):
//   - its reader reports an error frame only as is_error_frame (no id, no data),
//   - its writer logs every error frame's id as 20000080 (CAN_ERR_BUSERROR),
//   - its writer logs remote frames as "R" without the length,
//   - its writer appends the direction " R" / " T".
#include <gtest/gtest.h>

#include <cstdio>
#include <cstdlib>
#include <random>
#include <sstream>
#include <string>
#include <vector>

#include "drivers/candump/candump_line.h"
#include "drivers/candump/candump_reader.h"
#include "drivers/candump/candump_writer.h"
#include "tests/unit/candump/candump_test_support.h"

namespace resolver {
namespace {

using candump_test::TempPath;

constexpr const char* kPython = "/usr/bin/python3";

// Reads a log with python-can, or writes one from a frame list; frames travel
// as "ts_us id ext rtr err fd brs esi len hexdata channel" lines.
constexpr const char* kScript = R"PY(
import sys
import can
from can.io.canutils import CanutilsLogReader, CanutilsLogWriter

def read(path):
    for m in CanutilsLogReader(path):
        data = bytes(m.data).hex().upper() if m.data else "-"
        print(round(m.timestamp * 1e6), m.arbitration_id, int(m.is_extended_id), int(m.is_remote_frame),
              int(m.is_error_frame), int(m.is_fd), int(m.bitrate_switch), int(m.error_state_indicator),
              m.dlc, data, m.channel if m.channel is not None else "-")

def write(spec, path):
    w = CanutilsLogWriter(path)
    for line in open(spec):
        ts, ident, ext, rtr, err, fd, brs, esi, n, data, chan = line.split()
        sec, usec = divmod(int(ts), 1000000)
        m = can.Message(timestamp=float("%d.%06d" % (sec, usec)), arbitration_id=int(ident),
                        is_extended_id=ext == "1", is_remote_frame=rtr == "1", is_error_frame=err == "1",
                        is_fd=fd == "1", bitrate_switch=brs == "1", error_state_indicator=esi == "1",
                        dlc=int(n), data=None if data == "-" else bytes.fromhex(data), channel=chan,
                        check=False)
        w.on_message_received(m)
    w.stop()

if sys.argv[1] == "read":
    read(sys.argv[2])
else:
    write(sys.argv[2], sys.argv[3])
)PY";

bool python_can_available() {
  const std::string cmd = std::string(kPython) + " -c 'import can' >/dev/null 2>&1";
  return std::system(cmd.c_str()) == 0;
}

// Skips, or fails when RESOLVER_REQUIRE_PYCAN=1 says python-can must be there.
#define REQUIRE_PYCAN_OR_SKIP()                                                                         \
  do {                                                                                                  \
    if (!python_can_available()) {                                                                      \
      const char* req = std::getenv("RESOLVER_REQUIRE_PYCAN");                                          \
      if (req != nullptr && std::string(req) == "1") {                                                  \
        FAIL() << kPython << " cannot 'import can' but RESOLVER_REQUIRE_PYCAN=1; install python3-can"; \
      }                                                                                                 \
      GTEST_SKIP() << kPython << " cannot 'import can' (install python3-can, or set "                   \
                   << "RESOLVER_REQUIRE_PYCAN=1 to make this a failure)";                               \
    }                                                                                                   \
  } while (false)

std::string hex(const CanFrame& f) {
  if (f.len == 0) return "-";
  static constexpr char kDigits[] = "0123456789ABCDEF";
  std::string s;
  for (std::size_t i = 0; i < f.len; ++i) {
    s += kDigits[f.data[i] >> 4U];
    s += kDigits[f.data[i] & 0xFU];
  }
  return s;
}

std::string spec_line(const CanFrame& f) {
  std::ostringstream s;
  s << f.timestamp_us << ' ' << f.id << ' ' << f.extended << ' ' << f.rtr << ' ' << f.error << ' ' << f.fd
    << ' ' << ((f.fd_flags & 1U) != 0) << ' ' << ((f.fd_flags & 2U) != 0) << ' ' << int{f.len} << ' '
    << (f.rtr ? "-" : hex(f)) << ' ' << f.iface_name();
  return s.str();
}

std::vector<CanFrame> make_frames(std::size_t n) {
  std::mt19937_64 rng(99);
  std::int64_t t = 1'699'999'999'000'000;
  std::vector<CanFrame> frames;
  for (std::size_t i = 0; i < n; ++i) frames.push_back(candump_test::random_frame(rng, t));
  return frames;
}

std::vector<std::string> run_lines(const std::string& cmd, int& status) {
  std::vector<std::string> lines;
  FILE* pipe = ::popen(cmd.c_str(), "r");
  if (pipe == nullptr) {
    status = -1;
    return lines;
  }
  std::string current;
  for (int c; (c = std::fgetc(pipe)) != EOF;) {
    if (c == '\n') {
      lines.push_back(current);
      current.clear();
    } else {
      current += static_cast<char>(c);
    }
  }
  status = ::pclose(pipe);
  return lines;
}

TEST(CandumpPythonCan, PythonCanReadsOurLog) {
  REQUIRE_PYCAN_OR_SKIP();
  const auto frames = make_frames(3000);
  TempPath log;
  TempPath script(".py");
  candump_test::write_text(script.str(), kScript);
  {
    CandumpWriter writer(log.str());
    for (const CanFrame& f : frames) writer.write(f);
    writer.close();
  }
  int status = 0;
  const auto lines = run_lines(std::string(kPython) + " " + script.str() + " read " + log.str(), status);
  ASSERT_EQ(status, 0) << "python-can's CanutilsLogReader failed on " << log.str();
  ASSERT_EQ(lines.size(), frames.size());
  for (std::size_t i = 0; i < frames.size(); ++i) {
    CanFrame want = frames[i];
    if (want.error) {
      // python-can keeps only "is an error frame" and the time.
      std::istringstream fields(lines[i]);
      std::string ts, id, ext, rtr, err;
      fields >> ts >> id >> ext >> rtr >> err;
      ASSERT_EQ(ts, std::to_string(want.timestamp_us)) << "frame " << i << ": " << lines[i];
      ASSERT_EQ(err, "1") << "frame " << i << " is an error frame: " << lines[i];
      continue;
    }
    ASSERT_EQ(lines[i], spec_line(want)) << "frame " << i;
  }
}

TEST(CandumpPythonCan, WeReadPythonCansLog) {
  REQUIRE_PYCAN_OR_SKIP();
  const auto frames = make_frames(3000);
  TempPath spec;
  TempPath log;
  TempPath script(".py");
  candump_test::write_text(script.str(), kScript);
  std::string text;
  for (const CanFrame& f : frames) text += spec_line(f) + "\n";
  candump_test::write_text(spec.str(), text);
  ASSERT_EQ(std::system((std::string(kPython) + " " + script.str() + " write " + spec.str() + " " + log.str()).c_str()),
            0)
      << "python-can's CanutilsLogWriter failed";

  CandumpReader reader(log.str());
  CanFrame back;
  std::size_t i = 0;
  for (CandumpReader::Status s; (s = reader.next(back)) != CandumpReader::Status::kEnd; ++i) {
    ASSERT_EQ(s, CandumpReader::Status::kFrame)
        << log.str() << ":" << reader.line_number() << ":" << reader.problem().column << ": "
        << reader.problem().message;
    ASSERT_LT(i, frames.size());
    CanFrame want = frames[i];
    if (want.error) want.id = 0x80;  // "20000080#<data>": CAN_ERR_BUSERROR only
    if (want.rtr) want.len = 0;  // written as plain "R"
    ASSERT_TRUE(candump_test::same_frame(back, want))
        << "frame " << i << "\n got  " << candump_test::describe(back) << "\n want " << candump_test::describe(want);
  }
  EXPECT_EQ(i, frames.size());
}

}  // namespace
}  // namespace resolver
