// Impulsive samples (EMI spikes, bit errors): found by a robust test, counted,
// kept out of fits and floors, and reported.
//
// Test: the second difference d_i = y_{i+1} - 2 y_i + y_{i-1} of a signal over
// consecutive samples. A spike of size a at i gives the pattern (a, -2a, a), so
// sample i is an outlier when |d_i| exceeds kThreshold (12) robust standard
// deviations of d and is the largest of its three neighbours, and is no kink: a
// smooth signal's slope turning at one sample (a start from standstill, an instant
// speed step) moves only its own d, a spike its neighbours' by half its own
// (outliers.cpp kKinkShare; a simulated bench's starts at 5-15 % offsets were flagged
// in sin/cos and the position error). The robust scale
// is the MAD of d, bounded below by half the mean |d| (a quantized, slow signal
// has a zero MAD). For Gaussian noise 12 sigma is never reached (P < 1e-32); the
// smooth part of the signal (the error harmonics the fit explains) changes d by
// (k omega dt)^2 of its amplitude and enters the scale, not the test.
//
// find_outlier_bursts (the phase currents and sin/cos: prepare.cpp): spikes come in bursts too (a
// switching edge's ringing, a bus glitch over a few frames) and at a run's ends. Two
// spikes side by side or a sample apart tie or mask each other's patterns, and a run's
// last sample has no d: on a resolver-sim log with one-sided 10 A spikes on a phase
// current (50/s, 2 kHz) the single pass missed 8 of ~440 and flagged clean samples
// between them, and the missed ones (10 A against a 0.02 A floor) put i_dq at 9x its
// floor and its standstill floor at 24x. So:
//   - the test is twice the distance of y_i from the line through its nearest
//     unflagged neighbours (the same d for neighbours one apart; at most kMaxGap
//     samples away, so a smooth signal's curvature enters at most kMaxGap^2 / 4 times),
//     or at a run's end the line through the two on one side, extrapolated, its limit
//     widened by its noise;
//   - first-pass peaks are ranked also by the line that skips one sample each side
//     (beside a pair it misses both spikes);
//   - later passes take the flagged samples out and test again beside the large ones
//     (outliers.cpp kPeelAbove), until nothing new is flagged;
//   - the scale's mean |d| is over the |d| below 12 MADs (with the spikes in, the plain
//     mean put the scale at 10x the noise's);
//   - the components (i_d and i_q; sin/cos's angle and radius) are judged together: a
//     sample's rank is its largest over them in units of each one's limit (ranked one
//     after the other, a kink beside a spike large in the radius and small in the angle
//     took three clean samples with it);
//   - at the end, a flagged sample on the line through its unflagged neighbours in every
//     component (a clean one between spikes), or on the parabola through two either side
//     where the line spans flagged samples (the line misses a fast signal's curvature),
//     is unflagged, and so is a kink the first pass could not tell for a spike near it.
// A burst longer than about 2 kMaxGap - 1 samples is a level step, not a spike.
#pragma once

#include <cstdint>
#include <span>
#include <string>
#include <vector>

namespace resolver {

struct OutlierSignal {
  std::string signal;          ///< "position_error", "sin_cos", "i_dq"
  std::int64_t count = 0;
  double largest = 0.0;        ///< largest |spike| [unit of the signal]
  double scale = 0.0;          ///< robust sigma of the second differences [unit]
  std::vector<double> times;   ///< [s] of the first ones (at most 10)
};

/// Marks outliers of `y` (consecutive samples; `usable[i]` false = skip and break
/// the sequence) in `flags` (set to true). Returns the summary for `signal`.
OutlierSignal find_outliers(std::span<const double> t, std::span<const double> y, const std::vector<bool>& usable,
                            std::vector<bool>& flags, const std::string& signal);

/// The same with the later passes, the runs' ends and the trimmed scale (above), over
/// the components `ys` of one signal together (i_d and i_q, or sin/cos's angle and radius:
/// a sample is clean again only where it is on the line in both). For the phase currents
/// and sin/cos, whose spikes are the ADCs' (on a resolver-sim log with 3000-count spikes
/// on sin at 50/s, the one pass left one of a pair in: sin/cos at 19.7x its floor and three
/// effects proposed that were not there; on another seed the floor took them, 0.45x).
/// The position error keeps the one pass: its physical transients (an instant stop's
/// R/D loop ringing, a backlash take-up: steps the later passes peel sample by sample,
/// and whose large |d| the trimmed scale leaves out) moved a chunked backlash fit by 0.24
/// of its standard error from its whole log's.
OutlierSignal find_outlier_bursts(std::span<const double> t, std::span<const std::span<const double>> ys,
                                  const std::vector<bool>& usable, std::vector<bool>& flags, const std::string& signal);

}  // namespace resolver
