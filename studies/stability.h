// studies/stability.h: the stability suite: runs one extreme case through the
// reference, the analytic oracle and both backends at default and at searched-best settings,
// and gives separate verdicts: the reference's (exact / wrong / unchecked), each backend's state
// (clean, acne, leaks, stiff) and whether it ran cleanly (no wrong reference, NaN/Inf, failure or
// black frame).
// See docs/stability.md.
#pragma once

#include <filesystem>
#include <functional>
#include <optional>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "compare/compare.h"
#include "scene/frame.h"
#include "scene/scene.h"
#include "studies/analytic.h"
#include "studies/recommend.h"
#include "studies/sweep.h"

namespace shadowlab::studies {

// A beauty whose brightest channel stays below this (linear) is black. The ambient term alone
// (0.05 · albedo ≥ ~0.01 in every shipped scene) is far above it, so only a broken render trips it.
inline constexpr float kBlackFrameMax = 1e-4f;

struct StabilityOptions {
    int width = 160, height = 90;      // every render of the case
    std::optional<int> shadowMapSize;  // overrides the default settings' map size (tests: 512)
    bool search = true;                // run the bias search and the best-settings renders
    bool quick = true;                 // defaultGrid(scene, quick)
    // Keep only the bias series and robust rows of the grid (drop the map-size × filter block),
    // and use this map size for the raster series (0: the grid's own): the tests' small search.
    bool biasSeriesOnly = false;
    int searchMapSize = 0;
    bool validate = false;  // Vulkan validation on every raster render
    // The "best" renders use the recommendation searched in the case's own configuration
    // (studies/recommend.h: depth × slope, never worse than the defaults); these are its grids.
    std::vector<double> bestDepthSteps = RecommendOptions{}.depthSteps;
    std::vector<double> bestSlopeSteps = RecommendOptions{}.slopeSteps;
    std::vector<scene::Backend> backends{scene::Backend::Raster, scene::Backend::Raytrace};
    RenderFn render = renderWithBackend;  // tests may pass a fake
};

// One backend render of the case and what it measured.
struct BackendRun {
    scene::Backend backend = scene::Backend::Raster;  // Raster or Raytrace
    std::string variant;                              // "defaults" | "best"
    std::string settings;                             // short text of the overrides applied
    bool ok = false;                                  // rendered without throwing
    std::string error;                                // the exception's message when !ok
    bool blackFrame = false;
    compare::FrameHealth health;
    int validationMessages = -1;  // -1 when the frame does not say
    double timeMs = 0.0;
    std::size_t counted = 0;
    double falseShadowRate = 0.0, missedShadowRate = 0.0, mismatchRate = 0.0;
    std::vector<float> diffRgb;  // display-encoded, width·height·3; empty when !ok
    bool failed() const { return !ok || blackFrame || health.total() > 0 || validationMessages > 0; }
};

// The bias search's verdict for one method: a window, or "stiff" with what dominates.
struct MethodBias {
    scene::Backend backend = scene::Backend::Raster;  // Raster or Raytrace
    bool stiff = true;                                // no series of this backend has a window
    std::string kind;                                 // the series the verdict comes from ("depth", "slope", "ray")
    double lo = 0.0, hi = 0.0, recommended = 0.0;
    std::string dominant;  // when stiff: "false" (acne) or "missed" (leaks)
    std::string text;      // BiasSeries::describe() of each series, joined
};

// What a backend's shadows look like in one run, for the page's colored columns: "clean" (both
// rates ≤ kBiasWindowMaxRate), "acne" (false shadow above it), "leaks" (missed shadow above it),
// "acne+leaks", at the best bias "stiff" (still not clean: no searched bias is), "failed"
// (crash, NaN/Inf, black frame, validation messages) or "not run".
struct BackendState {
    std::string state;
    std::string text;  // "clean", "acne 13.1%", "leaks 0.24%", "stiff: acne 0.48%", "failed: device lost"
};
BackendState stateOf(const BackendRun* run, bool atBest);

struct StabilityCase {
    std::string name;         // file stem
    std::string description;  // from the scene file, when it has one
    int width = 0, height = 0;
    bool referenceOk = false;
    std::string referenceError;
    double referenceMs = 0.0;
    compare::FrameHealth referenceHealth;
    bool referenceBlack = false;
    scene::Frame reference;   // kept for the report's images
    std::string notAnalytic;  // why there is no analytic answer; empty when there is one
    std::optional<AnalyticCheck> analytic;
    std::vector<BackendRun> runs;  // defaults first, then best
    std::vector<MethodBias> bias;  // one per backend when searched
    nlohmann::json bestShadowBlock = nlohmann::json::object();
    std::vector<std::string> bestNotes;  // the recommendation's sentences (what it searched and measured)
    std::vector<std::string> failures;   // why the case FAILs; empty: PASS

    bool failed() const { return !failures.empty(); }
    // The reference's verdict: "exact" (matches the analytic answer), "wrong" (misses it, failed,
    // NaN/Inf or black), "unchecked" (no analytic answer for this scene, healthy).
    std::string referenceVerdict() const;
    const BackendRun* run(scene::Backend backend, const std::string& variant) const;
    const MethodBias* biasOf(scene::Backend backend) const;
};

// Never throws for a render failure (recorded in the case); throws scene::InputError for bad
// options. `description` is shown in the report.
StabilityCase runStabilityCase(const scene::Scene& scene, const StabilityOptions& options, const std::string& name = "",
                               const std::string& description = "");

// Every scenes/extreme/*.json under scene::scenesDirectory(), sorted by name.
std::vector<std::filesystem::path> extremeSceneFiles();

// Loads and runs each file in order (name = file stem, description from the file). A file that
// does not load becomes a failed case ("scene failed to load: ...") instead of stopping the suite.
// `progress` is called after each case.
std::vector<StabilityCase> runStabilitySuite(const std::vector<std::filesystem::path>& files,
                                             const StabilityOptions& options,
                                             const std::function<void(const StabilityCase&)>& progress = {});

// The scene file's "description" string, empty when absent or unreadable.
std::string readDescription(const std::filesystem::path& sceneFile);

nlohmann::json toJson(const StabilityCase& c);
std::string stabilityCsv(const std::vector<StabilityCase>& cases);
// DIR/stability.html (one section per case: verdict, table, reference and diff images),
// DIR/stability.csv, DIR/stability.json, DIR/stability/<case>-*.png. Creates DIR.
void writeStabilityReport(const std::filesystem::path& dir, const std::vector<StabilityCase>& cases);
// The suite's verdict: true when no case failed (the app exits non-zero otherwise).
bool suitePassed(const std::vector<StabilityCase>& cases);

}  // namespace shadowlab::studies
