// scene/mesh_loader.h: OBJ and glTF/GLB triangle meshes into world space (double precision).
// Non-finite vertices, out-of-range indices and unreadable files are errors; degenerate
// triangles are dropped and counted; missing normals are computed (area-weighted).
#pragma once

#include <filesystem>
#include <memory>

#include <glm/glm.hpp>

#include "scene/error.h"
#include "scene/scene.h"

namespace shadowlab::scene {

// Reads `meshFile` and applies `transform` (object to world). Errors name `sceneFile` and
// `path` (the JSON path of the object's "file" key) as well as the mesh file.
std::shared_ptr<const TriangleMesh> loadMesh(const std::filesystem::path& meshFile,
                                             const glm::dmat4& transform,
                                             const std::filesystem::path& sceneFile,
                                             const JsonPath& path);

// translate · Rz · Ry · Rx · scale, angles in degrees (a rotation about X is applied first).
glm::dmat4 objectTransform(const Vec3& translate, const Vec3& rotateDegrees, const Vec3& scale);

// Removes degenerate triangles and fills in missing normals; used by every mesh source.
void finalizeMesh(TriangleMesh& mesh);

}  // namespace shadowlab::scene
