// raster/memory.h: an upper estimate of the memory a raster render takes (lavapipe keeps every
// image and buffer in host memory), checked against what the machine has before rendering.
#pragma once

#include <cstdint>
#include <string_view>

#include "scene/render_plan.h"
#include "scene/scene.h"
#include "scene/settings.h"

namespace shadowlab::raster {

// The Frame, the lit pass's color and depth targets and their readback copies, the shadow maps
// (depth + blocker id, shadowMapLayers() layers), the filterable maps' moment arrays and the
// geometry buffers, plus a fixed allowance for the driver (llvmpipe's compiled shaders, LLVM). The program
// itself and writing the Frame are the caller's part (scene/memory.h).
std::uint64_t estimateMemoryBytes(const scene::Scene& scene, const scene::RenderPlan& plan,
                                  const scene::RasterSettings& settings);

// The shadow-map layers a render has at most: one per directional or spot light that needs a
// shadow test, settings.cascades for a directional one with cascades, six per point light.
std::uint64_t shadowMapLayers(const scene::Scene& scene, const scene::RenderPlan& plan,
                              const scene::RasterSettings& settings);

// What `render --view VIEW` holds on the host besides estimateMemoryBytes() (it writes no EXR):
// for "shadow-map" every layer's depths (4 bytes a texel) and the tiled display image (at most
// 12 bytes a texel, gaps included as a quarter more); for "light-frustum" a display image (12
// bytes), a cascade index (4) and a coverage record (16, raster/debug_views.cpp) per camera
// pixel; otherwise a display image and a cascade index per camera pixel.
std::uint64_t debugViewBytes(const scene::Scene& scene, const scene::RenderPlan& plan,
                             const scene::RasterSettings& settings, std::string_view view);

}  // namespace shadowlab::raster
