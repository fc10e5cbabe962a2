// raytrace/shadow_ray.h: shadow rays: where they start (the lesson's constant bias or a robust
// offset derived from the hit point's error bound), how they cross semi-transparent objects,
// and how spherical area lights are sampled.
#pragma once

#include "raytrace/real.h"
#include "raytrace/tracer.h"
#include "scene/scene.h"
#include "scene/settings.h"

namespace shadowlab::raytrace {

struct ShadowResult {
    double transmittance = 1.0;  // 1 = unblocked, 0 = fully blocked
    int blocker = -1;            // object index of the first blocker found, -1 = none
    // World distance from the ray's origin to the nearest hit on the ray (a blocker), 0 when none.
    // Exact for closest-hit rays; for any-hit rays, the nearest hit of the blocker found (a bound
    // from above when several objects block), or exact with nearestDistance.
    double distance = 0.0;
};

// The shadow ray's origin for a surface point and a direction toward the light.
// settings.robustOffset: move along the geometric normal (on the light's side) by the bound
// errorAlongNormal, then one more ulp per component away from the surface (pbrt-v4
// OffsetRayOrigin). Otherwise the lesson's p + rayBias·N with N the viewer- and light-facing
// shading normal, computed in Real.
template <typename Real>
Vec3T<Real> shadowOrigin(const SurfacePoint<Real>& sp, const Vec3T<Real>& towardLight,
                         const scene::RaytraceSettings& settings) {
    if (!settings.robustOffset) return sp.p + Real(settings.rayBias) * sp.ns;
    const Vec3T<Real> n = glm::dot(towardLight, sp.ng) < 0 ? -sp.ng : sp.ng;
    Vec3T<Real> o = sp.p + sp.errorAlongNormal * n;
    for (int k = 0; k < 3; ++k) {
        if (n[k] > 0)
            o[k] = nextUp(o[k]);
        else if (n[k] < 0)
            o[k] = nextDown(o[k]);
    }
    return o;
}

// One shadow ray over 0 < t < tMax. anyHit (opaque scenes only): stop at the first hit.
// Otherwise every object on the segment multiplies by (1 − opacity) once, however many of its
// surfaces the ray crosses (BLEND: 1 − opacity·alpha at its nearest hit), and the blocker is the
// nearest object hit. MASK texels below the cutoff are no hit in either mode. nearestDistance:
// a blocked any-hit ray traces once more for the nearest hit (the reference does, for
// ShadowResult::distance).
template <typename Real>
ShadowResult traceShadowRay(const Tracer<Real>& tracer, const Ray<Real>& ray, Real tMax, bool anyHit, bool conservative,
                            bool nearestDistance = false);

// Visibility of `light` from a surface point (N·L > 0 is the caller's business): one ray for
// directional and point lights; settings.samples stratified rays toward a spherical light
// (radius > 0), uniform over the cone the sphere subtends (its visible cap), averaged.
template <typename Real>
ShadowResult lightVisibility(const Tracer<Real>& tracer, const scene::Light& light, const SurfacePoint<Real>& sp,
                             const scene::RaytraceSettings& settings, bool anyHit, Rng& rng,
                             bool nearestDistance = false);

}  // namespace shadowlab::raytrace
