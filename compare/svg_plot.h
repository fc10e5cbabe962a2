// compare/svg_plot.h: small self-contained SVG charts for reports and sweeps: scatter plots
// with linear or log axes, series joined by lines (Pareto fronts, rate curves), vertical
// markers (the reference's run time) and shaded x ranges (the bias window). No scripts, no
// external fonts, so the same string works inline in HTML and as a standalone .svg file.
#pragma once

#include <optional>
#include <string>
#include <vector>

#include "compare/bias_window.h"

namespace shadowlab::compare {

struct PlotPoint {
    double x = 0.0, y = 0.0;
    std::string label;  // drawn beside the point when the series shows labels
    std::string title;  // hover tooltip (<title>), e.g. the settings of a sweep row
};

struct PlotSeries {
    std::string name;   // legend entry
    std::string color;  // any CSS color
    std::vector<PlotPoint> points;
    bool markers = true;      // draw a dot per point
    bool connect = false;     // join the points in increasing x with a line (fronts, curves)
    bool showLabels = false;  // write each point's label next to it
    bool dashed = false;
    // Marker shape: 0 circle, 1 square, 2 diamond, 3 plus, 4 hexagon; more wrap around (the
    // triangle is taken: it marks a value below a log axis). Sweeps
    // timed on several machines give each machine its own shape.
    int shape = 0;
};

struct PlotAxis {
    std::string title;
    bool log = false;
    bool percent = false;            // values are 0..1 rates, ticks read "1%"
    bool integer = false;            // values are counts or indices (frame pairs): ticks only at whole numbers
    std::optional<double> min, max;  // fixed range; otherwise fitted to the data with a margin
};

struct PlotMarker {
    double x = 0.0;  // a vertical dashed line across the plot
    std::string label;
};

struct PlotBand {
    double x0 = 0.0, x1 = 0.0;  // a shaded x range across the plot
    std::string label;
    std::string color = "#2e7d32";
};

struct ScatterPlot {
    std::string title;
    PlotAxis x, y;
    std::vector<PlotSeries> series;
    std::vector<PlotMarker> markers;
    std::vector<PlotBand> bands;
    std::string note;  // a verdict at the top right (e.g. "stiff: no bias window")
    int width = 640, height = 400;
};

// On a log axis, values ≤ 0 cannot be placed; they and any value below a fixed axis minimum
// are drawn as a triangle on the axis's low edge (meaning "0 or below the range") instead of
// being dropped, so a method with zero error still shows up.
std::string renderSvg(const ScatterPlot& plot);

// Tick values for an axis range (exposed for tests): linear ticks at 1/2/5·10^k steps, log
// ticks at decades (every k-th decade beyond 8), with 2 and 5 in between when the range spans
// fewer than three decades.
std::vector<double> axisTicks(double lo, double hi, bool log);

// ---- The two plots of a sweep report, built on renderSvg ----

// A plot color per backend: never red or blue, which mean false and missed shadow in the
// difference images. Known labels get fixed colors, others cycle through a palette by index.
std::string backendColor(const std::string& backend, std::size_t index);

struct SweepPoint {
    std::string backend;  // one series (and one front) per backend
    double timeMs = 0.0;
    double error = 0.0;   // a rate in 0..1, e.g. mismatch rate
    std::string label;    // settings of the row, shown on hover (and beside the point if asked)
    std::string machine;  // where it was timed; with more than one, each machine gets a marker shape
};

struct ErrorTimeOptions {
    std::string title = "Shadow error against run time";
    std::string errorName = "mismatch rate";
    bool logError = true;  // sweeps: log-log; the two-point run report uses a linear error axis
    bool fronts = true;    // join each backend's Pareto front
    bool labels = false;   // write each point's label beside it
};

// Error against time, one series per backend (in first-seen order), each backend's Pareto
// front as a line, the reference's run time as a dashed marker (skipped when ≤ 0). Points of
// more than one machine: one series per backend and machine, the machine's marker shape.
ScatterPlot errorTimePlot(const std::vector<SweepPoint>& points, double referenceTimeMs,
                          const ErrorTimeOptions& options = {});
// False- (red) and missed- (blue) shadow rates (log axis) against bias, the threshold as a dashed line and
// the bias window shaded green, or a "stiff" note when there is none.
ScatterPlot biasPlot(const std::vector<BiasSample>& samples, const BiasWindow& window, const std::string& biasName,
                     bool logBias);

}  // namespace shadowlab::compare
