// app/commands.cpp: what each subcommand does, in terms of the libraries. Inputs are loaded and
// validated completely before anything is written, so bad input leaves no file behind.
#include "app/commands.h"

#include "app/guards.h"
#include "scene/folder_lock.h"

#include <algorithm>
#include <chrono>
#include <functional>
#include <cstdio>
#include <iostream>
#include <unistd.h>

#include <nlohmann/json.hpp>

#include "compare/compare.h"
#include "compare/report.h"
#include "compare/stability.h"
#include "compare/sweep.h"
#include "compare/sweep_report.h"
#include "raster/debug_views.h"
#include "raster/memory.h"
#include "raster/renderer.h"
#include "raytrace/memory.h"
#include "raytrace/renderer.h"
#include "scene/error.h"
#include "scene/frame_io.h"
#include "scene/loader.h"
#include "scene/memory.h"
#include "scene/render_plan.h"

namespace shadowlab::app {

namespace {

namespace fs = std::filesystem;
using Json = nlohmann::json;
using Clock = std::chrono::steady_clock;

// A scene ready to render: loaded, validated, settings resolved, plan made.
struct Prepared {
    scene::Scene scene;
    scene::RenderSettings settings;
    scene::RenderPlan plan;
};

void applyResolution(scene::Scene& s, const std::string& text) {
    int w = 0, h = 0;
    char x = 0, extra = 0;
    if (std::sscanf(text.c_str(), "%d%c%d%c", &w, &x, &h, &extra) != 3 || (x != 'x' && x != 'X'))
        throw scene::InputError("--resolution: expected WxH (e.g. 640x360), got '" + text + "'");
    if (w < 1 || h < 1 || w > scene::kMaxResolution || h > scene::kMaxResolution ||
        static_cast<long long>(w) * h > scene::kMaxPixels)
        throw scene::InputError("--resolution: " + text + " is outside 1x1.." +
                                std::to_string(scene::kMaxResolution) + " per side and " +
                                std::to_string(scene::kMaxPixels) + " pixels in all");
    s.camera.width = w;
    s.camera.height = h;
}

Prepared prepare(const SceneOptions& o) {
    Prepared p{readingInput(o.scene, [&] { return scene::loadScene(scene::findScene(o.scene)); }), {}, {}};
    if (o.resolution) applyResolution(p.scene, *o.resolution);
    p.settings = scene::resolveSettings(p.scene, o.settings);
    p.plan = scene::makeRenderPlan(p.scene, p.settings);
    if (o.explain)
        std::cerr << "render plan for " << p.scene.file.string() << ":\n"
                  << p.plan.explain()
                  << "raster shadow-map size: " << raster::chooseShadowMapSize(p.scene, p.settings.raster, &p.plan).reason << "\n"
                  << "raster bias: constant " << p.settings.raster.depthBias << " world units"
                  << (p.settings.raster.depthBiasIsDefault ? " (default: half a texel of the bounding-sphere map)" : "")
                  << ", slope " << p.settings.raster.slopeBias << " texels x tan(angle to light), "
                  << (p.settings.raster.hardwareBias
                          ? "through the rasterizer's depth-bias state in directional maps' depth pass (converted per "
                            "layer, recorded in the Frame; spot and point maps in the lit shader)"
                          : "in the lit shader")
                  << (p.settings.raster.receiverPlaneBias ? "; the receiver plane replaces the slope term in the shader"
                                                          : "")
                  << "\n";
    if (o.explain) {
        const std::vector<raster::LightCulling> culled = raster::culledCasters(p.scene, p.settings.raster, &p.plan);
        const std::size_t objects = p.scene.objects.size();
        for (std::size_t i = 0; i < culled.size(); ++i) {
            const raster::LightCulling& c = culled[i];
            std::cerr << "raster light " << i << ": ";
            if (c.layers.empty()) {
                std::cerr << "no caster culling ("
                          << (!p.settings.raster.cullCasters ? "turned off"
                              : p.plan.needsTransmittanceMap ? "the transmittance map draws every caster"
                                                             : "no shadow map")
                          << ")\n";
            } else if (c.layers.size() == 1) {
                std::cerr << c.culled[0] << " of " << objects
                          << " objects left out of the depth pass (cannot cast onto the visible receivers)\n";
            } else {
                // Per cascade or cube face: each draws only what can cast onto its own receivers.
                std::cerr << c.total() << " of " << c.layers.size() * objects << " object draws left out of "
                          << c.layers.size() << " depth passes (";
                for (std::size_t k = 0; k < c.layers.size(); ++k)
                    std::cerr << (k ? ", " : "") << c.layers[k] << " " << c.culled[k] << " of " << objects;
                std::cerr << "; cannot cast onto the receivers each map serves)\n";
            }
        }
    }
    return p;
}

// Progress on stderr: long work says what it is doing and how long it took.
class Stage {
public:
    explicit Stage(std::string what) : what_(std::move(what)), start_(Clock::now()) {
        std::cerr << "shadowlab: " << what_ << " ..." << std::flush;
        if (!isatty(STDERR_FILENO)) std::cerr << "\n";
    }
    void done(const std::string& note = "") {
        const double s = std::chrono::duration<double>(Clock::now() - start_).count();
        char buf[64];
        std::snprintf(buf, sizeof buf, "%.2f s", s);
        if (isatty(STDERR_FILENO)) std::cerr << " " << buf;
        else std::cerr << "shadowlab: " << what_ << ": " << buf;
        std::cerr << (note.empty() ? "" : ", " + note) << "\n";
    }

private:
    std::string what_;
    Clock::time_point start_;
};

void checkValidation(const scene::Frame& frame, const scene::RasterSettings& settings) {
    if (!settings.validate) return;
    const auto it = frame.attributes.find("validation_messages");
    if (it == frame.attributes.end() || it->second != "0")
        throw std::runtime_error("the Vulkan validation layer reported " +
                                 (it == frame.attributes.end() ? std::string("an unknown number of") : it->second) +
                                 " message(s) (printed above)");
}

// `debug`: raster only, what the debug views need (every channel is read back with it).
scene::Frame renderBackend(const Prepared& p, const std::string& backend,
                           scene::ChannelMask channels = scene::kAllChannels, raster::RenderDebug* debug = nullptr) {
    scene::Frame f;
    if (backend == "raster") {
        f = debug ? raster::render(p.scene, p.plan, p.settings.raster, debug)
                  : raster::render(p.scene, p.plan, p.settings.raster, channels);
        checkValidation(f, p.settings.raster);
    } else if (backend == "raytrace") {
        f = raytrace::render(p.scene, p.plan, p.settings.raytrace);
    } else {
        f = raytrace::renderReference(p.scene, p.plan, p.settings.raytrace);
    }
    f.attributes["scene"] = p.scene.file.string();
    f.attributes["version"] = SHADOWLAB_VERSION;
    return f;
}

Json timingsJson(const scene::Frame& f) {
    Json t = Json::object();
    for (const auto& [stage, ms] : f.timingsMs) t[stage] = ms;
    t["total"] = f.totalTimeMs();
    return t;
}

// An upper estimate of the memory rendering `backend` takes (see scene/memory.h), without the
// program itself and the Frame's writing.
std::uint64_t backendMemory(const Prepared& p, const std::string& backend) {
    return backend == "raster" ? raster::estimateMemoryBytes(p.scene, p.plan, p.settings.raster)
                               : raytrace::estimateMemoryBytes(p.scene, p.plan);
}

// "peak memory 412 MiB (estimated at most 530 MiB)", and the same figures for --json.
std::string memoryLine(std::uint64_t estimate) {
    return "peak memory " + std::to_string(scene::peakResidentBytes() / scene::kMiB) + " MiB (estimated at most " +
           std::to_string(estimate / scene::kMiB) + " MiB)";
}
Json memoryJson(std::uint64_t estimate) {
    return {{"peak_mib", scene::peakResidentBytes() / scene::kMiB}, {"estimate_mib", estimate / scene::kMiB}};
}

// Sweep progress: a bar with ETA on a terminal, one plain line per configuration otherwise.
std::function<void(const compare::SweepProgress&)> sweepProgressPrinter() {
    const bool tty = isatty(STDERR_FILENO);
    return [tty](const compare::SweepProgress& pr) {
        const std::string what = pr.row ? pr.row->config.label() : "";
        const std::string outcome = pr.row && !pr.row->error.empty() ? "failed: " + pr.row->error
                                    : pr.row ? "mismatch " + std::to_string(100.0 * pr.row->rate("mismatch_rate")).substr(0, 5) + "%"
                                             : "";
        const int eta = int(pr.etaSeconds + 0.5);
        char line[512];
        std::snprintf(line, sizeof line, "[%zu/%zu] %s: %s, ETA %dm%02ds", pr.done, pr.total, what.c_str(),
                      outcome.c_str(), eta / 60, eta % 60);
        if (tty) {
            const int width = 24;
            const int filled = int(width * double(pr.done) / double(std::max<std::size_t>(pr.total, 1)));
            std::cerr << "\r\033[K[" << std::string(filled, '#') << std::string(width - filled, '.') << "] " << line
                      << (pr.done == pr.total ? "\n" : "") << std::flush;
        } else {
            std::cerr << "shadowlab: sweep " << line << "\n";
        }
    };
}

// The display image of a `--view` (raster/debug_views.h), from a raster Frame and its RenderDebug
// (the shadow-map view needs debug.captureShadowMaps).
raster::DisplayImage debugView(const std::string& view, const scene::Frame& frame, const scene::Scene& scene,
                               const raster::RenderDebug& debug) {
    if (view == "shadow-map") return raster::shadowMapView(debug);
    if (view == "cascades") return raster::cascadeView(frame, debug);
    if (view == "light-frustum") return raster::lightFrustumView(frame, scene, debug);
    return raster::texelDensityView(frame, scene, debug);
}

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

int render(const RenderOptions& o) {
    std::string ext = o.output.extension().string();
    if (ext != ".exr" && ext != ".png")
        throw scene::InputError(o.output.string() + ": unknown output type '" + ext + "' (use .exr or .png)");
    if (o.view && (o.backend != "raster" || ext != ".png"))
        throw scene::InputError("--view " + *o.view + ": needs --backend raster and a .png output (a view is a "
                                "display image of the shadow maps), got --backend " + o.backend + " and '" + ext + "'");
    checkOutputFile(o.output);  // before any work: an output that cannot be written fails now
    const Prepared p = prepare(o.common);
    // A view writes a display image, not the Frame; the shadow-map view holds every layer's depths.
    const std::uint64_t estimate =
        scene::kProgramBytes + scene::sceneBytes(p.scene) + backendMemory(p, o.backend) +
        (o.view ? raster::debugViewBytes(p.scene, p.plan, p.settings.raster, *o.view)
                : scene::frameWriteBytes(p.scene));
    scene::checkMemory(estimate, o.view ? "rendering the " + *o.view + " view of " +
                                              std::to_string(p.scene.camera.width) + "x" +
                                              std::to_string(p.scene.camera.height)
                                        : "rendering " + std::to_string(p.scene.camera.width) + "x" +
                                              std::to_string(p.scene.camera.height) + " with " + o.backend);
    // Only once the input is known to be good may the output's folder be created.
    if (o.output.has_parent_path()) fs::create_directories(o.output.parent_path());
    if (o.view) {
        Stage stage("rendering the " + *o.view + " view of " + p.scene.file.filename().string());
        raster::RenderDebug debug;
        debug.captureShadowMaps = *o.view == "shadow-map";
        const scene::Frame frame = raster::render(p.scene, p.plan, p.settings.raster, &debug);
        checkValidation(frame, p.settings.raster);
        const raster::DisplayImage img = debugView(*o.view, frame, p.scene, debug);
        scene::writePngDisplay(o.output, img.width, img.height, img.rgb);
        stage.done(std::to_string(img.width) + "x" + std::to_string(img.height) + " -> " + o.output.string() +
                   ", " + memoryLine(estimate));
        if (o.common.json) {
            Json j = {{"backend", o.backend}, {"view", *o.view}, {"output", o.output.string()},
                      {"timings_ms", timingsJson(frame)}, {"attributes", frame.attributes},
                      {"memory", memoryJson(estimate)}};
            std::cout << j.dump(2) << "\n";
        }
        return 0;
    }
    Stage stage("rendering " + p.scene.file.filename().string() + " with " + o.backend);
    // A PNG holds the beauty only, in 8-bit sRGB: the raster backend then renders nothing else,
    // into an 8-bit sRGB target.
    const scene::Frame frame = renderBackend(
        p, o.backend, ext == ".png" ? scene::kChannelBeauty | scene::kBeautyForDisplay : scene::kAllChannels);
    scene::writeFrame(frame, o.output);
    stage.done(std::to_string(frame.width) + "x" + std::to_string(frame.height) + " -> " + o.output.string() +
               ", " + memoryLine(estimate));
    if (o.common.json) {
        Json j = {{"backend", o.backend}, {"output", o.output.string()}, {"timings_ms", timingsJson(frame)},
                  {"attributes", frame.attributes}, {"memory", memoryJson(estimate)}};
        std::cout << j.dump(2) << "\n";
    }
    return 0;
}

int compareFiles(const CompareOptions& o) {
    if (o.output.extension() != ".png")
        throw scene::InputError(o.output.string() + ": the difference image must be a .png");
    checkOutputFile(o.output);
    const scene::Frame method = readingInput(o.method.string(), [&] { return scene::readFrame(o.method); });
    const scene::Frame reference = readingInput(o.reference.string(), [&] { return scene::readFrame(o.reference); });
    compare::Comparison c;
    try {
        c = compare::compareFrames(method, reference);
    } catch (const scene::InputError& e) {
        throw scene::InputError(o.method.string() + " vs " + o.reference.string() + ": " + e.what());
    }
    scene::writePngDisplay(o.output, c.width, c.height, c.diffRgb);
    if (o.json)
        std::cout << compare::toJson(c.metrics).dump(2) << "\n";
    else
        std::cout << compare::summaryLine(c.metrics) << "\n";
    return 0;
}

int info(bool validate) {
    std::cout << "shadowlab " << SHADOWLAB_VERSION << "\n";
    std::cout << "scenes: " << scene::scenesDirectory().string() << "\n";
    std::cout << raster::describeDevices(validate);
    return 0;
}

int run(const RunOptions& o) {
    checkOutputFolder(o.outputDir);
    const Prepared p = prepare(o.common);
    // The reference, the ray-traced and the raster Frames are all held until the report is
    // written, with a difference image for each method (the half-size sweep needs less).
    const std::uint64_t pixels = std::uint64_t(p.scene.camera.width) * std::uint64_t(p.scene.camera.height);
    // The raster backend's debug views for the report: its shadow maps read back, and one display
    // image at a time (a view's bytes hold the maps and the image being written).
    const bool views = !o.skipRaster && std::any_of(p.plan.lights.begin(), p.plan.lights.end(),
                                                     [](const scene::LightPlan& l) { return l.needsShadowTest; });
    const std::uint64_t estimate =
        scene::kProgramBytes + scene::sceneBytes(p.scene) + backendMemory(p, "raytrace") + scene::frameBytes(p.scene) +
        (o.skipRaster ? 0 : backendMemory(p, "raster")) + scene::frameWriteBytes(p.scene) +
        2 * pixels * 3 * sizeof(float) +
        (views ? raster::debugViewBytes(p.scene, p.plan, p.settings.raster, "shadow-map") : 0);
    scene::checkMemory(estimate, "run at " + std::to_string(p.scene.camera.width) + "x" +
                                     std::to_string(p.scene.camera.height));
    fs::create_directories(o.outputDir);
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
    int status = 0;

    Json metrics = {{"scene", p.scene.file.string()},
                    {"resolution", {p.scene.camera.width, p.scene.camera.height}},
                    {"version", SHADOWLAB_VERSION}};
    compare::ReportInput report;
    report.sceneName = p.scene.file.stem().string();
    report.scenePath = p.scene.file.string();
    report.planText = p.plan.explain();
    for (const scene::Object& object : p.scene.objects) report.objectNames.push_back(object.name);

    Stage refStage("reference (double precision, robust offsets)");
    const scene::Frame reference = renderBackend(p, "reference");
    scene::writeFrame(reference, dir / "reference.exr");
    scene::writePngLinear(dir / "reference.png", reference.width, reference.height, reference.beauty);
    refStage.done();
    metrics["reference"] = {{"timings_ms", timingsJson(reference)}, {"attributes", reference.attributes}};
    report.reference = {"reference", "reference.png", reference};

    for (const std::string backend : {"raytrace", "raster"}) {
        if (backend == "raster" && o.skipRaster) continue;
        Stage stage(backend == "raster" ? "raster (Vulkan shadow map)" : "raytrace (shadow rays)");
        scene::Frame frame;
        raster::RenderDebug debug;
        debug.captureShadowMaps = views;
        try {
            frame = renderBackend(p, backend, scene::kAllChannels, backend == "raster" && views ? &debug : nullptr);
        } catch (const std::exception& e) {
            // One backend failing (no Vulkan driver, say) must not lose the other's results.
            std::cerr << "\nshadowlab: error: " << backend << " backend failed: " << e.what() << "\n";
            metrics["methods"][backend] = {{"error", e.what()}};
            report.failures.push_back({backend, e.what()});
            status = 1;
            continue;
        }
        scene::writeFrame(frame, dir / (backend + ".exr"));
        scene::writePngLinear(dir / (backend + ".png"), frame.width, frame.height, frame.beauty);
        const compare::Comparison c = compare::compareFrames(frame, reference);
        scene::writePngDisplay(dir / ("diff-" + backend + ".png"), c.width, c.height, c.diffRgb);
        stage.done(compare::summaryLine(c.metrics));
        metrics["methods"][backend] = {{"metrics", compare::toJson(c.metrics)},
                                       {"timings_ms", timingsJson(frame)},
                                       {"attributes", frame.attributes}};
        report.methods.push_back({backend, backend + ".png", "diff-" + backend + ".png", frame, c.metrics});
        if (backend == "raster" && views) {
            for (const RunView& v : kRunViews) {
                if (std::string_view(v.view) == "cascades" && debug.cascadeSplits.empty()) continue;
                const raster::DisplayImage img = debugView(v.view, frame, p.scene, debug);
                const std::string png = std::string("raster-") + v.view + ".png";
                scene::writePngDisplay(dir / png, img.width, img.height, img.rgb);
                report.shadowMapViews.push_back({v.title, png, img.width, img.height, v.caption});
            }
        }
    }

    if (!o.skipSweep) {
        // A small sweep at half resolution puts error against run time and the bias windows into
        // the report. It starts fresh in a temporary folder (rows of an earlier build must not mix
        // with this one's) that replaces sweep/ in one step when it is complete, so a run killed
        // in the middle leaves the old sweep/ whole.
        compare::SweepGrid grid = compare::defaultGrid(p.scene, true);
        grid.resolution = std::to_string(std::max(16, p.scene.camera.width / 2)) + "x" +
                          std::to_string(std::max(16, p.scene.camera.height / 2));
        for (compare::SweepConfig& c : grid.configs) {
            if (o.skipRaster && c.backend == "raster") c.backend.clear();
            c.overrides.threads = o.common.settings.threads;
            c.overrides.device = o.common.settings.device;
            c.overrides.validate = o.common.settings.validate;
        }
        std::erase_if(grid.configs, [](const compare::SweepConfig& c) { return c.backend.empty(); });
        compare::SweepOptions options;
        options.outputDir = scene::temporarySibling(dir / "sweep");
        options.progress = sweepProgressPrinter();
        Stage stage("quick sweep of " + std::to_string(grid.configs.size()) + " configurations at " + *grid.resolution);
        const compare::SweepResult result = compare::runSweep(p.scene, grid, options);
        const compare::SweepReportInput input =
            compare::makeSweepReportInput(report.sceneName, report.scenePath, result);
        compare::writeSweepReport(options.outputDir, input);
        scene::replaceDirectory(options.outputDir, dir / "sweep");
        report.sweep = compare::summarizeSweep(input, "sweep/report.html");
        stage.done("sweep/report.html");
        metrics["sweep"] = {{"configurations", result.rows.size()}, {"report", "sweep/report.html"},
                            {"results", "sweep/results.csv"}};
    }

    metrics["memory"] = memoryJson(estimate);
    scene::writeTextAtomic(dir / "metrics.json", metrics.dump(2) + "\n");
    compare::writeReport(dir, report);
    // The commit: this run's files replace the previous run's as a set; the user's own files
    // (and the lock) stay.
    scene::replaceFolderContents(dir, target, [](const std::string& name) { return !isRunOutput(name); });
    staging.committed = true;
    std::cerr << "shadowlab: wrote " << (o.outputDir / "report.html").string() << "; " << memoryLine(estimate) << "\n";
    if (o.common.json) std::cout << metrics.dump(2) << "\n";
    return status;
}

int sweep(const SweepOptions& o) {
    checkOutputFolder(o.outputDir);
    const Prepared p = prepare(o.common);
    compare::SweepGrid grid = o.grid ? readingInput(o.grid->string(), [&] { return compare::loadGrid(*o.grid, p.scene); })
                                     : compare::defaultGrid(p.scene, o.quick);
    if (o.repetitions) grid.repetitions = *o.repetitions;
    if (o.common.resolution) grid.resolution = o.common.resolution;
    // Settings given on the command line apply to every configuration that does not vary them.
    const scene::SettingsOverrides& base = o.common.settings;
    for (compare::SweepConfig& c : grid.configs) {
        auto& v = c.overrides;
        if (!v.shadowMapSize) v.shadowMapSize = base.shadowMapSize;
        if (!v.depthBias) v.depthBias = base.depthBias;
        if (!v.slopeBias) v.slopeBias = base.slopeBias;
        if (!v.filter) v.filter = base.filter;
        if (!v.cascades) v.cascades = base.cascades;
        if (!v.rayBias) v.rayBias = base.rayBias;
        if (!v.precision) v.precision = base.precision;
        if (!v.samples) v.samples = base.samples;
        v.threads = base.threads;
        v.device = base.device;
        v.validate = base.validate;
    }

    compare::SweepOptions options;
    options.outputDir = o.outputDir;
    options.resume = o.resume;
    options.progress = sweepProgressPrinter();
    // One writer per folder: two sweeps appending to one journal would duplicate its keys.
    fs::create_directories(o.outputDir);
    const scene::FolderLock lock(o.outputDir, "sweep");
    std::cerr << "shadowlab: sweep of " << grid.configs.size() << " configurations, " << grid.repetitions
              << " timed frames each, into " << o.outputDir.string() << "\n";
    const compare::SweepResult result = compare::runSweep(p.scene, grid, options);
    compare::writeSweepReport(o.outputDir, compare::makeSweepReportInput(p.scene.file.stem().string(),
                                                                         p.scene.file.string(), result));
    std::size_t failed = 0;
    for (const auto& r : result.rows) failed += r.error.empty() ? 0 : 1;
    std::cerr << "shadowlab: wrote " << (o.outputDir / "report.html").string() << ", results.csv and results.json ("
              << result.rows.size() << " rows" << (failed ? ", " + std::to_string(failed) + " failed" : "") << ")\n";
    if (o.common.json) std::cout << compare::rowsToJson(result.rows).dump(2) << "\n";
    return failed ? 1 : 0;
}

int stability(const StabilityCommandOptions& o) {
    // Every case is loaded and checked before anything renders or is written.
    checkOutputFolder(o.outputDir);
    std::vector<fs::path> files;
    if (o.scenes.empty()) {
        for (const auto& e : fs::directory_iterator(scene::scenesDirectory() / "extreme"))
            if (e.path().extension() == ".json") files.push_back(e.path());
        std::sort(files.begin(), files.end());
    } else {
        for (const std::string& name : o.scenes) files.push_back(scene::findScene(name));
    }
    std::vector<scene::Scene> scenes;
    for (const fs::path& f : files)
        scenes.push_back(readingInput(f.string(), [&] { return scene::loadScene(f); }));
    scene::Scene probe;
    applyResolution(probe, o.resolution);
    fs::create_directories(o.outputDir);
    const scene::FolderLock lock(o.outputDir, "stability");

    compare::StabilityOptions options;
    options.width = probe.camera.width;
    options.height = probe.camera.height;
    options.shadowMapSize = o.shadowMapSize;
    options.search = !o.noSearch;
    options.quick = !o.fullGrid;
    options.validate = o.validate;

    std::vector<compare::StabilityCase> cases;
    for (std::size_t i = 0; i < scenes.size(); ++i) {
        const std::string name = files[i].stem().string();
        Stage stage("stability case " + std::to_string(i + 1) + "/" + std::to_string(scenes.size()) + " " + name);
        cases.push_back(compare::runStabilityCase(scenes[i], options, name, compare::readDescription(files[i])));
        stage.done(compare::suitePassed({cases.back()}) ? "ok" : "FAILED");
    }
    compare::writeStabilityReport(o.outputDir, cases);
    std::cerr << "shadowlab: wrote " << (o.outputDir / "stability.html").string() << "\n";
    if (o.json) {
        Json all = Json::array();
        for (const auto& c : cases) all.push_back(compare::toJson(c));
        std::cout << all.dump(2) << "\n";
    }
    if (!compare::suitePassed(cases)) {
        std::cerr << "shadowlab: stability: at least one case failed (see the report)\n";
        return 1;
    }
    return 0;
}

}  // namespace shadowlab::app
