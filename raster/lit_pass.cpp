// raster/lit_pass.cpp: the camera pass and the readback of its targets.
#include "raster/lit_pass.h"

#include <algorithm>
#include <bit>
#include <cstring>
#include <iterator>

#include "raster/pipeline.h"
#include "raster/vulkan_error.h"
#include "shaders/spirv.h"

namespace shadowlab::raster {

bool hasOneMapLight(const LitVariant& variant) {
    if (variant.lightCount != 1 || variant.receiverPlane) return false;
    return (variant.lightKinds == (1u << SHADOWLAB_LIGHT_DIRECTIONAL) && variant.cascades == 1) ||
           variant.lightKinds == (1u << SHADOWLAB_LIGHT_SPOT);
}

bool bakesLightConstants(const LitVariant& v) {
    return hasOneMapLight(v) || (v.lightCount == 1 && !v.receiverPlane && v.cascades > 1 &&
                                 v.lightKinds == (1u << SHADOWLAB_LIGHT_DIRECTIONAL));
}

bool bakesEveryLight(const LitVariant& v) { return v.lightCount > 0 && !bakesLightConstants(v); }

namespace {
// None or pcf2x2, one light of `kind`, no semi-transparent casters, no receiver plane, no per-light
// targets, and the size-optimized modules asked for: the constants SHADOWLAB_ONE_SUN, _SPOT and
// _POINT fix (lit_constants.glsl).
bool oneLightOfKind(const LitVariant& v, int kind) {
    const bool taps = v.filter == scene::ShadowFilter::None || v.filter == scene::ShadowFilter::Pcf2x2;
    return v.oneLightModules && taps && v.lightTargets == 0 && v.lightCount == 1 && v.lightKinds == (1u << kind) &&
           !v.transmittance && !v.receiverPlane;
}
}  // namespace

bool usesSunModules(const LitVariant& v) { return oneLightOfKind(v, SHADOWLAB_LIGHT_DIRECTIONAL); }

bool usesSpotOrPointModule(const LitVariant& v) {
    return v.specializedLightConstants && v.cascades == 1 &&
           ((oneLightOfKind(v, SHADOWLAB_LIGHT_SPOT) && bakesLightConstants(v)) ||
            (oneLightOfKind(v, SHADOWLAB_LIGHT_POINT) && bakesEveryLight(v)));
}

std::array<float, kPackedLightConstants> packLightConstants(const shaders::LitUniforms& u, bool everyLight) {
    const shaders::LightData& l = u.lights[0];
    const bool spot = l.kind == SHADOWLAB_LIGHT_SPOT;
    const glm::vec3 place = spot ? l.position : l.towardLight;
    std::array<float, kPackedLightConstants> c{place.x,          place.y,
                                               place.z,          l.layer,
                                               l.radiance.x,     l.radiance.y,
                                               l.radiance.z,     l.visibilityWeight,
                                               l.depthBiasWorld, l.slopeBiasTexels,
                                               l.texelWorldSize, l.depthPerWorld,
                                               l.maxSlopeTan,    l.normalOffsetTexels,
                                               float(l.pcfSize), 0.0f};
    if (spot) {
        const float spotSlots[8] = {l.spotDirection.x, l.spotDirection.y, l.spotDirection.z, l.spotCosCone,
                                    l.mapNear,         l.mapFar,          l.lightSize,       0.0f};
        std::copy(std::begin(spotSlots), std::end(spotSlots), c.begin() + 16);
    }
    const float frameSlots[8] = {u.forward.x, u.forward.y, u.forward.z, u.ambient, u.mapSize, 0.0f, 0.0f, 0.0f};
    std::copy(std::begin(frameSlots), std::end(frameSlots), c.begin() + 24);
    c[32] = u.cascadeStart;
    c[33] = u.cascadeBlendBand;
    // A cascade's matrix's first three rows (an orthographic map's last is 0 0 0 1) and the rest.
    auto packCascade = [](const shaders::CascadeData& d, float* at) {
        for (int row = 0; row < 3; ++row)
            for (int column = 0; column < 4; ++column) at[4 * row + column] = d.toShadow[column][row];
        at[12] = d.sliceFar;
        at[13] = d.texelWorldSize;
        at[14] = d.depthPerWorld;
        at[15] = d.depthBiasWorld;
    };
    for (std::size_t k = 0; k < SHADOWLAB_MAX_CASCADES; ++k) packCascade(u.cascades[k], c.data() + 34 + 16 * k);
    // One light with one map (hasOneMapLight): cascade 0's first three rows are its toShadow's, and
    // a spot's last row takes the slots' spare components, as lit.vert packs them (lit.frag
    // oneMapMatrix forms the map coordinates with them).
    const bool oneMap = (l.kind == SHADOWLAB_LIGHT_DIRECTIONAL && l.cascadeCount <= 1) || spot;
    if (u.lightCount == 1 && oneMap)
        for (int row = 0; row < 3; ++row)
            for (int column = 0; column < 4; ++column) c[34 + 4 * row + column] = l.toShadow[column][row];
    if (u.lightCount == 1 && spot) {
        c[15] = l.toShadow[0][3];
        c[23] = l.toShadow[1][3];
        c[29] = l.toShadow[2][3];
        c[30] = l.toShadow[3][3];
        c[31] = l.spotCosInner;  // (the last spare component, lit.vert's outFrame[1].w)
    }
    const int bakedLights = everyLight ? std::clamp(u.lightCount, 0, SHADOWLAB_MAX_LIGHTS) : 0;
    for (std::size_t i = 0; i < std::size_t(bakedLights); ++i) {
        const shaders::LightData& d = u.lights[i];
        const glm::vec3 toward = d.kind == SHADOWLAB_LIGHT_DIRECTIONAL ? d.towardLight : d.position;
        const float slots[kPackedPerLight - 16] = {toward.x,          toward.y,
                                                   toward.z,          d.layer,
                                                   d.radiance.x,      d.radiance.y,
                                                   d.radiance.z,      d.visibilityWeight,
                                                   d.depthBiasWorld,  d.slopeBiasTexels,
                                                   d.texelWorldSize,  d.depthPerWorld,
                                                   d.maxSlopeTan,     d.normalOffsetTexels,
                                                   float(d.pcfSize),  float(d.kind),
                                                   d.spotDirection.x, d.spotDirection.y,
                                                   d.spotDirection.z, d.spotCosCone,
                                                   d.mapNear,         d.mapFar,
                                                   d.lightSize,       float(d.cascadeCount)};
        float* const at = c.data() + 34 + 16 * SHADOWLAB_MAX_CASCADES + kPackedPerLight * i;
        std::copy(std::begin(slots), std::end(slots), at);
        for (int column = 0; column < 4; ++column)
            for (int row = 0; row < 4; ++row) at[24 + 4 * column + row] = d.toShadow[column][row];
        at[40] = d.pointFaceTan;
        at[41] = float(d.filterCode);
        at[42] = d.spotCosInner;
        for (int face = 0; face < 6; ++face) {
            at[44 + 2 * face] = d.pointFaces[face].near;
            at[45 + 2 * face] = d.pointFaces[face].far;
        }
        float* const cascades = c.data() + 34 + 16 * SHADOWLAB_MAX_CASCADES + kPackedPerLight * SHADOWLAB_MAX_LIGHTS +
                                16 * SHADOWLAB_MAX_CASCADES * i;
        for (std::size_t k = 0; k < SHADOWLAB_MAX_CASCADES; ++k)
            packCascade(u.cascades[i * SHADOWLAB_MAX_CASCADES + k], cascades + 16 * k);
    }
    return c;
}

// lit.frag: its outputs (beauty only, the AOVs, the per-light targets), the camera's alpha test,
// and for none and pcf2x2 the *_taps build without the other filters' code (lavapipe turns all of a
// module into NIR before the specialization constants remove what a pipeline does not run: the full
// module doubled the lit pipeline's creation); where usesSunModules(), the *_sun modules (*_sun_map
// with one map and no blend bands, *_baked of those for baked constants); where
// usesSpotOrPointModule(), the *_spot or *_point module; elsewhere the general ones, *_baked where
// the one light's constants are baked in, *_every where every light's are.
// lit.vert: the build whose outputs are the fragment shader's inputs.
namespace {
using Spirv = std::span<const std::uint32_t>;
// Of a family's four lit.frag modules, the one for the variant's outputs (the AOVs or the beauty
// alone) and the camera's alpha test.
Spirv fragmentOf(const LitVariant& v, bool alpha, Spirv aovs, Spirv aovsAlpha, Spirv beauty, Spirv beautyAlpha) {
    return v.aovTarget ? (alpha ? aovsAlpha : aovs) : (alpha ? beautyAlpha : beauty);
}
// Of a family's lit.vert builds, the one with the alpha test's coordinates, the no-id one where the
// fragment module reads no object id (the beauty alone without the alpha test: spirv-opt's size
// passes removed the input), or the plain one.
Spirv vertexOf(const LitVariant& v, bool alpha, Spirv plain, Spirv withAlpha, Spirv noId) {
    return alpha ? withAlpha : v.aovTarget ? plain : noId;
}
}  // namespace

LitStages litStages(const LitVariant& v, bool alpha) {
    using namespace shaders;
    const bool taps = v.filter == scene::ShadowFilter::None || v.filter == scene::ShadowFilter::Pcf2x2;
    if (usesSunModules(v)) {
        if (v.cascades == 1 && !v.cascadeBlend && v.specializedLightConstants)
            return {vertexOf(v, alpha, litVertBakedSpirv(), litVertAlphaBakedSpirv(), litVertNoIdBakedSpirv()),
                    fragmentOf(v, alpha, litFragTapsSunMapBakedSpirv(), litFragAlphaTapsSunMapBakedSpirv(),
                               litFragBeautyTapsSunMapBakedSpirv(), litFragBeautyAlphaTapsSunMapBakedSpirv())};
        if (v.cascades == 1 && !v.cascadeBlend)
            return {vertexOf(v, alpha, litVertSunSpirv(), litVertAlphaSunSpirv(), litVertNoIdSunSpirv()),
                    fragmentOf(v, alpha, litFragTapsSunMapSpirv(), litFragAlphaTapsSunMapSpirv(),
                               litFragBeautyTapsSunMapSpirv(), litFragBeautyAlphaTapsSunMapSpirv())};
        return {vertexOf(v, alpha, litVertBakedSpirv(), litVertAlphaBakedSpirv(), litVertNoIdBakedSpirv()),
                fragmentOf(v, alpha, litFragTapsSunSpirv(), litFragAlphaTapsSunSpirv(), litFragBeautyTapsSunSpirv(),
                           litFragBeautyAlphaTapsSunSpirv())};
    }
    if (usesSpotOrPointModule(v)) {
        // One spot: its constants baked in. One point light: every light's constants baked in.
        const auto vertex = vertexOf(v, alpha, litVertBakedSpirv(), litVertAlphaBakedSpirv(), litVertNoIdBakedSpirv());
        if (v.lightKinds == (1u << SHADOWLAB_LIGHT_SPOT))
            return {vertex, fragmentOf(v, alpha, litFragTapsSpotSpirv(), litFragAlphaTapsSpotSpirv(),
                                       litFragBeautyTapsSpotSpirv(), litFragBeautyAlphaTapsSpotSpirv())};
        return {vertex, fragmentOf(v, alpha, litFragTapsPointSpirv(), litFragAlphaTapsPointSpirv(),
                                   litFragBeautyTapsPointSpirv(), litFragBeautyAlphaTapsPointSpirv())};
    }
    if (v.specializedLightConstants && bakesEveryLight(v)) {
        // Every light baked in: the general modules' *_every builds, without flat light inputs.
        const auto vertex = vertexOf(v, alpha, litVertBakedSpirv(), litVertAlphaBakedSpirv(), litVertNoIdBakedSpirv());
        if (!v.aovTarget)
            return {vertex,
                    taps
                        ? (alpha ? shaders::litFragBeautyAlphaTapsEverySpirv() : shaders::litFragBeautyTapsEverySpirv())
                        : (alpha ? shaders::litFragBeautyAlphaEverySpirv() : shaders::litFragBeautyEverySpirv())};
        if (v.lightTargets > 0)
            return {vertex,
                    taps
                        ? (alpha ? shaders::litFragLightsAlphaTapsEverySpirv() : shaders::litFragLightsTapsEverySpirv())
                        : (alpha ? shaders::litFragLightsAlphaEverySpirv() : shaders::litFragLightsEverySpirv())};
        return {vertex, taps ? (alpha ? shaders::litFragAlphaTapsEverySpirv() : shaders::litFragTapsEverySpirv())
                             : (alpha ? shaders::litFragAlphaEverySpirv() : shaders::litFragEverySpirv())};
    }
    if (v.specializedLightConstants) {
        // One spot light, or one sun with another filter or a transmittance map: the general
        // modules without the flat light inputs.
        const auto vertex = vertexOf(v, alpha, litVertBakedSpirv(), litVertAlphaBakedSpirv(), litVertNoIdBakedSpirv());
        if (!v.aovTarget)
            return {vertex,
                    taps
                        ? (alpha ? shaders::litFragBeautyAlphaTapsBakedSpirv() : shaders::litFragBeautyTapsBakedSpirv())
                        : (alpha ? shaders::litFragBeautyAlphaBakedSpirv() : shaders::litFragBeautyBakedSpirv())};
        return {vertex, taps ? (alpha ? shaders::litFragAlphaTapsBakedSpirv() : shaders::litFragTapsBakedSpirv())
                             : (alpha ? shaders::litFragAlphaBakedSpirv() : shaders::litFragBakedSpirv())};
    }
    const auto vertex = vertexOf(v, alpha, litVertSpirv(), litVertAlphaSpirv(), litVertNoIdSpirv());
    if (!v.aovTarget)
        return {vertex, taps ? (alpha ? shaders::litFragBeautyAlphaTapsSpirv() : shaders::litFragBeautyTapsSpirv())
                             : (alpha ? shaders::litFragBeautyAlphaSpirv() : shaders::litFragBeautySpirv())};
    if (v.lightTargets > 0)
        return {vertex, taps ? (alpha ? shaders::litFragLightsAlphaTapsSpirv() : shaders::litFragLightsTapsSpirv())
                             : (alpha ? shaders::litFragLightsAlphaSpirv() : shaders::litFragLightsSpirv())};
    return {vertex, taps ? (alpha ? shaders::litFragAlphaTapsSpirv() : shaders::litFragTapsSpirv())
                         : (alpha ? shaders::litFragAlphaSpirv() : shaders::litFragSpirv())};
}

LitPipeline createLitPipeline(const Context& ctx, const LitVariant& variant, VkDescriptorSetLayout alphaSetLayout,
                              const glm::vec3& background, bool withBackground) {
    requireFormat(ctx, kLitDepthFormat, VK_FORMAT_FEATURE_DEPTH_STENCIL_ATTACHMENT_BIT, "the camera depth buffer");
    // A pipeline for a color format the device cannot render into is invalid usage, which a driver
    // may answer by crashing (NVIDIA's did, given RGB32F): refused here, the format named.
    requireFormat(ctx, variant.beautyFormat, VK_FORMAT_FEATURE_COLOR_ATTACHMENT_BIT, "the lit pass's beauty target");
    VkDevice device = ctx.device.get();
    const VkDescriptorSetLayoutBinding bindings[] = {
        {.binding = 0,
         .descriptorType = VK_DESCRIPTOR_TYPE_UNIFORM_BUFFER,
         .descriptorCount = 1,
         .stageFlags = VK_SHADER_STAGE_VERTEX_BIT | VK_SHADER_STAGE_FRAGMENT_BIT},
        // Per-object albedo, read by lit.vert (and passed on flat).
        {.binding = 1,
         .descriptorType = VK_DESCRIPTOR_TYPE_STORAGE_BUFFER,
         .descriptorCount = 1,
         .stageFlags = VK_SHADER_STAGE_VERTEX_BIT},
        {.binding = 2,
         .descriptorType = VK_DESCRIPTOR_TYPE_COMBINED_IMAGE_SAMPLER,
         .descriptorCount = 1,
         .stageFlags = VK_SHADER_STAGE_FRAGMENT_BIT},
        {.binding = 3,
         .descriptorType = VK_DESCRIPTOR_TYPE_COMBINED_IMAGE_SAMPLER,
         .descriptorCount = 1,
         .stageFlags = VK_SHADER_STAGE_FRAGMENT_BIT},
        // The shadow maps' raw depths (no compare), for the PCSS blocker search.
        {.binding = 4,
         .descriptorType = VK_DESCRIPTOR_TYPE_COMBINED_IMAGE_SAMPLER,
         .descriptorCount = 1,
         .stageFlags = VK_SHADER_STAGE_FRAGMENT_BIT},
        // The transmittance maps: the product of 1 − opacity, and the nearest transparent depth.
        {.binding = 5,
         .descriptorType = VK_DESCRIPTOR_TYPE_COMBINED_IMAGE_SAMPLER,
         .descriptorCount = 1,
         .stageFlags = VK_SHADER_STAGE_FRAGMENT_BIT},
        {.binding = 6,
         .descriptorType = VK_DESCRIPTOR_TYPE_COMBINED_IMAGE_SAMPLER,
         .descriptorCount = 1,
         .stageFlags = VK_SHADER_STAGE_FRAGMENT_BIT},
        // Behind the nearest transparent layer: the product of the rest, and their nearest depth.
        {.binding = 7,
         .descriptorType = VK_DESCRIPTOR_TYPE_COMBINED_IMAGE_SAMPLER,
         .descriptorCount = 1,
         .stageFlags = VK_SHADER_STAGE_FRAGMENT_BIT},
        {.binding = 8,
         .descriptorType = VK_DESCRIPTOR_TYPE_COMBINED_IMAGE_SAMPLER,
         .descriptorCount = 1,
         .stageFlags = VK_SHADER_STAGE_FRAGMENT_BIT},
        // The filterable maps' blurred moments (raster/moment_maps.h), linearly filtered.
        {.binding = 9,
         .descriptorType = VK_DESCRIPTOR_TYPE_COMBINED_IMAGE_SAMPLER,
         .descriptorCount = 1,
         .stageFlags = VK_SHADER_STAGE_FRAGMENT_BIT},
        // Each layer's transmittance window (shaders::TransmitWindows).
        {.binding = 10,
         .descriptorType = VK_DESCRIPTOR_TYPE_UNIFORM_BUFFER,
         .descriptorCount = 1,
         .stageFlags = VK_SHADER_STAGE_FRAGMENT_BIT},
    };
    const VkDescriptorSetLayoutCreateInfo setInfo{
        .sType = VK_STRUCTURE_TYPE_DESCRIPTOR_SET_LAYOUT_CREATE_INFO,
        .bindingCount = 11,
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
    // 17: the lights' constants baked in (bool), 18..115: light 0's values, 116..563: every light's, 564..1075: every light's cascades
    // (packLightConstants).
    constexpr std::uint32_t kConstants = 18 + kPackedLightConstants;
    const scene::MomentSettings& m = variant.moments;
    std::int32_t constants[kConstants] = {std::int32_t(variant.filter),
                                          variant.blockerIds ? 1 : 0,
                                          std::int32_t(variant.lightCount),
                                          std::int32_t(variant.lightKinds),
                                          std::int32_t(variant.cascades),
                                          variant.transmittance ? 1 : 0,
                                          variant.receiverPlane ? 1 : 0,
                                          variant.cascadeBlend ? 1 : 0,
                                          variant.displayTarget ? 0 : 1,
                                          variant.normalOffset ? 1 : 0,
                                          variant.vertexLightConstants ? 1 : 0,
                                          std::bit_cast<std::int32_t>(float(m.minVariance)),
                                          std::bit_cast<std::int32_t>(float(m.bleedReduction)),
                                          std::bit_cast<std::int32_t>(float(m.evsmPositive)),
                                          std::bit_cast<std::int32_t>(float(m.evsmNegative)),
                                          std::bit_cast<std::int32_t>(float(m.esmExponent)),
                                          std::bit_cast<std::int32_t>(float(m.momentBias)),
                                          variant.specializedLightConstants ? 1 : 0};
    for (std::size_t i = 0; i < kPackedLightConstants; ++i)
        constants[18 + i] = std::bit_cast<std::int32_t>(variant.lightConstants[i]);
    VkSpecializationMapEntry entries[kConstants];
    for (std::uint32_t i = 0; i < kConstants; ++i) entries[i] = {i, 4 * i, 4};
    const VkSpecializationInfo specialization{
        .mapEntryCount = kConstants, .pMapEntries = entries, .dataSize = sizeof constants, .pData = constants};
    std::vector<VkFormat> colorFormats{variant.displayTarget ? kLitDisplayFormat : variant.beautyFormat};
    if (variant.aovTarget) {
        colorFormats.insert(colorFormats.end(), kLitPlanes - 1, kLitPlaneFormat);
        colorFormats.insert(colorFormats.end(), variant.lightTargets, kLitLightsFormat);
    }
    const LitStages stages = litStages(variant, p.alpha);
    p.pipeline = createGraphicsPipeline(ctx, PipelineDesc{
                                                 .vertexShader = stages.vertex,
                                                 .fragmentShader = stages.fragment,
                                                 .fragmentSpecialization = &specialization,
                                                 .vertexSpecialization = &specialization,
                                                 .layout = layout,
                                                 .usesUv = p.alpha,
                                                 .colorFormats = colorFormats,
                                                 .depthFormat = kLitDepthFormat,
                                                 // Reversed Z: nearer is larger.
                                                 .depthCompare = VK_COMPARE_OP_GREATER,
                                             });
    if (!variant.displayTarget && withBackground) {
        // The background: where the depth is still the cleared far plane (0), which no fragment
        // of the scene can leave there (GREATER than 0 to be drawn). Its color as specialization
        // constants (the bits of the floats the clear used).
        const VkPipelineLayoutCreateInfo emptyLayout{.sType = VK_STRUCTURE_TYPE_PIPELINE_LAYOUT_CREATE_INFO};
        VkPipelineLayout backgroundLayout = VK_NULL_HANDLE;
        VK_CHECK(vkCreatePipelineLayout(device, &emptyLayout, nullptr, &backgroundLayout));
        p.backgroundLayout = PipelineLayoutHandle(device, backgroundLayout);
        const float color[3] = {background.r, background.g, background.b};
        const VkSpecializationMapEntry colorEntries[3] = {{0, 0, 4}, {1, 4, 4}, {2, 8, 4}};
        const VkSpecializationInfo colorInfo{
            .mapEntryCount = 3, .pMapEntries = colorEntries, .dataSize = sizeof color, .pData = color};
        p.background = createGraphicsPipeline(
            ctx, PipelineDesc{
                     .vertexShader = shaders::backgroundVertSpirv(),
                     .fragmentShader = !variant.aovTarget         ? shaders::backgroundFragBeautySpirv()
                                       : variant.lightTargets > 0 ? shaders::backgroundFragLightsSpirv()
                                                                  : shaders::backgroundFragSpirv(),
                     .fragmentSpecialization = &colorInfo,
                     .layout = backgroundLayout,
                     .vertexBuffer = false,
                     .colorFormats = colorFormats,
                     .depthFormat = kLitDepthFormat,
                     .depthCompare = VK_COMPARE_OP_EQUAL,
                     .depthWrite = false,
                 });
    }
    return p;
}

std::size_t litPlaneTexelBytes(const LitTargets& targets, LitPlane plane) {
    return plane == LitPlane::kBeauty ? targets.beautyTexelBytes : 4;
}

VkFormat litBeautyFormat(const Context& ctx, bool hostReadable) {
    VkFormatProperties rgb{};
    vkGetPhysicalDeviceFormatProperties(ctx.physicalDevice, kLitBeautyFormat, &rgb);
    const VkFormatFeatureFlags needed = VK_FORMAT_FEATURE_COLOR_ATTACHMENT_BIT | VK_FORMAT_FEATURE_TRANSFER_SRC_BIT;
    const VkFormatFeatureFlags features = hostReadable ? rgb.linearTilingFeatures : rgb.optimalTilingFeatures;
    return (features & needed) == needed ? kLitBeautyFormat : kLitBeautyFallbackFormat;
}

LitTargets createLitTargets(const Context& ctx, std::uint32_t width, std::uint32_t height, std::uint32_t lightTargets,
                            bool readInPlace) {
    const std::uint32_t limit = ctx.properties.limits.maxImageDimension2D;
    if (width > limit || height > limit)
        throw RasterError("image " + std::to_string(width) + "x" + std::to_string(height) +
                          " exceeds the device's limit of " + std::to_string(limit) + " per side (" +
                          ctx.deviceReport.name + ")");
    // A target per channel, and two for eight lights' visibility: 6 + 2 attachments.
    const std::uint32_t attachments = kLitPlanes + lightTargets;
    if (ctx.properties.limits.maxColorAttachments < attachments)
        throw RasterError(
            "the lit pass renders into " + std::to_string(attachments) + " color targets (one per Frame " + "channel" +
            (lightTargets ? ", and the per-light visibility" : "") + "), and " + ctx.deviceReport.name + " allows " +
            std::to_string(ctx.properties.limits.maxColorAttachments) + "; choose another device with --device");
    LitTargets t;
    t.width = width;
    t.height = height;
    const VkFormatFeatureFlags needed = VK_FORMAT_FEATURE_COLOR_ATTACHMENT_BIT | VK_FORMAT_FEATURE_TRANSFER_SRC_BIT;
    t.hostReadable = readInPlace && canReadImagesOnHost(ctx, kLitPlaneFormat, kLitTargetUsage) &&
                     canReadImagesOnHost(ctx, kLitLightsFormat, kLitTargetUsage);
    t.beautyFormat = litBeautyFormat(ctx, t.hostReadable);
    t.beautyTexelBytes = t.beautyFormat == kLitBeautyFormat ? 12 : 16;
    requireFormat(ctx, t.beautyFormat, needed, "the lit pass's beauty target");
    requireFormat(ctx, kLitPlaneFormat, needed, "the lit pass's AOV targets");
    requireFormat(ctx, kLitLightsFormat, needed, "the lit pass's per-light visibility targets");
    requireFormat(ctx, kLitDepthFormat, VK_FORMAT_FEATURE_DEPTH_STENCIL_ATTACHMENT_BIT, "the camera depth buffer");
    // The planes (the beauty and five floats), the light targets, D32 depth, as many readback
    // buffers, and the RGBA8 display target.
    requireDeviceMemory(ctx, VkDeviceSize(width) * height * ((t.beautyTexelBytes + 20 + lightTargets * 16) * 2 + 4 + 4),
                        "a " + std::to_string(width) + "x" + std::to_string(height) + " image");
    for (std::uint32_t p = 0; p < kLitPlanes; ++p) {
        const VkFormat format = p == 0 ? t.beautyFormat : kLitPlaneFormat;
        t.planes[p] = createImage(ctx, format, width, height, 1, kLitTargetUsage, VK_IMAGE_ASPECT_COLOR_BIT,
                                  VK_IMAGE_VIEW_TYPE_2D, t.hostReadable);
        // Rendering into a Frame's memory needs the Frame's layout: the host-readable path, RGB
        // beauty, rows without padding.
        if (t.hostReadable && (p > 0 || t.beautyFormat == kLitBeautyFormat))
            t.frameImageBytes[p] =
                hostImageBytes(ctx, format, width, height, kLitTargetUsage, litPlaneTexelBytes(t, LitPlane(p)));
    }
    t.depth = createImage(ctx, kLitDepthFormat, width, height, 1, VK_IMAGE_USAGE_DEPTH_STENCIL_ATTACHMENT_BIT,
                          VK_IMAGE_ASPECT_DEPTH_BIT, VK_IMAGE_VIEW_TYPE_2D);
    for (std::uint32_t i = 0; i < lightTargets; ++i)
        t.lights.push_back(createImage(ctx, kLitLightsFormat, width, height, 1, kLitTargetUsage,
                                       VK_IMAGE_ASPECT_COLOR_BIT, VK_IMAGE_VIEW_TYPE_2D, t.hostReadable));
    // (lavapipe allocates host memory on first touch, so a target never rendered costs address
    // space only.)
    if (t.hostReadable && canReadImagesOnHost(ctx, kLitDisplayFormat, kLitTargetUsage))
        t.display = createImage(ctx, kLitDisplayFormat, width, height, 1, kLitTargetUsage, VK_IMAGE_ASPECT_COLOR_BIT,
                                VK_IMAGE_VIEW_TYPE_2D, true);
    return t;
}

LitBindings createLitBindings(const Context& ctx, const LitPipeline& pipeline, const shaders::LitUniforms& uniforms,
                              const shaders::TransmitWindows& windows, const std::vector<glm::vec4>& albedos,
                              const ShadowMaps& maps, const TransmittanceMaps& transmittance,
                              const MomentMaps& moments) {
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
    b.transmitWindows = uploadBuffer(ctx, &windows, sizeof windows, VK_BUFFER_USAGE_UNIFORM_BUFFER_BIT);
    b.albedos = uploadBuffer(ctx, albedos, VK_BUFFER_USAGE_STORAGE_BUFFER_BIT);

    const VkDescriptorPoolSize sizes[] = {
        {VK_DESCRIPTOR_TYPE_UNIFORM_BUFFER, 2},
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
    const VkDescriptorBufferInfo windowInfo{b.transmitWindows.buffer.get(), 0, VK_WHOLE_SIZE};
    const VkDescriptorImageInfo imageInfo{sampler, maps.depth.view.get(), VK_IMAGE_LAYOUT_SHADER_READ_ONLY_OPTIMAL};
    const VkDescriptorImageInfo idInfo{idSampler, maps.ids.view.get(), VK_IMAGE_LAYOUT_SHADER_READ_ONLY_OPTIMAL};
    const VkDescriptorImageInfo depthInfo{depthSampler, maps.depth.view.get(),
                                          VK_IMAGE_LAYOUT_SHADER_READ_ONLY_OPTIMAL};
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
        {.sType = VK_STRUCTURE_TYPE_WRITE_DESCRIPTOR_SET,
         .dstSet = b.set,
         .dstBinding = 0,
         .descriptorCount = 1,
         .descriptorType = VK_DESCRIPTOR_TYPE_UNIFORM_BUFFER,
         .pBufferInfo = &uniformInfo},
        {.sType = VK_STRUCTURE_TYPE_WRITE_DESCRIPTOR_SET,
         .dstSet = b.set,
         .dstBinding = 1,
         .descriptorCount = 1,
         .descriptorType = VK_DESCRIPTOR_TYPE_STORAGE_BUFFER,
         .pBufferInfo = &albedoInfo},
        {.sType = VK_STRUCTURE_TYPE_WRITE_DESCRIPTOR_SET,
         .dstSet = b.set,
         .dstBinding = 2,
         .descriptorCount = 1,
         .descriptorType = VK_DESCRIPTOR_TYPE_COMBINED_IMAGE_SAMPLER,
         .pImageInfo = &imageInfo},
        {.sType = VK_STRUCTURE_TYPE_WRITE_DESCRIPTOR_SET,
         .dstSet = b.set,
         .dstBinding = 3,
         .descriptorCount = 1,
         .descriptorType = VK_DESCRIPTOR_TYPE_COMBINED_IMAGE_SAMPLER,
         .pImageInfo = &idInfo},
        {.sType = VK_STRUCTURE_TYPE_WRITE_DESCRIPTOR_SET,
         .dstSet = b.set,
         .dstBinding = 4,
         .descriptorCount = 1,
         .descriptorType = VK_DESCRIPTOR_TYPE_COMBINED_IMAGE_SAMPLER,
         .pImageInfo = &depthInfo},
        {.sType = VK_STRUCTURE_TYPE_WRITE_DESCRIPTOR_SET,
         .dstSet = b.set,
         .dstBinding = 5,
         .descriptorCount = 1,
         .descriptorType = VK_DESCRIPTOR_TYPE_COMBINED_IMAGE_SAMPLER,
         .pImageInfo = &transmittanceInfo},
        {.sType = VK_STRUCTURE_TYPE_WRITE_DESCRIPTOR_SET,
         .dstSet = b.set,
         .dstBinding = 6,
         .descriptorCount = 1,
         .descriptorType = VK_DESCRIPTOR_TYPE_COMBINED_IMAGE_SAMPLER,
         .pImageInfo = &nearInfo},
        {.sType = VK_STRUCTURE_TYPE_WRITE_DESCRIPTOR_SET,
         .dstSet = b.set,
         .dstBinding = 7,
         .descriptorCount = 1,
         .descriptorType = VK_DESCRIPTOR_TYPE_COMBINED_IMAGE_SAMPLER,
         .pImageInfo = &restInfo},
        {.sType = VK_STRUCTURE_TYPE_WRITE_DESCRIPTOR_SET,
         .dstSet = b.set,
         .dstBinding = 8,
         .descriptorCount = 1,
         .descriptorType = VK_DESCRIPTOR_TYPE_COMBINED_IMAGE_SAMPLER,
         .pImageInfo = &secondInfo},
        {.sType = VK_STRUCTURE_TYPE_WRITE_DESCRIPTOR_SET,
         .dstSet = b.set,
         .dstBinding = 9,
         .descriptorCount = 1,
         .descriptorType = VK_DESCRIPTOR_TYPE_COMBINED_IMAGE_SAMPLER,
         .pImageInfo = &momentInfo},
        {.sType = VK_STRUCTURE_TYPE_WRITE_DESCRIPTOR_SET,
         .dstSet = b.set,
         .dstBinding = 10,
         .descriptorCount = 1,
         .descriptorType = VK_DESCRIPTOR_TYPE_UNIFORM_BUFFER,
         .pBufferInfo = &windowInfo},
    };
    vkUpdateDescriptorSets(device, 11, writes, 0, nullptr);
    return b;
}

const std::vector<IndexRange>* litDrawRanges(const DrawGeometry& geometry, bool byLift) {
    if (geometry.litCulled) return byLift ? &geometry.litRangesByLiftVisible : &geometry.litRangesVisible;
    const std::vector<IndexRange>& ranges = byLift ? geometry.litRangesByLift : geometry.litRanges;
    return ranges.empty() ? nullptr : &ranges;
}

std::size_t litTrianglesDrawn(const DrawGeometry& geometry, bool byLift) {
    const std::vector<IndexRange>* ranges = litDrawRanges(geometry, byLift);
    if (!ranges) return geometry.indexCount / 3;
    std::size_t indices = 0;
    for (const IndexRange& r : *ranges) indices += r.count;
    return indices / 3;
}

void recordLitPass(VkCommandBuffer commands, const LitPipeline& pipeline, const LitBindings& bindings,
                   const LitTargets& targets, const LitAttachments& attachments, const DrawGeometry& geometry,
                   const glm::vec3& background, LitOutputs outputs, const LitPipeline* alphaPipeline,
                   const LitPipeline* liftFreePipeline, bool backgroundInAttachments) {
    const VkPipelineStageFlags2 colorStage = VK_PIPELINE_STAGE_2_COLOR_ATTACHMENT_OUTPUT_BIT;
    const VkPipelineStageFlags2 depthStages =
        VK_PIPELINE_STAGE_2_EARLY_FRAGMENT_TESTS_BIT | VK_PIPELINE_STAGE_2_LATE_FRAGMENT_TESTS_BIT;
    // The float targets are not cleared: the background pipeline writes every pixel the scene
    // leaves uncovered (their old contents are discarded), or they hold the background already
    // (kept). The display target is cleared.
    const bool clear = outputs == LitOutputs::kDisplay || !pipeline.background;
    const bool keep = !clear && backgroundInAttachments;
    // The previous frame's copy or host read read them: the barrier orders this frame's writes after it.
    std::vector<ImageTransition> before;
    std::vector<VkRenderingAttachmentInfo> colors;
    for (std::size_t i = 0; i < attachments.images.size(); ++i) {
        before.push_back({attachments.images[i], VK_IMAGE_ASPECT_COLOR_BIT, 1,
                          keep ? VK_IMAGE_LAYOUT_GENERAL : VK_IMAGE_LAYOUT_UNDEFINED,
                          VK_IMAGE_LAYOUT_COLOR_ATTACHMENT_OPTIMAL,
                          targets.hostReadable ? VK_PIPELINE_STAGE_2_HOST_BIT : VK_PIPELINE_STAGE_2_COPY_BIT,
                          VK_ACCESS_2_NONE, colorStage, VK_ACCESS_2_COLOR_ATTACHMENT_WRITE_BIT});
        const bool isBeauty = i == 0;  // (the sRGB target encodes the linear clear color)
        colors.push_back(
            {.sType = VK_STRUCTURE_TYPE_RENDERING_ATTACHMENT_INFO,
             .imageView = attachments.views[i],
             .imageLayout = VK_IMAGE_LAYOUT_COLOR_ATTACHMENT_OPTIMAL,
             .loadOp = clear  ? VK_ATTACHMENT_LOAD_OP_CLEAR
                       : keep ? VK_ATTACHMENT_LOAD_OP_LOAD
                              : VK_ATTACHMENT_LOAD_OP_DONT_CARE,
             .storeOp = VK_ATTACHMENT_STORE_OP_STORE,
             .clearValue = {.color = {.float32 = {isBeauty ? background.r : 0.0f, isBeauty ? background.g : 0.0f,
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
    setViewport(commands, targets.width, targets.height);
    if (geometry.indexCount > 0) {
        const VkDeviceSize offset = 0;
        vkCmdBindVertexBuffers(commands, 0, 1, &geometry.vertices, &offset);
        if (geometry.uvs != VK_NULL_HANDLE) vkCmdBindVertexBuffers(commands, 1, 1, &geometry.uvs, &offset);
        vkCmdBindIndexBuffer(commands, geometry.indices, 0, VK_INDEX_TYPE_UINT32);
        const LitPipeline* bound = nullptr;
        auto use = [&](const LitPipeline& p) {
            if (bound == &p) return;
            bound = &p;
            vkCmdBindPipeline(commands, VK_PIPELINE_BIND_POINT_GRAPHICS, p.pipeline.get());
            vkCmdBindDescriptorSets(commands, VK_PIPELINE_BIND_POINT_GRAPHICS, p.layout.get(), 0, 1, &bindings.set, 0,
                                    nullptr);
            if (p.alpha)
                vkCmdBindDescriptorSets(commands, VK_PIPELINE_BIND_POINT_GRAPHICS, p.layout.get(), 1, 1,
                                        &geometry.alphaSet, 0, nullptr);
        };
        const bool byLift = liftFreePipeline && !geometry.litRangesByLift.empty();
        const std::vector<IndexRange>* ranges = litDrawRanges(geometry, byLift);
        if (!ranges) {
            use(pipeline);
            vkCmdDrawIndexed(commands, geometry.indexCount, 1, 0, 0, 0);
            ranges = &geometry.litRanges;  // (empty)
        }
        for (const IndexRange& r : *ranges) {
            if (r.count == 0) continue;
            use(r.alpha && alphaPipeline ? *alphaPipeline : byLift && r.liftFree ? *liftFreePipeline : pipeline);
            vkCmdDrawIndexed(commands, r.count, 1, r.first, 0, 0);
        }
    }
    if (!clear && !keep) {
        vkCmdBindPipeline(commands, VK_PIPELINE_BIND_POINT_GRAPHICS, pipeline.background.get());
        vkCmdDraw(commands, 3, 1, 0, 0);
    }
    vkCmdEndRendering(commands);
    std::vector<ImageTransition> after;
    for (VkImage image : attachments.images)
        // Host access to a linear image needs GENERAL (Vulkan spec); the display target is
        // host-readable whenever it exists.
        if (targets.hostReadable)
            after.push_back({image, VK_IMAGE_ASPECT_COLOR_BIT, 1, VK_IMAGE_LAYOUT_COLOR_ATTACHMENT_OPTIMAL,
                             VK_IMAGE_LAYOUT_GENERAL, colorStage, VK_ACCESS_2_COLOR_ATTACHMENT_WRITE_BIT,
                             VK_PIPELINE_STAGE_2_HOST_BIT, VK_ACCESS_2_HOST_READ_BIT});
        else
            after.push_back({image, VK_IMAGE_ASPECT_COLOR_BIT, 1, VK_IMAGE_LAYOUT_COLOR_ATTACHMENT_OPTIMAL,
                             VK_IMAGE_LAYOUT_TRANSFER_SRC_OPTIMAL, colorStage, VK_ACCESS_2_COLOR_ATTACHMENT_WRITE_BIT,
                             VK_PIPELINE_STAGE_2_COPY_BIT, VK_ACCESS_2_TRANSFER_READ_BIT});
    transition(commands, after);
}

Readback createReadback(const Context& ctx, const LitTargets& targets) {
    const VkDeviceSize pixels = VkDeviceSize(targets.width) * targets.height;
    Readback r;
    for (std::uint32_t p = 0; p < kLitPlanes; ++p)
        r.planes[p] = createReadbackBuffer(ctx, pixels * litPlaneTexelBytes(targets, LitPlane(p)));
    for (std::size_t i = 0; i < targets.lights.size(); ++i) r.lights.push_back(createReadbackBuffer(ctx, pixels * 16));
    return r;
}

void recordReadback(VkCommandBuffer commands, const LitTargets& targets, const Readback& readback,
                    const ReadbackSelection& selection) {
    const VkBufferImageCopy region{
        .imageSubresource = {.aspectMask = VK_IMAGE_ASPECT_COLOR_BIT,
                             .mipLevel = 0,
                             .baseArrayLayer = 0,
                             .layerCount = 1},
        .imageExtent = {targets.width, targets.height, 1},
    };
    for (std::uint32_t p = 0; p < kLitPlanes; ++p)
        if (selection.planes[p])
            vkCmdCopyImageToBuffer(commands, targets.planes[p].image.get(), VK_IMAGE_LAYOUT_TRANSFER_SRC_OPTIMAL,
                                   readback.planes[p].buffer.get(), 1, &region);
    if (selection.lights)
        for (std::size_t i = 0; i < targets.lights.size(); ++i)
            vkCmdCopyImageToBuffer(commands, targets.lights[i].image.get(), VK_IMAGE_LAYOUT_TRANSFER_SRC_OPTIMAL,
                                   readback.lights[i].buffer.get(), 1, &region);
    transferToHostBarrier(commands);
}

}  // namespace shadowlab::raster
