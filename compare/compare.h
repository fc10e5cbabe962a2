// compare/compare.h: classifies each pixel of a method Frame against a reference Frame of the
// same scene and camera (DESIGN.md "Compare"), measures the shadow error and draws the
// difference image. See docs/compare.md for the rules and the colors.
#pragma once

#include <algorithm>
#include <array>
#include <cstddef>
#include <map>
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include <nlohmann/json.hpp>

#include "compare/thresholds.h"
#include "scene/frame.h"

namespace shadowlab::compare {

// What a pixel is, in the order of DESIGN.md's table. Invalid is ours: a non-finite value in
// a channel the rule reads (visibility, object_id, ndotl) of either frame.
enum class PixelClass : unsigned char {
    AgreeLit,
    AgreeShadow,
    FalseShadow,   // V_R − V_M > τ: acne, over-darkening (red)
    MissedShadow,  // V_M − V_R > τ: light leak, peter-panning (blue)
    NotCounted,    // silhouette mismatch, N·L ≤ 0, background (neutral gray)
    Invalid,       // NaN/Inf in the method or the reference (magenta)
};
inline constexpr int kPixelClassCount = 6;
const char* toString(PixelClass c);

// Display-encoded (0..1) colors of the difference image. Lit and shadowed agreement show the
// reference's luminance (desaturated, so a red or blue object in the scene cannot be mistaken
// for an error class) mapped into two separate bands: lit bright, shadow dark. Not-counted is
// a flat gray between the two bands, so silhouettes stay visible but carry no texture.
struct DiffColors {
    static constexpr std::array<float, 3> kFalseShadow{1.0f, 0.08f, 0.05f};
    static constexpr std::array<float, 3> kMissedShadow{0.10f, 0.40f, 1.0f};
    static constexpr std::array<float, 3> kNotCounted{0.42f, 0.42f, 0.42f};
    static constexpr std::array<float, 3> kInvalid{1.0f, 0.0f, 1.0f};
    // gray = base + scale · Y, Y = sRGB-encoded luminance of the reference beauty in 0..1.
    static constexpr float kLitBase = 0.62f, kLitScale = 0.33f;        // 0.62 .. 0.95
    static constexpr float kShadowBase = 0.06f, kShadowScale = 0.16f;  // 0.06 .. 0.22
};
// The diff color of one pixel given its class and the reference's linear beauty there.
std::array<float, 3> diffColor(PixelClass c, float refR, float refG, float refB);

// Pure rule of the table, for one pixel; exposed so tests and sweeps share it.
// `counted` is false when the ids differ, either is 0, or N·L ≤ 0 in either frame.
PixelClass classifyCounted(float vMethod, float vReference);

struct NonFinite {
    std::size_t nan = 0;
    std::size_t inf = 0;
    std::size_t total() const { return nan + inf; }
};

// Non-finite values per channel of one Frame; a stability check reads these.
struct FrameHealth {
    NonFinite beauty, visibility, objectId, ndotl, depth, blockerId;
    std::size_t total() const;
};
FrameHealth measureHealth(const scene::Frame& frame);

struct Timing {
    double totalMs = 0.0;
    std::vector<std::pair<std::string, double>> stagesMs;  // in the order they ran
};

// Errors on one receiver object (the object seen at the pixel).
struct ObjectErrors {
    int objectId = 0;  // index + 1
    std::size_t counted = 0;
    std::size_t falseShadow = 0;
    std::size_t missedShadow = 0;
    std::size_t selfShadowAcne = 0;
    std::size_t terminatorMissed = 0;
};

// The square window of the image with the most wrong (false + missed shadow) pixels; the
// report zooms into it so single-pixel acne is visible at a glance.
struct ErrorHotspot {
    int x = 0, y = 0;  // top-left pixel
    int size = 0;      // side in pixels; 0 when the image is empty
    std::size_t wrongPixels = 0;
};

// The continuous error of one light's own visibility channel (Frame::lightVisibility), over the
// frame's counted pixels. Where light i does not reach a point both frames hold 0 there.
struct LightError {
    int light = 0;  // index in scene order
    double meanAbsVisibilityError = 0.0;
    std::size_t penumbraPixels = 0;
    double meanAbsVisibilityErrorPenumbra = 0.0;
    std::size_t softErrorPixels = 0;
    // Counted pixels whose own channel crosses τ: this light's shadow wrong outright, which the
    // combined visibility may not count where another light still reaches the point.
    std::size_t falseShadow = 0, missedShadow = 0;
};

struct Metrics {
    int width = 0, height = 0;
    std::size_t totalPixels = 0;

    // Classes; counted = agreeLit + agreeShadow + falseShadow + missedShadow.
    std::size_t counted = 0;
    std::size_t agreeLit = 0, agreeShadow = 0, falseShadow = 0, missedShadow = 0;
    std::size_t notCounted = 0;  // includes silhouette mismatch, facing away, background
    std::size_t invalid = 0;     // non-finite in either frame; not counted

    // Rates over counted pixels (0 when nothing counts).
    double falseShadowRate = 0.0, missedShadowRate = 0.0;
    double mismatchRate = 0.0;            // (falseShadow + missedShadow) / counted
    double meanAbsVisibilityError = 0.0;  // mean |V_M − V_R| over counted pixels

    // Shadowed sets (V ≤ τ) over counted pixels; IoU = 1 when both are empty.
    std::size_t shadowedMethod = 0, shadowedReference = 0;
    std::size_t shadowedIntersection = 0, shadowedUnion = 0;
    double shadowIoU = 1.0;

    // Pixels where the object ids differ (either may be background), over all pixels.
    std::size_t silhouetteMismatch = 0;
    double silhouetteMismatchRate = 0.0;
    // Same object, but one frame has N·L > 0 and the other not (shading normals disagree).
    std::size_t ndotlSignMismatch = 0;

    // Self-shadow acne: false-shadow pixels whose method blocker id is the pixel's own object.
    // Needs the method's blocker ids (the reference's is 0 on any false-shadow pixel anyway).
    bool hasBlockerIds = false;
    std::size_t selfShadowAcne = 0;
    double selfShadowAcneRate = 0.0;  // over counted
    // Of it, pixels lit near grazing (the reference's N·L below kTerminatorNdotL): a curved
    // receiver bending away from its own map texels faster than the slope bias's tangent plane
    // follows, which a normal offset clears where a larger bias would cost contact shadows.
    std::size_t selfShadowAcneGrazing = 0;

    // Missed shadow split by the reference's blocker distance (Frame::blockerDistance): bias
    // leaks where the blocker is within the contact distance of the receiver (thresholds.h
    // kContactTexels), bleeding where it is farther and the pixel is away from the reference's
    // shadow edges (near one, a far blocker's missed shadow is the edge's aliasing: neither), and
    // never for a point-sampled method, which has no filter to bleed. Needs the reference's distances and a contact
    // distance from the method's bias and texel attributes (or CompareOptions); unknown, not
    // zero, without them.
    bool hasBlockerDistance = false;
    // D at tanθ ≤ 1 (the smallest it is), world units; with a spot or point-light map, whose texel
    // grows with the distance from the light, the smallest over the counted pixels.
    double contactDistance = 0.0;
    std::size_t bleeding = 0, biasLeak = 0;
    double bleedingRate = 0.0, biasLeakRate = 0.0;  // over counted

    // Missed shadow at a smooth-shaded mesh's terminator: the reference's blocker is the receiver's
    // own object and its N·L is below kTerminatorNdotL (the reference's facets shadowing their
    // neighbours, which offsets along the shading normal and a map's bias hide). Needs the
    // reference's blocker ids; unknown, not zero, without them.
    bool hasReferenceBlockerIds = false;
    std::size_t terminatorMissed = 0;
    double terminatorMissedRate = 0.0;  // over counted
    // Of the bias leaks, those at the terminator: a facet's neighbour is always within the
    // contact distance, so the findings keep them out of the peter-panning they name.
    std::size_t terminatorBiasLeak = 0;
    std::size_t biasLeakBesideTerminator() const { return biasLeak - std::min(biasLeak, terminatorBiasLeak); }

    // Edge-aware split of the wrong pixels: within edgeRadius pixels of a reference shadow
    // boundary they are aliasing (a resolution problem), elsewhere bias error. Two exceptions:
    // a missed-shadow pixel near an edge whose reference blocker lies within the contact
    // distance is a bias leak (a shadow thinner than the edge radius, lost whole to the bias,
    // lies near its own edges), and a point-sampled method has no aliasing at all.
    int edgeRadius = kDefaultEdgeRadiusPixels;
    std::size_t referenceShadowEdgePixels = 0;
    std::size_t falseShadowNearEdge = 0, missedShadowNearEdge = 0;
    std::size_t biasLeakNearEdge = 0;  // of missedShadowNearEdge, the bias leaks
    // The method tests each pixel's own point, as the reference does (a ray tracer: its frame
    // records a ray_bias and no shadow-map texel), so nothing of its error is a sampling grid's.
    bool pointSampled = false;
    // falseShadowNearEdge + missedShadowNearEdge − biasLeakNearEdge; 0 when pointSampled.
    std::size_t aliasingPixels = 0;
    std::size_t biasErrorPixels = 0;                 // the other wrong pixels
    double aliasingRate = 0.0, biasErrorRate = 0.0;  // over counted

    std::vector<ObjectErrors> perObject;  // objects with any counted pixel, by id
    ErrorHotspot hotspot;

    // Continuous error |V_M − V_R| beside the classes, which τ = 0.5 makes blind to a penumbra
    // that is wrong by less than half the range (docs/compare.md "Continuous error").
    double maxAbsVisibilityError = 0.0;           // over counted pixels
    std::size_t penumbraPixels = 0;               // counted with 0 < V_R < 1 (kPenumbraMargin)
    double meanAbsVisibilityErrorPenumbra = 0.0;  // mean |V_M − V_R| over them; 0 when none
    // Counted pixels with kSoftErrorTolerance < |V_M − V_R| ≤ τ: wrong, but agreeing in class.
    std::size_t softErrorPixels = 0;
    double softErrorRate = 0.0;  // over counted
    // Of softErrorPixels, those within edgeRadius of the reference's shadow edges: a filter's blur
    // of a hard edge (pcf2x2 softens every edge by a texel), not a wrong penumbra or banding.
    std::size_t softErrorNearEdge = 0;
    // Counted pixels where some light's own channel crosses τ (each pixel once, however many lights).
    std::size_t perLightWrongPixels = 0;
    std::vector<LightError> perLight;  // one per light when both frames have per-light channels

    std::string methodBackend, referenceBackend;  // Frame attribute "backend", if any
    Timing methodTiming, referenceTiming;
    FrameHealth methodHealth, referenceHealth;
};

struct CompareOptions {
    int edgeRadius = kDefaultEdgeRadiusPixels;
    int hotspotSize = 0;  // side of the hotspot window; 0 = min(width, height) / 6 in 16..96
    // The contact distance's parts, world units (b + (s + kContactTexels)·t·max(1, tanθ)); unset:
    // read from the method's attributes (raster: depth_bias, slope_bias, texel_world_size, the
    // largest of several maps, a spot's or cube face's "X*d" taken at the pixel's distance d along
    // its texel_axis, the pixel's position from the frame's depth and camera; ray tracer:
    // kContactRayBiasFactor × ray_bias). contactTexel replaces every map's texel.
    std::optional<double> contactBias, contactTexel, contactSlope;
};

struct Comparison {
    Metrics metrics;
    int width = 0, height = 0;
    std::vector<float> diffRgb;                    // display-encoded 0..1, 3 per pixel, row 0 on top
    std::vector<PixelClass> classes;               // one per pixel
    std::vector<float> heatRgb;                    // the error heat map (heatColor), 3 per pixel
    std::vector<std::vector<float>> lightHeatRgb;  // one heat map per light, with perLight
};

// The heat map's color scale, display-encoded: |ΔV| in 0..1 through five stops at 0, 0.25,
// 0.5, 0.75 and 1, linear in between (an inferno-like ramp: dark for no error, bright for large
// error, monotonic in luminance so it reads in gray too). 0.25 is kSoftErrorTolerance, 0.5 is τ.
struct HeatScale {
    static constexpr std::array<std::array<float, 3>, 5> kStops{{
        {0.00f, 0.00f, 0.02f},  // 0: no error
        {0.34f, 0.06f, 0.43f},  // 0.25: purple
        {0.74f, 0.22f, 0.33f},  // 0.5: red-magenta
        {0.98f, 0.56f, 0.04f},  // 0.75: orange
        {0.99f, 1.00f, 0.64f},  // 1: pale yellow
    }};
};
// The heat-map color of a counted pixel's |ΔV| (clamped to 0..1; NaN gives the invalid color).
// Not-counted pixels use DiffColors::kNotCounted, invalid ones DiffColors::kInvalid.
std::array<float, 3> heatColor(float absError);

// Throws scene::InputError when the sizes differ or a channel has the wrong length (naming
// which frame and which channel).
Comparison compareFrames(const scene::Frame& method, const scene::Frame& reference, const CompareOptions& options = {});

nlohmann::json toJson(const Metrics& metrics);
// True when the pixels off by more than kSoftErrorTolerance without crossing τ away from the
// reference's shadow edges are a notable share (kNotableSoftErrorRate) and outnumber the wrong
// ones: the classes then understate the error. (At the edges it is the filter's blur.)
bool softErrorDominates(const Metrics& metrics);
// Soft-error pixels away from the reference's shadow edges (softErrorPixels − softErrorNearEdge):
// the partial shadow a filter's blur of a hard edge does not explain.
std::size_t softErrorAwayFromEdges(const Metrics& metrics);
// True when, with several lights, the pixels wrong in some light's own channel
// (Metrics::perLightWrongPixels) outnumber the combined mask's wrong ones and are a
// notable share (more than kNotableSoftErrorRate of the counted pixels): then the words say that
// one light's shadow hides under another. A few such pixels are a ray tracer's edge noise.
bool lightsHideWrongPixels(const Metrics& metrics);
// One line for a terminal, e.g.
// "counted 301234 px: false shadow 0.82% (self acne 0.80%), missed 0.10%, IoU 0.981, ...", ending
// in "SOFT ERROR dominates: ..." where softErrorDominates.
std::string summaryLine(const Metrics& metrics);

}  // namespace shadowlab::compare
