// raster/debug_views.h: images that show how the shadow maps are spent (`shadowlab render
// --view`): the maps themselves, the beauty image tinted by cascade, and shadow-map texel size
// against screen-pixel size at every visible point. All are display images (sRGB-encoded RGB in
// 0..1), made on the CPU from a Frame and the RenderDebug of the same render.
#pragma once

#include <array>
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
// debug.layerLabels in its top-left corner. Depth as gray per layer: the texel nearest the
// light white, the farthest stored depth dark gray (normalized over the layer's stored range);
// texels where nothing was drawn (cleared to depth 1) dark blue. A tile smaller than the map
// shows the minimum depth of each block of texels, so thin casters stay visible.
inline constexpr int kShadowMapViewGap = 4;
int shadowMapTileSize(std::uint32_t mapSize);  // min(mapSize, 512)
DisplayImage shadowMapView(const RenderDebug& debug);

// The cascade each pixel's shadow test used: the number of cascade split depths (the inner ones,
// debug.cascadeSplits[1..count-1]) its view depth exceeds, compared in float as lit.frag does; 0
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

}  // namespace shadowlab::raster
