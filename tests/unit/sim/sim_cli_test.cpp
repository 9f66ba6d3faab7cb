// resolver-sim's command line: every catalog v2 and registry effect is accepted through
// --effect, lands in the truth file, and a bad value fails naming the parameter.
// Runs the real executable (RESOLVER_SIM_EXE, set by tests/unit/sim/CMakeLists.txt).
#include <gtest/gtest.h>

#include <cstdio>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>
#include <sys/wait.h>

namespace {

struct Result {
  int status = -1;
  std::string output;  ///< stdout and stderr
};

Result run(const std::string& args) {
  const std::string command = std::string(RESOLVER_SIM_EXE) + " " + args + " 2>&1";
  Result r;
  FILE* pipe = ::popen(command.c_str(), "r");
  if (pipe == nullptr) return r;
  char buf[512];
  while (std::fgets(buf, sizeof buf, pipe) != nullptr) r.output += buf;
  const int raw = ::pclose(pipe);
  r.status = WIFEXITED(raw) ? WEXITSTATUS(raw) : -1;
  return r;
}

std::string read_file(const std::filesystem::path& p) {
  std::ifstream in(p);
  std::stringstream ss;
  ss << in.rdbuf();
  return ss.str();
}

TEST(SimCli, EveryNewEffectThroughDashDashEffect) {
  const std::filesystem::path dir = std::filesystem::temp_directory_path() / ("resolver_sim_cli_" + std::to_string(::getpid()));
  std::filesystem::create_directories(dir);
  const struct {
    const char* spec;
    const char* in_truth;
  } cases[] = {
      {"sampling_skew:tau=2e-6", "\"sampling_skew\": {\"tau\": 2e-06}"},
      {"eccentricity:e=5e-4,phase=1", "\"eccentricity\": {\"e\": 0.0005, \"phase\": 1}"},
      {"mounting_offset:theta_0=0.05", "\"mounting_offset\": {\"theta_0\": 0.05}"},
      {"current_offsets:off_a=0.05,off_b=-0.03", "\"current_offsets\": {\"off_a\": 0.05, \"off_b\": -0.03}"},
      {"current_gain_mismatch:gain_a=0.01", "\"current_gain_mismatch\": {\"gain_a\": 0.01, \"gain_b\": 0}"},
      {"dead_time:t_d=2e-6", "\"dead_time\": {\"t_d\": 2e-06}"},
      // The registry's effects added in issue 12.
      {"delay:d=1e-3", "\"delay\": {\"d\": 0.001}"},
      {"backlash:h=0.01", "\"backlash\": {\"h\": 0.01}"},
      {"channel_delay:tau=2e-6", "\"channel_delay\": {\"tau\": 2e-06}"},
      {"harmonics:k3_opp=2e-4,k20=1e-5", "\"harmonics\": {\"k20\": 1e-05, \"k3_opp\": 0.0002}"},
      {"mechanical_harmonics:a2=1e-4,b2=-1e-4", "\"mechanical_harmonics\": {\"a2\": 0.0001, \"b2\": -0.0001}"},
      {"outliers:rate=10,size=2000", "\"outliers\": {\"rate\": 10, \"size\": 2000}"},
  };
  for (const auto& c : cases) {
    const std::filesystem::path log = dir / "x.log";
    const std::filesystem::path truth = dir / "x.json";
    const Result r = run("--out " + log.string() + " --duration 0.05 --truth " + truth.string() + " --effect " + c.spec);
    ASSERT_EQ(r.status, 0) << c.spec << "\n" << r.output;
    EXPECT_GT(std::filesystem::file_size(log), 0U);
    const std::string json = read_file(truth);
    EXPECT_NE(json.find(c.in_truth), std::string::npos) << c.spec << "\n" << json;
  }
  const Result bad = run("--out " + (dir / "bad.log").string() + " --duration 0.05 --effect sampling_skew:tau=0.5");
  EXPECT_EQ(bad.status, 2);
  EXPECT_NE(bad.output.find("tau"), std::string::npos) << bad.output;
  const Result unknown = run("--out " + (dir / "bad.log").string() + " --duration 0.05 --effect backlash:width=0.01");
  EXPECT_EQ(unknown.status, 2);
  EXPECT_NE(unknown.output.find("'width'"), std::string::npos) << unknown.output;
  EXPECT_NE(unknown.output.find("valid parameters: h"), std::string::npos) << unknown.output;
  const Result listing = run("--list-effects");
  EXPECT_EQ(listing.status, 0);
  EXPECT_EQ(listing.output.find("not implemented"), std::string::npos) << listing.output;
  EXPECT_NE(listing.output.find("dead_time"), std::string::npos);
  std::filesystem::remove_all(dir);
}

}  // namespace
