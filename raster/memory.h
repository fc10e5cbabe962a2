// raster/memory.h: an upper estimate of the memory a raster render takes (lavapipe keeps every
// image and buffer in host memory), checked against what the machine has before rendering.
#pragma once

#include <cstdint>

#include "scene/render_plan.h"
#include "scene/scene.h"
#include "scene/settings.h"

namespace shadowlab::raster {

// The Frame, the lit pass's color and depth targets and their readback copies, the shadow maps
// (depth + blocker id, one layer per directional or spot light, six per point light) and the
// geometry buffers, plus a fixed allowance for the driver (llvmpipe's compiled shaders, LLVM). The program
// itself and writing the Frame are the caller's part (scene/memory.h).
std::uint64_t estimateMemoryBytes(const scene::Scene& scene, const scene::RenderPlan& plan,
                                  const scene::RasterSettings& settings);

}  // namespace shadowlab::raster
