// studies/sweep_report.h: the HTML report of a sweep (`shadowlab sweep`, and the quick sweep
// `run` includes): reference, each backend's best and worst configuration with difference
// images and zooms, error against per-frame time with Pareto fronts, the bias plots, every row
// in a table, and the recommended "shadow" block (studies/auto_bias.h). Self-contained: inline
// CSS and SVG, images by relative path, no scripts.
#pragma once

#include <cstddef>
#include <filesystem>
#include <string>
#include <vector>

#include <optional>

#include "compare/report.h"
#include "compare/thresholds.h"
#include "studies/auto_bias.h"
#include "studies/recommend.h"
#include "studies/sweep.h"

namespace shadowlab::studies {

struct SweepReportInput {
    std::string sceneName;  // the title
    std::string scenePath;
    std::vector<SweepRow> rows;                      // in grid order; image paths relative to the report's folder
    std::string referencePng = "reference.png";      // relative to the report's folder; "" = none
    double referenceMs = 0.0;                        // the reference's render time (a marker on the plot)
    int width = 0, height = 0;                       // render size; 0 = read from the rows' metrics
    double threshold = compare::kBiasWindowMaxRate;  // bias-window threshold
    // The block searched in the user's configuration and verified against their defaults
    // (studies/recommend.h). Without it the page and recommended-shadow.json show the probe
    // slice's block, marked as not measured against the defaults.
    std::optional<Recommendation> recommendation;
};

// The input for a finished runSweep(): its rows, reference.png and the reference's time and size.
SweepReportInput makeSweepReportInput(const std::string& sceneName, const std::string& scenePath,
                                      const SweepResult& result);

// The page as a string (what writeSweepReport writes), for tests.
std::string renderSweepReportHtml(const SweepReportInput& input);
// The summary in words, one sentence per line: per backend the fastest configuration under
// kSweepGoodMismatchRate (or the most accurate when none is), the bias windows or "stiff", the
// robust-offset verdict, failures.
std::vector<std::string> describeSweep(const SweepReportInput& input, const AutoBias& bias);
// The error-against-per-frame-time plot of the sweep (log-log, Pareto front per backend).
std::string sweepErrorTimeSvg(const SweepReportInput& input);

// With a flicker axis: mean flicker rate against mismatch rate, one series per backend and one for
// the raster held view (docs/sweep.md).
std::string sweepFlickerSvg(const SweepReportInput& input);

// Writes dir/report.html, dir/recommended-shadow.json ({"shadow": the block to merge into the
// scene's "shadow", "measured": what it gained against the defaults, or null}) and beside them error-time.svg and bias-depth.svg,
// bias-slope.svg, bias-ray.svg for the kinds that have data, flicker-error.svg with a flicker axis (a stale one of a kind without data
// is removed). Every file is written atomically.
void writeSweepReport(const std::filesystem::path& dir, const SweepReportInput& input);

// What the run report shows of a sweep (ReportInput::sweep); `href` is the sweep report's path
// relative to the run report, e.g. "sweep/report.html".
compare::SweepSummary summarizeSweep(const SweepReportInput& input, const std::string& href);

}  // namespace shadowlab::studies
