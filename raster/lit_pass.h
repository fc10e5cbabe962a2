// raster/lit_pass.h: the camera pass: reversed-Z depth, shading with the shadow-map test per
// light (shaders/lit.frag), and the Frame's AOVs in two RGBA32F targets, then the readback.
#pragma once

#include <cstdint>
#include <vector>

#include <glm/glm.hpp>

#include "raster/moment_maps.h"
#include "raster/shadow_pass.h"
#include "scene/settings.h"
#include "shaders/interface.h"

namespace shadowlab::raster {

inline constexpr VkFormat kLitColorFormat = VK_FORMAT_R32G32B32A32_SFLOAT;
inline constexpr VkFormat kLitDepthFormat = VK_FORMAT_D32_SFLOAT;
// The beauty of frames that are only written as an 8-bit PNG (scene::kBeautyForDisplay): the
// device encodes sRGB on store, 4 bytes a pixel instead of 16 (docs/raster.md "Display target").
inline constexpr VkFormat kLitDisplayFormat = VK_FORMAT_R8G8B8A8_SRGB;

// What is fixed when the lit pipeline is created (lit.frag's specialization constants and
// variant): lavapipe executes every branch of a shader, so run-time switches cost as much as
// the work they skip.
struct LitVariant {
    scene::ShadowFilter filter = scene::ShadowFilter::Pcf2x2;  // of every light
    bool blockerIds = true;         // look up blocker ids (the blocker-id maps must be rendered)
    bool aovTarget = true;          // false: the beauty target only (no AOVs, no per-light targets)
    bool displayTarget = false;     // the beauty target is kLitDisplayFormat (implies !aovTarget)
    bool normalOffset = true;       // a normal offset is set (false: its code is left out)
    std::uint32_t lightTargets = 0;  // 0, or kLightTargets: per-light visibility targets
    std::uint32_t lightCount = 1;    // = LitUniforms::lightCount
    std::uint32_t lightKinds = 7;    // bit (1 << SHADOWLAB_LIGHT_*) for each kind in the scene
    std::uint32_t cascades = 1;      // cascades of the cascaded directional lights (1: none cascaded)
    bool transmittance = false;      // semi-transparent casters: read the transmittance maps
    bool receiverPlane = false;      // receiver-plane depth bias in every filter tap
    bool cascadeBlend = false;       // blend bands before the cascade splits (LitUniforms::cascadeBlendBand)
    // Light 0's constants reach lit.frag as flat outputs of lit.vert instead of uniform reads
    // (shaders/lit_constants.glsl kVertexLightConstants); takes effect only where
    // usesVertexLightCoordinates().
    bool vertexLightConstants = false;
    // The filterable filters' parameters (specialization constants 11..16; unused by the others).
    scene::MomentSettings moments;
};
// Whether lit.frag takes light 0's map coordinates from lit.vert (lit_constants.glsl
// kVertexLightCoordinates, the same condition): one light, directional with one map or a spot, and
// no receiver-plane bias.
bool usesVertexLightCoordinates(const LitVariant& variant);
// Per-light visibility targets: four lights in each RGBA32F target, SHADOWLAB_MAX_LIGHTS in all.
inline constexpr std::uint32_t kLightTargets = (SHADOWLAB_MAX_LIGHTS + 3) / 4;

struct LitPipeline {
    DescriptorSetLayoutHandle setLayout;
    PipelineLayoutHandle layout;
    PipelineHandle pipeline;
    // The SHADOWLAB_ALPHA shaders (the camera's alpha test): UVs at vertex binding 1,
    // DrawGeometry::alphaSet bound at set 1.
    bool alpha = false;
};
// alphaSetLayout (raster/alpha_casters.h; VK_NULL_HANDLE: none): scenes with MASK or BLEND
// materials, whose texels the camera looks through as camera rays do (docs/raster.md).
LitPipeline createLitPipeline(const Context& ctx, const LitVariant& variant = {},
                              VkDescriptorSetLayout alphaSetLayout = VK_NULL_HANDLE);

struct LitTargets {
    Image beauty;  // rgb: linear color, a: visibility
    Image aovs;    // x: object id, y: N·L, z: view depth, w: blocker id
    Image depth;   // reversed Z (cleared to 0 = far)
    // With lightTargets: light i's visibility in component i % 4 of lights[i / 4].
    std::vector<Image> lights;
    // The 8-bit sRGB beauty (kLitDisplayFormat), host-readable; only where the float targets are
    // read in place and the device can render to a linear image of that format (else null, and
    // display frames use the float beauty target).
    Image display;
    // Color targets are linear images in host-visible memory, read in place after the pass
    // (lavapipe); otherwise they are copied into readback buffers.
    bool hostReadable = false;
    std::uint32_t width = 0;
    std::uint32_t height = 0;
};
// readInPlace: make the color targets host-readable where the device allows it.
LitTargets createLitTargets(const Context& ctx, std::uint32_t width, std::uint32_t height,
                            std::uint32_t lightTargets = 0, bool readInPlace = true);

// The lit pass's descriptor set: uniforms, per-object albedo, shadow maps behind a NEAREST
// depth-compare sampler (lit.frag builds the filters from its taps), blocker ids, and the
// transmittance maps (placeholders in scenes without semi-transparent casters).
struct LitBindings {
    SamplerHandle sampler;    // depth compare, for the shadow maps
    SamplerHandle idSampler;  // plain NEAREST, for the blocker ids
    SamplerHandle depthSampler;  // plain NEAREST, the maps' raw depths (PCSS blocker search)
    SamplerHandle momentSampler;  // LINEAR, clamp to edge: the filterable maps' moments
    Buffer uniforms;
    Buffer albedos;
    DescriptorPoolHandle pool;
    VkDescriptorSet set = VK_NULL_HANDLE;  // freed with the pool
};
LitBindings createLitBindings(const Context& ctx, const LitPipeline& pipeline, const shaders::LitUniforms& uniforms,
                              const std::vector<glm::vec4>& albedos, const ShadowMaps& maps,
                              const TransmittanceMaps& transmittance, const MomentMaps& moments);

// Records the pass; background pixels keep `background` (rgb, visibility 0) and zero AOVs.
// Leaves every color target in TRANSFER_SRC_OPTIMAL for recordReadback(), or, for host-readable
// targets, in GENERAL and visible to host reads once the submission has finished.
// Which targets a frame renders into, as its pipeline was made: every target, the float beauty
// only (a pipeline without aovTarget), or the 8-bit display beauty only (displayTarget).
enum class LitOutputs { kAll, kBeauty, kDisplay };
void recordLitPass(VkCommandBuffer commands, const LitPipeline& pipeline, const LitBindings& bindings,
                   const LitTargets& targets, const DrawGeometry& geometry, const glm::vec3& background,
                   LitOutputs outputs = LitOutputs::kAll);

struct Readback {
    Buffer beauty;
    Buffer aovs;
    std::vector<Buffer> lights;  // one per LitTargets::lights
};
Readback createReadback(const Context& ctx, const LitTargets& targets);
// Copies the targets that are asked for (the others are left alone, which saves their copy).
struct ReadbackSelection {
    bool beauty = true;
    bool aovs = true;
    bool lights = true;
};
void recordReadback(VkCommandBuffer commands, const LitTargets& targets, const Readback& readback,
                    const ReadbackSelection& selection = {});

}  // namespace shadowlab::raster
