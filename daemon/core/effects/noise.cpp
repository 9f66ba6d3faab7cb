#include "daemon/core/effects/noise.h"

namespace resolver {

double gaussian_noise(NoiseEngine& engine, double sigma) {
  if (sigma == 0.0) return 0.0;
  // A fresh distribution per draw: no cached second value hides in a member, so
  // the sequence depends only on the engine state.
  std::normal_distribution<double> dist(0.0, sigma);
  return dist(engine);
}

}  // namespace resolver
