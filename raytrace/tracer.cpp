// raytrace/tracer.cpp: scene conversion to Real, per-object intersection and surface points
// with the rounding-error bounds the robust offsets rely on (derivations in docs/raytrace.md).
#include "raytrace/tracer.h"

#include <algorithm>
#include <atomic>
#include <cmath>
#include <cstring>
#include <limits>
#include <map>
#include <stdexcept>
#include <string>
#include <type_traits>

#include "raytrace/tolerances.h"

namespace shadowlab::raytrace {

namespace {

template <typename Real>
Vec3T<Real> toReal(const scene::Vec3& v) {
    return Vec3T<Real>(Real(v.x), Real(v.y), Real(v.z));
}

// Points and vectors through a 4x3 affine matrix in the order pbrt-v4's Transform uses, whose
// error bound γ(3)·(|m00·x| + |m01·y| + |m02·z| + |m03|) per component this order satisfies.
template <typename Real>
Vec3T<Real> applyPoint(const glm::mat<4, 3, Real, glm::defaultp>& m, const Vec3T<Real>& p) {
    Vec3T<Real> r;
    for (int k = 0; k < 3; ++k) r[k] = (m[0][k] * p.x + m[1][k] * p.y) + (m[2][k] * p.z + m[3][k]);
    return r;
}
template <typename Real>
Vec3T<Real> applyVector(const glm::mat<4, 3, Real, glm::defaultp>& m, const Vec3T<Real>& v) {
    Vec3T<Real> r;
    for (int k = 0; k < 3; ++k) r[k] = (m[0][k] * v.x + m[1][k] * v.y) + m[2][k] * v.z;
    return r;
}

// The float mesh walk: 8-wide nodes with the box test BoxTest, leaves of SSE packets whose
// candidate lanes the scalar watertight test decides in slot order. Fills the last hit.
struct SlotHit {
    float t = 0, b0 = 0, b1 = 0, b2 = 0;
    std::uint32_t slot = 0;
};

// The alpha test of a MASK mesh's hits: a hit whose alpha (factor × texture at the
// barycentric UV) is below the cutoff is no hit, and the walk goes on. Off (`on` false) for
// every other mesh, which then pays one predictable branch per hit.
template <typename Real>
struct MaskFilter {
    bool on = false;
    Real cutoff = 0, factor = 1;
    const scene::AlphaTexture* texture = nullptr;
    const std::uint32_t* slotPrims = nullptr;  // the tree's slot → triangle
    const std::uint32_t* indices = nullptr;
    const glm::vec<2, Real, glm::defaultp>* uvs = nullptr;  // null: constant alpha
    bool rejects(std::uint32_t slot, Real b0, Real b1, Real b2) const {
        if (!on) return false;
        Real alpha = factor;
        if (texture && uvs) {
            const std::uint32_t* ix = indices + 3 * std::size_t(slotPrims[slot]);
            const auto uv = b0 * uvs[ix[0]] + b1 * uvs[ix[1]] + b2 * uvs[ix[2]];
            alpha *= Real(scene::sampleAlpha(*texture, uv.x, uv.y));
        }
        return alpha < cutoff;  // glTF 3.9.4: alpha below the cutoff is fully transparent
    }
};

// The float mesh walk (WideBvh::walk) with its leaf test: packets of four triangles through
// triangle4Test, whose passing lanes are the scalar watertight test's answers bit for bit
// (plain mode, no zero edge, the same bound); the other candidate lanes (an edge exactly 0,
// conservative mode, or a bound lowered by a hit earlier in the packet) go to the scalar test.
// Lanes are decided in slot order, as the scalar loop always did. Fills the last hit.
template <bool kAnyHit, typename BoxTest>
inline bool traverseFloat(const Bvh8& bvh, const std::vector<TrianglePacket>& packets, const Ray<float>& ray,
                          float& tBest, bool conservative, SlotHit& out, const MaskFilter<float>& mask) {
    const Triangle4Ray r4(ray);
    const BoxTest boxes(ray);
    const std::uint32_t* prims = bvh.primitives().data();
    bool have = false;  // closest hit: `out` holds this walk's nearest hit so far
    return bvh.template walk<kAnyHit>(boxes, tBest, [&](std::uint32_t first, std::uint32_t count, float& tm) {
        bool any = false;
        // After a hit, a hit at exactly the same t is also tested, and the lower triangle
        // index wins: the answer is the minimum of (t, index), whatever the tree's order.
        // tm > 0 and finite once there is a hit: its bits + 1 are the next float up, so
        // t < bound means t <= tm.
        auto above = [](float x) {
            std::uint32_t bits;
            std::memcpy(&bits, &x, sizeof bits);
            ++bits;
            std::memcpy(&x, &bits, sizeof x);
            return x;
        };
        float bound = have ? above(tm) : tm;
        for (std::uint32_t base = first; base < first + count; base += 4) {
            const TrianglePacket& pk = packets[base / 4];
            const std::uint32_t lanes = std::min<std::uint32_t>(4, first + count - base);
            Triangle4Result res;
            triangle4Test(r4, pk, bound, (1 << lanes) - 1, res);
            int cand = res.pass | res.zeroEdge;
            const float packetBound = bound;
            while (cand != 0) {
                const int l = __builtin_ctz(unsigned(cand));
                cand &= cand - 1;
                float t, b0, b1, b2;
                if (!conservative && (res.pass >> l & 1) && bound == packetBound) {
                    t = res.t[l];
                    b0 = res.e[0][l] * res.invDet[l];
                    b1 = res.e[1][l] * res.invDet[l];
                    b2 = res.e[2][l] * res.invDet[l];
                } else if (!intersectTriangle(ray, pk.vertex(l, 0), pk.vertex(l, 1), pk.vertex(l, 2), bound,
                                              conservative, t, b0, b1, b2)) {
                    continue;
                }
                const std::uint32_t slot = base + std::uint32_t(l);
                if (mask.rejects(slot, b0, b1, b2)) continue;
                if (have && !(t < tm || prims[slot] < prims[out.slot])) continue;
                tm = t;
                out = SlotHit{t, b0, b1, b2, slot};
                if constexpr (kAnyHit) return true;
                have = true;
                bound = above(tm);
                any = true;
            }
        }
        return any;
    });
}

template <typename BoxTest>
inline bool traverseFloat(const Bvh8& bvh, const std::vector<TrianglePacket>& packets, const Ray<float>& ray,
                          float& tBest, bool conservative, bool anyHit, SlotHit& out, const MaskFilter<float>& mask) {
    return anyHit ? traverseFloat<true, BoxTest>(bvh, packets, ray, tBest, conservative, out, mask)
                  : traverseFloat<false, BoxTest>(bvh, packets, ray, tBest, conservative, out, mask);
}

#if defined(SHADOWLAB_AVX_BOX_TEST)
// The walk with the box test of the ray's octant (OctantTest<0..7>: its rows are constants). Called
// only from the `flatten` functions below, which inline it with their own target.
template <template <int> class OctantTest>
inline bool traverseFloatByOctant(const Bvh8& bvh, const std::vector<TrianglePacket>& packets, const Ray<float>& ray,
                                  float& tBest, bool conservative, bool anyHit, SlotHit& out,
                                  const MaskFilter<float>& mask) {
    switch (detail::octantOf(ray)) {
        case 0: return traverseFloat<OctantTest<0>>(bvh, packets, ray, tBest, conservative, anyHit, out, mask);
        case 1: return traverseFloat<OctantTest<1>>(bvh, packets, ray, tBest, conservative, anyHit, out, mask);
        case 2: return traverseFloat<OctantTest<2>>(bvh, packets, ray, tBest, conservative, anyHit, out, mask);
        case 3: return traverseFloat<OctantTest<3>>(bvh, packets, ray, tBest, conservative, anyHit, out, mask);
        case 4: return traverseFloat<OctantTest<4>>(bvh, packets, ray, tBest, conservative, anyHit, out, mask);
        case 5: return traverseFloat<OctantTest<5>>(bvh, packets, ray, tBest, conservative, anyHit, out, mask);
        case 6: return traverseFloat<OctantTest<6>>(bvh, packets, ray, tBest, conservative, anyHit, out, mask);
        default: return traverseFloat<OctantTest<7>>(bvh, packets, ray, tBest, conservative, anyHit, out, mask);
    }
}

// The same walk compiled for AVX, one copy per ray octant (the box test's rows are constants):
// `flatten` inlines everything it calls (the walk, the leaf test, the SSE packet filter, the
// scalar triangle test) into this one function, so the AVX code exists only here and runs only
// after detail::useAvx() said the CPU has AVX. Target "avx" enables no FMA, so the float
// results are the SSE path's, bit for bit.
__attribute__((target("avx"), flatten)) bool traverseFloatAvx(const Bvh8& bvh,
                                                              const std::vector<TrianglePacket>& packets,
                                                              const Ray<float>& ray, float& tBest, bool conservative,
                                                              bool anyHit, SlotHit& out,
                                                              const MaskFilter<float>& mask) {
    return traverseFloatByOctant<detail::ChildBoxTestAvx8Octant>(bvh, packets, ray, tBest, conservative, anyHit, out,
                                                                 mask);
}

// The walk with the AVX2 box test (ChildBoxTestAvx2Octant) for rays whose inverse direction is
// finite; the others take traverseFloatAvx. Target "avx2" enables no FMA either.
__attribute__((target("avx2"), flatten)) bool traverseFloatAvx2(const Bvh8& bvh,
                                                                const std::vector<TrianglePacket>& packets,
                                                                const Ray<float>& ray, float& tBest, bool conservative,
                                                                bool anyHit, SlotHit& out,
                                                                const MaskFilter<float>& mask) {
    return traverseFloatByOctant<detail::ChildBoxTestAvx2Octant>(bvh, packets, ray, tBest, conservative, anyHit, out,
                                                                 mask);
}
#endif

#if defined(SHADOWLAB_AVX_BOX_TEST)
// The double walk with the AVX box test (ChildBoxTestAvx8Double): the same walk (traverseWith)
// and leaf, so the same visits in the same order as the scalar test's.
template <typename LeafFn>
__attribute__((target("avx"), flatten)) bool traverseDoubleAvx(const Bvh8& bvh, const Ray<double>& ray, double& tBest,
                                                               bool anyHit, LeafFn& leaf) {
    return bvh.traverseWith<detail::ChildBoxTestAvx8Double>(ray, tBest, anyHit, leaf);
}
#endif

// Per thread: for a few trees, the packet that last blocked an any-hit ray. Keyed by the
// tracer's unique id (never reused, unlike an address) and the tree's index.
struct OccluderCache {
    static constexpr int kEntries = 8;
    struct Entry {
        std::uint64_t tracer = 0;
        std::uint32_t blas = 0, packet = 0;
        bool valid = false;  // the previous any-hit ray in this tree was blocked, by `packet`
    };
    Entry entries[kEntries];
};
thread_local OccluderCache occluderCache;
thread_local std::uint64_t occluderCacheHitCount = 0;
std::atomic<bool> occluderCacheOn{true};
std::atomic<std::uint64_t> nextTracerId{1};

}  // namespace

void setOccluderCache(bool on) { occluderCacheOn.store(on); }
bool occluderCacheEnabled() { return occluderCacheOn.load(); }
std::uint64_t occluderCacheHits() { return occluderCacheHitCount; }

template <typename Real>
Tracer<Real>::Tracer(const scene::Scene& scene) : id_(nextTracerId.fetch_add(1)) {
    objects_.reserve(scene.objects.size());
    // How often each geometry is placed in the whole scene: once means copied to world space,
    // more means one bottom-level tree shared by its instances.
    std::map<const scene::TriangleMesh*, int> uses, blasOf;
    for (const scene::Object& obj : scene.objects)
        if (const auto* m = std::get_if<scene::Mesh>(&obj.shape))
            for (const scene::MeshInstance& inst : m->instances) ++uses[inst.geometry.get()];
    for (std::size_t i = 0; i < scene.objects.size(); ++i) {
        const scene::Object& obj = scene.objects[i];
        const double opacity = scene.materialOf(obj).opacity;
        const std::size_t objectIndex = objects_.size();
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
            d.uvMin = glm::vec<2, Real, glm::defaultp>(q->uvMin);
            d.uvMax = glm::vec<2, Real, glm::defaultp>(q->uvMax);
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
            objects_.push_back({ShapeKind::Mesh, int(meshObjects_.size()), opacity});
            meshObjects_.push_back(buildMeshObject(obj, *m, uses, blasOf));
        }
        const scene::Material& mat = scene.materialOf(obj);
        ObjectData& od = objects_[objectIndex];
        od.opaque = mat.opaque();
        if (mat.alphaMode != scene::AlphaMode::Opaque) {
            od.alpha = int(alphas_.size());
            alphas_.push_back({mat.alphaMode, Real(mat.alphaCutoff), Real(mat.alphaFactor), mat.alphaTexture,
                               Real(mat.cameraCutoff()), mat});
        }
    }
}

template <typename Real>
Real Tracer<Real>::textureAlpha(const ObjectData& od, const Ray<Real>& ray, const Hit<Real>& hit) const {
    const AlphaData& a = alphas_[std::size_t(od.alpha)];
    if (!a.texture) return Real(1);
    if (od.kind == ShapeKind::Quad) {
        // (u, v) from the point's offsets along the quad's axes, as intersectObject tests them.
        const QuadData& q = quads_[od.index];
        const Vec rel = ray.o + hit.t * ray.d - q.center;
        const Real s = glm::dot(rel, q.uAxis) / (Real(2) * q.halfU) + Real(0.5);
        const Real t = glm::dot(rel, q.vAxis) / (Real(2) * q.halfV) + Real(0.5);
        return Real(scene::sampleAlpha(*a.texture, q.uvMin.x + s * (q.uvMax.x - q.uvMin.x),
                                       q.uvMin.y + t * (q.uvMax.y - q.uvMin.y)));
    }
    if (od.kind != ShapeKind::Mesh) return Real(1);  // (the loader allows no texture on spheres and boxes)
    const MeshObjectData& mo = meshObjects_[od.index];
    const MeshData& m = meshes_[hit.instance >= 0 ? mo.instances[hit.instance].blas : mo.flat];
    if (m.uvs.empty()) return Real(1);
    const std::uint32_t* ix = &m.indices[3 * std::size_t(hit.prim)];
    const auto uv = hit.b0 * m.uvs[ix[0]] + hit.b1 * m.uvs[ix[1]] + hit.b2 * m.uvs[ix[2]];
    return Real(scene::sampleAlpha(*a.texture, uv.x, uv.y));
}

template <typename Real>
double Tracer<Real>::transmittance(const Ray<Real>& ray, const Hit<Real>& hit) const {
    const ObjectData& od = objects_[hit.object];
    if (od.alpha < 0) return 1.0 - od.opacity;
    const AlphaData& a = alphas_[std::size_t(od.alpha)];
    return a.material.transmittance(a.mode == scene::AlphaMode::Blend ? double(textureAlpha(od, ray, hit)) : 1.0);
}

template <typename Real>
typename Tracer<Real>::MeshObjectData Tracer<Real>::buildMeshObject(
    const scene::Object& obj, const scene::Mesh& m, const std::map<const scene::TriangleMesh*, int>& uses,
    std::map<const scene::TriangleMesh*, int>& blasOf) {
    if (m.instances.empty())
        throw std::invalid_argument(obj.name + ": mesh '" + m.file.string() + "' has no geometry loaded");
    MeshObjectData mo;
    // Meshes placed once are copied into world space and merged per object: one tree, no
    // transform per ray (docs/raytrace.md, "Instances").
    std::vector<scene::Vec3> positions, normals;
    std::vector<scene::Vec2> uvs;
    std::vector<std::uint32_t> indices;
    bool allUvs = true;
    std::vector<scene::Bounds> instanceBounds;
    for (const scene::MeshInstance& inst : m.instances) {
        if (!inst.geometry)
            throw std::invalid_argument(obj.name + ": mesh '" + m.file.string() + "' has no geometry loaded");
        const scene::TriangleMesh& g = *inst.geometry;
        triangles_ += g.triangleCount();
        if (uses.at(&g) == 1) {
            const glm::dmat3 nm = scene::normalMatrix(inst.transform);
            allUvs = allUvs && g.uvs.size() == g.positions.size();
            if (g.normals.size() != g.positions.size()) {
                // No vertex normals (a mesh built in code; the loaders always compute them): flat
                // triangles with each face's normal, so the other meshes merged here keep theirs
                // and the raster backend draws the same normals.
                for (std::size_t t = 0; t + 2 < g.indices.size(); t += 3) {
                    const std::uint32_t i[3] = {g.indices[t], g.indices[t + 1], g.indices[t + 2]};
                    const scene::Vec3 face =
                        nm * glm::cross(g.positions[i[1]] - g.positions[i[0]], g.positions[i[2]] - g.positions[i[0]]);
                    const double len = glm::length(face);
                    const scene::Vec3 n = len > 0.0 ? face / len : scene::Vec3(0, 1, 0);  // degenerate: never hit
                    for (const std::uint32_t k : i) {
                        indices.push_back(std::uint32_t(positions.size()));
                        positions.push_back(scene::transformPoint(inst.transform, g.positions[k]));
                        normals.push_back(n);
                        if (allUvs) uvs.push_back(g.uvs[k]);
                    }
                }
                continue;
            }
            const std::uint32_t base = std::uint32_t(positions.size());
            for (const scene::Vec3& p : g.positions) positions.push_back(scene::transformPoint(inst.transform, p));
            for (const scene::Vec3& n : g.normals) normals.push_back(glm::normalize(nm * n));
            if (allUvs) uvs.insert(uvs.end(), g.uvs.begin(), g.uvs.end());
            for (std::uint32_t i : g.indices) indices.push_back(base + i);
            continue;
        }
        auto [it, added] = blasOf.emplace(&g, int(meshes_.size()));
        if (added) buildMesh(g.positions, g.normals, g.indices, g.uvs);
        InstanceData in;
        in.blas = it->second;
        const glm::dmat4 toWorld(inst.transform);
        const glm::dmat4 toObject = glm::inverse(toWorld);
        in.toWorld = Affine(inst.transform);
        in.toObject = Affine(glm::dmat4x3(toObject));
        in.normalToWorld = glm::mat<3, 3, Real, glm::defaultp>(scene::normalMatrix(inst.transform));
        for (int c = 0; c < 4; ++c) {
            in.absToWorld[c] = glm::abs(in.toWorld[c]);
            in.absToObject[c] = glm::abs(in.toObject[c]);
        }
        // R = toObject·toWorld − I with the stored (Real) matrices, evaluated in long double
        // (products of two floats are exact; of two doubles nearly so), plus γ(4) of the
        // magnitudes in long double as the bound on that evaluation's own rounding.
        using L = long double;
        const L gammaL4 =
            4 * (std::numeric_limits<L>::epsilon() / 2) / (1 - 4 * (std::numeric_limits<L>::epsilon() / 2));
        for (int c = 0; c < 4; ++c)
            for (int r = 0; r < 3; ++r) {
                L sum = c == 3 ? L(in.toObject[3][r]) : 0, mag = c == 3 ? std::abs(L(in.toObject[3][r])) : 0;
                for (int k = 0; k < 3; ++k) {
                    const L prod = L(in.toObject[k][r]) * L(in.toWorld[c][k]);
                    sum += prod;
                    mag += std::abs(prod);
                }
                if (c == r) sum -= 1;
                in.inverseError[c][r] =
                    roundUp<Real>(double((std::abs(sum) + gammaL4 * (mag + 1)) * (1 + 4 * gammaL4)));
            }
        // World box of the placed mesh, padded so that rounding in the ray's transform never
        // culls an instance at its silhouette (the object-space test decides; tolerances.h).
        scene::Bounds local, world;
        for (const scene::Vec3& p : g.positions) local.extend(p);
        for (int k = 0; k < 8; ++k)
            world.extend(scene::transformPoint(
                inst.transform, scene::Vec3((k & 1) ? local.max.x : local.min.x, (k & 2) ? local.max.y : local.min.y,
                                            (k & 4) ? local.max.z : local.min.z)));
        const double pad = kInstanceBoxPad * (world.maxAbsCoordinate() + world.diagonal());
        world.min -= scene::Vec3(pad);
        world.max += scene::Vec3(pad);
        instanceBounds.push_back(world);
        mo.instances.push_back(in);
    }
    if (!indices.empty()) {
        if (!allUvs) uvs.clear();
        mo.flat = buildMesh(positions, normals, indices, uvs);
    }
    if (!mo.instances.empty()) mo.top = Bvh8::build(instanceBounds);
    return mo;
}

template <typename Real>
int Tracer<Real>::buildMesh(const std::vector<scene::Vec3>& positions, const std::vector<scene::Vec3>& normals,
                            const std::vector<std::uint32_t>& indices, const std::vector<scene::Vec2>& uvs) {
    MeshData d;
    if (uvs.size() == positions.size()) {
        d.uvs.reserve(uvs.size());
        for (const scene::Vec2& uv : uvs) d.uvs.emplace_back(uv);
    }
    d.positions.reserve(positions.size());
    for (const scene::Vec3& p : positions) d.positions.push_back(toReal<Real>(p));
    if (normals.size() == positions.size()) {
        d.normals.reserve(normals.size());
        for (const scene::Vec3& n : normals) d.normals.push_back(toReal<Real>(n));
    }
    d.indices = indices;
    std::vector<scene::Bounds> triBounds(indices.size() / 3);
    for (std::size_t t = 0; t < triBounds.size(); ++t)
        for (int k = 0; k < 3; ++k) triBounds[t].extend(positions[indices[3 * t + k]]);
    // The reference keeps the double build's tree; the float tracer takes the float build's
    // (closest-hit ties go to the lowest triangle index, so the hits do not depend on the tree).
    if constexpr (std::is_same_v<Real, float>)
        d.bvh = detail::fastFloatBuild() ? Bvh8::buildFast(triBounds, d.positions, d.indices) : Bvh8::build(triBounds);
    else
        d.bvh = Bvh8::build(triBounds);
    const std::vector<std::uint32_t>& slots = d.bvh.primitives();
    if constexpr (std::is_same_v<Real, float>) {
        d.packets.resize(slots.size() / WideRef::kLeafAlign);
        for (std::size_t s = 0; s < slots.size(); ++s) {
            TrianglePacket& pk = d.packets[s / 4];
            for (int k = 0; k < 3; ++k)
                for (int a = 0; a < 3; ++a)
                    pk.v[3 * k + a][s % 4] = slots[s] == WideRef::kEmpty
                                                 ? std::numeric_limits<float>::quiet_NaN()
                                                 : d.positions[d.indices[3 * std::size_t(slots[s]) + k]][a];
        }
    } else {
        d.slotVertices.reserve(3 * slots.size());
        for (std::uint32_t tri : slots)
            for (int k = 0; k < 3; ++k)
                d.slotVertices.push_back(tri == WideRef::kEmpty ? Vec(0)
                                                                : d.positions[d.indices[3 * std::size_t(tri) + k]]);
    }
    uniqueTriangles_ += triBounds.size();
    meshes_.push_back(std::move(d));
    return int(meshes_.size()) - 1;
}

template <typename Real>
bool Tracer<Real>::intersectMesh(const MeshData& m, const Ray<Real>& ray, Real& tBest, bool conservative, bool anyHit,
                                 Hit<Real>& hit, const AlphaData* alpha, Real cutoff) const {
    MaskFilter<Real> mask;
    if (alpha) {
        mask.on = true;
        mask.cutoff = cutoff;
        mask.factor = alpha->factor;
        mask.texture = alpha->texture.get();
        mask.slotPrims = m.bvh.primitives().data();
        mask.indices = m.indices.data();
        mask.uvs = m.uvs.empty() ? nullptr : m.uvs.data();
    }
    auto record = [&](std::uint32_t slot, Real t, Real b0, Real b1, Real b2) {
        hit.t = t;
        hit.prim = int(m.bvh.primitives()[slot]);
        hit.b0 = b0;
        hit.b1 = b1;
        hit.b2 = b2;
    };
    if constexpr (std::is_same_v<Real, float>) {
        SlotHit sh;
        // Any hit: first the packet that blocked this thread's previous any-hit ray in this
        // tree (docs/raytrace.md, "Occluder cache"). Neighbouring shadow rays are mostly
        // blocked by the same triangles, so this often answers without a walk; a hit there is
        // a hit of the same exact test, so the boolean answer cannot change.
        OccluderCache::Entry* cached = nullptr;
        // (Not for MASK meshes: the cached packet would need the alpha test too; they walk.)
        if (anyHit && !mask.on && occluderCacheOn.load(std::memory_order_relaxed)) {
            const std::uint32_t blas = std::uint32_t(&m - meshes_.data());
            cached = &occluderCache.entries[blas % OccluderCache::kEntries];
            if (cached->tracer != id_ || cached->blas != blas) {
                cached->tracer = id_;
                cached->blas = blas;
                cached->valid = false;
            } else if (cached->valid) {
                const Triangle4Ray r4(ray);
                const TrianglePacket& pk = m.packets[cached->packet];
                int cand = triangle4Candidates(r4, pk, tBest, 0xF);
                while (cand != 0) {
                    const int l = __builtin_ctz(unsigned(cand));
                    cand &= cand - 1;
                    float t, b0, b1, b2;
                    if (!intersectTriangle(ray, pk.vertex(l, 0), pk.vertex(l, 1), pk.vertex(l, 2), tBest, conservative,
                                           t, b0, b1, b2))
                        continue;
                    tBest = t;
                    record(4 * cached->packet + std::uint32_t(l), t, b0, b1, b2);
                    ++occluderCacheHitCount;
                    return true;
                }
            }
        }
#if defined(SHADOWLAB_AVX_BOX_TEST)
        const bool found = detail::useAvx() && detail::useAvx2() && detail::avx2BoxTestApplies(ray)
                               ? traverseFloatAvx2(m.bvh, m.packets, ray, tBest, conservative, anyHit, sh, mask)
                           : detail::useAvx()
                               ? traverseFloatAvx(m.bvh, m.packets, ray, tBest, conservative, anyHit, sh, mask)
                               : traverseFloat<detail::ChildBoxTest<float, 8>>(m.bvh, m.packets, ray, tBest,
                                                                               conservative, anyHit, sh, mask);
#else
        const bool found =
            traverseFloat<detail::ChildBoxTest<float, 8>>(m.bvh, m.packets, ray, tBest, conservative, anyHit, sh, mask);
#endif
        if (found) record(sh.slot, sh.t, sh.b0, sh.b1, sh.b2);
        if (cached) {
            // Only a ray that was blocked leaves a packet to try: after an unblocked ray the
            // next one goes straight to the walk, so mostly-lit scenes pay nothing for the cache.
            cached->valid = found;
            cached->packet = sh.slot / 4;
        }
        return found;
    } else {
        auto leaf = [&](std::uint32_t first, std::uint32_t count, Real& tm) {
            bool any = false;
            for (std::uint32_t slot = first; slot < first + count; ++slot) {
                const Vec* v = &m.slotVertices[3 * std::size_t(slot)];
                Real t, b0, b1, b2;
                if (!intersectTriangle(ray, v[0], v[1], v[2], tm, conservative, t, b0, b1, b2)) continue;
                if (mask.rejects(slot, b0, b1, b2)) continue;
                tm = t;
                record(slot, t, b0, b1, b2);
                if (anyHit) return true;
                any = true;
            }
            return any;
        };
#if defined(SHADOWLAB_AVX_BOX_TEST)
        if (detail::useAvx()) return traverseDoubleAvx(m.bvh, ray, tBest, anyHit, leaf);
#endif
        return m.bvh.traverse(ray, tBest, anyHit, leaf);
    }
}

template <typename Real>
bool Tracer<Real>::intersectObject(int object, const Ray<Real>& ray, Real tMax, bool conservative, bool anyHit,
                                   Hit<Real>& hit, scene::AlphaTest alphaTest) const {
    const ObjectData& od = objects_[object];
    // Shadow rays drop MASK texels below the cutoff (BLEND attenuates: transmittance()); camera
    // rays drop those and BLEND texels below scene::kBlendVisibleAlpha (cameraCutoff).
    const AlphaData* mask = nullptr;
    Real cutoff = 0;
    if (od.alpha >= 0) {
        const AlphaData& a = alphas_[std::size_t(od.alpha)];
        if (alphaTest == scene::AlphaTest::Shadow && a.mode == scene::AlphaMode::Mask) {
            mask = &a;
            cutoff = a.cutoff;
        } else if (alphaTest == scene::AlphaTest::Camera) {
            mask = &a;
            cutoff = a.cameraCutoff;
        }
    }
    // An analytic shape's one hit, tested like a mesh's (a sphere's or box's alpha is constant).
    auto cut = [&](Hit<Real>& h) {
        return mask && mask->factor * (mask->texture ? textureAlpha(od, ray, h) : Real(1)) < cutoff;
    };
    switch (od.kind) {
        case ShapeKind::Sphere: {
            const SphereData& s = spheres_[od.index];
            Real t;
            if (!intersectSphere(ray, s.center, s.radius, tMax, conservative, t)) return false;
            hit.t = t;
            hit.object = object;
            hit.prim = 0;
            return !cut(hit);
        }
        case ShapeKind::Quad: {
            const QuadData& q = quads_[od.index];
            Real t;
            if (!intersectPlane(ray, q.center, q.normal, tMax, conservative, t)) return false;
            // The rectangle's edges need no robustness: only the plane decides self-hits.
            const Vec rel = ray.o + t * ray.d - q.center;
            if (!(std::abs(glm::dot(rel, q.uAxis)) <= q.halfU && std::abs(glm::dot(rel, q.vAxis)) <= q.halfV))
                return false;
            hit.t = t;
            hit.object = object;
            hit.prim = 0;
            return !cut(hit);
        }
        case ShapeKind::Box: {
            const BoxData& b = boxes_[od.index];
            Real t;
            int face;
            if (!intersectBox(ray, b.lo, b.hi, tMax, t, face)) return false;
            hit.t = t;
            hit.object = object;
            hit.prim = face;
            return !cut(hit);
        }
        case ShapeKind::Mesh: {
            const MeshObjectData& mo = meshObjects_[od.index];
            Real tBest = tMax;
            bool found = false;
            if (mo.flat >= 0 && intersectMesh(meshes_[mo.flat], ray, tBest, conservative, anyHit, hit, mask, cutoff)) {
                hit.object = object;
                hit.instance = -1;
                if (anyHit) return true;
                found = true;
            }
            if (mo.instances.empty()) return found;
            const std::vector<std::uint32_t>& slots = mo.top.primitives();
            return mo.top.traverse(ray, tBest, anyHit, [&](std::uint32_t first, std::uint32_t count, Real& tm) {
                bool any = false;
                for (std::uint32_t slot = first; slot < first + count; ++slot) {
                    const InstanceData& in = mo.instances[slots[slot]];
                    // The ray in object space: t keeps its meaning (affine map, d not normalized).
                    const Ray<Real> local(applyPoint(in.toObject, ray.o), applyVector(in.toObject, ray.d));
                    if (!intersectMesh(meshes_[in.blas], local, tm, conservative, anyHit, hit, mask, cutoff)) continue;
                    hit.object = object;
                    hit.instance = int(slots[slot]);
                    if (anyHit) return true;
                    any = true;
                }
                return any;
            }) || found;
        }
    }
    return false;
}

template <typename Real>
bool Tracer<Real>::closestHit(const Ray<Real>& ray, Real tMax, bool conservative, Hit<Real>& hit) const {
    bool found = false;
    for (int i = 0; i < objectCount(); ++i) {
        Hit<Real> h;
        if (intersectObject(i, ray, tMax, conservative, false, h, scene::AlphaTest::Camera)) {
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
SurfacePoint<Real> Tracer<Real>::surfacePoint(const Ray<Real>& ray, const Hit<Real>& hit, bool robust) const {
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
            const MeshObjectData& mo = meshObjects_[od.index];
            const InstanceData* in = hit.instance >= 0 ? &mo.instances[hit.instance] : nullptr;
            const MeshData& m = meshes_[in ? in->blas : mo.flat];
            const std::uint32_t* ix = &m.indices[3 * std::size_t(hit.prim)];
            const Vec& p0 = m.positions[ix[0]];
            const Vec& p1 = m.positions[ix[1]];
            const Vec& p2 = m.positions[ix[2]];
            Vec po(0), poError(0);  // robust: the point in the triangles' own space, and its bound
            if (robust) {
                // Barycentric interpolation: error ≤ γ(7)·Σ|b_i·p_i| (pbrt-v4
                // Triangle::InteractionFromIntersection, derived in pbrt-v3 §3.9.4).
                po = hit.b0 * p0 + hit.b1 * p1 + hit.b2 * p2;
                poError = gamma<Real>(7) * (glm::abs(hit.b0 * p0) + glm::abs(hit.b1 * p1) + glm::abs(hit.b2 * p2));
                sp.p = po;
                sp.pError = poError;
                if (in) {
                    // To world space with pbrt-v4's bound for a point that carries an error
                    // (Transform::operator()(Point3fi), pbrt-v3 §3.9.3): (1 + γ(3))·|M|·e +
                    // γ(3)·(|M|·|p| + |t|). The exact surface is the stored M applied exactly.
                    sp.p = applyPoint(in->toWorld, po);
                    const Vec mErr = applyVector(in->absToWorld, poError);
                    sp.pError = (1 + gamma<Real>(3)) * mErr + gamma<Real>(3) * applyPoint(in->absToWorld, glm::abs(po));
                }
            }
            Vec ng = glm::cross(p1 - p0, p2 - p0);
            Vec ns(0);
            if (!m.normals.empty())
                ns = hit.b0 * m.normals[ix[0]] + hit.b1 * m.normals[ix[1]] + hit.b2 * m.normals[ix[2]];
            if (in) {  // normals by the inverse transpose
                ng = in->normalToWorld * ng;
                ns = in->normalToWorld * ns;
            }
            sp.ng = glm::normalize(ng);
            const Real len = glm::length(ns);
            sp.ns = len > 0 ? ns / len : sp.ng;
            if (glm::dot(sp.ns, sp.ng) < 0) sp.ns = -sp.ns;  // winding decides the side
            if (robust && in) {
                sp.errorAlongNormal = glm::dot(glm::abs(sp.ng), sp.pError);
                // A shadow ray from o ≈ p is taken back to object space as toObject·o, which
                // differs from the exact preimage of o by at most e = γ(3)·(|toObject|·|o| +
                // |t'|) (the product's rounding) + |R|·|x| (toObject is not exactly toWorld's
                // inverse; x ≈ po the preimage). That moves the origin by |M|·e in world space,
                // so the offset grows by that much along the normal; the factor 2 covers
                // |o| ≥ |p| by the offset itself and the rounding of these bounds.
                const Vec e = Real(2) * (gamma<Real>(3) * applyPoint(in->absToObject, glm::abs(sp.p)) +
                                         applyPoint(in->inverseError, glm::abs(po)));
                sp.errorAlongNormal += glm::dot(glm::abs(sp.ng), applyVector(in->absToWorld, e));
            }
            break;
        }
    }
    if (robust && od.kind != ShapeKind::Quad && od.kind != ShapeKind::Box &&
        !(od.kind == ShapeKind::Mesh && hit.instance >= 0))
        sp.errorAlongNormal = glm::dot(glm::abs(sp.ng), sp.pError);
    // Two-sided surfaces: the normals face the side the ray came from.
    if (glm::dot(sp.ng, ray.d) > 0) {
        sp.ng = -sp.ng;
        sp.ns = -sp.ns;
        sp.backFacing = true;
    }
    return sp;
}

template <typename Real>
std::size_t Tracer<Real>::meshBytes() const {
    std::size_t n = 0;
    for (const MeshData& m : meshes_)
        n += m.positions.capacity() * sizeof(Vec) + m.normals.capacity() * sizeof(Vec) +
             m.indices.capacity() * sizeof(std::uint32_t) + m.bvh.bytes() +
             m.packets.capacity() * sizeof(TrianglePacket) + m.slotVertices.capacity() * sizeof(Vec) +
             m.uvs.capacity() * sizeof(m.uvs[0]);
    for (const MeshObjectData& mo : meshObjects_) n += mo.instances.capacity() * sizeof(InstanceData) + mo.top.bytes();
    return n;
}

template class Tracer<float>;
template class Tracer<double>;

}  // namespace shadowlab::raytrace
