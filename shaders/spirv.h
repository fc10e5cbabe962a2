// shaders/spirv.h: the SPIR-V of each shader stage, compiled at build time and embedded.
#pragma once

#include <cstdint>
#include <span>

namespace shadowlab::shaders {

std::span<const std::uint32_t> shadowVertSpirv();
std::span<const std::uint32_t> shadowFragSpirv();
// The transmittance pass (semi-transparent casters).
std::span<const std::uint32_t> transmitVertSpirv();
std::span<const std::uint32_t> transmitFragSpirv();
// transmit.frag compiled with SHADOWLAB_REST_LAYER: the second pass, behind the nearest layer.
std::span<const std::uint32_t> transmitFragRestSpirv();
// SHADOWLAB_ALPHA variants (alpha-tested and blended casters, shaders/alpha.glsl): the depth
// pass with and without blocker ids, and both transmittance passes.
std::span<const std::uint32_t> shadowVertAlphaSpirv();
std::span<const std::uint32_t> shadowFragAlphaSpirv();
std::span<const std::uint32_t> shadowFragAlphaDepthSpirv();
std::span<const std::uint32_t> transmitVertAlphaSpirv();
std::span<const std::uint32_t> transmitFragAlphaSpirv();
std::span<const std::uint32_t> transmitFragRestAlphaSpirv();
std::span<const std::uint32_t> litVertSpirv();
std::span<const std::uint32_t> litFragSpirv();
// lit.frag compiled with SHADOWLAB_LIGHT_OUTPUTS: two more targets with per-light visibility.
std::span<const std::uint32_t> litFragLightsSpirv();
// lit.frag compiled with SHADOWLAB_BEAUTY_ONLY: the beauty target only.
std::span<const std::uint32_t> litFragBeautySpirv();
// The filterable maps' moment and blur passes (raster/moment_maps.h).
std::span<const std::uint32_t> momentsCompSpirv();
// SHADOWLAB_ALPHA variants of the lit pass (scenes with MASK or BLEND materials): the camera's
// alpha test, UVs at vertex binding 1 and the alpha records at set 1.
std::span<const std::uint32_t> litVertAlphaSpirv();
std::span<const std::uint32_t> litFragAlphaSpirv();
std::span<const std::uint32_t> litFragLightsAlphaSpirv();
std::span<const std::uint32_t> litFragBeautyAlphaSpirv();
// Each lit.frag variant above compiled with SHADOWLAB_TAPS_ONLY: only the none and pcf2x2 filters.
std::span<const std::uint32_t> litFragTapsSpirv();
std::span<const std::uint32_t> litFragAlphaTapsSpirv();
std::span<const std::uint32_t> litFragLightsTapsSpirv();
std::span<const std::uint32_t> litFragLightsAlphaTapsSpirv();
std::span<const std::uint32_t> litFragBeautyTapsSpirv();
std::span<const std::uint32_t> litFragBeautyAlphaTapsSpirv();
// The *_taps variants without per-light targets again with SHADOWLAB_ONE_SUN (one directional
// light, no semi-transparent casters, no receiver plane), and with SHADOWLAB_ONE_MAP too (no
// cascades), optimized for size: the code those constants switch off is not in the module.
std::span<const std::uint32_t> litFragTapsSunSpirv();
std::span<const std::uint32_t> litFragAlphaTapsSunSpirv();
std::span<const std::uint32_t> litFragBeautyTapsSunSpirv();
std::span<const std::uint32_t> litFragBeautyAlphaTapsSunSpirv();
std::span<const std::uint32_t> litFragTapsSunMapSpirv();
std::span<const std::uint32_t> litFragAlphaTapsSunMapSpirv();
std::span<const std::uint32_t> litFragBeautyTapsSunMapSpirv();
std::span<const std::uint32_t> litFragBeautyAlphaTapsSunMapSpirv();
// lit.vert without the object id output, for the beauty-only shaders without the alpha test
// (which do not read it: spirv-opt's size passes remove the input).
std::span<const std::uint32_t> litVertNoIdSpirv();
// lit.vert for the *_sun_map modules with the light's constants from lit.vert (SHADOWLAB_ONE_SUN):
// the map matrix's rows in the slots a sun leaves spare, no outputs of their own.
std::span<const std::uint32_t> litVertSunSpirv();
std::span<const std::uint32_t> litVertAlphaSunSpirv();
std::span<const std::uint32_t> litVertNoIdSunSpirv();
// The *_sun_map and the general modules for the light's constants baked in (SHADOWLAB_BAKED_LIGHT:
// no flat light inputs), and lit.vert without those outputs to go with them (*_baked), which the
// cascaded *_sun modules take too.
std::span<const std::uint32_t> litFragTapsSunMapBakedSpirv();
std::span<const std::uint32_t> litFragAlphaTapsSunMapBakedSpirv();
std::span<const std::uint32_t> litFragBeautyTapsSunMapBakedSpirv();
std::span<const std::uint32_t> litFragBeautyAlphaTapsSunMapBakedSpirv();
std::span<const std::uint32_t> litFragTapsBakedSpirv();
std::span<const std::uint32_t> litFragAlphaTapsBakedSpirv();
std::span<const std::uint32_t> litFragBeautyTapsBakedSpirv();
std::span<const std::uint32_t> litFragBeautyAlphaTapsBakedSpirv();
std::span<const std::uint32_t> litFragBakedSpirv();
std::span<const std::uint32_t> litFragAlphaBakedSpirv();
std::span<const std::uint32_t> litFragBeautyBakedSpirv();
std::span<const std::uint32_t> litFragBeautyAlphaBakedSpirv();
// The general modules with every light's constants baked in (SHADOWLAB_EVERY_LIGHT), the AOVs, the
// beauty alone or the AOVs and per-light visibility (SHADOWLAB_LIGHT_OUTPUTS); go with lit.vert's *_baked.
std::span<const std::uint32_t> litFragEverySpirv();
std::span<const std::uint32_t> litFragTapsEverySpirv();
std::span<const std::uint32_t> litFragAlphaEverySpirv();
std::span<const std::uint32_t> litFragAlphaTapsEverySpirv();
std::span<const std::uint32_t> litFragBeautyEverySpirv();
std::span<const std::uint32_t> litFragBeautyTapsEverySpirv();
std::span<const std::uint32_t> litFragBeautyAlphaEverySpirv();
std::span<const std::uint32_t> litFragBeautyAlphaTapsEverySpirv();
std::span<const std::uint32_t> litFragLightsEverySpirv();
std::span<const std::uint32_t> litFragLightsTapsEverySpirv();
std::span<const std::uint32_t> litFragLightsAlphaEverySpirv();
std::span<const std::uint32_t> litFragLightsAlphaTapsEverySpirv();
// One spot or one point light with none or pcf2x2, no semi-transparent casters, no receiver plane
// (SHADOWLAB_ONE_SPOT, SHADOWLAB_ONE_POINT), fixed in the source as the *_sun ones: the *_baked
// module of a spot, the *_every module of a point light, with their constants baked in.
std::span<const std::uint32_t> litFragTapsSpotSpirv();
std::span<const std::uint32_t> litFragTapsPointSpirv();
std::span<const std::uint32_t> litFragAlphaTapsSpotSpirv();
std::span<const std::uint32_t> litFragAlphaTapsPointSpirv();
std::span<const std::uint32_t> litFragBeautyTapsSpotSpirv();
std::span<const std::uint32_t> litFragBeautyTapsPointSpirv();
std::span<const std::uint32_t> litFragBeautyAlphaTapsSpotSpirv();
std::span<const std::uint32_t> litFragBeautyAlphaTapsPointSpirv();
std::span<const std::uint32_t> litVertBakedSpirv();
std::span<const std::uint32_t> litVertAlphaBakedSpirv();
std::span<const std::uint32_t> litVertNoIdBakedSpirv();
// The lit pass's background (pixels no object covers): a triangle over the image, and the values
// for the float targets of the AOV, beauty-only and per-light variants.
std::span<const std::uint32_t> backgroundVertSpirv();
std::span<const std::uint32_t> backgroundFragSpirv();
std::span<const std::uint32_t> backgroundFragBeautySpirv();
std::span<const std::uint32_t> backgroundFragLightsSpirv();

}  // namespace shadowlab::shaders
