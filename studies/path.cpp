// studies/path.cpp: the path study's frames (camera and light paths), the render loop with one
// Renderer and one acceleration structure per backend, the journal and resume, and the outputs:
// metrics.json, the flicker plot, the animations (OpenImageIO's GIF writer) and report.html.
#include "studies/path.h"

#include <fcntl.h>
#include <unistd.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <fstream>
#include <map>
#include <set>
#include <sstream>

#include <OpenImageIO/imageio.h>

#include "compare/svg_plot.h"
#include "compare/text.h"
#include "raster/light_frustum.h"
#include "scene/append_line.h"
#include "scene/camera.h"
#include "scene/camera_animation.h"
#include "scene/error.h"
#include "scene/frame_io.h"
#include "scene/json_input.h"
#include "scene/render_plan.h"
#include "studies/backend.h"
#include "studies/shard.h"

namespace shadowlab::studies {

namespace {

namespace fs = std::filesystem;
using Json = nlohmann::json;
constexpr double kPi = 3.14159265358979323846;

// v turned by `degrees` about the unit axis `k` (Rodrigues).
scene::Vec3 rotate(const scene::Vec3& v, const scene::Vec3& k, double degrees) {
    const double a = degrees * kPi / 180.0, c = std::cos(a), s = std::sin(a);
    return v * c + glm::cross(k, v) * s + k * glm::dot(k, v) * (1.0 - c);
}

// A frame's time without its one-time setup: what a frame costs once the renderer exists.
double frameMs(const scene::Frame& f) { return f.totalTimeMs() - f.timing("setup"); }

using scene::appendLine;  // a finished line survives a kill or a power loss

// A method's name in frame files, the journal, path.json, metrics.json and the report: its
// backend's name, and for the raster backend's held view that name with "-held".
std::string nameOf(scene::Backend b) { return scene::toString(b); }
std::string heldViewName() { return nameOf(scene::Backend::Raster) + "-held"; }

std::string frameName(int t, const std::string& what) {
    char buf[32];
    std::snprintf(buf, sizeof buf, "%04d-", t);
    return std::string(buf) + what + ".exr";
}

// The display-encoded sRGB of a linear beauty (3 floats a pixel).
std::vector<float> displayBeauty(const scene::Frame& f) {
    std::vector<float> out(f.beauty.size());
    for (std::size_t i = 0; i < f.beauty.size(); ++i) out[i] = scene::linearToSrgb(f.beauty[i]);
    return out;
}

// Panels side by side with a 2-pixel dark gap, as 8-bit RGB.
std::vector<unsigned char> sideBySide(const std::vector<const std::vector<float>*>& panels, int w, int h, int& outW) {
    const int gap = 2;
    outW = int(panels.size()) * w + (int(panels.size()) - 1) * gap;
    std::vector<unsigned char> px(std::size_t(outW) * h * 3, 20);
    for (std::size_t p = 0; p < panels.size(); ++p)
        for (int y = 0; y < h; ++y)
            for (int x = 0; x < w; ++x)
                for (int c = 0; c < 3; ++c) {
                    const float v = (*panels[p])[(std::size_t(y) * w + x) * 3 + c];
                    px[(std::size_t(y) * outW + std::size_t(p) * (w + gap) + x) * 3 + c] =
                        (unsigned char)std::lround(std::clamp(v, 0.0f, 1.0f) * 255.0f);
                }
    return px;
}

// An animated GIF (OpenImageIO writes each subimage as one frame), written to a temporary name
// and renamed into place.
void writeGif(const fs::path& file, int w, int h, const std::vector<std::vector<unsigned char>>& frames, int fps) {
    const fs::path tmp = scene::temporarySibling(file);
    try {
        auto out = OIIO::ImageOutput::create(tmp.string());
        if (!out) throw std::runtime_error(file.string() + ": no GIF writer (" + OIIO::geterror() + ")");
        if (!out->supports("multiimage")) throw std::runtime_error(file.string() + ": the GIF writer has no animation");
        OIIO::ImageSpec spec(w, h, 3, OIIO::TypeDesc::UINT8);
        const int rate[2] = {fps, 1};
        spec.attribute("FramesPerSecond", OIIO::TypeRational, rate);
        spec.attribute("oiio:LoopCount", 0);  // forever
        std::vector<OIIO::ImageSpec> specs(frames.size(), spec);
        if (!out->open(tmp.string(), int(specs.size()), specs.data()))
            throw std::runtime_error(file.string() + ": " + out->geterror());
        for (std::size_t i = 0; i < frames.size(); ++i) {
            if (i > 0 && !out->open(tmp.string(), spec, OIIO::ImageOutput::AppendSubimage))
                throw std::runtime_error(file.string() + ": " + out->geterror());
            if (!out->write_image(OIIO::TypeDesc::UINT8, frames[i].data()))
                throw std::runtime_error(file.string() + ": " + out->geterror());
        }
        if (!out->close()) throw std::runtime_error(file.string() + ": " + out->geterror());
        fs::rename(tmp, file);
    } catch (...) {
        std::error_code ignored;
        fs::remove(tmp, ignored);
        throw;
    }
}

Json manifestOf(const scene::Scene& base, const PathSpec& spec, double amount, const PathRunOptions& o,
                const scene::RenderSettings& s) {
    const scene::RasterSettings& r = s.raster;
    return {{"scene", base.file.string()},
            {"resolution", {base.camera.width, base.camera.height}},
            {"kind", toString(spec.kind)},
            {"frames", spec.frames},
            {"amount", amount},
            {"light", spec.light},
            {"animation", spec.kind == PathKind::GltfAnimation ? Json(spec.animation) : Json(nullptr)},
            {nameOf(scene::Backend::Raster), o.raster},
            {nameOf(scene::Backend::Raytrace), o.raytrace},
            {"held_view", o.heldView},
            {"settings",
             // "auto": nobody chose a size, so each view gets the one its receivers need (at most
             // the default; raster/light_frustum.h); every frame's EXR holds the size it used.
             {{"shadow_map_size", r.shadowMapSizeIsDefault && r.shadowMapSize == scene::kDefaultShadowMapSize
                                      ? Json("auto")
                                      : Json(r.shadowMapSize)},
              {"filter", scene::toString(r.filter)},
              {"pcf_size", r.pcfSize},
              {"depth_bias", r.depthBias},
              {"slope_bias", r.slopeBias},
              {"normal_offset", r.normalOffset},
              {"fit_light_frustum", r.fitLightFrustum},
              {"snap_light_frustum", r.snapLightFrustum},
              {"cascades", r.cascades},
              {"cascade_blend", r.cascadeBlend},
              {"receiver_plane_bias", r.receiverPlaneBias},
              {"hardware_bias", r.hardwareBias},
              {"ray_bias", s.raytrace.robustOffset ? Json("robust") : Json(s.raytrace.rayBias)},
              {"precision", scene::toString(s.raytrace.precision)},
              {"samples", s.raytrace.samples}}}};
}

double median(std::vector<double> v) {
    if (v.empty()) return 0.0;
    std::sort(v.begin(), v.end());
    const std::size_t n = v.size();
    return n % 2 ? v[n / 2] : 0.5 * (v[n / 2 - 1] + v[n / 2]);
}

// The square window (side `size`) holding the most set pixels of `mask` (a summed-area table).
compare::ErrorHotspot densestWindow(const std::vector<unsigned char>& mask, int w, int h, int size) {
    compare::ErrorHotspot best;
    size = std::max(1, std::min({size, w, h}));
    best.size = size;
    std::vector<std::size_t> sat(std::size_t(w + 1) * (h + 1), 0);
    for (int y = 0; y < h; ++y)
        for (int x = 0; x < w; ++x)
            sat[std::size_t(y + 1) * (w + 1) + x + 1] =
                mask[std::size_t(y) * w + x] + sat[std::size_t(y) * (w + 1) + x + 1] +
                sat[std::size_t(y + 1) * (w + 1) + x] - sat[std::size_t(y) * (w + 1) + x];
    for (int y = 0; y + size <= h; ++y)
        for (int x = 0; x + size <= w; ++x) {
            const auto at = [&](int xx, int yy) { return sat[std::size_t(yy) * (w + 1) + xx]; };
            const std::size_t n = at(x + size, y + size) - at(x, y + size) - at(x + size, y) + at(x, y);
            if (n > best.wrongPixels) {
                best.wrongPixels = n;
                best.x = x;
                best.y = y;
            }
        }
    return best;
}

struct Loaded {
    std::vector<scene::Frame> frames;
};

}  // namespace

const char* toString(PathKind kind) {
    switch (kind) {
        case PathKind::Orbit: return "orbit";
        case PathKind::Dolly: return "dolly";
        case PathKind::Pan: return "pan";
        case PathKind::SubTexel: return "subtexel";
        case PathKind::SunAzimuth: return "sun-azimuth";
        case PathKind::SunElevation: return "sun-elevation";
        case PathKind::LightMove: return "light-move";
        case PathKind::GltfAnimation: return "gltf-animation";
    }
    return "?";
}

PathKind parsePathKind(const std::string& text) {
    for (PathKind k : {PathKind::Orbit, PathKind::Dolly, PathKind::Pan, PathKind::SubTexel, PathKind::SunAzimuth,
                       PathKind::SunElevation, PathKind::LightMove, PathKind::GltfAnimation})
        if (text == toString(k)) return k;
    throw scene::InputError(
        "--kind: expected orbit|dolly|pan|subtexel|sun-azimuth|sun-elevation|light-move|gltf-animation, got '" + text +
        "'");
}

bool isCameraPath(PathKind kind) {
    return kind == PathKind::Orbit || kind == PathKind::Dolly || kind == PathKind::Pan || kind == PathKind::SubTexel ||
           kind == PathKind::GltfAnimation;
}

PathSpec pathSpecOf(const scene::PathBlock& block) {
    PathSpec spec;
    spec.kind = parsePathKind(block.kind);
    if (block.frames) spec.frames = *block.frames;
    spec.amount = block.amount;
    spec.light = block.light.value_or(0);
    spec.animation = block.animation.value_or("");
    return spec;
}

double defaultAmount(PathKind kind) {
    switch (kind) {
        case PathKind::Orbit: return 20.0;
        case PathKind::Dolly: return 0.3;
        case PathKind::Pan: return 0.1;
        case PathKind::SubTexel: return 0.1;
        case PathKind::SunAzimuth: return 20.0;
        case PathKind::SunElevation: return 10.0;
        case PathKind::LightMove: return 0.1;
        case PathKind::GltfAnimation: return 0.0;  // the keys set the motion
    }
    return 0.0;
}

SubTexelStep subTexelStep(const scene::Scene& scene, const scene::RasterSettings& settings, double amount) {
    SubTexelStep s;
    const scene::CameraBasis cam = scene::cameraBasis(scene.camera);
    const double distance = glm::length(scene.camera.lookAt - scene.camera.position);
    s.pixel = 2.0 * distance * cam.tanHalfFovY / cam.height;
    // The texel of the first directional light's map as the raster backend makes it (fitted or
    // the bounding sphere's), at the size it would choose; without one, the pixel alone.
    s.texel = s.pixel;
    const int size = raster::chooseShadowMapSize(scene, settings).size;
    for (const scene::Light& l : scene.lights)
        if (l.type == scene::LightType::Directional) {
            const raster::LightFrustum f =
                settings.fitLightFrustum
                    ? raster::fitDirectionalLightToReceivers(scene, l.direction, size, settings.snapLightFrustum)
                    : raster::fitDirectionalLight(scene.bounds(), l.direction, size);
            s.texel = f.texelWorldSize();
            break;
        }
    s.step = amount * std::min(s.texel, s.pixel);
    return s;
}

std::vector<scene::Scene> pathScenes(const scene::Scene& base, const scene::RenderSettings& settings,
                                     const PathSpec& spec) {
    if (spec.frames < 2 || spec.frames > 10000)
        throw scene::InputError("--frames: must be in 2..10000, got " + std::to_string(spec.frames));
    const double amount = spec.amount.value_or(defaultAmount(spec.kind));
    if (!std::isfinite(amount)) throw scene::InputError("--amount: must be finite");
    if (!isCameraPath(spec.kind) && (spec.light < 0 || std::size_t(spec.light) >= base.lights.size()))
        throw scene::InputError("--light: the scene has " + std::to_string(base.lights.size()) + " light(s), got " +
                                std::to_string(spec.light));
    if ((spec.kind == PathKind::SunAzimuth || spec.kind == PathKind::SunElevation) &&
        base.lights[std::size_t(spec.light)].type != scene::LightType::Directional)
        throw scene::InputError("--kind " + std::string(toString(spec.kind)) + ": light " + std::to_string(spec.light) +
                                " is not directional");
    if (spec.kind == PathKind::LightMove && base.lights[std::size_t(spec.light)].type == scene::LightType::Directional)
        throw scene::InputError("--kind light-move: light " + std::to_string(spec.light) +
                                " is directional (use sun-azimuth or sun-elevation)");
    if (spec.kind == PathKind::GltfAnimation && spec.amount)
        throw scene::InputError("--amount: a glTF camera animation has no amount (its keys set the motion)");
    const scene::CameraAnimation* animation =
        spec.kind == PathKind::GltfAnimation ? &scene::findCameraAnimation(base, spec.animation) : nullptr;
    if (animation && !(animation->end > animation->start))
        throw scene::InputError("--camera-animation: animation " + std::to_string(animation->index) +
                                " has one key time: nothing moves");
    if (spec.kind == PathKind::Dolly && !(amount < 1.0))
        throw scene::InputError("--amount: a dolly covers a fraction < 1 of the distance, got " +
                                std::to_string(amount));

    const scene::CameraBasis cam = scene::cameraBasis(base.camera);
    const scene::Vec3 yAxis(0, 1, 0);
    const double diagonal = base.bounds().diagonal();
    const double step = spec.kind == PathKind::SubTexel ? subTexelStep(base, settings.raster, amount).step : 0.0;
    std::vector<scene::Scene> out;
    for (int t = 0; t < spec.frames; ++t) {
        const double u = double(t) / double(spec.frames - 1);  // 0 .. 1 along the path
        scene::Scene s = base;
        scene::Camera& c = s.camera;
        switch (spec.kind) {
            case PathKind::Orbit:
                c.position = c.lookAt + rotate(base.camera.position - c.lookAt, yAxis, amount * u);
                c.up = rotate(base.camera.up, yAxis, amount * u);
                break;
            case PathKind::Dolly: c.position = c.lookAt + (base.camera.position - c.lookAt) * (1.0 - amount * u); break;
            case PathKind::Pan: {
                const scene::Vec3 d = cam.right * (amount * u * glm::length(base.camera.lookAt - base.camera.position));
                c.position += d;
                c.lookAt += d;
                break;
            }
            case PathKind::SubTexel: {
                const scene::Vec3 d = glm::normalize(cam.right + cam.up) * (step * t);
                c.position += d;
                c.lookAt += d;
                break;
            }
            case PathKind::SunAzimuth: {
                scene::Light& l = s.lights[std::size_t(spec.light)];
                l.direction = glm::normalize(rotate(l.direction, yAxis, amount * u));
                break;
            }
            case PathKind::SunElevation: {
                scene::Light& l = s.lights[std::size_t(spec.light)];
                scene::Vec3 axis = glm::cross(l.direction, yAxis);
                if (glm::length(axis) < 1e-9) axis = scene::Vec3(1, 0, 0);  // straight down: tilt about X
                l.direction = glm::normalize(rotate(l.direction, glm::normalize(axis), amount * u));
                break;
            }
            case PathKind::LightMove: s.lights[std::size_t(spec.light)].position.x += amount * u * diagonal; break;
            case PathKind::GltfAnimation:
                c = scene::animatedCamera(base, *animation, animation->start + u * (animation->end - animation->start));
                break;
        }
        out.push_back(std::move(s));
    }
    return out;
}

namespace {

// Method names in report order, from a folder's manifest (path.json).
std::vector<std::string> methodNames(const Json& manifest) {
    std::vector<std::string> names;
    const bool raster = manifest.at(nameOf(scene::Backend::Raster)).get<bool>();
    const bool held = raster && manifest.at("held_view").get<bool>() &&
                      isCameraPath(parsePathKind(manifest.at("kind").get<std::string>()));
    if (raster) names.push_back(nameOf(scene::Backend::Raster));
    if (held) names.push_back(heldViewName());
    if (manifest.at(nameOf(scene::Backend::Raytrace)).get<bool>()) names.push_back(nameOf(scene::Backend::Raytrace));
    return names;
}

// What shards of one path share: the manifest without the scene's path (a shared file system may
// be mounted at different places), the scene's hash and the program version.
Json pathIdentity(const scene::Scene& base, const Json& manifest) {
    Json id = manifest;
    id.erase("scene");
    id["scene_hash"] = sceneHash(base);
    id["version"] = SHADOWLAB_VERSION;
    return id;
}

Json pathShardManifest(const scene::Scene& base, const Json& manifest, const Shard& shard, int frames) {
    return {{"program", "shadowlab"},
            {"command", commandLine()},
            {"cwd", commandDirectory()},
            {"study", "path"},
            {"scene", base.file.string()},
            {"identity", pathIdentity(base, manifest)},
            {"shard", {{"index", shard.index}, {"count", shard.count}}},
            {"frames", frames}};
}

// Measures every method's frames in `dir` (all of them on disk) against the same frame's reference
// and writes metrics.json, flicker.svg, the animations, the worst pairs' zooms and report.html.
void measurePath(PathResult& result, const fs::path& dir, const std::string& sceneFile,
                 const std::vector<std::string>& names, std::map<std::string, double>& setupMs,
                 std::map<std::string, std::vector<double>>& times) {
    const fs::path framesDir = dir / "frames";
    const PathSpec& spec = result.spec;
    // Measure: every frame of every method against the same frame's reference.
    auto load = [&](const std::string& name) {
        std::vector<scene::Frame> frames;
        for (int t = 0; t < result.frames; ++t) frames.push_back(scene::readFrame(framesDir / frameName(t, name)));
        return frames;
    };
    const std::string referenceName = nameOf(scene::Backend::Reference);
    const std::vector<scene::Frame> refs = load(referenceName);
    result.referenceSetupMs = setupMs[referenceName];
    result.referenceFrameMs = times[referenceName];
    std::vector<const scene::Frame*> refPointers;
    for (const scene::Frame& f : refs) refPointers.push_back(&f);
    result.referenceTemporal = compare::measureTemporal(refPointers, refPointers);

    const int w = refs[0].width, h = refs[0].height;
    const int fps = 8;
    std::string gifs, zooms;
    compare::ScatterPlot plot;
    plot.title = "Flicker per frame pair";  // the definition is in the text above the plot
    plot.x.title = "frame pair (t, t+1)";
    plot.x.min = 0.0;  // pairs 0 .. frames - 2, not a fitted margin past the last one
    plot.x.max = double(std::max<std::size_t>(refs.size(), 3) - 2);
    plot.x.integer = true;
    plot.y.title = "flicker rate";
    plot.y.percent = true;
    plot.y.min = 0.0;
    for (std::size_t mi = 0; mi < names.size(); ++mi) {
        const std::string& name = names[mi];
        PathMethod m;
        m.name = name;
        m.setupMs = setupMs[name];
        m.frameMs = times[name];
        const std::vector<scene::Frame> frames = load(name);
        // The held view compares with frame 0's reference: it is drawn from frame 0's camera.
        std::vector<compare::Comparison> comparisons;
        std::vector<const scene::Frame*> methodPointers, heldRefs;
        std::vector<const std::vector<compare::PixelClass>*> classes;
        for (int t = 0; t < result.frames; ++t) {
            const scene::Frame& r = name == heldViewName() ? refs[0] : refs[std::size_t(t)];
            comparisons.push_back(compare::compareFrames(frames[std::size_t(t)], r));
            m.metrics.push_back(comparisons.back().metrics);
            methodPointers.push_back(&frames[std::size_t(t)]);
            heldRefs.push_back(&r);
        }
        for (const compare::Comparison& c : comparisons) classes.push_back(&c.classes);
        m.temporal = measureTemporal(methodPointers, heldRefs, classes);

        // The animation: method, reference, difference side by side.
        std::vector<std::vector<unsigned char>> gifFrames;
        int gw = 0;
        for (int t = 0; t < result.frames; ++t) {
            const std::vector<float> a = displayBeauty(frames[std::size_t(t)]),
                                     b = displayBeauty(*heldRefs[std::size_t(t)]);
            gifFrames.push_back(sideBySide({&a, &b, &comparisons[std::size_t(t)].diffRgb}, w, h, gw));
        }
        writeGif(dir / (name + ".gif"), gw, h, gifFrames, fps);
        // Small frames are magnified by a whole factor (crisp pixels) so their shadows can be seen.
        const int shown = gw > 1200 ? 1200 : gw * std::max(1, 960 / gw);
        gifs += "<figure><img src=\"" + name + ".gif\" alt=\"" + name + "\" style=\"width:" + std::to_string(shown) +
                "px;image-rendering:pixelated\"><figcaption><b>" + compare::escapeHtml(name) +
                "</b>: method | reference | difference, " + std::to_string(fps) + " frames/s</figcaption></figure>\n";

        // The worst pair: its flicker pixels (red) over the method's frame t, the densest window zoomed.
        if (m.temporal.worstPair >= 0 && m.temporal.pairs[std::size_t(m.temporal.worstPair)].flicker > 0) {
            const int t = m.temporal.worstPair;
            const scene::Frame& f0 = frames[std::size_t(t)];
            const scene::Frame& f1 = frames[std::size_t(t) + 1];
            const scene::Frame& r0 = *heldRefs[std::size_t(t)];
            const scene::Frame& r1 = *heldRefs[std::size_t(t) + 1];
            const std::vector<unsigned char> mask = compare::flickerMask(
                f0, f1, r0, r1, comparisons[std::size_t(t)].classes, comparisons[std::size_t(t) + 1].classes);
            std::vector<float> map = displayBeauty(f0);
            for (std::size_t i = 0; i < mask.size(); ++i)
                if (mask[i]) map[3 * i] = 1.0f, map[3 * i + 1] = 0.08f, map[3 * i + 2] = 0.05f;
            const compare::ErrorHotspot win = densestWindow(mask, w, h, std::max(16, std::min(w, h) / 5));
            // Zoom: frame t, frame t + 1 and the flicker map of the window, magnified 6x.
            const int z = 6, side = win.size * z;
            auto crop = [&](const std::vector<float>& rgb) {
                std::vector<float> out(std::size_t(side) * side * 3);
                for (int y = 0; y < side; ++y)
                    for (int x = 0; x < side; ++x)
                        for (int c = 0; c < 3; ++c)
                            out[(std::size_t(y) * side + x) * 3 + c] =
                                rgb[(std::size_t(win.y + y / z) * w + win.x + x / z) * 3 + c];
                return out;
            };
            const std::vector<float> c0 = crop(displayBeauty(f0)), c1 = crop(displayBeauty(f1)), cm = crop(map);
            int zw = 0;
            const std::vector<unsigned char> zoom = sideBySide({&c0, &c1, &cm}, side, side, zw);
            std::vector<float> zoomFloat(zoom.size());
            for (std::size_t i = 0; i < zoom.size(); ++i) zoomFloat[i] = zoom[i] / 255.0f;
            const std::string zoomName = name + "-worst-pair.png";
            scene::writePngDisplay(dir / zoomName, zw, side, zoomFloat);
            zooms += "<figure><img src=\"" + zoomName + "\" alt=\"worst pair of " + name + "\"><figcaption><b>" +
                     compare::escapeHtml(name) + "</b>, worst pair (" + std::to_string(t) + ", " +
                     std::to_string(t + 1) + "): frame t | frame t+1 | flicker pixels in red; window " +
                     std::to_string(win.size) + " px at (" + std::to_string(win.x) + ", " + std::to_string(win.y) +
                     "), " + compare::formatCount(win.wrongPixels) + " of the pair's " +
                     compare::formatCount(m.temporal.pairs[std::size_t(t)].flicker) +
                     " flicker pixels</figcaption></figure>\n";
        }

        compare::PlotSeries series;
        series.name = name;
        const bool heldView = name == heldViewName();
        series.color = compare::backendColor(heldView ? nameOf(scene::Backend::Raster) + " held view" : name, mi);
        series.connect = true;
        series.dashed = heldView;
        for (const compare::PairStability& p : m.temporal.pairs)
            series.points.push_back(
                {double(p.first), p.flickerRate, "",
                 name + " pair " + std::to_string(p.first) + ": " + compare::formatCount(p.flicker) + " px"});
        plot.series.push_back(series);
        result.methods.push_back(std::move(m));
    }
    const std::string svg = compare::renderSvg(plot);
    scene::writeTextAtomic(dir / "flicker.svg", svg);

    // Error per frame: which frames get shadows wrong, and how, beside how they change.
    compare::ScatterPlot errorPlot;
    errorPlot.title = "Wrong pixels per frame";
    errorPlot.x.title = "frame";
    errorPlot.x.min = 0.0;
    errorPlot.x.max = double(std::max<std::size_t>(refs.size(), 2) - 1);
    errorPlot.x.integer = true;
    errorPlot.y.title = "mismatch rate";
    errorPlot.y.percent = true;
    errorPlot.y.min = 0.0;
    std::string errorText;
    for (std::size_t mi = 0; mi < result.methods.size(); ++mi) {
        const PathMethod& m = result.methods[mi];
        if (m.metrics.empty()) continue;
        compare::PlotSeries series;
        series.name = m.name;
        const bool heldView = m.name == heldViewName();
        series.color = compare::backendColor(heldView ? nameOf(scene::Backend::Raster) + " held view" : m.name, mi);
        series.connect = true;
        series.dashed = heldView;
        std::size_t best = 0, worst = 0;
        for (std::size_t t = 0; t < m.metrics.size(); ++t) {
            const compare::Metrics& x = m.metrics[t];
            series.points.push_back({double(t), x.mismatchRate, "",
                                     m.name + " frame " + std::to_string(t) + ": " +
                                         compare::formatCount(x.falseShadow) + " false, " +
                                         compare::formatCount(x.missedShadow) + " missed"});
            if (x.mismatchRate < m.metrics[best].mismatchRate) best = t;
            if (x.mismatchRate > m.metrics[worst].mismatchRate) worst = t;
        }
        errorPlot.series.push_back(series);
        if (heldView) continue;  // the held view's frames are not the path's
        const compare::Metrics& w0 = m.metrics[worst];
        if (w0.falseShadow + w0.missedShadow == 0) {
            errorText += "<p><b>" + compare::escapeHtml(m.name) + "</b>: no wrong pixel in any frame.</p>\n";
            continue;
        }
        const std::string worstName = "frame " + std::to_string(worst);
        errorText +=
            "<p><b>" + compare::escapeHtml(m.name) + "</b>: " +
            (w0.mismatchRate == m.metrics[best].mismatchRate
                 ? compare::formatPercent(w0.mismatchRate) + " wrong in every frame"
                 : compare::formatPercent(m.metrics[best].mismatchRate) + " wrong at frame " + std::to_string(best) +
                       ", up to " + compare::formatPercent(w0.mismatchRate) + " at " + worstName) +
            "; " + worstName + " has " + compare::formatCount(w0.falseShadow) + " false and " +
            compare::formatCount(w0.missedShadow) + " missed shadow pixels, " +
            (w0.missedShadow <= w0.falseShadow ? std::string("mostly false (acne or over-darkening)")
             : 2 * w0.terminatorMissed > w0.missedShadow
                 ? "mostly missed, " + compare::formatCount(w0.terminatorMissed) +
                       " of them at a smooth-shaded mesh's terminator (a tessellation effect: docs/compare.md)"
                 : std::string("mostly missed (light leaking or peter-panning)")) +
            " (<code>frames/" + frameName(int(worst), m.name) + "</code>).</p>\n";
    }
    const std::string errorSvg = compare::renderSvg(errorPlot);
    scene::writeTextAtomic(dir / "error.svg", errorSvg);
    scene::writeTextAtomic(dir / "metrics.json", toJson(result).dump(2) + "\n");

    // The report.
    std::ostringstream html;
    html << "<!doctype html><html><head><meta charset=\"utf-8\"><title>shadowlab path: "
         << compare::escapeHtml(toString(spec.kind))
         << "</title><style>body{font-family:sans-serif;margin:1.5em;max-width:1300px}table{border-collapse:collapse}"
            "td,th{border:1px solid #ccc;padding:3px 8px;text-align:right}th{background:#eee}"
            "td,tr th:first-child{white-space:nowrap}figure{margin:1em 0}"
            "</style></head><body>\n";
    html << "<h1>Temporal stability: " << compare::escapeHtml(toString(spec.kind)) << " path</h1>\n<p>Scene <code>"
         << compare::escapeHtml(sceneFile) << "</code>, " << result.frames << " frames at " << w << "x" << h
         << ", amount " << compare::formatShort(result.amount)
         << ". Pixels are compared between frames at the same image "
         << "position; flicker counts the counted pixels whose lit/shadow state changes while the reference's does "
         << "not (docs/temporal.md).</p>\n";
    html << "<table><tr><th>method</th><th>setup</th><th>median per frame</th><th>mean flicker</th><th>max flicker</th>"
            "<th>flicker px</th><th>error variation</th><th>swim (px)</th><th>edge offset (px)</th>"
            "<th>mean mismatch</th></tr>\n";
    auto row = [&](const std::string& name, double setup, const std::vector<double>& ms,
                   const compare::TemporalSummary& tsum, double mismatch) {
        html << "<tr><th>" << compare::escapeHtml(name) << "</th><td>" << compare::formatDuration(setup) << "</td><td>"
             << compare::formatDuration(median(ms)) << "</td><td>" << compare::formatPercent(tsum.meanFlickerRate)
             << "</td><td>" << compare::formatPercent(tsum.maxFlickerRate) << "</td><td>"
             << compare::formatCount(tsum.totalFlicker) << "</td><td>"
             << compare::formatFixed(tsum.meanErrorVariation, 5) << "</td><td>"
             << compare::formatFixed(tsum.meanSwimPixels, 3) << "</td><td>"
             << compare::formatFixed(tsum.meanEdgeOffset, 3) << "</td><td>"
             << (mismatch < 0 ? std::string("-") : compare::formatPercent(mismatch)) << "</td></tr>\n";
    };
    row(nameOf(scene::Backend::Reference), result.referenceSetupMs, result.referenceFrameMs, result.referenceTemporal,
        -1.0);
    for (const PathMethod& m : result.methods) {
        double mismatch = 0.0;
        for (const compare::Metrics& x : m.metrics) mismatch += x.mismatchRate;
        row(m.name, m.setupMs, m.frameMs, m.temporal, m.metrics.empty() ? 0.0 : mismatch / double(m.metrics.size()));
    }
    html << "</table>\n<p>Setup is paid once for the path (the raster Renderer with its device, buffers and "
            "pipelines; the ray tracer's acceleration structure); per frame is the rest (the raster update of the "
            "light frusta and uniforms included).</p>\n";
    html << svg << "\n<h2>Error per frame</h2>\n" << errorText << errorSvg << "\n<h2>Animations</h2>\n" << gifs;
    if (!zooms.empty()) html << "<h2>Worst frame pair</h2>\n" << zooms;
    html << "<p>Every figure: <a href=\"metrics.json\">metrics.json</a>; the frames: <code>frames/</code>.</p>"
            "</body></html>\n";
    scene::writeTextAtomic(dir / "report.html", html.str());
}

}  // namespace

PathResult runPath(const scene::Scene& base, const scene::RenderSettings& settings, const PathSpec& spec,
                   const PathRunOptions& options) {
    PathResult result;
    result.spec = spec;
    result.amount = spec.amount.value_or(defaultAmount(spec.kind));
    const std::vector<scene::Scene> scenes = pathScenes(base, settings, spec);
    result.frames = int(scenes.size());
    const bool held = options.raster && options.heldView && isCameraPath(spec.kind);

    const bool sharded = options.shardCount > 0;
    if (sharded && !(options.shardIndex >= 0 && options.shardIndex < options.shardCount))
        throw scene::InputError("--shard: expected K/N with 0 <= K < N");
    const Shard shard{options.shardIndex, std::max(1, options.shardCount)};
    std::set<int> mine;  // the frames this process renders
    for (int t : pathShardFrames(result.frames, shard.index, shard.count)) mine.insert(t);

    // The folder: a manifest says which path it holds; the journal which frames are done.
    const fs::path dir = sharded ? options.outputDir / shardFolderName(shard) : options.outputDir;
    const fs::path framesDir = dir / "frames";
    const fs::path journal = dir / "frames.jsonl", manifestFile = dir / "path.json";
    const Json manifest = manifestOf(base, spec, result.amount, options, settings);
    std::error_code ec;
    if (fs::exists(journal, ec) && !options.resume)
        throw scene::InputError(dir.string() + ": already holds a path (frames.jsonl); use --resume to continue it");
    if (options.resume && fs::exists(manifestFile, ec)) {
        Json old;
        try {
            old = scene::readJsonFile(manifestFile);
        } catch (const scene::SceneError&) {
            throw scene::InputError(manifestFile.string() + ": unreadable; remove the folder to start again");
        }
        if (old != manifest)
            throw scene::InputError(manifestFile.string() +
                                    ": the folder holds another path (scene, kind, frames, amount or settings differ)");
    }
    fs::create_directories(framesDir);
    scene::removeStaleTemporaries(framesDir);
    scene::writeTextAtomic(manifestFile, manifest.dump(2) + "\n");
    if (sharded)
        scene::writeTextAtomic(dir / "shard.json",
                               pathShardManifest(base, manifest, shard, result.frames).dump(2) + "\n");

    // Finished frames: the journal's lines (a torn last line is dropped and the journal rewritten).
    std::map<int, Json> done;
    if (options.resume && fs::exists(journal, ec)) {
        std::string kept;
        for (const scene::JournalLine& l : scene::readJournalLines(journal)) {
            try {
                const Json j = Json::parse(l.text);
                done[j.at("frame").get<int>()] = j;
                kept += l.text + "\n";
            } catch (const std::exception&) {
                break;  // a kill in the middle of the last write
            }
        }
        scene::writeTextAtomic(journal, kept);
    }

    const std::vector<std::string> names = methodNames(manifest);

    // One renderer per backend for the whole path, made for frame 0 (the raster vertex buffer is
    // relative to frame 0's camera: a resumed path renders exactly what an unbroken one does).
    const scene::RenderPlan plan = scene::makeRenderPlan(scenes[0], settings);
    std::unique_ptr<BackendRenderer> rasterRenderer, tracer, reference;
    std::map<std::string, double> setupMs;
    std::map<std::string, std::vector<double>> times;
    // Progress counts this process's frames (a shard's, not the path's) and estimates the time
    // left from the frames rendered here (resumed ones cost nothing).
    const auto start = std::chrono::steady_clock::now();
    std::size_t finishedHere = 0, renderedHere = 0, toRender = 0;
    for (int t : mine) toRender += done.count(t) ? 0 : 1;
    for (int t = 0; t < result.frames; ++t) {
        if (!mine.count(t)) continue;
        if (done.count(t)) {
            const Json& j = done[t];
            for (const auto& [name, ms] : j.at("frame_ms").items()) times[name].push_back(ms.get<double>());
            const Json setups = j.value("setup_ms", Json::object());  // kept: items() refers to it
            for (const auto& [name, ms] : setups.items()) setupMs[name] = ms.get<double>();
            ++result.resumedFrames;
            ++finishedHere;
            continue;
        }
        const scene::Scene& s = scenes[std::size_t(t)];
        Json line = {{"frame", t}, {"frame_ms", Json::object()}, {"setup_ms", Json::object()}};
        auto record = [&](const std::string& name, const scene::Frame& f, double setup) {
            scene::writeFrame(f, framesDir / frameName(t, name));
            line["frame_ms"][name] = frameMs(f);
            line["setup_ms"][name] = setup;
        };
        if (!reference) reference = makeRenderer(scene::Backend::Reference, scenes[0], plan, settings);
        reference->update(s);
        record(nameOf(scene::Backend::Reference), reference->render(), reference->setupMs());
        if (options.raytrace) {
            if (!tracer) tracer = makeRenderer(scene::Backend::Raytrace, scenes[0], plan, settings);
            tracer->update(s);
            record(nameOf(scene::Backend::Raytrace), tracer->render(), tracer->setupMs());
        }
        if (options.raster) {
            double setup = 0.0;
            if (!rasterRenderer) {
                rasterRenderer = makeRenderer(scene::Backend::Raster, scenes[0], plan, settings);
                setup = rasterRenderer->setupMs();
            }
            rasterRenderer->update(s);
            scene::Frame f = rasterRenderer->render();
            setup += f.timing("setup");  // pipelines made by the first frame
            record(nameOf(scene::Backend::Raster), f, setup);
            if (held) {
                rasterRenderer->update(s, scenes[0].camera);
                record(heldViewName(), rasterRenderer->render(), 0.0);
            }
            if (settings.raster.validate && rasterRenderer->validationMessages() > 0)
                throw std::runtime_error("the Vulkan validation layer reported " +
                                         std::to_string(rasterRenderer->validationMessages()) +
                                         " message(s) (printed above)");
        }
        for (const auto& [name, ms] : line["frame_ms"].items()) times[name].push_back(ms.get<double>());
        for (const auto& [name, ms] : line["setup_ms"].items())
            if (ms.get<double>() > 0.0 || !setupMs.count(name)) setupMs[name] = ms.get<double>();
        appendLine(journal, line.dump());
        ++finishedHere;
        ++renderedHere;
        if (options.progress) {
            const double elapsed = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
            options.progress(pathProgressLine(t, result.frames, finishedHere, sharded ? mine.size() : 0,
                                              elapsed / double(renderedHere) * double(toRender - renderedHere)));
        }
    }
    if (sharded) return result;  // measured by mergePathShards, from every shard's frames
    measurePath(result, dir, base.file.string(), names, setupMs, times);
    return result;
}

Json toJson(const PathResult& r) {
    Json methods = Json::array();
    for (const PathMethod& m : r.methods) {
        Json frames = Json::array();
        for (std::size_t t = 0; t < m.metrics.size(); ++t) {
            Json f = toJson(m.metrics[t]);
            f["frame"] = t;
            f["frame_ms"] = t < m.frameMs.size() ? m.frameMs[t] : 0.0;
            frames.push_back(f);
        }
        methods.push_back({{"name", m.name},
                           {"setup_ms", m.setupMs},
                           {"median_frame_ms", median(m.frameMs)},
                           {"temporal", toJson(m.temporal)},
                           {"frames", frames}});
    }
    return {{"kind", toString(r.spec.kind)},
            {"frames", r.frames},
            {"amount", r.amount},
            {"light", r.spec.light},
            {"resumed_frames", r.resumedFrames},
            {nameOf(scene::Backend::Reference),
             {{"setup_ms", r.referenceSetupMs},
              {"median_frame_ms", median(r.referenceFrameMs)},
              {"frame_ms", r.referenceFrameMs},
              {"temporal", toJson(r.referenceTemporal)}}},
            {"methods", methods}};
}

std::string pathProgressLine(int frame, int frames, std::size_t shardDone, std::size_t shardFrames,
                             double secondsLeft) {
    const int eta = int(std::max(0.0, secondsLeft) + 0.5);
    char text[160];
    if (shardFrames > 0)
        std::snprintf(text, sizeof text, "frame %d/%d (%zu of %zu in this shard), ETA %dm%02ds", frame + 1, frames,
                      shardDone, shardFrames, eta / 60, eta % 60);
    else
        std::snprintf(text, sizeof text, "frame %d/%d, ETA %dm%02ds", frame + 1, frames, eta / 60, eta % 60);
    return text;
}

std::vector<int> pathShardFrames(int frames, int index, int count) {
    std::vector<int> out;
    for (int t = index; count > 0 && t < frames; t += count) out.push_back(t);
    return out;
}

namespace {

// The shard folders under `input`: itself when it holds shard.json, else its shard-* folders.
std::vector<fs::path> pathShardFolders(const fs::path& input) {
    std::error_code ec;
    std::vector<fs::path> dirs;
    if (fs::exists(input / "shard.json", ec)) return {input};
    for (const auto& e : fs::directory_iterator(input, ec))
        if (e.is_directory() && e.path().filename().string().rfind("shard-", 0) == 0 &&
            fs::exists(e.path() / "shard.json"))
            dirs.push_back(e.path());
    std::sort(dirs.begin(), dirs.end());
    return dirs;
}

// The first field in which two path identities differ, in words; empty when they are one path's.
std::string identityDifference(const Json& a, const Json& b) {
    for (const auto& [key, value] : a.items())
        if (!b.contains(key) || b[key] != value)
            return key + " " + value.dump() + " vs " + (b.contains(key) ? b[key].dump() : std::string("(none)"));
    for (const auto& [key, value] : b.items())
        if (!a.contains(key)) return key + " (none) vs " + value.dump();
    return "";
}

}  // namespace

bool holdsPathShards(const std::vector<fs::path>& inputs) {
    for (const fs::path& input : inputs) {
        std::error_code ec;
        if (!fs::is_directory(input, ec)) continue;
        for (const fs::path& d : pathShardFolders(input)) {
            const Json j = scene::readJsonFileOrNull(d / "shard.json");
            return j.is_object() && j.value("study", "") == "path";
        }
    }
    return false;
}

MergedPath mergePathShards(const std::vector<fs::path>& inputs, const fs::path& out) {
    if (inputs.empty()) throw scene::InputError("merge: no input folder");
    MergedPath merged;
    Json identity, manifest;
    std::string sceneFile;
    fs::path firstDir, base;
    int frames = 0;
    std::map<int, fs::path> shardOf;                 // shard index → its first folder
    std::map<int, std::pair<fs::path, Json>> lines;  // frame → (folder, journal line)
    std::error_code ec;
    for (const fs::path& input : inputs) {
        if (!fs::is_directory(input, ec)) throw scene::InputError(input.string() + ": no such folder");
        const std::vector<fs::path> dirs = pathShardFolders(input);
        if (dirs.empty()) throw scene::InputError(input.string() + ": holds no path shard (shard-K-of-N/shard.json)");
        if (base.empty()) base = dirs.size() == 1 && dirs.front() == input ? input.parent_path() : input;
        for (const fs::path& d : dirs) {
            const fs::path file = d / "shard.json";
            const Json j = scene::readJsonFile(file);
            if (!j.is_object() || j.value("study", "") != "path" || !j.contains("identity") || !j.contains("shard") ||
                !j.contains("frames"))
                throw scene::InputError(file.string() +
                                        ": not the manifest of a path shard (a sweep's or a check's "
                                        "shards are merged on their own)");
            const int index = j["shard"].value("index", -1), count = j["shard"].value("count", 0);
            if (identity.is_null()) {
                identity = j["identity"];
                sceneFile = j.value("scene", "");
                frames = j["frames"].get<int>();
                merged.shardCount = count;
                firstDir = d;
                manifest = scene::readJsonFile(d / "path.json");
            } else if (const std::string diff = identityDifference(identity, j["identity"]); !diff.empty()) {
                throw scene::InputError(d.string() + ": a shard of another path than " + firstDir.string() + " (" +
                                        diff + ")");
            } else if (count != merged.shardCount) {
                throw scene::InputError(d.string() + ": a shard of a split into " + std::to_string(count) + ", not " +
                                        std::to_string(merged.shardCount) + " as " + firstDir.string());
            }
            if (!(index >= 0 && index < count)) throw scene::InputError(file.string() + ": shard index out of range");
            merged.shardDirs.push_back(d);
            shardOf.emplace(index, d);
            // The journal, strictly: a damaged line is an error, a torn last line a frame not finished.
            const fs::path journal = d / "frames.jsonl";
            for (const scene::JournalLine& l : scene::readJournalLines(journal)) {
                const std::string at = journal.string() + ":" + std::to_string(l.number);
                Json row;
                int t = -1;
                try {
                    row = Json::parse(l.text);
                    t = row.at("frame").get<int>();
                    row.at("frame_ms").items();
                } catch (const std::exception&) {
                    if (l.torn) break;
                    throw scene::InputError(at + ": damaged journal line (not a finished frame)");
                }
                if (t < 0 || t >= frames || t % count != index)
                    throw scene::InputError(at + ": frame " + std::to_string(t) + " does not belong to shard " +
                                            std::to_string(index) + "/" + std::to_string(count));
                if (lines.count(t)) {
                    ++merged.duplicates;
                    continue;
                }
                lines[t] = {d, row};
            }
        }
    }
    // Every missing or unfinished shard, in one message, with the command that completes it: a
    // shard's own recorded command line, else the scene and folder with the options left to the user.
    std::vector<std::string> problems;
    const std::string scene = quoteArg(sceneFile.empty() ? std::string("SCENE") : sceneFile);
    const RecordedCommand recorded = recordedShardCommand(merged.shardDirs);
    auto command = [&](int k, bool resume) {
        const std::string c = shardCommandText(recorded.args, {k, merged.shardCount}, resume, recorded.cwd);
        if (!c.empty()) return "`" + c + "`";
        return "`shadowlab path " + scene + " -o " + quoteArg(base.string()) + " --shard " + std::to_string(k) + "/" +
               std::to_string(merged.shardCount) + (resume ? " --resume" : "") + "` and the same path options";
    };
    for (int k = 0; k < merged.shardCount; ++k) {
        const std::vector<int> want = pathShardFrames(frames, k, merged.shardCount);
        std::size_t missing = 0;
        for (int t : want) missing += lines.count(t) ? 0 : 1;
        if (missing == 0) continue;
        const std::string name = std::to_string(k) + "/" + std::to_string(merged.shardCount);
        if (!shardOf.count(k))
            problems.push_back("shard " + name + " is missing (no " + shardFolderName({k, merged.shardCount}) +
                               "): render it with " + command(k, false));
        else
            problems.push_back("shard " + name + " is unfinished (" + std::to_string(missing) + " of " +
                               std::to_string(want.size()) + " frames missing): finish it with " + command(k, true));
    }
    if (!problems.empty()) {
        std::string what = "merge: the path is incomplete:";
        for (const std::string& p : problems) what += "\n  " + p;
        throw scene::InputError(what);
    }
    const std::vector<std::string> names = methodNames(manifest);
    std::vector<std::string> all = names;
    all.push_back(nameOf(scene::Backend::Reference));
    for (const auto& [t, entry] : lines)
        for (const std::string& name : all)
            if (!fs::exists(entry.first / "frames" / frameName(t, name), ec))
                throw scene::InputError((entry.first / "frames" / frameName(t, name)).string() +
                                        ": missing, though the journal lists frame " + std::to_string(t));
    if (fs::exists(out / "shard.json", ec))
        throw scene::InputError(out.string() + ": is a shard folder; merge into another");
    if (fs::exists(out / "frames.jsonl", ec) && !fs::exists(out / "merge.json", ec))
        throw scene::InputError(out.string() + ": holds an unsharded path; merge into another folder");

    // The merged folder: the frames linked (or copied), the journal in frame order, the manifest,
    // then the measurement. All of it is made in a staging folder inside `out` and moved into place
    // only once everything was measured: a damaged frame found while measuring leaves `out` as it was.
    const bool outExisted = fs::exists(out, ec);
    fs::create_directories(out);
    scene::removeStaleTemporaries(out);  // a staging folder a killed merge left behind
    const fs::path stage = scene::temporarySibling(out / "merge");
    struct Staging {
        fs::path dir, out;
        bool removeOut = false, committed = false;
        ~Staging() {
            std::error_code ec;
            if (committed) return;
            fs::remove_all(dir, ec);
            if (removeOut && fs::is_empty(out, ec)) fs::remove(out, ec);
        }
    } staging{stage, out, !outExisted};
    fs::create_directories(stage / "frames");
    std::map<std::string, double> setupMs;
    std::map<std::string, std::vector<double>> times;
    std::string journal;
    for (const auto& [t, entry] : lines) {
        for (const std::string& name : all)
            placeFile(entry.first / "frames" / frameName(t, name), stage / "frames" / frameName(t, name));
        journal += entry.second.dump() + "\n";
        for (const auto& [name, ms] : entry.second.at("frame_ms").items()) times[name].push_back(ms.get<double>());
        const Json setups = entry.second.value("setup_ms", Json::object());
        for (const auto& [name, ms] : setups.items())
            if (ms.get<double>() > 0.0 || !setupMs.count(name)) setupMs[name] = ms.get<double>();
    }
    scene::writeTextAtomic(stage / "frames.jsonl", journal);
    scene::writeTextAtomic(stage / "path.json", manifest.dump(2) + "\n");
    Json dirs = Json::array();
    for (const fs::path& d : merged.shardDirs) dirs.push_back(d.string());
    scene::writeTextAtomic(
        stage / "merge.json",
        Json{{"shards", merged.shardCount}, {"folders", dirs}, {"duplicates", merged.duplicates}}.dump(2) + "\n");

    PathResult& result = merged.result;
    result.spec.kind = parsePathKind(manifest.at("kind").get<std::string>());
    result.spec.frames = frames;
    result.spec.light = manifest.value("light", 0);
    if (manifest.contains("animation") && manifest["animation"].is_string())
        result.spec.animation = manifest["animation"].get<std::string>();
    result.amount = manifest.at("amount").get<double>();
    result.spec.amount = result.amount;
    result.frames = frames;
    result.resumedFrames = 0;  // a merge renders nothing, so nothing was resumed
    measurePath(result, stage, sceneFile, names, setupMs, times);
    // The commit: each staged entry replaces its namesake (an earlier merge's).
    for (const auto& e : fs::directory_iterator(stage)) {
        const fs::path target = out / e.path().filename();
        fs::remove_all(target);
        fs::rename(e.path(), target);
    }
    fs::remove(stage);
    staging.committed = true;
    return merged;
}

std::vector<std::string> pathDifferences(const fs::path& a, const fs::path& b) {
    const std::function<void(Json&)> strip = [&](Json& j) {
        if (j.is_object()) {
            for (const char* k :
                 {"setup_ms", "median_frame_ms", "frame_ms", "method_timing", "reference_timing", "resumed_frames"})
                j.erase(k);
            for (auto& [key, value] : j.items()) strip(value);
        } else if (j.is_array()) {
            for (Json& v : j) strip(v);
        }
    };
    Json ja = scene::readJsonFile(a / "metrics.json"), jb = scene::readJsonFile(b / "metrics.json");
    strip(ja);
    strip(jb);
    std::vector<std::string> out;
    for (const Json& op : Json::diff(ja, jb)) {
        const std::string at = op.value("path", "");
        const Json::json_pointer p(at);
        out.push_back(at + ": " + (ja.contains(p) ? ja[p].dump() : std::string("(none)")) + " vs " +
                      (jb.contains(p) ? jb[p].dump() : std::string("(none)")));
        if (out.size() >= 20) break;
    }
    return out;
}

}  // namespace shadowlab::studies
