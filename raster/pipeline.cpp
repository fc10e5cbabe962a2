// raster/pipeline.cpp: shader modules and the shared graphics-pipeline builder.
#include "raster/pipeline.h"

#include <algorithm>

#include "raster/geometry.h"
#include "raster/vulkan_error.h"

namespace shadowlab::raster {

ShaderModuleHandle createShaderModule(const Context& ctx, std::span<const std::uint32_t> spirv) {
    const VkShaderModuleCreateInfo info{
        .sType = VK_STRUCTURE_TYPE_SHADER_MODULE_CREATE_INFO,
        .codeSize = spirv.size_bytes(),
        .pCode = spirv.data(),
    };
    VkShaderModule module = VK_NULL_HANDLE;
    VK_CHECK(vkCreateShaderModule(ctx.device.get(), &info, nullptr, &module));
    return ShaderModuleHandle(ctx.device.get(), module);
}

PipelineHandle createGraphicsPipeline(const Context& ctx, const PipelineDesc& desc) {
    const ShaderModuleHandle vertex = createShaderModule(ctx, desc.vertexShader);
    ShaderModuleHandle fragment;
    std::vector<VkPipelineShaderStageCreateInfo> stages{{
        .sType = VK_STRUCTURE_TYPE_PIPELINE_SHADER_STAGE_CREATE_INFO,
        .stage = VK_SHADER_STAGE_VERTEX_BIT,
        .module = vertex.get(),
        .pName = "main",
        .pSpecializationInfo = desc.vertexSpecialization,
    }};
    if (!desc.fragmentShader.empty()) {
        fragment = createShaderModule(ctx, desc.fragmentShader);
        stages.push_back({
            .sType = VK_STRUCTURE_TYPE_PIPELINE_SHADER_STAGE_CREATE_INFO,
            .stage = VK_SHADER_STAGE_FRAGMENT_BIT,
            .module = fragment.get(),
            .pName = "main",
            .pSpecializationInfo = desc.fragmentSpecialization,
        });
    }

    const VkVertexInputBindingDescription bindings[2] = {
        {.binding = 0, .stride = sizeof(Vertex), .inputRate = VK_VERTEX_INPUT_RATE_VERTEX},
        {.binding = 1, .stride = sizeof(glm::vec2), .inputRate = VK_VERTEX_INPUT_RATE_VERTEX}};
    std::vector<VkVertexInputAttributeDescription> attributes{
        {.location = 0, .binding = 0, .format = VK_FORMAT_R32G32B32_SFLOAT, .offset = offsetof(Vertex, position)},
    };
    if (desc.usesObjectId)
        attributes.push_back(
            {.location = 2, .binding = 0, .format = VK_FORMAT_R32_UINT, .offset = offsetof(Vertex, objectId)});
    if (desc.usesNormal)
        attributes.push_back(
            {.location = 1, .binding = 0, .format = VK_FORMAT_R32G32B32_SFLOAT, .offset = offsetof(Vertex, normal)});
    if (desc.usesUv)
        attributes.push_back({.location = 3, .binding = 1, .format = VK_FORMAT_R32G32_SFLOAT, .offset = 0});
    const VkPipelineVertexInputStateCreateInfo vertexInput{
        .sType = VK_STRUCTURE_TYPE_PIPELINE_VERTEX_INPUT_STATE_CREATE_INFO,
        .vertexBindingDescriptionCount = !desc.vertexBuffer ? 0u
                                         : desc.usesUv      ? 2u
                                                            : 1u,
        .pVertexBindingDescriptions = bindings,
        .vertexAttributeDescriptionCount = desc.vertexBuffer ? std::uint32_t(attributes.size()) : 0u,
        .pVertexAttributeDescriptions = attributes.data(),
    };
    const VkPipelineInputAssemblyStateCreateInfo inputAssembly{
        .sType = VK_STRUCTURE_TYPE_PIPELINE_INPUT_ASSEMBLY_STATE_CREATE_INFO,
        .topology = VK_PRIMITIVE_TOPOLOGY_TRIANGLE_LIST,
    };
    const VkPipelineViewportStateCreateInfo viewport{
        .sType = VK_STRUCTURE_TYPE_PIPELINE_VIEWPORT_STATE_CREATE_INFO,
        .viewportCount = 1,
        .scissorCount = 1,
    };
    const VkPipelineRasterizationStateCreateInfo rasterization{
        .sType = VK_STRUCTURE_TYPE_PIPELINE_RASTERIZATION_STATE_CREATE_INFO,
        .polygonMode = VK_POLYGON_MODE_FILL,
        .cullMode = VK_CULL_MODE_NONE,
        .frontFace = VK_FRONT_FACE_COUNTER_CLOCKWISE,
        // Off unless the hardware bias is asked for: biases are applied in the lit shader, in world units.
        .depthBiasEnable = desc.dynamicDepthBias ? VK_TRUE : VK_FALSE,
        .lineWidth = 1.0f,
    };
    const VkPipelineMultisampleStateCreateInfo multisample{
        .sType = VK_STRUCTURE_TYPE_PIPELINE_MULTISAMPLE_STATE_CREATE_INFO,
        .rasterizationSamples = VK_SAMPLE_COUNT_1_BIT,
    };
    const VkPipelineDepthStencilStateCreateInfo depthStencil{
        .sType = VK_STRUCTURE_TYPE_PIPELINE_DEPTH_STENCIL_STATE_CREATE_INFO,
        .depthTestEnable = VK_TRUE,
        .depthWriteEnable = desc.depthWrite ? VK_TRUE : VK_FALSE,
        .depthCompareOp = desc.depthCompare,
        .maxDepthBounds = 1.0f,
    };
    std::vector<VkPipelineColorBlendAttachmentState> blend(
        desc.colorFormats.size(), VkPipelineColorBlendAttachmentState{
                                      .blendEnable = VK_FALSE,
                                      .colorWriteMask = VK_COLOR_COMPONENT_R_BIT | VK_COLOR_COMPONENT_G_BIT |
                                                        VK_COLOR_COMPONENT_B_BIT | VK_COLOR_COMPONENT_A_BIT,
                                  });
    if (desc.transmittanceBlend && blend.size() == 2) {
        // dst · src: result = src·0 + dst·src.
        blend[0].blendEnable = VK_TRUE;
        blend[0].srcColorBlendFactor = VK_BLEND_FACTOR_ZERO;
        blend[0].dstColorBlendFactor = VK_BLEND_FACTOR_SRC_COLOR;
        blend[0].colorBlendOp = VK_BLEND_OP_ADD;
        blend[0].srcAlphaBlendFactor = VK_BLEND_FACTOR_ZERO;
        blend[0].dstAlphaBlendFactor = VK_BLEND_FACTOR_SRC_ALPHA;
        blend[0].alphaBlendOp = VK_BLEND_OP_ADD;
        // min(src, dst) (the factors are ignored by MIN).
        blend[1].blendEnable = VK_TRUE;
        blend[1].srcColorBlendFactor = VK_BLEND_FACTOR_ONE;
        blend[1].dstColorBlendFactor = VK_BLEND_FACTOR_ONE;
        blend[1].colorBlendOp = VK_BLEND_OP_MIN;
        blend[1].srcAlphaBlendFactor = VK_BLEND_FACTOR_ONE;
        blend[1].dstAlphaBlendFactor = VK_BLEND_FACTOR_ONE;
        blend[1].alphaBlendOp = VK_BLEND_OP_MIN;
    }
    const VkPipelineColorBlendStateCreateInfo colorBlend{
        .sType = VK_STRUCTURE_TYPE_PIPELINE_COLOR_BLEND_STATE_CREATE_INFO,
        .attachmentCount = std::uint32_t(blend.size()),
        .pAttachments = blend.data(),
    };
    const VkDynamicState dynamicStates[] = {VK_DYNAMIC_STATE_VIEWPORT, VK_DYNAMIC_STATE_SCISSOR,
                                            VK_DYNAMIC_STATE_DEPTH_BIAS};
    const VkPipelineDynamicStateCreateInfo dynamic{
        .sType = VK_STRUCTURE_TYPE_PIPELINE_DYNAMIC_STATE_CREATE_INFO,
        .dynamicStateCount = desc.dynamicDepthBias ? 3u : 2u,
        .pDynamicStates = dynamicStates,
    };
    const VkPipelineRenderingCreateInfo rendering{
        .sType = VK_STRUCTURE_TYPE_PIPELINE_RENDERING_CREATE_INFO,
        .colorAttachmentCount = std::uint32_t(desc.colorFormats.size()),
        .pColorAttachmentFormats = desc.colorFormats.data(),
        .depthAttachmentFormat = desc.depthFormat,
    };
    const VkGraphicsPipelineCreateInfo info{
        .sType = VK_STRUCTURE_TYPE_GRAPHICS_PIPELINE_CREATE_INFO,
        .pNext = &rendering,
        .stageCount = std::uint32_t(stages.size()),
        .pStages = stages.data(),
        .pVertexInputState = &vertexInput,
        .pInputAssemblyState = &inputAssembly,
        .pViewportState = &viewport,
        .pRasterizationState = &rasterization,
        .pMultisampleState = &multisample,
        .pDepthStencilState = &depthStencil,
        .pColorBlendState = desc.colorFormats.empty() ? nullptr : &colorBlend,
        .pDynamicState = &dynamic,
        .layout = desc.layout,
    };
    VkPipeline pipeline = VK_NULL_HANDLE;
    VK_CHECK(vkCreateGraphicsPipelines(ctx.device.get(), ctx.pipelineCache.get(), 1, &info, nullptr, &pipeline));
    return PipelineHandle(ctx.device.get(), pipeline);
}

void requireFormat(const Context& ctx, VkFormat format, VkFormatFeatureFlags features, const char* purpose) {
    VkFormatProperties props{};
    vkGetPhysicalDeviceFormatProperties(ctx.physicalDevice, format, &props);
    if ((props.optimalTilingFeatures & features) != features)
        throw RasterError("the Vulkan device " + ctx.deviceReport.name + " does not support format " +
                          std::to_string(int(format)) + " for " + purpose + " (features 0x" + std::to_string(features) +
                          " missing); choose another device with --device");
}

void setViewport(VkCommandBuffer commands, std::uint32_t width, std::uint32_t height) {
    const VkViewport viewport{
        .x = 0, .y = 0, .width = float(width), .height = float(height), .minDepth = 0.0f, .maxDepth = 1.0f};
    const VkRect2D scissor{.offset = {0, 0}, .extent = {width, height}};
    vkCmdSetViewport(commands, 0, 1, &viewport);
    vkCmdSetScissor(commands, 0, 1, &scissor);
}

DescriptorSet createDescriptorSet(const Context& ctx, std::span<const VkDescriptorSetLayoutBinding> bindings) {
    VkDevice device = ctx.device.get();
    DescriptorSet d;
    const VkDescriptorSetLayoutCreateInfo setInfo{.sType = VK_STRUCTURE_TYPE_DESCRIPTOR_SET_LAYOUT_CREATE_INFO,
                                                  .bindingCount = std::uint32_t(bindings.size()),
                                                  .pBindings = bindings.data()};
    VkDescriptorSetLayout setLayout = VK_NULL_HANDLE;
    VK_CHECK(vkCreateDescriptorSetLayout(device, &setInfo, nullptr, &setLayout));
    d.layout = DescriptorSetLayoutHandle(device, setLayout);
    std::vector<VkDescriptorPoolSize> sizes;
    for (const VkDescriptorSetLayoutBinding& b : bindings) {
        auto same = std::find_if(sizes.begin(), sizes.end(),
                                 [&](const VkDescriptorPoolSize& s) { return s.type == b.descriptorType; });
        if (same == sizes.end())
            sizes.push_back({b.descriptorType, b.descriptorCount});
        else
            same->descriptorCount += b.descriptorCount;
    }
    const VkDescriptorPoolCreateInfo poolInfo{.sType = VK_STRUCTURE_TYPE_DESCRIPTOR_POOL_CREATE_INFO,
                                              .maxSets = 1,
                                              .poolSizeCount = std::uint32_t(sizes.size()),
                                              .pPoolSizes = sizes.data()};
    VkDescriptorPool pool = VK_NULL_HANDLE;
    VK_CHECK(vkCreateDescriptorPool(device, &poolInfo, nullptr, &pool));
    d.pool = DescriptorPoolHandle(device, pool);
    const VkDescriptorSetAllocateInfo allocInfo{.sType = VK_STRUCTURE_TYPE_DESCRIPTOR_SET_ALLOCATE_INFO,
                                                .descriptorPool = pool,
                                                .descriptorSetCount = 1,
                                                .pSetLayouts = &setLayout};
    VK_CHECK(vkAllocateDescriptorSets(device, &allocInfo, &d.set));
    return d;
}

SamplerHandle createNearestSampler(const Context& ctx) {
    const VkSamplerCreateInfo info{
        .sType = VK_STRUCTURE_TYPE_SAMPLER_CREATE_INFO,
        .magFilter = VK_FILTER_NEAREST,
        .minFilter = VK_FILTER_NEAREST,
        .mipmapMode = VK_SAMPLER_MIPMAP_MODE_NEAREST,
        .addressModeU = VK_SAMPLER_ADDRESS_MODE_CLAMP_TO_EDGE,
        .addressModeV = VK_SAMPLER_ADDRESS_MODE_CLAMP_TO_EDGE,
        .addressModeW = VK_SAMPLER_ADDRESS_MODE_CLAMP_TO_EDGE,
        .maxLod = 0.0f,
    };
    VkSampler sampler = VK_NULL_HANDLE;
    VK_CHECK(vkCreateSampler(ctx.device.get(), &info, nullptr, &sampler));
    return SamplerHandle(ctx.device.get(), sampler);
}

}  // namespace shadowlab::raster
