// raster/lit_pass.cpp: the camera pass and the readback of its targets.
#include "raster/lit_pass.h"

#include <bit>
#include <cstring>

#include "raster/pipeline.h"
#include "raster/vulkan_error.h"
#include "shaders/spirv.h"

namespace shadowlab::raster {

bool usesVertexLightCoordinates(const LitVariant& variant) {
    if (variant.lightCount != 1 || variant.receiverPlane) return false;
    return (variant.lightKinds == (1u << SHADOWLAB_LIGHT_DIRECTIONAL) && variant.cascades == 1) ||
           variant.lightKinds == (1u << SHADOWLAB_LIGHT_SPOT);
}

LitPipeline createLitPipeline(const Context& ctx, const LitVariant& variant, VkDescriptorSetLayout alphaSetLayout) {
    requireFormat(ctx, kLitColorFormat,
                  VK_FORMAT_FEATURE_COLOR_ATTACHMENT_BIT | VK_FORMAT_FEATURE_TRANSFER_SRC_BIT, "the lit pass targets");
    requireFormat(ctx, kLitDepthFormat, VK_FORMAT_FEATURE_DEPTH_STENCIL_ATTACHMENT_BIT, "the camera depth buffer");
    VkDevice device = ctx.device.get();
    const VkDescriptorSetLayoutBinding bindings[] = {
        {.binding = 0, .descriptorType = VK_DESCRIPTOR_TYPE_UNIFORM_BUFFER, .descriptorCount = 1,
         .stageFlags = VK_SHADER_STAGE_VERTEX_BIT | VK_SHADER_STAGE_FRAGMENT_BIT},
        // Per-object albedo, read by lit.vert (and passed on flat).
        {.binding = 1, .descriptorType = VK_DESCRIPTOR_TYPE_STORAGE_BUFFER, .descriptorCount = 1,
         .stageFlags = VK_SHADER_STAGE_VERTEX_BIT},
        {.binding = 2, .descriptorType = VK_DESCRIPTOR_TYPE_COMBINED_IMAGE_SAMPLER, .descriptorCount = 1,
         .stageFlags = VK_SHADER_STAGE_FRAGMENT_BIT},
        {.binding = 3, .descriptorType = VK_DESCRIPTOR_TYPE_COMBINED_IMAGE_SAMPLER, .descriptorCount = 1,
         .stageFlags = VK_SHADER_STAGE_FRAGMENT_BIT},
        // The shadow maps' raw depths (no compare), for the PCSS blocker search.
        {.binding = 4, .descriptorType = VK_DESCRIPTOR_TYPE_COMBINED_IMAGE_SAMPLER, .descriptorCount = 1,
         .stageFlags = VK_SHADER_STAGE_FRAGMENT_BIT},
        // The transmittance maps: the product of 1 − opacity, and the nearest transparent depth.
        {.binding = 5, .descriptorType = VK_DESCRIPTOR_TYPE_COMBINED_IMAGE_SAMPLER, .descriptorCount = 1,
         .stageFlags = VK_SHADER_STAGE_FRAGMENT_BIT},
        {.binding = 6, .descriptorType = VK_DESCRIPTOR_TYPE_COMBINED_IMAGE_SAMPLER, .descriptorCount = 1,
         .stageFlags = VK_SHADER_STAGE_FRAGMENT_BIT},
        // Behind the nearest transparent layer: the product of the rest, and their nearest depth.
        {.binding = 7, .descriptorType = VK_DESCRIPTOR_TYPE_COMBINED_IMAGE_SAMPLER, .descriptorCount = 1,
         .stageFlags = VK_SHADER_STAGE_FRAGMENT_BIT},
        {.binding = 8, .descriptorType = VK_DESCRIPTOR_TYPE_COMBINED_IMAGE_SAMPLER, .descriptorCount = 1,
         .stageFlags = VK_SHADER_STAGE_FRAGMENT_BIT},
        // The filterable maps' blurred moments (raster/moment_maps.h), linearly filtered.
        {.binding = 9, .descriptorType = VK_DESCRIPTOR_TYPE_COMBINED_IMAGE_SAMPLER, .descriptorCount = 1,
         .stageFlags = VK_SHADER_STAGE_FRAGMENT_BIT},
    };
    const VkDescriptorSetLayoutCreateInfo setInfo{
        .sType = VK_STRUCTURE_TYPE_DESCRIPTOR_SET_LAYOUT_CREATE_INFO,
        .bindingCount = 10,
        .pBindings = bindings,
    };
    LitPipeline p;
    VkDescriptorSetLayout setLayout = VK_NULL_HANDLE;
    VK_CHECK(vkCreateDescriptorSetLayout(device, &setInfo, nullptr, &setLayout));
    p.setLayout = DescriptorSetLayoutHandle(device, setLayout);
    p.alpha = alphaSetLayout != VK_NULL_HANDLE;
    const VkDescriptorSetLayout setLayouts[2] = {setLayout, alphaSetLayout};  // shaders/alpha.glsl at set 1
    const VkPipelineLayoutCreateInfo layoutInfo{
        .sType = VK_STRUCTURE_TYPE_PIPELINE_LAYOUT_CREATE_INFO,
        .setLayoutCount = p.alpha ? 2u : 1u,
        .pSetLayouts = setLayouts,
    };
    VkPipelineLayout layout = VK_NULL_HANDLE;
    VK_CHECK(vkCreatePipelineLayout(device, &layoutInfo, nullptr, &layout));
    p.layout = PipelineLayoutHandle(device, layout);
    // shaders/lit_constants.glsl's constant_id 0: the filter code, 1: blocker ids (a bool is 32
    // bits wide), 2: the light count, 3: the light kinds, 4: the cascade count, 5: transmittance
    // (bool), 6: receiver-plane bias (bool), 7: cascade blend bands (bool), 8: visibility in the
    // beauty's alpha (bool; not for the display target), 9: normal offset (bool), 10: the light's
    // constants as flat vertex outputs (bool), 11..16: the filterable maps' parameters (float bits:
    // minimum variance, bleeding reduction, EVSM exponents, ESM exponent, MSM moment bias). Both
    // stages get them all.
    constexpr std::uint32_t kConstants = 17;
    const scene::MomentSettings& m = variant.moments;
    const std::int32_t constants[kConstants] = {
        std::int32_t(variant.filter),     variant.blockerIds ? 1 : 0,       std::int32_t(variant.lightCount),
        std::int32_t(variant.lightKinds), std::int32_t(variant.cascades),   variant.transmittance ? 1 : 0,
        variant.receiverPlane ? 1 : 0,    variant.cascadeBlend ? 1 : 0,     variant.displayTarget ? 0 : 1,
        variant.normalOffset ? 1 : 0,     variant.vertexLightConstants ? 1 : 0,
        std::bit_cast<std::int32_t>(float(m.minVariance)), std::bit_cast<std::int32_t>(float(m.bleedReduction)),
        std::bit_cast<std::int32_t>(float(m.evsmPositive)), std::bit_cast<std::int32_t>(float(m.evsmNegative)),
        std::bit_cast<std::int32_t>(float(m.esmExponent)), std::bit_cast<std::int32_t>(float(m.momentBias))};
    VkSpecializationMapEntry entries[kConstants];
    for (std::uint32_t i = 0; i < kConstants; ++i) entries[i] = {i, 4 * i, 4};
    const VkSpecializationInfo specialization{
        .mapEntryCount = kConstants, .pMapEntries = entries, .dataSize = sizeof constants, .pData = constants};
    std::vector<VkFormat> colorFormats{variant.displayTarget ? kLitDisplayFormat : kLitColorFormat};
    if (variant.aovTarget) colorFormats.insert(colorFormats.end(), 1 + variant.lightTargets, kLitColorFormat);
    p.pipeline = createGraphicsPipeline(ctx, PipelineDesc{
                                                 .vertexShader = p.alpha ? shaders::litVertAlphaSpirv()
                                                                         : shaders::litVertSpirv(),
                                                 .fragmentShader =
                                                     !variant.aovTarget
                                                         ? (p.alpha ? shaders::litFragBeautyAlphaSpirv()
                                                                    : shaders::litFragBeautySpirv())
                                                     : variant.lightTargets > 0
                                                         ? (p.alpha ? shaders::litFragLightsAlphaSpirv()
                                                                    : shaders::litFragLightsSpirv())
                                                         : (p.alpha ? shaders::litFragAlphaSpirv() : shaders::litFragSpirv()),
                                                 .fragmentSpecialization = &specialization,
                                                 .vertexSpecialization = &specialization,
                                                 .layout = layout,
                                                 .usesUv = p.alpha,
                                                 .colorFormats = colorFormats,
                                                 .depthFormat = kLitDepthFormat,
                                                 // Reversed Z: nearer is larger.
                                                 .depthCompare = VK_COMPARE_OP_GREATER,
                                             });
    return p;
}

LitTargets createLitTargets(const Context& ctx, std::uint32_t width, std::uint32_t height,
                            std::uint32_t lightTargets, bool readInPlace) {
    const std::uint32_t limit = ctx.properties.limits.maxImageDimension2D;
    if (width > limit || height > limit)
        throw RasterError("image " + std::to_string(width) + "x" + std::to_string(height) +
                          " exceeds the device's limit of " + std::to_string(limit) + " per side (" +
                          ctx.deviceReport.name + ")");
    // Two (plus lightTargets) RGBA32F targets, D32 depth, as many RGBA32F readback buffers, and
    // the RGBA8 display target.
    requireDeviceMemory(ctx, VkDeviceSize(width) * height * ((2 + lightTargets) * 16 * 2 + 4 + 4),
                        "a " + std::to_string(width) + "x" + std::to_string(height) + " image");
    LitTargets t;
    t.width = width;
    t.height = height;
    const VkImageUsageFlags colorUsage = VK_IMAGE_USAGE_COLOR_ATTACHMENT_BIT | VK_IMAGE_USAGE_TRANSFER_SRC_BIT;
    t.hostReadable = readInPlace && canReadImagesOnHost(ctx, kLitColorFormat, colorUsage);
    t.beauty = createImage(ctx, kLitColorFormat, width, height, 1, colorUsage, VK_IMAGE_ASPECT_COLOR_BIT,
                           VK_IMAGE_VIEW_TYPE_2D, t.hostReadable);
    t.aovs = createImage(ctx, kLitColorFormat, width, height, 1, colorUsage, VK_IMAGE_ASPECT_COLOR_BIT,
                         VK_IMAGE_VIEW_TYPE_2D, t.hostReadable);
    t.depth = createImage(ctx, kLitDepthFormat, width, height, 1, VK_IMAGE_USAGE_DEPTH_STENCIL_ATTACHMENT_BIT,
                          VK_IMAGE_ASPECT_DEPTH_BIT, VK_IMAGE_VIEW_TYPE_2D);
    for (std::uint32_t i = 0; i < lightTargets; ++i)
        t.lights.push_back(createImage(ctx, kLitColorFormat, width, height, 1, colorUsage, VK_IMAGE_ASPECT_COLOR_BIT,
                                       VK_IMAGE_VIEW_TYPE_2D, t.hostReadable));
    // (lavapipe allocates host memory on first touch, so a display target never rendered costs
    // address space only.)
    if (t.hostReadable && canReadImagesOnHost(ctx, kLitDisplayFormat, colorUsage))
        t.display = createImage(ctx, kLitDisplayFormat, width, height, 1, colorUsage, VK_IMAGE_ASPECT_COLOR_BIT,
                                VK_IMAGE_VIEW_TYPE_2D, true);
    return t;
}

LitBindings createLitBindings(const Context& ctx, const LitPipeline& pipeline, const shaders::LitUniforms& uniforms,
                              const std::vector<glm::vec4>& albedos, const ShadowMaps& maps,
                              const TransmittanceMaps& transmittance, const MomentMaps& moments) {
    VkDevice device = ctx.device.get();
    LitBindings b;
    // A depth-compare sampler: result = (ref <= stored), i.e. "receiver depth - bias <= stored
    // depth" is lit. Outside the map the border is depth 1 (far), so there everything is lit.
    // NEAREST for every filter: lit.frag does the filtering (lavapipe has no linear filtering
    // of D32_SFLOAT, and shader-side weights are the same on every driver).
    const VkFilter texFilter = VK_FILTER_NEAREST;
    const VkSamplerCreateInfo samplerInfo{
        .sType = VK_STRUCTURE_TYPE_SAMPLER_CREATE_INFO,
        .magFilter = texFilter,
        .minFilter = texFilter,
        .mipmapMode = VK_SAMPLER_MIPMAP_MODE_NEAREST,
        .addressModeU = VK_SAMPLER_ADDRESS_MODE_CLAMP_TO_BORDER,
        .addressModeV = VK_SAMPLER_ADDRESS_MODE_CLAMP_TO_BORDER,
        .addressModeW = VK_SAMPLER_ADDRESS_MODE_CLAMP_TO_EDGE,
        .compareEnable = VK_TRUE,
        .compareOp = VK_COMPARE_OP_LESS_OR_EQUAL,
        .minLod = 0.0f,
        .maxLod = 0.0f,
        .borderColor = VK_BORDER_COLOR_FLOAT_OPAQUE_WHITE,
    };
    VkSampler sampler = VK_NULL_HANDLE;
    VK_CHECK(vkCreateSampler(device, &samplerInfo, nullptr, &sampler));
    b.sampler = SamplerHandle(device, sampler);
    // The blocker ids: the same NEAREST addressing, no compare; 0 (no blocker) outside.
    VkSamplerCreateInfo idSamplerInfo = samplerInfo;
    idSamplerInfo.compareEnable = VK_FALSE;
    idSamplerInfo.compareOp = VK_COMPARE_OP_NEVER;
    idSamplerInfo.borderColor = VK_BORDER_COLOR_INT_TRANSPARENT_BLACK;
    VkSampler idSampler = VK_NULL_HANDLE;
    VK_CHECK(vkCreateSampler(device, &idSamplerInfo, nullptr, &idSampler));
    b.idSampler = SamplerHandle(device, idSampler);
    // Raw depths for the PCSS blocker search: no compare; depth 1 (nothing) outside the map.
    VkSamplerCreateInfo depthSamplerInfo = samplerInfo;
    depthSamplerInfo.compareEnable = VK_FALSE;
    depthSamplerInfo.compareOp = VK_COMPARE_OP_NEVER;
    VkSampler depthSampler = VK_NULL_HANDLE;
    VK_CHECK(vkCreateSampler(device, &depthSamplerInfo, nullptr, &depthSampler));
    b.depthSampler = SamplerHandle(device, depthSampler);

    VkSamplerCreateInfo momentSamplerInfo = depthSamplerInfo;
    momentSamplerInfo.magFilter = VK_FILTER_LINEAR;
    momentSamplerInfo.minFilter = VK_FILTER_LINEAR;
    momentSamplerInfo.addressModeU = VK_SAMPLER_ADDRESS_MODE_CLAMP_TO_EDGE;
    momentSamplerInfo.addressModeV = VK_SAMPLER_ADDRESS_MODE_CLAMP_TO_EDGE;
    momentSamplerInfo.addressModeW = VK_SAMPLER_ADDRESS_MODE_CLAMP_TO_EDGE;
    VkSampler momentSampler = VK_NULL_HANDLE;
    VK_CHECK(vkCreateSampler(device, &momentSamplerInfo, nullptr, &momentSampler));
    b.momentSampler = SamplerHandle(device, momentSampler);
    b.uniforms = uploadBuffer(ctx, &uniforms, sizeof uniforms, VK_BUFFER_USAGE_UNIFORM_BUFFER_BIT);
    b.albedos = uploadBuffer(ctx, albedos, VK_BUFFER_USAGE_STORAGE_BUFFER_BIT);

    const VkDescriptorPoolSize sizes[] = {
        {VK_DESCRIPTOR_TYPE_UNIFORM_BUFFER, 1},
        {VK_DESCRIPTOR_TYPE_STORAGE_BUFFER, 1},
        {VK_DESCRIPTOR_TYPE_COMBINED_IMAGE_SAMPLER, 8},
    };
    const VkDescriptorPoolCreateInfo poolInfo{
        .sType = VK_STRUCTURE_TYPE_DESCRIPTOR_POOL_CREATE_INFO,
        .maxSets = 1,
        .poolSizeCount = 3,
        .pPoolSizes = sizes,
    };
    VkDescriptorPool pool = VK_NULL_HANDLE;
    VK_CHECK(vkCreateDescriptorPool(device, &poolInfo, nullptr, &pool));
    b.pool = DescriptorPoolHandle(device, pool);
    const VkDescriptorSetLayout setLayout = pipeline.setLayout.get();
    const VkDescriptorSetAllocateInfo allocInfo{
        .sType = VK_STRUCTURE_TYPE_DESCRIPTOR_SET_ALLOCATE_INFO,
        .descriptorPool = pool,
        .descriptorSetCount = 1,
        .pSetLayouts = &setLayout,
    };
    VK_CHECK(vkAllocateDescriptorSets(device, &allocInfo, &b.set));

    const VkDescriptorBufferInfo uniformInfo{b.uniforms.buffer.get(), 0, VK_WHOLE_SIZE};
    const VkDescriptorBufferInfo albedoInfo{b.albedos.buffer.get(), 0, VK_WHOLE_SIZE};
    const VkDescriptorImageInfo imageInfo{sampler, maps.depth.view.get(), VK_IMAGE_LAYOUT_SHADER_READ_ONLY_OPTIMAL};
    const VkDescriptorImageInfo idInfo{idSampler, maps.ids.view.get(), VK_IMAGE_LAYOUT_SHADER_READ_ONLY_OPTIMAL};
    const VkDescriptorImageInfo depthInfo{depthSampler, maps.depth.view.get(), VK_IMAGE_LAYOUT_SHADER_READ_ONLY_OPTIMAL};
    // The transmittance maps use the raw-depth sampler: NEAREST, border 1 (all light, nothing near).
    const VkDescriptorImageInfo transmittanceInfo{depthSampler, transmittance.transmittance.view.get(),
                                                  VK_IMAGE_LAYOUT_SHADER_READ_ONLY_OPTIMAL};
    const VkDescriptorImageInfo nearInfo{depthSampler, transmittance.nearDepth.view.get(),
                                         VK_IMAGE_LAYOUT_SHADER_READ_ONLY_OPTIMAL};
    const VkDescriptorImageInfo restInfo{depthSampler, transmittance.restTransmittance.view.get(),
                                         VK_IMAGE_LAYOUT_SHADER_READ_ONLY_OPTIMAL};
    const VkDescriptorImageInfo secondInfo{depthSampler, transmittance.secondDepth.view.get(),
                                           VK_IMAGE_LAYOUT_SHADER_READ_ONLY_OPTIMAL};
    const VkDescriptorImageInfo momentInfo{momentSampler, moments.moments.view.get(),
                                           VK_IMAGE_LAYOUT_SHADER_READ_ONLY_OPTIMAL};
    const VkWriteDescriptorSet writes[] = {
        {.sType = VK_STRUCTURE_TYPE_WRITE_DESCRIPTOR_SET, .dstSet = b.set, .dstBinding = 0, .descriptorCount = 1,
         .descriptorType = VK_DESCRIPTOR_TYPE_UNIFORM_BUFFER, .pBufferInfo = &uniformInfo},
        {.sType = VK_STRUCTURE_TYPE_WRITE_DESCRIPTOR_SET, .dstSet = b.set, .dstBinding = 1, .descriptorCount = 1,
         .descriptorType = VK_DESCRIPTOR_TYPE_STORAGE_BUFFER, .pBufferInfo = &albedoInfo},
        {.sType = VK_STRUCTURE_TYPE_WRITE_DESCRIPTOR_SET, .dstSet = b.set, .dstBinding = 2, .descriptorCount = 1,
         .descriptorType = VK_DESCRIPTOR_TYPE_COMBINED_IMAGE_SAMPLER, .pImageInfo = &imageInfo},
        {.sType = VK_STRUCTURE_TYPE_WRITE_DESCRIPTOR_SET, .dstSet = b.set, .dstBinding = 3, .descriptorCount = 1,
         .descriptorType = VK_DESCRIPTOR_TYPE_COMBINED_IMAGE_SAMPLER, .pImageInfo = &idInfo},
        {.sType = VK_STRUCTURE_TYPE_WRITE_DESCRIPTOR_SET, .dstSet = b.set, .dstBinding = 4, .descriptorCount = 1,
         .descriptorType = VK_DESCRIPTOR_TYPE_COMBINED_IMAGE_SAMPLER, .pImageInfo = &depthInfo},
        {.sType = VK_STRUCTURE_TYPE_WRITE_DESCRIPTOR_SET, .dstSet = b.set, .dstBinding = 5, .descriptorCount = 1,
         .descriptorType = VK_DESCRIPTOR_TYPE_COMBINED_IMAGE_SAMPLER, .pImageInfo = &transmittanceInfo},
        {.sType = VK_STRUCTURE_TYPE_WRITE_DESCRIPTOR_SET, .dstSet = b.set, .dstBinding = 6, .descriptorCount = 1,
         .descriptorType = VK_DESCRIPTOR_TYPE_COMBINED_IMAGE_SAMPLER, .pImageInfo = &nearInfo},
        {.sType = VK_STRUCTURE_TYPE_WRITE_DESCRIPTOR_SET, .dstSet = b.set, .dstBinding = 7, .descriptorCount = 1,
         .descriptorType = VK_DESCRIPTOR_TYPE_COMBINED_IMAGE_SAMPLER, .pImageInfo = &restInfo},
        {.sType = VK_STRUCTURE_TYPE_WRITE_DESCRIPTOR_SET, .dstSet = b.set, .dstBinding = 8, .descriptorCount = 1,
         .descriptorType = VK_DESCRIPTOR_TYPE_COMBINED_IMAGE_SAMPLER, .pImageInfo = &secondInfo},
        {.sType = VK_STRUCTURE_TYPE_WRITE_DESCRIPTOR_SET, .dstSet = b.set, .dstBinding = 9, .descriptorCount = 1,
         .descriptorType = VK_DESCRIPTOR_TYPE_COMBINED_IMAGE_SAMPLER, .pImageInfo = &momentInfo},
    };
    vkUpdateDescriptorSets(device, 10, writes, 0, nullptr);
    return b;
}

void recordLitPass(VkCommandBuffer commands, const LitPipeline& pipeline, const LitBindings& bindings,
                   const LitTargets& targets, const DrawGeometry& geometry, const glm::vec3& background,
                   LitOutputs outputs) {
    const VkPipelineStageFlags2 colorStage = VK_PIPELINE_STAGE_2_COLOR_ATTACHMENT_OUTPUT_BIT;
    const VkPipelineStageFlags2 depthStages =
        VK_PIPELINE_STAGE_2_EARLY_FRAGMENT_TESTS_BIT | VK_PIPELINE_STAGE_2_LATE_FRAGMENT_TESTS_BIT;
    const Image* beautyImage = outputs == LitOutputs::kDisplay ? &targets.display : &targets.beauty;
    std::vector<const Image*> colorImages{beautyImage};
    if (outputs == LitOutputs::kAll) {
        colorImages.push_back(&targets.aovs);
        for (const Image& l : targets.lights) colorImages.push_back(&l);
    }
    // The previous frame's copy read them: the barrier orders this frame's writes after it.
    std::vector<ImageTransition> before;
    std::vector<VkRenderingAttachmentInfo> colors;
    for (const Image* image : colorImages) {
        before.push_back({image->image.get(), VK_IMAGE_ASPECT_COLOR_BIT, 1, VK_IMAGE_LAYOUT_UNDEFINED,
                          VK_IMAGE_LAYOUT_COLOR_ATTACHMENT_OPTIMAL,
                          targets.hostReadable ? VK_PIPELINE_STAGE_2_HOST_BIT : VK_PIPELINE_STAGE_2_COPY_BIT,
                          VK_ACCESS_2_NONE, colorStage, VK_ACCESS_2_COLOR_ATTACHMENT_WRITE_BIT});
        const bool isBeauty = image == beautyImage;  // (the sRGB target encodes the linear clear color)
        colors.push_back({.sType = VK_STRUCTURE_TYPE_RENDERING_ATTACHMENT_INFO,
                          .imageView = image->view.get(),
                          .imageLayout = VK_IMAGE_LAYOUT_COLOR_ATTACHMENT_OPTIMAL,
                          .loadOp = VK_ATTACHMENT_LOAD_OP_CLEAR,
                          .storeOp = VK_ATTACHMENT_STORE_OP_STORE,
                          .clearValue = {.color = {.float32 = {isBeauty ? background.r : 0.0f,
                                                               isBeauty ? background.g : 0.0f,
                                                               isBeauty ? background.b : 0.0f, 0.0f}}}});
    }
    before.push_back({targets.depth.image.get(), VK_IMAGE_ASPECT_DEPTH_BIT, 1, VK_IMAGE_LAYOUT_UNDEFINED,
                      VK_IMAGE_LAYOUT_DEPTH_ATTACHMENT_OPTIMAL, depthStages,
                      VK_ACCESS_2_DEPTH_STENCIL_ATTACHMENT_WRITE_BIT, depthStages,
                      VK_ACCESS_2_DEPTH_STENCIL_ATTACHMENT_READ_BIT | VK_ACCESS_2_DEPTH_STENCIL_ATTACHMENT_WRITE_BIT});
    transition(commands, before);
    const VkRenderingAttachmentInfo depth{
        .sType = VK_STRUCTURE_TYPE_RENDERING_ATTACHMENT_INFO,
        .imageView = targets.depth.view.get(),
        .imageLayout = VK_IMAGE_LAYOUT_DEPTH_ATTACHMENT_OPTIMAL,
        .loadOp = VK_ATTACHMENT_LOAD_OP_CLEAR,
        .storeOp = VK_ATTACHMENT_STORE_OP_DONT_CARE,
        .clearValue = {.depthStencil = {0.0f, 0}},  // reversed Z: 0 is the far plane
    };
    const VkRenderingInfo rendering{
        .sType = VK_STRUCTURE_TYPE_RENDERING_INFO,
        .renderArea = {{0, 0}, {targets.width, targets.height}},
        .layerCount = 1,
        .colorAttachmentCount = std::uint32_t(colors.size()),
        .pColorAttachments = colors.data(),
        .pDepthAttachment = &depth,
    };
    vkCmdBeginRendering(commands, &rendering);
    if (geometry.indexCount > 0) {
        vkCmdBindPipeline(commands, VK_PIPELINE_BIND_POINT_GRAPHICS, pipeline.pipeline.get());
        setViewport(commands, targets.width, targets.height);
        vkCmdBindDescriptorSets(commands, VK_PIPELINE_BIND_POINT_GRAPHICS, pipeline.layout.get(), 0, 1,
                                &bindings.set, 0, nullptr);
        const VkDeviceSize offset = 0;
        vkCmdBindVertexBuffers(commands, 0, 1, &geometry.vertices, &offset);
        if (pipeline.alpha) {
            vkCmdBindDescriptorSets(commands, VK_PIPELINE_BIND_POINT_GRAPHICS, pipeline.layout.get(), 1, 1,
                                    &geometry.alphaSet, 0, nullptr);
            vkCmdBindVertexBuffers(commands, 1, 1, &geometry.uvs, &offset);
        }
        vkCmdBindIndexBuffer(commands, geometry.indices, 0, VK_INDEX_TYPE_UINT32);
        vkCmdDrawIndexed(commands, geometry.indexCount, 1, 0, 0, 0);
    }
    vkCmdEndRendering(commands);
    std::vector<ImageTransition> after;
    for (const Image* image : colorImages)
        // Host access to a linear image needs GENERAL (Vulkan spec); the display target is
        // host-readable whenever it exists.
        if (targets.hostReadable)
            after.push_back({image->image.get(), VK_IMAGE_ASPECT_COLOR_BIT, 1,
                             VK_IMAGE_LAYOUT_COLOR_ATTACHMENT_OPTIMAL, VK_IMAGE_LAYOUT_GENERAL, colorStage,
                             VK_ACCESS_2_COLOR_ATTACHMENT_WRITE_BIT, VK_PIPELINE_STAGE_2_HOST_BIT,
                             VK_ACCESS_2_HOST_READ_BIT});
        else
            after.push_back({image->image.get(), VK_IMAGE_ASPECT_COLOR_BIT, 1,
                             VK_IMAGE_LAYOUT_COLOR_ATTACHMENT_OPTIMAL, VK_IMAGE_LAYOUT_TRANSFER_SRC_OPTIMAL,
                             colorStage, VK_ACCESS_2_COLOR_ATTACHMENT_WRITE_BIT, VK_PIPELINE_STAGE_2_COPY_BIT,
                             VK_ACCESS_2_TRANSFER_READ_BIT});
    transition(commands, after);
}

Readback createReadback(const Context& ctx, const LitTargets& targets) {
    const VkDeviceSize bytes = VkDeviceSize(targets.width) * targets.height * 4 * sizeof(float);
    Readback r;
    r.beauty = createReadbackBuffer(ctx, bytes);
    r.aovs = createReadbackBuffer(ctx, bytes);
    for (std::size_t i = 0; i < targets.lights.size(); ++i) r.lights.push_back(createReadbackBuffer(ctx, bytes));
    return r;
}

void recordReadback(VkCommandBuffer commands, const LitTargets& targets, const Readback& readback,
                    const ReadbackSelection& selection) {
    const VkBufferImageCopy region{
        .imageSubresource = {.aspectMask = VK_IMAGE_ASPECT_COLOR_BIT, .mipLevel = 0, .baseArrayLayer = 0,
                             .layerCount = 1},
        .imageExtent = {targets.width, targets.height, 1},
    };
    if (selection.beauty)
        vkCmdCopyImageToBuffer(commands, targets.beauty.image.get(), VK_IMAGE_LAYOUT_TRANSFER_SRC_OPTIMAL,
                               readback.beauty.buffer.get(), 1, &region);
    if (selection.aovs)
        vkCmdCopyImageToBuffer(commands, targets.aovs.image.get(), VK_IMAGE_LAYOUT_TRANSFER_SRC_OPTIMAL,
                               readback.aovs.buffer.get(), 1, &region);
    if (selection.lights)
        for (std::size_t i = 0; i < targets.lights.size(); ++i)
            vkCmdCopyImageToBuffer(commands, targets.lights[i].image.get(), VK_IMAGE_LAYOUT_TRANSFER_SRC_OPTIMAL,
                                   readback.lights[i].buffer.get(), 1, &region);
    transferToHostBarrier(commands);
}

}  // namespace shadowlab::raster
