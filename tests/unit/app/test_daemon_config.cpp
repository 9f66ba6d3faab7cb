// resolverd's TOML config: defaults, overrides, and errors that name the
// file, line and key.
#include <gtest/gtest.h>

#include "daemon/app/daemon_config.h"

namespace resolver {
namespace {

std::string error_of(std::string_view text) {
  try {
    parse_daemon_config(text, "test.toml");
  } catch (const ConfigError& e) {
    return e.what();
  }
  return "";
}

TEST(DaemonConfig, EmptyFileKeepsDefaults) {
  const DaemonConfig c = parse_daemon_config("", "empty.toml");
  EXPECT_EQ(c.channels.angle, "RESOLVER_ANGLE");
  EXPECT_EQ(c.bench.p_r, 3);
  EXPECT_TRUE(c.signal_map.roles[static_cast<std::size_t>(Role::kRdAngle)].has_value());
}

TEST(DaemonConfig, OverridesAndUserSignalMap) {
  const DaemonConfig c = parse_daemon_config(R"(
[lcm]
url = "memq://"
[channels]
angle = "BENCH2_ANGLE"
[output]
angle_decimation = 10
[bench]
p_r = 1
p = 4
[layout]
dbc = "/tmp/x.dbc"
crc = "none"
[layout.signals]
rd_angle = "FB.Angle"
i_a = "CUR.Ia"
)", "user.toml");
  EXPECT_EQ(c.lcm_url, "memq://");
  EXPECT_EQ(c.channels.angle, "BENCH2_ANGLE");
  EXPECT_EQ(c.channels.dq, "RESOLVER_DQ");
  EXPECT_EQ(c.angle_decimation, 10);
  EXPECT_EQ(c.bench.p, 4);
  EXPECT_EQ(c.signal_map.crc, CrcAlgorithm::kNone);
  const auto& rd = c.signal_map.roles[static_cast<std::size_t>(Role::kRdAngle)];
  ASSERT_TRUE(rd.has_value());
  EXPECT_EQ(rd->message, "FB");
  EXPECT_EQ(rd->signal, "Angle");
  EXPECT_FALSE(c.signal_map.roles[static_cast<std::size_t>(Role::kSin)].has_value())
      << "a user map replaces the default one";
}

TEST(DaemonConfig, RelativeDbcPathIsTakenFromTheConfigsFolder) {
  const std::string text = "[layout]\ndbc = \"layouts/my.dbc\"\n";
  EXPECT_EQ(parse_daemon_config(text, "/etc/resolverd/bench.toml").dbc_path, "/etc/resolverd/layouts/my.dbc");
  EXPECT_EQ(parse_daemon_config(text, "configs/bench.toml").dbc_path, "configs/layouts/my.dbc");
  EXPECT_EQ(parse_daemon_config(text, "bench.toml").dbc_path, "layouts/my.dbc");
  EXPECT_EQ(parse_daemon_config("[layout]\ndbc = \"/abs/my.dbc\"\n", "/etc/resolverd/bench.toml").dbc_path,
            "/abs/my.dbc");
}

TEST(DaemonConfig, SyntaxErrorNamesFileAndLine) {
  const std::string e = error_of("[bench]\np_r = 3\np = = 4\n");
  EXPECT_NE(e.find("test.toml:3:"), std::string::npos) << e;
  EXPECT_NE(e.find("TOML syntax error"), std::string::npos) << e;
}

TEST(DaemonConfig, UnknownKeyIsAnErrorListingValidKeys) {
  const std::string e = error_of("[bench]\npr = 3\n");
  EXPECT_NE(e.find("test.toml:2"), std::string::npos) << e;
  EXPECT_NE(e.find("unknown key 'pr'"), std::string::npos) << e;
  EXPECT_NE(e.find("p_r"), std::string::npos) << e;
}

TEST(DaemonConfig, BadValuesAreRejectedWithTheRule) {
  EXPECT_NE(error_of("[bench]\np_r = \"three\"\n").find("must be an integer"), std::string::npos);
  EXPECT_NE(error_of("[bench]\nrd_bits = 20\n").find("rd_bits must be 1..16"), std::string::npos);
  EXPECT_NE(error_of("[output]\nangle_decimation = 0\n").find(">= 1"), std::string::npos);
  EXPECT_NE(error_of("[layout]\ncrc = \"crc32\"\n").find("j1850_bench"), std::string::npos);
  EXPECT_NE(error_of("[layout.signals]\nsine = \"A.b\"\n").find("unknown role 'sine'"), std::string::npos);
  EXPECT_NE(error_of("[layout.signals]\nsin = \"nodot\"\n").find("MESSAGE.signal"), std::string::npos);
  EXPECT_NE(error_of("[estimator]\nmethod = \"magic\"\n")
                .find("available: model, hwang_integral, sincos_least_squares, fourier_reference"),
            std::string::npos);
  // Fuzz finding F4: a float among the harmonic orders was converted out of range
  // (undefined behaviour); integers beyond int wrapped silently (4294967304 -> 8).
  EXPECT_NE(error_of("[estimator]\nharmonics = [3, 1e90]\n").find("orders must be integers 2..16"), std::string::npos);
  EXPECT_NE(error_of("[estimator]\nharmonics = [3.0]\n").find("orders must be integers 2..16"), std::string::npos);
  EXPECT_NE(error_of("[output]\nripple_revolutions = 4294967304\n").find("4294967304 is out of range"),
            std::string::npos);
}

// Issue 25: max_order = 2000 ran for minutes (a fit of 4001 parameters updated
// every sample), 2147483647 ended in std::bad_alloc.
TEST(DaemonConfig, MaxOrderOutsideItsRangeIsNamedWithTheRange) {
  for (const char* v : {"2000", "2147483647", "20", "0", "-3"}) {
    const std::string e = error_of(std::string("[estimator]\nmethod = \"fourier_reference\"\nmax_order = ") + v + "\n");
    EXPECT_NE(e.find("test.toml:3: [estimator] max_order must be 1..19"), std::string::npos) << v << ": " << e;
    EXPECT_NE(e.find(std::string("got ") + v), std::string::npos) << e;
  }
  EXPECT_EQ(parse_daemon_config("[estimator]\nmax_order = 19\n", "ok.toml").fourier.max_order, 19);
  EXPECT_EQ(parse_daemon_config("[estimator]\nmax_order = 1\n", "ok.toml").fourier.max_order, 1);
}

// Issue 25: sample_rate_hz = 1e-300 was taken (every period 1e300 s: "0 moving
// over 3.2e+303 s"), 0.001 made a 2 s log 4e6 s long.
TEST(DaemonConfig, AbsurdRatesAreNamedWithTheRange) {
  for (const char* v : {"1e-300", "0.001", "1e300", "2e6", "-5", "inf", "nan"}) {
    const std::string e = error_of(std::string("[bench]\np = 2\nsample_rate_hz = ") + v + "\n");
    EXPECT_NE(e.find("test.toml:3: [bench] sample_rate_hz must be 1 .. 1e6 Hz (0 = take it from BENCH_INFO), got "),
              std::string::npos)
        << v << ": " << e;
    const std::string r = error_of(std::string("[input.csv]\nrow_rate_hz = ") + v + "\n");
    EXPECT_NE(r.find("test.toml:2: [input.csv] row_rate_hz must be 1 .. 1e6 Hz"), std::string::npos) << v << ": " << r;
  }
  EXPECT_EQ(parse_daemon_config("[bench]\nsample_rate_hz = 0\n", "ok.toml").bench.sample_rate_hz, 0.0);
  EXPECT_EQ(parse_daemon_config("[bench]\nsample_rate_hz = 1\n", "ok.toml").bench.sample_rate_hz, 1.0);
  EXPECT_EQ(parse_daemon_config("[bench]\nsample_rate_hz = 1e6\n", "ok.toml").bench.sample_rate_hz, 1e6);
}

// Issue 25: p_r = 2147483647 was taken, and a replay "converged over 2856153251 revolutions".
TEST(DaemonConfig, PolePairsBeyondWhatABenchHasAreNamed) {
  EXPECT_NE(error_of("[bench]\np_r = 2147483647\n").find("test.toml:2: [bench] p_r must be 1..255 (resolver pole "
                                                           "pairs, as BENCH_INFO carries them), got 2147483647"),
            std::string::npos)
      << error_of("[bench]\np_r = 2147483647\n");
  EXPECT_NE(error_of("[bench]\np_r = 3\np = 256\n").find("test.toml:3: [bench] p must be 1..255 (motor"),
            std::string::npos);
  EXPECT_NE(error_of("[bench]\np = 0\n").find("[bench] p must be 1..255"), std::string::npos);
  const DaemonConfig c = parse_daemon_config("[bench]\np_r = 255\np = 1\n", "ok.toml");
  EXPECT_EQ(c.bench.p_r, 255);
  EXPECT_EQ(c.bench.p, 1);
}

TEST(DaemonConfig, WakeIdsAreAutoOrCanIds) {
  const DaemonConfig d = parse_daemon_config("", "t.toml");
  EXPECT_TRUE(d.can.wake_auto);
  EXPECT_TRUE(d.can.wake_ids.empty());
  EXPECT_TRUE(parse_daemon_config("[can]\nwake_ids = \"auto\"\n", "t.toml").can.wake_auto);
  const DaemonConfig c = parse_daemon_config("[can]\nwake_ids = [0x102, 0x18FF0001]\n", "t.toml");
  EXPECT_FALSE(c.can.wake_auto);
  EXPECT_EQ(c.can.wake_ids, (std::vector<std::uint32_t>{0x102, 0x18FF0001}));
  const DaemonConfig every = parse_daemon_config("[can]\nwake_ids = []\n", "t.toml");
  EXPECT_FALSE(every.can.wake_auto);
  EXPECT_TRUE(every.can.wake_ids.empty());
  EXPECT_NE(error_of("[can]\nwake_ids = 0x102\n").find("test.toml:2: [can] wake_ids must be \"auto\" or an array"),
            std::string::npos);
  EXPECT_NE(error_of("[can]\nwake_ids = \"sometimes\"\n").find("must be \"auto\" or an array"), std::string::npos);
  EXPECT_NE(error_of("[can]\nwake_ids = [0x20000000]\n").find("from 0 to 0x1FFFFFFF"), std::string::npos);
  EXPECT_NE(error_of("[can]\nwake_ids = [-1]\n").find("from 0 to 0x1FFFFFFF"), std::string::npos);
  EXPECT_NE(error_of("[can]\nwake_ids = [\"0x102\"]\n").find("from 0 to 0x1FFFFFFF"), std::string::npos);
}

TEST(DaemonConfig, HealthThresholdsDefaultFromThePhysicsAndOverride) {
  const DaemonConfig d = parse_daemon_config("", "t.toml");
  EXPECT_FALSE(d.health_full_scale_set);  // from the DBC
  EXPECT_DOUBLE_EQ(d.health.loss_of_signal_fraction, 0.05);
  EXPECT_DOUBLE_EQ(d.health.loss_of_tracking_rad, 5.0 * kPi / 180.0);
  const DaemonConfig c = parse_daemon_config(
      "[health]\nfull_scale = 2047\nloss_of_signal_fraction = 0.1\ndegradation_low_fraction = 0.3\n"
      "degradation_high_fraction = 0.9\ndegradation_mismatch = 0.2\nloss_of_tracking_deg = 10\n"
      "overspeed_rad_per_sample = 1.0\nstopped_below_hz = 0.5\noutlier_sigmas = 10\nblock_s = 0.2\n",
      "t.toml");
  EXPECT_TRUE(c.health_full_scale_set);
  EXPECT_DOUBLE_EQ(c.health.full_scale, 2047.0);
  EXPECT_DOUBLE_EQ(c.health.loss_of_signal_fraction, 0.1);
  EXPECT_DOUBLE_EQ(c.health.degradation_low_fraction, 0.3);
  EXPECT_DOUBLE_EQ(c.health.degradation_high_fraction, 0.9);
  EXPECT_DOUBLE_EQ(c.health.degradation_mismatch, 0.2);
  EXPECT_DOUBLE_EQ(c.health.loss_of_tracking_rad, 10.0 * kPi / 180.0);
  EXPECT_DOUBLE_EQ(c.health.overspeed_rad_per_sample, 1.0);
  EXPECT_DOUBLE_EQ(c.health.stopped_below_hz, 0.5);
  EXPECT_DOUBLE_EQ(c.health.outlier_sigmas, 10.0);
  EXPECT_DOUBLE_EQ(c.health.block_s, 0.2);
}

TEST(DaemonConfig, HealthBadValuesAndUnknownKeys) {
  EXPECT_NE(error_of("[health]\nlos = 0.1\n").find("unknown key 'los' in [health]"), std::string::npos);
  EXPECT_NE(error_of("[health]\nfull_scale = -1\n").find("full_scale must be a finite number >= 0"), std::string::npos);
  EXPECT_NE(error_of("[health]\nloss_of_signal_fraction = 0\n").find("loss_of_signal_fraction must be in (0, 1]"),
            std::string::npos);
  EXPECT_NE(error_of("[health]\nloss_of_signal_fraction = nan\n").find("loss_of_signal_fraction must be"),
            std::string::npos);
  EXPECT_NE(error_of("[health]\nloss_of_signal_fraction = 0.5\n").find("loss_of_signal_fraction <= degradation_low"),
            std::string::npos);
  EXPECT_NE(error_of("[health]\noverspeed_rad_per_sample = 4\n").find("(0, pi]"), std::string::npos);
  EXPECT_NE(error_of("[health]\nloss_of_tracking_deg = 0\n").find("(0, 180] degrees"), std::string::npos);
  EXPECT_NE(error_of("[health]\nstopped_below_hz = -1\n").find("stopped_below_hz must be"), std::string::npos);
  EXPECT_NE(error_of("[health]\noutlier_sigmas = 1\n").find("above 2"), std::string::npos);
  EXPECT_NE(error_of("[health]\nblock_s = 0\n").find("block_s must be in (0, 10]"), std::string::npos);
  EXPECT_NE(error_of("[health]\nblock_s = \"fast\"\n").find("must be a number"), std::string::npos);
}

TEST(DaemonConfig, MissingFileSaysSo) {
  try {
    load_daemon_config("/nonexistent/resolverd.toml");
    FAIL();
  } catch (const ConfigError& e) {
    EXPECT_NE(std::string(e.what()).find("/nonexistent/resolverd.toml"), std::string::npos);
  }
}

// A directory opens and reads as an empty file: it must not be a config of defaults
// (resolverd's SIGHUP reload reads the path again with no access check before it).
TEST(DaemonConfig, DirectorySaysSo) {
  try {
    (void)load_daemon_config("/tmp");
    FAIL() << "a directory was loaded as a config";
  } catch (const ConfigError& e) {
    EXPECT_NE(std::string(e.what()).find("/tmp: it is a directory"), std::string::npos) << e.what();
  }
}

TEST(DaemonConfig, CsvScopeExportColumnMap) {
  const DaemonConfig c = parse_daemon_config(R"(
[input]
format = "csv"
[input.csv]
delimiter = ";"
decimal = ","
header_lines = 5
time_column = "Time"
time_unit = "filetime"
[input.csv.columns]
rd_angle = { column = "Resolver", unit = "deg" }
ref_angle = { column = 3, unit = "counts", full_scale = 65536, divide = 21 }
i_a = { column = "Ia", unit = "mA", scale = 2.0, offset = -1.0 }
)", "scope.toml");
  EXPECT_EQ(c.input_format, LogFormat::kCsv);
  EXPECT_EQ(c.csv.format.delimiter, CsvFormat::Delimiter::kSemicolon);
  EXPECT_EQ(c.csv.format.decimal, ',');
  EXPECT_EQ(c.csv.format.header_lines, 5);
  ASSERT_TRUE(c.csv.map.time);
  EXPECT_EQ(c.csv.map.time->name, "Time");
  EXPECT_EQ(c.csv.map.time_unit, TimeUnit::kFiletime);
  const auto& rd = c.csv.map.roles[static_cast<std::size_t>(Role::kRdAngle)];
  ASSERT_TRUE(rd);
  EXPECT_DOUBLE_EQ(rd->to_role_unit, 3.14159265358979323846 / 180.0);
  const auto& ref = c.csv.map.roles[static_cast<std::size_t>(Role::kRefAngle)];
  ASSERT_TRUE(ref);
  EXPECT_EQ(ref->column.index, 3);
  EXPECT_DOUBLE_EQ(ref->to_role_unit, 2.0 * 3.14159265358979323846 / 65536.0);
  EXPECT_DOUBLE_EQ(ref->divide, 21.0);
  const auto& ia = c.csv.map.roles[static_cast<std::size_t>(Role::kIA)];
  ASSERT_TRUE(ia);
  EXPECT_DOUBLE_EQ(ia->to_role_unit, 1e-3);
  EXPECT_DOUBLE_EQ(ia->scale, 2.0);
  EXPECT_DOUBLE_EQ(ia->offset, -1.0);
}

TEST(DaemonConfig, CsvMistakesAreNamed) {
  const std::string base = "[input.csv]\ntime_column = \"t\"\n[input.csv.columns]\n";
  EXPECT_NE(error_of(base + "rd_angle = { column = \"R\" }\n").find("rd_angle: unit \"\" is not an angle unit; one of: rad, deg"),
            std::string::npos);
  EXPECT_NE(error_of(base + "rd_angle = { column = \"R\", unit = \"counts\" }\n").find("needs full_scale"),
            std::string::npos);
  EXPECT_NE(error_of(base + "i_a = { column = \"I\", unit = \"kA\" }\nrd_angle = { column = \"R\", unit = \"rad\" }\n")
                .find("i_a: unit \"kA\" is not a current unit; one of: A, mA"),
            std::string::npos);
  EXPECT_NE(error_of(base + "sin = { column = \"S\", divide = 2 }\n").find("for rd_angle and ref_angle only"),
            std::string::npos);
  EXPECT_NE(error_of(base + "sin = { column = \"S\" }\n").find("needs rd_angle, or both sin and cos"),
            std::string::npos);
  EXPECT_NE(error_of(base + "speed = { column = \"S\" }\n").find("unknown role 'speed'"), std::string::npos);
  EXPECT_NE(error_of("[input.csv]\n[input.csv.columns]\nrd_angle = { column = 2, unit = \"rad\" }\n")
                .find("no time_column: set row_rate_hz"),
            std::string::npos);
  EXPECT_NE(error_of("[input.csv]\ncolumn_names = false\ntime_column = \"t\"\n").find("give its 1-based index"),
            std::string::npos);
  EXPECT_NE(error_of("[input.csv]\ndecimal = \",\"\ndelimiter = \",\"\n").find("cannot be told apart"),
            std::string::npos);
  EXPECT_NE(error_of("[input.csv]\ntime_unit = \"min\"\n").find("\"filetime\""), std::string::npos);
  EXPECT_NE(error_of("[input]\nformat = \"blf\"\n").find("\"asc\""), std::string::npos);
}

TEST(DaemonConfig, LogFormatFromTheExtension) {
  EXPECT_EQ(log_format_for_path("a/b.log"), LogFormat::kCandump);
  EXPECT_EQ(log_format_for_path("b.ASC"), LogFormat::kAsc);
  EXPECT_EQ(log_format_for_path("scope.csv"), LogFormat::kCsv);
  EXPECT_EQ(log_format_for_path("optical_encoder_ab.txt"), LogFormat::kCsv);
  EXPECT_EQ(log_format_for_path("dir.csv/noext"), LogFormat::kCandump);
}

}  // namespace
}  // namespace resolver
