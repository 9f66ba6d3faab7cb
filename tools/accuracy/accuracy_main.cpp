// resolver-accuracy: how close the estimators come to the Cramer-Rao bound, how
// fast they converge and how much 2x dq ripple their compensation removes, on
// simulated data with known truth (accuracy_experiments.h). Prints markdown.
#include <CLI/CLI.hpp>
#include <fmt/format.h>

#include <chrono>
#include <cmath>
#include <cstdio>
#include <exception>
#include <stdexcept>
#include <string>

#include "daemon/app/exit_codes.h"
#include "tools/accuracy/accuracy_experiments.h"
#include "daemon/service/program_version.h"

namespace {

using namespace resolver::accuracy;

constexpr double kStdTarget = 2.0;      // least-squares std <= 2 x CRLB (issue)
constexpr double kRippleTargetDb = 40.0;  // ripple reduction >= 40 dB ... (issue)
constexpr double kFloorFactor = 1.5;    // ... or within 1.5 x the noise floor (mean over seeds)
constexpr double kConvergedRevs = 1.0;  // signal-domain estimator within 1 % of alpha after 1 revolution

// Comments above the commands: help2man splits "command   # comment" into a tagged
// paragraph, the command apart from its comment.
constexpr const char* kExamples = R"(Examples:
  # 50 seeds, the full report (about a minute)
  resolver-accuracy
  # 10 seeds, a smoke run
  resolver-accuracy --quick
  resolver-accuracy --seeds 200 > accuracy.md)";

std::string sci(double v) {
  if (std::isnan(v)) return "-";
  return fmt::format("{:.2e}", v);
}

std::string revs(double r) {
  if (std::isinf(r)) return "never";
  return fmt::format("{:.2f}", r);
}

void print_accuracy(const AccuracyStudy& st, int seeds) {
  const auto& ch = st.config.chain;
  fmt::print("\n## Estimator accuracy: alpha = {}, beta = {} rad, o_s = {}, o_c = {}\n\n",
             ch.get("amplitude_imbalance", "alpha"), ch.get("quadrature", "beta"), ch.get("offsets", "o_s"),
             ch.get("offsets", "o_c"));
  fmt::print("{} r/min constant, {} samples per log ({:.0f} resolver electrical revolutions), {} seeds. "
             "Bound: CRLB (cramer_rao.h) with sigma_eff = {:.3f} counts and A = {:.0f} counts for the sin/cos "
             "estimators; the LS floor of the R/D quantization (sigma_q = {:.3e} rad) for the R/D-angle ones.\n\n",
             st.config.profile.front().rpm_start, st.samples, st.revolutions, seeds, st.sigma_sc_eff,
             st.config.amplitude_counts, st.sigma_q);
  fmt::print("| estimator | param | truth | bias | std | bound | bound kind | std/bound | mean reported se | std <= 2 bound |\n");
  fmt::print("|---|---|---|---|---|---|---|---|---|---|\n");
  for (const EstimatorStats& e : st.estimators) {
    for (const ParamStats& p : e.params) {
      const double ratio = p.std / p.bound;
      const std::string target = e.signal_domain ? (ratio <= kStdTarget ? "met" : "NOT met") : "(n/a: R/D)";
      fmt::print("| {} | {} | {:g} | {} | {} | {} | {} | {:.2f} | {} | {} |\n", e.name, p.name, p.truth, sci(p.bias),
                 sci(p.std), sci(p.bound), e.bound_kind, ratio, sci(p.mean_reported_se), target);
    }
  }
  fmt::print("\nSame logs, alpha differences per log (mean +- std over seeds): Hwang - LS(reference) = {} +- {}; "
             "Fourier - LS(reference) = {} +- {}.\n",
             sci(st.hwang_minus_ls_mean), sci(st.hwang_minus_ls_std), sci(st.fourier_minus_ls_mean),
             sci(st.fourier_minus_ls_std));
}

void print_convergence(const std::vector<ConvergenceStudy>& studies, int seeds) {
  fmt::print("\n## Convergence to within 1 % of alpha (alpha only, 200 r/min, {} seeds)\n\n", seeds);
  fmt::print("Resolver electrical revolutions of data (p_r = p = 3, so also motor electrical revolutions) after which "
             "every later estimate, checked each quarter revolution up to the end of the log, stays within 1 %. Bias and std "
             "at end: the estimate from the whole log (10 revolutions), over seeds: Hwang vs least squares on the same "
             "alpha-only logs.\n\n");
  fmt::print("| estimator | alpha | median | 90 % | max | seeds within 1 rev | target (signal domain: <= 1 rev) | "
             "bias at end | std at end |\n");
  fmt::print("|---|---|---|---|---|---|---|---|---|\n");
  for (const ConvergenceStudy& st : studies) {
    for (const ConvergenceStats& e : st.estimators) {
      const bool signal = e.name.rfind("sin/cos", 0) == 0;
      const double q90 = e.quantile(0.9);
      std::string target = "(n/a)";
      if (signal) target = q90 <= kConvergedRevs + 1e-9 ? "met (90 % of seeds)" : "NOT met";
      if (signal && e.quantile(1.0) <= kConvergedRevs + 1e-9) target = "met (all seeds)";
      fmt::print("| {} | {:g} | {} | {} | {} | {:.0f} % | {} | {} | {} |\n", e.name, st.alpha, revs(e.quantile(0.5)),
                 revs(q90), revs(e.quantile(1.0)), 100.0 * e.fraction_within(kConvergedRevs), target,
                 sci(e.final_bias(st.alpha)), sci(e.final_std()));
    }
  }
}

std::string reduction(double raw, double comp, double floor) {
  const double db = 20.0 * std::log10(raw / comp);
  const char* verdict = db >= kRippleTargetDb ? "met" : (comp <= kFloorFactor * floor ? "floor" : "NOT met");
  return fmt::format("{:.1f} ({})", db, verdict);
}

void print_ripple(const std::vector<RippleStudy>& studies) {
  fmt::print("\n## 2x i_d ripple, raw vs compensated angle (alpha only, I_q = 10 A)\n\n");
  fmt::print("Estimators fitted on the first second, ripple coherently averaged over the next two seconds; amplitudes "
             "are means over seeds [A]. Floor = expected 2x amplitude of the current and angle noise alone "
             "(accuracy_experiments.cpp). dB = 20 log10(raw / compensated); (met) >= 40 dB, (floor) within "
             "{} x the floor.\n\n",
             kFloorFactor);
  fmt::print("| r/min | alpha | seeds | revs | raw | Hwang | Fourier | sin/cos LS | reference angle | floor R/D | floor sin/cos | "
             "dB Hwang | dB Fourier | dB sin/cos |\n");
  fmt::print("|---|---|---|---|---|---|---|---|---|---|---|---|---|---|\n");
  for (const RippleStudy& r : studies) {
    fmt::print("| {:.0f} | {:g} | {} | {:.0f} | {} | {} | {} | {} | {} | {} | {} | {} | {} | {} |\n", r.rpm, r.alpha,
               r.seeds, r.eval_revolutions, sci(r.raw), sci(r.hwang), sci(r.fourier), sci(r.sincos), sci(r.ref),
               sci(r.floor_rd), sci(r.floor_sincos), reduction(r.raw, r.hwang, r.floor_rd),
               reduction(r.raw, r.fourier, r.floor_rd), reduction(r.raw, r.sincos, r.floor_sincos));
  }
}

int run(int argc, char** argv) {
  CLI::App app{"resolver-accuracy: estimator bias and spread against the Cramer-Rao bound, convergence and 2x dq "
               "ripple reduction on simulated data with known truth; prints a markdown report.",
               "resolver-accuracy"};  // the name in the usage line, not argv[0] (a build path)
  app.footer(std::string(kExamples) + "\n" + resolver::exit_code::kHelpText);
  app.set_version_flag("--version", resolver::version_line("resolver-accuracy"));
  int seeds = 50;
  bool quick = false;
  app.add_option("--seeds", seeds, "number of simulated logs per configuration (default 50)")->check(CLI::Range(2, 100000));
  app.add_flag("--quick", quick, "10 seeds unless --seeds is given: a smoke run");
  if (auto code = resolver::exit_code::parse_command_line(app, argc, argv)) return *code;
  if (quick && app.get_option("--seeds")->count() == 0) seeds = 10;

  // No input to blame: what a study throws is a bug (70; a refused argument too, not a
  // usage error), or out of memory (4).
  try {
    const auto t0 = std::chrono::steady_clock::now();
    fmt::print("# resolver-accuracy\n\n");
    fmt::print("Simulator defaults (tools/sim/bench_simulator.h): p_r = p = 3, 2 kHz samples, A = 26000 counts, "
               "sigma_sc = 2 counts, sigma_i = 0.02 A, 16-bit R/D with a type-II loop (omega_n = 3000 rad/s, "
               "zeta = 0.7), reference encoder aligned. {} seeds; seed k also draws the start angle.\n",
               seeds);
    StudyOptions opt;
    opt.seeds = seeds;
    for (double alpha : {0.03, 0.003}) print_accuracy(run_accuracy_study(alpha, opt), seeds);
    std::vector<ConvergenceStudy> conv;
    for (double alpha : {0.03, 0.003}) conv.push_back(run_convergence_study(alpha, opt));
    print_convergence(conv, seeds);
    std::vector<RippleStudy> ripple;
    for (double rpm : {200.0, 1000.0}) {
      for (double alpha : {0.003, 0.03}) ripple.push_back(run_ripple_study(rpm, alpha, seeds));
    }
    print_ripple(ripple);
    const double secs = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
    fmt::print("\nRun time {:.1f} s.\n", secs);
  } catch (const std::invalid_argument& e) {
    throw std::logic_error(e.what());
  }
  return std::fflush(stdout) == 0 ? resolver::exit_code::kDone : resolver::exit_code::kIo;
}

}  // namespace

int main(int argc, char** argv) {
  return resolver::run_program("resolver-accuracy", [&] { return run(argc, argv); });
}
