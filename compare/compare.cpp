// compare/compare.cpp: per-pixel classification of a method Frame against the reference,
// the metrics derived from the classes, and the difference image.
#include "compare/compare.h"

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <limits>
#include <map>
#include <string>
#include <variant>
#include <vector>

#include <glm/glm.hpp>

#include "compare/text.h"
#include "scene/error.h"
#include "scene/frame_io.h"

namespace shadowlab::compare {

namespace {

using scene::Frame;
using scene::InputError;

void countValue(NonFinite& n, float v) {
    if (std::isnan(v))
        ++n.nan;
    else if (std::isinf(v))
        ++n.inf;
}

NonFinite countChannel(const std::vector<float>& values) {
    NonFinite n;
    for (const float v : values) countValue(n, v);
    return n;
}

void checkChannel(const std::string& which, const char* channel, std::size_t actual, std::size_t expected,
                  bool optional) {
    if (optional && actual == 0) return;
    if (actual != expected)
        throw InputError(which + " frame: channel '" + channel + "' has " + std::to_string(actual) +
                         " values, expected " + std::to_string(expected) + (actual == 0 ? " (missing)" : ""));
}

void checkFrame(const std::string& which, const Frame& f) {
    if (f.width <= 0 || f.height <= 0)
        throw InputError(which + " frame is empty (" + std::to_string(f.width) + "x" + std::to_string(f.height) + ")");
    const std::size_t n = f.pixelCount();
    checkChannel(which, "beauty", f.beauty.size(), 3 * n, which == "method");
    checkChannel(which, "visibility", f.visibility.size(), n, false);
    checkChannel(which, "object_id", f.objectId.size(), n, false);
    checkChannel(which, "ndotl", f.ndotl.size(), n, false);
    checkChannel(which, "Z", f.depth.size(), n, true);
    checkChannel(which, "blocker_id", f.blockerId.size(), n, true);
}

// Object ids round to the nearest integer (thresholds.h, kObjectIdRounding).
long long roundId(float id) { return static_cast<long long>(std::floor(id + kObjectIdRounding)); }

Timing timingOf(const Frame& f) { return {f.totalTimeMs(), f.timingsMs}; }

// The ';'-separated entries of an attribute, in order (one per shadow-map layer for the raster
// backend's texel_world_size and texel_axis).
std::vector<std::string> entries(const std::string& text) {
    std::vector<std::string> out;
    std::size_t start = 0;
    while (start <= text.size()) {
        const std::size_t end = std::min(text.find(';', start), text.size());
        out.push_back(text.substr(start, end - start));
        start = end + 1;
    }
    return out;
}

// The number an entry starts with; NaN when there is none.
double leadingNumber(const std::string& part) {
    char* stop = nullptr;
    const double v = std::strtod(part.c_str(), &stop);
    return stop != part.c_str() && std::isfinite(v) ? v : std::numeric_limits<double>::quiet_NaN();
}

// The largest number of a Frame attribute holding one or several (';'-separated) numbers. NaN
// when there is none.
double largestNumber(const std::string& text) {
    double best = std::numeric_limits<double>::quiet_NaN();
    for (const std::string& part : entries(text)) {
        const double v = leadingNumber(part);
        if (std::isfinite(v) && !(v <= best)) best = v;
    }
    return best;
}

// A perspective shadow map (a spot's, a point light's cube face): its texel at world point p is
// perUnit·(p − apex)·axis (the raster backend's texel_world_size "X*d" and texel_axis).
struct PerspectiveTexel {
    double perUnit = 0.0;
    glm::dvec3 apex{0.0}, axis{0.0};
};

// The contact distance's constant, texel and slope parts (thresholds.h): from the options, else
// the method's attributes. The texel is NaN when the method is no shadow map.
struct Contact {
    double bias = std::numeric_limits<double>::quiet_NaN();
    double texel = 0.0, slope = 0.0;  // texel: the largest orthographic map's (or the option's)
    // Perspective maps with their apex and axis, whose texel is taken at the pixel's distance;
    // `fallback`: those whose texel_axis is missing (frames written before it), or every one when
    // the pixel's position is unknown: their X·d counts as X, the largest.
    std::vector<PerspectiveTexel> perspective;
    double fallback = 0.0;
    bool known() const { return std::isfinite(bias); }
    // The largest map's texel at world point p (none: unknown, `fallback` for every perspective map).
    double texelAt(const glm::dvec3* p) const {
        double t = std::max(texel, fallback);
        for (const PerspectiveTexel& l : perspective)
            t = std::max(t, p ? l.perUnit * std::max(0.0, glm::dot(*p - l.apex, l.axis)) : l.perUnit);
        return t;
    }
    double at(float ndotl, double texelHere) const {
        const double n = std::clamp(double(ndotl), 1e-6, 1.0);
        const double tanTheta = std::min(std::sqrt(std::max(0.0, 1.0 - n * n)) / n, kContactMaxTan);
        return bias + (slope + kContactTexels) * texelHere * std::max(1.0, tanTheta);
    }
};

std::string attribute(const Frame& f, const std::string& key) {
    const auto it = f.attributes.find(key);
    return it == f.attributes.end() ? std::string() : it->second;
}

// A texel_axis entry "x,y,z,dx,dy,dz"; false for "-" (orthographic) or anything else.
bool parseAxis(const std::string& text, PerspectiveTexel& l) {
    double v[6];
    const char* at = text.c_str();
    for (double& x : v) {
        char* stop = nullptr;
        x = std::strtod(at, &stop);
        if (stop == at || !std::isfinite(x)) return false;
        at = stop;
        if (*at == ',') ++at;
    }
    l.apex = glm::dvec3(v[0], v[1], v[2]);
    l.axis = glm::dvec3(v[3], v[4], v[5]);
    return *at == '\0' && glm::length(l.axis) > 0.0;
}

Contact contactOf(const Frame& method, const CompareOptions& o) {
    Contact c;
    const std::string texel = attribute(method, "texel_world_size");
    if (!texel.empty() || o.contactTexel) {
        c.bias = o.contactBias.value_or(largestNumber(attribute(method, "depth_bias")));
        c.slope = o.contactSlope.value_or(largestNumber(attribute(method, "slope_bias")));
        if (!std::isfinite(c.slope)) c.slope = 0.0;
        if (o.contactTexel) {
            c.texel = *o.contactTexel;
        } else {
            // Per layer: "X" (orthographic) or "X*d" (perspective, with its texel_axis entry).
            const std::vector<std::string> sizes = entries(texel), axes = entries(attribute(method, "texel_axis"));
            bool any = false;
            for (std::size_t k = 0; k < sizes.size(); ++k) {
                const double x = leadingNumber(sizes[k]);
                if (!std::isfinite(x)) continue;
                any = true;
                if (sizes[k].find('*') == std::string::npos) {
                    c.texel = std::max(c.texel, x);
                    continue;
                }
                PerspectiveTexel l;
                l.perUnit = x;
                if (k < axes.size() && axes.size() == sizes.size() && parseAxis(axes[k], l)) {
                    l.axis = glm::normalize(l.axis);
                    c.perspective.push_back(l);
                } else {
                    c.fallback = std::max(c.fallback, x);
                }
            }
            if (!any) c.bias = std::numeric_limits<double>::quiet_NaN();
        }
        if (!std::isfinite(c.texel)) c.bias = std::numeric_limits<double>::quiet_NaN();
    } else if (o.contactBias) {
        c.bias = *o.contactBias;
    } else {
        const std::string ray = attribute(method, "ray_bias");
        if (ray == "robust")
            c.bias = 0.0;
        else if (!ray.empty())
            c.bias = kContactRayBiasFactor * largestNumber(ray);
    }
    return c;
}

// World positions of a frame's pixels from its view depth (the Z channel) and its camera (the
// worldToCamera and worldToNDC attributes, scene/frame_identity.h): OpenEXR's camera space has
// z = view depth, so pixel (x, y) with NDC ((x + 0.5)/W, (y + 0.5)/H) and depth z solves two
// linear equations for camera x, y. Unknown without the matrices or the depths.
class PixelPositions {
public:
    PixelPositions(const Frame& depthFrame, const Frame& cameraFrame) : depth_(depthFrame.depth) {
        const auto toCamera = cameraFrame.typedAttributes.find("worldToCamera");
        const auto toNdc = cameraFrame.typedAttributes.find("worldToNDC");
        if (toCamera == cameraFrame.typedAttributes.end() || toNdc == cameraFrame.typedAttributes.end()) return;
        const auto* m = std::get_if<glm::mat4>(&toCamera->second);
        const auto* n = std::get_if<glm::mat4>(&toNdc->second);
        if (!m || !n || depth_.size() != depthFrame.pixelCount()) return;
        cameraToWorld_ = glm::inverse(glm::dmat4(*m));
        projection_ = glm::dmat4(*n) * cameraToWorld_;
        width_ = depthFrame.width;
        height_ = depthFrame.height;
        known_ = true;
    }
    bool known() const { return known_; }
    // Pixel i's world position; false where it has no finite depth.
    bool at(std::size_t i, glm::dvec3& p) const {
        const double z = depth_[i];
        if (!known_ || !std::isfinite(z) || z <= 0.0) return false;
        const double u = (double(i % std::size_t(width_)) + 0.5) / width_;
        const double v = (double(i / std::size_t(width_)) + 0.5) / height_;
        const glm::dmat4& P = projection_;  // P[column][row]
        // Row r of P·(x, y, z, 1) minus its NDC coordinate times row 3: a·x + b·y = c.
        auto row = [&](int r, double ndc, double& a, double& b, double& c) {
            a = P[0][r] - ndc * P[0][3];
            b = P[1][r] - ndc * P[1][3];
            c = -((P[2][r] - ndc * P[2][3]) * z + (P[3][r] - ndc * P[3][3]));
        };
        double a0, b0, c0, a1, b1, c1;
        row(0, u, a0, b0, c0);
        row(1, v, a1, b1, c1);
        const double det = a0 * b1 - a1 * b0;
        if (!(std::abs(det) > 0.0)) return false;
        const glm::dvec4 world =
            cameraToWorld_ * glm::dvec4((c0 * b1 - c1 * b0) / det, (a0 * c1 - a1 * c0) / det, z, 1.0);
        p = glm::dvec3(world);
        return true;
    }

private:
    const std::vector<float>& depth_;
    glm::dmat4 cameraToWorld_{1.0}, projection_{1.0};
    int width_ = 0, height_ = 0;
    bool known_ = false;
};

float srgbLuminance(float r, float g, float b) {
    // Rec. 709 luminance of the linear color, then the sRGB curve, so the gray ramp of the
    // diff image looks like the reference image does on screen.
    auto finite = [](float v) { return std::isfinite(v) ? v : 0.0f; };
    const float y = 0.2126f * finite(r) + 0.7152f * finite(g) + 0.0722f * finite(b);
    return scene::linearToSrgb(y);
}

// Reference shadow state used by the edge detector: -1 where the reference has no shadow
// answer (background, facing away, non-finite), else 1 shadowed / 0 lit.
std::vector<signed char> referenceShadowState(const Frame& r) {
    const std::size_t n = r.pixelCount();
    std::vector<signed char> s(n, -1);
    for (std::size_t i = 0; i < n; ++i) {
        const float v = r.visibility[i], id = r.objectId[i], nl = r.ndotl[i];
        if (!std::isfinite(v) || !std::isfinite(id) || !std::isfinite(nl)) continue;
        if (roundId(id) == 0 || !(nl > kMinNdotL)) continue;
        s[i] = v <= kVisibilityTolerance ? 1 : 0;
    }
    return s;
}

// Pixels on a reference shadow boundary: a 4-neighbour on the SAME object has the other state.
// Neighbours on another object are silhouettes or contacts, where a missing contact shadow is
// bias error (peter-panning), not aliasing.
std::vector<unsigned char> shadowEdges(const Frame& r, const std::vector<signed char>& state) {
    const int w = r.width, h = r.height;
    std::vector<unsigned char> edge(state.size(), 0);
    auto idAt = [&](std::size_t i) { return roundId(r.objectId[i]); };
    for (int y = 0; y < h; ++y)
        for (int x = 0; x < w; ++x) {
            const std::size_t i = std::size_t(y) * w + x;
            if (state[i] < 0) continue;
            auto differs = [&](std::size_t j) { return state[j] >= 0 && state[j] != state[i] && idAt(j) == idAt(i); };
            if ((x > 0 && differs(i - 1)) || (x + 1 < w && differs(i + 1)) || (y > 0 && differs(i - w)) ||
                (y + 1 < h && differs(i + w)))
                edge[i] = 1;
        }
    return edge;
}

// Square (Chebyshev) dilation by `radius`, separable: rows, then columns.
std::vector<unsigned char> dilate(const std::vector<unsigned char>& mask, int w, int h, int radius) {
    if (radius <= 0) return mask;
    std::vector<unsigned char> rows(mask.size(), 0), out(mask.size(), 0);
    for (int y = 0; y < h; ++y) {
        int last = -1000000000;  // x of the last set pixel seen on this row, scanning right
        for (int x = 0; x < w; ++x) {
            if (mask[std::size_t(y) * w + x]) last = x;
            if (x - last <= radius) rows[std::size_t(y) * w + x] = 1;
        }
        last = 1000000000;
        for (int x = w - 1; x >= 0; --x) {
            if (mask[std::size_t(y) * w + x]) last = x;
            if (last - x <= radius) rows[std::size_t(y) * w + x] = 1;
        }
    }
    for (int x = 0; x < w; ++x) {
        int last = -1000000000;
        for (int y = 0; y < h; ++y) {
            if (rows[std::size_t(y) * w + x]) last = y;
            if (y - last <= radius) out[std::size_t(y) * w + x] = 1;
        }
        last = 1000000000;
        for (int y = h - 1; y >= 0; --y) {
            if (rows[std::size_t(y) * w + x]) last = y;
            if (last - y <= radius) out[std::size_t(y) * w + x] = 1;
        }
    }
    return out;
}

// Densest square window of wrong pixels, by a summed-area table; ties keep the first (top-left).
ErrorHotspot findHotspot(const std::vector<PixelClass>& classes, int w, int h, int size) {
    ErrorHotspot best;
    if (size <= 0) size = std::clamp(std::min(w, h) / 6, 16, 96);
    size = std::min({size, w, h});
    best.size = size;
    if (size <= 0) return best;
    const std::size_t sw = std::size_t(w) + 1;
    std::vector<std::size_t> sat(sw * (std::size_t(h) + 1), 0);
    for (int y = 0; y < h; ++y)
        for (int x = 0; x < w; ++x) {
            const PixelClass c = classes[std::size_t(y) * w + x];
            const std::size_t wrong = c == PixelClass::FalseShadow || c == PixelClass::MissedShadow;
            sat[(y + 1) * sw + x + 1] = wrong + sat[y * sw + x + 1] + sat[(y + 1) * sw + x] - sat[y * sw + x];
        }
    for (int y = 0; y + size <= h; ++y)
        for (int x = 0; x + size <= w; ++x) {
            const std::size_t a = sat[y * sw + x], b = sat[y * sw + x + size];
            const std::size_t c = sat[(y + size) * sw + x], d = sat[(y + size) * sw + x + size];
            const std::size_t count = d + a - b - c;
            if (count > best.wrongPixels) {
                best.wrongPixels = count;
                best.x = x;
                best.y = y;
            }
        }
    return best;
}

double rate(std::size_t part, std::size_t whole) {
    return whole == 0 ? 0.0 : static_cast<double>(part) / static_cast<double>(whole);
}

nlohmann::json toJson(const NonFinite& n) { return {{"nan", n.nan}, {"inf", n.inf}}; }

nlohmann::json toJson(const FrameHealth& h) {
    return {{"beauty", toJson(h.beauty)},
            {"visibility", toJson(h.visibility)},
            {"object_id", toJson(h.objectId)},
            {"ndotl", toJson(h.ndotl)},
            {"Z", toJson(h.depth)},
            {"blocker_id", toJson(h.blockerId)},
            {"total", h.total()}};
}

nlohmann::json toJson(const Timing& t) {
    nlohmann::json stages = nlohmann::json::array();
    for (const auto& [name, ms] : t.stagesMs) stages.push_back({{"stage", name}, {"ms", ms}});
    // A frame that records no stage (an external mask) has no run time: null, not 0 ms.
    nlohmann::json total = nullptr;
    if (!t.stagesMs.empty()) total = t.totalMs;
    return {{"total_ms", total}, {"stages", stages}};
}

}  // namespace

const char* toString(PixelClass c) {
    switch (c) {
        case PixelClass::AgreeLit: return "agree-lit";
        case PixelClass::AgreeShadow: return "agree-shadow";
        case PixelClass::FalseShadow: return "false-shadow";
        case PixelClass::MissedShadow: return "missed-shadow";
        case PixelClass::NotCounted: return "not-counted";
        case PixelClass::Invalid: return "invalid";
    }
    return "?";
}

std::size_t FrameHealth::total() const {
    return beauty.total() + visibility.total() + objectId.total() + ndotl.total() + depth.total() + blockerId.total();
}

FrameHealth measureHealth(const Frame& f) {
    return {countChannel(f.beauty), countChannel(f.visibility), countChannel(f.objectId),
            countChannel(f.ndotl),  countChannel(f.depth),      countChannel(f.blockerId)};
}

PixelClass classifyCounted(float vMethod, float vReference) {
    if (vReference - vMethod > kVisibilityTolerance) return PixelClass::FalseShadow;
    if (vMethod - vReference > kVisibilityTolerance) return PixelClass::MissedShadow;
    return vReference > kVisibilityTolerance ? PixelClass::AgreeLit : PixelClass::AgreeShadow;
}

std::array<float, 3> heatColor(float e) {
    if (std::isnan(e)) return DiffColors::kInvalid;
    const float t = std::clamp(e, 0.0f, 1.0f) * 4.0f;
    const int k = std::min(3, int(t));
    const float f = t - float(k);
    const auto& a = HeatScale::kStops[k];
    const auto& b = HeatScale::kStops[k + 1];
    return {a[0] + f * (b[0] - a[0]), a[1] + f * (b[1] - a[1]), a[2] + f * (b[2] - a[2])};
}

std::array<float, 3> diffColor(PixelClass c, float refR, float refG, float refB) {
    using C = DiffColors;
    switch (c) {
        case PixelClass::AgreeLit: {
            const float g = C::kLitBase + C::kLitScale * srgbLuminance(refR, refG, refB);
            return {g, g, g};
        }
        case PixelClass::AgreeShadow: {
            const float g = C::kShadowBase + C::kShadowScale * srgbLuminance(refR, refG, refB);
            return {g, g, g};
        }
        case PixelClass::FalseShadow: return C::kFalseShadow;
        case PixelClass::MissedShadow: return C::kMissedShadow;
        case PixelClass::NotCounted: return C::kNotCounted;
        case PixelClass::Invalid: return C::kInvalid;
    }
    return C::kInvalid;
}

Comparison compareFrames(const Frame& method, const Frame& reference, const CompareOptions& options) {
    checkFrame("method", method);
    checkFrame("reference", reference);
    if (method.width != reference.width || method.height != reference.height)
        throw InputError("frame sizes differ: method is " + std::to_string(method.width) + "x" +
                         std::to_string(method.height) + ", reference is " + std::to_string(reference.width) + "x" +
                         std::to_string(reference.height));
    if (options.edgeRadius < 0) throw InputError("edge radius must be >= 0, got " + std::to_string(options.edgeRadius));

    const int w = reference.width, h = reference.height;
    const std::size_t n = reference.pixelCount();
    Comparison out;
    out.width = w;
    out.height = h;
    out.classes.assign(n, PixelClass::NotCounted);
    out.diffRgb.assign(3 * n, 0.0f);
    Metrics& m = out.metrics;
    m.width = w;
    m.height = h;
    m.totalPixels = n;
    m.hasBlockerIds = !method.blockerId.empty();
    m.edgeRadius = options.edgeRadius;
    const Contact contact = contactOf(method, options);
    m.pointSampled = !attribute(method, "ray_bias").empty() && attribute(method, "texel_world_size").empty();
    m.hasBlockerDistance = contact.known() && reference.blockerDistance.size() == n && reference.blockerId.size() == n;
    m.hasReferenceBlockerIds = reference.blockerId.size() == n;
    // Perspective maps' texels at each pixel's distance: its position from the method's depths and
    // the camera either frame records (the same camera: compare refuses two different ones).
    const bool methodCamera = method.typedAttributes.count("worldToNDC") > 0;
    const PixelPositions positions(method.depth.size() == n ? method : reference, methodCamera ? method : reference);
    const bool perPixel = !contact.perspective.empty() && positions.known();
    auto contactAt = [&](std::size_t i, float ndotl) {
        glm::dvec3 p;
        return contact.at(ndotl, contact.texelAt(perPixel && positions.at(i, p) ? &p : nullptr));
    };
    // D at tanθ ≤ 1: its smallest over the counted pixels where a perspective map's texel varies.
    if (m.hasBlockerDistance)
        m.contactDistance =
            perPixel ? std::numeric_limits<double>::infinity() : contact.at(1.0f, contact.texelAt(nullptr));

    const auto refState = referenceShadowState(reference);
    const auto edges = shadowEdges(reference, refState);
    m.referenceShadowEdgePixels = static_cast<std::size_t>(std::count(edges.begin(), edges.end(), 1));
    const auto nearEdge = dilate(edges, w, h, options.edgeRadius);

    std::map<long long, ObjectErrors> perObject;
    double sumAbs = 0.0, sumAbsPenumbra = 0.0;
    out.heatRgb.assign(3 * n, 0.0f);
    auto isPenumbra = [](float v) { return v > kPenumbraMargin && v < 1.0f - kPenumbraMargin; };
    // Per light only when both frames hold the same lights' channels at full size.
    const std::size_t lights = method.lightVisibility.size();
    bool perLight = lights > 0 && reference.lightVisibility.size() == lights;
    for (std::size_t l = 0; perLight && l < lights; ++l)
        perLight = method.lightVisibility[l].size() == n && reference.lightVisibility[l].size() == n;
    std::vector<double> lightSum(perLight ? lights : 0, 0.0), lightPenumbraSum(lightSum);
    if (perLight) {
        m.perLight.resize(lights);
        out.lightHeatRgb.assign(lights, std::vector<float>(3 * n, 0.0f));
        for (std::size_t l = 0; l < lights; ++l) m.perLight[l].light = int(l);
    }
    for (std::size_t i = 0; i < n; ++i) {
        const float vm = method.visibility[i], vr = reference.visibility[i];
        const float idm = method.objectId[i], idr = reference.objectId[i];
        const float nm = method.ndotl[i], nr = reference.ndotl[i];
        PixelClass c = PixelClass::NotCounted;
        const bool idsFinite = std::isfinite(idm) && std::isfinite(idr);
        if (idsFinite && roundId(idm) != roundId(idr)) ++m.silhouetteMismatch;

        if (!idsFinite || !std::isfinite(vm) || !std::isfinite(vr) || !std::isfinite(nm) || !std::isfinite(nr)) {
            c = PixelClass::Invalid;
        } else if (roundId(idm) != roundId(idr) || roundId(idr) == 0) {
            c = PixelClass::NotCounted;
        } else if (!(nm > kMinNdotL) || !(nr > kMinNdotL)) {
            if ((nm > kMinNdotL) != (nr > kMinNdotL)) ++m.ndotlSignMismatch;
            c = PixelClass::NotCounted;
        } else {
            c = classifyCounted(vm, vr);
            ++m.counted;
            if (perPixel && m.hasBlockerDistance) m.contactDistance = std::min(m.contactDistance, contactAt(i, 1.0f));
            const double e = std::fabs(double(vm) - double(vr));
            sumAbs += e;
            m.maxAbsVisibilityError = std::max(m.maxAbsVisibilityError, e);
            // With several lights a point in one light's shadow has a fractional combined V: the
            // penumbra is where some light's own visibility is partial.
            bool refPenumbra = lightSum.empty() && isPenumbra(vr);
            for (std::size_t l = 0; l < lightSum.size() && !refPenumbra; ++l)
                refPenumbra = isPenumbra(reference.lightVisibility[l][i]);
            if (refPenumbra) {
                ++m.penumbraPixels;
                sumAbsPenumbra += e;
            }
            if (e > kSoftErrorTolerance && e <= kVisibilityTolerance) {
                ++m.softErrorPixels;
                if (nearEdge[i]) ++m.softErrorNearEdge;
            }
            const auto heat = heatColor(float(e));
            std::copy(heat.begin(), heat.end(), out.heatRgb.begin() + 3 * std::ptrdiff_t(i));
            bool someLightWrong = false;
            for (std::size_t l = 0; l < lightSum.size(); ++l) {
                const float lm = method.lightVisibility[l][i], lr = reference.lightVisibility[l][i];
                const double el = std::isfinite(lm) && std::isfinite(lr) ? std::fabs(double(lm) - double(lr)) : 1.0;
                LightError& le = m.perLight[l];
                lightSum[l] += el;
                if (isPenumbra(lr)) {
                    ++le.penumbraPixels;
                    lightPenumbraSum[l] += el;
                }
                if (el > kSoftErrorTolerance && el <= kVisibilityTolerance) ++le.softErrorPixels;
                if (std::isfinite(lm) && std::isfinite(lr)) {
                    const PixelClass lc = classifyCounted(lm, lr);
                    le.falseShadow += lc == PixelClass::FalseShadow;
                    le.missedShadow += lc == PixelClass::MissedShadow;
                    someLightWrong = someLightWrong || lc == PixelClass::FalseShadow || lc == PixelClass::MissedShadow;
                }
                const auto lh = heatColor(float(el));
                std::copy(lh.begin(), lh.end(), out.lightHeatRgb[l].begin() + 3 * std::ptrdiff_t(i));
            }
            m.perLightWrongPixels += someLightWrong;
            const bool shM = vm <= kVisibilityTolerance, shR = vr <= kVisibilityTolerance;
            m.shadowedMethod += shM;
            m.shadowedReference += shR;
            m.shadowedIntersection += shM && shR;
            m.shadowedUnion += shM || shR;
            ObjectErrors& obj = perObject[roundId(idr)];
            ++obj.counted;
            if (c == PixelClass::FalseShadow) {
                ++m.falseShadow;
                ++obj.falseShadow;
                if (m.hasBlockerIds && std::isfinite(method.blockerId[i]) &&
                    roundId(method.blockerId[i]) == roundId(idr)) {
                    ++m.selfShadowAcne;
                    ++obj.selfShadowAcne;
                    if (nr < kTerminatorNdotL) ++m.selfShadowAcneGrazing;
                }
                if (nearEdge[i]) ++m.falseShadowNearEdge;
            } else if (c == PixelClass::MissedShadow) {
                ++m.missedShadow;
                ++obj.missedShadow;
                if (nearEdge[i]) ++m.missedShadowNearEdge;
                const bool terminator = m.hasReferenceBlockerIds && std::isfinite(reference.blockerId[i]) &&
                                        roundId(reference.blockerId[i]) == roundId(idr) && nr < kTerminatorNdotL;
                if (terminator) {
                    ++m.terminatorMissed;
                    ++obj.terminatorMissed;
                }
                // The reference's blocker, by its distance from the receiver: within the contact
                // distance, a bias leak; farther and away from the reference's shadow edges,
                // bleeding (near an edge it is the edge's aliasing). Without a blocker neither.
                if (m.hasBlockerDistance && roundId(reference.blockerId[i]) > 0 &&
                    std::isfinite(reference.blockerDistance[i])) {
                    if (double(reference.blockerDistance[i]) <= contactAt(i, nr)) {
                        ++m.biasLeak;
                        if (terminator) ++m.terminatorBiasLeak;
                        if (nearEdge[i]) ++m.biasLeakNearEdge;
                    } else if (!nearEdge[i] && !m.pointSampled && !terminator) {
                        // Bleeding is a filter's (a ray has none), and the terminator's faceted
                        // shadow is counted apart, whatever its blocker's distance.
                        ++m.bleeding;
                    }
                }
            } else if (c == PixelClass::AgreeLit) {
                ++m.agreeLit;
            } else {
                ++m.agreeShadow;
            }
        }
        if (c == PixelClass::NotCounted || c == PixelClass::Invalid) {
            const auto& flat = c == PixelClass::NotCounted ? DiffColors::kNotCounted : DiffColors::kInvalid;
            std::copy(flat.begin(), flat.end(), out.heatRgb.begin() + 3 * std::ptrdiff_t(i));
            for (auto& lh : out.lightHeatRgb) std::copy(flat.begin(), flat.end(), lh.begin() + 3 * std::ptrdiff_t(i));
        }
        if (c == PixelClass::NotCounted) ++m.notCounted;
        if (c == PixelClass::Invalid) ++m.invalid;
        out.classes[i] = c;
        const auto rgb =
            diffColor(c, reference.beauty[3 * i], reference.beauty[3 * i + 1], reference.beauty[3 * i + 2]);
        std::copy(rgb.begin(), rgb.end(), out.diffRgb.begin() + 3 * std::ptrdiff_t(i));
    }

    const std::size_t wrong = m.falseShadow + m.missedShadow;
    m.falseShadowRate = rate(m.falseShadow, m.counted);
    m.missedShadowRate = rate(m.missedShadow, m.counted);
    m.mismatchRate = rate(wrong, m.counted);
    m.meanAbsVisibilityError = m.counted ? sumAbs / double(m.counted) : 0.0;
    m.meanAbsVisibilityErrorPenumbra = m.penumbraPixels ? sumAbsPenumbra / double(m.penumbraPixels) : 0.0;
    m.softErrorRate = rate(m.softErrorPixels, m.counted);
    for (std::size_t l = 0; l < lightSum.size(); ++l) {
        LightError& le = m.perLight[l];
        le.meanAbsVisibilityError = m.counted ? lightSum[l] / double(m.counted) : 0.0;
        le.meanAbsVisibilityErrorPenumbra = le.penumbraPixels ? lightPenumbraSum[l] / double(le.penumbraPixels) : 0.0;
    }
    m.shadowIoU = m.shadowedUnion ? double(m.shadowedIntersection) / double(m.shadowedUnion) : 1.0;
    m.silhouetteMismatchRate = rate(m.silhouetteMismatch, m.totalPixels);
    m.selfShadowAcneRate = rate(m.selfShadowAcne, m.counted);
    if (std::isinf(m.contactDistance)) m.contactDistance = contact.at(1.0f, contact.texelAt(nullptr));  // none counted
    m.bleedingRate = rate(m.bleeding, m.counted);
    m.biasLeakRate = rate(m.biasLeak, m.counted);
    m.terminatorMissedRate = rate(m.terminatorMissed, m.counted);
    m.aliasingPixels = m.pointSampled ? 0 : m.falseShadowNearEdge + m.missedShadowNearEdge - m.biasLeakNearEdge;
    m.biasErrorPixels = wrong - m.aliasingPixels;
    m.aliasingRate = rate(m.aliasingPixels, m.counted);
    m.biasErrorRate = rate(m.biasErrorPixels, m.counted);
    for (auto& [id, obj] : perObject) {
        obj.objectId = static_cast<int>(id);
        m.perObject.push_back(obj);
    }
    m.hotspot = findHotspot(out.classes, w, h, options.hotspotSize);
    m.methodBackend = attribute(method, "backend");
    m.referenceBackend = attribute(reference, "backend");
    m.methodTiming = timingOf(method);
    m.referenceTiming = timingOf(reference);
    m.methodHealth = measureHealth(method);
    m.referenceHealth = measureHealth(reference);
    return out;
}

nlohmann::json toJson(const Metrics& m) {
    nlohmann::json perObject = nlohmann::json::array();
    for (const auto& o : m.perObject)
        perObject.push_back({{"object_id", o.objectId},
                             {"counted", o.counted},
                             {"false_shadow", o.falseShadow},
                             {"missed_shadow", o.missedShadow},
                             {"self_shadow_acne", o.selfShadowAcne},
                             {"terminator_missed", o.terminatorMissed}});
    nlohmann::json j = {
        {"width", m.width},
        {"height", m.height},
        {"total_pixels", m.totalPixels},
        {"counted", m.counted},
        {"agree_lit", m.agreeLit},
        {"agree_shadow", m.agreeShadow},
        {"false_shadow", m.falseShadow},
        {"missed_shadow", m.missedShadow},
        {"not_counted", m.notCounted},
        {"invalid", m.invalid},
        {"false_shadow_rate", m.falseShadowRate},
        {"missed_shadow_rate", m.missedShadowRate},
        {"mismatch_rate", m.mismatchRate},
        {"mean_abs_visibility_error", m.meanAbsVisibilityError},
        {"max_abs_visibility_error", m.maxAbsVisibilityError},
        {"penumbra_pixels", m.penumbraPixels},
        {"mean_abs_visibility_error_penumbra", m.meanAbsVisibilityErrorPenumbra},
        {"soft_error_pixels", m.softErrorPixels},
        {"soft_error_rate", m.softErrorRate},
        {"soft_error_tolerance", kSoftErrorTolerance},
        {"soft_error_near_edge", m.softErrorNearEdge},
        {"per_light_wrong_pixels", m.perLightWrongPixels},
        {"shadowed_method", m.shadowedMethod},
        {"shadowed_reference", m.shadowedReference},
        {"shadowed_intersection", m.shadowedIntersection},
        {"shadowed_union", m.shadowedUnion},
        {"shadow_iou", m.shadowIoU},
        {"silhouette_mismatch", m.silhouetteMismatch},
        {"silhouette_mismatch_rate", m.silhouetteMismatchRate},
        {"ndotl_sign_mismatch", m.ndotlSignMismatch},
        {"has_blocker_ids", m.hasBlockerIds},
        {"edge_radius", m.edgeRadius},
        {"reference_shadow_edge_pixels", m.referenceShadowEdgePixels},
        {"false_shadow_near_edge", m.falseShadowNearEdge},
        {"missed_shadow_near_edge", m.missedShadowNearEdge},
        {"point_sampled", m.pointSampled},
        {"aliasing_pixels", m.aliasingPixels},
        {"bias_error_pixels", m.biasErrorPixels},
        {"aliasing_rate", m.aliasingRate},
        {"bias_error_rate", m.biasErrorRate},
        {"per_object", perObject},
        {"hotspot",
         {{"x", m.hotspot.x}, {"y", m.hotspot.y}, {"size", m.hotspot.size}, {"wrong_pixels", m.hotspot.wrongPixels}}},
        {"method_backend", m.methodBackend},
        {"reference_backend", m.referenceBackend},
        {"method_timing", toJson(m.methodTiming)},
        {"reference_timing", toJson(m.referenceTiming)},
        {"method_non_finite", toJson(m.methodHealth)},
        {"reference_non_finite", toJson(m.referenceHealth)},
    };
    nlohmann::json lights = nlohmann::json::array();
    for (const LightError& l : m.perLight)
        lights.push_back({{"light", l.light},
                          {"mean_abs_visibility_error", l.meanAbsVisibilityError},
                          {"penumbra_pixels", l.penumbraPixels},
                          {"mean_abs_visibility_error_penumbra", l.meanAbsVisibilityErrorPenumbra},
                          {"soft_error_pixels", l.softErrorPixels},
                          {"false_shadow", l.falseShadow},
                          {"missed_shadow", l.missedShadow}});
    j["per_light"] = lights;
    // Without blocker ids self-shadow acne is unknown, not zero.
    if (m.hasBlockerIds) {
        j["self_shadow_acne"] = m.selfShadowAcne;
        j["self_shadow_acne_rate"] = m.selfShadowAcneRate;
        j["self_shadow_acne_grazing"] = m.selfShadowAcneGrazing;
    } else {
        j["self_shadow_acne"] = nullptr;
        j["self_shadow_acne_rate"] = nullptr;
        j["self_shadow_acne_grazing"] = nullptr;
    }
    j["terminator_missed"] = nullptr;
    j["terminator_missed_rate"] = nullptr;
    if (m.hasReferenceBlockerIds) {
        j["terminator_missed"] = m.terminatorMissed;
        j["terminator_missed_rate"] = m.terminatorMissedRate;
    }
    // Without the reference's blocker distances (older frames) bleeding is unknown, not zero.
    for (const char* k : {"bleeding", "bias_leak", "bias_leak_near_edge", "bleeding_rate", "bias_leak_rate",
                          "contact_distance", "bias_leak_beside_terminator", "bias_leak_beside_terminator_rate"})
        j[k] = nullptr;
    if (m.hasBlockerDistance) {
        j["bleeding"] = m.bleeding;
        j["bias_leak"] = m.biasLeak;
        j["bias_leak_near_edge"] = m.biasLeakNearEdge;
        j["bleeding_rate"] = m.bleedingRate;
        j["bias_leak_rate"] = m.biasLeakRate;
        // What the report's "bias leak, terminators aside" row and the findings count.
        j["bias_leak_beside_terminator"] = m.biasLeakBesideTerminator();
        j["bias_leak_beside_terminator_rate"] = double(m.biasLeakBesideTerminator()) / std::max<double>(1, m.counted);
        j["contact_distance"] = m.contactDistance;
    }
    return j;
}

bool softErrorDominates(const Metrics& m) {
    const std::size_t away = softErrorAwayFromEdges(m);
    return m.counted > 0 && double(away) / double(m.counted) > kNotableSoftErrorRate &&
           away > m.falseShadow + m.missedShadow;
}

std::size_t softErrorAwayFromEdges(const Metrics& m) {
    return m.softErrorPixels - std::min(m.softErrorPixels, m.softErrorNearEdge);
}

bool lightsHideWrongPixels(const Metrics& m) {
    return m.perLight.size() > 1 && m.perLightWrongPixels > m.falseShadow + m.missedShadow &&
           double(m.perLightWrongPixels) > kNotableSoftErrorRate * double(m.counted);
}

std::string summaryLine(const Metrics& m) {
    std::string s = "counted " + formatCount(m.counted) + " px: false shadow " + formatPercent(m.falseShadowRate);
    if (m.hasBlockerIds) s += " (self acne " + formatPercent(m.selfShadowAcneRate) + ")";
    s += ", missed " + formatPercent(m.missedShadowRate) + ", mismatch " + formatPercent(m.mismatchRate) + ", IoU " +
         formatFixed(m.shadowIoU, 3) + ", mean |dV| " + formatFixed(m.meanAbsVisibilityError, 4) + " (penumbra " +
         formatFixed(m.meanAbsVisibilityErrorPenumbra, 3) + " over " + formatCount(m.penumbraPixels) +
         " px), off by > " + formatFixed(kSoftErrorTolerance, 2) + " within tau " + formatCount(m.softErrorPixels) +
         " px (" + formatPercent(m.softErrorRate) + ", " + formatCount(m.softErrorNearEdge) +
         " at shadow edges), silhouette " + formatPercent(m.silhouetteMismatchRate) + ", run time " +
         formatRunTime(m.methodTiming.totalMs) + " (reference " + formatRunTime(m.referenceTiming.totalMs) + ")";
    const std::size_t bad = m.methodHealth.total() + m.referenceHealth.total();
    if (bad > 0)
        s += ", NON-FINITE values: method " + formatCount(m.methodHealth.total()) + ", reference " +
             formatCount(m.referenceHealth.total());
    // Filtered acne and wrong penumbrae stay under tau: where they outnumber the wrong pixels the
    // mismatch and the IoU read clean while the image is not, so the line says so.
    const std::size_t lightWrong = m.perLightWrongPixels;
    const bool lightsHide = lightsHideWrongPixels(m);
    if (softErrorDominates(m))
        s += "; SOFT ERROR dominates: " + formatPercent(double(softErrorAwayFromEdges(m)) / double(m.counted)) +
             " of the counted pixels are partly wrong away from the shadow edges (" +
             (lightsHide ? "one light's shadow wrong where another still reaches"
                         : "filtered acne, a penumbra of the wrong width") +
             "), more than the mismatch counts: judge this frame by mean |dV|";
    if (lightsHide)
        s += "; PER LIGHT " + formatCount(lightWrong) + " px wrong outright in the lights' own channels, more than " +
             "the combined mask's " + formatCount(m.falseShadow + m.missedShadow);
    return s;
}

}  // namespace shadowlab::compare
