// raster/cascades.h: cascaded shadow maps for directional lights: the practical split scheme
// over the view depth of the visible receivers, and one orthographic map per slice, sized by the
// slice's bounding sphere (rotation-stable) and snapped to a world-fixed texel grid (no swimming).
#pragma once

#include <array>
#include <optional>
#include <string>
#include <vector>

#include "raster/light_frustum.h"
#include "scene/camera.h"
#include "scene/scene.h"

namespace shadowlab::raster {

// Blend of the logarithmic and the uniform split (Zhang et al. 2006, "Parallel-split shadow
// maps", the "practical" scheme): C_i = λ·n·(f/n)^(i/N) + (1 − λ)·(n + (f − n)·i/N). λ = 1 is
// the logarithmic split (even texel density per unit of log depth, but a first slice of a few
// near-plane widths); λ = 0 the uniform one (the near slice as long as the far one). 0.75 keeps
// the near slices short where texels matter most and the far slice not absurdly long.
inline constexpr double kCascadeSplitLambda = 0.75;

// Each cascade map reaches this many texels past its slice's bounding sphere on every side, so
// that filter taps and normal offsets at the sphere's rim stay on the map (the widest PCF kernel
// is 15 taps: 7 texels from the center).
inline constexpr double kCascadeMarginTexels = 8.0;

// The view-depth range [near, far] (distance along the camera's forward axis) that the visible
// receivers cover: each object's bounding box clipped to the camera frustum, clamped to the
// camera's near and far planes. None when the camera sees none of the scene.
std::optional<std::array<double, 2>> visibleDepthRange(const scene::Scene& scene);

// The same over the visible receivers some caster can shade under light along `direction`
// (shadowableReceiverBoxes clipped to the camera frustum): past them nothing is shadowed, so the
// cascades need not reach there (lit.frag lights what lies past the last split). None when no
// visible receiver can be shaded.
std::optional<std::array<double, 2>> shadowableDepthRange(const scene::Scene& scene, const scene::Vec3& direction);

// count + 1 split depths from near to far (the first is near, the last far) by the practical
// scheme with blend `lambda`. Requires 0 < near < far and count >= 1.
std::vector<double> practicalSplits(double near, double far, int count, double lambda = kCascadeSplitLambda);

// The eight corners of the camera frustum between view depths d0 and d1.
std::array<scene::Vec3, 8> sliceCorners(const scene::CameraBasis& cam, double d0, double d1);

struct BoundingSphere {
    scene::Vec3 center{0, 0, 0};
    double radius = 0.0;
};
// The smallest sphere through the slice's corners (its center on the view axis): it depends only on
// d0, d1 and the field of view, not on where the camera looks, so its size does not change when the
// camera turns.
BoundingSphere sliceBoundingSphere(const scene::CameraBasis& cam, double d0, double d1);

// The map of one cascade: an orthographic frustum along `direction` whose square covers the slice's
// bounding sphere plus kCascadeMarginTexels (half-width quantized up to 1/16 of its power of two,
// so that small changes of the slice do not change the texel size), centered on the sphere's center
// snapped to the world-fixed texel grid of setBasis()'s axes; in depth it covers the sphere and
// reaches toward the light to every caster over the square (nearestCasterDepth()).
// snap = false: neither quantized nor on the grid (RasterSettings::snapLightFrustum).
LightFrustum fitCascade(const scene::Scene& scene, const scene::CameraBasis& cam, double d0, double d1,
                        const scene::Vec3& direction, int mapSize, bool snap = true);

// The receivers of cascade `c` of a set with these splits: visibleReceiverPointsInSlice() over
// [splits[c], splits[c + 1]], the first reaching down to the near plane and the last out to the
// far one (lit.frag gives them everything nearer or farther), the inner ends widened by
// kCascadeSplitSlack because lit.frag compares the view depth with the splits in float.
inline constexpr double kCascadeSplitSlack = 1e-4;
// With a blend band (RasterSettings::cascadeBlend), cascade c > 0 also serves the last `blend` of
// slice c − 1, where lit.frag mixes it in: its receivers start there.
std::vector<scene::Vec3> cascadeReceivers(const scene::Scene& scene, const std::vector<double>& splits, std::size_t c,
                                          double blend = 0.0);

struct CascadeSet {
    std::vector<double> splits;        // count + 1 view depths, near to far
    std::vector<LightFrustum> frusta;  // one per slice; empty when the camera sees none of the scene
};
// The splits over shadowableDepthRange() (visibleDepthRange() when no visible receiver can be
// shaded) and fitCascade() of each slice, except that a cascade whose
// map would be wider than the scene's bounding-sphere map (fitDirectionalLight) uses that instead.
// With a blend band (`blend` of each slice before its far split, lit.frag mixes the next cascade
// in there), each cascade c > 0 covers the band of slice c − 1 too: its slice starts there.
// `shadowable` as for fitDirectionalLightToReceivers.
CascadeSet fitCascades(const scene::Scene& scene, const scene::Vec3& direction, int count, int mapSize,
                       double blend = 0.0, bool snap = true, const std::vector<scene::Vec3>* shadowable = nullptr);
// The band the maps cover for these settings: the widest one (kMaxCascadeBlend) whenever blending
// is on, so that the maps, and every pixel outside the bands, do not change with the band's width;
// 0 when it is off (the maps of the plain slices).
inline double cascadeBandCover(const scene::RasterSettings& settings) {
    return settings.cascadeBlend > 0.0 ? scene::kMaxCascadeBlend : 0.0;
}

// Automatic cascade count (settings.cascadesIsDefault): one map is kept while its texel is at most
// kCascadeTexelsPerPixel screen pixels wide at the nearest visible receiver (where a pixel's
// footprint is smallest); past that, the fewest cascades (2..kMaxCascades) whose every slice keeps
// its texel within that many pixels at the slice's near end, or, when no count does, the count
// whose worst slice is finest (fewer on a tie within kCascadeGainTolerance). Each cascade is one
// more depth pass over the scene, so a count is taken only when it is that much finer.
// Two pixels a texel: bilinear PCF's edge then moves by at most about a pixel, and a small
// caster still spans several texels wherever it spans a few pixels.
inline constexpr double kCascadeTexelsPerPixel = 2.0;
inline constexpr double kCascadeGainTolerance = 1.1;
struct CascadeChoice {
    int count = 1;
    std::string reason;
};
// The texels per pixel a count gives (its worst slice) are measured at settings.shadowMapSize (a
// default size is kDefaultShadowMapSize, which chooseShadowMapSize then keeps for cascades). With a
// plan, only lights it gives a shadow test count. A forced count (or one other than 1 set in code
// after resolveSettings) is kept.
CascadeChoice chooseCascades(const scene::Scene& scene, const scene::RasterSettings& settings,
                             const scene::RenderPlan* plan = nullptr);
// settings with the automatic choices the raster backend makes before drawing resolved: the
// cascade count (chooseCascades), then the map size (chooseShadowMapSize), and a default constant
// bias re-derived for that size. `reasons` (cascades, map size) when given.
scene::RasterSettings resolveAutomaticChoices(const scene::Scene& scene, const scene::RasterSettings& settings,
                                              const scene::RenderPlan* plan, CascadeChoice* cascades = nullptr,
                                              ShadowMapSizeChoice* mapSize = nullptr);

}  // namespace shadowlab::raster
