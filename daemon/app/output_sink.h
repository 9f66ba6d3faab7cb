// Where the pipeline's messages go. The pipeline only sees this interface;
// LcmOutput publishes on LCM, tests record into vectors (Drake's
// DrakeLcmInterface idea: the transport is passed in, never global).
#pragma once

#include <resolver/angle_t.hpp>
#include <resolver/dq_t.hpp>
#include <resolver/estimate_t.hpp>
#include <resolver/health_t.hpp>
#include <resolver/model_fit_t.hpp>

namespace resolver {

class OutputSink {
 public:
  virtual ~OutputSink() = default;
  virtual void publish(const angle_t& msg) = 0;
  virtual void publish(const dq_t& msg) = 0;
  virtual void publish(const estimate_t& msg) = 0;
  virtual void publish(const model_fit_t& msg) = 0;
  virtual void publish(const health_t& msg) = 0;
};

}  // namespace resolver
