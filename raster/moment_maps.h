// raster/moment_maps.h: the filterable shadow maps (vsm, evsm2, evsm4, esm, msm): after the depth
// pass, two compute passes turn each layer's depths into the technique's moments and blur them
// (of linear depth) with a separable box of MomentSettings::blurWidth texels; the lit pass samples the result with
// a linear filter (shaders/lit.frag momentVisibility). See docs/raster.md.
#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include "raster/context.h"
#include "raster/resources.h"
#include "raster/shadow_layers.h"
#include "raster/shadow_pass.h"
#include "scene/settings.h"

namespace shadowlab::raster {

// Every technique stores RGBA32F (the unused channels of vsm, evsm2 and esm included): one
// storage-image format for the one compute shader, 32-bit because EVSM's exponents (up to 42) and
// MSM's fourth power need it (16-bit floats hold e^11 at most and lose MSM's z⁴ to rounding), and
// lavapipe filters it linearly. Checked at run time (requireMomentFormat).
inline constexpr VkFormat kMomentFormat = VK_FORMAT_R32G32B32A32_SFLOAT;
inline constexpr std::uint64_t kMomentBytesPerTexel = 16;

// The moment images a render holds: the blurred moments (sampled by the lit pass), size x size x
// layers, and the intermediate after the x pass, one size x size layer that each layer's pair of
// passes reuses in turn (a layer's y pass reads it before the next layer's x pass writes it).
std::uint64_t momentBytes(std::uint64_t size, std::uint64_t layers);

struct MomentMaps {
    Image blurredX;  // moments averaged along x (pass 0), read by pass 1: one layer
    Image moments;   // the result, sampled by the lit pass (SHADER_READ_ONLY_OPTIMAL after the passes)
    std::uint32_t size = 0;
    std::uint32_t layers = 0;
};
// size 1, layers 1 for renders without a filterable map (keeps the lit pass's descriptor valid);
// cleared to 0 there and left in SHADER_READ_ONLY_OPTIMAL.
MomentMaps createMomentMaps(const Context& ctx, std::uint32_t size, std::uint32_t layers);

struct MomentPipeline {
    DescriptorSet descriptors;
    PipelineLayoutHandle layout;
    PipelineHandle pipeline;      // pass 0: the moments, blurred along x
    PipelineHandle blurPipeline;  // pass 1: blurred along y
    SamplerHandle depthSampler;   // NEAREST, for texelFetch of the depth array
    int radius = 0;               // the blur's, in texels (baked into both pipelines)
};
// The two passes for `filter` (a filterable one) with `settings`' blur width and exponents, baked
// into each pipeline. Throws RasterError naming kMomentFormat and the device when the format
// cannot be a storage image or be filtered linearly.
MomentPipeline createMomentPipeline(const Context& ctx, const ShadowMaps& maps, const MomentMaps& moments,
                                    scene::ShadowFilter filter, const scene::MomentSettings& settings);

// Records both of the pipeline's passes after the depth pass, layer by layer (the x pass, then the
// y pass, through the one intermediate layer): the depth array in
// SHADER_READ_ONLY_OPTIMAL (written by the depth pass) to moments in SHADER_READ_ONLY_OPTIMAL,
// ready for the lit pass's fragment shader. `layers` (the array's, in order) says which layers
// are perspective and their near and far: their moments are of linear depth
// (d − near)/(far − near), d along the layer's axis; orthographic layers' depths are linear
// already and kept as stored.
// `windows` (one per layer; null: whole layers) are the texels the lit pass's lookups read
// (layerLookupWindow): the y pass writes those alone, the x pass those widened by the blur radius
// along y, and it reads depths within a further radius along x: layerReadWindow, the texels the
// depth pass drew. Each texel written is the same as a whole layer's (the blur clamps to the map,
// not to the window), and a lookup reads no other.
void recordMomentPasses(VkCommandBuffer commands, const MomentPipeline& pipeline, const ShadowMaps& maps,
                        const MomentMaps& moments, const std::vector<ShadowLayer>& layers,
                        const std::vector<TexelRect>* windows = nullptr);

// For --explain and the Frame: the passes and memory the technique adds.
std::string describeMomentCost(scene::ShadowFilter filter, std::uint32_t size, std::uint32_t layers, int blurWidth);

}  // namespace shadowlab::raster
