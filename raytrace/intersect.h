// raytrace/intersect.h: ray–sphere, ray–triangle (watertight) and ray–box tests in Real.
// Each test has a plain mode (the lesson's: accept any t > 0) and a conservative mode used with
// robust offsets: a hit is accepted only when its t is positive beyond its own rounding error,
// which together with an origin offset past the hit point's error bound rules out self-hits.
#pragma once

#include <cmath>
#include <limits>
#include <type_traits>
#include <utility>

#include "raytrace/real.h"

namespace shadowlab::raytrace {

template <typename Real>
struct Ray {
    using Vec = Vec3T<Real>;
    Vec o;
    Vec d;  // need not be unit length; t is measured in units of |d|
    Vec invDir;
    int dirIsNeg[3];
    // Watertight triangle test set-up (Woop, Benthin, Wald 2013, JCGT 2(1)): the axis where
    // the direction is largest becomes z, and the shear that maps d to +z.
    int kx, ky, kz;
    Real sx, sy, sz;

    Ray() = default;
    Ray(const Vec& origin, const Vec& direction) : o(origin), d(direction) {
        for (int i = 0; i < 3; ++i) {
            invDir[i] = Real(1) / d[i];
            dirIsNeg[i] = invDir[i] < 0 ? 1 : 0;
        }
        kz = maxDimension(glm::abs(d));
        kx = (kz + 1) % 3;
        ky = (kx + 1) % 3;
        sx = -d[kx] / d[kz];
        sy = -d[ky] / d[kz];
        sz = Real(1) / d[kz];
    }
};

// Ray–sphere with the numerically careful discriminant of Haines et al., "Precision
// Improvements for Ray/Sphere Intersection" (Ray Tracing Gems, ch. 7): 4a(r + |v|)(r − |v|)
// with v the center's offset from the ray's closest point, and the stable root pair q/a, c/q.
// N is Real (plain mode) or Interval<Real> (conservative mode: pbrt-v4's Sphere::BasicIntersect
// uses intervals the same way, src/pbrt/shapes.h).
template <typename N, typename Real>
inline bool intersectSphereT(const Ray<Real>& ray, const Vec3T<Real>& center, Real radius, Real tMax, Real& tHit) {
    const N fx = N(ray.o.x) - N(center.x), fy = N(ray.o.y) - N(center.y), fz = N(ray.o.z) - N(center.z);
    const N dx(ray.d.x), dy(ray.d.y), dz(ray.d.z);
    const N r(radius);
    const N a = sqrOf(dx) + sqrOf(dy) + sqrOf(dz);
    const N b = N(Real(2)) * (dx * fx + dy * fy + dz * fz);
    const N c = sqrOf(fx) + sqrOf(fy) + sqrOf(fz) - sqrOf(r);
    const N k = b / (N(Real(2)) * a);
    const N vx = fx - k * dx, vy = fy - k * dy, vz = fz - k * dz;
    const N len = sqrtOf(sqrOf(vx) + sqrOf(vy) + sqrOf(vz));
    const N discrim = N(Real(4)) * a * (r + len) * (r - len);
    if (lowerOf(discrim) < 0) return false;
    const N root = sqrtOf(discrim);
    const N q = midOf(b) < 0 ? N(Real(-0.5)) * (b - root) : N(Real(-0.5)) * (b + root);
    N t0 = q / a, t1 = c / q;
    if (lowerOf(t0) > lowerOf(t1)) std::swap(t0, t1);
    if (upperOf(t0) > tMax || lowerOf(t1) <= 0) return false;
    N t = t0;
    if (lowerOf(t) <= 0) {
        t = t1;
        if (!(upperOf(t) < tMax)) return false;
    }
    tHit = midOf(t);
    return tHit > 0 && tHit < tMax;
}

template <typename Real>
inline bool intersectSphere(const Ray<Real>& ray, const Vec3T<Real>& center, Real radius, Real tMax, bool conservative,
                            Real& tHit) {
    // Conservative = the plain test and the interval test agree on a hit. Most shadow rays
    // miss in the plain test, so the slower interval arithmetic runs only for candidates.
    if (!intersectSphereT<Real>(ray, center, radius, tMax, tHit)) return false;
    return !conservative || intersectSphereT<Interval<Real>>(ray, center, radius, tMax, tHit);
}

// Ray–plane for quads: the plane is exactly {x : n·(x − c) = 0} for the Real values n and c.
// N is Real (plain) or Interval<Real> (conservative): with intervals a hit is kept only when
// every t the rounding allows is positive, so a ray leaving the plane from a point truly on
// its far side is never taken back (a grazing ray whose n·d may be 0 is rejected outright).
template <typename N, typename Real>
inline bool intersectPlaneT(const Ray<Real>& ray, const Vec3T<Real>& c, const Vec3T<Real>& n, Real tMax, Real& tHit) {
    const N num = N(n.x) * (N(c.x) - N(ray.o.x)) + N(n.y) * (N(c.y) - N(ray.o.y)) + N(n.z) * (N(c.z) - N(ray.o.z));
    const N den = N(n.x) * N(ray.d.x) + N(n.y) * N(ray.d.y) + N(n.z) * N(ray.d.z);
    if constexpr (std::is_floating_point_v<N>) {
        if (den == 0) return false;
    }
    const N t = num / den;
    if (!(lowerOf(t) > 0)) return false;
    tHit = midOf(t);
    return tHit < tMax;
}

template <typename Real>
inline bool intersectPlane(const Ray<Real>& ray, const Vec3T<Real>& c, const Vec3T<Real>& n, Real tMax,
                           bool conservative, Real& tHit) {
    if (!intersectPlaneT<Real>(ray, c, n, tMax, tHit)) return false;
    return !conservative || intersectPlaneT<Interval<Real>>(ray, c, n, tMax, tHit);
}

// Watertight ray–triangle test (Woop, Benthin, Wald, "Watertight Ray/Triangle Intersection",
// JCGT 2(1), 2013): vertices are translated to the ray origin, permuted and sheared so the ray
// is +z, and the 2D edge functions decide inside/outside consistently for triangles that share
// an edge. In float, edge functions that come out exactly 0 are recomputed in double, as pbrt-v4
// does (src/pbrt/shapes.cpp, IntersectTriangle), so rays through shared edges and vertices
// never slip between triangles. Conservative mode rejects t <= δt, pbrt-v4's bound on the
// rounding error of t (derived in pbrt-v3 §3.9.6); it was derived for that algebra, so the code
// below keeps the same sequence of operations.
template <typename Real>
inline bool intersectTriangle(const Ray<Real>& ray, const Vec3T<Real>& p0, const Vec3T<Real>& p1, const Vec3T<Real>& p2,
                              Real tMax, bool conservative, Real& tHit, Real& b0, Real& b1, Real& b2) {
    using Vec = Vec3T<Real>;
    const Vec a = p0 - ray.o, b = p1 - ray.o, c = p2 - ray.o;
    Real ax = a[ray.kx], ay = a[ray.ky], az = a[ray.kz];
    Real bx = b[ray.kx], by = b[ray.ky], bz = b[ray.kz];
    Real cx = c[ray.kx], cy = c[ray.ky], cz = c[ray.kz];
    ax += ray.sx * az;
    ay += ray.sy * az;
    bx += ray.sx * bz;
    by += ray.sy * bz;
    cx += ray.sx * cz;
    cy += ray.sy * cz;
    // Edge functions: twice the signed areas of the sub-triangles seen down the ray.
    Real e0 = bx * cy - by * cx;
    Real e1 = cx * ay - cy * ax;
    Real e2 = ax * by - ay * bx;
    if constexpr (std::is_same_v<Real, float>) {
        if (e0 == 0 || e1 == 0 || e2 == 0) {
            // Products of two floats are exact in double: one rounding, the sign is right.
            e0 = float(double(bx) * double(cy) - double(by) * double(cx));
            e1 = float(double(cx) * double(ay) - double(cy) * double(ax));
            e2 = float(double(ax) * double(by) - double(ay) * double(bx));
        }
    }
    if ((e0 < 0 || e1 < 0 || e2 < 0) && (e0 > 0 || e1 > 0 || e2 > 0)) return false;
    const Real det = e0 + e1 + e2;
    if (det == 0) return false;
    az *= ray.sz;
    bz *= ray.sz;
    cz *= ray.sz;
    const Real tScaled = e0 * az + e1 * bz + e2 * cz;
    if (det < 0 && (tScaled >= 0 || tScaled < tMax * det)) return false;
    if (det > 0 && (tScaled <= 0 || tScaled > tMax * det)) return false;
    const Real invDet = Real(1) / det;
    const Real t = tScaled * invDet;
    if (!(t > 0 && t < tMax)) return false;
    if (conservative) {
        const Real maxZt = std::max({std::abs(az), std::abs(bz), std::abs(cz)});
        const Real maxXt = std::max({std::abs(ax), std::abs(bx), std::abs(cx)});
        const Real maxYt = std::max({std::abs(ay), std::abs(by), std::abs(cy)});
        const Real deltaZ = gamma<Real>(3) * maxZt;
        const Real deltaX = gamma<Real>(5) * (maxXt + maxZt);
        const Real deltaY = gamma<Real>(5) * (maxYt + maxZt);
        const Real deltaE = 2 * (gamma<Real>(2) * maxXt * maxYt + deltaY * maxXt + deltaX * maxYt);
        const Real maxE = std::max({std::abs(e0), std::abs(e1), std::abs(e2)});
        const Real deltaT = 3 * (gamma<Real>(3) * maxE * maxZt + deltaE * maxZt + deltaZ * maxE) * std::abs(invDet);
        if (t <= deltaT) return false;
    }
    tHit = t;
    b0 = e0 * invDet;
    b1 = e1 * invDet;
    b2 = e2 * invDet;
    return true;
}

// Slab test against an axis-aligned box. (bound − o)·(1/d) has the exact sign of the true
// value (a subtraction and products round but never flip a sign), so a ray leaving a face from
// an origin strictly outside that face's plane gets t < 0 on that slab and cannot hit the box
// again: the box needs no conservative variant. `face` is axis + 3·(max side ? 1 : 0).
template <typename Real>
inline bool intersectBox(const Ray<Real>& ray, const Vec3T<Real>& lo, const Vec3T<Real>& hi, Real tMax, Real& tHit,
                         int& face) {
    Real tNear = -std::numeric_limits<Real>::infinity();
    Real tFar = std::numeric_limits<Real>::infinity();
    int nearFace = -1, farFace = -1;
    for (int i = 0; i < 3; ++i) {
        if (ray.d[i] == 0) {
            if (ray.o[i] < lo[i] || ray.o[i] > hi[i]) return false;
            continue;
        }
        Real t0 = (lo[i] - ray.o[i]) * ray.invDir[i];
        Real t1 = (hi[i] - ray.o[i]) * ray.invDir[i];
        int f0 = i, f1 = i + 3;
        if (t0 > t1) {
            std::swap(t0, t1);
            std::swap(f0, f1);
        }
        if (t0 > tNear) {
            tNear = t0;
            nearFace = f0;
        }
        if (t1 < tFar) {
            tFar = t1;
            farFace = f1;
        }
        if (tNear > tFar) return false;
    }
    if (tNear > 0) {
        if (!(tNear < tMax)) return false;
        tHit = tNear;
        face = nearFace;
        return true;
    }
    if (tFar > 0 && tFar < tMax) {  // origin inside the box: the exit face
        tHit = tFar;
        face = farFace;
        return true;
    }
    return false;
}

// Slab test for BVH node bounds (float, rounded outward). The near and far planes of each
// slab are picked by the direction's sign instead of compared, and the three slabs are merged
// without early exits, which keeps the test branch-light. tFar is widened by 1 + 2γ(3) (pbrt-v4
// Bounds3::IntersectP) so rounding never culls a node the ray touches. NaN slab values
// (0·inf when the origin lies on a slab plane of a flat box) never cull: `v > t ? v : t`
// keeps t when v is NaN.
template <typename Real>
inline bool intersectBounds(const Ray<Real>& ray, const float* lo, const float* hi, Real tMax) {
    constexpr Real kWiden = 1 + 2 * gamma<Real>(3);
    Real tNear = 0, tFar = tMax;
    for (int i = 0; i < 3; ++i) {
        const Real nearPlane = ray.dirIsNeg[i] ? Real(hi[i]) : Real(lo[i]);
        const Real farPlane = ray.dirIsNeg[i] ? Real(lo[i]) : Real(hi[i]);
        const Real tn = (nearPlane - ray.o[i]) * ray.invDir[i];
        const Real tf = (farPlane - ray.o[i]) * ray.invDir[i] * kWiden;
        tNear = tn > tNear ? tn : tNear;
        tFar = tf < tFar ? tf : tFar;
    }
    return tNear <= tFar;
}

}  // namespace shadowlab::raytrace
