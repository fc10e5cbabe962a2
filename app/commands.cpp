// app/commands.cpp: what each subcommand does, in terms of the libraries. Inputs are loaded and
// validated completely before anything is written, so bad input leaves no file behind.
#include "app/commands.h"

#include "app/guards.h"
#include "scene/folder_lock.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <fstream>
#include <functional>
#include <optional>
#include <cstdio>
#include <iostream>
#include <set>
#include <sstream>
#include <unistd.h>

#include <nlohmann/json.hpp>

#include "studies/backend.h"
#include "studies/check.h"
#include "studies/check_report.h"
#include "compare/compare.h"
#include "compare/gates.h"
#include "studies/machine.h"
#include "studies/merge.h"
#include "studies/path.h"
#include "compare/report.h"
#include "studies/shard.h"
#include "studies/stability.h"
#include "studies/sweep.h"
#include "studies/sweep_report.h"
#include "compare/text.h"
#include "raster/cascades.h"
#include "raster/debug_views.h"
#include "raster/memory.h"
#include "raster/moment_maps.h"
#include "raster/renderer.h"
#include "raster/shadow_layers.h"
#include "raster/tolerances.h"
#include "raytrace/memory.h"
#include "raytrace/renderer.h"
#include "raytrace/view_search.h"
#include "scene/error.h"
#include "scene/frame_identity.h"
#include "scene/frame_io.h"
#include "scene/gltf_export.h"
#include "scene/input_file.h"
#include "scene/loader.h"
#include "scene/mask_io.h"
#include "scene/memory.h"
#include "scene/model_view.h"
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

// The choices a scene file leaves open (scene/model_view.h): a file camera, a ground, the sun,
// then a search for a view and a sun that show shadows where the file has no camera or light.
void chooseView(scene::Scene& s, const SceneOptions* o) {
    if (o && o->camera) scene::applyCameraOption(s, *o->camera);
    scene::applyGround(s, o ? o->ground : std::nullopt);
    if (o && o->sun) scene::applySunOption(s, *o->sun);
    raytrace::chooseViewAndSun(s, o && o->settings.threads ? *o->settings.threads : 0);
}

// The raster backend's automatic choices, each with its reason (--explain; the Frame records the
// same reasons): light-frustum fitting, the cascade count, the map size.
std::string explainAutomaticChoices(const Prepared& p) {
    const scene::RasterSettings& s = p.settings.raster;
    raster::CascadeChoice cascades;
    raster::ShadowMapSizeChoice size;
    raster::resolveAutomaticChoices(p.scene, s, &p.plan, &cascades, &size);
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
                                          std::uint32_t(raster::shadowMapLayers(p.scene, p.plan, s)),
                                          s.moments.blurWidth) +
               ", on top of the depth pass; the lit pass makes one linear lookup per light instead of compare taps\n";
    }
    return out;
}

std::string formatNumberShort(double v) {
    std::ostringstream o;
    o << v;
    return o.str();
}

// --explain's words for the slope bias past its cap (lit.frag; docs/raster.md "Grazing light").
std::string grazingLiftText(const scene::RasterSettings& r) {
    if (!(r.slopeBias > 0.0)) return "";
    std::ostringstream o;
    o << "; past tan " << raster::kMaxSlopeTan << " (" << std::round(std::atan(raster::kMaxSlopeTan) * 1800.0 / 3.14159265358979) / 10.0
      << " deg between normal and light) the slope term goes on as a lift along the normal, slope x texel x (sin - "
      << raster::kMaxSlopeTan
      << " cos): the same margin from the receiver's own plane with the lookup moved less than a texel per texel of "
         "slope, where that margin along the light would pass through casters (grazing_normal_offset in the Frame"
      << (r.hardwareBias ? "; spot and point maps only: the rasterizer's slope term is not capped)" : ")");
    return o.str();
}

Prepared prepare(const SceneOptions& o) {
    Prepared p{readingInput(o.scene, [&] { return scene::loadScene(scene::findScene(o.scene)); }), {}, {}};
    if (o.resolution) applyResolution(p.scene, *o.resolution);
    chooseView(p.scene, &o);
    for (const std::string& note : p.scene.origin.notes) std::cerr << "shadowlab: note: " << note << "\n";
    if (o.explain) std::cerr << scene::explainOrigin(p.scene);
    p.settings = scene::resolveSettings(p.scene, o.settings);
    p.plan = scene::makeRenderPlan(p.scene, p.settings);
    if (o.explain)
        std::cerr << "render plan for " << p.scene.file.string() << ":\n"
                  << p.plan.explain()
                  << explainAutomaticChoices(p)
                  << "raster bias: constant " << p.settings.raster.depthBias << " world units"
                  << (p.settings.raster.depthBiasIsDefault
                          ? (p.settings.raster.fitLightFrustum
                                 ? " (default: half a texel of each map as fitted or cascaded; this value for a "
                                   "bounding-sphere map and spot and point maps)"
                                 : " (default: half a texel of the bounding-sphere map; of each cascade's with cascades)")
                          : "")
                  << ", slope " << p.settings.raster.slopeBias << " texels x tan(angle to light), "
                  << (p.settings.raster.hardwareBias
                          ? "through the rasterizer's depth-bias state in directional maps' depth pass (converted per "
                            "layer, recorded in the Frame; spot and point maps in the lit shader)"
                          : "in the lit shader")
                  << (p.settings.raster.receiverPlaneBias ? "; the receiver plane replaces the slope term in the shader"
                                                          : "")
                  << grazingLiftText(p.settings.raster)
                  << (p.settings.raster.normalOffset > 0.0
                          ? "; normal offset " + formatNumberShort(p.settings.raster.normalOffset) + " texels"
                          : std::string())
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
        std::cerr << raster::explainShadowLayers(
            raster::planShadowLayers(p.scene, p.plan, raster::resolveAutomaticChoices(p.scene, p.settings.raster, &p.plan)),
            p.scene.objects.size());
    }
    return p;
}

// A light with a radius casts soft shadows; in the raster backend only pcss estimates them, every
// other filter gives a hard (or PCF-blurred) edge whose penumbra error the classes barely see.
std::vector<std::string> hardFilterWarnings(const scene::Scene& s, const scene::RasterSettings& r) {
    std::vector<std::string> out;
    if (r.filter == scene::ShadowFilter::Pcss) return out;
    for (std::size_t i = 0; i < s.lights.size(); ++i)
        if (s.lights[i].radius > 0.0 && s.lights[i].type != scene::LightType::Directional)
            out.push_back("light " + std::to_string(i) + " has a radius (" + compare::formatShort(s.lights[i].radius) +
                          ") and casts soft shadows, but the raster backend renders it with the hard filter '" +
                          scene::toString(r.filter) + "': its penumbra is wrong (see the continuous error); use --filter pcss.");
    return out;
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
scene::Frame renderBackend(const Prepared& p, scene::Backend backend,
                           scene::ChannelMask channels = scene::kAllChannels, raster::RenderDebug* debug = nullptr) {
    scene::Frame f = compare::renderFrame(backend, p.scene, p.plan, p.settings, channels, debug);
    if (backend == scene::Backend::Raster) checkValidation(f, p.settings.raster);
    f.attributes["scene"] = p.scene.file.string();
    for (const auto& [key, text] : p.scene.origin.choices) f.attributes["choice." + key] = text;
    for (std::size_t i = 0; i < p.scene.origin.notes.size(); ++i)
        f.attributes["note." + std::to_string(i)] = p.scene.origin.notes[i];
    f.attributes["version"] = SHADOWLAB_VERSION;
    scene::recordIdentity(f, p.scene);
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
std::uint64_t backendMemory(const Prepared& p, scene::Backend backend) {
    return compare::estimateMemoryBytes(backend, p.scene, p.plan, p.settings);
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


// `render -o` into a missing folder: created once the input is known to be good, and the user is
// told (docs/decisions.md, "Output paths"); app::checkOutputFile has refused what cannot be used.
void createOutputFolder(const fs::path& output) {
    if (!output.has_parent_path()) return;
    std::error_code ec;
    if (fs::is_directory(output.parent_path(), ec)) return;
    fs::create_directories(output.parent_path());
    std::cerr << "shadowlab: created the folder " << output.parent_path().string() << " for " << output.filename().string()
              << "\n";
}

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

scene::Budgets parseBudgets(const BudgetOptions& o) {
    scene::Budgets b;
    for (int k = 0; k < scene::kBudgetKindCount; ++k) {
        const auto kind = scene::BudgetKind(k);
        if (o.text[k]) b[kind] = scene::parseBudgetLimit(*o.text[k], kind, scene::budgetInfo(kind).option);
    }
    return b;
}

// Prints every budget checked for `method` on stderr (broken ones say so); true when one broke.
bool reportBudgets(const std::string& method, const std::vector<compare::BudgetCheck>& checks) {
    for (const compare::BudgetCheck& c : checks)
        std::cerr << "shadowlab: budget: " << method << ": "
                  << compare::describe(c) << "\n";
    return compare::anyBroken(checks);
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

// The scene as glTF for other engines (docs/export.md): the scene as its file says, no view
// search or ground, since another engine renders it from the file alone.
int exportScene(const ExportOptions& o) {
    std::string ext = o.output.extension().string();
    std::transform(ext.begin(), ext.end(), ext.begin(), ::tolower);
    if (ext != ".glb" && ext != ".gltf")
        throw scene::InputError(o.output.string() + ": unknown export type '" + o.output.extension().string() +
                                "' (use .glb or .gltf)");
    if (!(o.tolerance > 0.0 && o.tolerance < 0.5))
        throw scene::InputError("--tolerance: must be in (0, 0.5) (a fraction of a sphere's radius), got " +
                                std::to_string(o.tolerance));
    checkOutputFile(o.output);
    const scene::Scene s = readingInput(o.scene, [&] { return scene::loadScene(scene::findScene(o.scene)); });
    createOutputFolder(o.output);
    Stage stage("exporting " + s.file.filename().string());
    const scene::ExportResult r = scene::exportGltf(s, o.output, {o.tolerance});
    char tol[32];
    std::snprintf(tol, sizeof tol, "%.3g", r.achievedTolerance);
    stage.done(std::to_string(r.nodes) + " nodes, " + std::to_string(r.triangles) + " triangles, sphere sagitta " +
               tol + " x radius -> " + o.output.string());
    return 0;
}

int render(const RenderOptions& o) {
    std::string ext = o.output.extension().string();
    if (ext != ".exr" && ext != ".png")
        throw scene::InputError(o.output.string() + ": unknown output type '" + ext + "' (use .exr or .png)");
    const std::string backendName = scene::toString(o.backend);
    if (o.view && (o.backend != scene::Backend::Raster || ext != ".png"))
        throw scene::InputError("--view " + *o.view + ": needs --backend raster and a .png output (a view is a "
                                "display image of the shadow maps), got --backend " + backendName + " and '" + ext + "'");
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
                                              std::to_string(p.scene.camera.height) + " with " + backendName);
    // Only once the input is known to be good may the output's folder be created.
    createOutputFolder(o.output);
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
            Json j = {{"backend", backendName}, {"view", *o.view}, {"output", o.output.string()},
                      {"timings_ms", timingsJson(frame)}, {"attributes", frame.attributes},
                      {"memory", memoryJson(estimate)}};
            std::cout << j.dump(2) << "\n";
        }
        return 0;
    }
    if (o.backend == scene::Backend::Raster)
        for (const std::string& w : hardFilterWarnings(p.scene, p.settings.raster))
            std::cerr << "shadowlab: warning: " << w << "\n";
    Stage stage("rendering " + p.scene.file.filename().string() + " with " + backendName);
    // A PNG holds the beauty only, in 8-bit sRGB: the raster backend then renders nothing else,
    // into an 8-bit sRGB target.
    const scene::Frame frame = renderBackend(
        p, o.backend, ext == ".png" ? scene::kChannelBeauty | scene::kBeautyForDisplay : scene::kAllChannels);
    scene::writeFrame(frame, o.output);
    stage.done(std::to_string(frame.width) + "x" + std::to_string(frame.height) + " -> " + o.output.string() +
               ", " + memoryLine(estimate));
    if (o.common.json) {
        Json j = {{"backend", backendName}, {"output", o.output.string()}, {"timings_ms", timingsJson(frame)},
                  {"attributes", frame.attributes}, {"memory", memoryJson(estimate)}};
        std::cout << j.dump(2) << "\n";
    }
    return 0;
}

int compareFiles(const CompareOptions& o) {
    if (o.output.extension() != ".png")
        throw scene::InputError(o.output.string() + ": the difference image must be a .png");
    if (o.heat && o.heat->extension() != ".png")
        throw scene::InputError(o.heat->string() + ": the heat map must be a .png");
    const scene::Budgets budgets = parseBudgets(o.budgets);
    const bool maskOnly = o.maskChannel || o.maskInvert || o.maskSrgb || scene::looksLikeMask(o.method);
    const scene::Frame reference = readingInput(o.reference.string(), [&] { return scene::readFrame(o.reference); });
    const scene::Frame method =
        maskOnly ? scene::frameFromMask(scene::readShadowMask(o.method, {o.maskChannel, o.maskInvert, o.maskSrgb}),
                                        reference, o.method)
                 : readingInput(o.method.string(), [&] { return scene::readFrame(o.method); });
    if (const std::string d = scene::describeIdentityDifference(method, reference); !d.empty()) {
        if (!o.allowDifferentScene)
            throw scene::InputError(o.method.string() + " vs " + o.reference.string() + ": " + d +
                                    "; compare frames of one scene, camera and size (--allow-different-scene "
                                    "compares them anyway)");
        std::cerr << "shadowlab: warning: " << d << " (--allow-different-scene)\n";
    }
    compare::Comparison c;
    std::vector<compare::BudgetCheck> checks;
    try {
        c = compare::compareFrames(method, reference);
        checks = compare::checkBudgets(c.metrics, budgets);
    } catch (const scene::InputError& e) {
        throw scene::InputError(o.method.string() + " vs " + o.reference.string() + ": " + e.what());
    }
    scene::writePngDisplay(o.output, c.width, c.height, c.diffRgb);
    if (o.heat) scene::writePngDisplay(*o.heat, c.width, c.height, c.heatRgb);
    if (o.json) {
        Json j = compare::toJson(c.metrics);
        if (!checks.empty()) j["budgets"] = compare::toJson(checks);
        std::cout << j.dump(2) << "\n";
    } else {
        std::cout << compare::summaryLine(c.metrics) << "\n";
    }
    return reportBudgets(o.method.filename().string(), checks) ? kExitBudgetBroken : 0;
}

int info(bool validate) {
    std::cout << "shadowlab " << SHADOWLAB_VERSION << "\n";
    std::cout << "scenes: " << scene::scenesDirectory().string() << "\n";
    std::cout << raster::describeDevices(validate);
    return 0;
}

int run(const RunOptions& o) {
    checkOutputFolder(o.outputDir);
    const scene::Budgets cliBudgets = parseBudgets(o.budgets);
    const Prepared p = prepare(o.common);
    const scene::Budgets budgets = p.scene.budgets.overriddenBy(cliBudgets);
    bool budgetBroken = false;
    // The reference, the ray-traced and the raster Frames are all held until the report is
    // written, with a difference image for each method (the half-size sweep needs less).
    const std::uint64_t pixels = std::uint64_t(p.scene.camera.width) * std::uint64_t(p.scene.camera.height);
    // The raster backend's debug views for the report: its shadow maps read back, and one display
    // image at a time (a view's bytes hold the maps and the image being written).
    const bool views = !o.skipRaster && std::any_of(p.plan.lights.begin(), p.plan.lights.end(),
                                                     [](const scene::LightPlan& l) { return l.needsShadowTest; });
    const std::uint64_t estimate =
        scene::kProgramBytes + scene::sceneBytes(p.scene) + backendMemory(p, scene::Backend::Raytrace) + scene::frameBytes(p.scene) +
        (o.skipRaster ? 0 : backendMemory(p, scene::Backend::Raster)) + scene::frameWriteBytes(p.scene) +
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
    const std::vector<std::string> earlierFiles = readRunManifest(target);
    std::vector<std::string> written;  // for the manifest
    int status = 0;

    Json metrics = {{"scene", p.scene.file.string()},
                    {"resolution", {p.scene.camera.width, p.scene.camera.height}},
                    {"version", SHADOWLAB_VERSION}};
    compare::ReportInput report;
    report.sceneName = p.scene.file.stem().string();
    report.scenePath = p.scene.file.string();
    report.planText = p.plan.explain() + explainAutomaticChoices(p);  // and the raster backend's choices
    for (const scene::Object& object : p.scene.objects) report.objectNames.push_back(object.name);

    if (!o.skipRaster) {
        report.warnings = hardFilterWarnings(p.scene, p.settings.raster);
        for (const std::string& w : report.warnings) std::cerr << "shadowlab: warning: " << w << "\n";
        if (!report.warnings.empty()) metrics["warnings"] = report.warnings;
    }
    Stage refStage("reference (double precision, robust offsets)");
    const scene::Frame reference = renderBackend(p, scene::Backend::Reference);
    scene::writeFrame(reference, dir / "reference.exr");
    scene::writePngLinear(dir / "reference.png", reference.width, reference.height, reference.beauty);
    written.insert(written.end(), {"reference.exr", "reference.png"});
    refStage.done();
    metrics["reference"] = {{"timings_ms", timingsJson(reference)}, {"attributes", reference.attributes}};
    report.reference = {"reference", "reference.png", reference};

    // The user's configuration at the requested resolution, kept for the recommendation's check.
    std::optional<scene::Frame> defaultsFrame[2];  // raytrace, raster
    for (const scene::Backend b : {scene::Backend::Raytrace, scene::Backend::Raster}) {
        const bool isRaster = b == scene::Backend::Raster;
        if (isRaster && o.skipRaster) continue;
        const std::string backend = scene::toString(b);
        Stage stage(isRaster ? "raster (Vulkan shadow map)" : "raytrace (shadow rays)");
        scene::Frame frame;
        raster::RenderDebug debug;
        debug.captureShadowMaps = views;
        try {
            frame = renderBackend(p, b, scene::kAllChannels, isRaster && views ? &debug : nullptr);
        } catch (const std::exception& e) {
            // One backend failing (no Vulkan driver, say) must not lose the other's results.
            std::cerr << "\nshadowlab: error: " << backend << " backend failed: " << e.what() << "\n";
            metrics["methods"][backend] = {{"error", e.what()}};
            report.failures.push_back({backend, e.what()});
            status = 1;
            continue;
        }
        defaultsFrame[isRaster] = frame;
        scene::writeFrame(frame, dir / (backend + ".exr"));
        scene::writePngLinear(dir / (backend + ".png"), frame.width, frame.height, frame.beauty);
        const compare::Comparison c = compare::compareFrames(frame, reference);
        scene::writePngDisplay(dir / ("diff-" + backend + ".png"), c.width, c.height, c.diffRgb);
        written.insert(written.end(), {backend + ".exr", backend + ".png", "diff-" + backend + ".png"});
        stage.done(compare::summaryLine(c.metrics));
        metrics["methods"][backend] = {{"metrics", compare::toJson(c.metrics)},
                                       {"timings_ms", timingsJson(frame)},
                                       {"attributes", frame.attributes}};
        const std::vector<compare::BudgetCheck> checks = compare::checkBudgets(c.metrics, budgets);
        if (!checks.empty()) metrics["methods"][backend]["budgets"] = compare::toJson(checks);
        budgetBroken = reportBudgets(backend, checks) || budgetBroken;
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
                const raster::DisplayImage img = debugView(v.view, frame, p.scene, debug);
                const std::string png = std::string("raster-") + v.view + ".png";
                scene::writePngDisplay(dir / png, img.width, img.height, img.rgb);
                written.push_back(png);
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
        compare::SweepReportInput input = compare::makeSweepReportInput(report.sceneName, report.scenePath, result);
        {
            Stage rec("recommended shadow block: biases searched in this configuration, checked at " +
                      std::to_string(p.scene.camera.width) + "x" + std::to_string(p.scene.camera.height));
            scene::Scene half = p.scene;
            half.camera.width = result.reference.width;
            half.camera.height = result.reference.height;
            compare::RecommendOptions ro;
            ro.user = o.common.settings;
            ro.raster = !o.skipRaster;
            input.recommendation = compare::recommendShadow(
                half, result.reference, p.scene, reference, defaultsFrame[1] ? &*defaultsFrame[1] : nullptr,
                defaultsFrame[0] ? &*defaultsFrame[0] : nullptr,
                compare::rayCandidateOf(compare::recommendBias(result.rows)), ro);
            rec.done(std::to_string(input.recommendation->points.size()) + " raster points");
            for (const std::string& note : input.recommendation->notes) std::cerr << "shadowlab: " << note << "\n";
        }
        compare::writeSweepReport(options.outputDir, input);
        scene::replaceDirectory(options.outputDir, dir / "sweep");
        written.push_back("sweep/");
        report.sweep = compare::summarizeSweep(input, "sweep/report.html");
        stage.done("sweep/report.html");
        metrics["sweep"] = {{"configurations", result.rows.size()}, {"report", "sweep/report.html"},
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
    std::cerr << "shadowlab: wrote " << (o.outputDir / "report.html").string() << "; " << memoryLine(estimate) << "\n";
    if (o.common.json) std::cout << metrics.dump(2) << "\n";
    // A failure (1) says more than a broken budget: a method that did not render measured nothing.
    return status != 0 ? status : budgetBroken ? kExitBudgetBroken : 0;
}

namespace {

// One shard of a sweep: its rows only, into DIR/shard-K-of-N; the report comes from `merge`.
int sweepShard(const SweepOptions& o, const scene::Scene& scene, const compare::SweepGrid& grid,
               const compare::SweepOptions& options) {
    const compare::Shard shard = compare::parseShard(*o.shard);
    const std::size_t mine = compare::shardGrid(grid, shard).configs.size();
    const fs::path dir = o.outputDir / compare::shardFolderName(shard);
    // One writer per shard folder: the same shard started twice would duplicate its journal's keys.
    fs::create_directories(dir);
    const scene::FolderLock lock(dir, "sweep --shard");
    std::cerr << "shadowlab: sweep shard " << shard.index << "/" << shard.count << ": " << mine << " of "
              << compare::gridKeys(grid).size() << " configurations, " << grid.repetitions
              << " timed frames each, into " << dir.string() << "\n";
    compare::SharedReferenceOptions ref;
    ref.log = [](const std::string& line) { std::cerr << "shadowlab: " << line << "\n"; };
    const compare::SweepResult result = compare::runShard(scene, grid, shard, options, ref);
    std::size_t failed = 0;
    for (const auto& r : result.rows) failed += r.error.empty() ? 0 : 1;
    std::cerr << "shadowlab: wrote " << dir.string() << " (" << result.rows.size() << " rows"
              << (failed ? ", " + std::to_string(failed) + " failed" : "") << "); when every shard is done: shadowlab merge "
              << o.outputDir.string() << "\n";
    if (o.common.json) std::cout << compare::rowsToJson(result.rows).dump(2) << "\n";
    return failed ? 1 : 0;
}

}  // namespace

namespace {

// `merge` of check shards: the junit.xml, summary.md and cases/ of the unsharded check, and its exit code.
int mergeCheck(const MergeOptions& o) {
    const compare::MergedCheck merged = compare::readCheckShards(o.inputs);
    fs::path out;
    if (o.outputDir) out = *o.outputDir;
    else if (o.inputs.size() == 1 && !fs::exists(o.inputs.front() / "shard.json")) out = o.inputs.front();
    else
        throw scene::InputError("merge: give the merged folder with -o (the inputs are " +
                                std::string(o.inputs.size() == 1 ? "a shard folder" : "several folders") + ")");
    compare::writeMergedCheck(merged, out);
    std::size_t failed = 0, errors = 0;
    for (const compare::CasePart& p : merged.parts) {
        failed += p.verdict == compare::CaseVerdict::Failed ? 1 : 0;
        errors += p.verdict == compare::CaseVerdict::Error ? 1 : 0;
    }
    std::cerr << "shadowlab: merged " << merged.shardDirs.size() << " check shards of " << merged.identity.suiteName
              << ": " << merged.parts.size() - failed - errors << " passed, " << failed << " failed, " << errors
              << " errors; wrote " << (out / "junit.xml").string() << ", summary.md, summary.html, cases/\n";
    return errors ? 1 : failed ? kExitBudgetBroken : 0;
}

}  // namespace

namespace {

void printPathSummary(const compare::PathResult& result) {
    for (const compare::PathMethod& m : result.methods)
        std::cerr << "shadowlab: " << m.name << ": mean flicker " << compare::formatPercent(m.temporal.meanFlickerRate)
                  << " (" << m.temporal.totalFlicker << " px over " << m.temporal.pairs.size() << " pairs), swim "
                  << compare::formatFixed(m.temporal.meanSwimPixels, 3) << " px, edge offset "
                  << compare::formatFixed(m.temporal.meanEdgeOffset, 3) << " px\n";
}

// `merge` of path shards: the frames, metrics.json and report of the unsharded path.
int mergePath(const MergeOptions& o) {
    fs::path out;
    if (o.outputDir) out = *o.outputDir;
    else if (o.inputs.size() == 1 && !fs::exists(o.inputs.front() / "shard.json")) out = o.inputs.front();
    else
        throw scene::InputError("merge: give the merged folder with -o (the inputs are " +
                                std::string(o.inputs.size() == 1 ? "a shard folder" : "several folders") + ")");
    const compare::MergedPath merged = compare::mergePathShards(o.inputs, out);
    std::cerr << "shadowlab: merged " << merged.shardCount << " path shards (" << merged.shardDirs.size() << " folders, "
              << merged.result.frames << " frames"
              << (merged.duplicates ? ", " + std::to_string(merged.duplicates) + " duplicate frames merged once" : "")
              << ")\n";
    printPathSummary(merged.result);
    std::cerr << "shadowlab: wrote " << (out / "report.html").string() << " and metrics.json\n";
    if (o.json) std::cout << compare::toJson(merged.result).dump(2) << "\n";
    return 0;
}

}  // namespace

int merge(const MergeOptions& o) {
    if (compare::holdsCheckShards(o.inputs)) return mergeCheck(o);
    if (compare::holdsPathShards(o.inputs)) return mergePath(o);
    const compare::MergedSweep merged = compare::readShards(o.inputs);
    fs::path out;
    if (o.outputDir) {
        out = *o.outputDir;
    } else if (o.inputs.size() == 1 && !fs::exists(o.inputs.front() / "shard.json")) {
        out = o.inputs.front();
    } else {
        throw scene::InputError("merge: give the merged folder with -o (the inputs are " +
                                std::string(o.inputs.size() == 1 ? "a shard folder" : "several folders") + ")");
    }
    compare::writeMerged(merged, out);
    compare::writeSweepReport(out, compare::mergedReportInput(merged, out));
    std::size_t failed = 0;
    std::set<std::string> machines;
    for (const auto& r : merged.rows) {
        failed += r.error.empty() ? 0 : 1;
        machines.insert(compare::machineFromJson(r.machine).id());
    }
    std::cerr << "shadowlab: merged " << merged.shardCount << " shards (" << merged.shardDirs.size() << " folders, "
              << merged.rows.size() << " rows" << (failed ? ", " + std::to_string(failed) + " failed" : "")
              << (merged.duplicates ? ", " + std::to_string(merged.duplicates) + " duplicate rows merged once" : "")
              << (machines.size() > 1 ? ", timed on " + std::to_string(machines.size()) + " machines" : "")
              << "): wrote " << (out / "report.html").string() << ", results.csv and results.json\n";
    if (o.json) std::cout << compare::rowsToJson(merged.rows).dump(2) << "\n";
    return failed ? 1 : 0;
}

int sweep(const SweepOptions& o) {
    checkOutputFolder(o.outputDir);
    const Prepared p = prepare(o.common);
    compare::SweepGrid grid = o.grid ? readingInput(o.grid->string(), [&] { return compare::loadGrid(*o.grid, p.scene); })
                                     : compare::defaultGrid(p.scene, o.quick);
    if (o.repetitions) grid.repetitions = *o.repetitions;
    if (o.common.resolution) grid.resolution = o.common.resolution;
    if (o.flicker || o.flickerFrames) {
        compare::PathSpec path = grid.flicker.value_or(compare::defaultFlickerPath());
        // Given without a value, CLI11 reports the flag as "true": the default kind.
        if (o.flicker && !o.flicker->empty() && *o.flicker != "true") path.kind = compare::parsePathKind(*o.flicker);
        if (o.flickerFrames) path.frames = *o.flickerFrames;
        compare::flickerScenes(compare::sweepScene(p.scene, grid), path);  // a bad path fails before anything is written
        grid.flicker = path;
    }
    // Settings given on the command line apply to every configuration that does not vary them.
    const scene::SettingsOverrides& base = o.common.settings;
    for (compare::SweepConfig& c : grid.configs) {
        auto& v = c.overrides;
        if (!v.shadowMapSize) v.shadowMapSize = base.shadowMapSize;
        if (!v.depthBias) v.depthBias = base.depthBias;
        if (!v.slopeBias) v.slopeBias = base.slopeBias;
        if (!v.filter) v.filter = base.filter;
        if (!v.cascades) v.cascades = base.cascades;
        if (!v.cascadeBlend) v.cascadeBlend = base.cascadeBlend;
        if (!v.snapLightFrustum) v.snapLightFrustum = base.snapLightFrustum;
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
    // Shards share the output folder; each holds the lock of its own shard folder.
    if (o.shard) return sweepShard(o, p.scene, grid, options);
    // One writer per folder: two sweeps appending to one journal would duplicate its keys.
    fs::create_directories(o.outputDir);
    const scene::FolderLock lock(o.outputDir, "sweep");
    std::cerr << "shadowlab: sweep of " << grid.configs.size() << " configurations, " << grid.repetitions
              << " timed frames each, into " << o.outputDir.string() << "\n";
    const compare::SweepResult result = compare::runSweep(p.scene, grid, options);
    compare::SweepReportInput input =
        compare::makeSweepReportInput(p.scene.file.stem().string(), p.scene.file.string(), result);
    {
        // The recommendation is searched and checked at the sweep's resolution, in the settings
        // given on the command line (the grid's own rows vary them; the user runs these).
        scene::Scene at = p.scene;
        at.camera.width = result.reference.width;
        at.camera.height = result.reference.height;
        compare::RecommendOptions ro;
        ro.user = o.common.settings;
        ro.raster = std::any_of(grid.configs.begin(), grid.configs.end(),
                                [](const compare::SweepConfig& c) { return c.backend == "raster"; });
        ro.raytrace = std::any_of(grid.configs.begin(), grid.configs.end(),
                                  [](const compare::SweepConfig& c) { return c.backend == "raytrace"; });
        Stage rec("recommended shadow block: biases searched in this configuration");
        input.recommendation = compare::recommendShadow(at, result.reference, at, result.reference, nullptr, nullptr,
                                                        compare::rayCandidateOf(compare::recommendBias(result.rows)), ro);
        rec.done();
        for (const std::string& note : input.recommendation->notes) std::cerr << "shadowlab: " << note << "\n";
    }
    compare::writeSweepReport(o.outputDir, input);
    std::size_t failed = 0;
    for (const auto& r : result.rows) failed += r.error.empty() ? 0 : 1;
    std::cerr << "shadowlab: wrote " << (o.outputDir / "report.html").string() << ", results.csv and results.json ("
              << result.rows.size() << " rows" << (failed ? ", " + std::to_string(failed) + " failed" : "") << ")\n";
    if (o.common.json) std::cout << compare::rowsToJson(result.rows).dump(2) << "\n";
    return failed ? 1 : 0;
}

int check(const CheckOptions& o) {
    // The suite, every scene it names and the baseline are read and checked before anything runs.
    const compare::CheckSuite fullSuite = compare::loadSuite(o.suite);
    compare::CheckSuite suite = fullSuite;
    const std::optional<fs::path> baselineFile = o.baseline ? o.baseline : suite.baseline;
    if (o.updateBaseline && !baselineFile)
        throw scene::InputError(o.suite.string() + ": --update-baseline: the suite names no \"baseline\" file and "
                                "--baseline gives none");
    std::optional<compare::Baseline> baseline;
    if (baselineFile && !o.updateBaseline) {
        if (!fs::exists(*baselineFile))
            throw scene::InputError(baselineFile->string() + ": no such baseline (write one with --update-baseline)");
        baseline = compare::loadBaseline(*baselineFile);
    }
    std::optional<compare::Shard> shard;
    compare::CheckShardManifest manifest;
    if (o.shard) {
        shard = compare::parseShard(*o.shard);
        // N shards writing one baseline would race; a baseline comes from an unsharded run.
        if (o.updateBaseline)
            throw scene::InputError("check --shard: --update-baseline is not sharded; update the baseline with an "
                                    "unsharded `check`");
        manifest.version = SHADOWLAB_VERSION;
        manifest.suite = o.suite.string();
        manifest.suiteName = suite.name;
        manifest.suiteHash = compare::fileHash(o.suite);
        manifest.baselineHash = baseline ? compare::fileHash(*baselineFile) : "none";
        manifest.shard = *shard;
        for (const auto& c : fullSuite.cases) manifest.suiteCases.push_back(c.name);
        suite = compare::shardSuite(fullSuite, *shard);
        for (const auto& c : suite.cases) manifest.cases.push_back(c.name);
        std::cerr << "shadowlab: check shard " << shard->index << "/" << shard->count << ": " << suite.cases.size()
                  << " of " << fullSuite.cases.size() << " cases\n";
    }
    std::cerr << "shadowlab: check " << suite.name << ": " << suite.cases.size() << " cases"
              << (baseline ? " against " + baselineFile->string() : std::string(" without a baseline")) << "\n";
    const auto results = compare::runSuite(
        suite, baseline ? &*baseline : nullptr, [&](std::size_t done, const compare::CaseResult& r) {
            std::string what = r.verdict == compare::CaseVerdict::Error ? "ERROR: " + r.error
                               : r.metrics ? compare::summaryLine(*r.metrics) : "";
            if (r.verdict == compare::CaseVerdict::Failed) what = "FAILED: " + r.failures.front() + "; " + what;
            std::cerr << "shadowlab: check [" << done << "/" << suite.cases.size() << "] " << r.name << ": " << what
                      << "\n";
        });

    // Everything goes to a fresh folder that replaces DIR in one step: no file of an earlier run
    // (a difference image of a case that failed then) survives next to this run's.
    const fs::path dir = shard ? o.outputDir / compare::shardFolderName(*shard) : o.outputDir;
    if (dir.has_parent_path()) fs::create_directories(dir.parent_path());
    // Not beside a shard: the shared folder may hold other machines' live temporaries, whose
    // writers this host cannot see.
    if (!shard) scene::removeStaleTemporaries(dir.has_parent_path() ? dir.parent_path() : fs::path("."));
    const fs::path tmp = scene::temporarySibling(dir);
    fs::create_directories(tmp / "cases");
    std::size_t failed = 0, errors = 0;
    for (std::size_t i = 0; i < results.size(); ++i) {
        const compare::CaseResult& r = results[i];
        failed += r.verdict == compare::CaseVerdict::Failed ? 1 : 0;
        errors += r.verdict == compare::CaseVerdict::Error ? 1 : 0;
        scene::writeTextAtomic(tmp / "cases" / (r.name + ".json"), compare::caseJson(suite.cases[i], r).dump(2) + "\n");
        if (!r.diffRgb.empty())
            scene::writePngDisplay(tmp / "cases" / (r.name + "-diff.png"), r.width, r.height, r.diffRgb);
    }
    scene::writeTextAtomic(tmp / "junit.xml", compare::junitXml(suite, results));
    scene::writeTextAtomic(tmp / "summary.md", compare::markdownSummary(suite, results, o.updateBaseline));
    std::set<std::string> withDiff;
    for (const compare::CaseResult& r : results)
        if (!r.diffRgb.empty()) withDiff.insert(r.name);
    scene::writeTextAtomic(tmp / "summary.html",
                           compare::htmlSummary(suite.name, compare::caseParts(suite, results), o.updateBaseline, withDiff));
    if (shard) {
        nlohmann::json parts = nlohmann::json::array();
        for (const compare::CasePart& part : compare::caseParts(suite, results)) parts.push_back(compare::toJson(part));
        scene::writeTextAtomic(tmp / "shard-parts.json", parts.dump(1) + "\n");
        scene::writeTextAtomic(tmp / "shard.json", compare::toJson(manifest).dump(1) + "\n");
    }
    scene::replaceDirectory(tmp, dir);
    if (o.updateBaseline) {
        // Cases that could not render keep their old entry; cases no longer in the suite go.
        compare::Baseline old, next;
        try {
            if (fs::exists(*baselineFile)) old = compare::loadBaseline(*baselineFile);
        } catch (const scene::SceneError&) {
            // A damaged baseline is being replaced.
        }
        for (const compare::CaseResult& r : results) {
            if (r.metrics) next[r.name] = compare::baselineEntry(*r.metrics);
            else if (old.count(r.name)) next[r.name] = old[r.name];
        }
        scene::writeTextAtomic(*baselineFile, compare::baselineJson(suite.name, next).dump(2) + "\n");
        std::cerr << "shadowlab: wrote the baseline " << baselineFile->string() << "\n";
    }
    std::cerr << "shadowlab: check " << suite.name << ": " << results.size() - failed - errors << " passed, " << failed
              << " failed, " << errors << " errors; wrote " << (dir / "junit.xml").string() << ", summary.md, summary.html, cases/\n";
    return errors ? 1 : failed ? kExitBudgetBroken : 0;
}

int path(const PathCommandOptions& o) {
    const Prepared p = prepare(o.common);
    // The command line's path replaces the scene's "path" block when it names a kind; otherwise the
    // block is used, with --frames, --amount and --light over its values.
    compare::PathSpec spec;
    const bool cliKind = o.kind || o.cameraAnimation;
    if (!cliKind && p.scene.path) spec = compare::pathSpecOf(*p.scene.path);
    if (o.kind) spec.kind = compare::parsePathKind(*o.kind);
    if (o.cameraAnimation) {
        if (o.kind && spec.kind != compare::PathKind::GltfAnimation)
            throw scene::InputError("--camera-animation: follows a glTF animation; it cannot go with --kind " + *o.kind);
        spec.kind = compare::PathKind::GltfAnimation;
        // Given without a value, CLI11 reports the flag as "true": the first animation.
        spec.animation = *o.cameraAnimation == "true" ? std::string() : *o.cameraAnimation;
    }
    if (o.frames) spec.frames = *o.frames;
    if (o.amount) spec.amount = o.amount;
    if (o.light) spec.light = *o.light;
    compare::pathScenes(p.scene, p.settings, spec);  // bad paths fail before anything is written
    compare::PathRunOptions options;
    options.outputDir = o.outputDir;
    options.resume = o.resume;
    options.raster = !o.skipRaster;
    options.raytrace = !o.skipRaytrace;
    options.heldView = !o.noHeldView;
    options.progress = [](const std::string& line) { std::cerr << "shadowlab: path " << line << "\n"; };
    const std::string kind = compare::toString(spec.kind);
    if (o.shard) {
        const compare::Shard shard = compare::parseShard(*o.shard);
        options.shardIndex = shard.index;
        options.shardCount = shard.count;
        const fs::path dir = o.outputDir / compare::shardFolderName(shard);
        fs::create_directories(dir);
        const scene::FolderLock lock(dir, "path --shard");
        std::cerr << "shadowlab: " << kind << " path shard " << shard.index << "/" << shard.count << ": "
                  << compare::pathShardFrames(spec.frames, shard.index, shard.count).size() << " of " << spec.frames
                  << " frames into " << dir.string() << "\n";
        const compare::PathResult result = compare::runPath(p.scene, p.settings, spec, options);
        std::cerr << "shadowlab: wrote " << dir.string() << " (" << result.resumedFrames << " frames resumed); when every "
                  << "shard is done: shadowlab merge " << o.outputDir.string() << "\n";
        return 0;
    }
    std::cerr << "shadowlab: " << kind << " path of " << spec.frames << " frames into " << o.outputDir.string() << "\n";
    const compare::PathResult result = compare::runPath(p.scene, p.settings, spec, options);
    printPathSummary(result);
    std::cerr << "shadowlab: wrote " << (o.outputDir / "report.html").string() << " and metrics.json\n";
    if (o.common.json) std::cout << compare::toJson(result).dump(2) << "\n";
    return 0;
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
    for (const fs::path& f : files) {
        scenes.push_back(readingInput(f.string(), [&] { return scene::loadScene(f); }));
        chooseView(scenes.back(), nullptr);
    }
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
        // The reference's verdict and each backend's state, not one PASS that hides acne.
        const compare::StabilityCase& c = cases.back();
        std::string note = std::string(c.failed() ? "FAILED to run cleanly; " : "") + "reference " + c.referenceVerdict();
        for (const char* backend : {"raster", "raytrace"})
            for (const char* variant : {"defaults", "best"})
                if (const compare::BackendRun* r = c.run(backend, variant))
                    note += std::string("; ") + backend + " at " + variant + ": " +
                            compare::stateOf(r, std::string(variant) == "best").text;
        stage.done(note);
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
