// scene/settings.cpp: command line over the scene's "shadow" block over scene-scaled defaults.
#include "scene/settings.h"

#include <algorithm>
#include <cmath>
#include <sstream>
#include <string>

#include "scene/error.h"

namespace shadowlab::scene {

namespace {

ShadowFilter parseFilter(const std::string& text, const std::string& where) {
    if (text == "none") return ShadowFilter::None;
    if (text == "pcf2x2") return ShadowFilter::Pcf2x2;
    if (text == "pcf") return ShadowFilter::Pcf;
    if (text == "poisson") return ShadowFilter::Poisson;
    if (text == "pcss") return ShadowFilter::Pcss;
    if (text == "vsm") return ShadowFilter::Vsm;
    if (text == "evsm2") return ShadowFilter::Evsm2;
    if (text == "evsm4") return ShadowFilter::Evsm4;
    if (text == "esm") return ShadowFilter::Esm;
    if (text == "msm") return ShadowFilter::Msm;
    throw InputError(where + ": expected none|pcf2x2|pcf|poisson|pcss|vsm|evsm2|evsm4|esm|msm, got '" + text + "'");
}

Precision parsePrecision(const std::string& text, const std::string& where) {
    if (text == "float") return Precision::Float;
    if (text == "double") return Precision::Double;
    throw InputError(where + ": expected float|double, got '" + text + "'");
}

// The value as given (shortest round-trip form), for an error message.
std::string formatBlend(double v) {
    std::ostringstream s;
    s.precision(17);
    s << v;
    return s.str();
}

}  // namespace

double defaultRayBias(const Scene& scene) {
    // The lesson's bias (1e-4) was for a scene of unit size. Scale it with the scene's extent,
    // and never below what float rounding of the coordinates needs (about 2^-23 relative, with
    // a 16x margin for the arithmetic of a hit point).
    const Bounds b = scene.bounds();
    const double extent = std::max(b.diagonal(), 1e-30);
    return std::max(1e-4 * extent, rayBiasFloor(scene));
}

double rayBiasFloor(const Scene& scene) { return 16.0 * 1.1920929e-7 * scene.bounds().maxAbsCoordinate(); }

double rayBiasAt(const RaytraceSettings& s, double z, double fovYDegrees, int height) {
    if (!(s.rayBiasPixels > 0.0)) return s.rayBias;
    const double footprint =
        2.0 * z * std::tan(0.5 * fovYDegrees * 3.14159265358979323846 / 180.0) / std::max(height, 1);
    const double scaled = s.rayBiasPixels * footprint;
    // NaN (no depth) falls to the scene-scaled bias.
    return std::isfinite(scaled) ? std::min(s.rayBias, std::max(s.rayBiasFloor, scaled)) : s.rayBias;
}

double defaultDepthBias(const Scene& scene, int shadowMapSize) {
    // An orthographic map fitted to the bounding sphere spans its diameter (the bounds'
    // diagonal): one texel is diagonal / size in world units.
    return 0.5 * scene.bounds().diagonal() / std::max(shadowMapSize, 1);
}

RenderSettings resolveSettings(const Scene& scene, const SettingsOverrides& o) {
    RenderSettings s;
    const ShadowDefaults& d = scene.shadow;

    s.raster.shadowMapSize = o.shadowMapSize.value_or(d.shadowMapSize.value_or(kDefaultShadowMapSize));
    s.raster.shadowMapSizeIsDefault = !o.shadowMapSize && !d.shadowMapSize;
    if (s.raster.shadowMapSize < 16 || s.raster.shadowMapSize > 16384)
        throw InputError("--shadow-map-size: must be in 16..16384, got " + std::to_string(s.raster.shadowMapSize));
    // Default bias: half a texel of constant bias and one texel of slope bias.
    s.raster.depthBias = o.depthBias.value_or(d.depthBias.value_or(defaultDepthBias(scene, s.raster.shadowMapSize)));
    s.raster.depthBiasIsDefault = !o.depthBias && !d.depthBias;
    s.raster.slopeBias = o.slopeBias.value_or(d.slopeBias.value_or(1.0));
    if (!std::isfinite(s.raster.depthBias) || s.raster.depthBias < 0.0)
        throw InputError("--depth-bias: must be a finite value >= 0 (world units)");
    if (!std::isfinite(s.raster.slopeBias) || s.raster.slopeBias < 0.0)
        throw InputError("--slope-bias: must be a finite value >= 0 (texels)");
    s.raster.filter =
        o.filter ? parseFilter(*o.filter, "--filter") : parseFilter(d.filter.value_or("pcf2x2"), "shadow.filter");
    s.raster.pcfSize = o.pcfSize.value_or(d.pcfSize.value_or(3));
    if (s.raster.pcfSize < 1 || s.raster.pcfSize > 15)
        throw InputError("--pcf-size: must be in 1..15 texels, got " + std::to_string(s.raster.pcfSize));
    MomentSettings& m = s.raster.moments;
    auto take = [](double& into, const std::optional<double>& option, const std::optional<double>& fromScene,
                   const char* name, double lo, double hi) {
        into = option.value_or(fromScene.value_or(into));
        if (!(into >= lo && into <= hi))  // also rejects NaN
            throw InputError(std::string(name) + ": must be in " + formatBlend(lo) + ".." + formatBlend(hi) + ", got " +
                             formatBlend(into));
    };
    take(m.minVariance, o.minVariance, d.minVariance, "--min-variance", 0.0, 1.0);
    take(m.bleedReduction, o.bleedReduction, d.bleedReduction, "--bleeding-reduction", 0.0, 0.99);
    take(m.evsmPositive, o.evsmPositive, d.evsmPositive, "--evsm-positive", 0.0, kMaxEvsmExponent);
    take(m.evsmNegative, o.evsmNegative, d.evsmNegative, "--evsm-negative", 0.0, kMaxEvsmExponent);
    take(m.esmExponent, o.esmExponent, d.esmExponent, "--esm-exponent", 0.0, kMaxEsmExponent);
    take(m.momentBias, o.momentBias, d.momentBias, "--moment-bias", 0.0, 1.0);
    m.blurWidth = o.blurWidth.value_or(d.blurWidth.value_or(m.blurWidth));
    if (m.blurWidth < 1 || m.blurWidth > kMaxBlurWidth || m.blurWidth % 2 == 0)
        throw InputError("--blur-width: must be odd, in 1.." + std::to_string(kMaxBlurWidth) + " texels, got " +
                         std::to_string(m.blurWidth));
    s.raster.normalOffset = o.normalOffset.value_or(d.normalOffset.value_or(0.0));
    if (!std::isfinite(s.raster.normalOffset) || s.raster.normalOffset < 0.0)
        throw InputError("--normal-offset: must be a finite value >= 0 (texels)");
    s.raster.receiverPlaneBias = o.receiverPlaneBias.value_or(d.receiverPlaneBias.value_or(false));
    s.raster.hardwareBias = o.hardwareBias.value_or(d.hardwareBias.value_or(false));
    // Fitted by default: a map around the scene's bounding sphere loses every shadow of small
    // casters on a large ground (docs/decisions.md, "Defaults that keep the shadow").
    s.raster.fitLightFrustum = o.fitLightFrustum.value_or(d.fitLightFrustum.value_or(true));
    s.raster.fitLightFrustumIsDefault = !o.fitLightFrustum && !d.fitLightFrustum;
    s.raster.snapLightFrustum = o.snapLightFrustum.value_or(true);
    s.raster.cascades = o.cascades.value_or(d.cascades.value_or(1));
    s.raster.cascadesIsDefault = !o.cascades && !d.cascades;
    if (s.raster.cascades < 1 || s.raster.cascades > kMaxCascades)
        throw InputError("--cascades: must be in 1.." + std::to_string(kMaxCascades) + ", got " +
                         std::to_string(s.raster.cascades));
    s.raster.cascadeBlend = o.cascadeBlend.value_or(d.cascadeBlend.value_or(0.0));
    if (!(s.raster.cascadeBlend >= 0.0 && s.raster.cascadeBlend <= kMaxCascadeBlend))  // also rejects NaN
        throw InputError("--cascade-blend: must be in 0..0.5 (a fraction of each cascade's slice), got " +
                         formatBlend(s.raster.cascadeBlend));
    s.raster.device = o.device.value_or("");
    s.raster.validate = o.validate;

    if (o.rayBias) {
        if (*o.rayBias == "robust") {
            s.raytrace.robustOffset = true;
        } else {
            std::size_t used = 0;
            double v = 0;
            try {
                v = std::stod(*o.rayBias, &used);
            } catch (const std::exception&) {
                used = 0;
            }
            if (used != o.rayBias->size() || !std::isfinite(v) || v < 0.0)
                throw InputError("--ray-bias: expected a number >= 0 or 'robust', got '" + *o.rayBias + "'");
            s.raytrace.rayBias = v;
        }
    } else if (d.robustRayOffset.value_or(false)) {
        s.raytrace.robustOffset = true;
    } else if (d.rayBias) {
        s.raytrace.rayBias = *d.rayBias;
    } else {
        // The lesson's bias scaled to the scene, at most; less where a pixel covers less, so that
        // a large ground does not set the offset of what stands near the camera.
        s.raytrace.rayBias = defaultRayBias(scene);
        s.raytrace.rayBiasPixels = kDefaultRayBiasPixels;
        s.raytrace.rayBiasFloor = rayBiasFloor(scene);
    }
    s.raytrace.precision = o.precision ? parsePrecision(*o.precision, "--precision")
                                       : parsePrecision(d.precision.value_or("float"), "shadow.precision");
    s.raytrace.samples = o.samples.value_or(d.samples.value_or(16));
    if (s.raytrace.samples < 1 || s.raytrace.samples > 65536)
        throw InputError("--samples: must be in 1..65536, got " + std::to_string(s.raytrace.samples));
    s.raytrace.threads = o.threads.value_or(0);
    if (s.raytrace.threads < 0 || s.raytrace.threads > 1024)
        throw InputError("--threads: must be in 0..1024 (0 = all), got " + std::to_string(s.raytrace.threads));
    return s;
}

RaytraceSettings referenceSettings(const RaytraceSettings& base) {
    RaytraceSettings r = base;
    r.precision = Precision::Double;
    r.robustOffset = true;
    r.rayBias = 0.0;
    r.rayBiasPixels = 0.0;
    // Area lights: enough samples that the reference's own noise stays below the error it
    // reports (see docs/decisions.md); point lights need one.
    r.samples = std::max(base.samples, 256);
    return r;
}

const char* toString(ShadowFilter f) {
    switch (f) {
        case ShadowFilter::None: return "none";
        case ShadowFilter::Pcf2x2: return "pcf2x2";
        case ShadowFilter::Pcf: return "pcf";
        case ShadowFilter::Poisson: return "poisson";
        case ShadowFilter::Pcss: return "pcss";
        case ShadowFilter::Vsm: return "vsm";
        case ShadowFilter::Evsm2: return "evsm2";
        case ShadowFilter::Evsm4: return "evsm4";
        case ShadowFilter::Esm: return "esm";
        case ShadowFilter::Msm: return "msm";
    }
    return "?";
}
const char* toString(Precision p) { return p == Precision::Float ? "float" : "double"; }
const char* toString(Backend b) {
    switch (b) {
        case Backend::Raster: return "raster";
        case Backend::Raytrace: return "raytrace";
        case Backend::Reference: return "reference";
    }
    return "?";
}

}  // namespace shadowlab::scene
