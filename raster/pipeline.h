// raster/pipeline.h: graphics pipelines for dynamic rendering (no render pass objects): the
// shadow and lit passes describe what differs, this builds the rest the same way for both.
#pragma once

#include <cstdint>
#include <span>
#include <vector>

#include "raster/context.h"

namespace shadowlab::raster {

ShaderModuleHandle createShaderModule(const Context& ctx, std::span<const std::uint32_t> spirv);

struct PipelineDesc {
    std::span<const std::uint32_t> vertexShader;
    std::span<const std::uint32_t> fragmentShader;                 // empty: depth only
    const VkSpecializationInfo* fragmentSpecialization = nullptr;  // the fragment stage's constants
    const VkSpecializationInfo* vertexSpecialization = nullptr;    // the vertex stage's
    VkPipelineLayout layout = VK_NULL_HANDLE;
    bool usesNormal = true;    // declare vertex location 1; the validation layer warns about unused inputs
    bool usesObjectId = true;  // declare vertex location 2 (the same warning)
    // Declare vertex location 3, the texture coordinates (vec2) of vertex binding 1 (alpha-tested
    // casters, raster/alpha_casters.h).
    bool usesUv = false;
    // false: no vertex buffer at all (a shader that makes its vertices from gl_VertexIndex).
    bool vertexBuffer = true;
    std::vector<VkFormat> colorFormats;
    VkFormat depthFormat = VK_FORMAT_D32_SFLOAT;
    VkCompareOp depthCompare = VK_COMPARE_OP_LESS;
    bool depthWrite = true;
    // The transmittance pass's blending (raster/shadow_pass.h): color target 0 multiplied
    // (dst · src), target 1 kept at the minimum.
    bool transmittanceBlend = false;
    // Depth bias on, its factors dynamic (vkCmdSetDepthBias before each draw): the hardware bias.
    bool dynamicDepthBias = false;
};

// Triangle lists, no culling (quads are two-sided, and both faces must cast), depth test on,
// depth write and blending as desc says, viewport and scissor dynamic.
PipelineHandle createGraphicsPipeline(const Context& ctx, const PipelineDesc& desc);

// One descriptor set of `bindings`, with its layout and a pool sized for exactly it: what each pass
// that binds one set of its own needs (the set is freed with the pool).
struct DescriptorSet {
    DescriptorSetLayoutHandle layout;
    DescriptorPoolHandle pool;
    VkDescriptorSet set = VK_NULL_HANDLE;
};
DescriptorSet createDescriptorSet(const Context& ctx, std::span<const VkDescriptorSetLayoutBinding> bindings);

// A sampler that returns stored texels: nearest, clamped to the edge, one level (texelFetch and
// exact taps on depth and moment maps).
SamplerHandle createNearestSampler(const Context& ctx);

// Throws RasterError naming the device and the format when it lacks `features` (optimal tiling).
void requireFormat(const Context& ctx, VkFormat format, VkFormatFeatureFlags features, const char* purpose);

// Viewport and scissor covering width x height.
void setViewport(VkCommandBuffer commands, std::uint32_t width, std::uint32_t height);

}  // namespace shadowlab::raster
