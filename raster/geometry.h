// raster/geometry.h: the scene as triangles for the GPU. Analytic shapes are tessellated,
// meshes are taken as they are, and every position is made relative to an origin (the camera)
// in double before it becomes float, so scenes far from the world origin stay precise.
#pragma once

#include <cstdint>
#include <vector>

#include <glm/glm.hpp>

#include "scene/scene.h"

namespace shadowlab::raster {

struct Vertex {
    glm::vec3 position{0.0f};    // world position minus the origin (camera-relative)
    glm::vec3 normal{0.0f};      // unit; flat per face for boxes, per vertex for spheres and meshes
    std::uint32_t objectId = 0;  // object index + 1
};
static_assert(sizeof(Vertex) == 28, "vertex layout is declared to the pipelines with this stride");

struct SceneGeometry {
    std::vector<Vertex> vertices;
    // Per vertex, only with alpha-tested casters (tessellateScene's withUvs): quads' own
    // coordinates, meshes' TEXCOORD_n / vt, 0 elsewhere. A second vertex buffer, so that the
    // Vertex layout and scenes without alpha stay as they are.
    std::vector<glm::vec2> uvs;
    std::vector<std::uint32_t> indices;  // three per triangle
    int maxSphereSegments = 0;           // the finest sphere (0 when there is none)
    // Object i's triangles are indices objectFirstIndex[i] .. objectFirstIndex[i + 1] − 1.
    std::vector<std::uint32_t> objectFirstIndex;
    std::size_t triangleCount() const { return indices.size() / 3; }
};

// Segments around a sphere of `radius` whose nearest point is `distance` from the camera, for
// a camera with tan(fovY/2) = `tanHalfFovY` and `imageHeight` rows: the smallest n whose chord
// error r·(1 − cos(π/n)) is at most kSphereChordErrorPixels of a pixel's world size there,
// clamped to kMinSphereSegments..kMaxSphereSegments (even).
int sphereSegments(double radius, double distance, double tanHalfFovY, int imageHeight);

// Every object of `scene` as triangles, positions relative to `origin`. Throws RasterError for
// a mesh whose geometry was not loaded.
SceneGeometry tessellateScene(const scene::Scene& scene, const scene::Vec3& origin, bool withUvs = false);

}  // namespace shadowlab::raster
