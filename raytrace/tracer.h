// raytrace/tracer.h: the scene converted to Real (float for the method, double for the
// reference) with one BVH per geometry (meshes placed once merged in world space per object,
// meshes placed several times shared in object space under a top-level tree of their
// instances), and the queries every pass is built from: closest hit,
// any hit, per-object hits and the surface point (position, error bound, normals) of a hit.
#pragma once

#include <cstdint>
#include <map>
#include <memory>
#include <vector>

#include "raytrace/intersect.h"
#include "raytrace/real.h"
#include "raytrace/triangle4.h"
#include "raytrace/wide_bvh.h"
#include "scene/scene.h"

namespace shadowlab::raytrace {

template <typename Real>
struct Hit {
    Real t = std::numeric_limits<Real>::infinity();
    int object = -1;              // index into Scene::objects
    int prim = 0;                 // mesh: triangle index; box: face (axis + 3 on the max side)
    int instance = -1;            // mesh: the instance hit (index in its object), -1 for world-space triangles
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
    // The ray met the surface from behind: against a triangle's winding, from inside a sphere or
    // a box, from a quad's back (the view search tells rooms from solids by it).
    bool backFacing = false;
};

enum class ShapeKind : std::uint8_t { Sphere, Quad, Box, Mesh };

template <typename Real>
class Tracer {
public:
    using Vec = Vec3T<Real>;

    // Converts every object to Real and builds the mesh trees (the "setup" stage).
    explicit Tracer(const scene::Scene& scene);

    // Nearest hit with 0 < t < tMax. Conservative: reject hits whose t could be <= 0 under
    // rounding (used with robust offsets). Camera rays: MASK texels below the cutoff and BLEND
    // texels below scene::kBlendVisibleAlpha are no hit (scene::Material::cameraSkips).
    bool closestHit(const Ray<Real>& ray, Real tMax, bool conservative, Hit<Real>& hit) const;
    // Any hit with 0 < t < tMax; `blocker` gets the object index of the first found. Shadow
    // rays: alpha-tested (MASK) texels below their cutoff are no hit.
    bool anyHit(const Ray<Real>& ray, Real tMax, bool conservative, int& blocker) const;
    // Hits on one object only. With anyHit, the first hit found rather than the nearest.
    // alpha: which hits the alpha test of scene::Material drops (scene::AlphaTest).
    bool intersectObject(int object, const Ray<Real>& ray, Real tMax, bool conservative, bool anyHit, Hit<Real>& hit,
                         scene::AlphaTest alpha = scene::AlphaTest::Shadow) const;
    // The light a hit on a non-opaque object lets through: 1 − opacity, or for BLEND
    // 1 − opacity·alpha(uv) with the alpha at the hit (scene::Material::transmittance).
    double transmittance(const Ray<Real>& ray, const Hit<Real>& hit) const;
    bool opaqueObject(int object) const { return objects_[object].opaque; }

    // Position and normals of a hit. Plain mode is the lesson's p = o + t·d. Robust mode
    // recomputes p from the surface (sphere: reprojected; quad: projected onto its plane, axis-
    // aligned ones snapped; box: face snapped; triangle: barycentric) with an error bound.
    SurfacePoint<Real> surfacePoint(const Ray<Real>& ray, const Hit<Real>& hit, bool robust) const;

    int objectCount() const { return int(objects_.size()); }
    ShapeKind kind(int object) const { return objects_[object].kind; }
    double opacity(int object) const { return objects_[object].opacity; }
    // Placed triangles: an instanced mesh counts once per instance (what the scene shows).
    std::size_t triangleCount() const { return triangles_; }
    // Triangles stored: an instanced mesh counts once (what memory is spent on).
    std::size_t uniqueTriangleCount() const { return uniqueTriangles_; }
    // Bytes held for meshes: vertices, normals, indices, BVH nodes, slot table, the
    // slot-ordered triangle copies, instances and their top-level trees (capacities, so what is
    // really allocated). Per triangle, divide by uniqueTriangleCount().
    std::size_t meshBytes() const;
    // Bottom-level structures built (world-space meshes plus one per instanced geometry).
    std::size_t blasCount() const { return meshes_.size(); }

private:
    struct ObjectData {
        ShapeKind kind;
        int index;  // into the array of its kind
        double opacity;
        bool opaque = true;  // scene::Material::opaque()
        int alpha = -1;      // into alphas_: a MASK or BLEND material
    };

public:
    // An object's alpha (MASK or BLEND); the texture is shared with the scene's material.
    struct AlphaData {
        scene::AlphaMode mode = scene::AlphaMode::Opaque;
        Real cutoff = 0, factor = 1;
        std::shared_ptr<const scene::AlphaTexture> texture;  // may be null (constant alpha)
        Real cameraCutoff = 0;     // the camera's: the cutoff (MASK) or scene::kBlendVisibleAlpha (BLEND)
        scene::Material material;  // for transmittance(): the same formula as the scene's
    };

private:
    struct SphereData {
        Vec center;
        Real radius;
    };
    struct QuadData {
        Vec center;
        Vec normal;  // the plane is exactly {x : normal·(x − center) = 0} in Real
        Vec uAxis, vAxis;
        Real halfU, halfV;
        glm::vec<2, Real, glm::defaultp> uvMin{0}, uvMax{1};  // texture coordinates at the −/+ corners
        int snapAxis;  // axis the normal is along, when the plane is axis-aligned; else -1
    };
    struct BoxData {
        Vec lo, hi;
    };
    // A bottom-level structure: triangles with their BVH, in world space (every mesh used
    // once, its instances merged per object) or in object space (a mesh placed several times).
    struct MeshData {
        std::vector<Vec> positions;
        std::vector<Vec> normals;  // per vertex, may be empty
        std::vector<std::uint32_t> indices;
        std::vector<glm::vec<2, Real, glm::defaultp>> uvs;  // per vertex, only for alpha textures
        Bvh8 bvh;
        // The triangles' vertices again in BVH slot order, so a leaf reads contiguous memory
        // with no index indirection: float keeps SSE packets of four triangles (one per four
        // slots), double keeps three vertices per slot; the other vector stays empty.
        std::vector<TrianglePacket> packets;
        std::vector<Vec> slotVertices;
    };

    // Object space → world space and back in Real, 4x3 (m[column][row]); applied as pbrt-v4's
    // Transform applies a point, (m00·x + m01·y) + (m02·z + m03), which its γ(3) bound assumes.
    using Affine = glm::mat<4, 3, Real, glm::defaultp>;
    struct InstanceData {
        int blas;  // into meshes_
        Affine toWorld, toObject;
        glm::mat<3, 3, Real, glm::defaultp> normalToWorld;  // inverse transpose of toWorld's linear part
        // Robust offsets (docs/raytrace.md, "Instances"): |toWorld|, |toObject| and a bound on
        // |toObject·toWorld − I| (the stored inverse is not the exact inverse of the stored
        // transform), linear part and translation.
        Affine absToWorld, absToObject, inverseError;
    };
    struct MeshObjectData {
        int flat = -1;  // the object's meshes used once, merged in world space; -1 if none
        std::vector<InstanceData> instances;
        Bvh8 top;  // over the instances' world boxes
    };

    MeshObjectData buildMeshObject(const scene::Object& obj, const scene::Mesh& m,
                                   const std::map<const scene::TriangleMesh*, int>& uses,
                                   std::map<const scene::TriangleMesh*, int>& blasOf);
    bool intersectMesh(const MeshData& m, const Ray<Real>& ray, Real& tMax, bool conservative, bool anyHit,
                       Hit<Real>& hit, const AlphaData* mask = nullptr, Real cutoff = 0) const;
    int buildMesh(const std::vector<scene::Vec3>& positions, const std::vector<scene::Vec3>& normals,
                  const std::vector<std::uint32_t>& indices, const std::vector<scene::Vec2>& uvs = {});
    // The texture's alpha at a hit (1 without a texture).
    Real textureAlpha(const ObjectData& od, const Ray<Real>& ray, const Hit<Real>& hit) const;

    std::vector<ObjectData> objects_;
    std::vector<SphereData> spheres_;
    std::vector<QuadData> quads_;
    std::vector<BoxData> boxes_;
    std::vector<MeshData> meshes_;
    std::vector<MeshObjectData> meshObjects_;
    std::vector<AlphaData> alphas_;
    std::size_t triangles_ = 0;
    std::size_t uniqueTriangles_ = 0;
    std::uint64_t id_;  // unique per tracer, keys the per-thread occluder cache
};

// Float any-hit queries first test the packet that blocked the same thread's previous any-hit
// ray in the same tree (on by default; docs/raytrace.md, "Occluder cache"). Off only to measure
// or test without it; answers are the same either way.
void setOccluderCache(bool on);
bool occluderCacheEnabled();
std::uint64_t occluderCacheHits();  // answered by the cache on this thread so far (for tests)

extern template class Tracer<float>;
extern template class Tracer<double>;

}  // namespace shadowlab::raytrace
