// scene/shading.h: the lesson's shading model, shared by the CPU backends; shaders/lit.frag
// implements the same formulas in GLSL.
//   color = albedo · Σ_lights light.color · irradiance · max(0, N·L) · visibility + ambient · albedo
// Directional light: irradiance = intensity. Point/spot: intensity / (4π d²) (Scratchapixel's
// point light falloff); a spot is dark outside its cone.
#pragma once

#include <cmath>

#include "scene/scene.h"

namespace shadowlab::scene {

template <typename V>
struct LightSample {
    V toLight;          // unit vector from the point toward the light
    double distance;    // to the light's position; infinity for directional
    double irradiance;  // intensity reaching the point before N·L and visibility
    // False outside a spot's cone: the light's geometry does not reach the point, whatever its
    // intensity (lit.frag tests the same, so a light of intensity 0 is treated alike in both).
    bool reaches = true;
};

inline LightSample<Vec3> sampleLight(const Light& light, const Vec3& p) {
    constexpr double kPi = 3.14159265358979323846;
    if (light.type == LightType::Directional)
        return {-light.direction, std::numeric_limits<double>::infinity(), light.intensity};
    const Vec3 d = light.position - p;
    const double dist = glm::length(d);
    const Vec3 l = d / dist;
    double irradiance = light.intensity / (4.0 * kPi * dist * dist);
    bool reaches = true;
    if (light.type == LightType::Spot) {
        const double cosCone = std::cos(light.coneAngleDegrees * kPi / 180.0);
        if (glm::dot(-l, light.direction) < cosCone) {
            irradiance = 0.0;
            reaches = false;
        }
    }
    return {l, dist, irradiance, reaches};
}

}  // namespace shadowlab::scene
