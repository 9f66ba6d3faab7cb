#include "tools/model/pooled_run.h"

#include <algorithm>
#include <future>
#include <iostream>
#include <stdexcept>

#include "daemon/core/discovery/pool.h"
#include "daemon/service/program_errors.h"
#include <fmt/format.h>
#include <fmt/ranges.h>

#include "tools/model/discovery_run.h"
#include "tools/model/html_page.h"
#include "tools/model/html_report.h"
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


/// The page of the discovery loop on the pooled logs, with each log's residual and own
/// fit (of the final model) in a section of its own.
int write_pooled_report(const PooledRun& run, const std::vector<const DiscoveryInput*>& inputs,
                        const std::vector<LogSamples>& samples, DiscoveryOptions options) {
  options.series_points = 4000;  // as write_report (resolver_model_main.cpp)
  DiscoveryRun discovery;
  LogComparison logs;
  try {
    auto pooled = std::make_shared<PooledLogs>(prepare_pooled(inputs, run.logs, options.prepare));
    discovery = run_discovery(std::shared_ptr<const PreparedLog>(pooled, &pooled->pool), run.effects, options, run.max_steps);
    const ModelFit& last = discovery.steps.back().fit;
    logs = compare_logs(*pooled, run.logs, last, last.effects, options);
  } catch (const std::invalid_argument& e) {
    throw InputError(Fault::kData, e.what());
  }
  // What the page's header counts, over every log.
  LogSamples all;
  all.bench_info = true;
  for (std::size_t i = 0; i < samples.size(); ++i) {
    all.frames += samples[i].frames;
    all.bench_info = all.bench_info && samples[i].bench_info;
    for (const std::string& n : run.notes(samples[i])) all.notes.push_back(run.logs[i] + ": " + n);
  }
  for (std::string& n : disagreement_notes(logs.comparisons)) all.notes.push_back(std::move(n));
  const std::string section = "<h2 id=\"pooled\">The pooled logs</h2>\n<pre>" +
                              html::escape(format_pool_text(run.logs, discovery.steps.back().fit, logs)) + "</pre>\n";
  const std::string page =
      format_model_html(discovery, all, fmt::format("{}", fmt::join(run.logs, " + ")), options.explained_ratio, section);
  write_text_file(run.html_out, page);  // throws std::system_error: exit 3
  std::cout << summarize_discovery(discovery) << "\n"
            << "wrote " << run.html_out << " (" << (page.size() + 512) / 1024 << " KiB)\n";
  return 0;
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
  if (!run.html_out.empty()) return write_pooled_report(run, inputs, samples, options);
  PooledExplanation p;
  try {
    p = explain_pooled(inputs, run.logs, run.effects, options, run.explain);
  } catch (const std::invalid_argument& e) {
    throw InputError(Fault::kData, e.what());
  }
  std::cout << (run.json ? format_model_json(p.pooled, run.explain, notes, format_pool_json(p.names, p.pooled.fit, p.logs))
                         : format_model_text(p.pooled, run.explain, notes) + format_pool_text(p.names, p.pooled.fit, p.logs));
  return 0;
}

}  // namespace resolver
