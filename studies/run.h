// studies/run.h: the `run` study: the reference and each backend rendered in the user's
// configuration, each compared with the reference (difference and heat images, budgets), the raster
// backend's debug views, the quick sweep with its recommended shadow block, and the report, all
// written into the output folder as one set (docs/decisions.md, "Run folders").
#pragma once

#include <cstdint>
#include <filesystem>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "compare/gates.h"
#include "scene/backend.h"
#include "scene/budgets.h"
#include "scene/frame.h"
#include "scene/render_plan.h"
#include "scene/scene.h"
#include "scene/settings.h"
#include "studies/sweep.h"

namespace shadowlab::raster {
struct DisplayImage;
struct RenderDebug;
}  // namespace shadowlab::raster

namespace shadowlab::studies {

// What a run tells as it goes; the app prints it on stderr. Every method does nothing unless
// overridden.
class RunProgress {
public:
    virtual ~RunProgress() = default;
    // A long stage begins ("reference (double precision, robust offsets)") and ends with a note (a
    // metrics summary, or empty), unless it throws or backendFailed() ends it. Stages nest: the
    // recommendation is one inside the quick sweep's.
    virtual void begin(const std::string& /*stage*/) {}
    virtual void end(const std::string& /*note*/) {}
    // A backend threw: its stage ends here, and the run goes on without its results.
    virtual void backendFailed(scene::Backend /*backend*/, const std::string& /*error*/) {}
    virtual void warning(const std::string& /*text*/) {}
    // Every budget checked for a method, as soon as it is measured (none when no budget is set).
    virtual void budgets(const std::string& /*method*/, const std::vector<compare::BudgetCheck>& /*checks*/) {}
    virtual void sweep(const SweepProgress& /*progress*/) {}
    virtual void note(const std::string& /*text*/) {}  // the recommendation's sentences
};

struct RunStudyOptions {
    std::filesystem::path outputDir;
    bool raster = true;             // false: --no-raster (the reference and the ray tracer only)
    bool sweep = true;              // false: --no-sweep (no quick sweep and no recommendation)
    scene::Budgets budgets;         // the command line's, over the scene's own, for every method
    scene::SettingsOverrides user;  // the command line's settings (the sweep's rows keep its threads,
                                    // device and validation; the recommendation searches in them)
    RunProgress* progress = nullptr;
};

struct RunStudyResult {
    nlohmann::json metrics;            // what metrics.json holds
    std::uint64_t memoryEstimate = 0;  // the upper estimate checked before anything rendered
    bool backendFailed = false;        // a backend threw: it measured nothing
    bool budgetBroken = false;         // a method broke at least one error budget
};

// The memory a run holds at its peak, estimated before it renders (docs/reliability.md, "Memory"):
// the program, the scene, the Frames held until the report, their EXR writing and debug views, and
// one renderer of each backend, the largest of the run's own at full size and, with the quick sweep,
// each of its rows' at half size.
JobMemory estimateRunMemory(const scene::Scene& scene, const scene::RenderSettings& settings,
                            const scene::RenderPlan& plan, const RunStudyOptions& options);

// Renders, measures and writes OUTPUT/{reference,raytrace,raster}.{exr,png}, diff-*.png, heat-*.png,
// raster-*.png (the debug views), sweep/, metrics.json, report.html and .shadowlab-run.json, built
// in a folder beside OUTPUT that replaces this run's names in it once all are written: the
// previous run's files stay whole until then, and a user's own files stay. `plan` is
// makeRenderPlan(scene, settings). Throws scene::InputError when the run would not fit in memory
// or OUTPUT is locked by another command; a backend's failure is recorded, not thrown.
RunStudyResult runStudy(const scene::Scene& scene, const scene::RenderSettings& settings, const scene::RenderPlan& plan,
                        const RunStudyOptions& options);

// The names `run` writes at the top of its folder: what a new run replaces as a set. Anything
// else in the folder is the user's and is kept.
bool isRunOutput(const std::string& name);

// One frame of `backend` as the command line writes it: the Frame's own attributes plus the
// scene file, the scene's automatic choices ("choice.*"), the program version and the scene's
// identity (scene/frame_identity.h). With raster validation on, any validation message throws.
// `debug`: raster only, what the debug views need (every channel is read back with it).
scene::Frame renderForOutput(const scene::Scene& scene, const scene::RenderPlan& plan,
                             const scene::RenderSettings& settings, scene::Backend backend,
                             scene::ChannelMask channels = scene::kAllChannels, raster::RenderDebug* debug = nullptr);
// Throws std::runtime_error when settings.validate is on and `frame` does not say that the
// validation layer reported no message.
void checkValidation(const scene::Frame& frame, const scene::RasterSettings& settings);

// The display image of a raster debug view ("shadow-map", "cascades", "light-frustum",
// "texel-density"; raster/debug_views.h) from a raster Frame and its RenderDebug (the shadow-map
// view needs debug.captureShadowMaps).
raster::DisplayImage debugView(const std::string& view, const scene::Frame& frame, const scene::Scene& scene,
                               const raster::RenderDebug& debug);

// The raster backend's automatic choices, each with its reason, one line each (`--explain` and the
// report's plan): light-frustum fitting, the cascade count, the map size, a filterable map's cost.
std::string explainAutomaticChoices(const scene::Scene& scene, const scene::RenderPlan& plan,
                                    const scene::RasterSettings& settings);

// A light with a radius casts soft shadows; in the raster backend only pcss estimates them, every
// other filter gives a hard (or PCF-blurred) edge whose penumbra error the classes barely see: one
// warning per such light.
std::vector<std::string> hardFilterWarnings(const scene::Scene& scene, const scene::RasterSettings& settings);

// A Frame's timings by stage, with "total" (metrics.json, `render --json`).
nlohmann::json timingsJson(const scene::Frame& frame);
// The peak resident memory so far and `estimate`, in MiB (metrics.json, `render --json`).
nlohmann::json memoryJson(std::uint64_t estimate);

}  // namespace shadowlab::studies
