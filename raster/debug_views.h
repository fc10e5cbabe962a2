// raster/debug_views.h: images that show how the shadow maps are spent (`shadowlab render
// --view`): the maps themselves, the beauty image tinted by cascade, shadow-map texel size
// against screen-pixel size at every visible point, and the light frusta drawn over the scene
// with what each map covers. All are display images (sRGB-encoded RGB in 0..1), made on the CPU
// from a Frame and the RenderDebug of the same render.
#pragma once

#include <array>
#include <optional>
#include <string>
#include <vector>

#include "raster/renderer.h"
#include "scene/camera.h"
#include "scene/frame.h"
#include "scene/scene.h"

namespace shadowlab::raster {

struct DisplayImage {
    int width = 0;
    int height = 0;
    std::vector<float> rgb;  // 3 floats per pixel, display-encoded 0..1, row 0 at the top
};

// Tiles of every shadow-map layer (debug.layerDepths must be captured), in layer order left to
// right, top to bottom: cols = ceil(sqrt(layers)), rows = ceil(layers / cols), each tile
// shadowMapTileSize(mapSize) pixels, kShadowMapViewGap pixels apart, each labelled with
// the layer's label in its top-left corner. Depth as gray per layer: the texel nearest the
// light white, the farthest stored depth dark gray (normalized over the layer's stored range);
// texels where nothing was drawn (cleared to depth 1) dark blue. A tile smaller than the map
// shows the minimum depth of each block of texels, so thin casters stay visible.
inline constexpr int kShadowMapViewGap = 4;
int shadowMapTileSize(std::uint32_t mapSize);  // min(mapSize, 512)
DisplayImage shadowMapView(const RenderDebug& debug);

// The cascade each pixel's shadow test used: the number of cascade split depths (the inner ones,
// cascadeSplits(debug.layers)[1..count-1]) its view depth exceeds, compared in float as lit.frag does; 0
// for every receiver without cascades; -1 on the background.
std::vector<int> cascadeIndices(const scene::Frame& frame, const RenderDebug& debug);
// Display color of cascade c (0..3): red, green, blue, yellow.
std::array<float, 3> cascadeTint(int cascade);
// The beauty image, each receiver's color replaced by its cascade's tint times (0.3 + 0.7 ×
// the luminance of its sRGB beauty), so the shading stays readable; background unchanged.
DisplayImage cascadeView(const scene::Frame& frame, const RenderDebug& debug);

// World size of one screen pixel at view depth z: the pixel's footprint on a plane facing the
// camera, 2·z·tan(fovY/2)/height.
double pixelWorldSize(const scene::CameraBasis& cam, double z);
// Per pixel, the world size of a shadow-map texel of the first shadowed light at the visible
// point divided by pixelWorldSize there (directional: the map's or the pixel's cascade's
// texel; spot and point: the texel per unit distance times the distance along the map's axis).
// NaN on the background or without a shadowed light.
std::vector<double> texelToPixelRatios(const scene::Frame& frame, const scene::Scene& scene, const RenderDebug& debug);
// The ramp over log2(ratio), clamped at ±3 (8×): 1:1 green; texels larger than pixels
// (undersampled: jagged, blocky shadows) through yellow (2.8×) to red (8×); texels smaller
// (oversampled: map resolution wasted) through cyan (1/2.8) to blue (1/8).
std::array<float, 3> densityColor(double ratio);
// densityColor of every pixel's ratio; the background dark gray.
DisplayImage texelDensityView(const scene::Frame& frame, const scene::Scene& scene, const RenderDebug& debug);

// --- The light-frustum view ---

// Whether world point p lies in the volume a map of frustum f holds, boundaries included.
// Orthographic: |(p − center)·right| and |(p − center)·up| <= halfWidth, and (p − center)·direction
// in nearDepth..farDepth. Perspective: with d = (p − position)·direction, near <= d <= far and
// |(p − position)·right − d·windowU|, |(p − position)·up − d·windowV| <= d·tanHalfFov (the
// pyramid of the map's window between near and far).
// Outside, the shader's lookup lands off the map (or past its far plane) and finds no caster.
bool insideLightMap(const LightFrustum& f, const scene::Vec3& p);

// The frustum's eight corners: bit 0 of the index picks −/+ right, bit 1 −/+ up, bit 2 the near
// or far end (orthographic: center ± halfWidth·right ± halfWidth·up + nearDepth|farDepth·direction;
// perspective: position + d·(direction + (windowU ± tanHalfFov)·right + (windowV ± tanHalfFov)·up),
// d = near|far).
std::array<scene::Vec3, 8> frustumCorners(const LightFrustum& f);
// Its 12 edges as pairs of corner indices: four around the near end, four around the far end,
// four joining them.
inline constexpr int kFrustumEdges[12][2] = {{0, 1}, {1, 3}, {3, 2}, {2, 0}, {4, 5}, {5, 7},
                                             {7, 6}, {6, 4}, {0, 4}, {1, 5}, {2, 6}, {3, 7}};

// A point in continuous pixel coordinates (pixel (i, j) spans x in [i, i+1), y in [j, j+1), row 0
// at the top; its center is (i + 0.5, j + 0.5), as scene::pixelDirection) and its view depth z
// along the camera's forward axis.
struct ScreenPoint {
    double x = 0.0, y = 0.0, z = 0.0;
};
// The pinhole projection of world point p (z must be > 0): with d = p − eye,
// x = (1 + d·right / (z·tan(fovY/2)·aspect))·W/2, y = (1 − d·up / (z·tan(fovY/2)))·H/2, z = d·forward.
ScreenPoint projectPoint(const scene::CameraBasis& cam, const scene::Vec3& p);
struct ScreenSegment {
    ScreenPoint a, b;
};
// World segment a–b clipped to view depths >= near (the camera's near plane) in world space, then
// projected: a part behind the camera never reaches the image (it would wrap around through
// infinity). None when the whole segment is nearer than `near`. The ends may lie outside the image.
std::optional<ScreenSegment> projectSegment(const scene::CameraBasis& cam, double near, const scene::Vec3& a,
                                            const scene::Vec3& b);

// Per pixel, how the shadow maps cover its visible point p = eye + Z·pixelDirection(x, y):
// Background (no object); Uncovered when a shadowed light reaches p but the map the shader uses
// for p does not hold it (insideLightMap): that light can cast no shadow there, a light-leak
// source; else Covered when some shadowed light's map holds p; else Outside (in no map, and no
// shadowed light reaches it: outside every spot's cone, or no light has a map). The map the shader
// uses: a single map's; a cascaded light's, the pixel's cascade (cascadeIndices); a point light's,
// the cube face of p's major axis from the light (lit.frag cubeFace). "Reaches": the Frame's N·L
// (the largest over the lights) > 0 where the Frame has it, and for a spot, p within its cone.
// A point inside a map but not reached (a spot map's corners past the cone, a surface facing
// away) counts as Covered: the view shows what each map holds, not only what it needs to.
// A directional light's map need not hold a point no caster can shade (outside every box of
// shadowableReceiverBoxes, padded by this fraction of the scene's size): it stays Outside.
inline constexpr double kCoverageBoxPad = 1e-5;
enum class Coverage : int { Background = 0, Outside = 1, Covered = 2, Uncovered = 3 };
std::vector<Coverage> lightMapCoverage(const scene::Frame& frame, const scene::Scene& scene, const RenderDebug& debug);

// The tint of light `light` (its colour over its largest component; white when black), or of
// cascade c of a cascaded light (cascadeTint).
std::array<float, 3> lightTint(const scene::Light& light);
// Stripes of the Uncovered mark: pixel (x, y) is magenta when ((x + y) / kLeakStripeWidth) is even.
inline constexpr int kLeakStripeWidth = 3;
inline constexpr std::array<float, 3> kLeakColor{1.0f, 0.0f, 1.0f};

// The backdrop (the sRGB beauty × kFrustumViewDim) with each pixel coloured by lightMapCoverage():
// Covered: the mean tint of the lights whose maps hold it (a cascaded light: its cascade's tint) ×
// (kCoveredShade[0] + kCoveredShade[1] × sRGB luminance of the beauty; at most 0.75, so that
// outlines at full strength stand out); Uncovered: magenta stripes over the backdrop; Outside and
// Background: the backdrop. Over that, each map's 12 edges in its tint (a cascade's: cascadeTint):
// solid where nearer the camera than the visible surface, dashed and mixed half way into the
// image where behind it; frustumLineWidth(height) px wide with a dark one-pixel halo each side,
// clipped at the camera's near plane. Point lights get a ring-and-cross marker at the light's
// position instead (their six faces cover every direction, so six outlines would be clutter and
// only near/far bound the map), spot lights get it besides their pyramid. A legend in the top-left
// corner: a swatch and a label per map ("L0", "L0 C1" for cascade 1) and the stripes, "OUT".
inline constexpr float kFrustumViewDim = 0.4f;
inline constexpr float kCoveredShade[2] = {0.2f, 0.55f};
int frustumLineWidth(int imageHeight);  // 1 below 360 rows, else 2
DisplayImage lightFrustumView(const scene::Frame& frame, const scene::Scene& scene, const RenderDebug& debug);

}  // namespace shadowlab::raster
