// resolverd's configuration: defaults, TOML file, validation.
//
// Every field has a default that works on the bundled default layout, so the
// daemon runs with no config file at all. A config file only overrides.
// Example (all keys optional):
//
//   [lcm]
//   url = "udpm://239.255.76.67:7667?ttl=0"
//   [can]
//   receive_buffer_bytes = 4194304
//   wake_ids = "auto"          # wake once per sample, on the frame that completes it (learnt);
//                              # or fixed: [0x102]; [] = every frame
//   [channels]
//   angle = "RESOLVER_ANGLE"   # also dq, estimate, model_fit, health
//   [output]
//   angle_decimation = 1       # publish angle_t every Nth sample
//   dq_decimation = 10
//   ripple_revolutions = 8     # electrical revolutions averaged (coherently) for dq ripple
//   [bench]                    # used until a BENCH_INFO frame says otherwise
//   p_r = 3
//   p = 3
//   rd_bits = 16
//   use_bench_info = true
//   sample_rate_hz = 2000      # used until BENCH_INFO gives it; 0 = unknown
//   time_source = "counter"    # sample time = counter / sample rate; "frame" = frame timestamps
//   reference_aligned = false  # true: the reference encoder's zero is on the rotor d axis (resolver-sim's is),
//                              # so a constant position error is the mounting offset, not the reference's zero
//   [layout]
//   dbc = "/path/to/inverter.dbc"
//   counter_signal = "counter"
//   crc_signal = "crc"
//   crc = "j1850_bench"        # or "none"
//   bench_info_message = "BENCH_INFO"
//   max_counter_delta = 8      # counter steps of one sequence: frames up to this many periods out of
//                              # order join their sample (a sample waits as long for a missing frame);
//                              # a bigger jump starts a new sequence. Timed CSV rows: the reorder window
//   [layout.signals]           # role = "MESSAGE.signal"
//   sin = "RESOLVER_SAMPLE.sin"
//   [estimator]
//   method = "model"           # the [model] fitted live (default); or the seed "hwang_integral",
//                              # "sincos_least_squares", "fourier_reference"
//   min_revolutions = 3        # hwang_integral
//   max_speed_change = 0.02    # hwang_integral
//   forgetting = 1.0           # sincos_least_squares / fourier_reference: 1 = all data
//   harmonics = [3]            # sincos_least_squares with a reference angle: K_n fitted
//   max_order = 4              # fourier_reference: highest harmonic, 1..64
//   [compensation]
//   enabled = true
//   domain = "angle"           # or "signal" (sincos_least_squares: correct sin/cos, then atan2)
//   [model]                    # live model discovery: model_fit_t once per window
//   enabled = true
//   effects = ["amplitude_imbalance"]   # the active model; SIGHUP reloads it
//   window_revolutions = 16    # resolver electrical revolutions per window
//   candidates = true          # also rank the catalog effects not in the model
//   [input]
//   format = "auto"            # replayed files: "candump", "asc", "csv"; auto = by extension
//   [input.csv]                # CSV / scope exports (daemon/decode/row_decoder.h)
//   delimiter = "auto"         # ",", ";", "tab", "space" (runs of spaces), "auto"
//   decimal = "."              # or ","
//   header_lines = 0           # lines skipped before the column-name line; "auto" = until a line of numbers
//   column_names = true        # the first line after them names the columns
//   time_column = "Time"       # name or 1-based index; "" = none (rows at row_rate_hz)
//   time_unit = "s"            # "ms", "us", "filetime" (100 ns ticks since 1601-01-01)
//   row_rate_hz = 0            # only without a time column
//   [input.csv.columns]        # role = { column = name|index, unit, scale = 1, offset = 0,
//   rd_angle = { column = "Resolver", unit = "deg" }   #  full_scale (unit "counts"; sin/cos: the ADC's
//                              #  largest |value|, else health judges levels relatively), divide (angles) }
//   [[model.custom]]           # effects users add without recompiling (custom_effect.h)
//   name = "slow_drift"
//   signal = "position_error"  # position_error | rd_angle | sin | cos | i_d | i_q
//   terms = ["t", "t*sin(2*theta)"]
//   description = "alpha warming up"
//   [health]                   # signal faults (daemon/core/health/signal_health.h says where each default is from)
//   full_scale = 0             # [counts] |sin|,|cos| the ADC reaches; 0 = the DBC signal's range
//   loss_of_signal_fraction = 0.05     # LOS: amplitude below this share of full scale
//   degradation_low_fraction = 0.25    # DOS: amplitude below this share ...
//   degradation_high_fraction = 0.95   # ... or above this one
//   degradation_mismatch = 0.10        # DOS: amplitude swing over a block beyond this share of its mean
//   loss_of_tracking_deg = 5.0         # LOT: R/D vs sin/cos angle disagreement
//   overspeed_rad_per_sample = 0.785   # pi/4 of resolver electrical travel per sample
//   stopped_below_hz = 0.1             # resolver electrical revolutions per second
//   outlier_sigmas = 8.0               # robust z-score of an impulsive sample
//   block_s = 0.1                      # [s] evaluation block of sample time
#pragma once

#include <memory>
#include <optional>
#include <stdexcept>
#include <string>
#include <vector>

#include "daemon/app/log_format.h"
#include "daemon/core/estimation/hwang_integral.h"
#include "daemon/core/model/custom_effect.h"
#include "daemon/core/health/signal_health.h"
#include "daemon/core/estimation/sample_processor.h"
#include "daemon/decode/row_decoder.h"
#include "daemon/decode/signal_map.h"
#include "daemon/core/errors.h"
#include "drivers/csv/csv_format.h"

namespace resolver {

struct CanOptions {
  /// SO_RCVBUF for the CAN socket [bytes]; the kernel default (~200 kB)
  /// overflowed at full bus rate in the vcan guest. Capped by net.core.rmem_max.
  int receive_buffer_bytes = 4 << 20;
  /// Which frames wake the live reader: "auto" (default, wake_auto) learns
  /// the frame that completes the samples (daemon/app/wake_planner.h); a
  /// list fixes the IDs (above 0x7FF: 29-bit), [] = every frame. Only the
  /// named frames wake the daemon, the others of a sample wait in a second
  /// socket until it comes: one wake-up per sample instead of one per frame
  /// (drivers/socketcan/split_wake_source.h).
  bool wake_auto = true;
  std::vector<std::uint32_t> wake_ids;
};

struct LcmChannels {
  std::string angle = "RESOLVER_ANGLE";
  std::string dq = "RESOLVER_DQ";
  std::string estimate = "RESOLVER_ESTIMATE";
  std::string model_fit = "RESOLVER_MODEL_FIT";
  std::string health = "RESOLVER_HEALTH";
};

struct BenchDefaults {
  int p_r = 3;                 ///< resolver pole pairs
  int p = 3;                   ///< motor pole pairs
  int rd_bits = 16;            ///< R/D resolution [bits]
  bool use_bench_info = true;  ///< let BENCH_INFO frames override p_r, p, rd_bits, sample rate
  /// The reference encoder's zero is on the rotor d axis (set at commissioning, or
  /// resolver-sim's): a constant position error against it is then the mounting
  /// offset. Otherwise (a real bench's encoder, an open-loop command) the reference's
  /// zero is a free constant of the fit and the mounting offset is not identifiable.
  bool reference_aligned = false;
  /// Control/sample rate [Hz]; 0 = unknown until BENCH_INFO.
  double sample_rate_hz = 0.0;
  /// Where the estimators' time axis comes from. The DSP samples on a fixed
  /// clock and numbers its samples, so counter / sample rate is the exact
  /// sample time; frame timestamps carry bus and receive jitter (canplayer
  /// bursts, USB adapters batching: +-0.5 ms seen in the vcan guest), which at
  /// 200 r/min is ~30 mrad of apparent angle error against a 1.5 mrad signal.
  bool time_from_counter = true;
};

/// Live model discovery (docs/ARCHITECTURE.md §8): the active effect list and its window.
struct ModelFitOptions {
  bool enabled = true;
  /// The active model: effect references (daemon/core/model/model_spec.h), catalog
  /// effects or [[model.custom]] names, e.g. ["amplitude_imbalance", "harmonics(k5)"].
  std::vector<std::string> effects{"amplitude_imbalance"};  ///< the seed's model
  /// [[model.custom]] blocks as written, and compiled (shared: models point into them).
  std::vector<CustomEffectSpec> custom;
  std::shared_ptr<const CustomEffects> customs;
  double window_revolutions = 16.0;  ///< resolver electrical revolutions per model_fit_t
  bool candidates = true;            ///< rank the missing catalog effects (explain) or only fit
  bool reference_aligned = false;    ///< [bench] reference_aligned, copied here for the fit
};

/// A CSV / scope export's layout and column map ([input.csv]).
struct CsvInputConfig {
  CsvFormat format;
  RowMap map;  ///< empty: no [input.csv.columns] (a CSV cannot be read)
};

struct DaemonConfig {
  std::string source;  ///< file the config came from ("" = built-in defaults)
  std::string lcm_url;  ///< "" = LCM's default (udpm multicast)
  LcmChannels channels;
  int angle_decimation = 1;
  int dq_decimation = 1;
  int ripple_revolutions = 8;
  BenchDefaults bench;
  CanOptions can;
  /// "" = proto/resolver_bench.dbc, compiled into the binary. A relative [layout] dbc
  /// is taken from the config file's folder (stored here already joined to it).
  std::string dbc_path;
  SignalMap signal_map = SignalMap::bench_default();
  int max_counter_delta = 8;
  std::string estimator_method = "model";
  EstimatorMethod method = EstimatorMethod::kModel;
  HwangIntegralConfig hwang;
  SinCosLsConfig sincos;
  AngleFourierConfig fourier;
  bool compensation_enabled = true;
  CompensationDomain compensation_domain = CompensationDomain::kAngle;
  ModelFitOptions model;
  /// [health]: signal fault thresholds. health.full_scale applies only when
  /// health_full_scale_set; otherwise the pipeline takes it from the DBC.
  SignalHealthConfig health;
  bool health_full_scale_set = false;
  std::optional<LogFormat> input_format;  ///< [input] format; nullopt = from the extension
  CsvInputConfig csv;
};

/// Thrown for unreadable or invalid configuration; what() names the file,
/// the line where known, the key and what is expected. A usage fault: every
/// program exits 2 for it (daemon/service/program_errors.h).
class ConfigError : public InputError {
 public:
  explicit ConfigError(const std::string& message) : InputError(Fault::kUsage, message) {}
};

/// Reads a TOML config over the defaults. Unknown keys are errors (a typo
/// must not silently fall back to a default). Throws ConfigError.
DaemonConfig load_daemon_config(const std::string& path);
/// Parses TOML text (source_name is used in messages). Throws ConfigError.
DaemonConfig parse_daemon_config(std::string_view text, const std::string& source_name);

/// How messages name the built-in DBC used when the config names none.
std::string default_dbc_path();

}  // namespace resolver
