// studies/analytic.cpp: closed-form primary hits and hard shadows for spheres, quads and boxes
// (long double, camera-relative); written independently of raytrace/ so it can judge it.
#include "studies/analytic.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <sstream>

#include "scene/camera.h"
#include "scene/error.h"

namespace shadowlab::studies {
namespace {

using Real = long double;
struct V3 {
    Real x = 0, y = 0, z = 0;
};
V3 operator+(V3 a, V3 b) { return {a.x + b.x, a.y + b.y, a.z + b.z}; }
V3 operator-(V3 a, V3 b) { return {a.x - b.x, a.y - b.y, a.z - b.z}; }
V3 operator*(Real s, V3 a) { return {s * a.x, s * a.y, s * a.z}; }
Real dot(V3 a, V3 b) { return a.x * b.x + a.y * b.y + a.z * b.z; }
Real length(V3 a) { return std::sqrt(dot(a, a)); }
V3 normalize(V3 a) { return (1 / length(a)) * a; }
V3 fromD(const scene::Vec3& v) { return {Real(v.x), Real(v.y), Real(v.z)}; }
Real comp(V3 a, int k) { return k == 0 ? a.x : (k == 1 ? a.y : a.z); }

constexpr Real kInf = std::numeric_limits<Real>::infinity();

// One shape moved so that the camera is at the origin (the subtraction is exact in long double
// for double inputs of similar magnitude, which is what keeps the 1e7 cases exact).
struct Shape {
    enum Kind { Sphere, Quad, Box } kind = Sphere;
    V3 c;                 // sphere center / quad center
    Real r = 0;           // sphere radius
    V3 n, u, v;           // quad normal and edge axes (unit)
    Real hu = 0, hv = 0;  // quad half sizes
    V3 lo, hi;            // box
};

// A ray-shape intersection: t of the first crossing with t > tMin, the outward normal there,
// and whether the answer is within `margin` (a length) of flipping.
struct Crossing {
    Real t = kInf;
    V3 normal;
    bool knife = false;
};

// The ray o + t·d (d unit) against one shape. Knife edges: for convex shapes the chord length
// through the shape goes to zero at the silhouette, so "|chord| < margin" (on either side: a
// near miss is as undecided as a near hit) marks a grazing ray; for quads the distance of the
// plane hit to the nearest edge; for every shape, a crossing within margin of tMin.
Crossing intersect(const Shape& s, V3 o, V3 d, Real tMin, Real margin) {
    Crossing x;
    if (s.kind == Shape::Sphere) {
        const V3 oc = s.c - o;
        const Real t0 = dot(oc, d);  // closest approach along the ray
        const V3 perp = oc - t0 * d;
        const Real dist = length(perp);               // distance of the center to the line
        const Real h2 = (s.r - dist) * (s.r + dist);  // half chord², cancellation-free
        if (std::fabs(dist - s.r) <= margin) x.knife = true;
        if (h2 < 0) return x;
        const Real h = std::sqrt(h2);
        Real t = t0 - h;
        if (!(t > tMin)) t = t0 + h;
        if (!(t > tMin)) {
            if (std::fabs(t0 + h - tMin) <= margin) x.knife = true;
            return x;
        }
        if (std::fabs(t - tMin) <= margin) x.knife = true;
        x.t = t;
        x.normal = normalize(o + t * d - s.c);
        return x;
    }
    if (s.kind == Shape::Quad) {
        const Real dn = dot(d, s.n);
        const Real num = dot(s.c - o, s.n);
        // The ray starts in the quad's plane (coplanar geometry): the plane is never crossed.
        if (std::fabs(num) <= margin * 1e-3L) return x;
        if (dn == 0) return x;
        const Real t = num / dn;
        if (!(t > tMin)) return x;
        const V3 p = o + t * d - s.c;
        const Real a = std::fabs(dot(p, s.u)), b = std::fabs(dot(p, s.v));
        // Distance to the nearest edge measured in the plane, scaled to a distance across the
        // ray: a grazing ray (small |dn|) sweeps far along the plane per unit of position.
        const Real edge = std::min(std::fabs(a - s.hu), std::fabs(b - s.hv));
        const bool nearEdge = (a <= s.hu + margin && b <= s.hv + margin) && edge <= margin;
        if (nearEdge || std::fabs(t - tMin) <= margin) x.knife = true;
        if (a > s.hu || b > s.hv) return x;
        x.t = t;
        x.normal = s.n;
        return x;
    }
    // Box: slabs.
    Real tNear = -kInf, tFar = kInf;
    int nearAxis = -1;
    for (int k = 0; k < 3; ++k) {
        const Real dk = comp(d, k), ok = comp(o, k);
        const Real lo = comp(s.lo, k), hi = comp(s.hi, k);
        if (dk == 0) {
            if (ok < lo - margin || ok > hi + margin) return x;
            if (ok < lo || ok > hi) {
                x.knife = true;
                return x;
            }
            if (ok - lo <= margin || hi - ok <= margin) x.knife = true;
            continue;
        }
        Real t1 = (lo - ok) / dk, t2 = (hi - ok) / dk;
        if (t1 > t2) std::swap(t1, t2);
        if (t1 > tNear) {
            tNear = t1;
            nearAxis = k;
        }
        tFar = std::min(tFar, t2);
    }
    if (std::fabs(tFar - tNear) <= margin) x.knife = true;  // grazing an edge or corner
    if (tNear > tFar) return x;
    Real t = tNear;
    int axis = nearAxis;
    if (!(t > tMin)) {
        // Starting inside or on the box: the exit counts only for primary rays from inside,
        // which the suite's cameras never are; a point on the box's surface leaving it does not
        // hit it again.
        if (std::fabs(t - tMin) <= margin || std::fabs(tFar - tMin) <= margin) x.knife = true;
        return x;
    }
    if (std::fabs(t - tMin) <= margin) x.knife = true;
    x.t = t;
    V3 nrm;
    if (axis == 0) nrm.x = d.x > 0 ? -1 : 1;
    if (axis == 1) nrm.y = d.y > 0 ? -1 : 1;
    if (axis == 2) nrm.z = d.z > 0 ? -1 : 1;
    x.normal = nrm;
    return x;
}

}  // namespace

std::string whyNotAnalytic(const scene::Scene& scene) {
    if (scene.lights.empty()) return "no lights";
    for (std::size_t i = 0; i < scene.lights.size(); ++i) {
        const scene::Light& l = scene.lights[i];
        if (l.type != scene::LightType::Directional)
            return (l.type == scene::LightType::Point ? "point light " : "spot light ") + std::to_string(i);
    }
    for (const scene::Object& o : scene.objects) {
        if (std::holds_alternative<scene::Mesh>(o.shape)) return "mesh '" + o.name + "'";
        if (!scene.materialOf(o).opaque()) return "semi-transparent '" + o.name + "'";
        if (scene.materialOf(o).alphaMode == scene::AlphaMode::Mask) return "alpha-tested '" + o.name + "'";
    }
    return {};
}

std::optional<AnalyticFrame> analyticAnswer(const scene::Scene& scene) {
    if (!whyNotAnalytic(scene).empty()) return std::nullopt;
    const scene::CameraBasis cam = scene::cameraBasis(scene.camera);
    const V3 eye = fromD(cam.position);

    std::vector<Shape> shapes;
    for (const scene::Object& o : scene.objects) {
        Shape s;
        if (const auto* sp = std::get_if<scene::Sphere>(&o.shape)) {
            s.kind = Shape::Sphere;
            s.c = fromD(sp->center) - eye;
            s.r = sp->radius;
        } else if (const auto* q = std::get_if<scene::Quad>(&o.shape)) {
            s.kind = Shape::Quad;
            s.c = fromD(q->center) - eye;
            s.n = normalize(fromD(q->normal));
            s.u = normalize(fromD(q->uAxis));
            s.v = normalize(fromD(q->vAxis));
            s.hu = Real(q->size.x) / 2;
            s.hv = Real(q->size.y) / 2;
        } else {
            const auto& b = std::get<scene::Box>(o.shape);
            s.kind = Shape::Box;
            s.lo = fromD(b.min) - eye;
            s.hi = fromD(b.max) - eye;
        }
        shapes.push_back(s);
    }
    const scene::Bounds bounds = scene.bounds();
    const Real margin = kKnifeRelative * Real(std::max(bounds.diagonal(), 1e-300)) +
                        kKnifeCoordinateUlps * Real(std::max(bounds.maxAbsCoordinate(), glm::length(cam.position)));

    struct DirLight {
        V3 toLight;
        Real weight;  // irradiance · mean color, times N·L per pixel
    };
    std::vector<DirLight> lights;
    for (const scene::Light& l : scene.lights)
        lights.push_back(
            {normalize(-1.0L * fromD(l.direction)), Real(l.intensity) * Real(l.color.r + l.color.g + l.color.b) / 3});

    AnalyticFrame f;
    f.width = cam.width;
    f.height = cam.height;
    const std::size_t n = f.pixelCount();
    f.objectId.assign(n, 0);
    f.visibility.assign(n, 0.0f);
    f.ndotl.assign(n, 0.0f);
    f.lit.assign(n, 0);
    f.knifeEdge.assign(n, 0);

    for (int y = 0; y < f.height; ++y)
        for (int x = 0; x < f.width; ++x) {
            const std::size_t i = std::size_t(y) * f.width + x;
            const V3 d = normalize(fromD(scene::pixelDirection(cam, x, y)));
            // Primary: nearest crossing; knife when a grazed shape or a second shape at
            // (almost) the same distance could change the answer (silhouettes, z-fighting).
            int best = -1;
            Crossing hit;
            bool knife = false;
            std::vector<Crossing> all(shapes.size());
            for (std::size_t k = 0; k < shapes.size(); ++k) {
                all[k] = intersect(shapes[k], V3{}, d, 0, margin);
                if (all[k].t < hit.t) {
                    hit = all[k];
                    best = int(k);
                }
            }
            for (std::size_t k = 0; k < shapes.size(); ++k) {
                if (all[k].knife && all[k].t <= hit.t + margin) knife = true;
                if (int(k) != best && all[k].t < kInf && std::fabs(all[k].t - hit.t) <= margin) knife = true;
            }
            if (best < 0) {
                f.knifeEdge[i] = knife;
                continue;
            }
            f.objectId[i] = best + 1;
            const V3 p = hit.t * d;
            V3 nrm = hit.normal;
            if (dot(nrm, d) > 0) nrm = -1.0L * nrm;  // two-sided quads face the viewer
            Real weightSum = 0, weighted = 0, maxNdotL = -kInf;
            for (const DirLight& l : lights) {
                const Real ndotl = dot(nrm, l.toLight);
                maxNdotL = std::max(maxNdotL, ndotl);
                if (std::fabs(ndotl) <= kKnifeNdotL) knife = true;
                if (!(ndotl > 0) || !(l.weight > 0)) continue;
                Real v = 1;
                for (std::size_t k = 0; k < shapes.size(); ++k) {
                    // A convex shape (or a plane) never shadows its own point facing the light.
                    if (int(k) == best) continue;
                    const Crossing s = intersect(shapes[k], p, l.toLight, 0, margin);
                    if (s.knife) knife = true;
                    if (s.t < kInf) v = 0;
                }
                weightSum += l.weight * ndotl;
                weighted += l.weight * ndotl * v;
            }
            f.ndotl[i] = float(maxNdotL);
            if (weightSum > 0) {
                f.lit[i] = 1;
                f.visibility[i] = float(weighted / weightSum);
            }
            f.knifeEdge[i] = knife;
        }
    return f;
}

std::string AnalyticCheck::summary() const {
    std::ostringstream s;
    s << (passed() ? "matches" : "MISSES") << " the analytic answer: " << objectIdMismatches << " object-id and "
      << visibilityMismatches << " visibility mismatches of " << visibilityCompared << " judged pixels, "
      << knifeEdgePixels << " knife-edge pixels skipped";
    if (nonFinite) s << ", " << nonFinite << " non-finite";
    if (firstX >= 0) s << ", first at (" << firstX << ", " << firstY << ")";
    return s.str();
}

AnalyticCheck checkAgainstAnalytic(const scene::Frame& reference, const AnalyticFrame& answer) {
    if (reference.width != answer.width || reference.height != answer.height)
        throw scene::InputError("analytic check: reference is " + std::to_string(reference.width) + "x" +
                                std::to_string(reference.height) + ", the analytic answer " +
                                std::to_string(answer.width) + "x" + std::to_string(answer.height));
    const std::size_t n = answer.pixelCount();
    if (reference.objectId.size() != n || reference.visibility.size() != n)
        throw scene::InputError("analytic check: the reference lacks object_id or visibility");
    AnalyticCheck c;
    c.pixels = n;
    for (std::size_t i = 0; i < n; ++i) {
        if (answer.knifeEdge[i]) {
            ++c.knifeEdgePixels;
            continue;
        }
        const float id = reference.objectId[i], v = reference.visibility[i];
        bool wrong = false;
        if (!std::isfinite(id) || (answer.lit[i] && !std::isfinite(v))) {
            ++c.nonFinite;
            wrong = true;
        } else if (int(std::lround(id)) != answer.objectId[i]) {
            ++c.objectIdMismatches;
            wrong = true;
        } else if (answer.lit[i]) {
            ++c.visibilityCompared;
            if ((v > 0.5f) != (answer.visibility[i] > 0.5f)) {
                ++c.visibilityMismatches;
                wrong = true;
            }
        }
        if (wrong && c.firstX < 0) {
            c.firstX = int(i % std::size_t(answer.width));
            c.firstY = int(i / std::size_t(answer.width));
        }
    }
    return c;
}

}  // namespace shadowlab::studies
