// Persisting the learned resolver calibration across daemon restarts.
//
// resolverd keeps what it has learned (the active model's parameters with
// their standard errors, for the bench identity p_r/p) in one small text file,
// `<state dir>/calibration.txt` — under systemd the state dir is
// /var/lib/resolverd (StateDirectory=resolverd, passed as --state-dir
// ${STATE_DIRECTORY}). The file, format version 3 (versions 1 and 2, without the
// provenance lines, and version 1 also without the model and custom lines, are
// still read):
//
//   resolverd-calibration                      magic/identity line (first line)
//   format 2                                   format version
//   model amplitude_imbalance harmonics(k5)    the model's effect references (space separated)
//   custom drift<TAB>position_error<TAB>t*sin(2*theta)   a [[model.custom]] effect the model uses
//   p_r 1                                      resolver pole pairs
//   p 4                                        motor pole pairs
//   method hwang_integral                      estimator that produced it (may be empty)
//   samples 123456                             samples the estimate used
//   config /etc/resolverd/resolverd.toml       provenance (format 3, each line optional):
//   config_crc32 5e1f00aa                        the config file and CRC-32 of its text
//   layout 0badcafe the default bench layout ...  CRC-32 of the layout (DBC text + signal
//                                                map) and its description; a run on
//                                                another layout refuses the file
//   source /var/log/bench/run7.log             the log replayed, or the CAN interface
//   saved_at 2026-11-26T01:44:32Z              UTC
//   program resolverd 0.1.0 (git 7d43eb5)      the --version line of the writer
//   param amplitude_imbalance.alpha 0.0123 4.5e-05    name value std_error (nan: not identifiable)
//   ...
//   crc32 1a2b3c4d                             CRC-32 (IEEE 802.3) of every byte above
//
// Numbers are written in the shortest form that reads back bit-exactly. A
// line starting with '#' is a comment (covered by the checksum too).
//
// Writing is atomic: a temp file in the same directory is written, fsync'ed,
// renamed over the old file, and the directory is fsync'ed, so a crash or power
// cut leaves either the old or the new file, never a mix. A leftover temp file
// from an interrupted save is never read.
//
// Loading never throws: a missing file is normal on first start; a corrupt,
// truncated, foreign (other magic), wrong-version or inconsistent file is
// reported with the reason and ignored — the daemon then learns from scratch.
#pragma once

#include <cstdint>
#include <optional>
#include <string>
#include <vector>

#include "daemon/core/model/parameter.h"

namespace resolver {

/// One learned parameter, named as in estimate_t (e.g. "amplitude_imbalance.alpha").

struct Calibration {
  int p_r = 1;  ///< resolver pole pairs (theta = p_r * theta_m), 1..255 as in BENCH_INFO
  int p = 1;    ///< motor pole pairs (theta_e = p * theta_m), 1..255
  std::string method;        ///< estimator name, printable, no newline; may be empty
  std::int64_t samples = 0;  ///< samples the estimate is based on, >= 0
  /// The model's effect references (format 2; empty in a version-1 file).
  std::vector<std::string> model;
  /// The [[model.custom]] effects it uses: name, signal, terms (format 2).
  struct Custom {
    std::string name, signal;
    std::vector<std::string> terms;
    bool operator==(const Custom&) const = default;
  };
  std::vector<Custom> custom;
  /// Names [A-Za-z0-9_.:-]+, unique; std_error >= 0 or NaN. The file keeps name,
  /// value and standard error (the unit is the registry's: read back empty).
  std::vector<ModelParameter> params;
  /// Where the calibration came from (format 3; all empty in a version-1 or -2 file).
  /// Printable one-line texts: a line break written here is saved as '?'.
  struct Provenance {
    std::string config;        ///< config file path; "" = the built-in defaults
    std::string config_crc32;  ///< 8 hex digits, CRC-32 of the config file's text; "" with no file
    std::string layout_id;     ///< 8 hex digits identifying the layout (see calibration_gate.h)
    std::string layout;        ///< the layout in words, for messages
    std::string source;        ///< log path or CAN interface
    std::string saved_at;      ///< UTC, ISO 8601 ("2026-11-26T01:44:32Z")
    std::string program;       ///< the writer's --version line
    bool operator==(const Provenance&) const = default;
  };
  Provenance provenance;
  bool operator==(const Calibration&) const = default;
};

/// File name inside the state directory.
inline constexpr const char* kCalibrationFileName = "calibration.txt";
/// Format version this code writes; it also reads versions 1 and 2.
inline constexpr int kCalibrationFormatVersion = 3;

/// Full path of the calibration file in `dir`.
std::string calibration_path(const std::string& dir);

// Errors (the one rule, program_errors.h): a calibration that cannot be written or a
// file that cannot be read as one is InputError (Fault::kData) naming the field or the
// file and line; a failed file operation is IoError (a std::system_error: exit 3),
// naming the path, the step, the errno text and what to do. Only load_calibration,
// which runs at every start, reports instead of throwing (LoadResult).

/// Serialises `calibration` in format version 3 (with its checksum line). Throws
/// InputError when a field cannot be written (bad name, non-finite value, p_r/p out
/// of range, newline in method).
[[nodiscard]] std::string format_calibration(const Calibration& calibration);

/// Parses file contents; `where` names the source in messages. Throws InputError
/// (Fault::kData, Where::at_file(where)) saying why the text is not a calibration.
[[nodiscard]] Calibration parse_calibration(const std::string& text, const std::string& where);

/// Writes `calibration` atomically to calibration_path(dir). `dir` must exist
/// (systemd's StateDirectory= creates it). Throws like format_calibration, or
/// IoError naming the path, the failing step, errno text and what to do; on
/// failure the previous file, if any, is untouched.
void save_calibration(const std::string& dir, const Calibration& calibration);

struct LoadResult {
  enum class Status {
    kLoaded,    ///< `calibration` holds the file's contents
    kMissing,   ///< no file yet (first start); `problem` says where it looked
    kRejected,  ///< the file exists but is unusable; `problem` says why
  };
  Status status = Status::kMissing;
  std::optional<Calibration> calibration;
  std::string problem;  ///< empty when loaded
};

/// Reads calibration_path(dir). Never throws and never blocks: a FIFO, device or
/// directory in its place is rejected as not a regular file. See LoadResult.
LoadResult load_calibration(const std::string& dir);

/// Renames calibration_path(dir) to `<that path>.<tag>` (e.g. tag "refused-20261126T014432Z"),
/// so a refused file is kept for a person to look at and the next save does not
/// overwrite it. Returns the new path; throws IoError naming both paths.
std::string set_calibration_aside(const std::string& dir, const std::string& tag);

/// CRC-32 (IEEE 802.3, reflected poly 0xEDB88320, init and final xor
/// 0xFFFFFFFF); crc32("123456789") == 0xCBF43926.
std::uint32_t crc32_ieee(const std::string& bytes);

}  // namespace resolver
