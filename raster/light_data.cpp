// raster/light_data.cpp: the lit pass's per-light uniforms (see light_data.h).
#include "raster/light_data.h"

#include <cmath>

#include "raster/tolerances.h"

namespace shadowlab::raster {

shaders::LightData lightData(const scene::Light& light, int index, const std::vector<ShadowLayer>& layers,
                             const scene::RasterSettings& settings, const scene::Vec3& origin, double viewDepthOffset,
                             std::span<shaders::CascadeData, SHADOWLAB_MAX_CASCADES> cascades) {
    const bool spot = light.type == scene::LightType::Spot;
    const bool point = light.type == scene::LightType::Point;
    shaders::LightData l{};
    l.kind = point ? SHADOWLAB_LIGHT_POINT : spot ? SHADOWLAB_LIGHT_SPOT : SHADOWLAB_LIGHT_DIRECTIONAL;
    const double meanColor = (light.color.r + light.color.g + light.color.b) / 3.0;
    l.radiance = glm::vec3(light.color * light.intensity);
    l.visibilityWeight = float(light.intensity * meanColor);
    // This light's layers: [first, end) of `layers`, none without a shadow test.
    std::size_t first = 0;
    while (first < layers.size() && layers[first].light != index) ++first;
    std::size_t end = first;
    while (end < layers.size() && layers[end].light == index) ++end;
    l.layer = first < end ? float(first) : -1.0f;
    LightFrustum f;  // the light's one map (default without a shadow test)
    if (first < end) f = layers[end - 1].frustum;
    const ShadowLayer* const last = first < end ? &layers[end - 1] : nullptr;
    const bool cascaded = last && last->reason == LayerReason::kCascade;
    if (point && last) {
        // The shader picks the face and builds its projection itself; it needs each face's range.
        for (std::size_t k = first; k < end; ++k) {
            const int face = layers[k].index;
            l.pointFaces[face].near = float(layers[k].frustum.near);
            l.pointFaces[face].far = float(layers[k].frustum.far);
        }
        l.depthBiasWorld = float(last->shaderDepthBias);
        l.slopeBiasTexels = float(last->shaderSlopeBias);
        l.texelWorldSize = float(f.texelWorldSize());
    } else if (cascaded) {
        // One layer per slice; lit.frag picks the cascade by view depth (cascadeOf).
        for (std::size_t k = first; k < end; ++k) {
            const ShadowLayer& c = layers[k];
            shaders::CascadeData& cd = cascades[std::size_t(c.index)];
            cd.toShadow = glm::mat4(c.frustum.toTexture(origin));
            cd.sliceFar = float(c.sliceFar - viewDepthOffset);
            cd.texelWorldSize = float(c.frustum.texelWorldSize());
            cd.depthPerWorld = float(1.0 / c.frustum.depthRange());
            cd.depthBiasWorld = float(c.shaderDepthBias);
        }
        // Cascade 0 also fills the light's own map members (what cascadeCount <= 1 would use).
        const ShadowLayer& c0 = layers[first];
        f = c0.frustum;
        l.toShadow = cascades[0].toShadow;
        l.depthBiasWorld = float(c0.shaderDepthBias);
        l.slopeBiasTexels = float(c0.shaderSlopeBias);
        l.texelWorldSize = float(f.texelWorldSize());
        l.depthPerWorld = float(1.0 / f.depthRange());
    } else if (last) {
        l.toShadow = glm::mat4(f.toTexture(origin));
        l.depthBiasWorld = float(last->shaderDepthBias);
        l.slopeBiasTexels = float(last->shaderSlopeBias);
        l.texelWorldSize = float(f.texelWorldSize());
        l.depthPerWorld = spot ? 0.0f : float(1.0 / f.depthRange());
    }
    if (point) {
        l.position = glm::vec3(light.position - origin);
        l.pointFaceTan = float(cubeFaceTanHalfFov(settings.shadowMapSize));
        l.lightSize = float(2.0 * light.radius);
    } else if (spot) {
        constexpr double kPi = 3.14159265358979323846;
        l.position = glm::vec3(light.position - origin);
        l.spotDirection = glm::vec3(glm::normalize(light.direction));
        l.spotCosCone = float(std::cos(light.coneAngleDegrees * kPi / 180.0));
        l.spotCosInner = light.innerConeAngleDegrees < light.coneAngleDegrees
                             ? float(std::cos(light.innerConeAngleDegrees * kPi / 180.0))
                             : l.spotCosCone;
        l.mapNear = float(f.near);
        l.mapFar = float(f.far);
        l.lightSize = float(2.0 * light.radius);
    } else {
        l.towardLight = glm::vec3(-light.direction);
        l.cascadeCount = cascaded ? last->count : 0;
    }
    l.maxSlopeTan = float(kMaxSlopeTan);
    l.filterCode = int(settings.filter);
    l.normalOffsetTexels = float(settings.normalOffset);
    l.pcfSize = settings.pcfSize;
    return l;
}

}  // namespace shadowlab::raster
