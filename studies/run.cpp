// studies/run.cpp: the `run` study (see run.h): renders, compares, sweeps and writes the folder as a set.
#include "studies/run.h"

#include <algorithm>
#include <optional>
#include <string_view>

#include "compare/compare.h"
#include "compare/report.h"
#include "compare/text.h"
#include "raster/cascades.h"
#include "raster/debug_views.h"
#include "raster/memory.h"
#include "raster/moment_maps.h"
#include "raster/renderer.h"
#include "raster/shadow_layers.h"
#include "scene/folder_lock.h"
#include "scene/frame_identity.h"
#include "scene/frame_io.h"
#include "scene/input_file.h"
#include "scene/interrupt.h"
#include "scene/memory.h"
#include "studies/auto_bias.h"
#include "studies/backend.h"
#include "studies/recommend.h"
#include "studies/sweep_report.h"

namespace shadowlab::studies {

namespace {

namespace fs = std::filesystem;
using Json = nlohmann::json;

// What each view the run report shows is for, under its image.
struct RunView {
    const char* view;
    const char* title;
    const char* caption;
};
constexpr RunView kRunViews[] = {
    {"shadow-map", "shadow maps",
     "Every shadow-map layer as depth: near the light white, far dark gray, nothing drawn dark blue."},
    {"light-frustum", "light frustum",
     "What each map holds, tinted over the scene, and its frustum's edges (dashed where hidden); lit points no "
     "map holds are striped magenta: no shadow can fall there."},
    {"texel-density", "texel density",
     "Shadow-map texel against screen pixel at every visible point: green 1:1, yellow to red texels larger "
     "(blocky shadows), cyan to blue smaller (map resolution wasted)."},
    {"cascades", "cascades", "The cascade each pixel's shadow test used: red, green, blue, yellow from near to far."},
};

// The run folder's manifest: every file and folder a run wrote, relative to the folder. The next
// run into the same folder removes what the manifest lists and it did not write again (an earlier
// run's raster-cascades.png, or raster.exr before --no-raster), so the folder holds only what its
// report owns; nothing else in the folder is touched (docs/decisions.md, "Run folders").
constexpr const char* kRunManifest = ".shadowlab-run.json";

std::vector<std::string> readRunManifest(const fs::path& dir) {
    std::vector<std::string> names;
    std::error_code ec;
    if (!fs::exists(dir / kRunManifest, ec)) return names;
    try {
        // Through the input opener: a FIFO or a huge file in its place is refused, not waited on.
        const Json j = Json::parse(scene::readInputFile(dir / kRunManifest, scene::kMaxJsonFileBytes));
        for (const Json& n : j.at("files"))
            if (n.is_string()) names.push_back(n.get<std::string>());
    } catch (const std::exception&) {
        return {};  // not ours, or damaged: the names run writes are still replaced
    }
    return names;
}

// A run's staging folder: removed when the run ends without committing it.
struct StagingFolder {
    fs::path dir;
    bool committed = false;
    ~StagingFolder() {
        std::error_code ignored;
        if (!committed) fs::remove_all(dir, ignored);
    }
};

}  // namespace

bool isRunOutput(const std::string& name) {
    // A backend's Frame and image, by its name (scene::toString), and the run's own files.
    for (const scene::Backend b : scene::kBackends)
        for (const char* ext : {".exr", ".png"})
            if (name == std::string(scene::toString(b)) + ext) return true;
    for (const char* n : {"metrics.json", "report.html", "sweep", kRunManifest})
        if (name == n) return true;
    auto startsEnds = [&](const std::string& p, const std::string& s) {
        return name.size() > p.size() + s.size() && name.compare(0, p.size(), p) == 0 &&
               name.compare(name.size() - s.size(), s.size(), s) == 0;
    };
    return startsEnds("diff-", ".png") ||
           startsEnds(std::string(scene::toString(scene::Backend::Raster)) + "-", ".png") ||
           startsEnds("heat-", ".png");
}

void checkValidation(const scene::Frame& frame, const scene::RasterSettings& settings) {
    if (!settings.validate) return;
    const auto it = frame.attributes.find("validation_messages");
    if (it == frame.attributes.end() || it->second != "0")
        throw std::runtime_error("the Vulkan validation layer reported " +
                                 (it == frame.attributes.end() ? std::string("an unknown number of") : it->second) +
                                 " message(s) (printed above)");
}

scene::Frame renderForOutput(const scene::Scene& scene, const scene::RenderPlan& plan,
                             const scene::RenderSettings& settings, scene::Backend backend, scene::ChannelMask channels,
                             raster::RenderDebug* debug) {
    scene::Frame f = renderFrame(backend, scene, plan, settings, channels, debug);
    if (backend == scene::Backend::Raster) checkValidation(f, settings.raster);
    f.attributes["scene"] = scene.file.string();
    for (const auto& [key, text] : scene.origin.choices) f.attributes["choice." + key] = text;
    for (std::size_t i = 0; i < scene.origin.notes.size(); ++i)
        f.attributes["note." + std::to_string(i)] = scene.origin.notes[i];
    f.attributes["version"] = SHADOWLAB_VERSION;
    scene::recordIdentity(f, scene);
    return f;
}

raster::DisplayImage debugView(const std::string& view, const scene::Frame& frame, const scene::Scene& scene,
                               const raster::RenderDebug& debug) {
    if (view == "shadow-map") return raster::shadowMapView(debug);
    if (view == "cascades") return raster::cascadeView(frame, debug);
    if (view == "light-frustum") return raster::lightFrustumView(frame, scene, debug);
    return raster::texelDensityView(frame, scene, debug);
}

std::string explainAutomaticChoices(const scene::Scene& scene, const scene::RenderPlan& plan,
                                    const scene::RasterSettings& s) {
    raster::CascadeChoice cascades;
    raster::ShadowMapSizeChoice size;
    raster::resolveAutomaticChoices(scene, s, &plan, &cascades, &size);
    std::string out = "raster light frustum: ";
    out += s.fitLightFrustum ? "fitted to what the camera sees (visible receivers and the casters that can shade "
                               "them), snapped so it holds still"
                             : "the scene's bounding sphere";
    out += s.fitLightFrustumIsDefault ? " (default; --no-fit-light-frustum for the bounding sphere)\n"
                                      : " (set by --fit-light-frustum or the scene)\n";
    out += "raster cascades: " + cascades.reason + "\n";
    out += "raster shadow-map size: " + size.reason + "\n";
    if (scene::isFilterable(s.filter)) {
        // What the filterable map adds to the frame (docs/raster.md "Filterable shadow maps").
        const int side = size.size > 0 ? size.size : s.shadowMapSize;
        out += "raster filter cost: " +
               raster::describeMomentCost(s.filter, std::uint32_t(side),
                                          std::uint32_t(raster::shadowMapLayers(scene, plan, s)), s.moments.blurWidth) +
               ", on top of the depth pass; the lit pass makes one linear lookup per light instead of compare taps\n";
    }
    return out;
}

std::vector<std::string> hardFilterWarnings(const scene::Scene& s, const scene::RasterSettings& r) {
    std::vector<std::string> out;
    if (r.filter == scene::ShadowFilter::Pcss) return out;
    for (std::size_t i = 0; i < s.lights.size(); ++i)
        if (s.lights[i].radius > 0.0 && s.lights[i].type != scene::LightType::Directional)
            out.push_back("light " + std::to_string(i) + " has a radius (" + compare::formatShort(s.lights[i].radius) +
                          ") and casts soft shadows, but the raster backend renders it with the hard filter '" +
                          scene::toString(r.filter) +
                          "': its penumbra is wrong (see the continuous error); use --filter pcss.");
    return out;
}

Json timingsJson(const scene::Frame& f) {
    Json t = Json::object();
    for (const auto& [stage, ms] : f.timingsMs) t[stage] = ms;
    t["total"] = f.totalTimeMs();
    return t;
}

namespace {
// The quick sweep of a run: the default quick grid at half the run's resolution, without raster
// rows when the run has no raster backend, with the user's threads, device and validation.
SweepGrid quickGrid(const scene::Scene& scene, const RunStudyOptions& o) {
    SweepGrid grid = defaultGrid(scene, true);
    grid.resolution = std::to_string(std::max(16, scene.camera.width / 2)) + "x" +
                      std::to_string(std::max(16, scene.camera.height / 2));
    if (!o.raster)
        std::erase_if(grid.configs, [](const SweepConfig& c) { return c.backend == scene::Backend::Raster; });
    for (SweepConfig& c : grid.configs) {
        c.overrides.threads = o.user.threads;
        c.overrides.device = o.user.device;
        c.overrides.validate = o.user.validate;
    }
    return grid;
}

// Whether the report shows the raster backend's debug views: where a light has a shadow map.
bool hasDebugViews(const scene::RenderPlan& plan, const RunStudyOptions& o) {
    return o.raster && std::any_of(plan.lights.begin(), plan.lights.end(),
                                   [](const scene::LightPlan& l) { return l.needsShadowTest; });
}
}  // namespace

Json memoryJson(std::uint64_t estimate) {
    return {{"peak_mib", scene::peakResidentBytes() / scene::kMiB}, {"estimate_mib", estimate / scene::kMiB}};
}

JobMemory estimateRunMemory(const scene::Scene& scene, const scene::RenderSettings& settings,
                            const scene::RenderPlan& plan, const RunStudyOptions& o) {
    // The reference, the ray-traced and the raster Frames are all held until the report is
    // written, with a difference image for each method (the half-size sweep needs less).
    const std::uint64_t pixels = std::uint64_t(scene.camera.width) * std::uint64_t(scene.camera.height);
    // The raster backend's debug views for the report: its shadow maps read back, and one display
    // image at a time (a view's bytes hold the maps and the image being written).
    const bool views = hasDebugViews(plan, o);
    // One renderer at a time: the run's own at full size, or one of the sweep's at half size (whose
    // filterable maps compile a compute pipeline the run's filter may not need).
    const std::uint64_t tracerBytes = estimateMemoryBytes(scene::Backend::Raytrace, scene, plan, settings);
    std::uint64_t rasterBytes = o.raster ? estimateMemoryBytes(scene::Backend::Raster, scene, plan, settings) : 0;
    // (The sweep's largest is a raster row's only where the run has the raster backend; its
    // ray-traced renderers at half size are smaller than the run's own, counted above.)
    if (o.sweep && o.raster)
        rasterBytes = std::max(rasterBytes, estimateSweepMemory(scene, quickGrid(scene, o), o.user).largestRenderer);
    const std::uint64_t estimate = scene::kProgramBytes + scene::sceneBytes(scene) + tracerBytes +
                                   scene::frameBytes(scene) + rasterBytes + scene::frameWriteBytes(scene) +
                                   2 * pixels * 3 * sizeof(float) +
                                   (views ? raster::debugViewBytes(scene, plan, settings.raster, "shadow-map") : 0);
    return {estimate, std::max(tracerBytes, rasterBytes)};
}

RunStudyResult runStudy(const scene::Scene& scene, const scene::RenderSettings& settings, const scene::RenderPlan& plan,
                        const RunStudyOptions& o) {
    RunProgress silent;
    RunProgress& progress = o.progress ? *o.progress : silent;
    const scene::Budgets budgets = scene.budgets.overriddenBy(o.budgets);
    RunStudyResult result;
    const JobMemory memory = estimateRunMemory(scene, settings, plan, o);
    const std::uint64_t estimate = memory.total;
    scene::checkMemory(estimate,
                       "run at " + std::to_string(scene.camera.width) + "x" + std::to_string(scene.camera.height));
    result.memoryEstimate = estimate;
    const bool views = hasDebugViews(plan, o);
    // The heap one renderer frees is kept for the next while a whole renderer, none of it reused,
    // still fits beside it within the estimate.
    const scene::FreedHeapBudget heapBudget(estimate, memory.largestRenderer);
    if (fs::create_directories(o.outputDir)) scene::noteCreatedFolderOnInterrupt(o.outputDir);
    const scene::FolderLock lock(o.outputDir, "run");
    // The run's files are made in a fresh folder beside the output folder, which they replace as
    // a set once all are written (the commit at the end): a folder never mixes two runs, and a run that
    // fails half-way (a full disk) leaves the previous one whole.
    const fs::path target = fs::canonical(o.outputDir);
    scene::removeStaleTemporaries(target.parent_path());  // what an earlier run that was killed left behind
    scene::removeStaleTemporaries(target);
    const fs::path dir = scene::temporarySibling(target);
    fs::create_directory(dir);
    StagingFolder staging{dir};
    const std::vector<std::string> earlierFiles = readRunManifest(target);
    std::vector<std::string> written;  // for the manifest

    Json& metrics = result.metrics;
    metrics = {{"scene", scene.file.string()},
               {"resolution", {scene.camera.width, scene.camera.height}},
               {"version", SHADOWLAB_VERSION}};
    compare::ReportInput report;
    report.sceneName = scene.file.stem().string();
    report.scenePath = scene.file.string();
    report.planText = plan.explain() + explainAutomaticChoices(scene, plan, settings.raster);
    for (const scene::Object& object : scene.objects) report.objectNames.push_back(object.name);

    if (o.raster) {
        report.warnings = hardFilterWarnings(scene, settings.raster);
        for (const std::string& w : report.warnings) progress.warning(w);
        if (!report.warnings.empty()) metrics["warnings"] = report.warnings;
    }
    progress.begin("reference (double precision, robust offsets)");
    const scene::Frame reference = renderForOutput(scene, plan, settings, scene::Backend::Reference);
    const std::string referenceName = scene::toString(scene::Backend::Reference);
    scene::writeFrame(reference, dir / (referenceName + ".exr"));
    // One exposure for every image of the report, from the reference (the EXRs keep the values).
    const double exposure = scene::displayExposure(reference);
    report.displayExposure = exposure;
    metrics["display_exposure"] = exposure;
    scene::writePngLinear(dir / (referenceName + ".png"), reference.width, reference.height, reference.beauty,
                          exposure);
    written.insert(written.end(), {referenceName + ".exr", referenceName + ".png"});
    progress.end("");
    metrics[referenceName] = {{"timings_ms", timingsJson(reference)}, {"attributes", reference.attributes}};
    report.reference = {referenceName, referenceName + ".png", reference};

    // The user's configuration at the requested resolution, kept for the recommendation's check.
    std::optional<scene::Frame> defaultsFrame[2];  // raytrace, raster
    for (const scene::Backend b : {scene::Backend::Raytrace, scene::Backend::Raster}) {
        const bool isRaster = b == scene::Backend::Raster;
        if (isRaster && !o.raster) continue;
        const std::string backend = scene::toString(b);
        progress.begin(isRaster ? backend + " (Vulkan shadow map)" : backend + " (shadow rays)");
        scene::Frame frame;
        raster::RenderDebug debug;
        debug.captureShadowMaps = views;
        try {
            frame =
                renderForOutput(scene, plan, settings, b, scene::kAllChannels, isRaster && views ? &debug : nullptr);
        } catch (const std::exception& e) {
            // One backend failing (no Vulkan driver, say) must not lose the other's results.
            progress.backendFailed(b, e.what());
            metrics["methods"][backend] = {{"error", e.what()}};
            report.failures.push_back({backend, e.what()});
            result.backendFailed = true;
            continue;
        }
        defaultsFrame[isRaster] = frame;
        scene::writeFrame(frame, dir / (backend + ".exr"));
        scene::writePngLinear(dir / (backend + ".png"), frame.width, frame.height, frame.beauty, exposure);
        const compare::Comparison c = compare::compareFrames(frame, reference);
        scene::writePngDisplay(dir / ("diff-" + backend + ".png"), c.width, c.height, c.diffRgb);
        written.insert(written.end(), {backend + ".exr", backend + ".png", "diff-" + backend + ".png"});
        progress.end(compare::summaryLine(c.metrics));
        metrics["methods"][backend] = {{"metrics", compare::toJson(c.metrics)},
                                       {"timings_ms", timingsJson(frame)},
                                       {"attributes", frame.attributes}};
        const std::vector<compare::BudgetCheck> checks = compare::checkBudgets(c.metrics, budgets);
        if (!checks.empty()) metrics["methods"][backend]["budgets"] = compare::toJson(checks);
        progress.budgets(backend, checks);
        result.budgetBroken = compare::anyBroken(checks) || result.budgetBroken;
        compare::ReportMethod method{backend, backend + ".png", "diff-" + backend + ".png", frame, c.metrics};
        method.heatPng = "heat-" + backend + ".png";
        scene::writePngDisplay(dir / method.heatPng, c.width, c.height, c.heatRgb);
        written.push_back(method.heatPng);
        for (std::size_t l = 0; l < c.lightHeatRgb.size(); ++l) {
            method.lightHeatPngs.push_back("heat-" + backend + "-light" + std::to_string(l) + ".png");
            scene::writePngDisplay(dir / method.lightHeatPngs.back(), c.width, c.height, c.lightHeatRgb[l]);
            written.push_back(method.lightHeatPngs.back());
        }
        report.methods.push_back(std::move(method));
        if (isRaster && views) {
            for (const RunView& v : kRunViews) {
                if (std::string_view(v.view) == "cascades" && raster::cascadeSplits(debug.layers).empty()) continue;
                const raster::DisplayImage img = debugView(v.view, frame, scene, debug);
                const std::string png = backend + "-" + v.view + ".png";
                scene::writePngDisplay(dir / png, img.width, img.height, img.rgb);
                written.push_back(png);
                report.shadowMapViews.push_back({v.title, png, img.width, img.height, v.caption});
            }
        }
    }

    if (o.sweep) {
        // A small sweep at half resolution puts error against run time and the bias windows into
        // the report. It starts fresh in a temporary folder (rows of an earlier build must not mix
        // with this one's) that replaces sweep/ in one step when it is complete, so a run killed
        // in the middle leaves the old sweep/ whole.
        const SweepGrid grid = quickGrid(scene, o);
        SweepOptions options;
        options.outputDir = scene::temporarySibling(dir / "sweep");
        options.progress = [&progress](const SweepProgress& p) { progress.sweep(p); };
        progress.begin("quick sweep of " + std::to_string(grid.configs.size()) + " configurations at " +
                       *grid.resolution);
        const SweepResult sweep = runSweep(scene, grid, options);
        SweepReportInput input = makeSweepReportInput(report.sceneName, report.scenePath, sweep);
        {
            progress.begin("recommended shadow block: biases searched in this configuration, checked at " +
                           std::to_string(scene.camera.width) + "x" + std::to_string(scene.camera.height));
            scene::Scene half = scene;
            half.camera.width = sweep.reference.width;
            half.camera.height = sweep.reference.height;
            RecommendOptions ro;
            ro.user = o.user;
            ro.raster = o.raster;
            input.recommendation = recommendShadow(
                half, sweep.reference, scene, reference, defaultsFrame[1] ? &*defaultsFrame[1] : nullptr,
                defaultsFrame[0] ? &*defaultsFrame[0] : nullptr, rayCandidateOf(recommendBias(sweep.rows)), ro);
            progress.end(std::to_string(input.recommendation->points.size()) + " raster points");
            for (const std::string& note : input.recommendation->notes) progress.note(note);
        }
        writeSweepReport(options.outputDir, input);
        scene::replaceDirectory(options.outputDir, dir / "sweep");
        written.push_back("sweep/");
        report.sweep = summarizeSweep(input, "sweep/report.html");
        progress.end("sweep/report.html");
        metrics["sweep"] = {{"configurations", sweep.rows.size()},
                            {"report", "sweep/report.html"},
                            {"results", "sweep/results.csv"},
                            {"recommended", input.recommendation->toJson()}};
    }

    metrics["memory"] = memoryJson(estimate);
    scene::writeTextAtomic(dir / "metrics.json", metrics.dump(2) + "\n");
    compare::writeReport(dir, report);
    written.insert(written.end(), {"metrics.json", "report.html"});
    scene::writeTextAtomic(dir / kRunManifest, Json{{"files", written}}.dump(2) + "\n");
    // The commit: this run's files replace the previous run's as a set. What stays is the user's
    // own: neither a name run writes nor one the earlier run's manifest lists (and the lock).
    auto earlierRun = [&](const std::string& name) {
        return std::find(earlierFiles.begin(), earlierFiles.end(), name) != earlierFiles.end() ||
               std::find(earlierFiles.begin(), earlierFiles.end(), name + "/") != earlierFiles.end();
    };
    scene::replaceFolderContents(dir, target,
                                 [&](const std::string& name) { return !isRunOutput(name) && !earlierRun(name); });
    staging.committed = true;
    return result;
}

}  // namespace shadowlab::studies
