// shaders/spirv.cpp: hands out the SPIR-V arrays glslangValidator generated (--vn).
#include "shaders/spirv.h"

#include <cstdint>

#include "background_frag.spv.h"
#include "background_frag_beauty.spv.h"
#include "background_frag_lights.spv.h"
#include "background_vert.spv.h"
#include "lit_frag.spv.h"
#include "lit_frag_alpha.spv.h"
#include "lit_frag_alpha_baked.spv.h"
#include "lit_frag_alpha_every.spv.h"
#include "lit_frag_alpha_taps.spv.h"
#include "lit_frag_alpha_taps_baked.spv.h"
#include "lit_frag_alpha_taps_every.spv.h"
#include "lit_frag_alpha_taps_point.spv.h"
#include "lit_frag_alpha_taps_spot.spv.h"
#include "lit_frag_alpha_taps_sun.spv.h"
#include "lit_frag_alpha_taps_sun_map.spv.h"
#include "lit_frag_alpha_taps_sun_map_baked.spv.h"
#include "lit_frag_baked.spv.h"
#include "lit_frag_beauty.spv.h"
#include "lit_frag_beauty_alpha.spv.h"
#include "lit_frag_beauty_alpha_baked.spv.h"
#include "lit_frag_beauty_alpha_every.spv.h"
#include "lit_frag_beauty_alpha_taps.spv.h"
#include "lit_frag_beauty_alpha_taps_baked.spv.h"
#include "lit_frag_beauty_alpha_taps_every.spv.h"
#include "lit_frag_beauty_alpha_taps_point.spv.h"
#include "lit_frag_beauty_alpha_taps_spot.spv.h"
#include "lit_frag_beauty_alpha_taps_sun.spv.h"
#include "lit_frag_beauty_alpha_taps_sun_map.spv.h"
#include "lit_frag_beauty_alpha_taps_sun_map_baked.spv.h"
#include "lit_frag_beauty_baked.spv.h"
#include "lit_frag_beauty_every.spv.h"
#include "lit_frag_beauty_taps.spv.h"
#include "lit_frag_beauty_taps_baked.spv.h"
#include "lit_frag_beauty_taps_every.spv.h"
#include "lit_frag_beauty_taps_point.spv.h"
#include "lit_frag_beauty_taps_spot.spv.h"
#include "lit_frag_beauty_taps_sun.spv.h"
#include "lit_frag_beauty_taps_sun_map.spv.h"
#include "lit_frag_beauty_taps_sun_map_baked.spv.h"
#include "lit_frag_every.spv.h"
#include "lit_frag_lights.spv.h"
#include "lit_frag_lights_alpha.spv.h"
#include "lit_frag_lights_alpha_every.spv.h"
#include "lit_frag_lights_alpha_taps.spv.h"
#include "lit_frag_lights_alpha_taps_every.spv.h"
#include "lit_frag_lights_every.spv.h"
#include "lit_frag_lights_taps.spv.h"
#include "lit_frag_lights_taps_every.spv.h"
#include "lit_frag_taps.spv.h"
#include "lit_frag_taps_baked.spv.h"
#include "lit_frag_taps_every.spv.h"
#include "lit_frag_taps_point.spv.h"
#include "lit_frag_taps_spot.spv.h"
#include "lit_frag_taps_sun.spv.h"
#include "lit_frag_taps_sun_map.spv.h"
#include "lit_frag_taps_sun_map_baked.spv.h"
#include "lit_vert.spv.h"
#include "lit_vert_alpha.spv.h"
#include "lit_vert_alpha_baked.spv.h"
#include "lit_vert_alpha_sun.spv.h"
#include "lit_vert_baked.spv.h"
#include "lit_vert_no_id.spv.h"
#include "lit_vert_no_id_baked.spv.h"
#include "lit_vert_no_id_sun.spv.h"
#include "lit_vert_sun.spv.h"
#include "moments_comp.spv.h"
#include "shadow_frag.spv.h"
#include "shadow_frag_alpha.spv.h"
#include "shadow_frag_alpha_depth.spv.h"
#include "shadow_vert.spv.h"
#include "shadow_vert_alpha.spv.h"
#include "transmit_frag.spv.h"
#include "transmit_frag_alpha.spv.h"
#include "transmit_frag_rest.spv.h"
#include "transmit_frag_rest_alpha.spv.h"
#include "transmit_vert.spv.h"
#include "transmit_vert_alpha.spv.h"

namespace shadowlab::shaders {

std::span<const std::uint32_t> shadowVertSpirv() { return kShadowVertSpv; }
std::span<const std::uint32_t> shadowFragSpirv() { return kShadowFragSpv; }
std::span<const std::uint32_t> transmitVertSpirv() { return kTransmitVertSpv; }
std::span<const std::uint32_t> transmitFragSpirv() { return kTransmitFragSpv; }
std::span<const std::uint32_t> transmitFragRestSpirv() { return kTransmitFragRestSpv; }
std::span<const std::uint32_t> shadowVertAlphaSpirv() { return kShadowVertAlphaSpv; }
std::span<const std::uint32_t> shadowFragAlphaSpirv() { return kShadowFragAlphaSpv; }
std::span<const std::uint32_t> shadowFragAlphaDepthSpirv() { return kShadowFragAlphaDepthSpv; }
std::span<const std::uint32_t> transmitVertAlphaSpirv() { return kTransmitVertAlphaSpv; }
std::span<const std::uint32_t> transmitFragAlphaSpirv() { return kTransmitFragAlphaSpv; }
std::span<const std::uint32_t> transmitFragRestAlphaSpirv() { return kTransmitFragRestAlphaSpv; }
std::span<const std::uint32_t> litVertSpirv() { return kLitVertSpv; }
std::span<const std::uint32_t> litFragSpirv() { return kLitFragSpv; }
std::span<const std::uint32_t> litFragLightsSpirv() { return kLitFragLightsSpv; }
std::span<const std::uint32_t> litFragBeautySpirv() { return kLitFragBeautySpv; }
std::span<const std::uint32_t> momentsCompSpirv() { return kMomentsCompSpv; }
std::span<const std::uint32_t> litVertAlphaSpirv() { return kLitVertAlphaSpv; }
std::span<const std::uint32_t> litFragAlphaSpirv() { return kLitFragAlphaSpv; }
std::span<const std::uint32_t> litFragLightsAlphaSpirv() { return kLitFragLightsAlphaSpv; }
std::span<const std::uint32_t> litFragBeautyAlphaSpirv() { return kLitFragBeautyAlphaSpv; }
std::span<const std::uint32_t> litFragTapsSpirv() { return kLitFragTapsSpv; }
std::span<const std::uint32_t> litFragAlphaTapsSpirv() { return kLitFragAlphaTapsSpv; }
std::span<const std::uint32_t> litFragLightsTapsSpirv() { return kLitFragLightsTapsSpv; }
std::span<const std::uint32_t> litFragLightsAlphaTapsSpirv() { return kLitFragLightsAlphaTapsSpv; }
std::span<const std::uint32_t> litFragBeautyTapsSpirv() { return kLitFragBeautyTapsSpv; }
std::span<const std::uint32_t> litFragBeautyAlphaTapsSpirv() { return kLitFragBeautyAlphaTapsSpv; }
std::span<const std::uint32_t> litFragTapsSunSpirv() { return kLitFragTapsSunSpv; }
std::span<const std::uint32_t> litFragAlphaTapsSunSpirv() { return kLitFragAlphaTapsSunSpv; }
std::span<const std::uint32_t> litFragBeautyTapsSunSpirv() { return kLitFragBeautyTapsSunSpv; }
std::span<const std::uint32_t> litFragBeautyAlphaTapsSunSpirv() { return kLitFragBeautyAlphaTapsSunSpv; }
std::span<const std::uint32_t> litFragTapsSunMapSpirv() { return kLitFragTapsSunMapSpv; }
std::span<const std::uint32_t> litFragAlphaTapsSunMapSpirv() { return kLitFragAlphaTapsSunMapSpv; }
std::span<const std::uint32_t> litFragBeautyTapsSunMapSpirv() { return kLitFragBeautyTapsSunMapSpv; }
std::span<const std::uint32_t> litFragBeautyAlphaTapsSunMapSpirv() { return kLitFragBeautyAlphaTapsSunMapSpv; }
std::span<const std::uint32_t> litVertNoIdSpirv() { return kLitVertNoIdSpv; }
std::span<const std::uint32_t> litVertSunSpirv() { return kLitVertSunSpv; }
std::span<const std::uint32_t> litVertAlphaSunSpirv() { return kLitVertAlphaSunSpv; }
std::span<const std::uint32_t> litVertNoIdSunSpirv() { return kLitVertNoIdSunSpv; }
std::span<const std::uint32_t> litFragTapsSunMapBakedSpirv() { return kLitFragTapsSunMapBakedSpv; }
std::span<const std::uint32_t> litFragAlphaTapsSunMapBakedSpirv() { return kLitFragAlphaTapsSunMapBakedSpv; }
std::span<const std::uint32_t> litFragBeautyTapsSunMapBakedSpirv() { return kLitFragBeautyTapsSunMapBakedSpv; }
std::span<const std::uint32_t> litFragBeautyAlphaTapsSunMapBakedSpirv() {
    return kLitFragBeautyAlphaTapsSunMapBakedSpv;
}
std::span<const std::uint32_t> litFragTapsBakedSpirv() { return kLitFragTapsBakedSpv; }
std::span<const std::uint32_t> litFragAlphaTapsBakedSpirv() { return kLitFragAlphaTapsBakedSpv; }
std::span<const std::uint32_t> litFragBeautyTapsBakedSpirv() { return kLitFragBeautyTapsBakedSpv; }
std::span<const std::uint32_t> litFragBeautyAlphaTapsBakedSpirv() { return kLitFragBeautyAlphaTapsBakedSpv; }
std::span<const std::uint32_t> litFragBakedSpirv() { return kLitFragBakedSpv; }
std::span<const std::uint32_t> litFragAlphaBakedSpirv() { return kLitFragAlphaBakedSpv; }
std::span<const std::uint32_t> litFragBeautyBakedSpirv() { return kLitFragBeautyBakedSpv; }
std::span<const std::uint32_t> litFragBeautyAlphaBakedSpirv() { return kLitFragBeautyAlphaBakedSpv; }
std::span<const std::uint32_t> litFragEverySpirv() { return kLitFragEverySpv; }
std::span<const std::uint32_t> litFragTapsEverySpirv() { return kLitFragTapsEverySpv; }
std::span<const std::uint32_t> litFragTapsSpotSpirv() { return kLitFragTapsSpotSpv; }
std::span<const std::uint32_t> litFragTapsPointSpirv() { return kLitFragTapsPointSpv; }
std::span<const std::uint32_t> litFragAlphaTapsSpotSpirv() { return kLitFragAlphaTapsSpotSpv; }
std::span<const std::uint32_t> litFragAlphaTapsPointSpirv() { return kLitFragAlphaTapsPointSpv; }
std::span<const std::uint32_t> litFragBeautyTapsSpotSpirv() { return kLitFragBeautyTapsSpotSpv; }
std::span<const std::uint32_t> litFragBeautyTapsPointSpirv() { return kLitFragBeautyTapsPointSpv; }
std::span<const std::uint32_t> litFragBeautyAlphaTapsSpotSpirv() { return kLitFragBeautyAlphaTapsSpotSpv; }
std::span<const std::uint32_t> litFragBeautyAlphaTapsPointSpirv() { return kLitFragBeautyAlphaTapsPointSpv; }
std::span<const std::uint32_t> litFragAlphaEverySpirv() { return kLitFragAlphaEverySpv; }
std::span<const std::uint32_t> litFragAlphaTapsEverySpirv() { return kLitFragAlphaTapsEverySpv; }
std::span<const std::uint32_t> litFragBeautyEverySpirv() { return kLitFragBeautyEverySpv; }
std::span<const std::uint32_t> litFragBeautyTapsEverySpirv() { return kLitFragBeautyTapsEverySpv; }
std::span<const std::uint32_t> litFragBeautyAlphaEverySpirv() { return kLitFragBeautyAlphaEverySpv; }
std::span<const std::uint32_t> litFragBeautyAlphaTapsEverySpirv() { return kLitFragBeautyAlphaTapsEverySpv; }
std::span<const std::uint32_t> litFragLightsEverySpirv() { return kLitFragLightsEverySpv; }
std::span<const std::uint32_t> litFragLightsTapsEverySpirv() { return kLitFragLightsTapsEverySpv; }
std::span<const std::uint32_t> litFragLightsAlphaEverySpirv() { return kLitFragLightsAlphaEverySpv; }
std::span<const std::uint32_t> litFragLightsAlphaTapsEverySpirv() { return kLitFragLightsAlphaTapsEverySpv; }
std::span<const std::uint32_t> litVertBakedSpirv() { return kLitVertBakedSpv; }
std::span<const std::uint32_t> litVertAlphaBakedSpirv() { return kLitVertAlphaBakedSpv; }
std::span<const std::uint32_t> litVertNoIdBakedSpirv() { return kLitVertNoIdBakedSpv; }
std::span<const std::uint32_t> backgroundVertSpirv() { return kBackgroundVertSpv; }
std::span<const std::uint32_t> backgroundFragSpirv() { return kBackgroundFragSpv; }
std::span<const std::uint32_t> backgroundFragBeautySpirv() { return kBackgroundFragBeautySpv; }
std::span<const std::uint32_t> backgroundFragLightsSpirv() { return kBackgroundFragLightsSpv; }

}  // namespace shadowlab::shaders
