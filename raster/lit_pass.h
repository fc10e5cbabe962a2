// raster/lit_pass.h: the camera pass: reversed-Z depth, shading with the shadow-map test per
// light (shaders/lit.frag), and the Frame's AOVs in two RGBA32F targets, then the readback.
#pragma once

#include <cstdint>
#include <vector>

#include <glm/glm.hpp>

#include "raster/shadow_pass.h"
#include "scene/settings.h"
#include "shaders/interface.h"

namespace shadowlab::raster {

inline constexpr VkFormat kLitColorFormat = VK_FORMAT_R32G32B32A32_SFLOAT;
inline constexpr VkFormat kLitDepthFormat = VK_FORMAT_D32_SFLOAT;

struct LitPipeline {
    DescriptorSetLayoutHandle setLayout;
    PipelineLayoutHandle layout;
    PipelineHandle pipeline;
};
LitPipeline createLitPipeline(const Context& ctx);

struct LitTargets {
    Image beauty;  // rgb: linear color, a: visibility
    Image aovs;    // x: object id, y: N·L, z: view depth, w: blocker id
    Image depth;   // reversed Z (cleared to 0 = far)
    std::uint32_t width = 0;
    std::uint32_t height = 0;
};
LitTargets createLitTargets(const Context& ctx, std::uint32_t width, std::uint32_t height);

// The lit pass's descriptor set: uniforms, per-object albedo, shadow maps behind a NEAREST
// depth-compare sampler (lit.frag builds the filters from its taps), blocker ids.
struct LitBindings {
    SamplerHandle sampler;    // depth compare, for the shadow maps
    SamplerHandle idSampler;  // plain NEAREST, for the blocker ids
    SamplerHandle depthSampler;  // plain NEAREST, the maps' raw depths (PCSS blocker search)
    Buffer uniforms;
    Buffer albedos;
    DescriptorPoolHandle pool;
    VkDescriptorSet set = VK_NULL_HANDLE;  // freed with the pool
};
LitBindings createLitBindings(const Context& ctx, const LitPipeline& pipeline, const shaders::LitUniforms& uniforms,
                              const std::vector<glm::vec4>& albedos, const ShadowMaps& maps);

// Records the pass; background pixels keep `background` (rgb, visibility 0) and zero AOVs.
// Leaves both color targets in TRANSFER_SRC_OPTIMAL for recordReadback().
void recordLitPass(VkCommandBuffer commands, const LitPipeline& pipeline, const LitBindings& bindings,
                   const LitTargets& targets, const DrawGeometry& geometry, const glm::vec3& background);

struct Readback {
    Buffer beauty;
    Buffer aovs;
};
Readback createReadback(const Context& ctx, const LitTargets& targets);
void recordReadback(VkCommandBuffer commands, const LitTargets& targets, const Readback& readback);

}  // namespace shadowlab::raster
