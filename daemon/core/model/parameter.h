// One named value with its error: the one parameter type of every output.
// The Model's fitted parameters, the older estimators' results (estimate_t),
// discovery's fits and candidates, the persisted calibration, the exported table
// and the reports all carry their parameters as this.
#pragma once

#include <string>

namespace resolver {

struct ModelParameter {
  std::string name;        ///< "effect.param" (the registry's names; "signal.amplitude" for
                           ///< the sin/cos least squares' nuisance)
  double value = 0.0;      ///< in the parameter's own unit
  double std_error = 0.0;  ///< one standard error, same unit; NaN: not identifiable
  std::string unit;        ///< the registry's ParamInfo::unit, e.g. "[rad]"; empty where it has none
  bool operator==(const ModelParameter&) const = default;
};

}  // namespace resolver
