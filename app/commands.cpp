// app/commands.cpp: what each subcommand does, in terms of the libraries. Inputs are loaded and
// validated completely before anything is written, so bad input leaves no file behind.
#include "app/commands.h"

#include "app/guards.h"
#include "scene/folder_lock.h"

#include <unistd.h>
#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <fstream>
#include <functional>
#include <iostream>
#include <memory>
#include <optional>
#include <set>
#include <sstream>

#include <nlohmann/json.hpp>

#include "compare/compare.h"
#include "compare/gates.h"
#include "compare/text.h"
#include "raster/cascades.h"
#include "raster/debug_views.h"
#include "raster/devices.h"
#include "raster/light_frustum.h"
#include "raster/memory.h"
#include "raster/renderer.h"
#include "raster/shadow_layers.h"
#include "raster/tolerances.h"
#include "raster/vulkan_error.h"
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
#include "studies/backend.h"
#include "studies/check.h"
#include "studies/check_report.h"
#include "studies/machine.h"
#include "studies/merge.h"
#include "studies/path.h"
#include "studies/run.h"
#include "studies/shard.h"
#include "studies/stability.h"
#include "studies/sweep.h"
#include "studies/sweep_report.h"

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
        throw scene::InputError("--resolution: " + text + " is outside 1x1.." + std::to_string(scene::kMaxResolution) +
                                " per side and " + std::to_string(scene::kMaxPixels) + " pixels in all");
    s.camera.width = w;
    s.camera.height = h;
}

std::string formatNumberShort(double v) {
    std::ostringstream o;
    o << v;
    return o.str();
}

// The choices a scene file leaves open (scene/model_view.h): a file camera, a ground, the sun,
// then a search for a view and a sun that show shadows where the file has no camera or light.
void chooseView(scene::Scene& s, const SceneOptions* o) {
    if (o && o->camera) scene::applyCameraOption(s, *o->camera);
    scene::applyGround(s, o ? o->ground : std::nullopt);
    if (o && o->sun) scene::applySunOption(s, *o->sun);
    scene::fitGroundToSun(s);
    raytrace::chooseViewAndSun(s, o && o->settings.threads ? *o->settings.threads : 0);
    // A camera that frames none of the objects renders only background, which would compare as
    // a perfect agreement: say so.
    bool seen = false;
    for (const scene::Object& obj : s.objects)
        if (!raster::visibleReceiverPoints(s, scene::boundsOf(obj.shape)).empty()) {
            seen = true;
            break;
        }
    if (!seen) {
        const auto v = [](const scene::Vec3& p) {
            std::ostringstream t;
            t << "[" << p.x << ", " << p.y << ", " << p.z << "]";
            return t.str();
        };
        const scene::Bounds b = s.bounds();
        s.origin.notes.push_back("the camera at " + v(s.camera.position) + " looking at " + v(s.camera.lookAt) +
                                 " (near " + formatNumberShort(s.camera.near) + ", far " +
                                 formatNumberShort(s.camera.far) + ") frames none of the objects (bounds " + v(b.min) +
                                 " to " + v(b.max) + "): every pixel is background and there is no shadow to judge");
    }
}

// --explain's words for the slope bias past its cap (lit.frag; docs/raster.md "Grazing light").
std::string grazingLiftText(const scene::RasterSettings& r) {
    if (!(r.slopeBias > 0.0)) return "";
    std::ostringstream o;
    o << "; past tan " << raster::kMaxSlopeTan << " ("
      << std::round(std::atan(raster::kMaxSlopeTan) * 1800.0 / 3.14159265358979) / 10.0
      << " deg between normal and light) the slope term goes on as a lift along the normal, slope x texel x (sin - "
      << raster::kMaxSlopeTan
      << " cos): the same margin from the receiver's own plane with the lookup moved less than a texel per texel of "
         "slope, where that margin along the light would pass through casters (grazing_normal_offset in the Frame"
      << (r.hardwareBias ? "; spot and point maps only: the rasterizer's slope term is not capped)" : ")");
    return o.str();
}

// A --device that names no usable device is bad usage: refused before anything is rendered or
// written, as any other bad option is, rather than failing the raster backend midway through.
void checkDeviceOption(const SceneOptions& o) {
    if (!o.settings.device || o.settings.device->empty()) return;
    try {
        raster::selectDevice(raster::enumerateDevices(false), *o.settings.device);
    } catch (const raster::RasterError& e) {
        const std::string what = e.what();
        throw scene::InputError(what.rfind("--device", 0) == 0 ? what : "--device " + *o.settings.device + ": " + what);
    }
}

Prepared prepare(const SceneOptions& o) {
    checkDeviceOption(o);
    Prepared p{readingInput(o.scene, [&] { return scene::loadScene(scene::findScene(o.scene)); }), {}, {}};
    if (o.resolution) applyResolution(p.scene, *o.resolution);
    chooseView(p.scene, &o);
    for (const std::string& note : p.scene.origin.notes) std::cerr << "shadowlab: note: " << note << "\n";
    if (o.explain) std::cerr << scene::explainOrigin(p.scene);
    p.settings = scene::resolveSettings(p.scene, o.settings);
    p.plan = scene::makeRenderPlan(p.scene, p.settings);
    if (o.explain)
        std::cerr
            << "render plan for " << p.scene.file.string() << ":\n"
            << p.plan.explain()
            << studies::explainAutomaticChoices(p.scene, p.plan, p.settings.raster)
            // The bias for the map size chosen per view (what the layers and the Frame hold).
            << "raster bias: constant "
            << (p.settings.raster.depthBiasIsDefault && p.settings.raster.fitLightFrustum
                    ? "half a texel of each map as fitted or cascaded (the default; each map's value is on its L "
                      "line below), "
                    : "")
            << raster::resolveAutomaticChoices(p.scene, p.settings.raster, &p.plan).depthBias << " world units"
            << (p.settings.raster.depthBiasIsDefault
                    ? (p.settings.raster.fitLightFrustum
                           ? " for a bounding-sphere map and spot and point maps"
                           : " (default: half a texel of the bounding-sphere map; of each cascade's with cascades)")
                    : "")
            << ", slope " << p.settings.raster.slopeBias << " texels x tan(angle to light), "
            << (p.settings.raster.hardwareBias
                    ? "through the rasterizer's depth-bias state in directional maps' depth pass (converted per "
                      "layer, recorded in the Frame; spot and point maps in the lit shader)"
                    : "in the lit shader")
            << (p.settings.raster.receiverPlaneBias ? "; the receiver plane replaces the slope term in the shader" : "")
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
            raster::planShadowLayers(p.scene, p.plan,
                                     raster::resolveAutomaticChoices(p.scene, p.settings.raster, &p.plan)),
            p.scene.objects.size());
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
        if (isatty(STDERR_FILENO))
            std::cerr << " " << buf;
        else
            std::cerr << "shadowlab: " << what_ << ": " << buf;
        std::cerr << (note.empty() ? "" : ", " + note) << "\n";
    }

private:
    std::string what_;
    Clock::time_point start_;
};

// "peak memory 412 MiB (estimated at most 530 MiB)"; studies::memoryJson has the same figures for --json.
std::string memoryLine(std::uint64_t estimate) {
    return "peak memory " + std::to_string(scene::peakResidentBytes() / scene::kMiB) + " MiB (estimated at most " +
           std::to_string(estimate / scene::kMiB) + " MiB)";
}

// Sweep progress: a bar with ETA on a terminal, one plain line per configuration otherwise.
std::function<void(const studies::SweepProgress&)> sweepProgressPrinter() {
    const bool tty = isatty(STDERR_FILENO);
    return [tty](const studies::SweepProgress& pr) {
        const std::string what = pr.row ? pr.row->config.label() : "";
        const std::string outcome =
            pr.row && !pr.row->error.empty() ? "failed: " + pr.row->error
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
        std::cerr << "shadowlab: budget: " << method << ": " << compare::describe(c) << "\n";
    return compare::anyBroken(checks);
}

// What `run` tells as it goes, on stderr: its stages with their times, warnings, a backend's
// failure, the budgets, the sweep's progress and the recommendation's sentences.
class RunPrinter final : public studies::RunProgress {
public:
    void begin(const std::string& stage) override { stages_.push_back(std::make_unique<Stage>(stage)); }
    void end(const std::string& note) override {
        stages_.back()->done(note);
        stages_.pop_back();
    }
    void backendFailed(scene::Backend backend, const std::string& error) override {
        stages_.pop_back();
        std::cerr << "\nshadowlab: error: " << scene::toString(backend) << " backend failed: " << error << "\n";
    }
    void warning(const std::string& text) override { std::cerr << "shadowlab: warning: " << text << "\n"; }
    void budgets(const std::string& method, const std::vector<compare::BudgetCheck>& checks) override {
        reportBudgets(method, checks);
    }
    void sweep(const studies::SweepProgress& progress) override { sweepProgress_(progress); }
    void note(const std::string& text) override { std::cerr << "shadowlab: " << text << "\n"; }

private:
    std::vector<std::unique_ptr<Stage>> stages_;
    std::function<void(const studies::SweepProgress&)> sweepProgress_ = sweepProgressPrinter();
};

}  // namespace

// The scene as glTF for other engines (docs/export.md): the scene run and render would draw,
// with the view, sun and ground they would choose, since another engine renders it from the
// file alone and its shadows are graded against this scene's reference.
int exportScene(const ExportOptions& o) {
    scene::checkExportOptions(o.output, {o.tolerance});
    checkOutputFile(o.output);
    scene::Scene s = readingInput(o.common.scene, [&] { return scene::loadScene(scene::findScene(o.common.scene)); });
    if (o.common.resolution) applyResolution(s, *o.common.resolution);
    chooseView(s, &o.common);
    for (const std::string& note : s.origin.notes) std::cerr << "shadowlab: note: " << note << "\n";
    if (o.common.explain) std::cerr << scene::explainOrigin(s);
    const CreatedFolders folders(o.output);
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
        throw scene::InputError("--view " + *o.view +
                                ": needs --backend raster and a .png output (a view is a "
                                "display image of the shadow maps), got --backend " +
                                backendName + " and '" + ext + "'");
    checkOutputFile(o.output);  // before any work: an output that cannot be written fails now
    const Prepared p = prepare(o.common);
    // A view writes a display image, not the Frame; the shadow-map view holds every layer's depths.
    const std::uint64_t estimate = scene::kProgramBytes + scene::sceneBytes(p.scene) +
                                   studies::estimateMemoryBytes(o.backend, p.scene, p.plan, p.settings) +
                                   (o.view ? raster::debugViewBytes(p.scene, p.plan, p.settings.raster, *o.view)
                                           : scene::frameWriteBytes(p.scene));
    scene::checkMemory(estimate, o.view
                                     ? "rendering the " + *o.view + " view of " + std::to_string(p.scene.camera.width) +
                                           "x" + std::to_string(p.scene.camera.height)
                                     : "rendering " + std::to_string(p.scene.camera.width) + "x" +
                                           std::to_string(p.scene.camera.height) + " with " + backendName);
    // Only once the input is known to be good may the output's folder be created.
    const CreatedFolders folders(o.output);
    if (o.view) {
        Stage stage("rendering the " + *o.view + " view of " + p.scene.file.filename().string());
        raster::RenderDebug debug;
        debug.captureShadowMaps = *o.view == "shadow-map";
        const scene::Frame frame = raster::render(p.scene, p.plan, p.settings.raster, &debug);
        studies::checkValidation(frame, p.settings.raster);
        const raster::DisplayImage img = studies::debugView(*o.view, frame, p.scene, debug);
        scene::writePngDisplay(o.output, img.width, img.height, img.rgb);
        stage.done(std::to_string(img.width) + "x" + std::to_string(img.height) + " -> " + o.output.string() + ", " +
                   memoryLine(estimate));
        if (o.common.json) {
            Json j = {{"backend", backendName},         {"view", *o.view},
                      {"output", o.output.string()},    {"timings_ms", studies::timingsJson(frame)},
                      {"attributes", frame.attributes}, {"memory", studies::memoryJson(estimate)}};
            std::cout << j.dump(2) << "\n";
        }
        return 0;
    }
    if (o.backend == scene::Backend::Raster)
        for (const std::string& w : studies::hardFilterWarnings(p.scene, p.settings.raster))
            std::cerr << "shadowlab: warning: " << w << "\n";
    Stage stage("rendering " + p.scene.file.filename().string() + " with " + backendName);
    // A PNG is for looking at: the float beauty, scaled as run's report images are where more
    // than 1% of the scene would clip (bright glTF lights wash out every object and shadow); the
    // object ids say which pixels are the scene's.
    const bool png = ext == ".png";
    const scene::Frame frame =
        studies::renderForOutput(p.scene, p.plan, p.settings, o.backend,
                                 png ? scene::kChannelBeauty | scene::kChannelObjectId : scene::kAllChannels);
    const double exposure = png ? scene::displayExposure(frame) : 1.0;
    if (png)
        scene::writePngLinear(o.output, frame.width, frame.height, frame.beauty, exposure);
    else
        scene::writeFrame(frame, o.output);
    stage.done(std::to_string(frame.width) + "x" + std::to_string(frame.height) + " -> " + o.output.string() +
               (exposure != 1.0 ? ", scaled by " + compare::formatShort(exposure) +
                                      " for display (unscaled, over 1% of the scene would be white)"
                                : "") +
               ", " + memoryLine(estimate));
    if (o.common.json) {
        Json j = {{"backend", backendName},
                  {"output", o.output.string()},
                  {"timings_ms", studies::timingsJson(frame)},
                  {"attributes", frame.attributes},
                  {"memory", studies::memoryJson(estimate)}};
        if (png) j["display_exposure"] = exposure;
        std::cout << j.dump(2) << "\n";
    }
    return 0;
}

namespace {

// A mask read upside down (row 0 at the bottom, as a GL read-back gives it) or with 1 = shadowed
// is wrong nearly everywhere; said as such rather than only as a large false shadow. Empty when
// neither reading is much closer: under half the error, where the error is over 20%.
std::string maskReadingHint(const scene::ShadowMask& mask, const scene::Frame& reference, const fs::path& file,
                            double mismatchRate, bool invertGiven) {
    if (!(mismatchRate > 0.2)) return {};
    struct Reading {
        bool flip, invert;
        const char* what;
    };
    std::string best;
    double bestRate = 0.5 * mismatchRate;
    // The mask as read has --mask-invert applied already: inverting it again means dropping the flag.
    const char* inverted = invertGiven ? "without --mask-invert (1 = lit)" : "inverted (1 = shadowed: --mask-invert)";
    const std::string flippedInverted = std::string("flipped vertically and ") + inverted;
    for (const Reading& r : {Reading{true, false, "flipped vertically (row 0 at the bottom, as glReadPixels gives it)"},
                             Reading{false, true, inverted}, Reading{true, true, flippedInverted.c_str()}}) {
        scene::ShadowMask m = mask;
        for (int y = 0; r.flip && y < m.height / 2; ++y)
            std::swap_ranges(m.visibility.begin() + std::ptrdiff_t(y) * m.width,
                             m.visibility.begin() + std::ptrdiff_t(y + 1) * m.width,
                             m.visibility.begin() + std::ptrdiff_t(m.height - 1 - y) * m.width);
        if (r.invert)
            for (float& v : m.visibility) v = 1.0f - v;
        const double rate =
            compare::compareFrames(scene::frameFromMask(m, reference, file), reference).metrics.mismatchRate;
        if (rate < bestRate) {
            bestRate = rate;
            best = std::string("read ") + r.what + ", this mask would be " + compare::formatPercent(rate) +
                   " wrong instead of " + compare::formatPercent(mismatchRate);
        }
    }
    return best;
}

}  // namespace

int compareFiles(const CompareOptions& o) {
    if (o.output.extension() != ".png")
        throw scene::InputError(o.output.string() + ": the difference image must be a .png");
    if (o.heat && o.heat->extension() != ".png")
        throw scene::InputError(o.heat->string() + ": the heat map must be a .png");
    // Both outputs checked before anything is read or written, so that one cannot be written
    // and the other refused.
    checkOutputFile(o.output, "-o");
    if (o.heat) {
        checkOutputFile(*o.heat, "--heat");
        std::error_code ec;
        if (fs::weakly_canonical(fs::absolute(*o.heat), ec) == fs::weakly_canonical(fs::absolute(o.output), ec))
            throw scene::InputError("--heat " + o.heat->string() + ": names the same file as -o");
    }
    const scene::Budgets budgets = parseBudgets(o.budgets);
    // Only an EXR can be a Frame: any other file is read as a mask, which names the formats it takes.
    const bool maskOnly = o.maskChannel || o.maskInvert || o.maskSrgb ||
                          scene::lowercaseExtension(o.method) != ".exr" || scene::looksLikeMask(o.method);
    if (maskOnly && budgets[scene::BudgetKind::MaxBleeding])
        throw scene::InputError(o.method.string() +
                                ": --max-bleeding: a shadow mask records no bias or texel size, so light bleeding "
                                "cannot be told from bias leaks (use --max-missed-shadow)");
    const scene::Frame reference = readingInput(o.reference.string(), [&] { return scene::readFrame(o.reference); });
    std::optional<scene::ShadowMask> mask;
    if (maskOnly)
        mask = scene::readShadowMask(o.method,
                                     {o.maskChannel, o.maskInvert, o.maskSrgb, reference.width, reference.height});
    const scene::Frame method = mask ? scene::frameFromMask(*mask, reference, o.method)
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
    const CreatedFolders folders(o.output);
    scene::writePngDisplay(o.output, c.width, c.height, c.diffRgb);
    if (o.heat) {
        const CreatedFolders heatFolders(*o.heat);
        scene::writePngDisplay(*o.heat, c.width, c.height, c.heatRgb);
    }
    const std::string hint =
        mask ? maskReadingHint(*mask, reference, o.method, c.metrics.mismatchRate, o.maskInvert) : "";
    if (o.json) {
        Json j = compare::toJson(c.metrics);
        if (!checks.empty()) j["budgets"] = compare::toJson(checks);
        if (mask) j["mask_hint"] = hint.empty() ? Json(nullptr) : Json(hint);
        std::cout << j.dump(2) << "\n";
    } else {
        std::cout << compare::summaryLine(c.metrics) << "\n";
    }
    if (!hint.empty()) std::cerr << "shadowlab: hint: " << o.method.string() << ": " << hint << "\n";
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
    studies::RunStudyOptions options;
    options.outputDir = o.outputDir;
    options.raster = !o.skipRaster;
    options.sweep = !o.skipSweep;
    options.budgets = parseBudgets(o.budgets);
    options.user = o.common.settings;
    const Prepared p = prepare(o.common);
    RunPrinter printer;
    options.progress = &printer;
    const studies::RunStudyResult r = studies::runStudy(p.scene, p.settings, p.plan, options);
    std::cerr << "shadowlab: wrote " << (o.outputDir / "report.html").string() << "; " << memoryLine(r.memoryEstimate)
              << "\n";
    if (o.common.json) std::cout << r.metrics.dump(2) << "\n";
    // A failure (1) says more than a broken budget: a method that did not render measured nothing.
    return r.backendFailed ? 1 : r.budgetBroken ? kExitBudgetBroken : 0;
}

namespace {

// One shard of a sweep: its rows only, into DIR/shard-K-of-N; the report comes from `merge`.
int sweepShard(const SweepOptions& o, const scene::Scene& scene, const studies::SweepGrid& grid,
               const studies::SweepOptions& options) {
    const studies::Shard shard = studies::parseShard(*o.shard);
    const std::size_t mine = studies::shardGrid(grid, shard).configs.size();
    const fs::path dir = o.outputDir / studies::shardFolderName(shard);
    // One writer per shard folder: the same shard started twice would duplicate its journal's keys.
    fs::create_directories(dir);
    const scene::FolderLock lock(dir, "sweep --shard");
    std::cerr << "shadowlab: sweep shard " << shard.index << "/" << shard.count << ": " << mine << " of "
              << studies::gridKeys(grid).size() << " configurations, " << grid.repetitions
              << " timed frames each, into " << dir.string() << "\n";
    studies::SharedReferenceOptions ref;
    ref.log = [](const std::string& line) { std::cerr << "shadowlab: " << line << "\n"; };
    const studies::SweepResult result = studies::runShard(scene, grid, shard, options, ref);
    std::size_t failed = 0;
    for (const auto& r : result.rows) failed += r.error.empty() ? 0 : 1;
    std::cerr << "shadowlab: wrote " << dir.string() << " (" << result.rows.size() << " rows"
              << (failed ? ", " + std::to_string(failed) + " failed" : "")
              << "); when every shard is done: shadowlab merge " << o.outputDir.string() << "\n";
    if (o.common.json) std::cout << studies::rowsToJson(result.rows).dump(2) << "\n";
    return failed ? 1 : 0;
}

}  // namespace

namespace {

// `merge` of check shards: the junit.xml, summary.md and cases/ of the unsharded check, and its exit code.
int mergeCheck(const MergeOptions& o) {
    const studies::MergedCheck merged = studies::readCheckShards(o.inputs);
    fs::path out;
    if (o.outputDir)
        out = *o.outputDir;
    else if (o.inputs.size() == 1 && !fs::exists(o.inputs.front() / "shard.json"))
        out = o.inputs.front();
    else
        throw scene::InputError("merge: give the merged folder with -o (the inputs are " +
                                std::string(o.inputs.size() == 1 ? "a shard folder" : "several folders") + ")");
    studies::writeMergedCheck(merged, out);
    std::size_t failed = 0, errors = 0;
    for (const studies::CasePart& p : merged.parts) {
        failed += p.verdict == studies::CaseVerdict::Failed ? 1 : 0;
        errors += p.verdict == studies::CaseVerdict::Error ? 1 : 0;
    }
    std::cerr << "shadowlab: merged " << merged.shardDirs.size() << " check shards of " << merged.identity.suiteName
              << ": " << merged.parts.size() - failed - errors << " passed, " << failed << " failed, " << errors
              << " errors; wrote " << (out / "junit.xml").string() << ", summary.md, summary.html, cases/\n";
    return errors ? 1 : failed ? kExitBudgetBroken : 0;
}

}  // namespace

namespace {

void printPathSummary(const studies::PathResult& result) {
    for (const studies::PathMethod& m : result.methods)
        std::cerr << "shadowlab: " << m.name << ": mean flicker " << compare::formatPercent(m.temporal.meanFlickerRate)
                  << " (" << m.temporal.totalFlicker << " px over " << m.temporal.pairs.size() << " pairs), swim "
                  << compare::formatFixed(m.temporal.meanSwimPixels, 3) << " px, edge offset "
                  << compare::formatFixed(m.temporal.meanEdgeOffset, 3) << " px\n";
}

// `merge` of path shards: the frames, metrics.json and report of the unsharded path.
int mergePath(const MergeOptions& o) {
    fs::path out;
    if (o.outputDir)
        out = *o.outputDir;
    else if (o.inputs.size() == 1 && !fs::exists(o.inputs.front() / "shard.json"))
        out = o.inputs.front();
    else
        throw scene::InputError("merge: give the merged folder with -o (the inputs are " +
                                std::string(o.inputs.size() == 1 ? "a shard folder" : "several folders") + ")");
    const studies::MergedPath merged = studies::mergePathShards(o.inputs, out);
    std::cerr << "shadowlab: merged " << merged.shardCount << " path shards (" << merged.shardDirs.size()
              << " folders, " << merged.result.frames << " frames"
              << (merged.duplicates ? ", " + std::to_string(merged.duplicates) + " duplicate frames merged once" : "")
              << ")\n";
    printPathSummary(merged.result);
    std::cerr << "shadowlab: wrote " << (out / "report.html").string() << " and metrics.json\n";
    if (o.json) std::cout << studies::toJson(merged.result).dump(2) << "\n";
    return 0;
}

}  // namespace

int merge(const MergeOptions& o) {
    if (studies::holdsCheckShards(o.inputs)) return mergeCheck(o);
    if (studies::holdsPathShards(o.inputs)) return mergePath(o);
    const studies::MergedSweep merged = studies::readShards(o.inputs);
    fs::path out;
    if (o.outputDir) {
        out = *o.outputDir;
    } else if (o.inputs.size() == 1 && !fs::exists(o.inputs.front() / "shard.json")) {
        out = o.inputs.front();
    } else {
        throw scene::InputError("merge: give the merged folder with -o (the inputs are " +
                                std::string(o.inputs.size() == 1 ? "a shard folder" : "several folders") + ")");
    }
    studies::writeMerged(merged, out);
    studies::writeSweepReport(out, studies::mergedReportInput(merged, out));
    std::size_t failed = 0;
    std::set<std::string> machines;
    for (const auto& r : merged.rows) {
        failed += r.error.empty() ? 0 : 1;
        machines.insert(studies::machineFromJson(r.machine).id());
    }
    std::cerr << "shadowlab: merged " << merged.shardCount << " shards (" << merged.shardDirs.size() << " folders, "
              << merged.rows.size() << " rows" << (failed ? ", " + std::to_string(failed) + " failed" : "")
              << (merged.duplicates ? ", " + std::to_string(merged.duplicates) + " duplicate rows merged once" : "")
              << (machines.size() > 1 ? ", timed on " + std::to_string(machines.size()) + " machines" : "")
              << "): wrote " << (out / "report.html").string() << ", results.csv and results.json\n";
    if (o.json) std::cout << studies::rowsToJson(merged.rows).dump(2) << "\n";
    return failed ? 1 : 0;
}

int sweep(const SweepOptions& o) {
    checkOutputFolder(o.outputDir);
    const Prepared p = prepare(o.common);
    studies::SweepGrid grid = o.grid
                                  ? readingInput(o.grid->string(), [&] { return studies::loadGrid(*o.grid, p.scene); })
                                  : studies::defaultGrid(p.scene, o.quick);
    if (o.repetitions) grid.repetitions = *o.repetitions;
    if (o.common.resolution) grid.resolution = o.common.resolution;
    if (o.flicker || o.flickerFrames) {
        studies::PathSpec path = grid.flicker.value_or(studies::defaultFlickerPath());
        // Given without a value, CLI11 reports the flag as "true": the default kind.
        if (o.flicker && !o.flicker->empty() && *o.flicker != "true") path.kind = studies::parsePathKind(*o.flicker);
        if (o.flickerFrames) path.frames = *o.flickerFrames;
        studies::flickerScenes(studies::sweepScene(p.scene, grid),
                               path);  // a bad path fails before anything is written
        grid.flicker = path;
    }
    // Settings given on the command line apply to every configuration that does not vary them.
    const scene::SettingsOverrides& base = o.common.settings;
    for (studies::SweepConfig& c : grid.configs) {
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

    studies::SweepOptions options;
    options.outputDir = o.outputDir;
    options.resume = o.resume;
    options.progress = sweepProgressPrinter();
    // Row after row: the heap one renderer frees serves the next while the largest still fits.
    const studies::JobMemory memory = studies::estimateSweepMemory(p.scene, grid, o.common.settings);
    const scene::FreedHeapBudget heapBudget(memory.total, memory.largestRenderer);
    // Shards share the output folder; each holds the lock of its own shard folder.
    if (o.shard) return sweepShard(o, p.scene, grid, options);
    // One writer per folder: two sweeps appending to one journal would duplicate its keys.
    fs::create_directories(o.outputDir);
    const scene::FolderLock lock(o.outputDir, "sweep");
    std::cerr << "shadowlab: sweep of " << grid.configs.size() << " configurations, " << grid.repetitions
              << " timed frames each, into " << o.outputDir.string() << "\n";
    const studies::SweepResult result = studies::runSweep(p.scene, grid, options);
    studies::SweepReportInput input =
        studies::makeSweepReportInput(p.scene.file.stem().string(), p.scene.file.string(), result);
    {
        // The recommendation is searched and checked at the sweep's resolution, in the settings
        // given on the command line (the grid's own rows vary them; the user runs these).
        scene::Scene at = p.scene;
        at.camera.width = result.reference.width;
        at.camera.height = result.reference.height;
        studies::RecommendOptions ro;
        ro.user = o.common.settings;
        ro.raster = std::any_of(grid.configs.begin(), grid.configs.end(),
                                [](const studies::SweepConfig& c) { return c.backend == scene::Backend::Raster; });
        ro.raytrace = std::any_of(grid.configs.begin(), grid.configs.end(),
                                  [](const studies::SweepConfig& c) { return c.backend == scene::Backend::Raytrace; });
        Stage rec("recommended shadow block: biases searched in this configuration");
        input.recommendation =
            studies::recommendShadow(at, result.reference, at, result.reference, nullptr, nullptr,
                                     studies::rayCandidateOf(studies::recommendBias(result.rows)), ro);
        rec.done();
        for (const std::string& note : input.recommendation->notes) std::cerr << "shadowlab: " << note << "\n";
    }
    studies::writeSweepReport(o.outputDir, input);
    std::size_t failed = 0;
    for (const auto& r : result.rows) failed += r.error.empty() ? 0 : 1;
    std::cerr << "shadowlab: wrote " << (o.outputDir / "report.html").string() << ", results.csv and results.json ("
              << result.rows.size() << " rows" << (failed ? ", " + std::to_string(failed) + " failed" : "") << ")\n";
    if (o.common.json) std::cout << studies::rowsToJson(result.rows).dump(2) << "\n";
    return failed ? 1 : 0;
}

int check(const CheckOptions& o) {
    // The suite, every scene it names and the baseline are read and checked before anything runs.
    const studies::CheckSuite fullSuite = studies::loadSuite(o.suite);
    studies::CheckSuite suite = fullSuite;
    const std::optional<fs::path> baselineFile = o.baseline ? o.baseline : suite.baseline;
    if (o.updateBaseline && !baselineFile)
        throw scene::InputError(o.suite.string() +
                                ": --update-baseline: the suite names no \"baseline\" file and "
                                "--baseline gives none");
    std::optional<studies::Baseline> baseline;
    if (baselineFile && !o.updateBaseline) {
        if (!fs::exists(*baselineFile))
            throw scene::InputError(baselineFile->string() + ": no such baseline (write one with --update-baseline)");
        baseline = studies::loadBaseline(*baselineFile);
    }
    std::optional<studies::Shard> shard;
    studies::CheckShardManifest manifest;
    if (o.shard) {
        shard = studies::parseShard(*o.shard);
        // N shards writing one baseline would race; a baseline comes from an unsharded run.
        if (o.updateBaseline)
            throw scene::InputError(
                "check --shard: --update-baseline is not sharded; update the baseline with an "
                "unsharded `check`");
        manifest.version = SHADOWLAB_VERSION;
        manifest.suite = o.suite.string();
        manifest.suiteName = suite.name;
        manifest.suiteHash = studies::fileHash(o.suite);
        manifest.baselineHash = baseline ? studies::fileHash(*baselineFile) : "none";
        manifest.shard = *shard;
        for (const auto& c : fullSuite.cases) manifest.suiteCases.push_back(c.name);
        suite = studies::shardSuite(fullSuite, *shard);
        for (const auto& c : suite.cases) manifest.cases.push_back(c.name);
        std::cerr << "shadowlab: check shard " << shard->index << "/" << shard->count << ": " << suite.cases.size()
                  << " of " << fullSuite.cases.size() << " cases\n";
    }
    // The output folder is replaced as a whole once every case has run: refused now, before any
    // work, when that would take the user's own files or inputs with it.
    std::vector<fs::path> inputs = {o.suite};
    if (baselineFile) inputs.push_back(*baselineFile);
    for (const auto& c : fullSuite.cases) inputs.push_back(c.sceneFile);
    if (shard) {
        checkOutputFolder(o.outputDir);
        checkReplacedFolder(o.outputDir / studies::shardFolderName(*shard), inputs, "shard.json",
                            "\"check_suite_hash\"");
    } else {
        checkReplacedFolder(o.outputDir, inputs, "junit.xml", "<testsuites name=\"shadowlab check\"");
    }
    if (o.updateBaseline) checkOutputFile(*baselineFile, "--update-baseline");
    std::cerr << "shadowlab: check " << suite.name << ": " << suite.cases.size() << " cases"
              << (baseline ? " against " + baselineFile->string() : std::string(" without a baseline")) << "\n";
    const auto results =
        studies::runSuite(suite, baseline ? &*baseline : nullptr, [&](std::size_t done, const studies::CaseResult& r) {
            std::string what = r.verdict == studies::CaseVerdict::Error ? "ERROR: " + r.error
                               : r.metrics                              ? compare::summaryLine(*r.metrics)
                                                                        : "";
            if (r.verdict == studies::CaseVerdict::Failed) what = "FAILED: " + r.failures.front() + "; " + what;
            std::cerr << "shadowlab: check [" << done << "/" << suite.cases.size() << "] " << r.name << ": " << what
                      << "\n";
        });

    // Everything goes to a fresh folder that replaces DIR in one step: no file of an earlier run
    // (a difference image of a case that failed then) survives next to this run's.
    const fs::path dir = shard ? o.outputDir / studies::shardFolderName(*shard) : o.outputDir;
    if (dir.has_parent_path()) fs::create_directories(dir.parent_path());
    // Not beside a shard: the shared folder may hold other machines' live temporaries, whose
    // writers this host cannot see.
    if (!shard) scene::removeStaleTemporaries(dir.has_parent_path() ? dir.parent_path() : fs::path("."));
    const fs::path tmp = scene::temporarySibling(dir);
    fs::create_directories(tmp / "cases");
    std::size_t failed = 0, errors = 0;
    for (std::size_t i = 0; i < results.size(); ++i) {
        const studies::CaseResult& r = results[i];
        failed += r.verdict == studies::CaseVerdict::Failed ? 1 : 0;
        errors += r.verdict == studies::CaseVerdict::Error ? 1 : 0;
        scene::writeTextAtomic(tmp / "cases" / (r.name + ".json"), studies::caseJson(suite.cases[i], r).dump(2) + "\n");
        if (!r.diffRgb.empty())
            scene::writePngDisplay(tmp / "cases" / (r.name + "-diff.png"), r.width, r.height, r.diffRgb);
    }
    scene::writeTextAtomic(tmp / "junit.xml", studies::junitXml(suite, results));
    scene::writeTextAtomic(tmp / "summary.md", studies::markdownSummary(suite, results, o.updateBaseline));
    std::set<std::string> withDiff;
    for (const studies::CaseResult& r : results)
        if (!r.diffRgb.empty()) withDiff.insert(r.name);
    scene::writeTextAtomic(tmp / "summary.html", studies::htmlSummary(suite.name, studies::caseParts(suite, results),
                                                                      o.updateBaseline, withDiff));
    if (shard) {
        nlohmann::json parts = nlohmann::json::array();
        for (const studies::CasePart& part : studies::caseParts(suite, results)) parts.push_back(studies::toJson(part));
        scene::writeTextAtomic(tmp / "shard-parts.json", parts.dump(1) + "\n");
        scene::writeTextAtomic(tmp / "shard.json", studies::toJson(manifest).dump(1) + "\n");
    }
    scene::replaceDirectory(tmp, dir);
    if (o.updateBaseline) {
        // Cases that could not render keep their old entry; cases no longer in the suite go.
        studies::Baseline old, next;
        try {
            if (fs::exists(*baselineFile)) old = studies::loadBaseline(*baselineFile);
        } catch (const scene::SceneError&) {
            // A damaged baseline is being replaced.
        } catch (const scene::InputError&) {
            // So is one that cannot be read as a file (its writability was checked before the cases).
        }
        for (const studies::CaseResult& r : results) {
            if (r.metrics)
                next[r.name] = studies::baselineEntry(*r.metrics);
            else if (old.count(r.name))
                next[r.name] = old[r.name];
        }
        scene::writeTextAtomic(*baselineFile, studies::baselineJson(suite.name, next).dump(2) + "\n");
        std::cerr << "shadowlab: wrote the baseline " << baselineFile->string() << "\n";
    }
    std::cerr << "shadowlab: check " << suite.name << ": " << results.size() - failed - errors << " passed, " << failed
              << " failed, " << errors << " errors; wrote " << (dir / "junit.xml").string()
              << ", summary.md, summary.html, cases/\n";
    return errors ? 1 : failed ? kExitBudgetBroken : 0;
}

int path(const PathCommandOptions& o) {
    const Prepared p = prepare(o.common);
    // The command line's path replaces the scene's "path" block when it names a kind; otherwise the
    // block is used, with --frames, --amount and --light over its values.
    studies::PathSpec spec;
    const bool cliKind = o.kind || o.cameraAnimation;
    if (!cliKind && p.scene.path) spec = studies::pathSpecOf(*p.scene.path);
    if (o.kind) spec.kind = studies::parsePathKind(*o.kind);
    if (o.cameraAnimation) {
        if (o.kind && spec.kind != studies::PathKind::GltfAnimation)
            throw scene::InputError("--camera-animation: follows a glTF animation; it cannot go with --kind " +
                                    *o.kind);
        spec.kind = studies::PathKind::GltfAnimation;
        // Given without a value, CLI11 reports the flag as "true": the first animation.
        spec.animation = *o.cameraAnimation == "true" ? std::string() : *o.cameraAnimation;
    }
    if (o.frames) spec.frames = *o.frames;
    if (o.amount) spec.amount = o.amount;
    if (o.light) spec.light = *o.light;
    studies::pathScenes(p.scene, p.settings, spec);  // bad paths fail before anything is written
    studies::PathRunOptions options;
    options.outputDir = o.outputDir;
    options.resume = o.resume;
    options.raster = !o.skipRaster;
    options.raytrace = !o.skipRaytrace;
    options.heldView = !o.noHeldView;
    options.progress = [](const std::string& line) { std::cerr << "shadowlab: path " << line << "\n"; };
    const std::string kind = studies::toString(spec.kind);
    if (o.shard) {
        const studies::Shard shard = studies::parseShard(*o.shard);
        options.shardIndex = shard.index;
        options.shardCount = shard.count;
        const fs::path dir = o.outputDir / studies::shardFolderName(shard);
        fs::create_directories(dir);
        const scene::FolderLock lock(dir, "path --shard");
        std::cerr << "shadowlab: " << kind << " path shard " << shard.index << "/" << shard.count << ": "
                  << studies::pathShardFrames(spec.frames, shard.index, shard.count).size() << " of " << spec.frames
                  << " frames into " << dir.string() << "\n";
        const studies::PathResult result = studies::runPath(p.scene, p.settings, spec, options);
        std::cerr << "shadowlab: wrote " << dir.string() << " (" << result.resumedFrames
                  << " frames resumed); when every "
                  << "shard is done: shadowlab merge " << o.outputDir.string() << "\n";
        return 0;
    }
    std::cerr << "shadowlab: " << kind << " path of " << spec.frames << " frames into " << o.outputDir.string() << "\n";
    const studies::PathResult result = studies::runPath(p.scene, p.settings, spec, options);
    printPathSummary(result);
    std::cerr << "shadowlab: wrote " << (o.outputDir / "report.html").string() << " and metrics.json\n";
    if (o.common.json) std::cout << studies::toJson(result).dump(2) << "\n";
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

    studies::StabilityOptions options;
    options.width = probe.camera.width;
    options.height = probe.camera.height;
    options.shadowMapSize = o.shadowMapSize;
    options.search = !o.noSearch;
    options.quick = !o.fullGrid;
    options.validate = o.validate;

    std::vector<studies::StabilityCase> cases;
    for (std::size_t i = 0; i < scenes.size(); ++i) {
        const std::string name = files[i].stem().string();
        Stage stage("stability case " + std::to_string(i + 1) + "/" + std::to_string(scenes.size()) + " " + name);
        cases.push_back(studies::runStabilityCase(scenes[i], options, name, studies::readDescription(files[i])));
        // The reference's verdict and each backend's state, not one PASS that hides acne.
        const studies::StabilityCase& c = cases.back();
        std::string note =
            std::string(c.failed() ? "FAILED to run cleanly; " : "") + "reference " + c.referenceVerdict();
        for (const scene::Backend backend : {scene::Backend::Raster, scene::Backend::Raytrace})
            for (const char* variant : {"defaults", "best"})
                if (const studies::BackendRun* r = c.run(backend, variant))
                    note += std::string("; ") + scene::toString(backend) + " at " + variant + ": " +
                            studies::stateOf(r, std::string(variant) == "best").text;
        stage.done(note);
    }
    studies::writeStabilityReport(o.outputDir, cases);
    std::cerr << "shadowlab: wrote " << (o.outputDir / "stability.html").string() << "\n";
    if (o.json) {
        Json all = Json::array();
        for (const auto& c : cases) all.push_back(studies::toJson(c));
        std::cout << all.dump(2) << "\n";
    }
    if (!studies::suitePassed(cases)) {
        std::cerr << "shadowlab: stability: at least one case failed (see the report)\n";
        return 1;
    }
    return 0;
}

}  // namespace shadowlab::app
