// scene/mesh_loader.h: OBJ and glTF/GLB triangle meshes (double precision) in object space,
// each placed by a transform; a mesh that several glTF nodes or objects use is read once.
// Non-finite vertices, out-of-range indices and unreadable files are errors; degenerate
// triangles are dropped and counted; missing normals are computed (glTF: flat, as its spec
// requires; OBJ and PLY: area-weighted).
#pragma once

#include <cstdint>
#include <filesystem>
#include <map>
#include <memory>
#include <string>
#include <vector>

#include <glm/glm.hpp>

#include "scene/error.h"
#include "scene/scene.h"

namespace shadowlab::scene {

// What a glTF file holds besides triangles: its perspective cameras and KHR_lights_punctual
// lights, in the file's world space (not moved by the object transform).
struct GltfCamera {
    std::string name, nodeName;  // the camera's and its node's "name" ("" when unnamed)
    Vec3 position{0, 0, 0}, forward{0, 0, -1}, up{0, 1, 0};
    double yfovRadians = 0.0, znear = 0.0, zfar = 0.0, aspect = 0.0;  // zfar/aspect 0: unset
    int width = 0, height = 0;  // extras.shadowlab.resolution of a shadowlab export; 0: unset
};
struct GltfLight {
    int index = -1;    // in KHR_lights_punctual.lights
    std::string type;  // "directional" | "point" | "spot"
    Vec3 position{0, 0, 0}, direction{0, 0, -1}, color{1, 1, 1};
    double intensity = 1.0;         // lux (directional) or candela (point, spot)
    double outerConeRadians = 0.0;  // spot
    double innerConeRadians = 0.0;  // spot
    double radius = 0.0;            // extras.shadowlab.radius of a shadowlab export (a spherical light)
};
struct GltfExtras {
    std::vector<GltfCamera> cameras;
    std::vector<GltfLight> lights;
    // Animations whose translation or rotation channels move a camera's node; `camera` indexes
    // `cameras` (scene/camera_animation.h samples them).
    std::vector<CameraAnimation> cameraAnimations;
    // With MeshRequest::perMaterial: the file's materials in its order (alpha mode, cutoff,
    // baseColorFactor alpha and, for MASK and BLEND, the baseColorTexture's alpha).
    std::vector<Material> materials;
    // asset.extras.shadowlab is present: the file is a `shadowlab export` (scene/gltf_export.h).
    bool shadowlabExport = false;
    // What reading had to assume, for the user to see (a texture whose image file is missing).
    std::vector<std::string> notes;
    std::uint64_t loadBytes = 0;  // the file's temporaries while it was read (text, trees, buffers)
};

// What to read besides positions and normals.
struct MeshRequest {
    // TEXCOORD_n (glTF) or vt (OBJ) for every triangle: the set a JSON object's textured
    // material names; -1: none.
    int uvSet = -1;
    // glTF: one geometry per (mesh, material) with MeshInstance::fileMaterial set, the
    // materials in GltfExtras::materials and the UVs each MASK/BLEND texture needs (a model
    // given as the scene).
    bool perMaterial = false;
};

// Each mesh file read once per scene: objects that name the same file share its geometries
// (the key is the file's canonical path).
struct MeshCache {
    std::map<std::string, std::vector<MeshInstance>> files;
    std::map<std::string, GltfExtras> extras;  // each glTF file's cameras and lights
    std::uint64_t peakLoadBytes = 0;           // the largest file's temporaries while it was read
};

// Reads `meshFile`: one instance for an OBJ file, one per node that uses a mesh for glTF (the
// node hierarchy applied; a glTF mesh used by several nodes is one shared geometry), each then
// placed by `transform` (object to world). Errors name `sceneFile` and `path` (the JSON path of
// the object's "file" key) as well as the mesh file. For glTF files, `extras` (when given)
// receives the file's cameras and lights, also when the file was read earlier into `cache`.
std::vector<MeshInstance> loadMeshInstances(const std::filesystem::path& meshFile, const glm::dmat4& transform,
                                            const std::filesystem::path& sceneFile, const JsonPath& path,
                                            GltfExtras* extras = nullptr, MeshCache* cache = nullptr,
                                            const MeshRequest& request = {});

// Copies every instance into one world-space mesh (positions transformed, normals by the
// inverse transpose): for tools and tests that want one flat triangle list.
TriangleMesh flattenInstances(const std::vector<MeshInstance>& instances);

// loadMeshInstances, flattened.
std::shared_ptr<const TriangleMesh> loadMesh(const std::filesystem::path& meshFile, const glm::dmat4& transform,
                                             const std::filesystem::path& sceneFile, const JsonPath& path,
                                             GltfExtras* extras = nullptr);

// translate · Rz · Ry · Rx · scale, angles in degrees (a rotation about X is applied first).
glm::dmat4 objectTransform(const Vec3& translate, const Vec3& rotateDegrees, const Vec3& scale);

// Removes degenerate triangles and fills in missing normals; used by every mesh source.
void finalizeMesh(TriangleMesh& mesh);

}  // namespace shadowlab::scene
