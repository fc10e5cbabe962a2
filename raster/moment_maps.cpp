// raster/moment_maps.cpp: the filterable maps' moment arrays and their two compute passes.
#include "raster/moment_maps.h"

#include <algorithm>
#include <cstddef>
#include <cstdint>
#include <iterator>
#include <sstream>

#include "raster/pipeline.h"
#include "raster/vulkan_error.h"
#include "shaders/interface.h"
#include "shaders/spirv.h"

namespace shadowlab::raster {

namespace {

constexpr std::uint32_t kGroup = 8;  // moments.comp's local size (x and y)

void requireMomentFormat(const Context& ctx) {
    requireFormat(ctx, kMomentFormat,
                  VK_FORMAT_FEATURE_STORAGE_IMAGE_BIT | VK_FORMAT_FEATURE_SAMPLED_IMAGE_BIT |
                      VK_FORMAT_FEATURE_SAMPLED_IMAGE_FILTER_LINEAR_BIT,
                  "the filterable shadow maps' moments (VK_FORMAT_R32G32B32A32_SFLOAT as a storage image, "
                  "sampled with a linear filter)");
}

}  // namespace

std::uint64_t momentBytes(std::uint64_t size, std::uint64_t layers) {
    return size * size * (layers + 1) * kMomentBytesPerTexel;
}

MomentMaps createMomentMaps(const Context& ctx, std::uint32_t size, std::uint32_t layers) {
    if (size > 1) requireMomentFormat(ctx);
    requireDeviceMemory(
        ctx, momentBytes(size, layers),
        std::to_string(layers) + " moment map(s) of " + std::to_string(size) + "x" + std::to_string(size));
    MomentMaps m;
    m.size = size;
    m.layers = layers;
    const VkImageUsageFlags usage = VK_IMAGE_USAGE_STORAGE_BIT | VK_IMAGE_USAGE_SAMPLED_BIT;
    m.blurredX = createImage(ctx, kMomentFormat, size, size, 1, VK_IMAGE_USAGE_STORAGE_BIT, VK_IMAGE_ASPECT_COLOR_BIT,
                             VK_IMAGE_VIEW_TYPE_2D_ARRAY);
    m.moments = createImage(ctx, kMomentFormat, size, size, layers, usage, VK_IMAGE_ASPECT_COLOR_BIT,
                            VK_IMAGE_VIEW_TYPE_2D_ARRAY);
    // The lit pass's descriptor names the array in SHADER_READ_ONLY_OPTIMAL from the start: a
    // render without a filterable filter never reads it (its code is compiled out).
    VkCommandBuffer commands = ctx.beginCommands();
    transition(commands, {{m.moments.image.get(), VK_IMAGE_ASPECT_COLOR_BIT, layers, VK_IMAGE_LAYOUT_UNDEFINED,
                           VK_IMAGE_LAYOUT_SHADER_READ_ONLY_OPTIMAL, VK_PIPELINE_STAGE_2_NONE, VK_ACCESS_2_NONE,
                           VK_PIPELINE_STAGE_2_FRAGMENT_SHADER_BIT, VK_ACCESS_2_SHADER_SAMPLED_READ_BIT}});
    ctx.submitAndWait(commands);
    return m;
}

MomentPipeline createMomentPipeline(const Context& ctx, const ShadowMaps& maps, const MomentMaps& moments,
                                    scene::ShadowFilter filter, const scene::MomentSettings& settings) {
    requireMomentFormat(ctx);
    VkDevice device = ctx.device.get();
    MomentPipeline p;
    p.radius = (settings.blurWidth - 1) / 2;
    const VkDescriptorSetLayoutBinding bindings[] = {
        {.binding = 0,
         .descriptorType = VK_DESCRIPTOR_TYPE_COMBINED_IMAGE_SAMPLER,
         .descriptorCount = 1,
         .stageFlags = VK_SHADER_STAGE_COMPUTE_BIT},
        {.binding = 1,
         .descriptorType = VK_DESCRIPTOR_TYPE_STORAGE_IMAGE,
         .descriptorCount = 1,
         .stageFlags = VK_SHADER_STAGE_COMPUTE_BIT},
        {.binding = 2,
         .descriptorType = VK_DESCRIPTOR_TYPE_STORAGE_IMAGE,
         .descriptorCount = 1,
         .stageFlags = VK_SHADER_STAGE_COMPUTE_BIT},
    };
    p.descriptors = createDescriptorSet(ctx, bindings);
    const VkDescriptorSetLayout setLayout = p.descriptors.layout.get();
    const VkPushConstantRange range{VK_SHADER_STAGE_COMPUTE_BIT, 0, sizeof(shaders::MomentPush)};
    const VkPipelineLayoutCreateInfo layoutInfo{.sType = VK_STRUCTURE_TYPE_PIPELINE_LAYOUT_CREATE_INFO,
                                                .setLayoutCount = 1,
                                                .pSetLayouts = &setLayout,
                                                .pushConstantRangeCount = 1,
                                                .pPushConstantRanges = &range};
    VkPipelineLayout layout = VK_NULL_HANDLE;
    VK_CHECK(vkCreatePipelineLayout(device, &layoutInfo, nullptr, &layout));
    p.layout = PipelineLayoutHandle(device, layout);

    const ShaderModuleHandle module = createShaderModule(ctx, shaders::momentsCompSpirv());
    // moments.comp's specialization constants, in constant_id order: the pass, the filter code, the
    // blur radius, the maps' side and the three exponents.
    struct Constants {
        std::int32_t pass, filter, radius, size;
        float evsmPositive, evsmNegative, esmExponent;
    };
    const VkSpecializationMapEntry entries[] = {
        {0, offsetof(Constants, pass), 4},         {1, offsetof(Constants, filter), 4},
        {2, offsetof(Constants, radius), 4},       {3, offsetof(Constants, size), 4},
        {4, offsetof(Constants, evsmPositive), 4}, {5, offsetof(Constants, evsmNegative), 4},
        {6, offsetof(Constants, esmExponent), 4}};
    auto create = [&](std::int32_t pass) {
        const Constants constants{pass,
                                  std::int32_t(filter),
                                  std::int32_t(p.radius),
                                  std::int32_t(moments.size),
                                  float(settings.evsmPositive),
                                  float(settings.evsmNegative),
                                  float(settings.esmExponent)};
        const VkSpecializationInfo specialization{std::uint32_t(std::size(entries)), entries, sizeof constants,
                                                  &constants};
        const VkComputePipelineCreateInfo info{
            .sType = VK_STRUCTURE_TYPE_COMPUTE_PIPELINE_CREATE_INFO,
            .stage = {.sType = VK_STRUCTURE_TYPE_PIPELINE_SHADER_STAGE_CREATE_INFO,
                      .stage = VK_SHADER_STAGE_COMPUTE_BIT,
                      .module = module.get(),
                      .pName = "main",
                      .pSpecializationInfo = &specialization},
            .layout = layout,
        };
        VkPipeline pipeline = VK_NULL_HANDLE;
        VK_CHECK(vkCreateComputePipelines(device, ctx.pipelineCache.get(), 1, &info, nullptr, &pipeline));
        return PipelineHandle(device, pipeline);
    };
    p.pipeline = create(0);
    p.blurPipeline = create(1);

    p.depthSampler = createNearestSampler(ctx);
    const VkSampler sampler = p.depthSampler.get();
    const VkDescriptorImageInfo depthInfo{sampler, maps.depth.view.get(), VK_IMAGE_LAYOUT_SHADER_READ_ONLY_OPTIMAL};
    const VkDescriptorImageInfo xInfo{VK_NULL_HANDLE, moments.blurredX.view.get(), VK_IMAGE_LAYOUT_GENERAL};
    const VkDescriptorImageInfo outInfo{VK_NULL_HANDLE, moments.moments.view.get(), VK_IMAGE_LAYOUT_GENERAL};
    const VkWriteDescriptorSet writes[] = {
        {.sType = VK_STRUCTURE_TYPE_WRITE_DESCRIPTOR_SET,
         .dstSet = p.descriptors.set,
         .dstBinding = 0,
         .descriptorCount = 1,
         .descriptorType = VK_DESCRIPTOR_TYPE_COMBINED_IMAGE_SAMPLER,
         .pImageInfo = &depthInfo},
        {.sType = VK_STRUCTURE_TYPE_WRITE_DESCRIPTOR_SET,
         .dstSet = p.descriptors.set,
         .dstBinding = 1,
         .descriptorCount = 1,
         .descriptorType = VK_DESCRIPTOR_TYPE_STORAGE_IMAGE,
         .pImageInfo = &xInfo},
        {.sType = VK_STRUCTURE_TYPE_WRITE_DESCRIPTOR_SET,
         .dstSet = p.descriptors.set,
         .dstBinding = 2,
         .descriptorCount = 1,
         .descriptorType = VK_DESCRIPTOR_TYPE_STORAGE_IMAGE,
         .pImageInfo = &outInfo},
    };
    vkUpdateDescriptorSets(device, 3, writes, 0, nullptr);
    return p;
}

void recordMomentPasses(VkCommandBuffer commands, const MomentPipeline& pipeline, const ShadowMaps& maps,
                        const MomentMaps& moments, const std::vector<ShadowLayer>& layers,
                        const std::vector<TexelRect>* windows) {
    if (layers.size() != moments.layers || (windows && windows->size() != layers.size()))
        throw RasterError("recordMomentPasses: " + std::to_string(layers.size()) + " layers planned for " +
                          std::to_string(moments.layers) + " moment maps" +
                          (windows ? " and " + std::to_string(windows->size()) + " windows" : std::string()));
    const std::uint32_t layerCount = moments.layers;
    // The depth pass's writes (its final barrier made them visible to fragment shaders and copies
    // only) before the x pass's reads; both arrays' previous contents are not needed (UNDEFINED),
    // but the previous frame's lit pass may still read the moments (a reused Renderer).
    transition(commands,
               {{maps.depth.image.get(), VK_IMAGE_ASPECT_DEPTH_BIT, maps.layers,
                 VK_IMAGE_LAYOUT_SHADER_READ_ONLY_OPTIMAL, VK_IMAGE_LAYOUT_SHADER_READ_ONLY_OPTIMAL,
                 VK_PIPELINE_STAGE_2_EARLY_FRAGMENT_TESTS_BIT | VK_PIPELINE_STAGE_2_LATE_FRAGMENT_TESTS_BIT,
                 VK_ACCESS_2_DEPTH_STENCIL_ATTACHMENT_WRITE_BIT, VK_PIPELINE_STAGE_2_COMPUTE_SHADER_BIT,
                 VK_ACCESS_2_SHADER_SAMPLED_READ_BIT},
                {moments.blurredX.image.get(), VK_IMAGE_ASPECT_COLOR_BIT, 1, VK_IMAGE_LAYOUT_UNDEFINED,
                 VK_IMAGE_LAYOUT_GENERAL, VK_PIPELINE_STAGE_2_COMPUTE_SHADER_BIT, VK_ACCESS_2_NONE,
                 VK_PIPELINE_STAGE_2_COMPUTE_SHADER_BIT, VK_ACCESS_2_SHADER_STORAGE_WRITE_BIT},
                {moments.moments.image.get(), VK_IMAGE_ASPECT_COLOR_BIT, layerCount, VK_IMAGE_LAYOUT_UNDEFINED,
                 VK_IMAGE_LAYOUT_GENERAL, VK_PIPELINE_STAGE_2_FRAGMENT_SHADER_BIT, VK_ACCESS_2_NONE,
                 VK_PIPELINE_STAGE_2_COMPUTE_SHADER_BIT, VK_ACCESS_2_SHADER_STORAGE_WRITE_BIT}});
    vkCmdBindDescriptorSets(commands, VK_PIPELINE_BIND_POINT_COMPUTE, pipeline.layout.get(), 0, 1,
                            &pipeline.descriptors.set, 0, nullptr);
    const std::uint32_t size = moments.size;
    const auto radius = std::uint32_t(pipeline.radius);
    // Per layer, its x pass and then its y pass, each with the layer's own near and far and its
    // window; the intermediate layer goes from the x pass's writes to the y pass's reads, and from
    // those reads to the next layer's writes.
    const VkImage intermediate = moments.blurredX.image.get();
    const ImageTransition writtenToRead{intermediate,
                                        VK_IMAGE_ASPECT_COLOR_BIT,
                                        1,
                                        VK_IMAGE_LAYOUT_GENERAL,
                                        VK_IMAGE_LAYOUT_GENERAL,
                                        VK_PIPELINE_STAGE_2_COMPUTE_SHADER_BIT,
                                        VK_ACCESS_2_SHADER_STORAGE_WRITE_BIT,
                                        VK_PIPELINE_STAGE_2_COMPUTE_SHADER_BIT,
                                        VK_ACCESS_2_SHADER_STORAGE_READ_BIT};
    const ImageTransition readToWritten{intermediate,
                                        VK_IMAGE_ASPECT_COLOR_BIT,
                                        1,
                                        VK_IMAGE_LAYOUT_GENERAL,
                                        VK_IMAGE_LAYOUT_GENERAL,
                                        VK_PIPELINE_STAGE_2_COMPUTE_SHADER_BIT,
                                        VK_ACCESS_2_SHADER_STORAGE_READ_BIT,
                                        VK_PIPELINE_STAGE_2_COMPUTE_SHADER_BIT,
                                        VK_ACCESS_2_SHADER_STORAGE_WRITE_BIT};
    bool intermediateRead = false;  // a y pass has read the intermediate layer since it was written
    for (std::uint32_t k = 0; k < layerCount; ++k) {
        const TexelRect lookups = windows ? (*windows)[k] : TexelRect{0, 0, size, size};
        if (lookups.empty()) continue;
        const LightFrustum& f = layers[k].frustum;
        for (int pass = 0; pass < 2; ++pass) {
            const TexelRect w = pass == 0 ? grownWithin(lookups, 0, radius, size) : lookups;
            if (pass == 0 && intermediateRead) transition(commands, {readToWritten});
            if (pass == 1) transition(commands, {writtenToRead});
            vkCmdBindPipeline(commands, VK_PIPELINE_BIND_POINT_COMPUTE,
                              pass == 0 ? pipeline.pipeline.get() : pipeline.blurPipeline.get());
            const shaders::MomentPush push{
                .layer = glm::ivec4(int(k), f.perspective ? 1 : 0, 0, 0),
                .range = f.perspective ? glm::vec4(float(f.near), float(f.far), 0.0f, 0.0f) : glm::vec4(0.0f),
                .window = glm::ivec4(int(w.x0), int(w.y0), int(w.x1), int(w.y1))};
            vkCmdPushConstants(commands, pipeline.layout.get(), VK_SHADER_STAGE_COMPUTE_BIT, 0, sizeof push, &push);
            vkCmdDispatch(commands, (w.x1 - w.x0 + kGroup - 1) / kGroup, (w.y1 - w.y0 + kGroup - 1) / kGroup, 1);
        }
        intermediateRead = true;
    }
    transition(commands, {{moments.moments.image.get(), VK_IMAGE_ASPECT_COLOR_BIT, layerCount, VK_IMAGE_LAYOUT_GENERAL,
                           VK_IMAGE_LAYOUT_SHADER_READ_ONLY_OPTIMAL, VK_PIPELINE_STAGE_2_COMPUTE_SHADER_BIT,
                           VK_ACCESS_2_SHADER_STORAGE_WRITE_BIT, VK_PIPELINE_STAGE_2_FRAGMENT_SHADER_BIT,
                           VK_ACCESS_2_SHADER_SAMPLED_READ_BIT}});
}

std::string describeMomentCost(scene::ShadowFilter filter, std::uint32_t size, std::uint32_t layers, int blurWidth) {
    const double mib = double(momentBytes(size, layers)) / (1024.0 * 1024.0);
    std::ostringstream s;
    s.precision(3);
    s << scene::toString(filter) << ": 2 compute passes (moments and a " << blurWidth << "-texel box blur along x, "
      << "then along y) over the texels the lookups read, at most " << layers << " layer(s) of " << size << "x" << size
      << ", an RGBA32F moment array and one intermediate layer (" << mib << " MiB)";
    return s.str();
}

}  // namespace shadowlab::raster
