// resolver-model fit|explain A.log B.log ...: several logs of one bench fitted
// together (daemon/core/discovery/pool.h), read --jobs at a time.
#pragma once

#include <functional>
#include <string>
#include <vector>

#include "daemon/core/discovery/model_discovery.h"
#include "tools/model/log_samples.h"

namespace resolver {

struct PooledRun {
  std::vector<std::string> logs;
  std::vector<std::string> effects;
  DiscoveryOptions options;  ///< the untrusted inputs of every log are added, named by log
  bool explain = false;
  bool json = false;
  std::string html_out;  ///< report: the page to write (then the discovery loop runs, at most max_steps)
  int max_steps = 6;
  int jobs = 1;  ///< logs read at once (each read is one thread)
  /// Reads one log (a progress bar only when `quiet` is false: one log at a time).
  std::function<LogSamples(const std::string& log, bool quiet)> read;
  /// The log's faults that held for a large part of it, and its notes.
  std::function<void(LogSamples&, DiscoveryOptions&)> weigh_faults;
  std::function<std::vector<std::string>(const LogSamples&)> notes;
};

/// Reads, pools and fits (or with html_out runs the discovery loop and writes the page);
/// prints the text or JSON report (or the page's summary line) to stdout; returns 0.
/// A log that cannot be read throws its reader's error; one the fit refuses, or
/// logs that cannot be pooled, an InputError (data) naming the log.
int run_pooled(const PooledRun& run);

}  // namespace resolver
