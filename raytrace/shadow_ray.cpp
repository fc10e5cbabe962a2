// raytrace/shadow_ray.cpp: shadow-ray tracing with transmittance and area-light sampling.
#include "raytrace/shadow_ray.h"

#include <cmath>

namespace shadowlab::raytrace {

namespace {

constexpr double kPi = 3.14159265358979323846;

// Grid nx × ny = n with nx the largest divisor of n not above √n: every sample count is
// stratified exactly, squares fully in both dimensions.
void strataGrid(int n, int& nx, int& ny) {
    nx = int(std::sqrt(double(n)));
    while (nx > 1 && n % nx != 0) --nx;
    nx = std::max(nx, 1);
    ny = n / nx;
}

// Any unit vector perpendicular to w, robust for every w (Duff et al., "Building an
// Orthonormal Basis, Revisited", JCGT 6(1), 2017).
void orthonormalBasis(const scene::Vec3& w, scene::Vec3& t1, scene::Vec3& t2) {
    const double sign = std::copysign(1.0, w.z);
    const double a = -1.0 / (sign + w.z);
    const double b = w.x * w.y * a;
    t1 = scene::Vec3(1.0 + sign * w.x * w.x * a, sign * b, -sign * w.x);
    t2 = scene::Vec3(b, sign + w.y * w.y * a, -w.y);
}

}  // namespace

template <typename Real>
ShadowResult traceShadowRay(const Tracer<Real>& tracer, const Ray<Real>& ray, Real tMax, bool anyHit, bool conservative,
                            bool nearestDistance) {
    ShadowResult r;
    const double length = glm::length(scene::Vec3(ray.d));
    if (anyHit) {
        int blocker = -1;
        if (tracer.anyHit(ray, tMax, conservative, blocker)) {
            r.transmittance = 0.0;
            r.blocker = blocker;
            Hit<Real> h;
            const bool found = nearestDistance ? tracer.closestHit(ray, tMax, conservative, h)
                                               : tracer.intersectObject(blocker, ray, tMax, conservative, false, h);
            if (found) r.distance = double(h.t) * length;
        }
        return r;
    }
    // Closest-hit per object: each object crossed counts once; an opaque hit ends the segment
    // (nothing behind it matters), and the nearest hit names the blocker.
    Real nearest = tMax;
    bool opaqueHit = false;
    for (int i = 0; i < tracer.objectCount(); ++i) {
        Hit<Real> h;
        if (!tracer.intersectObject(i, ray, tMax, conservative, false, h)) continue;
        if (tracer.opaqueObject(i)) {
            opaqueHit = true;
            tMax = h.t;
        } else {
            // 1 − opacity, or for BLEND 1 − opacity·alpha at the object's nearest hit (MASK texels
            // below the cutoff were skipped by the intersection itself).
            r.transmittance *= tracer.transmittance(ray, h);
        }
        if (h.t <= nearest) {
            nearest = h.t;
            r.blocker = i;
        }
    }
    if (opaqueHit) r.transmittance = 0.0;
    if (r.blocker >= 0) r.distance = double(nearest) * length;
    return r;
}

template <typename Real>
ShadowResult lightVisibility(const Tracer<Real>& tracer, const scene::Light& light, const SurfacePoint<Real>& sp,
                             const scene::RaytraceSettings& settings, bool anyHit, Rng& rng, bool nearestDistance) {
    using Vec = Vec3T<Real>;
    const bool conservative = settings.robustOffset;
    if (light.type == scene::LightType::Directional) {
        const Vec w(Real(-light.direction.x), Real(-light.direction.y), Real(-light.direction.z));
        const Ray<Real> ray(shadowOrigin(sp, w, settings), w);
        return traceShadowRay(tracer, ray, std::numeric_limits<Real>::infinity(), anyHit, conservative,
                              nearestDistance);
    }
    const Vec lightPos(Real(light.position.x), Real(light.position.y), Real(light.position.z));
    if (!(light.radius > 0)) {
        // Segment to the light: d spans origin → light, so t runs 0..1.
        const Vec o = shadowOrigin(sp, lightPos - sp.p, settings);
        const Ray<Real> ray(o, lightPos - o);
        return traceShadowRay(tracer, ray, Real(1), anyHit, conservative, nearestDistance);
    }

    // Spherical light: sample directions uniformly in the cone it subtends (pbrt-v4
    // Sphere::Sample(ctx, u) does the same), stratified on an nx × ny grid, jittered.
    const scene::Vec3 p(sp.p);
    const scene::Vec3 toCenter = light.position - p;
    const double dc = glm::length(toCenter);
    ShadowResult result;
    result.transmittance = 1.0;
    if (dc <= light.radius) return result;  // inside the light: nothing can block it
    const scene::Vec3 wc = toCenter / dc;
    scene::Vec3 t1, t2;
    orthonormalBasis(wc, t1, t2);
    const double sinMax = light.radius / dc;
    const double cosMax = std::sqrt(std::max(0.0, 1.0 - sinMax * sinMax));
    const scene::Vec3 ns(sp.ns);
    int nx, ny;
    strataGrid(std::max(settings.samples, 1), nx, ny);
    double sum = 0.0;
    for (int j = 0; j < ny; ++j) {
        for (int i = 0; i < nx; ++i) {
            const double u1 = (j + rng.uniform()) / ny;
            const double u2 = (i + rng.uniform()) / nx;
            const double cosT = 1.0 - u1 * (1.0 - cosMax);
            const double sinT = std::sqrt(std::max(0.0, 1.0 - cosT * cosT));
            const double phi = 2.0 * kPi * u2;
            const scene::Vec3 w = sinT * std::cos(phi) * t1 + sinT * std::sin(phi) * t2 + cosT * wc;
            // Below the receiver's horizon the surface itself hides that part of the light.
            if (glm::dot(w, ns) <= 0) continue;
            // Distance to the near side of the light sphere along w.
            const double disc = light.radius * light.radius - dc * dc * std::max(0.0, 1.0 - cosT * cosT);
            const double tl = dc * cosT - std::sqrt(std::max(0.0, disc));
            const scene::Vec3 q = p + tl * w;
            const Vec target(Real(q.x), Real(q.y), Real(q.z));
            const Vec o = shadowOrigin(sp, target - sp.p, settings);
            const Ray<Real> ray(o, target - o);
            const ShadowResult r = traceShadowRay(tracer, ray, Real(1), anyHit, conservative, nearestDistance);
            sum += r.transmittance;
            if (result.blocker < 0 && r.blocker >= 0) {
                result.blocker = r.blocker;
                result.distance = r.distance;
            }
        }
    }
    result.transmittance = sum / double(nx * ny);
    return result;
}

template ShadowResult traceShadowRay<float>(const Tracer<float>&, const Ray<float>&, float, bool, bool, bool);
template ShadowResult traceShadowRay<double>(const Tracer<double>&, const Ray<double>&, double, bool, bool, bool);
template ShadowResult lightVisibility<float>(const Tracer<float>&, const scene::Light&, const SurfacePoint<float>&,
                                             const scene::RaytraceSettings&, bool, Rng&, bool);
template ShadowResult lightVisibility<double>(const Tracer<double>&, const scene::Light&, const SurfacePoint<double>&,
                                              const scene::RaytraceSettings&, bool, Rng&, bool);

}  // namespace shadowlab::raytrace
