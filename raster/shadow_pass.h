// raster/shadow_pass.h: renders depth from each shadowed light into one layer of a D32_SFLOAT
// shadow-map array, and the id of the nearest object into a matching R32_UINT blocker-id
// array. Both faces cast: quads are two-sided, and culling one side would leak light through it.
#pragma once

#include <cstdint>
#include <vector>

#include <glm/glm.hpp>

#include "raster/resources.h"

namespace shadowlab::raster {

inline constexpr VkFormat kShadowMapFormat = VK_FORMAT_D32_SFLOAT;
inline constexpr VkFormat kBlockerIdFormat = VK_FORMAT_R32_UINT;

struct ShadowPipeline {
    PipelineLayoutHandle layout;
    PipelineHandle pipeline;
};
// Without blockerIds: depth only, no fragment shader (much cheaper on lavapipe).
ShadowPipeline createShadowPipeline(const Context& ctx, bool blockerIds = true);

struct ShadowMaps {
    Image depth;                             // size x size x layers; view: 2D array for sampling
    std::vector<ImageViewHandle> layerViews;  // one 2D view per layer, for rendering
    Image ids;                               // object id nearest the light per texel, 0 = none
    std::vector<ImageViewHandle> idLayerViews;
    std::uint32_t size = 0;
    std::uint32_t layers = 0;
};
ShadowMaps createShadowMaps(const Context& ctx, std::uint32_t size, std::uint32_t layers);

// Index and vertex buffers of the whole scene (raster/geometry.h layout).
struct DrawGeometry {
    VkBuffer vertices = VK_NULL_HANDLE;
    VkBuffer indices = VK_NULL_HANDLE;
    std::uint32_t indexCount = 0;
    // Shadow pass only: per layer, the index ranges (first, count) drawn into it (the casters
    // left after culling); layers past the end of this list draw every index.
    std::vector<std::vector<std::pair<std::uint32_t, std::uint32_t>>> layerRanges;
};

// Records: every layer cleared to depth 1 (far: lit) and id 0, and layer i drawn with
// lightMatrices[i] (layers past the end of lightMatrices are only cleared), then both arrays
// made readable by fragment shaders (SHADER_READ_ONLY_OPTIMAL). Without blockerIds (the
// pipeline made so) the id array is not rendered, only moved to SHADER_READ_ONLY_OPTIMAL with
// undefined contents, for a lit pass that does not read it.
void recordShadowPass(VkCommandBuffer commands, const ShadowPipeline& pipeline, const ShadowMaps& maps,
                      const DrawGeometry& geometry, const std::vector<glm::mat4>& lightMatrices,
                      bool blockerIds = true);

// Diagnostics and tests: the depths of one layer after recordShadowPass() has run, row 0 first.
std::vector<float> readShadowMap(const Context& ctx, const ShadowMaps& maps, std::uint32_t layer);
std::vector<std::uint32_t> readBlockerIds(const Context& ctx, const ShadowMaps& maps, std::uint32_t layer);

}  // namespace shadowlab::raster
