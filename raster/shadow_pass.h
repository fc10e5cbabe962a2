// raster/shadow_pass.h: renders depth from each shadowed light into one layer of a D32_SFLOAT
// shadow-map array, and the id of the nearest object into a matching R32_UINT blocker-id
// array. Both faces cast: quads are two-sided, and culling one side would leak light through it.
#pragma once

#include <cstdint>
#include <vector>

#include <glm/glm.hpp>

#include "raster/pipeline.h"
#include "raster/resources.h"
#include "raster/shadow_layers.h"

namespace shadowlab::raster {

inline constexpr VkFormat kShadowMapFormat = VK_FORMAT_D32_SFLOAT;
inline constexpr VkFormat kBlockerIdFormat = VK_FORMAT_R32_UINT;

struct ShadowPipeline {
    PipelineLayoutHandle layout;
    PipelineHandle pipeline;
    bool hardwareBias = false;  // depth bias dynamic: set per layer before drawing
    // The SHADOWLAB_ALPHA shaders: UVs at vertex binding 1, DrawGeometry::alphaSet bound (set 0).
    bool alpha = false;
};
// Without blockerIds: depth only, no fragment shader (much cheaper on lavapipe). hardwareBias:
// depth bias on with dynamic factors (recordShadowPass sets each layer's). alphaSetLayout
// (AlphaCasters::descriptors): alpha-tested casters, whose MASK texels below the cutoff the
// fragment shader discards (then always with a fragment shader, also without blockerIds).
ShadowPipeline createShadowPipeline(const Context& ctx, bool blockerIds = true, bool hardwareBias = false,
                                    VkDescriptorSetLayout alphaSetLayout = VK_NULL_HANDLE);

// DepthBiasFactors, kShadowDepthUnitR: raster/shadow_layers.h.

struct ShadowMaps {
    Image depth;                              // size x size x layers; view: 2D array for sampling
    std::vector<ImageViewHandle> layerViews;  // one 2D view per layer, for rendering
    Image ids;                                // object id nearest the light per texel, 0 = none
    std::vector<ImageViewHandle> idLayerViews;
    std::uint32_t size = 0;
    std::uint32_t layers = 0;
};
ShadowMaps createShadowMaps(const Context& ctx, std::uint32_t size, std::uint32_t layers);

// One semi-transparent caster's triangles in the index buffer, for the transmittance pass.
struct TransparentDraw {
    std::uint32_t firstIndex = 0;
    std::uint32_t indexCount = 0;
    float transmittance = 1.0f;                  // 1 − opacity
    bool closed = true;                          // count only its surfaces facing the light (transmit.frag)
    glm::vec3 boundsMin{0.0f}, boundsMax{0.0f};  // its vertices' box (camera-relative, as uploaded)
    // Its triangles' corners, three a triangle, as uploaded (transmittanceWindow projects them);
    // empty for a caster of more than kTransmittanceWindowTriangles triangles (its box is used).
    std::vector<glm::vec3> triangles;
};

// TexelRect: raster/light_frustum.h.
// The window of a size² layer drawn with `lightMatrix` that holds every texel the semi-transparent
// casters can cover (the part of their triangles, or of the boxes of casters with too many to
// project each frame, on the light's side of the map's near plane, projected), with
// kTransmittanceWindowMarginTexels of margin, within the map; empty without casters, or where they
// lie wholly behind the near plane or project off the map.
TexelRect transmittanceWindow(const glm::mat4& lightMatrix, const std::vector<TransparentDraw>& casters,
                              std::uint32_t size);

// A run of the index buffer drawn with one pipeline: `alpha` = the SHADOWLAB_ALPHA variant, for
// objects whose texels the pass tests (MASK casters in the depth pass; MASK and BLEND surfaces in
// the lit pass). Objects that test nothing are drawn without it: a fragment shader that can
// discard keeps lavapipe from testing depth before shading and from a depth-only pass without
// any fragment shader, and reads the alpha records per fragment.
struct IndexRange {
    std::uint32_t first = 0;
    std::uint32_t count = 0;
    bool alpha = false;
    // Lit pass: no fragment of these triangles takes the slope bias's lift past its cap
    // (raster/lift_free.h), so the pipeline without that path may draw them.
    bool liftFree = false;
};

// Index and vertex buffers of the whole scene (raster/geometry.h layout).
struct DrawGeometry {
    VkBuffer vertices = VK_NULL_HANDLE;
    VkBuffer indices = VK_NULL_HANDLE;
    std::uint32_t indexCount = 0;
    // The depth pass draws the first opaqueIndexCount indices (all by default). With a
    // transmittance map the opaque casters' triangles come first and each semi-transparent
    // caster's follow as one range (`transparent`), drawn by the transmittance pass only.
    std::uint32_t opaqueIndexCount = ~0u;
    std::vector<TransparentDraw> transparent;
    std::uint32_t depthPassIndexCount() const { return opaqueIndexCount < indexCount ? opaqueIndexCount : indexCount; }
    // Shadow pass only: per layer, the index ranges drawn into it (the casters left after culling,
    // in index order); layers past the end of this list draw every index of the depth pass.
    std::vector<std::vector<IndexRange>> layerRanges;
    // Lit pass: every index in order, split where the camera's alpha test starts or stops (empty:
    // one draw of every index with the pass's pipeline).
    std::vector<IndexRange> litRanges;
    // The same cut where triangles become lift-free or stop being so (IndexRange::liftFree;
    // raster/lift_free.h): drawn instead of litRanges when the lit pass has a lift-free pipeline.
    std::vector<IndexRange> litRangesByLift;
    // The camera's view culling (raster/view_cull.h): litRanges and litRangesByLift cut to the
    // clusters the camera can see, drawn instead of them when litCulled (then an empty list draws
    // nothing).
    bool litCulled = false;
    std::vector<IndexRange> litRangesVisible;
    std::vector<IndexRange> litRangesByLiftVisible;
    // Alpha-tested casters (raster/alpha_casters.h): the UV buffer and the records' set, used by
    // pipelines made with an alpha set layout.
    VkBuffer uvs = VK_NULL_HANDLE;
    VkDescriptorSet alphaSet = VK_NULL_HANDLE;
};

// The transmittance map beside the depth map (made only for scenes with semi-transparent
// casters, RenderPlan::needsTransmittanceMap): per layer, the product T_all of 1 − opacity of the
// semi-transparent casters in front of the opaque depth (R32_SFLOAT, 1 = nothing), and the
// depth D1 of the nearest of them (R32_SFLOAT, 1 = none), in the depth map's depth space; and
// the same two for the fragments behind that nearest layer only (T_rest, D2), so that a receiver
// on the second layer gets the nearest layer's factor T_all / T_rest (lit.frag transmittanceTap).
inline constexpr VkFormat kTransmittanceFormat = VK_FORMAT_R32_SFLOAT;
struct TransmittanceMaps {
    Image transmittance;  // T_all
    std::vector<ImageViewHandle> transmittanceLayerViews;
    Image nearDepth;  // D1
    std::vector<ImageViewHandle> nearDepthLayerViews;
    Image restTransmittance;  // T_rest
    std::vector<ImageViewHandle> restTransmittanceLayerViews;
    Image secondDepth;  // D2
    std::vector<ImageViewHandle> secondDepthLayerViews;
    std::uint32_t size = 0;
    std::uint32_t layers = 0;
};
// Without semi-transparent casters the renderer makes 1x1x1 placeholders that keep the lit
// pass's descriptors valid.
TransmittanceMaps createTransmittanceMaps(const Context& ctx, std::uint32_t size, std::uint32_t layers);

// The transmittance pass: transmit.vert/.frag, depth test LESS against the depth map without
// writing it, target 0 multiplied, target 1 MIN (needs the device's independentBlend).
// alphaSetLayout: the SHADOWLAB_ALPHA variant (per-fragment alpha of MASK and textured BLEND casters).
ShadowPipeline createTransmittancePipeline(const Context& ctx, VkDescriptorSetLayout alphaSetLayout = VK_NULL_HANDLE);

// The second transmittance pass (behind the nearest layer): the same draws and blending, with
// transmit.frag's SHADOWLAB_REST_LAYER variant, which reads the first pass's nearest depths
// (`maps.nearDepth`, bound here once: the set belongs to these maps).
struct TransmittanceRestPipeline {
    SamplerHandle sampler;
    DescriptorSet descriptors;
    PipelineLayoutHandle layout;
    PipelineHandle pipeline;
    bool alpha = false;  // the alpha records' set at index 1
};
TransmittanceRestPipeline createTransmittanceRestPipeline(const Context& ctx, const TransmittanceMaps& maps,
                                                          VkDescriptorSetLayout alphaSetLayout = VK_NULL_HANDLE);

// What recordShadowPass needs for the transmittance passes: the pipelines (both or neither), the
// maps, and per layer the light it is drawn from (TransmitPush::light) and its window
// (transmittanceWindow; layers past its end: empty). Each layer's passes draw and clear only its
// window, and a layer with an empty window has none: what lies outside is never read as such
// (lit.frag reads TransmitWindows), so the maps need no clear there. At 2048² a whole layer is
// 4 × 16 MiB of clears; the casters' window is usually a small part of it, and most layers of a
// point light's cube see none of them.
struct TransmittancePass {
    const ShadowPipeline* pipeline = nullptr;
    const TransmittanceMaps* maps = nullptr;
    std::vector<glm::vec4> layerLights;
    const TransmittanceRestPipeline* rest = nullptr;
    std::vector<TexelRect> windows;
};

// Records: every layer cleared to depth 1 (far: lit) and id 0 within its window (below), and
// layer i drawn with lightMatrices[i] (layers past the end of lightMatrices are only cleared), then both arrays
// made readable by fragment shaders (SHADER_READ_ONLY_OPTIMAL). Without blockerIds (the
// pipeline made so) the id array is not rendered, only moved to SHADER_READ_ONLY_OPTIMAL with
// undefined contents, for a lit pass that does not read it. The depth pass draws only
// geometry.depthPassIndexCount() indices. With `transmittance`, each drawn layer with a window
// then gets the transmittance pass (within the window: its targets cleared to 1, the
// semi-transparent casters drawn, depth-tested against the layer's opaque depths), and after all
// layers' the second pass behind the nearest layer (reading the first's nearest depths); its maps
// end in SHADER_READ_ONLY_OPTIMAL either way (undefined outside the windows, and everywhere with
// `transmittance.pipeline` null, for a lit pass that does not read them).
// layerBias: a pipeline made with hardwareBias needs each drawn layer's factors (missing ones: 0).
// alphaPipeline: the SHADOWLAB_ALPHA variant of `pipeline`, for ranges with IndexRange::alpha
// (null: `pipeline` draws them). windows: per layer, the texels its depth pass clears and draws
// (layerReadWindow; the rest of the layer keeps what it held, undefined; an empty window: the
// layer is left as it was); null or layers past its end: the whole layer.
void recordShadowPass(VkCommandBuffer commands, const ShadowPipeline& pipeline, const ShadowMaps& maps,
                      const DrawGeometry& geometry, const std::vector<glm::mat4>& lightMatrices, bool blockerIds = true,
                      const TransmittancePass* transmittance = nullptr,
                      const std::vector<DepthBiasFactors>* layerBias = nullptr,
                      const ShadowPipeline* alphaPipeline = nullptr, const std::vector<TexelRect>* windows = nullptr);
// Diagnostics and tests: the depths of one layer after recordShadowPass() has run, row 0 first.
std::vector<float> readShadowMap(const Context& ctx, const ShadowMaps& maps, std::uint32_t layer);
std::vector<std::uint32_t> readBlockerIds(const Context& ctx, const ShadowMaps& maps, std::uint32_t layer);

}  // namespace shadowlab::raster
