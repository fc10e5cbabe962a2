// bench/bare_renderer.cpp: the bare two-pass lavapipe renderer (see bare_renderer.h).
#include "bare_renderer.h"

#include <chrono>
#include <cstring>
#include <ctime>
#include <vector>

#include "bare_aov_frag.spv.h"
#include "bare_aov_vert.spv.h"
#include "bare_depth_vert.spv.h"
#include "bare_ids_frag.spv.h"
#include "bare_ids_vert.spv.h"
#include "bare_lit_frag.spv.h"
#include "bare_lit_vert.spv.h"
#include "raster/context.h"
#include "raster/geometry.h"
#include "raster/light_frustum.h"
#include "raster/lit_pass.h"
#include "raster/pipeline.h"
#include "raster/resources.h"
#include "raster/vulkan_error.h"
#include "scene/camera.h"

namespace shadowlab::bench {

using namespace raster;

namespace {

using Clock = std::chrono::steady_clock;
double msSince(Clock::time_point t) { return std::chrono::duration<double, std::milli>(Clock::now() - t).count(); }
double cpuMs() {
    timespec t{};
    clock_gettime(CLOCK_PROCESS_CPUTIME_ID, &t);
    return double(t.tv_sec) * 1e3 + double(t.tv_nsec) * 1e-6;
}

struct Uniforms {
    glm::mat4 viewProj;
    glm::mat4 toShadow;
    glm::vec4 toLight;  // xyz toward the light, w: bias in map depth
    glm::vec4 color;    // rgb: albedo * radiance, w: ambient
    glm::vec4 slope;    // x: slope bias per unit tan(theta), map depth units
};

}  // namespace

struct BareRenderer::Impl {
    Context ctx{ContextOptions{}};
    std::uint32_t width = 0, height = 0, mapSize = 0, indexCount = 0;
    bool hardwarePcf = false;
    bool aovs = false;
    bool floatTarget = false;  // BareTarget::Aovs or FloatBeauty: the float beauty, never cleared or read back
    VkFormat beautyFormat = VK_FORMAT_UNDEFINED;
    glm::mat4 lightMatrix{1.0f};
    double setupMs = 0;
    Buffer vertices, indices, uniforms;
    Image map, color, depth;
    Image ids;                    // BareTarget::Aovs: the blocker-id map
    std::array<Image, 5> planes;  // BareTarget::Aovs: visibility, object id, N·L, depth, blocker id
    SamplerHandle nearest;
    Buffer readback;
    SamplerHandle sampler;
    DescriptorSetLayoutHandle setLayout;
    PipelineLayoutHandle depthLayout, litLayout;
    PipelineHandle depthPipeline, litPipeline;
    DescriptorPoolHandle pool;
    VkDescriptorSet set = VK_NULL_HANDLE;
};

BareRenderer::BareRenderer(const scene::Scene& scene, const scene::RasterSettings& settings, BareTarget target)
    : impl_(std::make_unique<Impl>()) {
    const auto start = Clock::now();
    Impl& m = *impl_;
    const Context& ctx = m.ctx;
    VkDevice device = ctx.device.get();
    const scene::CameraBasis cam = scene::cameraBasis(scene.camera);
    m.width = std::uint32_t(scene.camera.width);
    m.height = std::uint32_t(scene.camera.height);
    m.mapSize = std::uint32_t(settings.shadowMapSize);
    m.aovs = target == BareTarget::Aovs;
    m.floatTarget = m.aovs || target == BareTarget::FloatBeauty;
    VkFormat colorFormat = target == BareTarget::Srgb ? VK_FORMAT_R8G8B8A8_SRGB : VK_FORMAT_R8G8B8A8_UNORM;
    if (m.floatTarget) {
        // The beauty format ours renders into (RGB32F where the device renders to it).
        VkFormatProperties rgb{};
        vkGetPhysicalDeviceFormatProperties(ctx.physicalDevice, kLitBeautyFormat, &rgb);
        colorFormat = (rgb.optimalTilingFeatures & VK_FORMAT_FEATURE_COLOR_ATTACHMENT_BIT) ? kLitBeautyFormat
                                                                                           : kLitBeautyFallbackFormat;
    }
    m.beautyFormat = colorFormat;

    const SceneGeometry geometry = tessellateScene(scene, cam.position);
    m.vertices = uploadBuffer(ctx, geometry.vertices, VK_BUFFER_USAGE_VERTEX_BUFFER_BIT);
    m.indices = uploadBuffer(ctx, geometry.indices, VK_BUFFER_USAGE_INDEX_BUFFER_BIT);
    m.indexCount = std::uint32_t(geometry.indices.size());

    scene::Vec3 direction(0, -1, 0);
    glm::vec3 radiance(1.0f);
    for (const scene::Light& l : scene.lights)
        if (l.type == scene::LightType::Directional) {
            direction = l.direction;
            radiance = glm::vec3(l.color * l.intensity);
            break;
        }
    const LightFrustum f = fitDirectionalLight(scene.bounds(), direction, int(m.mapSize));
    m.lightMatrix = glm::mat4(f.toClip(cam.position));
    Uniforms u{};
    u.viewProj = glm::mat4(scene::projectionMatrix(cam, scene.camera.near, scene.camera.far) *
                           scene::viewMatrix(cam, cam.position));
    u.toShadow = glm::mat4(f.toTexture(cam.position));
    u.toLight = glm::vec4(glm::vec3(-glm::normalize(direction)), float(settings.depthBias / f.depthRange()));
    u.color = glm::vec4(0.8f * radiance, float(scene.ambient));
    // Our pcf2x2's slope term: slopeBias texels, plus one texel for the 2x2 footprint.
    u.slope = glm::vec4(float(2.0 * settings.slopeBias * f.texelWorldSize() / f.depthRange()), 0, 0, 0);
    m.uniforms = uploadBuffer(ctx, &u, sizeof u, VK_BUFFER_USAGE_UNIFORM_BUFFER_BIT);

    VkFormatProperties props{};
    vkGetPhysicalDeviceFormatProperties(ctx.physicalDevice, VK_FORMAT_D32_SFLOAT, &props);
    m.hardwarePcf = (props.optimalTilingFeatures & VK_FORMAT_FEATURE_SAMPLED_IMAGE_FILTER_LINEAR_BIT) != 0;

    m.map = createImage(ctx, VK_FORMAT_D32_SFLOAT, m.mapSize, m.mapSize, 1,
                        VK_IMAGE_USAGE_DEPTH_STENCIL_ATTACHMENT_BIT | VK_IMAGE_USAGE_SAMPLED_BIT,
                        VK_IMAGE_ASPECT_DEPTH_BIT, VK_IMAGE_VIEW_TYPE_2D);
    m.color = createImage(ctx, colorFormat, m.width, m.height, 1,
                          VK_IMAGE_USAGE_COLOR_ATTACHMENT_BIT | VK_IMAGE_USAGE_TRANSFER_SRC_BIT,
                          VK_IMAGE_ASPECT_COLOR_BIT, VK_IMAGE_VIEW_TYPE_2D);
    m.depth = createImage(ctx, VK_FORMAT_D32_SFLOAT, m.width, m.height, 1, VK_IMAGE_USAGE_DEPTH_STENCIL_ATTACHMENT_BIT,
                          VK_IMAGE_ASPECT_DEPTH_BIT, VK_IMAGE_VIEW_TYPE_2D);
    m.readback = createReadbackBuffer(ctx, VkDeviceSize(m.width) * m.height * 4);
    if (m.aovs) {
        m.ids = createImage(ctx, VK_FORMAT_R32_UINT, m.mapSize, m.mapSize, 1,
                            VK_IMAGE_USAGE_COLOR_ATTACHMENT_BIT | VK_IMAGE_USAGE_SAMPLED_BIT, VK_IMAGE_ASPECT_COLOR_BIT,
                            VK_IMAGE_VIEW_TYPE_2D);
        for (Image& plane : m.planes)
            plane = createImage(ctx, kLitPlaneFormat, m.width, m.height, 1, VK_IMAGE_USAGE_COLOR_ATTACHMENT_BIT,
                                VK_IMAGE_ASPECT_COLOR_BIT, VK_IMAGE_VIEW_TYPE_2D);
        m.nearest = createNearestSampler(ctx);
    }

    const VkFilter filter = m.hardwarePcf ? VK_FILTER_LINEAR : VK_FILTER_NEAREST;
    const VkSamplerCreateInfo samplerInfo{
        .sType = VK_STRUCTURE_TYPE_SAMPLER_CREATE_INFO,
        .magFilter = filter,
        .minFilter = filter,
        .addressModeU = VK_SAMPLER_ADDRESS_MODE_CLAMP_TO_BORDER,
        .addressModeV = VK_SAMPLER_ADDRESS_MODE_CLAMP_TO_BORDER,
        .addressModeW = VK_SAMPLER_ADDRESS_MODE_CLAMP_TO_BORDER,
        .compareEnable = VK_TRUE,
        .compareOp = VK_COMPARE_OP_LESS_OR_EQUAL,
        .borderColor = VK_BORDER_COLOR_FLOAT_OPAQUE_WHITE,
    };
    VkSampler sampler = VK_NULL_HANDLE;
    VK_CHECK(vkCreateSampler(device, &samplerInfo, nullptr, &sampler));
    m.sampler = SamplerHandle(device, sampler);

    const VkDescriptorSetLayoutBinding bindings[] = {
        {.binding = 0,
         .descriptorType = VK_DESCRIPTOR_TYPE_UNIFORM_BUFFER,
         .descriptorCount = 1,
         .stageFlags = VK_SHADER_STAGE_VERTEX_BIT | VK_SHADER_STAGE_FRAGMENT_BIT},
        {.binding = 1,
         .descriptorType = VK_DESCRIPTOR_TYPE_COMBINED_IMAGE_SAMPLER,
         .descriptorCount = 1,
         .stageFlags = VK_SHADER_STAGE_FRAGMENT_BIT},
        {.binding = 2,
         .descriptorType = VK_DESCRIPTOR_TYPE_COMBINED_IMAGE_SAMPLER,
         .descriptorCount = 1,
         .stageFlags = VK_SHADER_STAGE_FRAGMENT_BIT},
    };
    const std::uint32_t bindingCount = m.aovs ? 3 : 2;
    const VkDescriptorSetLayoutCreateInfo setInfo{.sType = VK_STRUCTURE_TYPE_DESCRIPTOR_SET_LAYOUT_CREATE_INFO,
                                                  .bindingCount = bindingCount,
                                                  .pBindings = bindings};
    VkDescriptorSetLayout setLayout = VK_NULL_HANDLE;
    VK_CHECK(vkCreateDescriptorSetLayout(device, &setInfo, nullptr, &setLayout));
    m.setLayout = DescriptorSetLayoutHandle(device, setLayout);

    const VkPushConstantRange push{.stageFlags = VK_SHADER_STAGE_VERTEX_BIT, .offset = 0, .size = 64};
    const VkPipelineLayoutCreateInfo depthLayoutInfo{.sType = VK_STRUCTURE_TYPE_PIPELINE_LAYOUT_CREATE_INFO,
                                                     .pushConstantRangeCount = 1,
                                                     .pPushConstantRanges = &push};
    VkPipelineLayout layout = VK_NULL_HANDLE;
    VK_CHECK(vkCreatePipelineLayout(device, &depthLayoutInfo, nullptr, &layout));
    m.depthLayout = PipelineLayoutHandle(device, layout);
    const VkPipelineLayoutCreateInfo litLayoutInfo{
        .sType = VK_STRUCTURE_TYPE_PIPELINE_LAYOUT_CREATE_INFO, .setLayoutCount = 1, .pSetLayouts = &setLayout};
    VK_CHECK(vkCreatePipelineLayout(device, &litLayoutInfo, nullptr, &layout));
    m.litLayout = PipelineLayoutHandle(device, layout);

    if (m.aovs)
        m.depthPipeline = createGraphicsPipeline(ctx, PipelineDesc{.vertexShader = kBareIdsVertSpv,
                                                                   .fragmentShader = kBareIdsFragSpv,
                                                                   .layout = m.depthLayout.get(),
                                                                   .usesNormal = false,
                                                                   .colorFormats = {VK_FORMAT_R32_UINT},
                                                                   .depthFormat = VK_FORMAT_D32_SFLOAT,
                                                                   .depthCompare = VK_COMPARE_OP_LESS});
    else
        m.depthPipeline = createGraphicsPipeline(ctx, PipelineDesc{.vertexShader = kBareDepthVertSpv,
                                                                   .layout = m.depthLayout.get(),
                                                                   .usesNormal = false,
                                                                   .depthFormat = VK_FORMAT_D32_SFLOAT,
                                                                   .depthCompare = VK_COMPARE_OP_LESS});
    const VkBool32 hardware = m.hardwarePcf ? VK_TRUE : VK_FALSE;
    const VkSpecializationMapEntry entry{0, 0, sizeof(VkBool32)};
    const VkSpecializationInfo specialization{
        .mapEntryCount = 1, .pMapEntries = &entry, .dataSize = sizeof hardware, .pData = &hardware};
    std::vector<VkFormat> colorFormats{colorFormat};
    if (m.aovs) colorFormats.insert(colorFormats.end(), m.planes.size(), kLitPlaneFormat);
    m.litPipeline = createGraphicsPipeline(
        ctx, PipelineDesc{.vertexShader = m.aovs ? std::span<const std::uint32_t>(kBareAovVertSpv)
                                                 : std::span<const std::uint32_t>(kBareLitVertSpv),
                          .fragmentShader = m.aovs ? std::span<const std::uint32_t>(kBareAovFragSpv)
                                                   : std::span<const std::uint32_t>(kBareLitFragSpv),
                          .fragmentSpecialization = &specialization,
                          .layout = m.litLayout.get(),
                          .colorFormats = colorFormats,
                          .depthFormat = VK_FORMAT_D32_SFLOAT,
                          // scene::projectionMatrix is reversed Z
                          .depthCompare = VK_COMPARE_OP_GREATER});

    const VkDescriptorPoolSize sizes[] = {{VK_DESCRIPTOR_TYPE_UNIFORM_BUFFER, 1},
                                          {VK_DESCRIPTOR_TYPE_COMBINED_IMAGE_SAMPLER, 2}};
    const VkDescriptorPoolCreateInfo poolInfo{
        .sType = VK_STRUCTURE_TYPE_DESCRIPTOR_POOL_CREATE_INFO, .maxSets = 1, .poolSizeCount = 2, .pPoolSizes = sizes};
    VkDescriptorPool pool = VK_NULL_HANDLE;
    VK_CHECK(vkCreateDescriptorPool(device, &poolInfo, nullptr, &pool));
    m.pool = DescriptorPoolHandle(device, pool);
    const VkDescriptorSetAllocateInfo allocInfo{.sType = VK_STRUCTURE_TYPE_DESCRIPTOR_SET_ALLOCATE_INFO,
                                                .descriptorPool = pool,
                                                .descriptorSetCount = 1,
                                                .pSetLayouts = &setLayout};
    VK_CHECK(vkAllocateDescriptorSets(device, &allocInfo, &m.set));
    const VkDescriptorBufferInfo uniformInfo{m.uniforms.buffer.get(), 0, VK_WHOLE_SIZE};
    const VkDescriptorImageInfo imageInfo{sampler, m.map.view.get(), VK_IMAGE_LAYOUT_SHADER_READ_ONLY_OPTIMAL};
    const VkDescriptorImageInfo idsInfo{m.nearest.get(), m.aovs ? m.ids.view.get() : VK_NULL_HANDLE,
                                        VK_IMAGE_LAYOUT_SHADER_READ_ONLY_OPTIMAL};
    const VkWriteDescriptorSet writes[] = {
        {.sType = VK_STRUCTURE_TYPE_WRITE_DESCRIPTOR_SET,
         .dstSet = m.set,
         .dstBinding = 0,
         .descriptorCount = 1,
         .descriptorType = VK_DESCRIPTOR_TYPE_UNIFORM_BUFFER,
         .pBufferInfo = &uniformInfo},
        {.sType = VK_STRUCTURE_TYPE_WRITE_DESCRIPTOR_SET,
         .dstSet = m.set,
         .dstBinding = 1,
         .descriptorCount = 1,
         .descriptorType = VK_DESCRIPTOR_TYPE_COMBINED_IMAGE_SAMPLER,
         .pImageInfo = &imageInfo},
        {.sType = VK_STRUCTURE_TYPE_WRITE_DESCRIPTOR_SET,
         .dstSet = m.set,
         .dstBinding = 2,
         .descriptorCount = 1,
         .descriptorType = VK_DESCRIPTOR_TYPE_COMBINED_IMAGE_SAMPLER,
         .pImageInfo = &idsInfo},
    };
    vkUpdateDescriptorSets(device, bindingCount, writes, 0, nullptr);
    m.setupMs = msSince(start);
}

BareRenderer::~BareRenderer() = default;
double BareRenderer::setupMs() const { return impl_->setupMs; }
std::string BareRenderer::pcfKind() const {
    return impl_->hardwarePcf ? "hardware (LINEAR compare sampler on D32)" : "one compare gather + bilinear weights";
}

BareTimings BareRenderer::render(std::vector<std::uint8_t>& rgba) {
    Impl& m = *impl_;
    const Context& ctx = m.ctx;
    BareTimings t;
    const VkPipelineStageFlags2 depthStages =
        VK_PIPELINE_STAGE_2_EARLY_FRAGMENT_TESTS_BIT | VK_PIPELINE_STAGE_2_LATE_FRAGMENT_TESTS_BIT;
    const VkDeviceSize zero = 0;

    auto start = Clock::now();
    double cpuStart = cpuMs();
    VkCommandBuffer cb = ctx.beginCommands();
    transition(cb, {{m.map.image.get(), VK_IMAGE_ASPECT_DEPTH_BIT, 1, VK_IMAGE_LAYOUT_UNDEFINED,
                     VK_IMAGE_LAYOUT_DEPTH_ATTACHMENT_OPTIMAL, VK_PIPELINE_STAGE_2_FRAGMENT_SHADER_BIT,
                     VK_ACCESS_2_NONE, depthStages, VK_ACCESS_2_DEPTH_STENCIL_ATTACHMENT_WRITE_BIT}});
    if (m.aovs)
        transition(
            cb, {{m.ids.image.get(), VK_IMAGE_ASPECT_COLOR_BIT, 1, VK_IMAGE_LAYOUT_UNDEFINED,
                  VK_IMAGE_LAYOUT_COLOR_ATTACHMENT_OPTIMAL, VK_PIPELINE_STAGE_2_FRAGMENT_SHADER_BIT, VK_ACCESS_2_NONE,
                  VK_PIPELINE_STAGE_2_COLOR_ATTACHMENT_OUTPUT_BIT, VK_ACCESS_2_COLOR_ATTACHMENT_WRITE_BIT}});
    const VkRenderingAttachmentInfo idsAttachment{.sType = VK_STRUCTURE_TYPE_RENDERING_ATTACHMENT_INFO,
                                                  .imageView = m.aovs ? m.ids.view.get() : VK_NULL_HANDLE,
                                                  .imageLayout = VK_IMAGE_LAYOUT_COLOR_ATTACHMENT_OPTIMAL,
                                                  .loadOp = VK_ATTACHMENT_LOAD_OP_CLEAR,
                                                  .storeOp = VK_ATTACHMENT_STORE_OP_STORE,
                                                  .clearValue = {.color = {.uint32 = {0, 0, 0, 0}}}};
    const VkRenderingAttachmentInfo mapAttachment{.sType = VK_STRUCTURE_TYPE_RENDERING_ATTACHMENT_INFO,
                                                  .imageView = m.map.view.get(),
                                                  .imageLayout = VK_IMAGE_LAYOUT_DEPTH_ATTACHMENT_OPTIMAL,
                                                  .loadOp = VK_ATTACHMENT_LOAD_OP_CLEAR,
                                                  .storeOp = VK_ATTACHMENT_STORE_OP_STORE,
                                                  .clearValue = {.depthStencil = {1.0f, 0}}};
    const VkRenderingInfo mapRendering{.sType = VK_STRUCTURE_TYPE_RENDERING_INFO,
                                       .renderArea = {{0, 0}, {m.mapSize, m.mapSize}},
                                       .layerCount = 1,
                                       .colorAttachmentCount = m.aovs ? 1u : 0u,
                                       .pColorAttachments = &idsAttachment,
                                       .pDepthAttachment = &mapAttachment};
    vkCmdBeginRendering(cb, &mapRendering);
    vkCmdBindPipeline(cb, VK_PIPELINE_BIND_POINT_GRAPHICS, m.depthPipeline.get());
    setViewport(cb, m.mapSize, m.mapSize);
    vkCmdPushConstants(cb, m.depthLayout.get(), VK_SHADER_STAGE_VERTEX_BIT, 0, 64, &m.lightMatrix);
    VkBuffer vb = m.vertices.buffer.get();
    vkCmdBindVertexBuffers(cb, 0, 1, &vb, &zero);
    vkCmdBindIndexBuffer(cb, m.indices.buffer.get(), 0, VK_INDEX_TYPE_UINT32);
    vkCmdDrawIndexed(cb, m.indexCount, 1, 0, 0, 0);
    vkCmdEndRendering(cb);
    transition(cb,
               {{m.map.image.get(), VK_IMAGE_ASPECT_DEPTH_BIT, 1, VK_IMAGE_LAYOUT_DEPTH_ATTACHMENT_OPTIMAL,
                 VK_IMAGE_LAYOUT_SHADER_READ_ONLY_OPTIMAL, depthStages, VK_ACCESS_2_DEPTH_STENCIL_ATTACHMENT_WRITE_BIT,
                 VK_PIPELINE_STAGE_2_FRAGMENT_SHADER_BIT, VK_ACCESS_2_SHADER_SAMPLED_READ_BIT}});
    if (m.aovs)
        transition(cb, {{m.ids.image.get(), VK_IMAGE_ASPECT_COLOR_BIT, 1, VK_IMAGE_LAYOUT_COLOR_ATTACHMENT_OPTIMAL,
                         VK_IMAGE_LAYOUT_SHADER_READ_ONLY_OPTIMAL, VK_PIPELINE_STAGE_2_COLOR_ATTACHMENT_OUTPUT_BIT,
                         VK_ACCESS_2_COLOR_ATTACHMENT_WRITE_BIT, VK_PIPELINE_STAGE_2_FRAGMENT_SHADER_BIT,
                         VK_ACCESS_2_SHADER_SAMPLED_READ_BIT}});
    ctx.submitAndWait(cb);
    t.shadowPass = msSince(start);
    t.cpuShadowPass = cpuMs() - cpuStart;

    start = Clock::now();
    cpuStart = cpuMs();
    cb = ctx.beginCommands();
    transition(cb, {{m.color.image.get(), VK_IMAGE_ASPECT_COLOR_BIT, 1, VK_IMAGE_LAYOUT_UNDEFINED,
                     VK_IMAGE_LAYOUT_COLOR_ATTACHMENT_OPTIMAL, VK_PIPELINE_STAGE_2_COPY_BIT, VK_ACCESS_2_NONE,
                     VK_PIPELINE_STAGE_2_COLOR_ATTACHMENT_OUTPUT_BIT, VK_ACCESS_2_COLOR_ATTACHMENT_WRITE_BIT},
                    {m.depth.image.get(), VK_IMAGE_ASPECT_DEPTH_BIT, 1, VK_IMAGE_LAYOUT_UNDEFINED,
                     VK_IMAGE_LAYOUT_DEPTH_ATTACHMENT_OPTIMAL, depthStages,
                     VK_ACCESS_2_DEPTH_STENCIL_ATTACHMENT_WRITE_BIT, depthStages,
                     VK_ACCESS_2_DEPTH_STENCIL_ATTACHMENT_READ_BIT | VK_ACCESS_2_DEPTH_STENCIL_ATTACHMENT_WRITE_BIT}});
    // The float floors clear no color target (ours clears none of its float targets either: its
    // background pass writes them, which the floors leave out).
    std::vector<VkRenderingAttachmentInfo> colorAttachments{
        {.sType = VK_STRUCTURE_TYPE_RENDERING_ATTACHMENT_INFO,
         .imageView = m.color.view.get(),
         .imageLayout = VK_IMAGE_LAYOUT_COLOR_ATTACHMENT_OPTIMAL,
         .loadOp = m.floatTarget ? VK_ATTACHMENT_LOAD_OP_DONT_CARE : VK_ATTACHMENT_LOAD_OP_CLEAR,
         .storeOp = VK_ATTACHMENT_STORE_OP_STORE,
         .clearValue = {.color = {.float32 = {0, 0, 0, 1}}}}};
    if (m.aovs)
        for (const Image& plane : m.planes) {
            transition(cb, {{plane.image.get(), VK_IMAGE_ASPECT_COLOR_BIT, 1, VK_IMAGE_LAYOUT_UNDEFINED,
                             VK_IMAGE_LAYOUT_COLOR_ATTACHMENT_OPTIMAL, VK_PIPELINE_STAGE_2_COLOR_ATTACHMENT_OUTPUT_BIT,
                             VK_ACCESS_2_NONE, VK_PIPELINE_STAGE_2_COLOR_ATTACHMENT_OUTPUT_BIT,
                             VK_ACCESS_2_COLOR_ATTACHMENT_WRITE_BIT}});
            colorAttachments.push_back({.sType = VK_STRUCTURE_TYPE_RENDERING_ATTACHMENT_INFO,
                                        .imageView = plane.view.get(),
                                        .imageLayout = VK_IMAGE_LAYOUT_COLOR_ATTACHMENT_OPTIMAL,
                                        .loadOp = VK_ATTACHMENT_LOAD_OP_DONT_CARE,
                                        .storeOp = VK_ATTACHMENT_STORE_OP_STORE});
        }
    const VkRenderingAttachmentInfo depthAttachment{.sType = VK_STRUCTURE_TYPE_RENDERING_ATTACHMENT_INFO,
                                                    .imageView = m.depth.view.get(),
                                                    .imageLayout = VK_IMAGE_LAYOUT_DEPTH_ATTACHMENT_OPTIMAL,
                                                    .loadOp = VK_ATTACHMENT_LOAD_OP_CLEAR,
                                                    .storeOp = VK_ATTACHMENT_STORE_OP_DONT_CARE,
                                                    .clearValue = {.depthStencil = {0.0f, 0}}};
    const VkRenderingInfo litRendering{.sType = VK_STRUCTURE_TYPE_RENDERING_INFO,
                                       .renderArea = {{0, 0}, {m.width, m.height}},
                                       .layerCount = 1,
                                       .colorAttachmentCount = std::uint32_t(colorAttachments.size()),
                                       .pColorAttachments = colorAttachments.data(),
                                       .pDepthAttachment = &depthAttachment};
    vkCmdBeginRendering(cb, &litRendering);
    vkCmdBindPipeline(cb, VK_PIPELINE_BIND_POINT_GRAPHICS, m.litPipeline.get());
    setViewport(cb, m.width, m.height);
    vkCmdBindDescriptorSets(cb, VK_PIPELINE_BIND_POINT_GRAPHICS, m.litLayout.get(), 0, 1, &m.set, 0, nullptr);
    vkCmdBindVertexBuffers(cb, 0, 1, &vb, &zero);
    vkCmdBindIndexBuffer(cb, m.indices.buffer.get(), 0, VK_INDEX_TYPE_UINT32);
    vkCmdDrawIndexed(cb, m.indexCount, 1, 0, 0, 0);
    vkCmdEndRendering(cb);
    transition(cb,
               {{m.color.image.get(), VK_IMAGE_ASPECT_COLOR_BIT, 1, VK_IMAGE_LAYOUT_COLOR_ATTACHMENT_OPTIMAL,
                 VK_IMAGE_LAYOUT_TRANSFER_SRC_OPTIMAL, VK_PIPELINE_STAGE_2_COLOR_ATTACHMENT_OUTPUT_BIT,
                 VK_ACCESS_2_COLOR_ATTACHMENT_WRITE_BIT, VK_PIPELINE_STAGE_2_COPY_BIT, VK_ACCESS_2_TRANSFER_READ_BIT}});
    ctx.submitAndWait(cb);
    t.litPass = msSince(start);
    t.cpuLitPass = cpuMs() - cpuStart;
    if (m.floatTarget) return t;  // the floors' targets stay on the device (ours renders into the Frame)

    start = Clock::now();
    cb = ctx.beginCommands();
    const VkBufferImageCopy region{
        .imageSubresource = {.aspectMask = VK_IMAGE_ASPECT_COLOR_BIT, .layerCount = 1},
        .imageExtent = {m.width, m.height, 1},
    };
    vkCmdCopyImageToBuffer(cb, m.color.image.get(), VK_IMAGE_LAYOUT_TRANSFER_SRC_OPTIMAL, m.readback.buffer.get(), 1,
                           &region);
    transferToHostBarrier(cb);
    ctx.submitAndWait(cb);
    invalidate(ctx, m.readback);
    rgba.resize(std::size_t(m.width) * m.height * 4);
    std::memcpy(rgba.data(), m.readback.mapped, rgba.size());
    t.readback = msSince(start);
    return t;
}

}  // namespace shadowlab::bench
