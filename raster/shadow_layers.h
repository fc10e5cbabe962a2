// raster/shadow_layers.h: the shadow-map layers a render draws, as a plain value: per layer its
// light, frustum, matrix, biases, casters and why it exists. Pure (no Vulkan): the renderer
// derives its maps, uniforms and Frame attributes from it, --explain prints it, and tests check
// the plan without a device.
#pragma once

#include <span>
#include <string>
#include <vector>

#include <glm/glm.hpp>

#include "raster/light_frustum.h"
#include "scene/render_plan.h"
#include "scene/scene.h"
#include "scene/settings.h"

namespace shadowlab::raster {

// The rasterizer's depth-bias factors of one layer (vkCmdSetDepthBias): the stored depth of a
// primitive grows by constant·r + slope·max(|∂z/∂x|, |∂z/∂y|), r the depth format's minimum
// resolvable difference at the primitive's depths (D32_SFLOAT: 2^(e − 23), e the exponent of
// its largest depth), the slopes in depth per texel.
struct DepthBiasFactors {
    float constant = 0.0f;
    float slope = 0.0f;
};
// D32_SFLOAT's r for depths in [0.5, 1): the unit the constant factor is converted in.
inline constexpr double kShadowDepthUnitR = 1.0 / 16777216.0;  // 2^-24

// Why a layer exists: a directional light's one map, one cascade of a cascaded directional
// light, a spot light's map, or one cube face of a point light.
enum class LayerReason { kDirectional, kCascade, kSpot, kCubeFace };

struct ShadowLayer {
    int light = -1;  // index into Scene::lights
    LayerReason reason = LayerReason::kDirectional;
    int index = 0;      // kCascade: the cascade; kCubeFace: the face (+X −X +Y −Y +Z −Z); else 0
    int count = 1;      // kCascade: the light's cascades; kCubeFace: 6; else 1
    std::string label;  // "L0", "L0 C2" (cascade 2), "L1 +X" (a point light's face)
    LightFrustum frustum;
    glm::mat4 matrix{1.0f};  // frustum.toClip(origin): what the depth pass draws this layer with
    // The constant bias of this layer's map (world units), wherever it is applied: half the
    // map's texel for a default bias on a fitted or cascaded directional map, else the setting.
    double depthBias = 0.0;
    // What lit.frag applies: the constant (world) and slope (texels) bias; 0, 0 where the depth
    // pass applies them (settings.hardwareBias on a directional map).
    double shaderDepthBias = 0.0;
    double shaderSlopeBias = 0.0;
    bool biasInDepthPass = false;   // settings.hardwareBias on a directional map
    DepthBiasFactors hardwareBias;  // the depth pass's factors (biasInDepthPass); else 0, 0
    // Per object, whether it is drawn into this layer; empty: every object (no caster culling:
    // settings.cullCasters off, or a transmittance map, whose draw order is not per object).
    std::vector<bool> casters;
    int culled = 0;  // objects left out of this layer
    // What the casters were tested against (settings.cullCasters): the receivers that read this
    // layer, the filter's reach and the normal offset in its texels, for layerCastingBoxes() and
    // layerReadWindow(); recorded also with a transmittance map, which culls no caster.
    std::vector<scene::Vec3> receivers;
    double cullReachTexels = 0.0, cullOffsetTexels = 0.0;
    // A filterable map's box blur radius in texels (the moment passes'; 0 for the others): the
    // depth pass draws the lookups' texels (layerLookupWindow) widened by it, and cullReachTexels
    // counts it.
    int blurRadius = 0;
    // kCascade: the view-depth slice the cascade serves, [splits[index], splits[index + 1]].
    double sliceNear = 0.0, sliceFar = 0.0;
};

// The texels of `layer` that its receivers' shadow tests can read (receiverTexels with the reach
// caster culling allows: cullReachTexels, cullOffsetTexels). The depth pass clears and draws only
// these; no lookup reads a texel outside. Empty for a perspective map (spot, cube face) with no
// receiver in front of it. The whole map where nothing bounds the reads: a layer that records no
// receivers (settings.cullCasters off, a camera that sees none of the scene). For a filterable map
// the texels its moment passes blur into layerLookupWindow(): that window widened by blurRadius.
TexelRect layerReadWindow(const ShadowLayer& layer);
// The texels the lit pass's lookups read: layerReadWindow() but for a filterable map, whose lookups
// read the blurred moments of these alone (the moment passes write no more; moment_maps.h).
TexelRect layerLookupWindow(const ShadowLayer& layer);
// `w` widened by dx texels along x and dy along y, within a map of `size` texels (an empty `w`
// stays empty).
TexelRect grownWithin(const TexelRect& w, std::uint32_t dx, std::uint32_t dy, std::uint32_t size);

// The layers for `settings` as resolved (resolveAutomaticChoices: cascade count, map size,
// default bias), in the order the shadow-map array holds them: per light that `plan` gives a
// shadow test (a light the plan does not list gets one), its map, cascades (when
// settings.cascades > 1 and the camera sees the scene) or six cube faces. Matrices take positions
// relative to `origin` (the renderer's: the camera's position when the geometry was uploaded).
std::vector<ShadowLayer> planShadowLayers(const scene::Scene& scene, const scene::RenderPlan& plan,
                                          const scene::RasterSettings& settings, const scene::Vec3& origin);
// The same relative to scene.camera's position.
std::vector<ShadowLayer> planShadowLayers(const scene::Scene& scene, const scene::RenderPlan& plan,
                                          const scene::RasterSettings& settings);

// Per box (world coordinates), whether what lies in it can cast onto a receiver of `layer`: the
// objects' test (castsOnto) for parts of objects, such as the shadow pass's index clusters. All
// true where the layer culls nothing (layer.casters empty).
std::vector<bool> layerCastingBoxes(const ShadowLayer& layer, std::span<const scene::Bounds> boxes);

// The cascades' count + 1 split depths along the view, and each cascade's texel world size, of
// the last cascaded light (the splits are every cascaded light's: they depend on the camera
// only); empty without cascades.
std::vector<double> cascadeSplits(const std::vector<ShadowLayer>& layers);
std::vector<double> cascadeTexels(const std::vector<ShadowLayer>& layers);
// Per light, what culling leaves out of its depth passes with the layers the renderer makes (planShadowLayers) for
// `settings` (and `plan`, when given: lights it gives no shadow test have no maps): per layer (one
// for a single map, one per cascade, six cube faces) its label ("" for a single map, "C0".., "+X"..)
// and how many objects its depth pass leaves out. No layers where nothing is culled: a light
// without a map, settings.cullCasters off, or a transmittance map (plan.needsTransmittanceMap,
// which draws every caster: raster/shadow_layers.cpp says why).
struct LightCulling {
    std::vector<std::string> layers;
    std::vector<int> culled;
    int total() const;  // object draws left out over all the light's layers
};
std::vector<LightCulling> culledCasters(const scene::Scene& scene, const scene::RasterSettings& settings,
                                        const scene::RenderPlan* plan = nullptr);
// One line a layer, for --explain: label, reason, frustum, texel, biases, culled casters.
std::string explainShadowLayers(const std::vector<ShadowLayer>& layers, std::size_t objectCount);

}  // namespace shadowlab::raster
