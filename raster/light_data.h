// raster/light_data.h: what the lit pass knows of each light (shaders/interface.h LightData and
// CascadeData), from the light, its shadow-map layers and the settings. Pure (no Vulkan), so tests
// check the named members against the settings without a device.
#pragma once

#include <span>
#include <vector>

#include "raster/shadow_layers.h"
#include "scene/scene.h"
#include "scene/settings.h"
#include "shaders/interface.h"

namespace shadowlab::raster {

// Light `index` as lit.frag reads it. `layers`: every layer of the render (planShadowLayers for
// `settings` and `origin`, the renderer's camera-relative origin); the light's own are its run of
// them, and without any it has no shadow test (layer −1). A cascaded directional light also
// fills `cascades`, its SHADOWLAB_MAX_CASCADES entries of LitUniforms::cascades, with each
// cascade's map, texel, depth scale, bias and slice end (a view depth less viewDepthOffset:
// lit.frag's view depths are taken from `origin`).
shaders::LightData lightData(const scene::Light& light, int index, const std::vector<ShadowLayer>& layers,
                             const scene::RasterSettings& settings, const scene::Vec3& origin, double viewDepthOffset,
                             std::span<shaders::CascadeData, SHADOWLAB_MAX_CASCADES> cascades);

}  // namespace shadowlab::raster
