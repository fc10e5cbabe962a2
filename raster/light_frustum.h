// raster/light_frustum.h: the projection of each light's shadow map: orthographic for a
// directional light (fitted to the scene's bounding sphere, or to the casters of what the
// camera sees), perspective for a spot light (its cone, or a window of it fitted to what the
// camera sees) and a point light's cube faces; and the texel size the biases scale with.
#pragma once

#include <cstdint>
#include <optional>
#include <span>
#include <string>
#include <vector>

#include <glm/glm.hpp>

#include "scene/render_plan.h"
#include "scene/scene.h"
#include "scene/settings.h"

namespace shadowlab::raster {

struct LightFrustum {
    bool perspective = false;         // spot light
    scene::Vec3 direction{0, -1, 0};  // unit, the way the light travels (the map looks along it)
    scene::Vec3 right{1, 0, 0};       // unit, the map's +u axis
    scene::Vec3 up{0, 0, 1};          // unit, the map's +v axis (v grows with framebuffer rows)
    int mapSize = 1;                  // texels per side
    // Orthographic: the map spans center ± halfWidth across, and depth 0..1 runs from
    // center − halfWidth·direction to center + halfWidth·direction... unless fitted, where
    // nearDepth/farDepth (along direction, relative to center) bound it.
    scene::Vec3 center{0, 0, 0};
    double halfWidth = 1;
    double nearDepth = -1, farDepth = 1;  // along direction from center; default ±halfWidth
    // Perspective: from `position`, depth from near to far along `direction`. The map holds the
    // directions whose tangents u = x/d (along right), v = y/d (along up) lie in the square window
    // windowU ± tanHalfFov, windowV ± tanHalfFov: symmetric about the axis (window 0, half-angle
    // atan(tanHalfFov)) unless fitted to receivers off the axis (an off-center perspective that
    // keeps the axis, so depth along it means the same).
    scene::Vec3 position{0, 0, 0};
    double tanHalfFov = 1;
    double windowU = 0, windowV = 0;
    double near = 0.1, far = 1;

    // Orthographic: world size of one texel. Perspective: per unit of distance along the axis
    // (tangent units per texel, 2·tanHalfFov/mapSize).
    double texelWorldSize() const;
    // World units per unit of orthographic depth (0..1).
    double depthRange() const { return farDepth - nearDepth; }

    // For positions given relative to `origin`: clip coordinates of the light's view, x, y in
    // −w..w across the map, z in 0..w from near to far.
    glm::dmat4 toClip(const scene::Vec3& origin) const;
    // The same with x, y mapped to texture coordinates: (u, v) = (x/w, y/w) in 0..1.
    glm::dmat4 toTexture(const scene::Vec3& origin) const;
    std::string describe() const;
};

// The sphere around `bounds` (center = box center, radius = half its diagonal), seen along
// `direction`. An empty or point-like bounds gets a tiny but valid frustum.
LightFrustum fitDirectionalLight(const scene::Bounds& bounds, const scene::Vec3& direction, int mapSize);

// A map covering only what can shadow what the camera sees: the receivers are the visible ones
// some caster can shade (visibleShadowableReceiverPoints; lit.frag lights a point past the map's
// square or depth, where no caster reaches), or, when there are none, the scene's bounds clipped
// to the camera frustum (its far plane pulled in to the scene); across the light
// the map covers their extent, and in depth it reaches back toward the light to the nearest
// object whose extent across the light overlaps theirs. Snapped so that it does not swim: the
// half-width rounded up to 1/16 of its power of two, the center on the world-fixed texel grid,
// near and far rounded outward to 1/16 of their range's power of two. Falls back to
// fitDirectionalLight() when the camera sees none of the scene.
// snap = false leaves all three unsnapped (RasterSettings::snapLightFrustum, the temporal study).
// `shadowable`, when given, is visibleShadowableReceiverPoints(scene, direction) already computed
// (chooseCascades fits every count from one set).
LightFrustum fitDirectionalLightToReceivers(const scene::Scene& scene, const scene::Vec3& direction, int mapSize,
                                            bool snap = true, const std::vector<scene::Vec3>* shadowable = nullptr);

// The map's basis for light travelling along `direction`: right = direction × (world Y, or X for
// a vertical light), up = right × direction. Fixed in the world, so texel grids are too.
void setBasis(LightFrustum& f, const scene::Vec3& direction);

// The vertices of the scene's bounds clipped to the camera frustum (its far plane pulled in to the
// scene's farthest corner): the convex hull of every receiver the camera can see. Empty when the
// camera sees none of the scene.
std::vector<scene::Vec3> visibleReceiverPoints(const scene::Scene& scene);
// The same for any box in the scene (an object's bounds): the part of it the camera frustum holds.
std::vector<scene::Vec3> visibleReceiverPoints(const scene::Scene& scene, const scene::Bounds& box);
// The same (for the scene's bounds) with the view depths further limited to [minDepth, maxDepth]:
// the receivers of one cascade's slice.
std::vector<scene::Vec3> visibleReceiverPointsInSlice(const scene::Scene& scene, double minDepth, double maxDepth);

// Whether an object can shade part of itself under a directional light: a mesh can, unless it is
// planar (all vertices within kPlanarMeshTolerance of its size of one plane, like a glTF ground).
// Spheres, boxes and quads cannot: a convex surface facing the light (N·L > 0) is not
// self-shadowed, and where N·L ≤ 0 lit.frag gives no light without a shadow test.
bool shadesItself(const scene::Object& object);
inline constexpr double kPlanarMeshTolerance = 1e-7;
// The receivers some caster can shade under light travelling along `direction`, one box per
// object (empty where nothing can shade it): each caster's bounds swept along the light until it
// has left the scene's bounds (padded by kShadowSweepPad of the scene's size, so that rounding
// keeps a ground at the scene's edge), intersected with every other object's bounds (and its own
// where shadesItself), and the object's box the bounding box of those intersections.
std::vector<scene::Bounds> shadowableReceiverBoxes(const scene::Scene& scene, const scene::Vec3& direction);
inline constexpr double kShadowSweepPad = 1e-9;
// visibleReceiverPoints() of each of those boxes, together: the vertices of the visible receivers
// some caster can shade. Empty when the camera sees none.
std::vector<scene::Vec3> visibleShadowableReceiverPoints(const scene::Scene& scene, const scene::Vec3& direction);

// The smallest depth along f.direction (relative to f.center) of any object whose bounding box's
// extent across the light (f.right, f.up, relative to f.center) overlaps [minU, maxU] × [minV,
// maxV]: how far toward the light a map covering that rectangle must reach to catch every
// caster. +infinity when no object overlaps.
double nearestCasterDepth(const scene::Scene& scene, const LightFrustum& f, double minU, double maxU, double minV,
                          double maxV);

// Spot light at `position` shining along `direction` with cone half-angle `coneDegrees`: the
// map's field of view is the cone plus a 2% margin; near and far enclose the scene's bounding
// sphere (near no closer than 1/1000 of far, which bounds the depth precision lost).
LightFrustum fitSpotLight(const scene::Bounds& bounds, const scene::Vec3& position, const scene::Vec3& direction,
                          double coneDegrees, int mapSize);

// Spot light `light` (a spot) fitted to what the camera sees (`fitLightFrustum`), from
// fitSpotLight()'s cone map:
// - window: the visible receivers (visibleReceiverPoints) projected into the map (u, v), their
//   rectangle clamped to the cone's square, held by the smallest square window that leaves
//   `marginTexels` texels of it (the filter's reach and the normal offset, as castsOnto) plus half
//   a texel (the center's snapping) on every side; its half-size is rounded up to a power of 2^(1/4)
//   and its center to a whole texel (a multiple of 2·tanHalfFov/mapSize), so a camera moving a
//   little keeps the texel grid still (no swimming). Kept at the cone when that window would not
//   be smaller, or when a receiver lies on or behind the light's plane;
// - near/far: far is the farthest visible receiver in front of the light (+ the margin's fraction
//   of its distance, + 1%), near the nearest point of any object's box inside the window's pyramid
//   (− 1%), snapped outward to powers of 2^(1/4) (snapDepthDown/Up: still while the camera
//   moves a little), both within the cone map's and near ≥ far/1000.
// The cone map when the camera sees none of the scene or no receiver lies in front of the light.
LightFrustum fitSpotLightToReceivers(const scene::Scene& scene, const scene::Light& light, int mapSize,
                                     double marginTexels);
// How far lit.frag moves a lookup point along its normal beyond what kCullMarginTexels holds, in
// texels: the normal offset, and the slope bias's lift past its cap (under slopeBias texels)
// beyond the first texel.
double lookupOffsetTexels(const scene::RasterSettings& settings);
// The margin fitSpotLightToReceivers and fitPointLightFaceToReceivers keep around the receivers,
// in texels of a map of mapSize: cullReachTexels plus lookupOffsetTexels, counted 2·√(1 + t²)
// times (t: tangent of the widest direction the map holds; castsOnto says why).
double fitMarginTexels(const scene::RasterSettings& settings, const scene::Light& light, int mapSize, double t);
// The fitted spot map when settings.fitLightFrustum, else the cone map.
LightFrustum spotLightFrustum(const scene::Scene& scene, const scene::RasterSettings& settings,
                              const scene::Light& light, int mapSize);
// Rounds a window half-size up to the next power of 2^(1/4) (the fitted windows' sizes).
double snapWindowHalfSize(double half);
// The fitted near/far planes' grid (spot maps and cube faces): distances from the light rounded
// down (near) or up (far) to a power of 2^(1/kDepthGridStepsPerOctave), so that a moving camera
// changes them, and with them the depth scale, only when what it sees crosses a step (so the
// map does not swim). light_frustum.cpp says why this grid and what depth precision it costs.
inline constexpr double kDepthGridStepsPerOctave = 4.0;
double snapDepthDown(double d);
double snapDepthUp(double d);

// The six faces of a point light's cube map, in this order: +X, −X, +Y, −Y, +Z, −Z (each
// face's `direction`; its right and up axes come from the same rule as every other frustum, and
// shaders/lit.frag rebuilds them the same way).
inline constexpr int kCubeFaces = 6;
scene::Vec3 cubeFaceDirection(int face);
// tan of each face's half field of view: 1 (90°) widened by kPointFaceMarginTexels texels, and
// never more than 2 for tiny maps.
double cubeFaceTanHalfFov(int mapSize);
// Face `face` of the cube map of a point light at `position`: a perspective frustum whose near
// and far planes enclose the scene's bounding sphere in every direction of the face's window (the
// same for all six faces; near = nearest distance / √(1 + 2t²), no closer than far ·
// kSpotMinNearOverFar).
LightFrustum fitPointLightFace(const scene::Bounds& bounds, const scene::Vec3& position, int face, int mapSize);
// The same face with near/far fitted to what the camera sees (`fitLightFrustum`), as a fitted spot
// map's: far from the visible receivers in front of the face, near from the objects' boxes inside
// the face's pyramid (its whole window, 90° plus the seam margin, which stays: the seams depend on
// it). fitPointLightFace() when no receiver lies in front of the face (nothing reads it).
LightFrustum fitPointLightFaceToReceivers(const scene::Scene& scene, const scene::Light& light, int face, int mapSize,
                                          double marginTexels);
// Face `face` of `light`'s cube map: fitted when settings.fitLightFrustum.
LightFrustum pointLightFaceFrustum(const scene::Scene& scene, const scene::RasterSettings& settings,
                                   const scene::Light& light, int face, int mapSize);

// Caster culling: which objects can shadow a receiver that reads map f. An object is
// left out of f's depth pass when it cannot write a depth any visible receiver's shadow test reads
// as nearer than itself; leaving it out then changes no comparison, so the image stays the same.
// The receivers are given as the vertices of their convex hull (visibleReceiverPoints, or one
// cascade's slice of it). With margin m (reachTexels + the normal offset, in f's texels):
// - orthographic: seen along the light, the object's bounding box must overlap the receivers'
//   extent across it widened by m texels, and reach nearer the light than the farthest receiver
//   (+ m texels);
// - perspective (spot, cube face): projected (u = x/d, v = y/d, d along the map's axis), the box's
//   rectangle must overlap the receivers' rectangle widened by m texels of angle, and its nearest
//   corner be nearer than the farthest receiver (d·(1 + m·texel angle)). The receivers' rectangle
//   is that of their hull's part in front of the light, clamped to the map's extent [−t, t]; where
//   the hull crosses the light's plane it is unbounded toward the side the crossing lies on. A box
//   with corners on both sides of the light's plane (or holding the light) is always kept; one
//   wholly behind it is left out (the map cannot hold it). The normal offset counts
//   2·√(1 + t²) times: it moves a point across the light's rays by up to that many texels of
//   angle while the offset is under a tenth of the point's distance (else nothing is culled).
// All true when there are no receivers.
std::vector<bool> castsOnto(const scene::Scene& scene, const LightFrustum& f, const std::vector<scene::Vec3>& receivers,
                            double reachTexels, double normalOffsetTexels);
// The same test for any boxes (world coordinates; an empty box is kept): the shadow pass's index
// clusters, whose triangles lie in their boxes as an object's lie in its own.
std::vector<bool> boxesCastOnto(std::span<const scene::Bounds> boxes, const LightFrustum& f,
                                const std::vector<scene::Vec3>& receivers, double reachTexels,
                                double normalOffsetTexels);
// Texels [x0, x1) × [y0, y1) of a shadow-map layer (the depth pass's framebuffer).
struct TexelRect {
    std::uint32_t x0 = 0, y0 = 0, x1 = 0, y1 = 0;
    bool empty() const { return x0 >= x1 || y0 >= y1; }
    std::uint64_t area() const { return empty() ? 0 : std::uint64_t(x1 - x0) * (y1 - y0); }
};
// The texels of f's map that the shadow lookups of `receivers` can read, by the reach castsOnto
// allows them, within the map. Empty where no receiver lies in front of a perspective map (none
// reads it); none where nothing bounds the reads (no receivers, or a perspective map's normal
// offset past castsOnto's bound).
std::optional<TexelRect> receiverTexels(const LightFrustum& f, const std::vector<scene::Vec3>& receivers,
                                        double reachTexels, double normalOffsetTexels);
// castsOnto() with every receiver the camera sees (visibleReceiverPoints(scene)).
std::vector<bool> castsIntoView(const scene::Scene& scene, const LightFrustum& f, double reachTexels,
                                double normalOffsetTexels = 0.0);
// The widest filter reach in texels (a 15-tap kernel's half, pcf2x2's extra texel, rounding: 8.7)
// and one texel of the slope bias's lift past its cap (lit.frag; the default slope bias's most).
inline constexpr double kCullMarginTexels = 10.0;
// That lift's part of kCullMarginTexels: it moves the lookup point along the normal, which a
// perspective map magnifies as it does the normal offset (castsOnto).
inline constexpr double kCullLiftTexels = 1.0;
// PCSS of a spot or point light with a size looks up to this fraction of the map's side from the
// point, in its blocker search and its widest kernel (shaders/lit.frag kPcssMaxSearchFraction,
// half of kPcssMaxFilterFraction).
inline constexpr double kPcssReachFraction = 1.0 / 16.0;
// A point light's PCSS taps go on into the neighbouring face (lit.frag cubeTap); an offset of r
// texels in one face is at most ~2.3·r texels in the next near their shared edge (the change of
// face coordinates 1/a, b/a has derivatives up to 1/a² and (a + |b|)/a² with a ≥ 1 − r·texel
// angle, |b| ≤ a), so the reach counts this many times there.
inline constexpr double kCubeWrapReachFactor = 3.0;
// How far from its own texel a receiver's shadow test of `light` reads, in texels of a map of
// mapSize: kCullMarginTexels, plus the PCSS reach for a spot or point light with a radius, plus a
// filterable map's blur radius (its lookup reads moments blurred over that many depth texels more).
double cullReachTexels(const scene::RasterSettings& settings, const scene::Light& light, int mapSize);
// The moment passes' box blur radius in texels for a filterable filter ((blur width − 1) / 2), 0
// for the others.
int momentBlurRadius(const scene::RasterSettings& settings);

// The objects drawn into one layer of `light` (f its frustum, receivers those that read it).
std::vector<bool> layerCasters(const scene::Scene& scene, const scene::RasterSettings& settings,
                               const scene::Light& light, const LightFrustum& f,
                               const std::vector<scene::Vec3>& receivers);

// Map size from the receivers' detail: when nobody chose a size (settings
// shadowMapSizeIsDefault and the size is kDefaultShadowMapSize), a map whose texel is smaller than
// the world footprint of a screen pixel on the visible receivers adds nothing the image can show.
// Each light with a map says how many texels it needs, and the size (one array holds every map)
// is the most any needs, rounded up to a power of two and clamped to [kMinAutoShadowMapSize, the
// default]:
// - directional: the widest map's width divided by the smallest pixel footprint on the visible
//   receivers;
// - spot: max over the visible receivers of 2·tanHalfFov·z / pixelWorldSize(zc), z the distance
//   along the spot's axis and zc the view depth (the texel there is z·2·tanHalfFov/N); z/zc is
//   linear-fractional, so its maximum over each object's visible part (a convex polytope, zc > 0)
//   is at a vertex. A fitted window (fitLightFrustum) depends on N (its margin is in texels, its
//   size snapped), so the size is the smallest power of two whose own window satisfies this;
// - point: a face's texel is 2/(N − 2·kPointFaceMarginTexels) per unit of ‖p − light‖∞ (the axial
//   distance in the face of p's major axis), so N ≥ 2·max(‖p − light‖∞ / pixelWorldSize(zc)) +
//   2·kPointFaceMarginTexels; ‖p − light‖∞/zc is quasi-convex (convex over positive affine), so
//   again largest at a vertex.
// Kept as set when forced, with cascades (sized per slice already) or when the camera sees
// nothing. `reason` says which, for --explain and the Frame.
// The casters count too: a caster narrower than a few texels is lost in the map (bilinear PCF
// blurs its shadow's edges over a texel each, and the slope bias eats a thin one), so each light
// also needs kTexelsPerCasterFeature texels across the smallest feature of every object that can
// shade a visible receiver (casterFeatureSize): N ≥ k·(map width)/feature for a directional map,
// k·2t·d/feature for a spot (d the object's farthest distance along the axis), 2k·d∞/feature + 24
// for a point light's faces.
// The smallest size chosen that way: below it the bias defaults (half a texel) grow coarse.
inline constexpr int kMinAutoShadowMapSize = 256;
// Texels a caster's smallest feature spans in the map: four leaves at least two texels of its
// shadow's interior past the one-texel PCF ramps at its edges (docs/raster.md).
inline constexpr double kTexelsPerCasterFeature = 4.0;
// The world size of an object's smallest feature, as a caster: a sphere's diameter, a box's
// shortest side, a quad's shorter side, and for a mesh the median over its placed triangles of
// their width (twice the area over the longest edge): a mesh holds no detail finer than its
// triangles, and the median ignores the few slivers every mesh has.
double casterFeatureSize(const scene::Object& object);
struct ShadowMapSizeChoice {
    int size = 0;
    std::string reason;
    // The texels the receivers and casters ask for (more than `size` where the default caps it);
    // 0 where the size is kept as set, with cascades, or with no receiver in view.
    double needed = 0.0;
};
// With a plan, only the lights it gives a shadow pass count (without: every light).
ShadowMapSizeChoice chooseShadowMapSize(const scene::Scene& scene, const scene::RasterSettings& settings,
                                        const scene::RenderPlan* plan = nullptr);

}  // namespace shadowlab::raster
