// The report page's plots as data: what each plot draws, in the units it shows
// (angles [deg], position error [arcmin], currents [A] or [mA]), and the JSON that
// the page's script (web/report_page.js) draws with uPlot and offers as CSV.
//
// Angle plots show binned means with a spread band over every fitted sample of the
// log (not a decimated series): a bin of the angle (2 deg) holds the mean of the
// samples that fall in it, their standard deviation and their mean angle (the
// point's x, so a curve is not shifted by where the samples sit in the bin). A bin
// with no sample is null: a line breaks only where the log has no angle. Measured
// data is drawn as dots in a band over the model's line. The discovery's per-sample
// series (ModelFit::series) ride along as the individual samples, hidden until the
// reader shows them. Each angle plot says how many of its bins hold samples.
//
// Pure: strings and vectors, no I/O.
#pragma once

#include <cstdint>
#include <limits>
#include <span>
#include <string>
#include <string_view>
#include <vector>

#include "tools/model/discovery_run.h"

namespace resolver::report {

/// Angle bins of the page's angle plots: 2 deg each, ~20 samples a bin at the report's series size.
inline constexpr int kAngleBins = 180;

enum class Mark : std::uint8_t {
  kLine,        ///< a line through (x, y); null y breaks it
  kPoints,      ///< dots
  kLinePoints,  ///< both
  kBand,        ///< binned mean as dots, with a band mean +- spread
};

struct Series {
  std::string label;  ///< legend text and the CSV's series column
  std::string color;  ///< CSS colour
  Mark mark = Mark::kLine;
  std::vector<double> x, y;  ///< same length; NaN y: no value (a gap)
  std::vector<double> spread;  ///< kBand: one standard deviation of the bin's samples
  std::vector<double> count;   ///< kBand: samples in the bin
  bool dashed = false;
  bool hidden = false;  ///< starts hidden; the legend shows it
  bool legend = true;   ///< false: no legend entry of its own (shown and hidden with the entry before it)
  double width = 1.5;   ///< [px] line width or dot diameter
  int digits = 6;       ///< significant digits in the page's data
  // Drawn by the fleet page's own script (web/fleet_page.js); empty on the report page.
  std::vector<double> error;       ///< per point, an error bar of +- this (a standard error); NaN: none
  std::vector<std::string> names;  ///< per point, what it is (a unit id): the readout shows it
  bool label_points = false;       ///< names written beside the points
};

struct Axis {
  std::string label;   ///< what it is, e.g. "θ, resolver electrical angle"
  std::string unit;    ///< e.g. "deg"; shown in brackets and in the CSV header
  std::string column;  ///< CSV column name (a MATLAB/pandas identifier), e.g. "theta_deg"
  bool log = false;
  double lo = std::numeric_limits<double>::quiet_NaN();  ///< fixed range (and zoom reset); NaN: from the data
  double hi = std::numeric_limits<double>::quiet_NaN();
  double step = 0.0;  ///< tick spacing; 0: automatic
};

struct Plot {
  std::string id;       ///< unique within the page
  std::string group;    ///< plots of one group zoom together (same x); empty: alone
  std::string title;
  std::string caption;  ///< plain text under the plot
  Axis x, y;
  std::vector<Series> series;
  int height = 300;     ///< [px]
  bool half = false;    ///< two to a row
  int angle_bins = 0;   ///< > 0: an angle plot, this many bins over [x.lo, x.hi)
  int filled_bins = 0;  ///< of them, bins holding at least one sample
};

struct AngleBins {
  std::vector<double> centre;  ///< [deg] mean angle of the bin's samples (the bin's centre when empty)
  std::vector<double> mean;    ///< of y in the bin (NaN when empty)
  std::vector<double> sd;      ///< standard deviation of y in the bin (NaN when empty, 0 for one sample)
  std::vector<double> count;
  int filled = 0;
};

/// Means and spreads of y in equal bins of an angle, accumulated one sample at a time.
class AngleBinner {
 public:
  /// `bins` equal bins over [0, 2 pi); y is multiplied by `scale` (e.g. rad -> arcmin).
  explicit AngleBinner(int bins = kAngleBins, double scale = 1.0);
  /// angle [rad], any value (wrapped). Non-finite pairs are skipped.
  void add(double angle, double y);
  [[nodiscard]] AngleBins result() const;

 private:
  double scale_;
  std::vector<double> n_, sum_, sum2_, angle_sum_;
};

/// AngleBinner over paired spans.
[[nodiscard]] AngleBins bin_by_angle(std::span<const double> angle, std::span<const double> y, int bins,
                                     double scale = 1.0);

/// A parameter's unit as tables and exports show it: the catalog's "[rad]" -> "rad".
[[nodiscard]] std::string bare_unit(std::string_view unit);

/// Every plot of the page, in page order, binned over run.log's fitted rows
/// (run_discovery sets it; without it the angle plots are left out).
[[nodiscard]] std::vector<Plot> report_plots(const DiscoveryRun& run);

/// When the final verdict is not explained: the signal whose residual is furthest above
/// its floor (report_plots puts its plot first); nullptr when explained.
[[nodiscard]] const SignalResidual* failing_signal(const DiscoveryRun& run);
/// Moves the failing signal's plot (i_dq: the dq spectrum, else its panel) to the front.
void lead_with_failing_signal(const DiscoveryRun& run, std::vector<Plot>& plots);
/// "One speed: ..." when the speed breakdown has one bin (report_plots then draws no
/// residual-vs-speed plot); "One direction: ..." when the direction breakdown has one
/// row. Empty otherwise.
[[nodiscard]] std::string one_speed_note(const ModelFit& f);
[[nodiscard]] std::string one_direction_note(const ModelFit& f);

/// The plots as one JSON array (web/report_page.js reads it).
[[nodiscard]] std::string plots_json(const std::vector<Plot>& plots);

}  // namespace resolver::report
