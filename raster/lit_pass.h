// raster/lit_pass.h: the camera pass: reversed-Z depth, shading with the shadow-map test per
// light (shaders/lit.frag), and the Frame's channels in one color target each, then the readback.
#pragma once

#include <array>
#include <cstdint>
#include <span>
#include <vector>

#include <glm/glm.hpp>

#include "raster/moment_maps.h"
#include "raster/shadow_pass.h"
#include "scene/settings.h"
#include "shaders/interface.h"

namespace shadowlab::raster {

// The lit pass's float color targets, in attachment order: one per Frame channel, each in the
// Frame's own layout (three floats of beauty, one float of each AOV per pixel). So on lavapipe the
// pass renders straight into a Frame's vectors (importHostImage, no readback at all), and
// elsewhere a readback is a copy of rows. The beauty-only variants attach the beauty alone.
enum class LitPlane : std::uint32_t { kBeauty, kVisibility, kObjectId, kNdotL, kDepth, kBlockerId };
inline constexpr std::uint32_t kLitPlanes = 6;
inline constexpr VkFormat kLitBeautyFormat = VK_FORMAT_R32G32B32_SFLOAT;
// Devices that cannot render into RGB32F (most GPUs) get RGBA32F, whose RGB the readback copies.
inline constexpr VkFormat kLitBeautyFallbackFormat = VK_FORMAT_R32G32B32A32_SFLOAT;
inline constexpr VkFormat kLitPlaneFormat = VK_FORMAT_R32_SFLOAT;  // visibility, object id, N·L, Z, blocker id
inline constexpr VkFormat kLitLightsFormat = VK_FORMAT_R32G32B32A32_SFLOAT;  // four lights' visibility
inline constexpr VkFormat kLitDepthFormat = VK_FORMAT_D32_SFLOAT;
// The beauty of frames that are only written as an 8-bit PNG (scene::kBeautyForDisplay): the
// device encodes sRGB on store, 4 bytes a pixel instead of 12 (docs/raster.md "Display target").
inline constexpr VkFormat kLitDisplayFormat = VK_FORMAT_R8G8B8A8_SRGB;

// Light 0's constants as lit.vert packs them into its flat outputs outLight[0..5] and outFrame[0..1]
// (the members of LightData that lit.frag reads for that light's kind, LitUniforms' forward, ambient
// and map size), in that order; then LitUniforms' cascadeStart and cascadeBlendBand and, for each of
// light 0's SHADOWLAB_MAX_CASCADES cascades, its toShadow's first three rows, sliceFar,
// texelWorldSize, depthPerWorld and depthBiasWorld (zeros where it has none), except that where
// light 0 is the only light and has one map (a directional light without cascades, or a spot),
// cascade 0's rows are its toShadow's first three rows, and a spot's last row takes the spare
// components of the light slots (lit.vert's outLight[3].w and [5].w, outFrame[1].y and .z) and its
// inner cone's cosine the last one (outFrame[1].w): the
// values a pipeline with LitVariant::specializedLightConstants bakes (shaders/lit_constants.glsl,
// constants 18..115).
// Then, for every light i of LitUniforms::lightCount (zeros for the rest), kPackedPerLight values
// at 98 + kPackedPerLight * i (constants 116 + ..): what lit.frag reads of it where every light is
// baked in (bakesEveryLight()), in fourteen slots of four: the direction toward a directional light
// or a spot or point light's position, layer; radiance, visibility weight; constant bias, slope
// bias, texel world size, depth per world unit; slope cap, normal offset, PCF size, kind; spot
// direction, cone cosine; map near, map far, light size, cascade count; toShadow's four columns;
// the point faces' tangent, the filter code, the spot's inner cone cosine, 0; the six point faces'
// near and far.
// Then each light's SHADOWLAB_MAX_CASCADES cascades, 16 values each as light 0's above (constants
// 564 + ..; zeros where it has none).
inline constexpr std::size_t kPackedPerLight = 56;
inline constexpr std::size_t kPackedLightConstants = 32 + 2 + 16 * SHADOWLAB_MAX_CASCADES +
                                                     kPackedPerLight * SHADOWLAB_MAX_LIGHTS +
                                                     16 * SHADOWLAB_MAX_CASCADES * SHADOWLAB_MAX_LIGHTS;
// everyLight false leaves the per-light values zero: where only light 0's are baked, a change of
// what those modules do not read (a point face's range, another light) must not take a Renderer off
// its baked pipelines, which Renderer::update decides by comparing the packed values.
std::array<float, kPackedLightConstants> packLightConstants(const shaders::LitUniforms& uniforms, bool everyLight);

// What is fixed when the lit pipeline is created (lit.frag's specialization constants and
// variant): lavapipe executes every branch of a shader, so run-time switches cost as much as
// the work they skip.
struct LitVariant {
    scene::ShadowFilter filter = scene::ShadowFilter::Pcf2x2;  // of every light
    bool blockerIds = true;                    // look up blocker ids (the blocker-id maps must be rendered)
    bool aovTarget = true;                     // false: the beauty target only (no AOVs, no per-light targets)
    bool displayTarget = false;                // the beauty target is kLitDisplayFormat (implies !aovTarget)
    bool normalOffset = true;                  // a normal offset is set (false: its code is left out)
    VkFormat beautyFormat = kLitBeautyFormat;  // the float beauty target's (LitTargets::beautyFormat)
    std::uint32_t lightTargets = 0;            // 0, or kLightTargets: per-light visibility targets
    std::uint32_t lightCount = 1;              // = LitUniforms::lightCount
    std::uint32_t lightKinds = 7;              // bit (1 << SHADOWLAB_LIGHT_*) for each kind in the scene
    std::uint32_t cascades = 1;                // cascades of the cascaded directional lights (1: none cascaded)
    bool transmittance = false;                // semi-transparent casters: read the transmittance maps
    bool receiverPlane = false;                // receiver-plane depth bias in every filter tap
    bool cascadeBlend = false;                 // blend bands before the cascade splits (LitUniforms::cascadeBlendBand)
    // Light 0's constants reach lit.frag as flat outputs of lit.vert instead of uniform reads
    // (shaders/lit_constants.glsl kVertexLightConstants); takes effect only where hasOneMapLight().
    bool vertexLightConstants = false;
    // The same values baked into the pipeline as specialization constants (shaders/lit_constants.glsl
    // kSpecializedLightConstants), `lightConstants` from packLightConstants(); lit.vert then writes
    // no flat outputs for them. Takes effect where bakesLightConstants(), and elsewhere bakes every
    // light's (bakesEveryLight()).
    bool specializedLightConstants = false;
    std::array<float, kPackedLightConstants> lightConstants{};
    // The filterable filters' parameters (specialization constants 11..16; unused by the others).
    scene::MomentSettings moments;
    // Where the variant allows (none or pcf2x2, one light, no semi-transparent casters, no receiver
    // plane, no per-light targets): the *_sun modules for a directional light, and with baked
    // constants the *_spot and *_point modules, with those constants fixed in the source and the
    // code they switch off left out, so that the pipeline is made several times faster (lavapipe
    // turns the whole module into NIR); false: the general modules (tests compare).
    bool oneLightModules = true;
};
// Whether the variant's one light has one map (lit_constants.glsl kOneMapLight, the same
// condition): one light, directional with one map or a spot, and no receiver-plane bias. lit.vert
// can pass its constants on flat, or the pipeline bake them in with its map matrix.
bool hasOneMapLight(const LitVariant& variant);
// Whether the variant can bake light 0's constants in: where hasOneMapLight(), or one
// cascaded directional light without the receiver-plane bias.
bool bakesLightConstants(const LitVariant& variant);
// Whether the variant bakes every light's constants in (lit_constants.glsl kEveryLightBaked): with a
// light, where bakesLightConstants() does not hold (several lights, a point light, the
// receiver-plane bias).
bool bakesEveryLight(const LitVariant& variant);
// Whether the variant has the constants SHADOWLAB_ONE_SUN fixes (lit_constants.glsl), with none or
// pcf2x2: the *_taps_sun modules (where LitVariant::oneLightModules asks for them).
bool usesSunModules(const LitVariant& variant);
// Whether the variant has the constants SHADOWLAB_ONE_SPOT or SHADOWLAB_ONE_POINT fixes, with none
// or pcf2x2 and its constants baked in: the *_taps_spot or *_taps_point module (where
// LitVariant::oneLightModules asks for them).
bool usesSpotOrPointModule(const LitVariant& variant);
// The SPIR-V of the lit pipeline's two stages for the variant (with the camera's alpha test or
// not). Each pair's vertex outputs are exactly its fragment inputs: llvmpipe stores every declared
// output per vertex and sets up every declared input per triangle, used or not, so the baked-constant
// and cascaded-sun pairs declare no flat light interface (docs/raster.md).
struct LitStages {
    std::span<const std::uint32_t> vertex;
    std::span<const std::uint32_t> fragment;
};
LitStages litStages(const LitVariant& variant, bool alpha);
// Per-light visibility targets: four lights in each RGBA32F target, SHADOWLAB_MAX_LIGHTS in all.
inline constexpr std::uint32_t kLightTargets = (SHADOWLAB_MAX_LIGHTS + 3) / 4;

struct LitPipeline {
    DescriptorSetLayoutHandle setLayout;
    PipelineLayoutHandle layout;
    PipelineHandle pipeline;
    // The SHADOWLAB_ALPHA shaders (the camera's alpha test): UVs at vertex binding 1,
    // DrawGeometry::alphaSet bound at set 1.
    bool alpha = false;
    // The float variants' background (shaders/background.frag): after the scene, a triangle over
    // the image at the far plane, depth test EQUAL, writes the background into the pixels nothing
    // covered, so the float targets need no clear (lavapipe clears texels wider than 4 bytes one
    // memcpy at a time). The display variant clears its 4-byte target instead (null here).
    PipelineLayoutHandle backgroundLayout;
    PipelineHandle background;
};
// alphaSetLayout (raster/alpha_casters.h; VK_NULL_HANDLE: none): the pipeline for MASK or BLEND
// surfaces whose alpha can cut, whose texels the camera looks through as camera rays do
// (docs/raster.md).
// background: the scene's background color (linear), for the background pipeline; withBackground
// false makes none (a pipeline that only draws triangles, e.g. the lift-free one).
LitPipeline createLitPipeline(const Context& ctx, const LitVariant& variant = {},
                              VkDescriptorSetLayout alphaSetLayout = VK_NULL_HANDLE,
                              const glm::vec3& background = glm::vec3(0.0f), bool withBackground = true);

// The float beauty target's format on this device: RGB32F where it can render into it (lavapipe),
// else RGBA32F. hostReadable: the target is a linear image read in place (LitTargets::hostReadable).
VkFormat litBeautyFormat(const Context& ctx, bool hostReadable);

struct LitTargets {
    // The Renderer's own targets for each plane (LitPlane order): rendered into when a frame
    // does not ask for that channel, or cannot render it into the Frame's memory.
    std::array<Image, kLitPlanes> planes;
    VkFormat beautyFormat = kLitBeautyFormat;  // or kLitBeautyFallbackFormat
    std::size_t beautyTexelBytes = 12;         // 12 or 16
    // Per plane, hostImageBytes() for an image over a Frame's vector (0: not possible here).
    std::array<std::size_t, kLitPlanes> frameImageBytes{};
    Image depth;  // reversed Z (cleared to 0 = far)
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
// The usage of every float color target (the Renderer's and those over a Frame).
inline constexpr VkImageUsageFlags kLitTargetUsage =
    VK_IMAGE_USAGE_COLOR_ATTACHMENT_BIT | VK_IMAGE_USAGE_TRANSFER_SRC_BIT;
// Bytes a texel of `plane` (the beauty: targets.beautyTexelBytes).
std::size_t litPlaneTexelBytes(const LitTargets& targets, LitPlane plane);

// The lit pass's descriptor set: uniforms, per-object albedo, shadow maps behind a NEAREST
// depth-compare sampler (lit.frag builds the filters from its taps), blocker ids, and the
// transmittance maps (placeholders in scenes without semi-transparent casters).
struct LitBindings {
    SamplerHandle sampler;        // depth compare, for the shadow maps
    SamplerHandle idSampler;      // plain NEAREST, for the blocker ids
    SamplerHandle depthSampler;   // plain NEAREST, the maps' raw depths (PCSS blocker search)
    SamplerHandle momentSampler;  // LINEAR, clamp to edge: the filterable maps' moments
    Buffer uniforms;
    Buffer transmitWindows;  // shaders::TransmitWindows
    Buffer albedos;
    DescriptorPoolHandle pool;
    VkDescriptorSet set = VK_NULL_HANDLE;  // freed with the pool
};
LitBindings createLitBindings(const Context& ctx, const LitPipeline& pipeline, const shaders::LitUniforms& uniforms,
                              const shaders::TransmitWindows& windows, const std::vector<glm::vec4>& albedos,
                              const ShadowMaps& maps, const TransmittanceMaps& transmittance,
                              const MomentMaps& moments);

// Which targets a frame renders into, as its pipeline was made: every target, the float beauty
// only (a pipeline without aovTarget), or the 8-bit display beauty only (displayTarget).
enum class LitOutputs { kAll, kBeauty, kDisplay };
// One frame's color attachments in the pipeline's order (the planes, then the light targets; or
// the display target): each an image and its view, the targets' own or one over the Frame.
struct LitAttachments {
    std::vector<VkImage> images;
    std::vector<VkImageView> views;
    void add(const Image& image) {
        images.push_back(image.image.get());
        views.push_back(image.view.get());
    }
};
// The ranges the lit pass draws (litRanges or, with byLift, litRangesByLift; their camera-visible
// parts when geometry.litCulled); null: one draw of every index.
const std::vector<IndexRange>* litDrawRanges(const DrawGeometry& geometry, bool byLift);
// The triangles those ranges hold.
std::size_t litTrianglesDrawn(const DrawGeometry& geometry, bool byLift);

// Records the pass; background pixels get `background` (rgb, visibility 0) and zero AOVs, from
// the background pipeline (float targets) or a clear (the display target). Leaves every color
// attachment in TRANSFER_SRC_OPTIMAL for recordReadback(), or, for host-readable targets, in
// GENERAL and visible to host reads once the submission has finished.
// alphaPipeline: the SHADOWLAB_ALPHA variant of `pipeline` for DrawGeometry::litRanges with
// IndexRange::alpha (null: `pipeline` draws them). liftFreePipeline: `pipeline` made without the
// slope bias's lift (LitVariant::normalOffset false), which then draws the lift-free ranges of
// DrawGeometry::litRangesByLift (null: litRanges, every one with the lift where `pipeline` has it).
// backgroundInAttachments (float targets only): every attachment is in GENERAL and already holds
// the background's values in every pixel (a new Frame's planes, per-light targets zeroed on the
// host); they are loaded and the background pipeline is not drawn.
void recordLitPass(VkCommandBuffer commands, const LitPipeline& pipeline, const LitBindings& bindings,
                   const LitTargets& targets, const LitAttachments& attachments, const DrawGeometry& geometry,
                   const glm::vec3& background, LitOutputs outputs = LitOutputs::kAll,
                   const LitPipeline* alphaPipeline = nullptr, const LitPipeline* liftFreePipeline = nullptr,
                   bool backgroundInAttachments = false);

struct Readback {
    std::array<Buffer, kLitPlanes> planes;
    std::vector<Buffer> lights;  // one per LitTargets::lights
};
Readback createReadback(const Context& ctx, const LitTargets& targets);
// Copies the targets that are asked for (the others are left alone, which saves their copy).
struct ReadbackSelection {
    std::array<bool, kLitPlanes> planes{};
    bool lights = false;
};
void recordReadback(VkCommandBuffer commands, const LitTargets& targets, const Readback& readback,
                    const ReadbackSelection& selection);

}  // namespace shadowlab::raster
