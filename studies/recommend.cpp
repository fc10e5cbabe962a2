// studies/recommend.cpp: searches depth × slope bias in the user's own raster configuration,
// verifies the best point and the sweep's ray-tracer choice at the requested resolution against
// the user's defaults, and writes the block that never loses to them.
#include "studies/recommend.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <memory>
#include <set>

#include "compare/compare.h"
#include "compare/text.h"
#include "scene/frame_identity.h"
#include "studies/backend.h"

namespace shadowlab::studies {

namespace {

using Json = nlohmann::json;

std::string sizeText(const scene::Scene& s) {
    return std::to_string(s.camera.width) + "x" + std::to_string(s.camera.height);
}

// The smallest positive number of an attribute holding one value or several joined by ';'.
double smallestPositive(const std::string& text) {
    double best = 0.0;
    std::size_t at = 0;
    while (at < text.size()) {
        const std::size_t end = std::min(text.find(';', at), text.size());
        char* stop = nullptr;
        const std::string part = text.substr(at, end - at);
        const double v = std::strtod(part.c_str(), &stop);
        if (stop != part.c_str() && std::isfinite(v) && v > 0.0 && (best == 0.0 || v < best)) best = v;
        at = end + 1;
    }
    return best;
}

std::string attribute(const scene::Frame& f, const char* key) {
    const auto it = f.attributes.find(key);
    return it == f.attributes.end() ? std::string() : it->second;
}

// What makes a rendered frame unusable (validation messages, non-finite values), or "".
std::string frameError(const scene::Frame& f, const scene::RenderSettings& settings, scene::Backend backend) {
    std::string error;
    const std::string messages = attribute(f, "validation_messages");
    if (settings.raster.validate && backend == scene::Backend::Raster && messages != "0")
        error = "the Vulkan validation layer reported " + (messages.empty() ? "an unknown number of" : messages) +
                " message(s)";
    if (compare::measureHealth(f).total() > 0) error = "non-finite values";
    return error;
}

// Renders one configuration; failures (exceptions, validation messages) are recorded in `error`.
scene::Frame renderOne(const RecommendOptions& o, const scene::Scene& s, const scene::SettingsOverrides& overrides,
                       scene::Backend backend, std::string& error) {
    try {
        const scene::RenderSettings settings = scene::resolveSettings(s, overrides);
        scene::Frame f = o.render(s, settings, backend);
        error = frameError(f, settings, backend);
        return f;
    } catch (const std::exception& e) {
        error = e.what();
        return {};
    }
}

// The measurement of a rendered frame, or the error that kept it from one.
Measured measured(scene::Frame f, const std::string& error, const scene::Frame& reference, scene::Frame* keep) {
    Measured m;
    if (!error.empty()) {
        m.error = error;
        return m;
    }
    try {
        m = measure(f, reference);
    } catch (const std::exception& e) {
        m.ok = false;
        m.error = e.what();
    }
    if (keep) *keep = std::move(f);
    return m;
}

Measured measureRender(const RecommendOptions& o, const scene::Scene& s, const scene::SettingsOverrides& overrides,
                       scene::Backend backend, const scene::Frame& reference, scene::Frame* keep = nullptr) {
    std::string error;
    scene::Frame f = renderOne(o, s, overrides, backend, error);
    return measured(std::move(f), error, reference, keep);
}

// The search's points differ from one another only in the two biases: with the default render
// function one raster renderer draws them all (BackendRenderer::setRasterBiases, the frames a new
// renderer given those biases draws), not a device, an upload and pipelines per point. A fake
// render function (tests) renders each point anew.
class PointRenderer {
public:
    PointRenderer(const RecommendOptions& o, const scene::Scene& s) : o_(o), scene_(s) {
        reuse_ = isRenderWithBackend(o.render);
    }
    Measured measure(const scene::SettingsOverrides& overrides, const scene::Frame& reference) {
        if (!reuse_) return measureRender(o_, scene_, overrides, scene::Backend::Raster, reference);
        std::string error;
        scene::Frame f;
        try {
            const scene::RenderSettings settings = scene::resolveSettings(scene_, overrides);
            if (renderer_)
                renderer_->setRasterBiases(scene_, settings.raster.depthBias, settings.raster.slopeBias);
            else
                renderer_ =
                    makeRenderer(scene::Backend::Raster, scene_, scene::makeRenderPlan(scene_, settings), settings);
            f = renderer_->render();
            scene::recordIdentity(f, scene_);
            error = frameError(f, settings, scene::Backend::Raster);
            // A renderer's validation count runs on from frame to frame: after a failed point the
            // next one starts from a new renderer, so that it fails only on its own messages.
            if (!error.empty()) renderer_.reset();
        } catch (const std::exception& e) {
            renderer_.reset();  // the next point starts from a new renderer
            error = e.what();
        }
        return measured(std::move(f), error, reference, nullptr);
    }

    // Its maps, geometry and pipelines go (and the freed heap with them, unless the job's budget keeps
    // it for the next: ~BackendRenderer).
    void release() { renderer_.reset(); }

private:
    const RecommendOptions& o_;
    const scene::Scene& scene_;
    bool reuse_ = false;
    std::unique_ptr<BackendRenderer> renderer_;
};

Json measuredJson(const Measured& m) {
    if (!m.ok) return {{"error", m.error}};
    return {{"mismatch_rate", m.mismatchRate},
            {"false_shadow_rate", m.falseShadowRate},
            {"missed_shadow_rate", m.missedShadowRate},
            {"shadow_iou", m.shadowIoU},
            {"mean_abs_visibility_error", m.meanAbsVisibilityError},
            {"soft_error_rate", m.softErrorRate},
            {"terminator_missed_rate", m.terminatorMissedRate}};
}

// The scene-file keys of the user's own settings (everything but the biases this file chooses),
// so the block reproduces the configuration that was measured.
Json userBlock(const scene::SettingsOverrides& u) {
    Json j = Json::object();
    if (u.shadowMapSize) j["shadow_map_size"] = *u.shadowMapSize;
    if (u.filter) j["filter"] = *u.filter;
    if (u.pcfSize) j["pcf_size"] = *u.pcfSize;
    if (u.normalOffset) j["normal_offset"] = *u.normalOffset;
    // The command line's flags arrive as false when not given: only an "on" is the user's choice.
    if (u.receiverPlaneBias.value_or(false)) j["receiver_plane_bias"] = true;
    if (u.hardwareBias.value_or(false)) j["hardware_bias"] = true;
    if (u.fitLightFrustum.value_or(false)) j["fit_light_frustum"] = true;
    if (u.cascades) j["cascades"] = *u.cascades;
    if (u.cascadeBlend) j["cascade_blend"] = *u.cascadeBlend;
    if (u.samples) j["samples"] = *u.samples;
    return j;
}

void setRayBias(Json& block, const std::string& text) {
    if (text == "robust") {
        block["ray_bias"] = "robust";
        return;
    }
    char* end = nullptr;
    const double v = std::strtod(text.c_str(), &end);
    if (end && *end == '\0' && std::isfinite(v)) block["ray_bias"] = v;
}

// 3 significant digits, like auto_bias's values, so the block reads well; a bias keeps its sign.
double tidy(double v) {
    if (!std::isfinite(v) || v == 0.0) return v;
    char buf[32];
    std::snprintf(buf, sizeof buf, "%.3g", v);
    return std::strtod(buf, nullptr);
}

// The midpoint between two axis values: geometric when both are positive (biases act on a log
// scale: the acne-to-leak trade-off spans decades), else arithmetic.
double midpoint(double a, double b) { return a > 0.0 && b > 0.0 ? std::sqrt(a * b) : 0.5 * (a + b); }

// The values to try around `v` on an axis: the midpoints to its neighbours, and beyond the largest
// value twice it (the window may lie past the coarse grid).
std::vector<double> around(const std::vector<double>& axis, double v) {
    std::vector<double> out{v};
    const auto it = std::lower_bound(axis.begin(), axis.end(), v);
    if (it != axis.begin()) out.push_back(midpoint(*(it - 1), v));
    if (it != axis.end() && it + 1 != axis.end())
        out.push_back(midpoint(v, *(it + 1)));
    else if (v > 0.0)
        out.push_back(2.0 * v);
    return out;
}

std::string percentPair(const Measured& a, const Measured& b) {
    std::string s = compare::formatPercent(a.mismatchRate) + " mismatch (IoU " + compare::formatFixed(a.shadowIoU, 3) +
                    ") against the defaults' " + compare::formatPercent(b.mismatchRate) + " (IoU " +
                    compare::formatFixed(b.shadowIoU, 3) + ")";
    if (a.terminatorMissedRate > 0.0 || b.terminatorMissedRate > 0.0)
        s += "; " + compare::formatPercent(a.judgedRate()) + " against " + compare::formatPercent(b.judgedRate()) +
             " without the missed shadow at smooth meshes' terminators (renderers mean to leave it, and the "
             "recommendation does not chase it)";
    return s;
}

}  // namespace

Measured measure(const scene::Frame& method, const scene::Frame& reference) {
    const compare::Metrics k = compare::compareFrames(method, reference).metrics;
    Measured m;
    m.ok = true;
    m.mismatchRate = k.mismatchRate;
    m.falseShadowRate = k.falseShadowRate;
    m.missedShadowRate = k.missedShadowRate;
    m.shadowIoU = k.shadowIoU;
    m.meanAbsVisibilityError = k.meanAbsVisibilityError;
    m.softErrorRate = k.softErrorRate;
    m.terminatorMissedRate = k.hasReferenceBlockerIds ? k.terminatorMissedRate : 0.0;
    m.timeMs = method.totalTimeMs();
    return m;
}

bool better(const Measured& a, const Measured& b) {
    if (!a.ok) return false;
    if (!b.ok) return true;
    if (a.judgedRate() != b.judgedRate()) return a.judgedRate() < b.judgedRate();
    return a.meanAbsVisibilityError < b.meanAbsVisibilityError;
}

bool beats(const Measured& c, const Measured& d) {
    if (!(c.ok && d.ok && c.judgedRate() <= d.judgedRate() && c.meanAbsVisibilityError <= d.meanAbsVisibilityError))
        return false;
    // A gain worth a change of settings, not a few pixels of sampling noise (a 16-sample ray
    // tracer's mean |ΔV| 6e-7 lower, two pixels fewer of 120,000): the wrong pixels or the mean
    // |ΔV| fall by a tenth and by at least kMaterialGain.
    const double dm = d.judgedRate() - c.judgedRate(), dv = d.meanAbsVisibilityError - c.meanAbsVisibilityError;
    return (dm >= 0.1 * d.judgedRate() && dm >= kMaterialGain) ||
           (dv >= 0.1 * d.meanAbsVisibilityError && dv >= kMaterialGain);
}

Json rayCandidateOf(const AutoBias& bias) {
    Json j = Json::object();
    for (const char* key : {"ray_bias", "precision"})
        if (bias.shadowBlock.contains(key)) j[key] = bias.shadowBlock[key];
    return j;
}

namespace {

double numberAttribute(const scene::Frame& f, const char* key) {
    const std::string text = attribute(f, key);
    char* end = nullptr;
    const double v = std::strtod(text.c_str(), &end);
    return !text.empty() && end && *end == '\0' ? v : 0.0;
}

// The default map size caps what the receivers ask for (the raster frame's shadow_map_size_needed
// above its shadow_map_size) and the user set no size: a larger map at the user's biases (the
// default depth bias is half a texel of each map, so it shrinks with the texel) is rendered at the
// requested resolution and replaces the block's choice when it beats what the block gives.
void tryLargerMap(const RecommendOptions& o, const scene::Scene& scene, const scene::Frame& reference,
                  const scene::Frame& defaults, Verified& v, Json& block, std::vector<std::string>& notes) {
    const double needed = numberAttribute(defaults, "shadow_map_size_needed");
    const int size = int(numberAttribute(defaults, "shadow_map_size"));
    if (o.user.shadowMapSize || !v.defaults.ok || size <= 0 || !(needed > size) || size >= o.largestMapSize) return;
    int larger = size;
    while (larger < needed && larger < o.largestMapSize) larger *= 2;
    larger = std::min(larger, o.largestMapSize);
    scene::SettingsOverrides ov = o.user;
    ov.shadowMapSize = larger;
    v.largerMapSize = larger;
    v.largerMap = measureRender(o, scene, ov, scene::Backend::Raster, reference);
    const std::string asked = "the default caps the map at " + std::to_string(size) +
                              " texels where the receivers and casters ask for " +
                              std::to_string(int(std::ceil(needed))) + ": ";
    const bool biasesWon = v.beatsDefaults;  // the searched biases or a normal offset
    if (beats(v.largerMap, v.recommended)) {
        notes.push_back(
            "For the shadow map, " + asked + "a " + std::to_string(larger) + " map gives " +
            percentPair(v.largerMap, v.defaults) +
            (biasesWon ? ", and it beats the searched settings' " + compare::formatPercent(v.recommended.judgedRate())
                       : std::string()) +
            " at " + sizeText(scene) +
            ", for four times the texels of each map and more render time. The block recommends "
            "shadow_map_size " +
            std::to_string(larger) + (biasesWon ? " in place of them." : "."));
        v.largerMapRecommended = true;
        v.beatsDefaults = true;
        v.recommended = v.largerMap;
        block.erase("depth_bias");
        block.erase("slope_bias");
        block.erase("normal_offset");
        v.normalOffsetRecommended = 0.0;
        // The user's own values stay: the larger map was rendered with them.
        if (o.user.depthBias) block["depth_bias"] = *o.user.depthBias;
        if (o.user.slopeBias) block["slope_bias"] = *o.user.slopeBias;
        if (o.user.normalOffset) block["normal_offset"] = *o.user.normalOffset;
        block["shadow_map_size"] = larger;
    } else {
        notes.push_back("For the shadow map, " + asked + "a " + std::to_string(larger) + " map " +
                        (v.largerMap.ok ? "gives " + percentPair(v.largerMap, v.defaults) + ", no better than " +
                                              (biasesWon ? "the searched settings" : "the defaults")
                                        : "failed (" + v.largerMap.error + ")") +
                        ": the block keeps the size.");
    }
}

// Normal offset on top of what the block recommends so far (`biases`: the searched depth and
// slope bias when they won). Near a curved mesh's terminator the surface bends away within a
// texel's footprint faster than the slope bias's tangent plane assumes, so its own map texels
// shadow it (a solid band, not a speckle) at every bias that keeps thin casters' shadows; moving
// the lookup a fraction of a texel off the surface clears it (docs/sweep.md "The recommendation").
void tryNormalOffset(const RecommendOptions& o, const scene::Scene& scene, const scene::Frame& reference,
                     const BiasPoint* biases, Verified& v, Json& block, std::vector<std::string>& notes) {
    if (o.user.normalOffset || !v.recommended.ok || o.normalOffsetSteps.empty()) return;
    scene::SettingsOverrides ov = o.user;
    if (biases) {
        ov.depthBias = biases->depthBias;
        ov.slopeBias = biases->slopeBias;
    }
    int best = -1;
    for (const double k : o.normalOffsetSteps) {
        ov.normalOffset = k;
        v.normalOffsets.emplace_back(k, measureRender(o, scene, ov, scene::Backend::Raster, reference));
        const Measured& m = v.normalOffsets.back().second;
        if (beats(m, best < 0 ? v.recommended : v.normalOffsets[std::size_t(best)].second))
            best = int(v.normalOffsets.size()) - 1;
    }
    std::string tried;
    for (const auto& [k, m] : v.normalOffsets)
        tried += (tried.empty() ? "" : ", ") + compare::formatShort(k) + " texel" + (k == 1.0 ? "" : "s") + ": " +
                 (m.ok ? compare::formatPercent(m.judgedRate()) : "failed");
    const std::string base = biases ? "the searched biases" : "the defaults";
    if (best < 0) {
        notes.push_back("For the shadow map, a normal offset on top of " + base + " is no better (" + tried +
                        " wrong without the terminator, against " + compare::formatPercent(v.recommended.judgedRate()) +
                        "): the block adds none.");
        return;
    }
    const auto& [k, m] = v.normalOffsets[std::size_t(best)];
    notes.push_back("For the shadow map, a normal offset of " + compare::formatShort(k) + " texel" +
                    (k == 1.0 ? "" : "s") + " on top of " + base + " gives " + percentPair(m, v.defaults) + " at " +
                    sizeText(scene) + " (of the offsets tried, " + tried +
                    " wrong without the terminator): it lifts the lookup off curved receivers near their terminators, "
                    "whose own texels "
                    "shadow them past any slope bias. The block recommends it.");
    v.normalOffsetRecommended = k;
    v.beatsDefaults = true;
    v.recommended = m;
    block["normal_offset"] = k;
}

}  // namespace

Json Recommendation::toJson() const {
    auto side = [&](const Verified& v, bool withPoints) {
        Json j = {{"beats_defaults", v.beatsDefaults},
                  {"searched", v.searched},
                  {"candidate", v.candidate},
                  {"defaults", measuredJson(v.defaults)},
                  {"tried", v.searched ? measuredJson(v.tried) : Json(nullptr)},
                  {"recommended", measuredJson(v.recommended)}};
        // The gain judged (the terminator's missed shadow left out, as beats() judges), never < 0.
        j["mismatch_rate_gain"] = v.defaults.ok && v.recommended.ok
                                      ? Json(v.defaults.judgedRate() - v.recommended.judgedRate())
                                      : Json(nullptr);
        if (withPoints) {
            j["searched_points"] = points.size();
            Json offsets = Json::array();
            for (const auto& [k, m] : v.normalOffsets)
                offsets.push_back({{"normal_offset", k}, {"measured", measuredJson(m)}});
            j["normal_offsets"] = offsets;
            j["normal_offset_recommended"] =
                v.normalOffsetRecommended > 0 ? Json(v.normalOffsetRecommended) : Json(nullptr);
            j["larger_map"] = v.largerMapSize > 0 ? Json{{"shadow_map_size", v.largerMapSize},
                                                         {"measured", measuredJson(v.largerMap)},
                                                         {"recommended", v.largerMapRecommended}}
                                                  : Json(nullptr);
        }
        return j;
    };
    return {{"shadow", shadowBlock},
            {"measured",
             {{"resolution", resolution},
              {"search_resolution", searchResolution},
              {scene::toString(scene::Backend::Raster), side(raster, true)},
              {scene::toString(scene::Backend::Raytrace), side(raytrace, false)},
              {"notes", notes}}}};
}

Recommendation recommendShadow(const scene::Scene& searchScene, const scene::Frame& searchReference,
                               const scene::Scene& scene, const scene::Frame& reference,
                               const scene::Frame* rasterDefaults, const scene::Frame* raytraceDefaults,
                               const Json& rayCandidate, const RecommendOptions& o) {
    Recommendation r;
    r.searchResolution = sizeText(searchScene);
    r.resolution = sizeText(scene);
    const scene::SettingsOverrides& user = o.user;
    Json block = userBlock(user);

    if (o.raster) {
        // The user's defaults at the requested resolution, first: the automatic map size follows
        // the image size, so the search holds the size this resolution resolves to (a bias in world
        // units found with another map size would be another configuration).
        Verified& v = r.raster;
        scene::Frame fullDefaults;
        v.defaults = rasterDefaults ? measure(*rasterDefaults, reference)
                                    : measureRender(o, scene, user, scene::Backend::Raster, reference, &fullDefaults);
        scene::SettingsOverrides searchUser = user;
        const std::string fullMap = attribute(rasterDefaults ? *rasterDefaults : fullDefaults, "shadow_map_size");
        if (!user.shadowMapSize && !fullMap.empty()) {
            char* end = nullptr;
            const long size = std::strtol(fullMap.c_str(), &end, 10);
            if (end && *end == '\0' && size >= 16 && size <= 16384) searchUser.shadowMapSize = int(size);
        }

        // The user's configuration as it is: the first point, and the scale of the search.
        BiasPoint d;
        d.defaults = true;
        scene::Frame defaultsFrame;
        d.at = measureRender(o, searchScene, searchUser, scene::Backend::Raster, searchReference, &defaultsFrame);
        const scene::RenderSettings resolved = scene::resolveSettings(searchScene, searchUser);
        const std::string applied = attribute(defaultsFrame, "depth_bias");
        double b0 = smallestPositive(applied);
        if (!(b0 > 0.0)) b0 = resolved.raster.depthBias;
        if (!(b0 > 0.0)) b0 = scene::defaultDepthBias(searchScene, resolved.raster.shadowMapSize);
        const double s0 = resolved.raster.slopeBias > 0.0 ? resolved.raster.slopeBias : 1.0;
        d.depthBias = b0;
        d.slopeBias = resolved.raster.slopeBias;
        r.points.push_back(d);
        // One applied value: the explicit (b0, s0) point would render the defaults again.
        const bool oneBias = applied.find(';') == std::string::npos && resolved.raster.slopeBias == s0;

        std::set<std::pair<double, double>> done;
        PointRenderer points(o, searchScene);
        auto tryPoint = [&](double depth, double slope, bool refined) {
            depth = tidy(depth);
            slope = tidy(slope);
            if (!done.insert({depth, slope}).second) return;
            if (oneBias && depth == tidy(b0) && slope == tidy(s0)) return;
            BiasPoint p;
            p.depthBias = depth;
            p.slopeBias = slope;
            p.refined = refined;
            scene::SettingsOverrides ov = searchUser;
            ov.depthBias = depth;
            ov.slopeBias = slope;
            p.at = points.measure(ov, searchReference);
            r.points.push_back(p);
        };
        if (d.at.ok) {
            std::vector<double> depthAxis, slopeAxis;
            for (double k : o.depthSteps) depthAxis.push_back(tidy(k * b0));
            for (double k : o.slopeSteps) slopeAxis.push_back(tidy(k * s0));
            for (double depth : depthAxis)
                for (double slope : slopeAxis) tryPoint(depth, slope, false);
            // Only points that could replace the defaults compete (beats(): no larger mean |ΔV|).
            auto bestIndex = [&] {
                int best = 0;
                for (int i = 1; i < int(r.points.size()); ++i)
                    if (beats(r.points[i].at, r.points[0].at) && better(r.points[i].at, r.points[best].at)) best = i;
                return best;
            };
            if (o.refine) {
                const BiasPoint centre = r.points[bestIndex()];
                const double cd = centre.defaults ? tidy(b0) : centre.depthBias;
                const double cs = centre.defaults ? tidy(s0) : centre.slopeBias;
                std::sort(depthAxis.begin(), depthAxis.end());
                std::sort(slopeAxis.begin(), slopeAxis.end());
                for (double depth : around(depthAxis, cd))
                    for (double slope : around(slopeAxis, cs)) tryPoint(depth, slope, true);
            }
            r.best = bestIndex();
        } else {
            r.best = 0;
        }

        points.release();  // before the check's renderer at the requested resolution
        // At the requested resolution: the user's defaults against the best point.
        const BiasPoint& best = r.points[r.best];
        if (!best.defaults && best.at.ok) {
            v.searched = true;
            v.candidate = "depth bias " + compare::formatShort(best.depthBias) + " world units, slope bias " +
                          compare::formatShort(best.slopeBias) + " texels";
            scene::SettingsOverrides ov = user;
            ov.depthBias = best.depthBias;
            ov.slopeBias = best.slopeBias;
            v.tried = measureRender(o, scene, ov, scene::Backend::Raster, reference);
            v.beatsDefaults = beats(v.tried, v.defaults);
        }
        v.recommended = v.beatsDefaults ? v.tried : v.defaults;
        const std::string config =
            "filter " + attribute(defaultsFrame, "filter") + ", map " + attribute(defaultsFrame, "shadow_map_size") +
            ", " + (resolved.raster.cascades > 1 ? std::to_string(resolved.raster.cascades) + " cascades, " : "") +
            (attribute(defaultsFrame, "light_frustum_fit") == "receivers" ? "fitted to the view"
                                                                          : "bounding-sphere fit");
        r.notes.push_back("The shadow map's biases were searched in the configuration you run (" + config +
                          "): " + std::to_string(r.points.size()) + " renders at " + r.searchResolution +
                          ", constant bias 0 .. " + compare::formatShort(o.depthSteps.back() * b0) +
                          " world units together with slope bias 0 .. " +
                          compare::formatShort(o.slopeSteps.back() * s0) + " texels, refined around the best point.");
        if (scene::isFilterable(resolved.raster.filter))
            r.notes.push_back(std::string("Filter ") + scene::toString(resolved.raster.filter) +
                              " biases the receiver's depth before its moment test as `none` does, so the same "
                              "search applies; its own parameters (min variance, light-bleeding reduction, "
                              "exponents, moment bias) are not searched here: give them as axes of a sweep grid, "
                              "whose automatic bias reads their parameter windows (docs/sweep.md).");
        if (v.beatsDefaults) {
            block["depth_bias"] = best.depthBias;
            block["slope_bias"] = best.slopeBias;
            r.notes.push_back("At " + r.resolution + ", " + v.candidate + " gives " +
                              percentPair(v.recommended, v.defaults) + ": " +
                              compare::formatPercent(v.defaults.judgedRate() - v.recommended.judgedRate()) +
                              " of the counted pixels fewer wrong. The block recommends it.");
        } else {
            if (user.depthBias) block["depth_bias"] = *user.depthBias;
            if (user.slopeBias) block["slope_bias"] = *user.slopeBias;
            std::string why;
            if (!v.defaults.ok)
                why = "the defaults did not render (" + v.defaults.error + "), so no bias is recommended.";
            else if (!v.searched)
                why = "no searched bias beats the defaults (" + compare::formatPercent(v.defaults.mismatchRate) +
                      " mismatch, IoU " + compare::formatFixed(v.defaults.shadowIoU, 3) + " at " + r.resolution +
                      "): the block keeps them.";
            else if (!v.tried.ok)
                why = "the best searched point (" + v.candidate + ") failed at " + r.resolution + " (" + v.tried.error +
                      "): the block keeps the defaults.";
            else
                why = "the best searched point (" + v.candidate + ") gives " + percentPair(v.tried, v.defaults) +
                      " and mean |dV| " + compare::formatFixed(v.tried.meanAbsVisibilityError, 4) + " against " +
                      compare::formatFixed(v.defaults.meanAbsVisibilityError, 4) + " at " + r.resolution +
                      ", not better in every respect: the block keeps the defaults.";
            r.notes.push_back("For the shadow map, " + why);
        }
        tryNormalOffset(o, scene, reference, v.beatsDefaults ? &best : nullptr, v, block, r.notes);
        tryLargerMap(o, scene, reference, rasterDefaults ? *rasterDefaults : fullDefaults, v, block, r.notes);
    }

    if (o.raytrace && rayCandidate.contains("ray_bias")) {
        Verified& v = r.raytrace;
        v.defaults = raytraceDefaults ? measure(*raytraceDefaults, reference)
                                      : measureRender(o, scene, user, scene::Backend::Raytrace, reference);
        scene::SettingsOverrides ov = user;
        const Json& rb = rayCandidate["ray_bias"];
        if (rb.is_string()) {
            ov.rayBias = rb.get<std::string>();
        } else {
            char buf[40];
            std::snprintf(buf, sizeof buf, "%.9g", rb.get<double>());
            ov.rayBias = buf;
        }
        if (rayCandidate.contains("precision")) ov.precision = rayCandidate["precision"].get<std::string>();
        v.searched = true;
        v.candidate = "ray bias " + *ov.rayBias + (ov.precision ? " (" + *ov.precision + ")" : "");
        v.tried = measureRender(o, scene, ov, scene::Backend::Raytrace, reference);
        v.beatsDefaults = beats(v.tried, v.defaults);
        v.recommended = v.beatsDefaults ? v.tried : v.defaults;
        if (v.beatsDefaults) {
            setRayBias(block, *ov.rayBias);
            if (ov.precision) block["precision"] = *ov.precision;
            r.notes.push_back(
                "For the ray tracer, " + v.candidate + " gives " + percentPair(v.recommended, v.defaults) + " at " +
                r.resolution + ", in " + compare::formatDuration(v.recommended.timeMs) + " against the defaults' " +
                compare::formatDuration(v.defaults.timeMs) + " (one render each). The block recommends it.");
        } else {
            if (user.rayBias) setRayBias(block, *user.rayBias);
            if (user.precision) block["precision"] = *user.precision;
            r.notes.push_back("For the ray tracer, the sweep's pick (" + v.candidate + ") " +
                              (v.tried.ok ? "gives " + percentPair(v.tried, v.defaults) + ", no better"
                                          : "failed (" + v.tried.error + ")") +
                              ": the block keeps the defaults.");
        }
    }
    r.shadowBlock = block;
    return r;
}

}  // namespace shadowlab::studies
