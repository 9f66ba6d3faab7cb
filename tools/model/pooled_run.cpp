#include "tools/model/pooled_run.h"

#include <algorithm>
#include <future>
#include <iostream>
#include <stdexcept>

#include "daemon/core/discovery/pool.h"
#include "daemon/service/program_errors.h"
#include "tools/model/model_report.h"
#include "tools/model/pool_report.h"

namespace resolver {

namespace {

/// Every log read, `jobs` at a time, in the order given (a reader's exception
/// propagates from the first log that failed).
std::vector<LogSamples> read_all(const PooledRun& run) {
  std::vector<LogSamples> out(run.logs.size());
  const auto jobs = static_cast<std::size_t>(std::max(1, run.jobs));
  for (std::size_t first = 0; first < run.logs.size(); first += jobs) {
    const std::size_t last = std::min(run.logs.size(), first + jobs);
    std::vector<std::future<LogSamples>> reading;
    for (std::size_t i = first; i < last; ++i) {
      reading.push_back(std::async(jobs == 1 ? std::launch::deferred : std::launch::async, run.read, run.logs[i],
                                   jobs > 1));
    }
    for (std::size_t i = first; i < last; ++i) out[i] = reading[i - first].get();
  }
  return out;
}

}  // namespace

int run_pooled(const PooledRun& run) {
  std::vector<LogSamples> samples = read_all(run);
  DiscoveryOptions options = run.options;
  std::vector<std::string> notes;
  std::vector<const DiscoveryInput*> inputs;
  for (std::size_t i = 0; i < samples.size(); ++i) {
    DiscoveryOptions own = run.options;
    run.weigh_faults(samples[i], own);
    for (const std::string& u : own.untrusted_input) options.untrusted_input.push_back(run.logs[i] + ": " + u);
    for (const std::string& n : run.notes(samples[i])) notes.push_back(run.logs[i] + ": " + n);
    inputs.push_back(&samples[i].input);
  }
  PooledExplanation p;
  try {
    p = explain_pooled(inputs, run.logs, run.effects, options, run.explain);
  } catch (const std::invalid_argument& e) {
    throw InputError(Fault::kData, e.what());
  }
  std::cout << (run.json ? format_model_json(p.pooled, run.explain, notes, format_pool_json(p))
                         : format_model_text(p.pooled, run.explain, notes) + format_pool_text(p));
  return 0;
}

}  // namespace resolver
