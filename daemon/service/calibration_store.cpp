#include "daemon/service/calibration_store.h"

#include <fcntl.h>
#include <sys/stat.h>
#include <unistd.h>

#include <array>
#include <cerrno>
#include <charconv>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <set>
#include <string_view>

#include "daemon/core/errors.h"

namespace resolver {

namespace {

constexpr std::string_view kMagic = "resolverd-calibration";
constexpr std::string_view kChecksumKey = "crc32 ";
/// A version-1 file is a few hundred bytes; anything above this is not ours.
constexpr std::size_t kMaxFileBytes = 1 << 20;  // [bytes]
constexpr int kMaxPolePairs = 255;               // BENCH_INFO carries p_r and p as u8

const std::array<std::uint32_t, 256>& crc_table() {
  static const std::array<std::uint32_t, 256> table = [] {
    std::array<std::uint32_t, 256> t{};
    for (std::uint32_t i = 0; i < 256; ++i) {
      std::uint32_t c = i;
      for (int k = 0; k < 8; ++k) c = (c & 1U) != 0 ? (c >> 1) ^ 0xEDB88320U : c >> 1;
      t[i] = c;
    }
    return t;
  }();
  return table;
}

bool valid_name(std::string_view name) {
  if (name.empty() || name.size() > 128) return false;
  for (const char ch : name) {
    const bool ok = (ch >= 'a' && ch <= 'z') || (ch >= 'A' && ch <= 'Z') || (ch >= '0' && ch <= '9') || ch == '_' ||
                    ch == '.' || ch == ':' || ch == '-';
    if (!ok) return false;
  }
  return true;
}

std::string shortest(double v) {
  std::array<char, 64> buf{};
  const auto res = std::to_chars(buf.data(), buf.data() + buf.size(), v);
  return std::string(buf.data(), res.ptr);
}

/// A line of a possibly foreign file, made safe to print in one message.
std::string printable(std::string_view line) {
  std::string out;
  for (const char ch : line.substr(0, 40)) out += (ch >= 0x20 && ch < 0x7f) ? ch : '?';
  if (line.size() > 40) out += "...";
  return out;
}

template <typename T>
bool parse_number(std::string_view text, T& out) {
  if (text.empty()) return false;
  const auto [ptr, ec] = std::from_chars(text.data(), text.data() + text.size(), out);
  return ec == std::errc{} && ptr == text.data() + text.size();
}

/// Splits "key rest" at the first space.
std::pair<std::string_view, std::string_view> split_key(std::string_view line) {
  const auto space = line.find(' ');
  if (space == std::string_view::npos) return {line, {}};
  return {line.substr(0, space), line.substr(space + 1)};
}

/// `text` on one line: control characters (a line break in a path) become '?'.
std::string one_line(std::string_view text) {
  std::string out(text);
  for (char& ch : out) {
    if (static_cast<unsigned char>(ch) < 0x20 || ch == 0x7f) ch = '?';
  }
  return out;
}

std::string errno_text(int err) { return std::strerror(err); }

/// Writes all of `data` to `fd`, retrying short writes and EINTR. errno on failure.
bool write_all(int fd, std::string_view data) {
  while (!data.empty()) {
    const ssize_t n = ::write(fd, data.data(), data.size());
    if (n < 0) {
      if (errno == EINTR) continue;
      return false;
    }
    data.remove_prefix(static_cast<std::size_t>(n));
  }
  return true;
}

}  // namespace

std::uint32_t crc32_ieee(const std::string& bytes) {
  const auto& table = crc_table();
  std::uint32_t crc = 0xFFFFFFFFU;
  for (const char ch : bytes) crc = table[(crc ^ static_cast<std::uint8_t>(ch)) & 0xFFU] ^ (crc >> 8);
  return crc ^ 0xFFFFFFFFU;
}

std::string calibration_path(const std::string& dir) {
  if (!dir.empty() && dir.back() == '/') return dir + kCalibrationFileName;
  return dir + "/" + kCalibrationFileName;
}

std::string format_calibration(const Calibration& c) {
  if (c.p_r < 1 || c.p_r > kMaxPolePairs || c.p < 1 || c.p > kMaxPolePairs) {
    throw InputError(Fault::kData, "cannot save the calibration: pole pairs p_r=" + std::to_string(c.p_r) + ", p=" + std::to_string(c.p) +
           " are outside 1..255; the bench identity must come from BENCH_INFO or the config");
  }
  if (c.method.find_first_of("\r\n") != std::string::npos) {
    throw InputError(Fault::kData, "cannot save the calibration: the method name contains a line break; use a one-line name");
  }
  if (c.samples < 0) {
    throw InputError(Fault::kData, "cannot save the calibration: samples=" + std::to_string(c.samples) + " is negative");
  }
  std::set<std::string> seen;
  for (const auto& param : c.params) {
    if (!valid_name(param.name)) {
      throw InputError(Fault::kData, "cannot save the calibration: parameter name '" + printable(param.name) +
             "' is empty or has characters outside [A-Za-z0-9_.:-]; rename the parameter");
    }
    if (!seen.insert(param.name).second) {
      throw InputError(Fault::kData, "cannot save the calibration: parameter '" + param.name + "' appears twice");
    }
    if (!std::isfinite(param.value) || std::isinf(param.std_error) || param.std_error < 0.0) {
      throw InputError(Fault::kData, "cannot save the calibration: parameter '" + param.name + "' has value " + shortest(param.value) +
             " and std_error " + shortest(param.std_error) +
             "; only finite values and a finite std_error >= 0 are saved (the estimate has not converged?)");
    }
  }
  std::string body;
  body += kMagic;
  body += "\n# learned by resolverd; edits break the checksum and the file is then ignored\n";
  body += "format " + std::to_string(kCalibrationFormatVersion) + "\n";
  body += "p_r " + std::to_string(c.p_r) + "\n";
  body += "p " + std::to_string(c.p) + "\n";
  body += "method " + c.method + "\n";
  body += "samples " + std::to_string(c.samples) + "\n";
  if (!c.model.empty()) {
    std::string line = "model";
    for (const auto& m : c.model) {
      if (m.empty() || m.find_first_of(" \t\r\n") != std::string::npos) {
        throw InputError(Fault::kData, "cannot save the calibration: effect reference '" + printable(m) + "' is empty or contains blanks");
      }
      line += " " + m;
    }
    body += line + "\n";
  }
  for (const auto& cu : c.custom) {
    std::string line = "custom " + cu.name + "\t" + cu.signal;
    for (const auto& t : cu.terms) {
      if (t.find_first_of("\t\r\n") != std::string::npos) {
        throw InputError(Fault::kData, "cannot save the calibration: a term of custom effect '" + printable(cu.name) + "' contains a tab or line break");
      }
      line += "\t" + t;
    }
    body += line + "\n";
  }
  for (const auto& param : c.params) {
    body += "param " + param.name + " " + shortest(param.value) + " " + shortest(param.std_error) + "\n";
  }
  const Calibration::Provenance& pv = c.provenance;
  for (const auto& [key, value] : {std::pair<const char*, const std::string*>{"config", &pv.config},
                                   {"config_crc32", &pv.config_crc32},
                                   {"source", &pv.source},
                                   {"saved_at", &pv.saved_at},
                                   {"program", &pv.program}}) {
    if (!value->empty()) body += std::string(key) + " " + one_line(*value) + "\n";
  }
  if (!pv.layout_id.empty()) {
    if (pv.layout_id.find_first_of(" \t\r\n") != std::string::npos) {
      throw InputError(Fault::kData, "cannot save the calibration: layout id '" + printable(pv.layout_id) + "' contains blanks");
    }
    body += "layout " + pv.layout_id + " " + one_line(pv.layout) + "\n";
  }
  char crc[16];
  std::snprintf(crc, sizeof crc, "%08x", static_cast<unsigned>(crc32_ieee(body)));
  return body + std::string(kChecksumKey) + crc + "\n";
}

namespace {

[[noreturn]] void refuse(const std::string& where, const std::string& why) {
  throw InputError(Fault::kData, why, Where::at_file(where));
}

/// The identity line and the format version, first, so a foreign or future file is
/// named as such rather than as "corrupt". Returns where the identity line ends.
std::size_t check_identity(std::string_view all, const std::string& where) {
  if (all.empty()) refuse(where, "empty file (an interrupted write by an old version?); it is ignored");
  const std::string_view first = all.substr(0, all.find('\n'));
  if (first.size() == all.size() && kMagic.substr(0, first.size()) == first) {
    refuse(where, "truncated inside the identity line; the file is ignored");
  }
  if (first != kMagic) {
    refuse(where, "not a resolverd calibration file: the first line is '" + printable(first) + "', expected '" +
                      std::string(kMagic) + "'; check --state-dir, the file is ignored");
  }
  std::size_t pos = first.size() + 1;
  std::string_view version_line;
  while (pos < all.size()) {
    const std::size_t end = all.find('\n', pos);
    const std::string_view line = all.substr(pos, end == std::string_view::npos ? std::string_view::npos : end - pos);
    pos = end == std::string_view::npos ? all.size() : end + 1;
    if (!line.empty() && line.front() == '#') continue;
    version_line = line;
    break;
  }
  const auto [key, rest] = split_key(version_line);
  int version = 0;
  if (key != "format" || !parse_number(rest, version)) {
    refuse(where, "no 'format N' line after the identity line (found '" + printable(version_line) +
                      "'); the file is truncated or damaged and is ignored");
  }
  if (version < 1 || version > kCalibrationFormatVersion) {
    refuse(where, "calibration format version " + std::to_string(version) + ", but this resolverd reads only versions " +
                      std::to_string(kCalibrationFormatVersion) +
                      ", 2 and 1; it was written by another resolverd release and is ignored (it is replaced at the "
                      "next save)");
  }
  return first.size();
}

/// The checksum: the last line, covering every byte before it. Returns where that line starts.
std::size_t check_checksum(const std::string& text, const std::string& where) {
  const std::string_view all(text);
  if (text.back() != '\n') refuse(where, "truncated: the file does not end with a complete line; it is ignored");
  const std::size_t last_start = all.rfind('\n', all.size() - 2);
  const std::size_t crc_line_start = last_start == std::string_view::npos ? 0 : last_start + 1;
  const std::string_view crc_line = all.substr(crc_line_start, all.size() - 1 - crc_line_start);
  if (crc_line.substr(0, kChecksumKey.size()) != kChecksumKey) {
    refuse(where, "truncated: the last line is '" + printable(crc_line) + "', not the 'crc32 XXXXXXXX' checksum; ignored");
  }
  std::uint32_t stated = 0;
  const std::string_view hex = crc_line.substr(kChecksumKey.size());
  const auto [ptr, ec] = std::from_chars(hex.data(), hex.data() + hex.size(), stated, 16);
  if (hex.size() != 8 || ec != std::errc{} || ptr != hex.data() + hex.size()) {
    refuse(where, "malformed checksum line '" + printable(crc_line) + "'; ignored");
  }
  const std::uint32_t actual = crc32_ieee(text.substr(0, crc_line_start));
  if (actual != stated) {
    char msg[160];
    std::snprintf(msg, sizeof msg, "checksum mismatch (file says %08x, contents give %08x): the file is corrupt; ignored",
                  static_cast<unsigned>(stated), static_cast<unsigned>(actual));
    refuse(where, msg);
  }
  return crc_line_start;
}

}  // namespace

Calibration parse_calibration(const std::string& text, const std::string& where) {
  auto fail = [&](const std::string& why) -> Calibration { refuse(where, why); };
  const std::size_t identity_end = check_identity(text, where);
  const std::size_t crc_line_start = check_checksum(text, where);
  const std::string_view all(text);

  // Fields. The checksum matched, so anything odd here was written that way.
  Calibration c;
  bool have_p_r = false, have_p = false, have_method = false, have_samples = false;
  std::set<std::string> names;
  std::size_t line_no = 1;
  std::size_t pos = identity_end + 1;
  while (pos < crc_line_start) {
    ++line_no;
    const std::size_t end = all.find('\n', pos);
    const std::string_view line = all.substr(pos, end - pos);
    pos = end + 1;
    if (line.empty() || line.front() == '#') continue;
    const auto [key, rest] = split_key(line);
    const std::string at = "line " + std::to_string(line_no) + ": ";
    if (key == "format") continue;  // checked above
    if (key == "p_r" || key == "p") {
      int v = 0;
      if (!parse_number(rest, v) || v < 1 || v > kMaxPolePairs) {
        return fail(at + std::string(key) + " '" + printable(rest) + "' is not a pole-pair count in 1..255; ignored");
      }
      bool& have = key == "p_r" ? have_p_r : have_p;
      if (have) return fail(at + std::string(key) + " appears twice; ignored");
      have = true;
      (key == "p_r" ? c.p_r : c.p) = v;
    } else if (key == "method") {
      if (have_method) return fail(at + "method appears twice; ignored");
      have_method = true;
      c.method = std::string(rest);
    } else if (key == "samples") {
      if (have_samples) return fail(at + "samples appears twice; ignored");
      if (!parse_number(rest, c.samples) || c.samples < 0) {
        return fail(at + "samples '" + printable(rest) + "' is not a count >= 0; ignored");
      }
      have_samples = true;
    } else if (key == "model") {
      std::string_view rest_refs = rest;
      while (!rest_refs.empty()) {
        const auto [ref, more] = split_key(rest_refs);
        if (!ref.empty()) c.model.emplace_back(ref);
        rest_refs = more;
      }
    } else if (key == "custom") {
      Calibration::Custom cu;
      std::vector<std::string> fields;
      std::size_t start = 0;
      const std::string text_rest(rest);
      for (std::size_t i = 0; i <= text_rest.size(); ++i) {
        if (i == text_rest.size() || text_rest[i] == '\t') {
          fields.push_back(text_rest.substr(start, i - start));
          start = i + 1;
        }
      }
      if (fields.size() < 3) return fail(at + "'custom' needs NAME<TAB>SIGNAL<TAB>TERM...; ignored");
      cu.name = fields[0];
      cu.signal = fields[1];
      cu.terms.assign(fields.begin() + 2, fields.end());
      c.custom.push_back(std::move(cu));
    } else if (key == "param") {
      const auto [name, values] = split_key(rest);
      const auto [value_text, error_text] = split_key(values);
      ModelParameter param;
      param.name = std::string(name);
      if (!valid_name(name) || !parse_number(value_text, param.value) || !parse_number(error_text, param.std_error) ||
          !std::isfinite(param.value) || std::isinf(param.std_error) || param.std_error < 0.0) {
        return fail(at + "'" + printable(line) + "' is not 'param NAME VALUE STD_ERROR' with finite numbers; ignored");
      }
      if (!names.insert(param.name).second) return fail(at + "parameter '" + param.name + "' appears twice; ignored");
      c.params.push_back(std::move(param));
    } else if (key == "config" || key == "config_crc32" || key == "source" || key == "saved_at" ||
               key == "program") {
      Calibration::Provenance& pv = c.provenance;
      std::string& field = key == "config"         ? pv.config
                           : key == "config_crc32" ? pv.config_crc32
                           : key == "source"       ? pv.source
                           : key == "saved_at"     ? pv.saved_at
                                                   : pv.program;
      field = std::string(rest);
    } else if (key == "layout") {
      const auto [id, description] = split_key(rest);
      if (id.empty()) return fail(at + "'layout' needs an id; ignored");
      c.provenance.layout_id = std::string(id);
      c.provenance.layout = std::string(description);
    } else {
      return fail(at + "unknown key '" + printable(key) + "'; ignored");
    }
  }
  if (!have_p_r || !have_p || !have_method || !have_samples) {
    return fail(std::string("the bench identity is incomplete (missing ") +
                (!have_p_r ? "p_r" : !have_p ? "p" : !have_method ? "method" : "samples") + "); ignored");
  }
  return c;
}

void save_calibration(const std::string& dir, const Calibration& calibration) {
  const std::string text = format_calibration(calibration);
  const std::string final_path = calibration_path(dir);
  const std::string temp_path = final_path + ".tmp";
  const std::string advice =
      "; check that the state directory exists and is writable by resolverd "
      "(--state-dir, StateDirectory=resolverd in the unit); the previous calibration, if any, is unchanged";
  auto step_failed = [&](const std::string& step, const std::string& path, int err) {
    return "cannot save the calibration: " + step + " '" + path + "' failed: " + errno_text(err) + advice;
  };

  const int fd = ::open(temp_path.c_str(), O_WRONLY | O_CREAT | O_TRUNC | O_CLOEXEC, 0644);
  if (fd < 0) throw IoError(step_failed("creating", temp_path, errno));
  if (!write_all(fd, text)) {
    const int err = errno;
    ::close(fd);
    ::unlink(temp_path.c_str());
    throw IoError(step_failed("writing", temp_path, err));
  }
  if (::fsync(fd) != 0) {
    const int err = errno;
    ::close(fd);
    ::unlink(temp_path.c_str());
    throw IoError(step_failed("fsync of", temp_path, err));
  }
  if (::close(fd) != 0) {
    const int err = errno;
    ::unlink(temp_path.c_str());
    throw IoError(step_failed("closing", temp_path, err));
  }
  if (::rename(temp_path.c_str(), final_path.c_str()) != 0) {
    const int err = errno;
    ::unlink(temp_path.c_str());
    throw IoError(step_failed("renaming the temp file over", final_path, err));
  }
  // Make the rename itself durable.
  const int dfd = ::open(dir.empty() ? "." : dir.c_str(), O_RDONLY | O_DIRECTORY | O_CLOEXEC);
  if (dfd < 0) throw IoError(step_failed("opening the directory", dir, errno));
  const int sync_rc = ::fsync(dfd);
  const int sync_err = errno;
  ::close(dfd);
  if (sync_rc != 0) throw IoError(step_failed("fsync of the directory", dir, sync_err));
}

LoadResult load_calibration(const std::string& dir) {
  LoadResult result;
  const std::string path = calibration_path(dir);
  // O_NONBLOCK: opening a FIFO for reading would otherwise wait for a writer
  // forever; fstat below then refuses anything that is not a regular file.
  const int fd = ::open(path.c_str(), O_RDONLY | O_CLOEXEC | O_NONBLOCK);
  if (fd < 0) {
    const int err = errno;
    if (err == ENOENT) {
      result.status = LoadResult::Status::kMissing;
      result.problem = "no saved calibration at " + path + " (first start); learning from scratch";
    } else {
      result.status = LoadResult::Status::kRejected;
      result.problem = "cannot read the saved calibration " + path + ": " + errno_text(err) +
                       "; check the state directory's permissions; learning from scratch";
    }
    return result;
  }
  struct stat st {};
  std::string text;
  std::string problem;
  if (::fstat(fd, &st) != 0 || !S_ISREG(st.st_mode)) {
    problem = path + ": not a regular file (" +
              (S_ISFIFO(st.st_mode)  ? std::string("a FIFO")
               : S_ISDIR(st.st_mode) ? std::string("a directory")
                                     : std::string("a device or socket")) +
              "); it is not read: remove it (the next save puts a file there); learning from scratch";
  } else if (static_cast<std::uint64_t>(st.st_size) > kMaxFileBytes) {
    problem = path + ": " + std::to_string(st.st_size) + " bytes is far larger than a calibration file (at most " +
              std::to_string(kMaxFileBytes) + "); not ours, ignored";
  } else {
    std::array<char, 4096> buf{};
    while (true) {
      const ssize_t n = ::read(fd, buf.data(), buf.size());
      if (n < 0 && errno == EINTR) continue;
      if (n < 0) {
        problem = "cannot read the saved calibration " + path + ": " + errno_text(errno) + "; learning from scratch";
        break;
      }
      if (n == 0) break;
      text.append(buf.data(), static_cast<std::size_t>(n));
      if (text.size() > kMaxFileBytes) {
        problem = path + ": grew past " + std::to_string(kMaxFileBytes) + " bytes while reading; ignored";
        break;
      }
    }
  }
  ::close(fd);
  if (problem.empty()) {
    try {
      result.calibration = parse_calibration(text, path);
    } catch (const InputError& e) {
      problem = e.what();
    }
  }
  if (result.calibration) {
    result.status = LoadResult::Status::kLoaded;
    result.problem.clear();
  } else {
    result.status = LoadResult::Status::kRejected;
    result.problem = problem;
  }
  return result;
}

std::string set_calibration_aside(const std::string& dir, const std::string& tag) {
  const std::string from = calibration_path(dir);
  const std::string to = from + "." + tag;
  if (::rename(from.c_str(), to.c_str()) != 0) throw IoError("cannot move " + from + " aside to " + to + ": " + errno_text(errno));
  return to;
}

}  // namespace resolver
