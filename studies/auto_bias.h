// studies/auto_bias.h: turns a sweep's bias series into a recommendation: the bias window of
// each bias parameter (or "stiff"), the bias in the middle of each window, and a ready "shadow"
// block for the scene file (see docs/compare.md, "Automatic bias").
#pragma once

#include <limits>
#include <optional>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "compare/bias_window.h"
#include "compare/thresholds.h"
#include "studies/sweep.h"

namespace shadowlab::studies {

// The rows of one bias kind that differ only in that bias ("map 1024, none, slope bias 0" for
// a depth-bias series): only such rows show one parameter's acne-to-leak trade-off.
struct BiasSeries {
    // "depth" | "slope" | "ray", or a filterable map's parameter (seriesKinds()): its window
    // is read the same way, from the false- and missed-shadow rates along the series.
    std::string kind;
    scene::Backend backend = scene::Backend::Raster;  // Raster or Raytrace
    // The overrides every row of the series shares (the bias itself left out), as scene-file
    // "shadow" keys: {"shadow_map_size": 1024, "filter": "none", "slope_bias": 0}.
    nlohmann::json context = nlohmann::json::object();
    std::vector<compare::BiasSample> samples;  // in bias order; failed rows left out
    compare::BiasWindow window;
    bool logSpaced = false;  // the positive samples are closer to a geometric than an arithmetic series
    // The middle of the window (geometric when lo > 0 and logSpaced, else arithmetic), or the
    // best compromise when the series is stiff.
    double recommended = std::numeric_limits<double>::quiet_NaN();
    // When stiff: what dominates at the best compromise, "false" (acne) or "missed" (leaks,
    // peter-panning); empty when the series has a window.
    std::string dominant;

    // "depth bias", "slope bias", "ray bias", "min variance", "ESM exponent", ...
    std::string name() const;
    // "world units" or "texels".
    std::string unit() const;
    // One sentence: the window and the recommended value, or "stiff" and the dominant artifact.
    std::string describe() const;
};

// What robust ray offsets (ray_bias "robust") achieved in the sweep.
struct RobustResult {
    std::string precision;  // "float" | "double" | "" (scene default)
    double falseShadowRate = 0.0, missedShadowRate = 0.0;
    double frameMs = 0.0;
    bool passes = false;  // both rates ≤ the threshold
};

struct AutoBias {
    double threshold = compare::kBiasWindowMaxRate;
    std::vector<BiasSeries> series;    // every series found, kinds in seriesKinds() order
    std::vector<RobustResult> robust;  // every robust-offset row that rendered
    // A valid scene-file "shadow" block (scene/loader.cpp readShadow accepts every key it holds):
    // the raster's chosen bias kind at its recommended value with the other kind at 0 (each was
    // measured alone), the shadow-map size and filter the series ran at, and the ray tracer's
    // "robust" (when it passes) or recommended ray bias with its precision; a filterable map's
    // parameter window's middle when its series ran with the block's filter. Empty when the sweep
    // had no bias series and no robust rows.
    nlohmann::json shadowBlock = nlohmann::json::object();
    // The sentences behind the block, in order: one per primary series, the robust verdict, the
    // choice made for the raster. Shown in reports.
    std::vector<std::string> notes;

    // The series of a kind with the most samples (first seen on a tie), nullptr when none.
    const BiasSeries* primary(const std::string& kind) const;
    // The passing robust row to recommend: float's where it passes, else the scene default's, else
    // double's (never by run time, which is noise between them); nullptr when none passes.
    const RobustResult* robustPick() const;
};

// Reads the bias series out of sweep rows (SweepConfig::biasKind / biasValue and the metrics'
// false_shadow_rate / missed_shadow_rate). Rows with an error or without both rates are left
// out. Throws scene::InputError when the threshold is not a finite rate ≥ 0.
AutoBias recommendBias(const std::vector<SweepRow>& rows, double threshold = compare::kBiasWindowMaxRate);

// Every kind a series may have, in the order of the notes: "depth", "slope", "ray", then the
// filterable maps' parameters "min_variance", "bleeding_reduction", "evsm_positive",
// "evsm_negative", "esm_exponent", "moment_bias" (the sweep axes of those names).
const std::vector<std::string>& seriesKinds();

// The middle of [lo, hi]: geometric when lo > 0 and the samples are log-spaced, else arithmetic.
double windowMiddle(double lo, double hi, bool logSpaced);
// True when the positive values (any order, duplicates ignored) step more evenly in ratio than in
// difference; false for fewer than two positive values, and for two unless they span a decade.
bool isLogSpaced(std::vector<double> values);

}  // namespace shadowlab::studies
