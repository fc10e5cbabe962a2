// raster/shadow_pass.cpp: the depth-only pass from the lights, and with semi-transparent casters
// the two transmittance passes after it.
#include "raster/shadow_pass.h"

#include <algorithm>
#include <cmath>
#include <cstring>

#include "raster/pipeline.h"
#include "raster/tolerances.h"
#include "raster/vulkan_error.h"
#include "shaders/interface.h"
#include "shaders/spirv.h"

namespace shadowlab::raster {

ShadowPipeline createShadowPipeline(const Context& ctx, bool blockerIds, bool hardwareBias,
                                    VkDescriptorSetLayout alphaSetLayout) {
    const bool alpha = alphaSetLayout != VK_NULL_HANDLE;
    requireFormat(ctx, kShadowMapFormat,
                  VK_FORMAT_FEATURE_DEPTH_STENCIL_ATTACHMENT_BIT | VK_FORMAT_FEATURE_SAMPLED_IMAGE_BIT,
                  "the shadow map");
    requireFormat(ctx, kBlockerIdFormat, VK_FORMAT_FEATURE_COLOR_ATTACHMENT_BIT | VK_FORMAT_FEATURE_SAMPLED_IMAGE_BIT,
                  "the blocker-id map");
    const VkPushConstantRange push{
        .stageFlags = VK_SHADER_STAGE_VERTEX_BIT, .offset = 0, .size = sizeof(shaders::ShadowPush)};
    const VkPipelineLayoutCreateInfo layoutInfo{
        .sType = VK_STRUCTURE_TYPE_PIPELINE_LAYOUT_CREATE_INFO,
        .setLayoutCount = alpha ? 1u : 0u,
        .pSetLayouts = alpha ? &alphaSetLayout : nullptr,
        .pushConstantRangeCount = 1,
        .pPushConstantRanges = &push,
    };
    ShadowPipeline p;
    p.alpha = alpha;
    VkPipelineLayout layout = VK_NULL_HANDLE;
    VK_CHECK(vkCreatePipelineLayout(ctx.device.get(), &layoutInfo, nullptr, &layout));
    p.layout = PipelineLayoutHandle(ctx.device.get(), layout);
    p.pipeline = createGraphicsPipeline(
        ctx, PipelineDesc{
                 .vertexShader = alpha ? shaders::shadowVertAlphaSpirv() : shaders::shadowVertSpirv(),
                 .fragmentShader =
                     alpha ? (blockerIds ? shaders::shadowFragAlphaSpirv() : shaders::shadowFragAlphaDepthSpirv())
                     : blockerIds ? shaders::shadowFragSpirv()
                                  : std::span<const std::uint32_t>(),
                 .layout = layout,
                 .usesNormal = false,
                 .usesUv = alpha,
                 .colorFormats = blockerIds ? std::vector<VkFormat>{kBlockerIdFormat} : std::vector<VkFormat>{},
                 .depthFormat = kShadowMapFormat,
                 .depthCompare = VK_COMPARE_OP_LESS,
                 .dynamicDepthBias = hardwareBias,
             });
    p.hardwareBias = hardwareBias;
    return p;
}

ShadowMaps createShadowMaps(const Context& ctx, std::uint32_t size, std::uint32_t layers) {
    if (size > ctx.properties.limits.maxImageDimension2D)
        throw RasterError("shadow map size " + std::to_string(size) + " exceeds the device's limit of " +
                          std::to_string(ctx.properties.limits.maxImageDimension2D) + " (" + ctx.deviceReport.name +
                          ")");
    // D32 depth and R32 ids per texel and layer.
    requireDeviceMemory(
        ctx, VkDeviceSize(size) * size * layers * 8,
        std::to_string(layers) + " shadow map(s) of " + std::to_string(size) + "x" + std::to_string(size));
    ShadowMaps m;
    m.size = size;
    m.layers = layers;
    m.depth = createImage(
        ctx, kShadowMapFormat, size, size, layers,
        VK_IMAGE_USAGE_DEPTH_STENCIL_ATTACHMENT_BIT | VK_IMAGE_USAGE_SAMPLED_BIT | VK_IMAGE_USAGE_TRANSFER_SRC_BIT,
        VK_IMAGE_ASPECT_DEPTH_BIT, VK_IMAGE_VIEW_TYPE_2D_ARRAY);
    m.ids =
        createImage(ctx, kBlockerIdFormat, size, size, layers,
                    VK_IMAGE_USAGE_COLOR_ATTACHMENT_BIT | VK_IMAGE_USAGE_SAMPLED_BIT | VK_IMAGE_USAGE_TRANSFER_SRC_BIT,
                    VK_IMAGE_ASPECT_COLOR_BIT, VK_IMAGE_VIEW_TYPE_2D_ARRAY);
    for (std::uint32_t i = 0; i < layers; ++i) {
        m.layerViews.push_back(createView(ctx, m.depth.image.get(), kShadowMapFormat, VK_IMAGE_ASPECT_DEPTH_BIT,
                                          VK_IMAGE_VIEW_TYPE_2D, i, 1));
        m.idLayerViews.push_back(createView(ctx, m.ids.image.get(), kBlockerIdFormat, VK_IMAGE_ASPECT_COLOR_BIT,
                                            VK_IMAGE_VIEW_TYPE_2D, i, 1));
    }
    return m;
}

TransmittanceMaps createTransmittanceMaps(const Context& ctx, std::uint32_t size, std::uint32_t layers) {
    requireFormat(ctx, kTransmittanceFormat,
                  VK_FORMAT_FEATURE_COLOR_ATTACHMENT_BIT | VK_FORMAT_FEATURE_COLOR_ATTACHMENT_BLEND_BIT |
                      VK_FORMAT_FEATURE_SAMPLED_IMAGE_BIT,
                  "the transmittance map");
    // Four R32F arrays: T_all, D1, T_rest, D2.
    requireDeviceMemory(
        ctx, VkDeviceSize(size) * size * layers * 16,
        std::to_string(layers) + " transmittance map(s) of " + std::to_string(size) + "x" + std::to_string(size));
    TransmittanceMaps m;
    m.size = size;
    m.layers = layers;
    const VkImageUsageFlags usage =
        VK_IMAGE_USAGE_COLOR_ATTACHMENT_BIT | VK_IMAGE_USAGE_SAMPLED_BIT | VK_IMAGE_USAGE_TRANSFER_SRC_BIT;
    m.transmittance = createImage(ctx, kTransmittanceFormat, size, size, layers, usage, VK_IMAGE_ASPECT_COLOR_BIT,
                                  VK_IMAGE_VIEW_TYPE_2D_ARRAY);
    m.nearDepth = createImage(ctx, kTransmittanceFormat, size, size, layers, usage, VK_IMAGE_ASPECT_COLOR_BIT,
                              VK_IMAGE_VIEW_TYPE_2D_ARRAY);
    m.restTransmittance = createImage(ctx, kTransmittanceFormat, size, size, layers, usage, VK_IMAGE_ASPECT_COLOR_BIT,
                                      VK_IMAGE_VIEW_TYPE_2D_ARRAY);
    m.secondDepth = createImage(ctx, kTransmittanceFormat, size, size, layers, usage, VK_IMAGE_ASPECT_COLOR_BIT,
                                VK_IMAGE_VIEW_TYPE_2D_ARRAY);
    for (std::uint32_t i = 0; i < layers; ++i) {
        auto layerView = [&](const Image& image) {
            return createView(ctx, image.image.get(), kTransmittanceFormat, VK_IMAGE_ASPECT_COLOR_BIT,
                              VK_IMAGE_VIEW_TYPE_2D, i, 1);
        };
        m.transmittanceLayerViews.push_back(layerView(m.transmittance));
        m.nearDepthLayerViews.push_back(layerView(m.nearDepth));
        m.restTransmittanceLayerViews.push_back(layerView(m.restTransmittance));
        m.secondDepthLayerViews.push_back(layerView(m.secondDepth));
    }
    return m;
}

namespace {

// Both transmittance passes: the semi-transparent casters' triangles depth-tested against the
// opaque map (not written), into the two R32F targets, blended as transmit.frag says.
PipelineHandle createTransmitPipeline(const Context& ctx, VkPipelineLayout layout,
                                      std::span<const std::uint32_t> fragmentShader, bool alpha) {
    return createGraphicsPipeline(
        ctx, PipelineDesc{
                 .vertexShader = alpha ? shaders::transmitVertAlphaSpirv() : shaders::transmitVertSpirv(),
                 .fragmentShader = fragmentShader,
                 .layout = layout,
                 .usesNormal = true,
                 .usesObjectId = alpha,
                 .usesUv = alpha,
                 .colorFormats = {kTransmittanceFormat, kTransmittanceFormat},
                 .depthFormat = kShadowMapFormat,
                 .depthCompare = VK_COMPARE_OP_LESS,
                 .depthWrite = false,
                 .transmittanceBlend = true,
             });
}

// Both passes' layout: the transmit push constants, and the set that holds D1 (the second pass).
PipelineLayoutHandle createTransmitLayout(const Context& ctx, VkDescriptorSetLayout set,
                                          VkDescriptorSetLayout alphaSet = VK_NULL_HANDLE) {
    if (!ctx.independentBlend)
        throw RasterError("semi-transparent casters need the independentBlend feature, which " + ctx.deviceReport.name +
                          " lacks (the transmittance map blends its two targets differently)");
    const VkPushConstantRange push{.stageFlags = VK_SHADER_STAGE_VERTEX_BIT,  // transmit.frag takes them flat
                                   .offset = 0,
                                   .size = sizeof(shaders::TransmitPush)};
    // The second pass's D1 set first, the alpha records' after it (shaders/alpha.glsl's set).
    std::vector<VkDescriptorSetLayout> sets;
    if (set != VK_NULL_HANDLE) sets.push_back(set);
    if (alphaSet != VK_NULL_HANDLE) sets.push_back(alphaSet);
    const VkPipelineLayoutCreateInfo layoutInfo{
        .sType = VK_STRUCTURE_TYPE_PIPELINE_LAYOUT_CREATE_INFO,
        .setLayoutCount = std::uint32_t(sets.size()),
        .pSetLayouts = sets.empty() ? nullptr : sets.data(),
        .pushConstantRangeCount = 1,
        .pPushConstantRanges = &push,
    };
    VkPipelineLayout layout = VK_NULL_HANDLE;
    VK_CHECK(vkCreatePipelineLayout(ctx.device.get(), &layoutInfo, nullptr, &layout));
    return PipelineLayoutHandle(ctx.device.get(), layout);
}

}  // namespace

ShadowPipeline createTransmittancePipeline(const Context& ctx, VkDescriptorSetLayout alphaSetLayout) {
    ShadowPipeline p;
    p.alpha = alphaSetLayout != VK_NULL_HANDLE;
    p.layout = createTransmitLayout(ctx, VK_NULL_HANDLE, alphaSetLayout);
    p.pipeline = createTransmitPipeline(
        ctx, p.layout.get(), p.alpha ? shaders::transmitFragAlphaSpirv() : shaders::transmitFragSpirv(), p.alpha);
    return p;
}

TransmittanceRestPipeline createTransmittanceRestPipeline(const Context& ctx, const TransmittanceMaps& maps,
                                                          VkDescriptorSetLayout alphaSetLayout) {
    VkDevice device = ctx.device.get();
    TransmittanceRestPipeline p;
    // transmit.frag reads D1 with texelFetch at its own texel: no filtering, no addressing.
    p.sampler = createNearestSampler(ctx);
    const VkSampler sampler = p.sampler.get();
    const VkDescriptorSetLayoutBinding binding{.binding = 0,
                                               .descriptorType = VK_DESCRIPTOR_TYPE_COMBINED_IMAGE_SAMPLER,
                                               .descriptorCount = 1,
                                               .stageFlags = VK_SHADER_STAGE_FRAGMENT_BIT};
    p.descriptors = createDescriptorSet(ctx, std::span(&binding, 1));
    const VkDescriptorSetLayout setLayout = p.descriptors.layout.get();
    const VkDescriptorImageInfo nearInfo{sampler, maps.nearDepth.view.get(), VK_IMAGE_LAYOUT_SHADER_READ_ONLY_OPTIMAL};
    const VkWriteDescriptorSet write{.sType = VK_STRUCTURE_TYPE_WRITE_DESCRIPTOR_SET,
                                     .dstSet = p.descriptors.set,
                                     .dstBinding = 0,
                                     .descriptorCount = 1,
                                     .descriptorType = VK_DESCRIPTOR_TYPE_COMBINED_IMAGE_SAMPLER,
                                     .pImageInfo = &nearInfo};
    vkUpdateDescriptorSets(device, 1, &write, 0, nullptr);
    p.alpha = alphaSetLayout != VK_NULL_HANDLE;
    p.layout = createTransmitLayout(ctx, setLayout, alphaSetLayout);
    p.pipeline = createTransmitPipeline(
        ctx, p.layout.get(), p.alpha ? shaders::transmitFragRestAlphaSpirv() : shaders::transmitFragRestSpirv(),
        p.alpha);
    return p;
}

TexelRect transmittanceWindow(const glm::mat4& lightMatrix, const std::vector<TransparentDraw>& casters,
                              std::uint32_t size) {
    double lo[2] = {1e300, 1e300}, hi[2] = {-1e300, -1e300};
    const glm::dmat4 m(lightMatrix);
    auto add = [&](const glm::dvec4& p) {
        // Framebuffer texels: (ndc + 1) / 2 · size on both axes (the depth pass's viewport).
        for (int a = 0; a < 2; ++a) {
            const double t = (p[a] / p.w + 1.0) * 0.5 * double(size);
            lo[a] = std::min(lo[a], t);
            hi[a] = std::max(hi[a], t);
        }
    };
    // What the rasterizer keeps of a convex polygon or polyhedron lies on the light's side of the
    // near plane (clip z >= 0, where a perspective map's w > 0 too): its projection lies in the hull
    // of the projected corners on that side and of the points where its edges cross the plane.
    bool unbounded = false;
    auto corner = [&](const glm::dvec4& p) {
        if (p.z < 0.0) return;
        if (!(p.w > 0.0))
            unbounded = true;  // (not a projection we know)
        else
            add(p);
    };
    auto edge = [&](const glm::dvec4& a, const glm::dvec4& b) {
        if ((a.z < 0.0) == (b.z < 0.0)) return;
        const glm::dvec4 p = a + (b - a) * (a.z / (a.z - b.z));
        if (!(p.w > 0.0))
            unbounded = true;
        else
            add(p);
    };
    for (const TransparentDraw& c : casters) {
        if (!c.triangles.empty()) {
            for (std::size_t t = 0; t + 2 < c.triangles.size(); t += 3) {
                glm::dvec4 v[3];
                for (int k = 0; k < 3; ++k) v[k] = m * glm::dvec4(glm::dvec3(c.triangles[t + std::size_t(k)]), 1.0);
                for (int k = 0; k < 3; ++k) {
                    corner(v[k]);
                    edge(v[k], v[(k + 1) % 3]);
                }
            }
            continue;
        }
        glm::dvec4 box[8];
        for (int k = 0; k < 8; ++k)
            box[k] = m * glm::dvec4(k & 1 ? c.boundsMax.x : c.boundsMin.x, k & 2 ? c.boundsMax.y : c.boundsMin.y,
                                    k & 4 ? c.boundsMax.z : c.boundsMin.z, 1.0);
        for (int k = 0; k < 8; ++k) {
            corner(box[k]);
            for (int bit = 1; bit < 8; bit <<= 1)  // the edges from corner k to a corner with one more bit
                if (!(k & bit)) edge(box[k], box[k | bit]);
        }
    }
    if (unbounded) return TexelRect{0, 0, size, size};
    if (lo[0] > hi[0]) return {};  // nothing on the light's side of the plane
    // A fragment of texel i has its center i + 0.5 inside the projection, so floor(lo) <= i <= floor(hi).
    std::uint32_t r[4];
    for (int a = 0; a < 2; ++a) {
        const double margin = double(kTransmittanceWindowMarginTexels);
        r[a] = std::uint32_t(std::clamp(std::floor(lo[a]) - margin, 0.0, double(size)));
        r[a + 2] = std::uint32_t(std::clamp(std::floor(hi[a]) + 1.0 + margin, 0.0, double(size)));
    }
    return TexelRect{r[0], r[1], r[2], r[3]};
}

namespace {

// One transmittance pass over every layer with a window: the product and nearest-depth targets (per
// layer views) cleared to 1 within the window and the semi-transparent casters drawn with
// `pipeline`, depth-tested against the layer's opaque depths; with `rest`, the second pass (its
// descriptor set bound).
void drawTransmittanceLayers(VkCommandBuffer commands, const TransmittancePass& pass, VkPipeline pipeline,
                             VkPipelineLayout layout, const TransmittanceRestPipeline* rest,
                             const std::vector<ImageViewHandle>& productViews,
                             const std::vector<ImageViewHandle>& depthViews, const ShadowMaps& shadow,
                             const DrawGeometry& geometry, const std::vector<glm::mat4>& lightMatrices) {
    const TransmittanceMaps& maps = *pass.maps;
    for (std::uint32_t layer = 0; layer < maps.layers; ++layer) {
        if (layer >= pass.windows.size() || pass.windows[layer].empty()) continue;  // nothing to draw, nothing read
        const TexelRect& window = pass.windows[layer];
        VkRenderingAttachmentInfo colors[2];
        for (int k = 0; k < 2; ++k)
            colors[k] = VkRenderingAttachmentInfo{
                .sType = VK_STRUCTURE_TYPE_RENDERING_ATTACHMENT_INFO,
                .imageView = (k == 0 ? productViews : depthViews)[layer].get(),
                .imageLayout = VK_IMAGE_LAYOUT_COLOR_ATTACHMENT_OPTIMAL,
                .loadOp = VK_ATTACHMENT_LOAD_OP_CLEAR,
                .storeOp = VK_ATTACHMENT_STORE_OP_STORE,
                .clearValue = {.color = {.float32 = {1.0f, 1.0f, 1.0f, 1.0f}}},  // all light, nothing near
            };
        const VkRenderingAttachmentInfo depth{
            .sType = VK_STRUCTURE_TYPE_RENDERING_ATTACHMENT_INFO,
            .imageView = shadow.layerViews[layer].get(),
            .imageLayout = VK_IMAGE_LAYOUT_DEPTH_ATTACHMENT_OPTIMAL,
            .loadOp = VK_ATTACHMENT_LOAD_OP_LOAD,
            .storeOp = VK_ATTACHMENT_STORE_OP_STORE,
        };
        const VkRenderingInfo rendering{
            .sType = VK_STRUCTURE_TYPE_RENDERING_INFO,
            .renderArea = {{std::int32_t(window.x0), std::int32_t(window.y0)},
                           {window.x1 - window.x0, window.y1 - window.y0}},
            .layerCount = 1,
            .colorAttachmentCount = 2,
            .pColorAttachments = colors,
            .pDepthAttachment = &depth,
        };
        vkCmdBeginRendering(commands, &rendering);
        if (layer < lightMatrices.size() && layer < pass.layerLights.size() && !geometry.transparent.empty()) {
            vkCmdBindPipeline(commands, VK_PIPELINE_BIND_POINT_GRAPHICS, pipeline);
            if (rest)
                vkCmdBindDescriptorSets(commands, VK_PIPELINE_BIND_POINT_GRAPHICS, layout, 0, 1, &rest->descriptors.set,
                                        0, nullptr);
            const bool alpha = rest ? rest->alpha : pass.pipeline->alpha;
            if (alpha)
                vkCmdBindDescriptorSets(commands, VK_PIPELINE_BIND_POINT_GRAPHICS, layout, rest ? 1 : 0, 1,
                                        &geometry.alphaSet, 0, nullptr);
            // The whole map's viewport (the depth pass's texels), cut to the window.
            setViewport(commands, maps.size, maps.size);
            const VkRect2D scissor{{std::int32_t(window.x0), std::int32_t(window.y0)},
                                   {window.x1 - window.x0, window.y1 - window.y0}};
            vkCmdSetScissor(commands, 0, 1, &scissor);
            const VkDeviceSize offset = 0;
            vkCmdBindVertexBuffers(commands, 0, 1, &geometry.vertices, &offset);
            if (alpha) vkCmdBindVertexBuffers(commands, 1, 1, &geometry.uvs, &offset);
            vkCmdBindIndexBuffer(commands, geometry.indices, 0, VK_INDEX_TYPE_UINT32);
            for (const TransparentDraw& object : geometry.transparent) {
                const shaders::TransmitPush push{.lightMatrix = lightMatrices[layer],
                                                 .light = pass.layerLights[layer],
                                                 .params = glm::vec4(object.transmittance, object.closed ? 1.0f : 0.0f,
                                                                     float(layer), kTransmittanceLayerSeparation)};
                vkCmdPushConstants(commands, layout, VK_SHADER_STAGE_VERTEX_BIT, 0, sizeof push, &push);
                vkCmdDrawIndexed(commands, object.indexCount, 1, object.firstIndex, 0, 0);
            }
        }
        vkCmdEndRendering(commands);
    }
}

// The transmittance pass of every layer drawn (the depth pass has run; the depth array is in
// DEPTH_ATTACHMENT_OPTIMAL), or, without a pipeline, only the layout change for the lit pass.
void recordTransmittance(VkCommandBuffer commands, const TransmittancePass& pass, const ShadowMaps& shadow,
                         const DrawGeometry& geometry, const std::vector<glm::mat4>& lightMatrices) {
    const TransmittanceMaps& maps = *pass.maps;
    const bool draw = pass.pipeline != nullptr && pass.rest != nullptr;
    // Source stage: the previous frame's lit pass (and second pass) sampled them.
    std::vector<ImageTransition> before;
    for (VkImage image : {maps.transmittance.image.get(), maps.nearDepth.image.get(),
                          maps.restTransmittance.image.get(), maps.secondDepth.image.get()})
        before.push_back(
            {image, VK_IMAGE_ASPECT_COLOR_BIT, maps.layers, VK_IMAGE_LAYOUT_UNDEFINED,
             draw ? VK_IMAGE_LAYOUT_COLOR_ATTACHMENT_OPTIMAL : VK_IMAGE_LAYOUT_SHADER_READ_ONLY_OPTIMAL,
             VK_PIPELINE_STAGE_2_FRAGMENT_SHADER_BIT, VK_ACCESS_2_NONE,
             draw ? VK_PIPELINE_STAGE_2_COLOR_ATTACHMENT_OUTPUT_BIT : VK_PIPELINE_STAGE_2_FRAGMENT_SHADER_BIT,
             draw ? VK_ACCESS_2_COLOR_ATTACHMENT_READ_BIT | VK_ACCESS_2_COLOR_ATTACHMENT_WRITE_BIT : VK_ACCESS_2_NONE});
    if (draw)  // the depth pass's writes before this pass's depth tests (same layout)
        before.push_back({shadow.depth.image.get(), VK_IMAGE_ASPECT_DEPTH_BIT, shadow.layers,
                          VK_IMAGE_LAYOUT_DEPTH_ATTACHMENT_OPTIMAL, VK_IMAGE_LAYOUT_DEPTH_ATTACHMENT_OPTIMAL,
                          VK_PIPELINE_STAGE_2_EARLY_FRAGMENT_TESTS_BIT | VK_PIPELINE_STAGE_2_LATE_FRAGMENT_TESTS_BIT,
                          VK_ACCESS_2_DEPTH_STENCIL_ATTACHMENT_WRITE_BIT,
                          VK_PIPELINE_STAGE_2_EARLY_FRAGMENT_TESTS_BIT | VK_PIPELINE_STAGE_2_LATE_FRAGMENT_TESTS_BIT,
                          VK_ACCESS_2_DEPTH_STENCIL_ATTACHMENT_READ_BIT});
    transition(commands, before);
    if (!draw) return;
    // 1. T_all and D1.
    drawTransmittanceLayers(commands, pass, pass.pipeline->pipeline.get(), pass.pipeline->layout.get(), nullptr,
                            maps.transmittanceLayerViews, maps.nearDepthLayerViews, shadow, geometry, lightMatrices);
    // 2. T_rest and D2, behind D1: the first pass's writes of D1 before the second's reads of it.
    const VkPipelineStageFlags2 readers = VK_PIPELINE_STAGE_2_FRAGMENT_SHADER_BIT | VK_PIPELINE_STAGE_2_COPY_BIT;
    const VkAccessFlags2 reads = VK_ACCESS_2_SHADER_SAMPLED_READ_BIT | VK_ACCESS_2_TRANSFER_READ_BIT;
    transition(commands, {{maps.nearDepth.image.get(), VK_IMAGE_ASPECT_COLOR_BIT, maps.layers,
                           VK_IMAGE_LAYOUT_COLOR_ATTACHMENT_OPTIMAL, VK_IMAGE_LAYOUT_SHADER_READ_ONLY_OPTIMAL,
                           VK_PIPELINE_STAGE_2_COLOR_ATTACHMENT_OUTPUT_BIT, VK_ACCESS_2_COLOR_ATTACHMENT_WRITE_BIT,
                           readers, reads}});
    drawTransmittanceLayers(commands, pass, pass.rest->pipeline.get(), pass.rest->layout.get(), pass.rest,
                            maps.restTransmittanceLayerViews, maps.secondDepthLayerViews, shadow, geometry,
                            lightMatrices);
    std::vector<ImageTransition> after;
    for (VkImage image :
         {maps.transmittance.image.get(), maps.restTransmittance.image.get(), maps.secondDepth.image.get()})
        after.push_back({image, VK_IMAGE_ASPECT_COLOR_BIT, maps.layers, VK_IMAGE_LAYOUT_COLOR_ATTACHMENT_OPTIMAL,
                         VK_IMAGE_LAYOUT_SHADER_READ_ONLY_OPTIMAL, VK_PIPELINE_STAGE_2_COLOR_ATTACHMENT_OUTPUT_BIT,
                         VK_ACCESS_2_COLOR_ATTACHMENT_WRITE_BIT, readers, reads});
    transition(commands, after);
}

}  // namespace

void recordShadowPass(VkCommandBuffer commands, const ShadowPipeline& pipeline, const ShadowMaps& maps,
                      const DrawGeometry& geometry, const std::vector<glm::mat4>& lightMatrices, bool blockerIds,
                      const TransmittancePass* transmittance, const std::vector<DepthBiasFactors>* layerBias,
                      const ShadowPipeline* alphaPipeline, const std::vector<TexelRect>* windows) {
    // Source stage: the previous frame's lit pass sampled both arrays (a reused Renderer).
    transition(commands,
               {{maps.depth.image.get(), VK_IMAGE_ASPECT_DEPTH_BIT, maps.layers, VK_IMAGE_LAYOUT_UNDEFINED,
                 VK_IMAGE_LAYOUT_DEPTH_ATTACHMENT_OPTIMAL, VK_PIPELINE_STAGE_2_FRAGMENT_SHADER_BIT, VK_ACCESS_2_NONE,
                 VK_PIPELINE_STAGE_2_EARLY_FRAGMENT_TESTS_BIT | VK_PIPELINE_STAGE_2_LATE_FRAGMENT_TESTS_BIT,
                 VK_ACCESS_2_DEPTH_STENCIL_ATTACHMENT_READ_BIT | VK_ACCESS_2_DEPTH_STENCIL_ATTACHMENT_WRITE_BIT},
                {maps.ids.image.get(), VK_IMAGE_ASPECT_COLOR_BIT, maps.layers, VK_IMAGE_LAYOUT_UNDEFINED,
                 blockerIds ? VK_IMAGE_LAYOUT_COLOR_ATTACHMENT_OPTIMAL : VK_IMAGE_LAYOUT_SHADER_READ_ONLY_OPTIMAL,
                 VK_PIPELINE_STAGE_2_FRAGMENT_SHADER_BIT, VK_ACCESS_2_NONE,
                 blockerIds ? VK_PIPELINE_STAGE_2_COLOR_ATTACHMENT_OUTPUT_BIT : VK_PIPELINE_STAGE_2_FRAGMENT_SHADER_BIT,
                 blockerIds ? VK_ACCESS_2_COLOR_ATTACHMENT_WRITE_BIT : VK_ACCESS_2_NONE}});
    for (std::uint32_t layer = 0; layer < maps.layers; ++layer) {
        const TexelRect window =
            windows && layer < windows->size() ? (*windows)[layer] : TexelRect{0, 0, maps.size, maps.size};
        if (window.empty()) continue;  // no receiver reads this layer: nothing to clear or draw
        const VkRect2D area{{std::int32_t(window.x0), std::int32_t(window.y0)},
                            {window.x1 - window.x0, window.y1 - window.y0}};
        const VkRenderingAttachmentInfo depth{
            .sType = VK_STRUCTURE_TYPE_RENDERING_ATTACHMENT_INFO,
            .imageView = maps.layerViews[layer].get(),
            .imageLayout = VK_IMAGE_LAYOUT_DEPTH_ATTACHMENT_OPTIMAL,
            .loadOp = VK_ATTACHMENT_LOAD_OP_CLEAR,
            .storeOp = VK_ATTACHMENT_STORE_OP_STORE,
            .clearValue = {.depthStencil = {1.0f, 0}},
        };
        const VkRenderingAttachmentInfo ids{
            .sType = VK_STRUCTURE_TYPE_RENDERING_ATTACHMENT_INFO,
            .imageView = maps.idLayerViews[layer].get(),
            .imageLayout = VK_IMAGE_LAYOUT_COLOR_ATTACHMENT_OPTIMAL,
            .loadOp = VK_ATTACHMENT_LOAD_OP_CLEAR,
            .storeOp = VK_ATTACHMENT_STORE_OP_STORE,
            .clearValue = {.color = {.uint32 = {0, 0, 0, 0}}},
        };
        const VkRenderingInfo rendering{
            .sType = VK_STRUCTURE_TYPE_RENDERING_INFO,
            .renderArea = area,
            .layerCount = 1,
            .colorAttachmentCount = blockerIds ? 1u : 0u,
            .pColorAttachments = blockerIds ? &ids : nullptr,
            .pDepthAttachment = &depth,
        };
        vkCmdBeginRendering(commands, &rendering);
        if (layer < lightMatrices.size() && geometry.depthPassIndexCount() > 0) {
            setViewport(commands, maps.size, maps.size);
            vkCmdSetScissor(commands, 0, 1, &area);
            const VkDeviceSize offset = 0;
            vkCmdBindVertexBuffers(commands, 0, 1, &geometry.vertices, &offset);
            if (geometry.uvs != VK_NULL_HANDLE) vkCmdBindVertexBuffers(commands, 1, 1, &geometry.uvs, &offset);
            vkCmdBindIndexBuffer(commands, geometry.indices, 0, VK_INDEX_TYPE_UINT32);
            const ShadowPipeline* bound = nullptr;
            auto use = [&](const ShadowPipeline& p) {
                if (bound == &p) return;
                bound = &p;
                vkCmdBindPipeline(commands, VK_PIPELINE_BIND_POINT_GRAPHICS, p.pipeline.get());
                if (p.hardwareBias) {
                    const DepthBiasFactors b =
                        layerBias && layer < layerBias->size() ? (*layerBias)[layer] : DepthBiasFactors{};
                    vkCmdSetDepthBias(commands, b.constant, 0.0f, b.slope);
                }
                const shaders::ShadowPush push{.lightMatrix = lightMatrices[layer]};
                vkCmdPushConstants(commands, p.layout.get(), VK_SHADER_STAGE_VERTEX_BIT, 0, sizeof push, &push);
                if (p.alpha)
                    vkCmdBindDescriptorSets(commands, VK_PIPELINE_BIND_POINT_GRAPHICS, p.layout.get(), 0, 1,
                                            &geometry.alphaSet, 0, nullptr);
            };
            if (layer < geometry.layerRanges.size()) {  // the casters left after culling
                for (const IndexRange& r : geometry.layerRanges[layer]) {
                    if (r.count == 0) continue;
                    use(r.alpha && alphaPipeline ? *alphaPipeline : pipeline);
                    vkCmdDrawIndexed(commands, r.count, 1, r.first, 0, 0);
                }
            } else {
                use(pipeline);
                vkCmdDrawIndexed(commands, geometry.depthPassIndexCount(), 1, 0, 0, 0);
            }
        }
        vkCmdEndRendering(commands);
    }
    if (transmittance) recordTransmittance(commands, *transmittance, maps, geometry, lightMatrices);
    std::vector<ImageTransition> after{
        {maps.depth.image.get(), VK_IMAGE_ASPECT_DEPTH_BIT, maps.layers, VK_IMAGE_LAYOUT_DEPTH_ATTACHMENT_OPTIMAL,
         VK_IMAGE_LAYOUT_SHADER_READ_ONLY_OPTIMAL,
         VK_PIPELINE_STAGE_2_EARLY_FRAGMENT_TESTS_BIT | VK_PIPELINE_STAGE_2_LATE_FRAGMENT_TESTS_BIT,
         VK_ACCESS_2_DEPTH_STENCIL_ATTACHMENT_WRITE_BIT,
         VK_PIPELINE_STAGE_2_FRAGMENT_SHADER_BIT | VK_PIPELINE_STAGE_2_COPY_BIT,
         VK_ACCESS_2_SHADER_SAMPLED_READ_BIT | VK_ACCESS_2_TRANSFER_READ_BIT}};
    if (blockerIds)
        after.push_back({maps.ids.image.get(), VK_IMAGE_ASPECT_COLOR_BIT, maps.layers,
                         VK_IMAGE_LAYOUT_COLOR_ATTACHMENT_OPTIMAL, VK_IMAGE_LAYOUT_SHADER_READ_ONLY_OPTIMAL,
                         VK_PIPELINE_STAGE_2_COLOR_ATTACHMENT_OUTPUT_BIT, VK_ACCESS_2_COLOR_ATTACHMENT_WRITE_BIT,
                         VK_PIPELINE_STAGE_2_FRAGMENT_SHADER_BIT | VK_PIPELINE_STAGE_2_COPY_BIT,
                         VK_ACCESS_2_SHADER_SAMPLED_READ_BIT | VK_ACCESS_2_TRANSFER_READ_BIT});
    transition(commands, after);
}

namespace {

// Copies one layer of `image` (in SHADER_READ_ONLY_OPTIMAL, left so) into host memory.
void readLayer(const Context& ctx, const ShadowMaps& maps, VkImage image, VkImageAspectFlags aspect,
               std::uint32_t layer, void* out) {
    if (layer >= maps.layers) throw std::out_of_range("shadow map has no layer " + std::to_string(layer));
    const VkDeviceSize bytes = VkDeviceSize(maps.size) * maps.size * 4;  // D32 and R32: 4 bytes a texel
    Buffer buffer = createReadbackBuffer(ctx, bytes);
    VkCommandBuffer commands = ctx.beginCommands();
    transition(commands, {{image, aspect, maps.layers, VK_IMAGE_LAYOUT_SHADER_READ_ONLY_OPTIMAL,
                           VK_IMAGE_LAYOUT_TRANSFER_SRC_OPTIMAL, VK_PIPELINE_STAGE_2_FRAGMENT_SHADER_BIT,
                           VK_ACCESS_2_NONE, VK_PIPELINE_STAGE_2_COPY_BIT, VK_ACCESS_2_TRANSFER_READ_BIT}});
    const VkBufferImageCopy region{
        .imageSubresource = {.aspectMask = aspect, .mipLevel = 0, .baseArrayLayer = layer, .layerCount = 1},
        .imageExtent = {maps.size, maps.size, 1},
    };
    vkCmdCopyImageToBuffer(commands, image, VK_IMAGE_LAYOUT_TRANSFER_SRC_OPTIMAL, buffer.buffer.get(), 1, &region);
    transition(commands, {{image, aspect, maps.layers, VK_IMAGE_LAYOUT_TRANSFER_SRC_OPTIMAL,
                           VK_IMAGE_LAYOUT_SHADER_READ_ONLY_OPTIMAL, VK_PIPELINE_STAGE_2_COPY_BIT, VK_ACCESS_2_NONE,
                           VK_PIPELINE_STAGE_2_FRAGMENT_SHADER_BIT, VK_ACCESS_2_SHADER_SAMPLED_READ_BIT}});
    transferToHostBarrier(commands);
    ctx.submitAndWait(commands);
    invalidate(ctx, buffer);
    std::memcpy(out, buffer.mapped, bytes);
}

}  // namespace

std::vector<float> readShadowMap(const Context& ctx, const ShadowMaps& maps, std::uint32_t layer) {
    std::vector<float> depths(std::size_t(maps.size) * maps.size);
    readLayer(ctx, maps, maps.depth.image.get(), VK_IMAGE_ASPECT_DEPTH_BIT, layer, depths.data());
    return depths;
}

std::vector<std::uint32_t> readBlockerIds(const Context& ctx, const ShadowMaps& maps, std::uint32_t layer) {
    std::vector<std::uint32_t> ids(std::size_t(maps.size) * maps.size);
    readLayer(ctx, maps, maps.ids.image.get(), VK_IMAGE_ASPECT_COLOR_BIT, layer, ids.data());
    return ids;
}

}  // namespace shadowlab::raster
