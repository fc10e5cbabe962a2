// studies/sweep.cpp: the sweep runner: grid, timing, the append-only journal and resume.
#include "studies/sweep.h"

#include <fcntl.h>
#include <unistd.h>
#include <algorithm>
#include <cerrno>
#include <chrono>
#include <cmath>
#include <csignal>
#include <cstdio>
#include <fstream>
#include <memory>
#include <set>
#include <sstream>
#include <stdexcept>

#include "compare/compare.h"
#include "scene/append_line.h"
#include "scene/backend.h"
#include "scene/error.h"
#include "scene/frame_identity.h"
#include "scene/frame_io.h"
#include "scene/input_file.h"
#include "scene/json_input.h"
#include "scene/memory.h"
#include "scene/render_plan.h"
#include "studies/backend.h"
#include "studies/machine.h"

namespace shadowlab::studies {

namespace {

namespace fs = std::filesystem;
using Json = nlohmann::json;

std::string number(double v) {
    char buf[40];
    std::snprintf(buf, sizeof buf, "%.9g", v);
    return buf;
}

// For labels people read: four significant digits (a row's key keeps every digit).
std::string shortNumber(double v) {
    char buf[40];
    std::snprintf(buf, sizeof buf, "%.4g", v);
    return buf;
}

double median(std::vector<double> v) {
    if (v.empty()) return 0.0;
    std::sort(v.begin(), v.end());
    const std::size_t n = v.size();
    return n % 2 ? v[n / 2] : 0.5 * (v[n / 2 - 1] + v[n / 2]);
}

// FNV-1a: a short, stable name for a configuration's images.
std::string shortHash(const std::string& text) {
    std::uint64_t h = 1469598103934665603ull;
    for (unsigned char c : text) h = (h ^ c) * 1099511628211ull;
    char buf[20];
    std::snprintf(buf, sizeof buf, "%012llx", static_cast<unsigned long long>(h & 0xffffffffffffull));
    return buf;
}

Json overridesToJson(const scene::SettingsOverrides& o) {
    Json j = Json::object();
    if (o.shadowMapSize) j["shadow_map_size"] = *o.shadowMapSize;
    if (o.filter) j["filter"] = *o.filter;
    if (o.depthBias) j["depth_bias"] = *o.depthBias;
    if (o.slopeBias) j["slope_bias"] = *o.slopeBias;
    if (o.rayBias) j["ray_bias"] = *o.rayBias;
    if (o.precision) j["precision"] = *o.precision;
    if (o.samples) j["samples"] = *o.samples;
    if (o.pcfSize) j["pcf_size"] = *o.pcfSize;
    if (o.normalOffset) j["normal_offset"] = *o.normalOffset;
    if (o.receiverPlaneBias) j["receiver_plane_bias"] = *o.receiverPlaneBias;
    if (o.hardwareBias) j["hardware_bias"] = *o.hardwareBias;
    if (o.fitLightFrustum) j["fit_light_frustum"] = *o.fitLightFrustum;
    if (o.cascades) j["cascades"] = *o.cascades;
    if (o.snapLightFrustum) j["snap_light_frustum"] = *o.snapLightFrustum;
    if (o.cascadeBlend) j["cascade_blend"] = *o.cascadeBlend;
    if (o.minVariance) j["min_variance"] = *o.minVariance;
    if (o.bleedReduction) j["bleeding_reduction"] = *o.bleedReduction;
    if (o.evsmPositive) j["evsm_positive"] = *o.evsmPositive;
    if (o.evsmNegative) j["evsm_negative"] = *o.evsmNegative;
    if (o.esmExponent) j["esm_exponent"] = *o.esmExponent;
    if (o.momentBias) j["moment_bias"] = *o.momentBias;
    if (o.blurWidth) j["blur_width"] = *o.blurWidth;
    return j;
}

scene::SettingsOverrides overridesFromJson(const Json& j) {
    scene::SettingsOverrides o;
    if (j.contains("shadow_map_size")) o.shadowMapSize = j["shadow_map_size"].get<int>();
    if (j.contains("filter")) o.filter = j["filter"].get<std::string>();
    if (j.contains("depth_bias")) o.depthBias = j["depth_bias"].get<double>();
    if (j.contains("slope_bias")) o.slopeBias = j["slope_bias"].get<double>();
    if (j.contains("ray_bias")) o.rayBias = j["ray_bias"].get<std::string>();
    if (j.contains("precision")) o.precision = j["precision"].get<std::string>();
    if (j.contains("samples")) o.samples = j["samples"].get<int>();
    if (j.contains("pcf_size")) o.pcfSize = j["pcf_size"].get<int>();
    if (j.contains("normal_offset")) o.normalOffset = j["normal_offset"].get<double>();
    if (j.contains("receiver_plane_bias")) o.receiverPlaneBias = j["receiver_plane_bias"].get<bool>();
    if (j.contains("hardware_bias")) o.hardwareBias = j["hardware_bias"].get<bool>();
    if (j.contains("fit_light_frustum")) o.fitLightFrustum = j["fit_light_frustum"].get<bool>();
    if (j.contains("cascades")) o.cascades = j["cascades"].get<int>();
    if (j.contains("snap_light_frustum")) o.snapLightFrustum = j["snap_light_frustum"].get<bool>();
    if (j.contains("cascade_blend")) o.cascadeBlend = j["cascade_blend"].get<double>();
    if (j.contains("min_variance")) o.minVariance = j["min_variance"].get<double>();
    if (j.contains("bleeding_reduction")) o.bleedReduction = j["bleeding_reduction"].get<double>();
    if (j.contains("evsm_positive")) o.evsmPositive = j["evsm_positive"].get<double>();
    if (j.contains("evsm_negative")) o.evsmNegative = j["evsm_negative"].get<double>();
    if (j.contains("esm_exponent")) o.esmExponent = j["esm_exponent"].get<double>();
    if (j.contains("moment_bias")) o.momentBias = j["moment_bias"].get<double>();
    if (j.contains("blur_width")) o.blurWidth = j["blur_width"].get<int>();
    return o;
}

// A journal's or results file's backend name, parsed once where the text is read.
scene::Backend backendFromJson(const Json& name) {
    const std::string text = name.get<std::string>();
    const std::optional<scene::Backend> b = scene::parseBackend(text);
    if (!b) throw std::invalid_argument("unknown backend '" + text + "'");
    return *b;
}

Json rowToJson(const SweepRow& r) {
    Json j = {{"key", r.key},
              {"backend", scene::toString(r.config.backend)},
              {"label", r.config.label()},
              {"overrides", overridesToJson(r.config.overrides)},
              {"bias_kind", r.config.biasKind},
              {"bias_value", std::isfinite(r.config.biasValue) ? Json(r.config.biasValue) : Json(nullptr)},
              {"repetitions", r.repetitions},
              {"setup_ms", r.setupMs},
              {"frame_ms", r.frameMs},
              {"frame_ms_min", r.frameMsMin},
              {"frame_ms_max", r.frameMsMax},
              {"metrics", r.metrics},
              {"settings", r.settings},
              {"error", r.error},
              {"image", r.image},
              {"diff_image", r.diffImage}};
    if (!r.machine.is_null()) j["machine"] = r.machine;
    if (!r.temporal.is_null()) j["temporal"] = r.temporal;
    return j;
}

SweepRow rowFromJson(const Json& j) {
    SweepRow r;
    r.config.backend = backendFromJson(j.at("backend"));
    r.config.overrides = overridesFromJson(j.at("overrides"));
    r.config.biasKind = j.value("bias_kind", "");
    r.config.biasValue = j.contains("bias_value") && j["bias_value"].is_number()
                             ? j["bias_value"].get<double>()
                             : std::numeric_limits<double>::quiet_NaN();
    r.key = j.at("key").get<std::string>();
    r.repetitions = j.value("repetitions", 0);
    r.setupMs = j.value("setup_ms", 0.0);
    r.frameMs = j.value("frame_ms", 0.0);
    r.frameMsMin = j.value("frame_ms_min", 0.0);
    r.frameMsMax = j.value("frame_ms_max", 0.0);
    r.metrics = j.value("metrics", Json(nullptr));
    r.settings = j.value("settings", Json::object());
    r.error = j.value("error", "");
    r.image = j.value("image", "");
    r.diffImage = j.value("diff_image", "");
    r.machine = j.value("machine", Json(nullptr));
    r.temporal = j.value("temporal", Json(nullptr));
    return r;
}

using scene::appendLine;  // a finished line survives a kill or a power loss

std::string csvField(const std::string& s) {
    if (s.find_first_of(",\"\n") == std::string::npos) return s;
    std::string q = "\"";
    for (char c : s) q += c == '"' ? std::string("\"\"") : std::string(1, c);
    return q + "\"";
}

std::string jsonNumber(const Json& metrics, const char* name) {
    if (!metrics.is_object() || !metrics.contains(name) || !metrics[name].is_number()) return "";
    return number(metrics[name].get<double>());
}

}  // namespace

bool isFilterableName(const std::string& filter) {
    return filter == "vsm" || filter == "evsm2" || filter == "evsm4" || filter == "esm" || filter == "msm";
}

bool isMomentAxis(const std::string& name) {
    return name == "min_variance" || name == "bleeding_reduction" || name == "evsm_positive" ||
           name == "evsm_negative" || name == "esm_exponent" || name == "moment_bias" || name == "blur_width";
}

std::optional<double>& momentOverride(scene::SettingsOverrides& o, const std::string& name) {
    if (name == "min_variance") return o.minVariance;
    if (name == "bleeding_reduction") return o.bleedReduction;
    if (name == "evsm_positive") return o.evsmPositive;
    if (name == "evsm_negative") return o.evsmNegative;
    if (name == "esm_exponent") return o.esmExponent;
    if (name == "moment_bias") return o.momentBias;
    throw std::logic_error("momentOverride: not a real-valued moment parameter: " + name);
}

std::optional<double> momentOverride(const scene::SettingsOverrides& o, const std::string& name) {
    return momentOverride(const_cast<scene::SettingsOverrides&>(o), name);  // read only
}

std::string SweepConfig::key() const {
    std::string k = std::string("backend=") + scene::toString(backend);
    const auto& o = overrides;
    if (o.shadowMapSize) k += ";map=" + std::to_string(*o.shadowMapSize);
    if (o.filter) k += ";filter=" + *o.filter;
    if (o.depthBias) k += ";depth_bias=" + number(*o.depthBias);
    if (o.slopeBias) k += ";slope_bias=" + number(*o.slopeBias);
    if (o.rayBias) k += ";ray_bias=" + *o.rayBias;
    if (o.precision) k += ";precision=" + *o.precision;
    if (o.samples) k += ";samples=" + std::to_string(*o.samples);
    if (o.pcfSize) k += ";pcf_size=" + std::to_string(*o.pcfSize);
    if (o.normalOffset) k += ";normal_offset=" + number(*o.normalOffset);
    if (o.receiverPlaneBias) k += std::string(";receiver_plane_bias=") + (*o.receiverPlaneBias ? "1" : "0");
    if (o.hardwareBias) k += std::string(";hardware_bias=") + (*o.hardwareBias ? "1" : "0");
    if (o.fitLightFrustum) k += std::string(";fit_light_frustum=") + (*o.fitLightFrustum ? "1" : "0");
    if (o.cascades) k += ";cascades=" + std::to_string(*o.cascades);
    // Appended only when set, so the keys of rows without them stay as they were.
    if (o.snapLightFrustum) k += std::string(";snap=") + (*o.snapLightFrustum ? "1" : "0");
    if (o.cascadeBlend) k += ";cascade_blend=" + number(*o.cascadeBlend);
    if (o.minVariance) k += ";min_variance=" + number(*o.minVariance);
    if (o.bleedReduction) k += ";bleeding_reduction=" + number(*o.bleedReduction);
    if (o.evsmPositive) k += ";evsm_positive=" + number(*o.evsmPositive);
    if (o.evsmNegative) k += ";evsm_negative=" + number(*o.evsmNegative);
    if (o.esmExponent) k += ";esm_exponent=" + number(*o.esmExponent);
    if (o.momentBias) k += ";moment_bias=" + number(*o.momentBias);
    if (o.blurWidth) k += ";blur_width=" + std::to_string(*o.blurWidth);
    return k;
}

std::string SweepConfig::settingsText() const {
    std::vector<std::string> parts;
    const auto& o = overrides;
    if (o.shadowMapSize) parts.push_back("map " + std::to_string(*o.shadowMapSize));
    if (o.filter) parts.push_back(*o.filter);
    if (o.depthBias) parts.push_back("depth bias " + shortNumber(*o.depthBias));
    if (o.slopeBias) parts.push_back("slope bias " + shortNumber(*o.slopeBias));
    if (o.rayBias) {
        char* end = nullptr;
        const double v = std::strtod(o.rayBias->c_str(), &end);
        parts.push_back(*o.rayBias == "robust"                       ? "robust offset"
                        : end && *end == '\0' && !o.rayBias->empty() ? "ray bias " + shortNumber(v)
                                                                     : "ray bias " + *o.rayBias);
    }
    if (o.precision) parts.push_back(*o.precision);
    if (o.samples) parts.push_back(std::to_string(*o.samples) + " samples");
    if (o.pcfSize) parts.push_back("pcf size " + std::to_string(*o.pcfSize));
    if (o.normalOffset) parts.push_back("normal offset " + shortNumber(*o.normalOffset));
    if (o.receiverPlaneBias) parts.push_back(*o.receiverPlaneBias ? "receiver-plane bias" : "no receiver-plane bias");
    if (o.hardwareBias) parts.push_back(*o.hardwareBias ? "hardware bias" : "shader bias");
    if (o.fitLightFrustum) parts.push_back(*o.fitLightFrustum ? "fitted frustum" : "bounds frustum");
    if (o.cascades) parts.push_back(std::to_string(*o.cascades) + (*o.cascades == 1 ? " cascade" : " cascades"));
    if (o.snapLightFrustum) parts.push_back(*o.snapLightFrustum ? "snapped" : "unsnapped");
    if (o.cascadeBlend) parts.push_back("blend " + number(*o.cascadeBlend));
    if (o.minVariance) parts.push_back("min variance " + number(*o.minVariance));
    if (o.bleedReduction) parts.push_back("bleeding reduction " + number(*o.bleedReduction));
    if (o.evsmPositive) parts.push_back("evsm+ " + number(*o.evsmPositive));
    if (o.evsmNegative) parts.push_back("evsm- " + number(*o.evsmNegative));
    if (o.esmExponent) parts.push_back("esm exponent " + number(*o.esmExponent));
    if (o.momentBias) parts.push_back("moment bias " + number(*o.momentBias));
    if (o.blurWidth) parts.push_back("blur " + std::to_string(*o.blurWidth));
    std::string s;
    for (std::size_t i = 0; i < parts.size(); ++i) s += (i ? ", " : "") + parts[i];
    return s;
}

std::string SweepConfig::label() const {
    const std::string settings = settingsText();
    return std::string(scene::toString(backend)) + ": " + (settings.empty() ? "defaults" : settings);
}

double SweepRow::temporalValue(const char* name, bool held) const {
    const Json* t = &temporal;
    if (held) t = temporal.is_object() && temporal.contains("held") ? &temporal["held"] : nullptr;
    if (!t || !t->is_object() || !t->contains(name) || !(*t)[name].is_number())
        return std::numeric_limits<double>::quiet_NaN();
    return (*t)[name].get<double>();
}

PathSpec defaultFlickerPath() {
    PathSpec p;
    p.kind = PathKind::SubTexel;
    p.frames = 4;
    return p;
}

std::vector<scene::Scene> flickerScenes(const scene::Scene& scene, const PathSpec& path) {
    return pathScenes(scene, scene::resolveSettings(scene, {}), path);
}

std::string flickerKey(const PathSpec& p) {
    std::string k = std::string("kind=") + toString(p.kind) + ";frames=" + std::to_string(p.frames) +
                    ";amount=" + number(p.amount.value_or(defaultAmount(p.kind))) + ";light=" + std::to_string(p.light);
    if (p.kind == PathKind::GltfAnimation) k += ";animation=" + p.animation;
    return k;
}

double SweepRow::rate(const char* name) const {
    if (!metrics.is_object() || !metrics.contains(name) || !metrics[name].is_number())
        return std::numeric_limits<double>::quiet_NaN();
    return metrics[name].get<double>();
}

double SweepRow::missedBesideTerminatorRate() const {
    const double all = rate("missed_shadow_rate"), terminator = rate("terminator_missed_rate");
    return all - (std::isfinite(terminator) ? terminator : 0.0);
}

SweepGrid defaultGrid(const scene::Scene& scene, bool quick) {
    SweepGrid g;
    g.repetitions = quick ? 2 : 3;
    const int biasMapSize = 1024;
    // World size of one texel of a map fitted to the scene's bounding sphere (settings.h).
    const double texel = 2.0 * scene::defaultDepthBias(scene, biasMapSize);
    const double extent = std::max(scene.bounds().diagonal(), 1e-30);

    // Every raster row names its map explicitly (the defaults fit it to the view and choose the
    // cascades per view): the bounding-sphere map with one cascade unless a row says otherwise, so
    // each row, and the texel unit of the bias series below, means the same on every view.
    auto raster = [&](int size, const std::string& filter) {
        SweepConfig c;
        c.backend = scene::Backend::Raster;
        c.overrides.shadowMapSize = size;
        c.overrides.filter = filter;
        c.overrides.fitLightFrustum = false;
        c.overrides.cascades = 1;
        return c;
    };
    const std::vector<int> sizes = quick ? std::vector<int>{512, 2048} : std::vector<int>{512, 1024, 2048, 4096};
    for (int size : sizes)
        for (const char* filter : {"none", "pcf2x2"}) g.configs.push_back(raster(size, filter));
    // Cascades against one map, where a directional light is shadowed: 3 cascades at the largest
    // quick size and at 1024 (the rows above are the 1-cascade side of the comparison). Three is
    // where the near slice gets most of its gain on our scenes (docs/raster.md); the fourth adds a
    // depth pass for a far slice that rarely needs it.
    bool directional = false;
    for (const scene::Light& l : scene.lights) directional = directional || l.type == scene::LightType::Directional;
    if (directional)
        for (int size : quick ? std::vector<int>{2048} : std::vector<int>{1024, 2048}) {
            SweepConfig c = raster(size, "pcf2x2");
            c.overrides.cascades = 3;
            g.configs.push_back(c);
        }
    // The same default biases through the rasterizer's depth-bias state (--hardware-bias), beside
    // the pcf2x2 row of the largest size: what moving them into the depth pass changes. Only with a
    // directional light (spot and point maps keep the shader's bias).
    if (directional) {
        SweepConfig c = raster(sizes.back(), "pcf2x2");
        c.overrides.hardwareBias = true;
        g.configs.push_back(c);
    }
    // The filterable maps, one row each at their default parameters beside pcf2x2 of the largest
    // size (the same map), so the error-vs-time plot shows which technique buys the most per
    // millisecond; their parameter windows are a grid file's axes (docs/sweep.md).
    for (const char* filter : {"vsm", "evsm2", "evsm4", "esm", "msm"})
        g.configs.push_back(raster(sizes.back(), filter));
    // The map fitted to what the camera sees (the default fitting, one cascade) against the
    // bounding-sphere maps above, at each size: what the fitted frustum gains on this view.
    for (int size : sizes) {
        SweepConfig c = raster(size, "pcf2x2");
        c.overrides.fitLightFrustum = true;
        g.configs.push_back(c);
    }

    // Constant depth bias alone (slope 0), then slope bias alone (constant 0): each series shows
    // one parameter's acne-to-leak trade-off and its bias window.
    const std::vector<double> texels = quick ? std::vector<double>{0, 0.25, 1, 4, 16, 64}
                                             : std::vector<double>{0, 0.125, 0.25, 0.5, 1, 2, 4, 8, 16, 32, 64};
    for (double k : texels) {
        SweepConfig c = raster(biasMapSize, "none");
        c.overrides.depthBias = k * texel;
        c.overrides.slopeBias = 0.0;
        c.biasKind = "depth";
        c.biasValue = k * texel;
        g.configs.push_back(c);
    }
    // No zero here: depth 0 + slope 0 is the first point of the depth series, shared by both.
    const std::vector<double> slopes =
        quick ? std::vector<double>{0.5, 2, 8} : std::vector<double>{0.25, 0.5, 1, 2, 4, 8, 16};
    for (double s : slopes) {
        SweepConfig c = raster(biasMapSize, "none");
        c.overrides.depthBias = 0.0;
        c.overrides.slopeBias = s;
        c.biasKind = "slope";
        c.biasValue = s;
        g.configs.push_back(c);
    }

    // The lesson's constant ray bias in float, from none to a tenth of the scene.
    const std::vector<int> decades =
        quick ? std::vector<int>{-8, -6, -4, -2} : std::vector<int>{-9, -8, -7, -6, -5, -4, -3, -2, -1};
    std::vector<double> rayBiases{0.0};
    for (int d : decades) rayBiases.push_back(extent * std::pow(10.0, d));
    for (double b : rayBiases) {
        SweepConfig c;
        c.backend = scene::Backend::Raytrace;
        c.overrides.rayBias = number(b);
        c.overrides.precision = "float";
        c.biasKind = "ray";
        c.biasValue = b;
        g.configs.push_back(c);
    }
    for (const char* precision : {"float", "double"}) {
        SweepConfig c;
        c.backend = scene::Backend::Raytrace;
        c.overrides.rayBias = "robust";
        c.overrides.precision = precision;
        g.configs.push_back(c);
    }
    return g;
}

SweepGrid loadGrid(const fs::path& file, const scene::Scene& scene) {
    using scene::JsonPath;
    using scene::SceneError;
    std::string text;
    try {
        text = scene::readInputFile(file, scene::kMaxJsonFileBytes);
    } catch (const scene::InputFileError& e) {
        throw SceneError(file, {}, e.problem());
    }
    const Json doc = scene::parseJsonText(file, text);
    const JsonPath root;
    if (!doc.is_object()) throw SceneError(file, root, "expected an object");
    SweepGrid g;
    g.configs.clear();
    // A backend's block is named by the backend (scene::parseBackend); the reference has none.
    auto backendBlock = [](const std::string& key) {
        const std::optional<scene::Backend> b = scene::parseBackend(key);
        return b == scene::Backend::Raster || b == scene::Backend::Raytrace;
    };
    for (const auto& [key, value] : doc.items()) {
        if (key != "repetitions" && key != "resolution" && !backendBlock(key) && key != "include_default" &&
            key != "flicker")
            throw SceneError(
                file, root / key,
                "unknown key; allowed: repetitions, resolution, raster, raytrace, include_default, flicker");
    }
    if (doc.contains("repetitions")) {
        const Json& r = doc["repetitions"];
        if (!r.is_number_integer() || r.get<long long>() < 1 || r.get<long long>() > 100)
            throw SceneError(file, root / "repetitions", "must be an integer in 1..100");
        g.repetitions = r.get<int>();
    }
    if (doc.contains("resolution")) {
        // Checked here as runSweep() will read it, so a bad value is named with its file and path.
        int w = 0, h = 0;
        char x = 0, extra = 0;
        const Json& res = doc["resolution"];
        if (!res.is_string() || std::sscanf(res.get<std::string>().c_str(), "%d%c%d%c", &w, &x, &h, &extra) != 3 ||
            x != 'x' || w < 1 || h < 1 || w > 16384 || h > 16384)
            throw SceneError(file, root / "resolution",
                             "expected \"WxH\" with sides in 1..16384, got " + scene::describeJson(res));
        g.resolution = res.get<std::string>();
    }
    if (doc.contains("flicker")) {
        // true: the default path; an object: its kind, frames, amount and light (docs/sweep.md).
        const Json& f = doc["flicker"];
        const JsonPath at = root / "flicker";
        if (f.is_boolean()) {
            if (f.get<bool>()) g.flicker = defaultFlickerPath();
        } else if (f.is_object()) {
            PathSpec p = defaultFlickerPath();
            for (const auto& [k, v] : f.items()) {
                if (k == "kind") {
                    if (!v.is_string())
                        throw SceneError(file, at / k, "expected a path kind, got " + scene::describeJson(v));
                    try {
                        p.kind = parsePathKind(v.get<std::string>());
                    } catch (const scene::InputError& e) {
                        throw SceneError(file, at / k, std::string(e.what()).substr(std::string("--kind: ").size()));
                    }
                } else if (k == "frames") {
                    if (!v.is_number_integer() || v.get<long long>() < 2 || v.get<long long>() > 64)
                        throw SceneError(
                            file, at / k,
                            "expected an integer in 2..64 (every row renders them), got " + scene::describeJson(v));
                    p.frames = v.get<int>();
                } else if (k == "amount") {
                    if (!v.is_number() || !std::isfinite(v.get<double>()))
                        throw SceneError(file, at / k, "expected a finite number, got " + scene::describeJson(v));
                    p.amount = v.get<double>();
                } else if (k == "light") {
                    if (!v.is_number_integer() || v.get<long long>() < 0 || v.get<long long>() > 1000)
                        throw SceneError(file, at / k, "expected a light index, got " + scene::describeJson(v));
                    p.light = v.get<int>();
                } else if (k == "animation") {
                    if (!v.is_string()) throw SceneError(file, at / k, "expected a name or index as a string");
                    p.animation = v.get<std::string>();
                } else {
                    throw SceneError(file, at / k, "unknown key; allowed: kind, frames, amount, light, animation");
                }
            }
            g.flicker = p;
        } else {
            throw SceneError(
                file, at,
                "expected true, false or an object {kind, frames, amount, light}, got " + scene::describeJson(f));
        }
        if (g.flicker) {
            try {
                flickerScenes(scene, *g.flicker);
            } catch (const scene::InputError& e) {
                throw SceneError(file, at, e.what());
            }
        }
    }
    if (doc.contains("include_default") && !doc["include_default"].is_boolean())
        throw SceneError(file, root / "include_default",
                         "expected true or false, got " + scene::describeJson(doc["include_default"]));
    if (doc.value("include_default", false)) g.configs = defaultGrid(scene, false).configs;

    // Each backend block holds axes (arrays); the grid is their cartesian product.
    auto axis = [&](const Json& block, const JsonPath& path, const char* name) {
        std::vector<Json> values;
        if (!block.contains(name)) return values;
        const Json& v = block[name];
        if (!v.is_array() || v.empty()) throw SceneError(file, path / name, "expected a non-empty array of values");
        if (v.size() > 1000) throw SceneError(file, path / name, "more than 1000 values");
        for (std::size_t i = 0; i < v.size(); ++i) values.push_back(v[i]);
        return values;
    };
    for (const scene::Backend backend : {scene::Backend::Raster, scene::Backend::Raytrace}) {
        const std::string section = scene::toString(backend);
        if (!doc.contains(section)) continue;
        const Json& block = doc[section];
        const JsonPath path = root / section;
        if (!block.is_object()) throw SceneError(file, path, "expected an object of axes");
        const bool isRaster = backend == scene::Backend::Raster;
        const std::vector<const char*> names = isRaster ? std::vector<const char*>{"shadow_map_size",
                                                                                   "filter",
                                                                                   "cascades",
                                                                                   "cascade_blend",
                                                                                   "fit_light_frustum",
                                                                                   "snap_light_frustum",
                                                                                   "receiver_plane_bias",
                                                                                   "hardware_bias",
                                                                                   "depth_bias",
                                                                                   "slope_bias",
                                                                                   "min_variance",
                                                                                   "bleeding_reduction",
                                                                                   "evsm_positive",
                                                                                   "evsm_negative",
                                                                                   "esm_exponent",
                                                                                   "moment_bias",
                                                                                   "blur_width"}
                                                        : std::vector<const char*>{"ray_bias", "precision", "samples"};
        for (const auto& [key, value] : block.items())
            if (std::none_of(names.begin(), names.end(), [&](const char* n) { return key == n; }))
                throw SceneError(file, path / key, "unknown axis for " + section);
        std::vector<SweepConfig> configs{SweepConfig{backend}};
        // A bias axis with one value holds that bias fixed; it is not the series the rows sample.
        std::size_t depthValues = 0;
        for (const char* name : names) {
            const std::vector<Json> values = axis(block, path, name);
            if (values.empty()) continue;
            if (std::string(name) == "depth_bias") depthValues = values.size();
            // The product is bounded before it is built: axes of 1000 values each multiply to
            // more configurations than memory holds.
            if (configs.size() * values.size() > kMaxGridConfigurations)
                throw SceneError(file, path / name,
                                 "the grid would have at least " + std::to_string(configs.size() * values.size()) +
                                     " configurations, more than " + std::to_string(kMaxGridConfigurations));
            std::vector<SweepConfig> next;
            next.reserve(configs.size() * values.size());
            for (const SweepConfig& base : configs)
                for (std::size_t i = 0; i < values.size(); ++i) {
                    const Json& v = values[i];
                    const JsonPath at = path / name / i;
                    SweepConfig c = base;
                    const std::string n = name;
                    auto num = [&](double lo) {
                        if (!v.is_number() || !std::isfinite(v.get<double>()) || v.get<double>() < lo)
                            throw SceneError(file, at,
                                             "expected a number >= " + number(lo) + ", got " + scene::describeJson(v));
                        return v.get<double>();
                    };
                    if (n == "shadow_map_size") {
                        if (!v.is_number_integer() || v.get<long long>() < 16 || v.get<long long>() > 16384)
                            throw SceneError(file, at,
                                             "expected an integer in 16..16384, got " + scene::describeJson(v));
                        c.overrides.shadowMapSize = v.get<int>();
                    } else if (n == "filter") {
                        const std::string f = v.is_string() ? v.get<std::string>() : std::string();
                        static const char* kFilters[] = {"none", "pcf2x2", "pcf",   "poisson", "pcss",
                                                         "vsm",  "evsm2",  "evsm4", "esm",     "msm"};
                        if (std::none_of(std::begin(kFilters), std::end(kFilters),
                                         [&](const char* k) { return f == k; }))
                            throw SceneError(file, at,
                                             "expected \"none\", \"pcf2x2\", \"pcf\", \"poisson\", \"pcss\", "
                                             "\"vsm\", \"evsm2\", \"evsm4\", \"esm\" or \"msm\", got " +
                                                 scene::describeJson(v));
                        c.overrides.filter = f;
                    } else if (n == "cascade_blend") {
                        const double b = num(0.0);
                        if (b > scene::kMaxCascadeBlend)
                            throw SceneError(
                                file, at,
                                "expected a number in 0..0.5 (a fraction of a slice), got " + scene::describeJson(v));
                        c.overrides.cascadeBlend = b;
                    } else if (n == "fit_light_frustum") {
                        if (!v.is_boolean())
                            throw SceneError(file, at, "expected true or false, got " + scene::describeJson(v));
                        c.overrides.fitLightFrustum = v.get<bool>();
                    } else if (n == "snap_light_frustum") {
                        if (!v.is_boolean())
                            throw SceneError(file, at, "expected true or false, got " + scene::describeJson(v));
                        c.overrides.snapLightFrustum = v.get<bool>();
                    } else if (n == "cascades") {
                        if (!v.is_number_integer() || v.get<long long>() < 1 ||
                            v.get<long long>() > scene::kMaxCascades)
                            throw SceneError(file, at,
                                             "expected an integer in 1.." + std::to_string(scene::kMaxCascades) +
                                                 " (cascaded shadow maps per directional light), got " +
                                                 scene::describeJson(v));
                        c.overrides.cascades = v.get<int>();
                    } else if (n == "receiver_plane_bias") {
                        if (!v.is_boolean())
                            throw SceneError(file, at, "expected true or false, got " + scene::describeJson(v));
                        c.overrides.receiverPlaneBias = v.get<bool>();
                    } else if (n == "hardware_bias") {
                        if (!v.is_boolean())
                            throw SceneError(file, at, "expected true or false, got " + scene::describeJson(v));
                        c.overrides.hardwareBias = v.get<bool>();
                    } else if (n == "depth_bias") {
                        c.overrides.depthBias = num(0.0);
                        c.biasKind = "depth";
                        c.biasValue = *c.overrides.depthBias;
                    } else if (n == "slope_bias") {
                        c.overrides.slopeBias = num(0.0);
                        if (c.biasKind.empty() || (depthValues == 1 && values.size() > 1)) {
                            c.biasKind = "slope";
                            c.biasValue = *c.overrides.slopeBias;
                        }
                    } else if (isMomentAxis(n)) {
                        // A filterable map's own parameter: ranges as resolveSettings checks them
                        // (below); an axis of several values is the series its window is read from.
                        if (n == "blur_width") {
                            if (!v.is_number_integer() || v.get<long long>() < 1 ||
                                v.get<long long>() > scene::kMaxBlurWidth || v.get<long long>() % 2 == 0)
                                throw SceneError(file, at,
                                                 "expected an odd integer in 1.." +
                                                     std::to_string(scene::kMaxBlurWidth) + " (texels), got " +
                                                     scene::describeJson(v));
                            c.overrides.blurWidth = v.get<int>();
                        } else {
                            // The ranges resolveSettings() accepts (scene/settings.cpp), checked
                            // here so a bad value is named with its JSON path.
                            const double hi = n == "min_variance" || n == "moment_bias" ? 1.0
                                              : n == "bleeding_reduction"               ? 0.99
                                              : n == "esm_exponent"                     ? scene::kMaxEsmExponent
                                                                                        : scene::kMaxEvsmExponent;
                            const double x = num(0.0);
                            if (x > hi)
                                throw SceneError(
                                    file, at,
                                    "expected a number in 0.." + number(hi) + ", got " + scene::describeJson(v));
                            momentOverride(c.overrides, n) = x;
                            if (values.size() > 1 &&
                                (c.biasKind.empty() || isFilterableName(c.overrides.filter.value_or("")))) {
                                c.biasKind = n;
                                c.biasValue = x;
                            }
                        }
                    } else if (n == "ray_bias") {
                        if (v.is_string() && v.get<std::string>() == "robust") {
                            c.overrides.rayBias = "robust";
                        } else {
                            c.overrides.rayBias = number(num(0.0));
                            c.biasKind = "ray";
                            c.biasValue = v.get<double>();
                        }
                    } else if (n == "precision") {
                        if (!v.is_string() || (v.get<std::string>() != "float" && v.get<std::string>() != "double"))
                            throw SceneError(file, at,
                                             "expected \"float\" or \"double\", got " + scene::describeJson(v));
                        c.overrides.precision = v.get<std::string>();
                    } else if (n == "samples") {
                        if (!v.is_number_integer() || v.get<long long>() < 1 || v.get<long long>() > 65536)
                            throw SceneError(file, at,
                                             "expected an integer in 1..65536, got " + scene::describeJson(v));
                        c.overrides.samples = v.get<int>();
                    }
                    next.push_back(c);
                }
            configs = std::move(next);
        }
        if (g.configs.size() + configs.size() > kMaxGridConfigurations)
            throw SceneError(
                file, path,
                "the grid would have more than " + std::to_string(kMaxGridConfigurations) + " configurations");
        g.configs.insert(g.configs.end(), configs.begin(), configs.end());
    }
    if (g.configs.empty()) throw SceneError(file, root, "the grid is empty: give a \"raster\" or \"raytrace\" block");
    // Validate every configuration's settings now, before anything renders or is written.
    for (std::size_t i = 0; i < g.configs.size(); ++i) {
        try {
            scene::resolveSettings(scene, g.configs[i].overrides);
        } catch (const scene::InputError& e) {
            throw SceneError(file, root / scene::toString(g.configs[i].backend),
                             std::string("configuration ") + g.configs[i].label() + ": " + e.what());
        }
    }
    return g;
}

scene::Frame renderWithBackend(const scene::Scene& scene, const scene::RenderSettings& settings,
                               scene::Backend backend) {
    scene::Frame f = renderFrame(backend, scene, scene::makeRenderPlan(scene, settings), settings);
    scene::recordIdentity(f, scene);
    return f;
}

bool isRenderWithBackend(const RenderFn& render) {
    using Fn = scene::Frame (*)(const scene::Scene&, const scene::RenderSettings&, scene::Backend);
    const Fn* fn = render.target<Fn>();
    return fn && *fn == &renderWithBackend;
}

namespace {

// The frames of one configuration: with the default render function, a raster or ray-traced
// configuration renders its warm-up and timed frames with one renderer, so the device, pipelines,
// geometry and shadow maps, or the acceleration structures, are set up once (the warm-up frame's
// "setup"), as a program that renders frames would; fakes passed in by tests render each frame
// anew.
std::function<scene::Frame()> frameSource(const SweepOptions& options, const scene::Scene& scene,
                                          const scene::RenderSettings& settings, scene::Backend backend) {
    if ((backend == scene::Backend::Raster || backend == scene::Backend::Raytrace) &&
        isRenderWithBackend(options.render)) {
        std::shared_ptr<BackendRenderer> renderer =
            makeRenderer(backend, scene, scene::makeRenderPlan(scene, settings), settings);
        auto first = std::make_shared<bool>(true);
        return [renderer, first, backend, &scene] {
            scene::Frame f = renderer->render();
            // The ray tracer's frames report no setup of their own (its trees are built by the
            // constructor): the first carries the constructor's, as the raster renderer's does.
            if (backend == scene::Backend::Raytrace && *first)
                for (auto& [stage, ms] : f.timingsMs)
                    if (stage == "setup") ms = renderer->setupMs();
            *first = false;
            scene::recordIdentity(f, scene);
            return f;
        };
    }
    return [&options, &scene, &settings, backend] { return options.render(scene, settings, backend); };
}

std::vector<const scene::Frame*> pointersTo(const std::vector<scene::Frame>& frames) {
    std::vector<const scene::Frame*> p;
    for (const scene::Frame& f : frames) p.push_back(&f);
    return p;
}

Json temporalFigures(const compare::TemporalSummary& t) {
    Json pairs = Json::array();
    for (const compare::PairStability& p : t.pairs) pairs.push_back(p.flicker);
    return {{"flicker_rate", t.meanFlickerRate},
            {"max_flicker_rate", t.maxFlickerRate},
            {"flicker_px", t.totalFlicker},
            {"error_variation", t.meanErrorVariation},
            {"swim_px", t.meanSwimPixels},
            {"edge_offset_px", t.meanEdgeOffset},
            {"pairs", pairs}};
}

// One configuration along the flicker axis's path, measured against the path's references. With
// the default render function one Renderer (raster) or acceleration structure (ray tracer) serves
// every frame, as `path` renders them, and a camera path adds the raster held view (each frame's
// shadow setup drawn from frame 0's camera, docs/temporal.md); other render functions render each
// frame anew and have no held view.
Json rowTemporal(const SweepOptions& options, const PathSpec& spec, const std::vector<scene::Scene>& scenes,
                 const std::vector<scene::Frame>& refs, const scene::RenderSettings& settings, scene::Backend backend) {
    const bool real = isRenderWithBackend(options.render);
    std::vector<scene::Frame> frames, held;
    if (real && (backend == scene::Backend::Raster || backend == scene::Backend::Raytrace)) {
        const std::unique_ptr<BackendRenderer> r =
            makeRenderer(backend, scenes[0], scene::makeRenderPlan(scenes[0], settings), settings);
        for (const scene::Scene& s : scenes) {
            r->update(s);
            frames.push_back(r->render());
            if (backend == scene::Backend::Raster && isCameraPath(spec.kind)) {
                r->update(s, scenes[0].camera);
                held.push_back(r->render());
            }
        }
        if (settings.raster.validate && r->validationMessages() > 0)
            throw std::runtime_error("the Vulkan validation layer reported " + std::to_string(r->validationMessages()) +
                                     " message(s) along the flicker path (printed above)");
    } else {
        for (const scene::Scene& s : scenes) frames.push_back(options.render(s, settings, backend));
    }
    Json j = temporalFigures(compare::measureTemporal(pointersTo(frames), pointersTo(refs)));
    j["path"] = toString(spec.kind);
    j["frames"] = int(scenes.size());
    if (!held.empty()) {
        const std::vector<const scene::Frame*> still(held.size(), &refs[0]);
        j["held"] = temporalFigures(compare::measureTemporal(pointersTo(held), still));
    }
    return j;
}

}  // namespace

std::vector<SweepRow> readJournal(const fs::path& file) {
    std::vector<SweepRow> rows;
    std::error_code ec;
    if (!fs::exists(file, ec)) return rows;
    std::istringstream in(scene::readInputFile(file, scene::kMaxJournalFileBytes));
    std::string line;
    while (std::getline(in, line)) {
        if (line.empty() || !scene::jsonNestingProblem(line).empty()) continue;
        try {
            rows.push_back(rowFromJson(Json::parse(line)));
        } catch (const std::exception&) {
            // A line cut short by a kill: the row did not finish, so it runs again on resume.
        }
    }
    return rows;
}

std::string rowsToCsv(const std::vector<SweepRow>& rows) {
    static const char* kMetrics[] = {"counted",
                                     "false_shadow",
                                     "missed_shadow",
                                     "false_shadow_rate",
                                     "missed_shadow_rate",
                                     "mismatch_rate",
                                     "mean_abs_visibility_error",
                                     "mean_abs_visibility_error_penumbra",
                                     "soft_error_rate",
                                     "shadow_iou",
                                     "self_shadow_acne_rate",
                                     "aliasing_rate",
                                     "bias_error_rate",
                                     "silhouette_mismatch_rate",
                                     "invalid"};
    std::ostringstream s;
    s << "key,backend,label,shadow_map_size,filter,cascades,depth_bias,slope_bias,ray_bias,precision,samples,"
         "bias_kind,bias_value,repetitions,setup_ms,frame_ms,frame_ms_min,frame_ms_max";
    for (const char* m : kMetrics) s << "," << m;
    s << ",error,machine";
    // The flicker axis's columns, only when a row has them: a sweep without it writes what it did.
    static const char* kTemporal[] = {"flicker_rate", "flicker_px", "error_variation", "swim_px", "edge_offset_px"};
    const bool temporal =
        std::any_of(rows.begin(), rows.end(), [](const SweepRow& r) { return !r.temporal.is_null(); });
    if (temporal) {
        s << ",flicker_path";
        for (const char* t : kTemporal) s << "," << t;
        for (const char* t : kTemporal) s << ",held_" << t;
    }
    s << "\n";
    for (const SweepRow& r : rows) {
        const auto& o = r.config.overrides;
        s << csvField(r.key) << "," << scene::toString(r.config.backend) << "," << csvField(r.config.label()) << ","
          << (o.shadowMapSize ? std::to_string(*o.shadowMapSize) : "") << "," << o.filter.value_or("") << ","
          << (o.cascades ? std::to_string(*o.cascades) : "") << "," << (o.depthBias ? number(*o.depthBias) : "") << ","
          << (o.slopeBias ? number(*o.slopeBias) : "") << "," << o.rayBias.value_or("") << ","
          << o.precision.value_or("") << "," << (o.samples ? std::to_string(*o.samples) : "") << ","
          << r.config.biasKind << "," << (std::isfinite(r.config.biasValue) ? number(r.config.biasValue) : "") << ","
          << r.repetitions << "," << number(r.setupMs) << "," << number(r.frameMs) << "," << number(r.frameMsMin) << ","
          << number(r.frameMsMax);
        for (const char* m : kMetrics) s << "," << jsonNumber(r.metrics, m);
        s << "," << csvField(r.error) << "," << csvField(machineFromJson(r.machine).host);
        if (temporal) {
            s << "," << csvField(r.temporal.is_object() ? r.temporal.value("path", "") : "");
            for (bool held : {false, true})
                for (const char* t : kTemporal) {
                    const double v = r.temporalValue(t, held);
                    s << "," << (std::isfinite(v) ? number(v) : "");
                }
        }
        s << "\n";
    }
    return s.str();
}

Json rowsToJson(const std::vector<SweepRow>& rows) {
    Json a = Json::array();
    for (const SweepRow& r : rows) a.push_back(rowToJson(r));
    return a;
}

scene::Scene sweepScene(const scene::Scene& baseScene, const SweepGrid& grid) {
    scene::Scene scene = baseScene;
    if (grid.resolution) {
        int w = 0, h = 0;
        char x = 0;
        char extra = 0;
        if (std::sscanf(grid.resolution->c_str(), "%d%c%d%c", &w, &x, &h, &extra) != 3 || (x != 'x' && x != 'X') ||
            w < 1 || h < 1 || w > 16384 || h > 16384 || static_cast<long long>(w) * h > (64LL << 20))
            throw scene::InputError("sweep resolution: expected WxH, got '" + *grid.resolution + "'");
        scene.camera.width = w;
        scene.camera.height = h;
    }
    return scene;
}

JobMemory estimateSweepMemory(const scene::Scene& baseScene, const SweepGrid& grid,
                              const scene::SettingsOverrides& user) {
    const scene::Scene scene = sweepScene(baseScene, grid);
    std::uint64_t largest = 0;
    auto consider = [&](scene::Backend backend, const scene::SettingsOverrides& overrides) {
        const scene::RenderSettings s = scene::resolveSettings(scene, overrides);
        largest = std::max(largest, estimateMemoryBytes(backend, scene, scene::makeRenderPlan(scene, s), s));
    };
    consider(scene::Backend::Reference, {});
    bool raster = false, traced = false;
    for (const SweepConfig& c : grid.configs) {
        consider(c.backend, c.overrides);
        (c.backend == scene::Backend::Raster ? raster : traced) = true;
    }
    // The recommendation's search, in the user's settings, for each backend the rows have.
    if (raster) consider(scene::Backend::Raster, user);
    if (traced) consider(scene::Backend::Raytrace, user);
    // The reference, a row's frame, the recommendation's defaults and point; along a flicker path
    // its references, a row's frames and (raster, a camera path) the held view's.
    const std::uint64_t pathFrames = grid.flicker ? std::uint64_t(std::max(grid.flicker->frames, 0)) : 0;
    const std::uint64_t frames = 4 + 3 * pathFrames;
    return {scene::kProgramBytes + scene::sceneBytes(scene) + largest + frames * scene::frameBytes(scene) +
                scene::frameWriteBytes(scene),
            largest};
}

Json journalRow(const SweepRow& row) { return rowToJson(row); }
SweepRow rowFromJournal(const Json& line) { return rowFromJson(line); }

SweepResult runSweep(const scene::Scene& baseScene, const SweepGrid& grid, const SweepOptions& options) {
    using Clock = std::chrono::steady_clock;
    const auto start = Clock::now();
    const fs::path dir = options.outputDir;
    const fs::path journal = dir / "results.jsonl";
    const fs::path manifest = dir / "sweep.json";

    const scene::Scene scene = sweepScene(baseScene, grid);
    Json identity = {{"scene", scene.file.string()}, {"resolution", {scene.camera.width, scene.camera.height}}};
    if (grid.flicker) identity["flicker"] = flickerKey(*grid.flicker);  // absent without the axis

    std::error_code ec;
    if (fs::exists(journal, ec) && !options.resume)
        throw scene::InputError(dir.string() +
                                ": already holds a sweep (results.jsonl); use --resume to "
                                "continue it, or choose another folder");
    std::vector<SweepRow> done;
    if (options.resume && fs::exists(journal, ec) && !fs::exists(manifest, ec))
        throw scene::InputError(dir.string() +
                                ": has results.jsonl but no sweep.json, so the scene it belongs "
                                "to is unknown; choose another folder");
    if (options.resume && fs::exists(manifest, ec)) {
        const std::string manifestText = scene::readInputFile(manifest, scene::kMaxJsonFileBytes);
        Json old;
        try {
            old = scene::parseJsonText(manifest, manifestText);
        } catch (const std::exception&) {
            old = nullptr;
        }
        if (old != identity)
            throw scene::InputError(
                dir.string() + ": holds a sweep of another scene or resolution (" +
                (old.is_null() ? std::string("unreadable sweep.json") : scene::describeJson(old, 200)) + ")");
        scene::removeStaleTemporaries(dir);
        scene::removeStaleTemporaries(dir / "images");
        done = readJournal(journal);
        // Failed configurations run again on resume (the failure may have been the machine's).
        done.erase(std::remove_if(done.begin(), done.end(), [](const SweepRow& r) { return !r.error.empty(); }),
                   done.end());
        // Rewrite the journal without a torn last line before appending to it again.
        std::string text;
        for (const SweepRow& r : done) text += rowToJson(r).dump() + "\n";
        scene::writeTextAtomic(journal, text);
    }
    fs::create_directories(dir / "images");
    scene::writeTextAtomic(manifest, identity.dump(2) + "\n");

    SweepResult result;
    // The reference is rendered once per scene and resolution, and reused on resume.
    const fs::path refFile = dir / "reference.exr";
    bool haveReference = false;
    if (options.resume && fs::exists(refFile, ec)) {
        try {
            result.reference = scene::readFrame(refFile);
            haveReference =
                result.reference.width == scene.camera.width && result.reference.height == scene.camera.height;
        } catch (const std::exception&) {
            haveReference = false;
        }
    }
    if (!haveReference && options.reference) {
        result.reference = options.reference(scene);
    } else if (!haveReference) {
        const scene::RenderSettings settings = scene::resolveSettings(scene, {});
        result.reference = options.render(scene, settings, scene::Backend::Reference);
        result.reference.attributes["scene"] = scene.file.string();
        scene::writeFrame(result.reference, refFile);
        scene::writePngLinear(dir / "reference.png", result.reference.width, result.reference.height,
                              result.reference.beauty);
    }
    result.referenceMs = result.reference.totalTimeMs();

    std::map<std::string, SweepRow> byKey;
    for (SweepRow& r : done) byKey[r.key] = std::move(r);

    // The flicker axis: the path's frames, and their references (rendered when a row first needs
    // them, cached as DIR/flicker/reference-NNNN.exr; frame 0 is the sweep's reference).
    std::vector<scene::Scene> pathFrames;
    std::vector<scene::Frame> pathReferences;
    if (grid.flicker) pathFrames = flickerScenes(scene, *grid.flicker);
    auto pathReferencesReady = [&]() -> const std::vector<scene::Frame>& {
        if (!pathReferences.empty() || pathFrames.empty()) return pathReferences;
        fs::create_directories(dir / "flicker");
        pathReferences.push_back(result.reference);
        for (std::size_t t = 1; t < pathFrames.size(); ++t) {
            char name[40];
            std::snprintf(name, sizeof name, "reference-%04zu.exr", t);
            const fs::path file = dir / "flicker" / name;
            scene::Frame f;
            bool cached = false;
            if (fs::exists(file, ec)) {
                try {
                    f = scene::readFrame(file);
                    cached = f.width == scene.camera.width && f.height == scene.camera.height;
                } catch (const std::exception&) {
                    cached = false;
                }
            }
            if (!cached) {
                f = options.render(pathFrames[t], scene::resolveSettings(pathFrames[t], {}), scene::Backend::Reference);
                scene::writeFrame(f, file);
            }
            pathReferences.push_back(std::move(f));
        }
        return pathReferences;
    };

    SweepProgress progress;
    progress.total = grid.configs.size();
    std::vector<SweepRow> rows;
    std::size_t renderedHere = 0;
    std::set<std::string> seen;  // a grid may name the same configuration twice: render it once
    for (const SweepConfig& config : grid.configs) {
        const std::string key = config.key();
        if (!seen.insert(key).second) {
            --progress.total;
            continue;
        }
        if (const auto it = byKey.find(key); it != byKey.end()) {
            rows.push_back(it->second);
            ++progress.done;
            ++progress.skipped;
            continue;
        }
        SweepRow row;
        row.config = config;
        row.key = key;
        try {
            const scene::RenderSettings settings = scene::resolveSettings(scene, config.overrides);
            // One warm-up frame (shader compilation, caches) that is not timed, then the runs. The
            // row's renderer goes before the flicker path makes its own: one renderer at a time
            // (estimateSweepMemory).
            scene::Frame frame;
            double warmUpSetup = 0.0;
            std::vector<double> setups, frames;
            {
                const std::function<scene::Frame()> renderFrame = frameSource(options, scene, settings, config.backend);
                frame = renderFrame();
                warmUpSetup = frame.timing("setup");
                for (int i = 0; i < grid.repetitions; ++i) {
                    frame = renderFrame();
                    const double setup = frame.timing("setup");
                    setups.push_back(setup);
                    frames.push_back(frame.totalTimeMs() - setup);
                }
            }
            row.repetitions = grid.repetitions;
            // A reused renderer paid its setup in the warm-up frame only.
            row.setupMs = median(setups) > 0.0 ? median(setups) : warmUpSetup;
            row.frameMs = median(frames);
            row.frameMsMin = *std::min_element(frames.begin(), frames.end());
            row.frameMsMax = *std::max_element(frames.begin(), frames.end());
            const compare::Comparison c = compare::compareFrames(frame, result.reference);
            row.metrics = toJson(c.metrics);
            if (grid.flicker)
                row.temporal =
                    rowTemporal(options, *grid.flicker, pathFrames, pathReferencesReady(), settings, config.backend);
            row.settings = frame.attributes;
            if (options.writeImages) {
                const std::string name = std::string(scene::toString(config.backend)) + "-" + shortHash(key);
                row.image = "images/" + name + ".png";
                row.diffImage = "images/" + name + "-diff.png";
                scene::writePngLinear(dir / row.image, frame.width, frame.height, frame.beauty);
                scene::writePngDisplay(dir / row.diffImage, c.width, c.height, c.diffRgb);
            }
        } catch (const scene::InputError&) {
            throw;
        } catch (const scene::OutputError&) {
            throw;  // a full disk fails the sweep, not one row after another
        } catch (const std::exception& e) {
            row.error = e.what();
            row.metrics = nullptr;
        }
        row.machine = toJson(currentMachine());
        appendLine(journal, rowToJson(row).dump());
        rows.push_back(row);
        ++renderedHere;
        scene::writeTextAtomic(dir / "results.csv", rowsToCsv(rows));
        scene::writeTextAtomic(dir / "results.json", rowsToJson(rows).dump(1) + "\n");

        ++progress.done;
        progress.row = &rows.back();
        progress.elapsedSeconds = std::chrono::duration<double>(Clock::now() - start).count();
        const std::size_t remaining = progress.total - progress.done;
        progress.etaSeconds = progress.elapsedSeconds / double(renderedHere) * double(remaining);
        if (options.progress) options.progress(progress);
    }
    scene::writeTextAtomic(dir / "results.csv", rowsToCsv(rows));
    scene::writeTextAtomic(dir / "results.json", rowsToJson(rows).dump(1) + "\n");
    result.rows = std::move(rows);
    return result;
}

}  // namespace shadowlab::studies
