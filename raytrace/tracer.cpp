// raytrace/tracer.cpp: scene conversion to Real, per-object intersection and surface points
// with the rounding-error bounds the robust offsets rely on (derivations in docs/raytrace.md).
#include "raytrace/tracer.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <stdexcept>
#include <string>
#include <type_traits>

namespace shadowlab::raytrace {

namespace {

template <typename Real>
Vec3T<Real> toReal(const scene::Vec3& v) {
    return Vec3T<Real>(Real(v.x), Real(v.y), Real(v.z));
}

}  // namespace

template <typename Real>
Tracer<Real>::Tracer(const scene::Scene& scene) {
    objects_.reserve(scene.objects.size());
    for (std::size_t i = 0; i < scene.objects.size(); ++i) {
        const scene::Object& obj = scene.objects[i];
        const double opacity = scene.materialOf(obj).opacity;
        if (const auto* s = std::get_if<scene::Sphere>(&obj.shape)) {
            objects_.push_back({ShapeKind::Sphere, int(spheres_.size()), opacity});
            spheres_.push_back({toReal<Real>(s->center), Real(s->radius)});
        } else if (const auto* q = std::get_if<scene::Quad>(&obj.shape)) {
            QuadData d;
            d.center = toReal<Real>(q->center);
            d.normal = toReal<Real>(q->normal);
            d.uAxis = toReal<Real>(q->uAxis);
            d.vAxis = toReal<Real>(q->vAxis);
            d.halfU = Real(0.5 * q->size.x);
            d.halfV = Real(0.5 * q->size.y);
            d.snapAxis = -1;
            for (int k = 0; k < 3; ++k)
                if (std::abs(d.normal[k]) == Real(1) && d.normal[(k + 1) % 3] == Real(0) &&
                    d.normal[(k + 2) % 3] == Real(0))
                    d.snapAxis = k;
            objects_.push_back({ShapeKind::Quad, int(quads_.size()), opacity});
            quads_.push_back(d);
        } else if (const auto* b = std::get_if<scene::Box>(&obj.shape)) {
            objects_.push_back({ShapeKind::Box, int(boxes_.size()), opacity});
            boxes_.push_back({toReal<Real>(b->min), toReal<Real>(b->max)});
        } else if (const auto* m = std::get_if<scene::Mesh>(&obj.shape)) {
            if (!m->geometry)
                throw std::invalid_argument(obj.name + ": mesh '" + m->file.string() +
                                            "' has no geometry loaded");
            const scene::TriangleMesh& g = *m->geometry;
            MeshData d;
            d.positions.reserve(g.positions.size());
            for (const scene::Vec3& p : g.positions) d.positions.push_back(toReal<Real>(p));
            if (g.normals.size() == g.positions.size()) {
                d.normals.reserve(g.normals.size());
                for (const scene::Vec3& n : g.normals) d.normals.push_back(toReal<Real>(n));
            }
            d.indices = g.indices;
            std::vector<scene::Bounds> triBounds(g.triangleCount());
            for (std::size_t t = 0; t < triBounds.size(); ++t)
                for (int k = 0; k < 3; ++k) triBounds[t].extend(g.positions[g.indices[3 * t + k]]);
            d.bvh = Bvh8::build(triBounds);
            const std::vector<std::uint32_t>& slots = d.bvh.primitives();
            if constexpr (std::is_same_v<Real, float>) {
                d.packets.resize(slots.size() / WideRef::kLeafAlign);
                for (std::size_t s = 0; s < slots.size(); ++s) {
                    TrianglePacket& pk = d.packets[s / 4];
                    for (int k = 0; k < 3; ++k)
                        for (int a = 0; a < 3; ++a)
                            pk.v[3 * k + a][s % 4] =
                                slots[s] == WideRef::kEmpty
                                    ? std::numeric_limits<float>::quiet_NaN()
                                    : d.positions[d.indices[3 * std::size_t(slots[s]) + k]][a];
                }
            } else {
                d.slotVertices.reserve(3 * slots.size());
                for (std::uint32_t tri : slots)
                    for (int k = 0; k < 3; ++k)
                        d.slotVertices.push_back(tri == WideRef::kEmpty
                                                     ? Vec(0)
                                                     : d.positions[d.indices[3 * std::size_t(tri) + k]]);
            }
            triangles_ += g.triangleCount();
            objects_.push_back({ShapeKind::Mesh, int(meshes_.size()), opacity});
            meshes_.push_back(std::move(d));
        }
    }
}

template <typename Real>
bool Tracer<Real>::intersectObject(int object, const Ray<Real>& ray, Real tMax, bool conservative,
                                   bool anyHit, Hit<Real>& hit) const {
    const ObjectData& od = objects_[object];
    switch (od.kind) {
        case ShapeKind::Sphere: {
            const SphereData& s = spheres_[od.index];
            Real t;
            if (!intersectSphere(ray, s.center, s.radius, tMax, conservative, t)) return false;
            hit.t = t;
            hit.object = object;
            hit.prim = 0;
            return true;
        }
        case ShapeKind::Quad: {
            const QuadData& q = quads_[od.index];
            Real t;
            if (!intersectPlane(ray, q.center, q.normal, tMax, conservative, t)) return false;
            // The rectangle's edges need no robustness: only the plane decides self-hits.
            const Vec rel = ray.o + t * ray.d - q.center;
            if (!(std::abs(glm::dot(rel, q.uAxis)) <= q.halfU &&
                  std::abs(glm::dot(rel, q.vAxis)) <= q.halfV))
                return false;
            hit.t = t;
            hit.object = object;
            hit.prim = 0;
            return true;
        }
        case ShapeKind::Box: {
            const BoxData& b = boxes_[od.index];
            Real t;
            int face;
            if (!intersectBox(ray, b.lo, b.hi, tMax, t, face)) return false;
            hit.t = t;
            hit.object = object;
            hit.prim = face;
            return true;
        }
        case ShapeKind::Mesh: {
            const MeshData& m = meshes_[od.index];
            Real tBest = tMax;
            auto record = [&](std::uint32_t slot, Real t, Real b0, Real b1, Real b2) {
                hit.t = t;
                hit.object = object;
                hit.prim = int(m.bvh.primitives()[slot]);
                hit.b0 = b0;
                hit.b1 = b1;
                hit.b2 = b2;
            };
            if constexpr (std::is_same_v<Real, float>) {
                const Triangle4Ray r4(ray);
                return m.bvh.traverse(ray, tBest, anyHit,
                                      [&](std::uint32_t first, std::uint32_t count, Real& tm) {
                    bool any = false;
                    for (std::uint32_t base = first; base < first + count; base += 4) {
                        const TrianglePacket& pk = m.packets[base / 4];
                        const std::uint32_t lanes = std::min<std::uint32_t>(4, first + count - base);
                        int cand = triangle4Candidates(r4, pk, tm, (1 << lanes) - 1);
                        // The scalar test decides, lane by lane in slot order as before.
                        while (cand != 0) {
                            const int l = __builtin_ctz(unsigned(cand));
                            cand &= cand - 1;
                            Real t, b0, b1, b2;
                            if (!intersectTriangle(ray, pk.vertex(l, 0), pk.vertex(l, 1),
                                                   pk.vertex(l, 2), tm, conservative, t, b0, b1, b2))
                                continue;
                            tm = t;
                            record(base + std::uint32_t(l), t, b0, b1, b2);
                            if (anyHit) return true;
                            any = true;
                        }
                    }
                    return any;
                });
            } else {
                return m.bvh.traverse(ray, tBest, anyHit,
                                      [&](std::uint32_t first, std::uint32_t count, Real& tm) {
                    bool any = false;
                    for (std::uint32_t slot = first; slot < first + count; ++slot) {
                        const Vec* v = &m.slotVertices[3 * std::size_t(slot)];
                        Real t, b0, b1, b2;
                        if (!intersectTriangle(ray, v[0], v[1], v[2], tm, conservative, t, b0, b1, b2))
                            continue;
                        tm = t;
                        record(slot, t, b0, b1, b2);
                        if (anyHit) return true;
                        any = true;
                    }
                    return any;
                });
            }
        }
    }
    return false;
}

template <typename Real>
bool Tracer<Real>::closestHit(const Ray<Real>& ray, Real tMax, bool conservative,
                              Hit<Real>& hit) const {
    bool found = false;
    for (int i = 0; i < objectCount(); ++i) {
        Hit<Real> h;
        if (intersectObject(i, ray, tMax, conservative, false, h)) {
            tMax = h.t;
            hit = h;
            found = true;
        }
    }
    return found;
}

template <typename Real>
bool Tracer<Real>::anyHit(const Ray<Real>& ray, Real tMax, bool conservative, int& blocker) const {
    for (int i = 0; i < objectCount(); ++i) {
        Hit<Real> h;
        if (intersectObject(i, ray, tMax, conservative, true, h)) {
            blocker = i;
            return true;
        }
    }
    return false;
}

template <typename Real>
SurfacePoint<Real> Tracer<Real>::surfacePoint(const Ray<Real>& ray, const Hit<Real>& hit,
                                              bool robust) const {
    SurfacePoint<Real> sp;
    sp.object = hit.object;
    sp.p = ray.o + hit.t * ray.d;  // the lesson's hit point
    sp.pError = Vec(0);
    const ObjectData& od = objects_[hit.object];
    switch (od.kind) {
        case ShapeKind::Sphere: {
            const SphereData& s = spheres_[od.index];
            if (robust) {
                // Reproject onto the sphere: the direction from the center is kept and the
                // length set to r; the result is within γ(5)·|local| of the sphere (pbrt-v4
                // Sphere::InteractionFromIntersection). Adding the center back rounds once more.
                Vec local = sp.p - s.center;
                local *= s.radius / glm::length(local);
                sp.p = s.center + local;
                sp.pError = gamma<Real>(6) * glm::abs(local) + gamma<Real>(1) * glm::abs(sp.p);
            }
            sp.ng = glm::normalize(sp.p - s.center);
            sp.ns = sp.ng;
            break;
        }
        case ShapeKind::Quad: {
            const QuadData& q = quads_[od.index];
            sp.ng = q.normal;
            sp.ns = q.normal;
            if (robust) {
                // Project onto the plane, snap an axis-aligned plane's coordinate exactly, then
                // bound the remaining distance by evaluating n·(p − c) in interval arithmetic.
                const Real s = glm::dot(q.normal, sp.p - q.center);
                sp.p -= s * q.normal;
                if (q.snapAxis >= 0) sp.p[q.snapAxis] = q.center[q.snapAxis];
                using I = Interval<Real>;
                I dist(Real(0)), nn(Real(0));
                for (int k = 0; k < 3; ++k) {
                    dist = dist + I(q.normal[k]) * (I(sp.p[k]) - I(q.center[k]));
                    nn = nn + sqrOf(I(q.normal[k]));
                }
                const I e = I(std::max(std::abs(dist.lo), std::abs(dist.hi))) / nn;
                sp.errorAlongNormal = e.hi;
                sp.pError = Vec(e.hi);
            }
            break;
        }
        case ShapeKind::Box: {
            const BoxData& b = boxes_[od.index];
            const int axis = hit.prim % 3;
            const bool maxSide = hit.prim >= 3;
            sp.ng = Vec(0);
            sp.ng[axis] = maxSide ? Real(1) : Real(-1);
            sp.ns = sp.ng;
            if (robust) {
                // The face coordinate is exact; the others carry the error of o + t·d with t
                // from a subtraction and a product by a rounded reciprocal (γ(3)), scaled by d
                // and added to o (two more roundings).
                sp.pError = gamma<Real>(5) * (glm::abs(ray.o) + glm::abs(hit.t * ray.d));
                sp.p[axis] = maxSide ? b.hi[axis] : b.lo[axis];
                sp.pError[axis] = 0;
                sp.errorAlongNormal = 0;
            }
            break;
        }
        case ShapeKind::Mesh: {
            const MeshData& m = meshes_[od.index];
            const std::uint32_t* ix = &m.indices[3 * std::size_t(hit.prim)];
            const Vec& p0 = m.positions[ix[0]];
            const Vec& p1 = m.positions[ix[1]];
            const Vec& p2 = m.positions[ix[2]];
            if (robust) {
                // Barycentric interpolation: error ≤ γ(7)·Σ|b_i·p_i| (pbrt-v4
                // Triangle::InteractionFromIntersection, derived in pbrt-v3 §3.9.4).
                sp.p = hit.b0 * p0 + hit.b1 * p1 + hit.b2 * p2;
                sp.pError = gamma<Real>(7) * (glm::abs(hit.b0 * p0) + glm::abs(hit.b1 * p1) +
                                              glm::abs(hit.b2 * p2));
            }
            sp.ng = glm::normalize(glm::cross(p1 - p0, p2 - p0));
            if (!m.normals.empty()) {
                const Vec n = hit.b0 * m.normals[ix[0]] + hit.b1 * m.normals[ix[1]] +
                              hit.b2 * m.normals[ix[2]];
                const Real len = glm::length(n);
                sp.ns = len > 0 ? n / len : sp.ng;
                if (glm::dot(sp.ns, sp.ng) < 0) sp.ns = -sp.ns;  // winding decides the side
            } else {
                sp.ns = sp.ng;
            }
            break;
        }
    }
    if (robust && od.kind != ShapeKind::Quad && od.kind != ShapeKind::Box)
        sp.errorAlongNormal = glm::dot(glm::abs(sp.ng), sp.pError);
    // Two-sided surfaces: the normals face the side the ray came from.
    if (glm::dot(sp.ng, ray.d) > 0) {
        sp.ng = -sp.ng;
        sp.ns = -sp.ns;
    }
    return sp;
}

template <typename Real>
std::size_t Tracer<Real>::meshBytes() const {
    std::size_t n = 0;
    for (const MeshData& m : meshes_)
        n += m.positions.capacity() * sizeof(Vec) + m.normals.capacity() * sizeof(Vec) +
             m.indices.capacity() * sizeof(std::uint32_t) + m.bvh.bytes() +
             m.packets.capacity() * sizeof(TrianglePacket) + m.slotVertices.capacity() * sizeof(Vec);
    return n;
}

template class Tracer<float>;
template class Tracer<double>;

}  // namespace shadowlab::raytrace
