// scene/settings.h: what a user can tune for one render, resolved from the command line,
// then the scene's "shadow" block, then scene-scaled defaults (resolveSettings()).
// Biases are in world units or shadow-map texels, never in a driver's depth-bias units.
#pragma once

#include <optional>
#include <string>

#include "scene/scene.h"

namespace shadowlab::scene {

enum class Backend { Raster, Raytrace, Reference };
// none: nearest texel; pcf2x2: bilinear 2x2 compare filtering; pcf: mean of pcfSize x pcfSize
// compare taps one texel apart; poisson: 16 compare taps on a per-pixel rotated Poisson disk of
// diameter pcfSize texels (raster/ implements them; see docs/raster.md).
// pcss: percentage-closer soft shadows for spot and point lights with a radius (Fernando 2005): a
// blocker search, then a Poisson filter as wide as the penumbra; elsewhere it is `poisson`.
// Filterable maps (raster/moment_maps.h, docs/raster.md): the depths become moments, blurred,
// sampled with a linear filter. vsm: Chebyshev on (z, z²) with light-bleeding reduction; evsm2,
// evsm4: Chebyshev on exponentially warped depths (positive; positive and negative); esm:
// exp(c·(z_occluder − z_receiver)); msm: 4-moment Hamburger moment shadow map (Peters & Klein 2015).
enum class ShadowFilter { None, Pcf2x2, Pcf, Poisson, Pcss, Vsm, Evsm2, Evsm4, Esm, Msm };
inline bool isFilterable(ShadowFilter f) { return f >= ShadowFilter::Vsm; }

// The filterable maps' parameters. Depths are the maps' normalized depths 0..1 (each map spans its
// light's fitted depth range), so the defaults scale with the scene. See docs/raster.md.
struct MomentSettings {
    double minVariance = 1e-6;    // vsm, evsm: variance floor (normalized depth², warped for evsm)
    double bleedReduction = 0.2;  // vsm, evsm: linstep(amount, 1, p) cuts this much of the tail
    double evsmPositive = 40.0;   // evsm: exp(c·(2z−1)); ≤ kMaxEvsmExponent (float overflow of the square)
    double evsmNegative = 5.0;    // evsm4: −exp(−c·(2z−1)); ≤ kMaxEvsmExponent
    double esmExponent = 80.0;    // esm: exp(c·z) stored; ≤ kMaxEsmExponent
    double momentBias = 3e-5;     // msm: moments pulled toward (0.5, 0.5, 0.5, 0.5) by this
    int blurWidth = 5;            // box blur width in texels (odd, 1 = none), both directions
};
// float32 holds up to 3.4e38 = e^88.7: EVSM stores exp(2c) (the square at z = 1), so c ≤ 44, less
// a margin for the blur's sums: 42. ESM stores exp(c) at z = 1: c ≤ 88, margin: 85.
inline constexpr double kMaxEvsmExponent = 42.0;
inline constexpr double kMaxEsmExponent = 85.0;
inline constexpr int kMaxBlurWidth = 63;
enum class Precision { Float, Double };

// Cascaded shadow maps: at most this many cascades per directional light. Four is what engines
// commonly ship (each cascade is one more depth pass; beyond four the near cascades gain little
// texel density while every pass redraws the whole scene), see docs/raster.md.
inline constexpr int kMaxCascades = 4;
// The widest cascade blend band, as a fraction of a slice: at most half, so the band before a
// split never reaches the band before the previous one (a pixel mixes at most two cascades).
inline constexpr double kMaxCascadeBlend = 0.5;

// The shadow-map size when neither the command line nor the scene sets one.
inline constexpr int kDefaultShadowMapSize = 2048;

struct RasterSettings {
    int shadowMapSize = kDefaultShadowMapSize;  // texels per side
    // True when shadowMapSize is the default (no option, no scene value): the raster backend may
    // then lower it to what the receivers' detail on screen needs (raster::chooseShadowMapSize).
    bool shadowMapSizeIsDefault = false;
    double depthBias = 0.0;  // world units along the light direction
    // True when depthBias is defaultDepthBias() (no option, no scene value): the raster backend
    // then re-derives it as half a texel of each fitted map (fitLightFrustum), see docs/raster.md.
    bool depthBiasIsDefault = false;
    // texels: bias += slopeBias * texelWorldSize * min(tan(angle to light), 10); past the cap the
    // raster shader lifts the lookup along the normal by slopeBias * texel * (sin - 10 cos)
    double slopeBias = 0.0;
    ShadowFilter filter = ShadowFilter::Pcf2x2;
    int pcfSize = 3;         // pcf: taps per side; poisson: kernel diameter in texels (1..15)
    MomentSettings moments;  // vsm, evsm2, evsm4, esm, msm
    double normalOffset =
        0.0;  // texels: the receiver moves along its normal by this x texel world size (plus the lift above)
    // Receiver-plane depth bias (Isidoro 2006): each filter tap compares against the receiver's
    // plane extrapolated to the texel it reads, instead of the slope bias (see docs/raster.md).
    bool receiverPlaneBias = false;
    // Constant and slope bias through the rasterizer's depth-bias state (vkCmdSetDepthBias) in the
    // depth pass of directional maps, converted from the world and texel units above, instead of
    // in the lit shader (spot and point maps keep the shader's; see docs/raster.md).
    bool hardwareBias = false;
    // Fit each light's map to the casters of visible receivers (else the scene's bounding sphere).
    // resolveSettings() turns it on unless the command line or the scene says otherwise; a
    // RasterSettings made in code starts from the unfitted map.
    bool fitLightFrustum = false;
    // True when fitLightFrustum is resolveSettings()'s default (no option, no scene value): only
    // --explain and the Frame's reasons read it.
    bool fitLightFrustumIsDefault = false;
    // Snap fitted directional maps and cascades to the world-fixed texel grid and their sizes to
    // coarse steps, so a moving camera does not make them swim. Off only for the temporal study
    // (docs/temporal.md), which measures what snapping buys; spot and point maps always snap.
    bool snapLightFrustum = true;
    // Directional lights: split the view's depth range into this many slices, each with its own
    // map (1 = one map for the whole view, as fitLightFrustum or the bounding sphere decide).
    int cascades = 1;
    // True when cascades is the default (no option, no scene value): the raster backend may then
    // raise it to what keeps the shadow texel near the pixel size (raster::chooseCascades).
    bool cascadesIsDefault = false;
    // Blend band before each cascade split: the last cascadeBlend of each slice (0..0.5, 0 = off:
    // the cascade switches abruptly at the split) mixes its cascade's visibility with the next's.
    double cascadeBlend = 0.0;
    // Leave objects that cannot cast onto the receivers a map serves out of its depth pass (every
    // map: raster castsOnto); tests and benchmarks turn it off to compare.
    bool cullCasters = true;
    std::string device;     // "" = lavapipe if present, else the first device; index or name substring
    bool validate = false;  // enable VK_LAYER_KHRONOS_validation and count its messages
};

struct RaytraceSettings {
    double rayBias = 0.0;  // world units along the normal (the lesson's bias)
    // The default's view scaling (docs/decisions.md, "Bias defaults"): where rayBiasPixels > 0 the
    // bias at a point is min(rayBias, max(rayBiasFloor, rayBiasPixels × the pixel's footprint at
    // its view depth)); 0 = rayBias everywhere, as a bias given by the user is.
    double rayBiasPixels = 0.0;
    double rayBiasFloor = 0.0;
    bool robustOffset = false;  // offset by a bound on the hit point's rounding error instead
    Precision precision = Precision::Float;
    int samples = 1;  // shadow samples per pixel for area lights
    int threads = 0;  // 0 = all hardware threads
};

struct RenderSettings {
    RasterSettings raster;
    RaytraceSettings raytrace;
};

// What the command line asked for; unset fields fall back to the scene's "shadow" block, then
// to the defaults of resolveSettings().
struct SettingsOverrides {
    std::optional<int> shadowMapSize;
    std::optional<double> depthBias;
    std::optional<double> slopeBias;
    std::optional<std::string> filter;
    std::optional<int> pcfSize;             // --pcf-size
    std::optional<double> minVariance;      // --min-variance
    std::optional<double> bleedReduction;   // --bleeding-reduction
    std::optional<double> evsmPositive;     // --evsm-positive
    std::optional<double> evsmNegative;     // --evsm-negative
    std::optional<double> esmExponent;      // --esm-exponent
    std::optional<double> momentBias;       // --moment-bias
    std::optional<int> blurWidth;           // --blur-width
    std::optional<double> normalOffset;     // --normal-offset (texels)
    std::optional<bool> receiverPlaneBias;  // --receiver-plane-bias
    std::optional<bool> hardwareBias;       // --hardware-bias
    std::optional<bool> fitLightFrustum;    // --fit-light-frustum on|off (--no-fit-light-frustum)
    std::optional<bool> snapLightFrustum;   // --no-snap sets false (the temporal study)
    std::optional<int> cascades;            // --cascades (1..kMaxCascades)
    std::optional<double> cascadeBlend;     // --cascade-blend (0..kMaxCascadeBlend)
    std::optional<std::string> rayBias;     // a number or "robust"
    std::optional<std::string> precision;
    std::optional<int> samples;
    std::optional<int> threads;
    std::optional<std::string> device;
    bool validate = false;
};

// Scene-scaled defaults (see docs/decisions.md): the lesson's constant ray bias, and half a
// shadow-map texel of constant depth bias for a map fitted to the scene's bounding sphere.
double defaultRayBias(const Scene& scene);
// What float rounding of a hit point needs far from the origin: 16 float steps of the scene's
// largest coordinate (the floor of the default ray bias).
double rayBiasFloor(const Scene& scene);
// The default ray bias at a view depth, in pixels of footprint (docs/decisions.md).
inline constexpr double kDefaultRayBiasPixels = 0.5;
// The bias a point gets under `s`: rayBias, or its view-scaled share at view depth z (world
// units) for a camera of vertical field fovYDegrees over `height` pixels.
double rayBiasAt(const RaytraceSettings& s, double z, double fovYDegrees, int height);
double defaultDepthBias(const Scene& scene, int shadowMapSize);
// Throws InputError naming the option (e.g. "--filter: expected none|pcf2x2, got 'x'").
RenderSettings resolveSettings(const Scene& scene, const SettingsOverrides& overrides);

// The reference: the ray tracer in double precision with robust offsets and no tunable bias.
RaytraceSettings referenceSettings(const RaytraceSettings& base);

const char* toString(ShadowFilter f);
const char* toString(Precision p);
const char* toString(Backend b);

}  // namespace shadowlab::scene
