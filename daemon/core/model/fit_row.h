// One prepared sample of a log as the fit sees it: the true angles and speed
// (signature.h's SignatureRow) and the measured deviations of every signal from
// an ideal chain (NaN where the log lacks the signal). Built by discovery's
// prepare step (daemon/core/discovery/prepare.h) and by the live window.
#pragma once

#include <cstdint>

#include "daemon/core/effects/signature.h"

namespace resolver {

struct FitRow {
  enum Flag : std::uint16_t {
    kHasRd = 1U << 0U,     ///< y_rd valid
    kHasSc = 1U << 1U,     ///< y_sa, y_sr valid
    kHasCur = 1U << 2U,    ///< y_d, y_q valid
    kMoving = 1U << 3U,    ///< the rotor moves (standstill rows enter no fit)
    kOutlier = 1U << 4U,   ///< an impulsive sample: kept out of fits and floors
    kFoldB = 1U << 5U,     ///< held-back validation: the second fold
    kExcluded = 1U << 6U,  ///< left out by the user's slicing (--direction, --moving-only) or unusable
  };
  SignatureRow sig;
  double y_rd = 0.0;  ///< [rad] theta_true - theta_rd
  double y_sa = 0.0;  ///< [rad] theta_true - atan2(s, c)
  double y_sr = 0.0;  ///< [1] radius / amplitude - 1
  double y_d = 0.0;   ///< [A] i_d in the frame of the true theta_e
  double y_q = 0.0;   ///< [A]
  std::uint16_t flags = 0;
  std::uint16_t part = 0;  ///< which log of a pooled fit (design.h "Parts"); 0 for one log
  std::int32_t block = 0;  ///< electrical revolution the row belongs to (robust standard errors)

  [[nodiscard]] bool has(Flag f) const { return (flags & f) != 0; }
  /// Enters the fit: moving and not an outlier.
  [[nodiscard]] bool fitted() const { return has(kMoving) && !has(kOutlier) && !has(kExcluded); }
};

}  // namespace resolver
