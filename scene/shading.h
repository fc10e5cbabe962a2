// scene/shading.h: the lesson's shading model, shared by the CPU backends; shaders/lit.frag
// implements the same formulas in GLSL.
//   color = albedo · Σ_lights light.color · irradiance · max(0, N·L) · visibility + ambient · albedo
// Directional light: irradiance = intensity. Point/spot: intensity / (4π d²) (Scratchapixel's
// point light falloff); a spot is dark outside its cone and, with an inner cone, falls off
// between the two (spotFalloff).
#pragma once

#include <algorithm>
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

// A spot's intensity at cos θ = cosAngle off its axis, relative to its axis: 1 within the inner
// cone, 0 outside the outer one, between them KHR_lights_punctual's curve, the square of the
// linear ramp in cos θ (its README's "recommended implementation"). A hard cone (cosInner ≤
// cosOuter) is 1 wherever it reaches. lit.frag has the same.
inline double spotFalloff(double cosAngle, double cosOuter, double cosInner) {
    if (!(cosInner > cosOuter)) return cosAngle >= cosOuter ? 1.0 : 0.0;
    const double t = std::clamp((cosAngle - cosOuter) / (cosInner - cosOuter), 0.0, 1.0);
    return t * t;
}

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
        const double cosAngle = glm::dot(-l, light.direction);
        if (cosAngle < cosCone) {
            irradiance = 0.0;
            reaches = false;
        } else if (light.innerConeAngleDegrees < light.coneAngleDegrees) {
            irradiance *= spotFalloff(cosAngle, cosCone, std::cos(light.innerConeAngleDegrees * kPi / 180.0));
        }
    }
    return {l, dist, irradiance, reaches};
}

}  // namespace shadowlab::scene
