// raster/alpha_casters.cpp: alpha records and texels uploaded once per Renderer.
#include "raster/alpha_casters.h"

#include <map>

#include "raster/vulkan_error.h"

namespace shadowlab::raster {

namespace {

// shaders/alpha.glsl's AlphaRecord (std430: two 16-byte vectors).
struct AlphaRecord {
    glm::vec4 params{0.0f, 0.0f, 1.0f, 1.0f};  // mode, the camera's cutoff, factor, opacity
    glm::uvec4 texture{0u};                    // first texel, width, height, wrapS + 4·wrapT
};
static_assert(sizeof(AlphaRecord) == 32, "AlphaRecord must match shaders/alpha.glsl (std430)");

}  // namespace

AlphaCasters createAlphaCasters(const Context& ctx, const scene::Scene& scene, const SceneGeometry& geometry) {
    if (geometry.uvs.size() != geometry.vertices.size())
        throw RasterError("alpha-tested casters need the geometry tessellated with texture coordinates");
    VkDevice device = ctx.device.get();
    AlphaCasters a;
    std::vector<AlphaRecord> records(scene.objects.size() + 1);
    std::vector<float> texels;
    std::map<const scene::AlphaTexture*, std::uint32_t> first;
    for (std::size_t i = 0; i < scene.objects.size(); ++i) {
        const scene::Material& m = scene.materialOf(scene.objects[i]);
        AlphaRecord& r = records[i + 1];
        r.params = glm::vec4(float(int(m.alphaMode)), float(m.cameraCutoff()), float(m.alphaFactor), float(m.opacity));
        if (!m.alphaTextured()) continue;
        const scene::AlphaTexture& t = *m.alphaTexture;
        auto [it, added] = first.emplace(&t, std::uint32_t(texels.size()));
        if (added) texels.insert(texels.end(), t.alpha.begin(), t.alpha.end());
        r.texture = glm::uvec4(it->second, std::uint32_t(t.width), std::uint32_t(t.height),
                               std::uint32_t(t.wrapS) + 4u * std::uint32_t(t.wrapT));
    }
    a.textureTexels = texels.size();
    if (texels.empty()) texels.push_back(1.0f);  // a storage buffer may not be empty
    a.uvs = uploadBuffer(ctx, geometry.uvs.empty() ? std::vector<glm::vec2>{glm::vec2(0.0f)} : geometry.uvs,
                         VK_BUFFER_USAGE_VERTEX_BUFFER_BIT);
    a.records = uploadBuffer(ctx, records, VK_BUFFER_USAGE_STORAGE_BUFFER_BIT);
    a.texels = uploadBuffer(ctx, texels, VK_BUFFER_USAGE_STORAGE_BUFFER_BIT);

    const VkDescriptorSetLayoutBinding bindings[2] = {{.binding = 0,
                                                       .descriptorType = VK_DESCRIPTOR_TYPE_STORAGE_BUFFER,
                                                       .descriptorCount = 1,
                                                       .stageFlags = VK_SHADER_STAGE_FRAGMENT_BIT},
                                                      {.binding = 1,
                                                       .descriptorType = VK_DESCRIPTOR_TYPE_STORAGE_BUFFER,
                                                       .descriptorCount = 1,
                                                       .stageFlags = VK_SHADER_STAGE_FRAGMENT_BIT}};
    a.descriptors = createDescriptorSet(ctx, bindings);
    const VkDescriptorBufferInfo recordInfo{a.records.buffer.get(), 0, VK_WHOLE_SIZE};
    const VkDescriptorBufferInfo texelInfo{a.texels.buffer.get(), 0, VK_WHOLE_SIZE};
    const VkWriteDescriptorSet writes[2] = {{.sType = VK_STRUCTURE_TYPE_WRITE_DESCRIPTOR_SET,
                                             .dstSet = a.descriptors.set,
                                             .dstBinding = 0,
                                             .descriptorCount = 1,
                                             .descriptorType = VK_DESCRIPTOR_TYPE_STORAGE_BUFFER,
                                             .pBufferInfo = &recordInfo},
                                            {.sType = VK_STRUCTURE_TYPE_WRITE_DESCRIPTOR_SET,
                                             .dstSet = a.descriptors.set,
                                             .dstBinding = 1,
                                             .descriptorCount = 1,
                                             .descriptorType = VK_DESCRIPTOR_TYPE_STORAGE_BUFFER,
                                             .pBufferInfo = &texelInfo}};
    vkUpdateDescriptorSets(device, 2, writes, 0, nullptr);
    return a;
}

AlphaPlan planAlpha(const scene::Scene& scene, bool transmittance, bool idleTestsLeftOut) {
    AlphaPlan plan;
    plan.byMaterial.resize(scene.materials.size());
    std::vector<bool> used(scene.materials.size(), false);
    for (const scene::Object& o : scene.objects) used[std::size_t(o.material)] = true;
    bool anyDepth = false, anyCamera = false, transmittanceReads = false;
    for (std::size_t i = 0; i < scene.materials.size(); ++i) {
        if (!used[i]) continue;
        const scene::Material& m = scene.materials[i];
        // (MASK's camera cutoff is its alpha cutoff: one answer serves both passes.)
        const bool cuts = !idleTestsLeftOut || m.alphaCanFallBelow(m.cameraCutoff());
        AlphaTests& t = plan.byMaterial[i];
        t.depth = m.alphaMode == scene::AlphaMode::Mask && cuts;
        t.camera = m.alphaMode != scene::AlphaMode::Opaque && cuts;
        anyDepth |= t.depth;
        anyCamera |= t.camera;
        // The transmittance passes draw the semi-transparent casters: a MASK one's test where it can
        // cut, a textured BLEND one's 1 − opacity·alpha(uv) whatever its texels.
        if (!m.opaque()) transmittanceReads |= t.depth || (m.alphaMode == scene::AlphaMode::Blend && m.alphaTextured());
    }
    plan.transmittanceReads = transmittance && transmittanceReads;
    plan.data = anyDepth || anyCamera || plan.transmittanceReads;
    return plan;
}

}  // namespace shadowlab::raster
