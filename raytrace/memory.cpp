// raytrace/memory.cpp: the ray tracer's memory estimate (see raytrace/memory.h).
#include "raytrace/memory.h"

#include <variant>

#include "scene/memory.h"

namespace shadowlab::raytrace {

std::uint64_t estimateMemoryBytes(const scene::Scene& scene, const scene::RenderPlan& plan) {
    std::uint64_t triangles = 0, vertices = 0;
    if (plan.needsTriangleBvh)
        for (const scene::Object& o : scene.objects)
            if (const auto* m = std::get_if<scene::Mesh>(&o.shape)) {
                triangles += m->triangleCount();
                for (const scene::MeshInstance& inst : m->instances)
                    if (inst.geometry) vertices += inst.geometry->positions.size();
            }
    // 100 bytes a triangle hold half a vertex a triangle (a closed mesh sharing its vertices has
    // about that many, by Euler's formula); a mesh with more (a glTF without normals loads flat,
    // three a triangle) adds each further vertex's float position and normal (24 bytes), and while
    // the tree is built the world-space double copy of both that a mesh placed once is merged
    // through (48 bytes; raytrace/tracer.cpp).
    const std::uint64_t extraVertices = 2 * vertices > triangles ? vertices - triangles / 2 : 0;
    constexpr std::uint64_t kAllowance = 64 * scene::kMiB;  // threads' stacks, tiles, the program
    std::uint64_t placements = 0;                           // one BVH entry per object, and per mesh instance
    for (const scene::Object& o : scene.objects)
        if (const auto* m = std::get_if<scene::Mesh>(&o.shape)) placements += m->instances.size();
    // Texture coordinates: three per alpha-textured triangle, two Reals each (double: 48 bytes).
    return kAllowance + scene::frameBytes(scene) + triangles * 100 + extraVertices * (24 + 48) +
           scene::alphaTexturedTriangles(scene) * 48 +
           (scene.objects.size() + placements) * scene::kBackendBytesPerObject;
}

}  // namespace shadowlab::raytrace
