// raytrace/tracer.h: the scene converted to Real (float for the method, double for the
// reference) with one BVH per mesh, and the queries every pass is built from: closest hit,
// any hit, per-object hits and the surface point (position, error bound, normals) of a hit.
#pragma once

#include <cstdint>
#include <vector>

#include "raytrace/wide_bvh.h"
#include "raytrace/intersect.h"
#include "raytrace/real.h"
#include "raytrace/triangle4.h"
#include "scene/scene.h"

namespace shadowlab::raytrace {

template <typename Real>
struct Hit {
    Real t = std::numeric_limits<Real>::infinity();
    int object = -1;  // index into Scene::objects
    int prim = 0;     // mesh: triangle index; box: face (axis + 3 on the max side)
    Real b0 = 0, b1 = 0, b2 = 0;  // mesh: barycentrics
};

template <typename Real>
struct SurfacePoint {
    using Vec = Vec3T<Real>;
    Vec p;       // the hit point
    Vec pError;  // robust mode: per-component bound on |p − exact surface point|; 0 otherwise
    // Robust mode: a bound on how far p may lie from the surface along ng, so that moving the
    // origin by more than this along ng puts it strictly on ng's side (see docs/raytrace.md).
    Real errorAlongNormal = 0;
    Vec ng;  // unit geometric normal, facing the side the ray came from
    Vec ns;  // unit shading normal, flipped together with ng
    int object = -1;
};

enum class ShapeKind : std::uint8_t { Sphere, Quad, Box, Mesh };

template <typename Real>
class Tracer {
public:
    using Vec = Vec3T<Real>;

    // Converts every object to Real and builds a BVH per mesh (the "setup" stage).
    explicit Tracer(const scene::Scene& scene);

    // Nearest hit with 0 < t < tMax. Conservative: reject hits whose t could be <= 0 under
    // rounding (used with robust offsets).
    bool closestHit(const Ray<Real>& ray, Real tMax, bool conservative, Hit<Real>& hit) const;
    // Any hit with 0 < t < tMax; `blocker` gets the object index of the first found.
    bool anyHit(const Ray<Real>& ray, Real tMax, bool conservative, int& blocker) const;
    // Hits on one object only. With anyHit, the first hit found rather than the nearest.
    bool intersectObject(int object, const Ray<Real>& ray, Real tMax, bool conservative,
                         bool anyHit, Hit<Real>& hit) const;

    // Position and normals of a hit. Plain mode is the lesson's p = o + t·d. Robust mode
    // recomputes p from the surface (sphere: reprojected; quad: projected onto its plane, axis-
    // aligned ones snapped; box: face snapped; triangle: barycentric) with an error bound.
    SurfacePoint<Real> surfacePoint(const Ray<Real>& ray, const Hit<Real>& hit, bool robust) const;

    int objectCount() const { return int(objects_.size()); }
    ShapeKind kind(int object) const { return objects_[object].kind; }
    double opacity(int object) const { return objects_[object].opacity; }
    std::size_t triangleCount() const { return triangles_; }
    // Bytes held for meshes: vertices, normals, indices, BVH nodes, slot table and the
    // slot-ordered triangle copies (capacities, so what is really allocated).
    std::size_t meshBytes() const;

private:
    struct ObjectData {
        ShapeKind kind;
        int index;  // into the array of its kind
        double opacity;
    };
    struct SphereData {
        Vec center;
        Real radius;
    };
    struct QuadData {
        Vec center;
        Vec normal;  // the plane is exactly {x : normal·(x − center) = 0} in Real
        Vec uAxis, vAxis;
        Real halfU, halfV;
        int snapAxis;  // axis the normal is along, when the plane is axis-aligned; else -1
    };
    struct BoxData {
        Vec lo, hi;
    };
    struct MeshData {
        std::vector<Vec> positions;
        std::vector<Vec> normals;  // per vertex, may be empty
        std::vector<std::uint32_t> indices;
        Bvh8 bvh;
        // The triangles' vertices again in BVH slot order, so a leaf reads contiguous memory
        // with no index indirection: float keeps SSE packets of four triangles (one per four
        // slots), double keeps three vertices per slot; the other vector stays empty.
        std::vector<TrianglePacket> packets;
        std::vector<Vec> slotVertices;
    };

    std::vector<ObjectData> objects_;
    std::vector<SphereData> spheres_;
    std::vector<QuadData> quads_;
    std::vector<BoxData> boxes_;
    std::vector<MeshData> meshes_;
    std::size_t triangles_ = 0;
};

extern template class Tracer<float>;
extern template class Tracer<double>;

}  // namespace shadowlab::raytrace
