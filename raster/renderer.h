// raster/renderer.h: the raster backend's entry points: render a Scene with shadow maps into a
// Frame, and list the Vulkan devices for `shadowlab info`.
#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include "raster/devices.h"
#include "raster/light_frustum.h"
#include "raster/vulkan_error.h"
#include "scene/frame.h"
#include "scene/render_plan.h"
#include "scene/scene.h"
#include "scene/settings.h"

namespace shadowlab::raster {

// Renders on a headless Vulkan 1.3 device (lavapipe unless settings.device names another):
// one depth pass per directional or spot light, six (a cube map) per point light, for each
// light whose plan says it needs a shadow test, then
// the lit camera pass, then the readback. Fills every Frame AOV including blockerId, the
// timings "setup", "shadow_pass", "lit_pass", "readback" and the attributes backend, device,
// shadow_map_size, filter, pcf_size, depth_bias (the value used, see depthBiasIsDefault),
// depth_bias_default, slope_bias, normal_offset, texel_world_size,
// light_frustum, light_frustum_fit, triangles, sphere_segments and, with settings.validate,
// validation_messages (the count; each is printed to stderr). Throws RasterError (no loader,
// driver or device; bad settings) or VulkanError (a failed call). Call it from one thread at a time: the Vulkan
// function pointers it loads are shared by the process.
// With `debug`, also fills it (debug views, tests): what each shadow-map layer holds and, with
// debug->captureShadowMaps, every layer's depths.
struct RenderDebug;
scene::Frame render(const scene::Scene& scene, const scene::RenderPlan& plan,
                    const scene::RasterSettings& settings, RenderDebug* debug = nullptr);

// What a render used, for the debug views (raster/debug_views.h) and tests.
struct RenderDebug {
    bool captureShadowMaps = false;  // in: read every layer back after the shadow pass
    // Out, one entry per shadow-map layer: its frustum, the light it belongs to, a short label
    // ("L0", "L0 C2" for cascade 2, "L1 +X" for a point light's face) and, when captured, its
    // depths (mapSize² floats, row 0 first; 1 = cleared, nothing there).
    std::vector<LightFrustum> frusta;
    std::vector<int> layerLight;
    std::vector<std::string> layerLabels;
    std::vector<std::vector<float>> layerDepths;
    std::uint32_t mapSize = 0;
    // Cascades (the same for every directional light: they depend on the camera only): the
    // count + 1 split depths along the view, and each cascade's texel world size. Empty without
    // cascades.
    std::vector<double> cascadeSplits;
    std::vector<double> cascadeTexels;
};

}  // namespace shadowlab::raster
