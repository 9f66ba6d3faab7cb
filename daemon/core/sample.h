// One joined bench sample, as every consumer sees it: resolverd's estimator,
// compensation and live model fit, and resolver-model offline. One struct and one
// time axis for both programs, so the same log fits the same way live and offline.
//
// Where the fields come from: the input layer (daemon/decode for CAN logs and
// SocketCAN, CSV/scope exports) joins the frames or rows of one control period
// and converts every signal to the units below; the sample clock sets t.
#pragma once

#include <cstdint>

namespace resolver {

struct Sample {
  /// [s] sample time: counter index / sample rate where the layout has a counter
  /// and the rate is known, else the frame's (or row's) timestamp. Any origin.
  double t = 0.0;
  /// Sample number: the counter unwrapped over its range (gaps advance it), or a
  /// running count of samples when the layout has no counter.
  std::int64_t index = 0;
  /// [us] timestamp of the sample's first frame or row (LCM utime).
  std::int64_t utime = 0;

  bool has_rd = false;
  double theta_rd = 0.0;  ///< [rad] R/D converter angle, resolver electrical, wrapped to [0, 2pi)
  bool has_sincos = false;
  double sin = 0.0;  ///< demodulated sin envelope [counts, any consistent unit]
  double cos = 0.0;  ///< demodulated cos envelope [same unit as sin]
  bool has_ref = false;
  double theta_m_ref = 0.0;  ///< [rad] reference encoder, mechanical, wrapped to [0, 2pi)
  bool has_currents = false;
  double i_a = 0.0, i_b = 0.0, i_c = 0.0;  ///< [A] measured phase currents
};

}  // namespace resolver
