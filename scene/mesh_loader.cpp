// scene/mesh_loader.cpp: tinyobjloader / tinygltf readers feeding one TriangleMesh format.
#include "scene/mesh_loader.h"

#include <algorithm>
#include <cmath>
#include <cstring>
#include <fstream>
#include <map>
#include <sstream>

#include <glm/gtc/matrix_transform.hpp>
#include <glm/gtc/quaternion.hpp>
#include <tiny_gltf.h>
#include <tiny_obj_loader.h>

namespace shadowlab::scene {

namespace {

namespace fs = std::filesystem;

[[noreturn]] void fail(const fs::path& sceneFile, const JsonPath& path, const fs::path& mesh,
                       const std::string& what) {
    throw SceneError(sceneFile, path, mesh.string() + ": " + what);
}

bool finite(const Vec3& v) { return std::isfinite(v.x) && std::isfinite(v.y) && std::isfinite(v.z); }

// tinyobjloader reads "nan" or "inf" coordinates as 0 without a word; find them first so a
// broken export is reported rather than silently reshaped.
void checkObjVertices(const fs::path& file, const fs::path& sceneFile, const JsonPath& path) {
    std::ifstream in(file);
    std::string line;
    for (std::size_t lineNo = 1; std::getline(in, line); ++lineNo) {
        if (line.size() < 2 || line[0] != 'v' || (line[1] != ' ' && line[1] != '\t')) continue;
        std::istringstream fields(line.substr(2));
        std::string token;
        for (int i = 0; i < 3 && fields >> token; ++i) {
            char* end = nullptr;
            const double v = std::strtod(token.c_str(), &end);
            if (end == token.c_str() || *end != '\0' || !std::isfinite(v))
                fail(sceneFile, path, file, "line " + std::to_string(lineNo) + ": vertex coordinate '" +
                                                token + "' is not a finite number");
        }
    }
}

void loadObj(const fs::path& file, TriangleMesh& mesh, const fs::path& sceneFile,
             const JsonPath& path) {
    checkObjVertices(file, sceneFile, path);
    tinyobj::ObjReaderConfig config;
    config.triangulate = true;
    config.vertex_color = false;
    config.mtl_search_path = file.parent_path().string();
    tinyobj::ObjReader reader;
    if (!reader.ParseFromFile(file.string(), config))
        fail(sceneFile, path, file, "not a readable OBJ file: " + reader.Error());
    const auto& attrib = reader.GetAttrib();
    const std::size_t vertexCount = attrib.vertices.size() / 3;
    const std::size_t normalCount = attrib.normals.size() / 3;
    bool allHaveNormals = normalCount > 0;
    std::size_t faces = 0;
    for (const auto& shape : reader.GetShapes()) {
        for (const auto& idx : shape.mesh.indices) {
            if (idx.vertex_index < 0 || std::size_t(idx.vertex_index) >= vertexCount)
                fail(sceneFile, path, file,
                     "face index " + std::to_string(idx.vertex_index + 1) + " is out of range (" +
                         std::to_string(vertexCount) + " vertices)");
            if (idx.normal_index < 0 || std::size_t(idx.normal_index) >= normalCount)
                allHaveNormals = false;
        }
        faces += shape.mesh.num_face_vertices.size();
    }
    if (faces == 0) fail(sceneFile, path, file, "has no faces");
    // One output vertex per OBJ corner keeps per-corner normals; fine for the sizes we load.
    for (const auto& shape : reader.GetShapes()) {
        for (const auto& idx : shape.mesh.indices) {
            const Vec3 p(attrib.vertices[3 * idx.vertex_index], attrib.vertices[3 * idx.vertex_index + 1],
                         attrib.vertices[3 * idx.vertex_index + 2]);
            if (!finite(p)) fail(sceneFile, path, file, "vertex " + std::to_string(idx.vertex_index + 1) + " is not finite");
            mesh.indices.push_back(std::uint32_t(mesh.positions.size()));
            mesh.positions.push_back(p);
            if (allHaveNormals)
                mesh.normals.emplace_back(attrib.normals[3 * idx.normal_index],
                                          attrib.normals[3 * idx.normal_index + 1],
                                          attrib.normals[3 * idx.normal_index + 2]);
        }
    }
    if (!allHaveNormals) mesh.normals.clear();
}

// Reads one accessor as doubles (`components` per element); validates every bound.
std::vector<double> readAccessor(const tinygltf::Model& model, int accessorIndex, int components,
                                 const fs::path& file, const fs::path& sceneFile, const JsonPath& path) {
    if (accessorIndex < 0 || std::size_t(accessorIndex) >= model.accessors.size())
        fail(sceneFile, path, file, "accessor " + std::to_string(accessorIndex) + " does not exist");
    const auto& acc = model.accessors[accessorIndex];
    if (acc.bufferView < 0 || std::size_t(acc.bufferView) >= model.bufferViews.size())
        fail(sceneFile, path, file, "accessor " + std::to_string(accessorIndex) + " has no buffer view");
    const auto& view = model.bufferViews[acc.bufferView];
    if (view.buffer < 0 || std::size_t(view.buffer) >= model.buffers.size())
        fail(sceneFile, path, file, "buffer view " + std::to_string(acc.bufferView) + " names a missing buffer");
    const auto& buffer = model.buffers[view.buffer];
    const int compSize = tinygltf::GetComponentSizeInBytes(acc.componentType);
    const int nComp = tinygltf::GetNumComponentsInType(acc.type);
    if (compSize <= 0 || nComp != components)
        fail(sceneFile, path, file, "accessor " + std::to_string(accessorIndex) + " has an unexpected type");
    const std::size_t stride = view.byteStride ? view.byteStride : std::size_t(compSize) * nComp;
    const std::size_t begin = view.byteOffset + acc.byteOffset;
    const std::size_t needed = acc.count == 0 ? 0 : begin + stride * (acc.count - 1) + std::size_t(compSize) * nComp;
    if (needed > buffer.data.size() || view.byteOffset + view.byteLength > buffer.data.size())
        fail(sceneFile, path, file, "accessor " + std::to_string(accessorIndex) + " reads past the end of its buffer");
    std::vector<double> out(acc.count * nComp);
    const unsigned char* base = buffer.data.data() + begin;
    for (std::size_t i = 0; i < acc.count; ++i) {
        for (int c = 0; c < nComp; ++c) {
            const unsigned char* p = base + i * stride + std::size_t(c) * compSize;
            double v = 0;
            switch (acc.componentType) {
                case TINYGLTF_COMPONENT_TYPE_FLOAT: { float f; std::memcpy(&f, p, 4); v = f; break; }
                case TINYGLTF_COMPONENT_TYPE_UNSIGNED_INT: { std::uint32_t u; std::memcpy(&u, p, 4); v = u; break; }
                case TINYGLTF_COMPONENT_TYPE_UNSIGNED_SHORT: { std::uint16_t u; std::memcpy(&u, p, 2); v = u; break; }
                case TINYGLTF_COMPONENT_TYPE_UNSIGNED_BYTE: v = *p; break;
                default: fail(sceneFile, path, file, "accessor " + std::to_string(accessorIndex) + " has an unsupported component type");
            }
            out[i * nComp + c] = v;
        }
    }
    return out;
}

glm::dmat4 nodeMatrix(const tinygltf::Node& node) {
    if (node.matrix.size() == 16) {
        glm::dmat4 m;
        for (int i = 0; i < 16; ++i) m[i / 4][i % 4] = node.matrix[i];
        return m;
    }
    glm::dmat4 m(1.0);
    if (node.translation.size() == 3)
        m = glm::translate(m, Vec3(node.translation[0], node.translation[1], node.translation[2]));
    if (node.rotation.size() == 4) {
        const glm::dquat q(node.rotation[3], node.rotation[0], node.rotation[1], node.rotation[2]);
        m = m * glm::mat4_cast(q);
    }
    if (node.scale.size() == 3) m = glm::scale(m, Vec3(node.scale[0], node.scale[1], node.scale[2]));
    return m;
}

// glTF textures are not needed for shadows: accept any image, even a missing one.
bool ignoreImage(tinygltf::Image*, const int, std::string*, std::string*, int, int,
                 const unsigned char*, int, void*) {
    return true;
}

// One glTF mesh (all its triangle primitives) in the mesh's own space.
void appendGltfMesh(const tinygltf::Model& model, int meshIndex, TriangleMesh& out,
                    const fs::path& file, const fs::path& sceneFile, const JsonPath& path) {
    if (meshIndex < 0 || std::size_t(meshIndex) >= model.meshes.size())
        fail(sceneFile, path, file, "node names mesh " + std::to_string(meshIndex) + ", which does not exist");
    for (const auto& prim : model.meshes[meshIndex].primitives) {
        if (prim.mode != TINYGLTF_MODE_TRIANGLES && prim.mode != -1) continue;  // points/lines cast nothing
        const auto pos = prim.attributes.find("POSITION");
        if (pos == prim.attributes.end()) fail(sceneFile, path, file, "a primitive has no POSITION");
        const std::vector<double> p = readAccessor(model, pos->second, 3, file, sceneFile, path);
        const std::size_t count = p.size() / 3;
        std::vector<double> n;
        if (const auto it = prim.attributes.find("NORMAL"); it != prim.attributes.end()) {
            n = readAccessor(model, it->second, 3, file, sceneFile, path);
            if (n.size() != p.size()) n.clear();
        }
        std::vector<double> idx;
        if (prim.indices >= 0) {
            idx = readAccessor(model, prim.indices, 1, file, sceneFile, path);
        } else {
            idx.resize(count);
            for (std::size_t i = 0; i < count; ++i) idx[i] = double(i);
        }
        const std::uint32_t base = std::uint32_t(out.positions.size());
        const bool keepNormals = !n.empty() && (out.positions.empty() || !out.normals.empty());
        if (!keepNormals) out.normals.clear();
        for (std::size_t i = 0; i < count; ++i) {
            const Vec3 v(p[3 * i], p[3 * i + 1], p[3 * i + 2]);
            if (!finite(v)) fail(sceneFile, path, file, "a vertex is not finite");
            out.positions.push_back(v);
            if (keepNormals) out.normals.emplace_back(n[3 * i], n[3 * i + 1], n[3 * i + 2]);
        }
        for (std::size_t i = 0; i + 2 < idx.size(); i += 3) {
            for (int k = 0; k < 3; ++k) {
                if (idx[i + k] >= double(count))
                    fail(sceneFile, path, file, "index " + std::to_string(std::uint64_t(idx[i + k])) +
                                                    " is out of range (" + std::to_string(count) + " vertices)");
                out.indices.push_back(base + std::uint32_t(idx[i + k]));
            }
        }
    }
}

// A node's camera and KHR_lights_punctual light, placed by the node's world transform (glTF
// cameras and lights look down their local −Z with +Y up).
void collectCameraAndLight(const tinygltf::Model& model, const tinygltf::Node& node,
                           const glm::dmat4& world, GltfExtras& out) {
    const Vec3 origin(world * glm::dvec4(0, 0, 0, 1));
    const Vec3 forward = glm::normalize(Vec3(world * glm::dvec4(0, 0, -1, 0)));
    const Vec3 up = glm::normalize(Vec3(world * glm::dvec4(0, 1, 0, 0)));
    if (node.camera >= 0 && std::size_t(node.camera) < model.cameras.size() &&
        model.cameras[node.camera].type == "perspective" && finite(forward) && finite(up)) {
        const auto& pc = model.cameras[node.camera].perspective;
        GltfCamera c;
        c.name = model.cameras[node.camera].name;
        c.nodeName = node.name;
        c.position = origin;
        c.forward = forward;
        c.up = up;
        c.yfovRadians = pc.yfov;
        c.znear = pc.znear;
        c.zfar = pc.zfar;
        c.aspect = pc.aspectRatio;
        out.cameras.push_back(c);
    }
    const auto ext = node.extensions.find("KHR_lights_punctual");
    if (ext == node.extensions.end() || !ext->second.Has("light")) return;
    const int index = ext->second.Get("light").GetNumberAsInt();
    if (index < 0 || std::size_t(index) >= model.lights.size()) return;
    const tinygltf::Light& l = model.lights[index];
    GltfLight light;
    light.type = l.type;
    light.position = origin;
    light.direction = forward;
    if (l.color.size() == 3) light.color = Vec3(l.color[0], l.color[1], l.color[2]);
    light.intensity = l.intensity;
    light.outerConeRadians = l.spot.outerConeAngle;
    out.lights.push_back(light);
}

// Placements of the file's geometries; `geometry` is still mutable while loading.
struct RawInstance {
    std::shared_ptr<TriangleMesh> geometry;
    glm::dmat4 transform;
};

void loadGltf(const fs::path& file, std::vector<RawInstance>& out, const fs::path& sceneFile,
              const JsonPath& path, GltfExtras* extras) {
    tinygltf::TinyGLTF loader;
    loader.SetImageLoader(ignoreImage, nullptr);
    tinygltf::Model model;
    std::string err, warn;
    std::string ext = file.extension().string();
    std::transform(ext.begin(), ext.end(), ext.begin(), ::tolower);
    const bool ok = ext == ".glb" ? loader.LoadBinaryFromFile(&model, &err, &warn, file.string())
                                  : loader.LoadASCIIFromFile(&model, &err, &warn, file.string());
    if (!ok) fail(sceneFile, path, file, "not a readable glTF file: " + (err.empty() ? warn : err));

    // Walk the default scene's node tree (depth first, in document order) so each node that
    // uses a mesh places it once; a mesh used by several nodes is read once and shared.
    std::vector<int> roots;
    const int sceneIndex = model.defaultScene >= 0 ? model.defaultScene : 0;
    if (std::size_t(sceneIndex) < model.scenes.size()) roots = model.scenes[sceneIndex].nodes;
    else for (std::size_t i = 0; i < model.nodes.size(); ++i) roots.push_back(int(i));
    std::vector<std::shared_ptr<TriangleMesh>> meshes(model.meshes.size());
    std::vector<std::pair<int, glm::dmat4>> stack;
    for (auto r = roots.rbegin(); r != roots.rend(); ++r) stack.emplace_back(*r, glm::dmat4(1.0));
    // glTF nodes form a forest (glTF 2.0 spec, 3.5.3: a node has at most one parent and no
    // cycles), so a walk reaches each node once; a second visit means a cycle or a shared child,
    // which would otherwise loop forever or grow exponentially (found by fuzzing).
    std::vector<char> visited(model.nodes.size(), 0);
    while (!stack.empty()) {
        auto [nodeIndex, parent] = stack.back();
        stack.pop_back();
        if (nodeIndex < 0 || std::size_t(nodeIndex) >= model.nodes.size())
            fail(sceneFile, path, file, "the node hierarchy names node " + std::to_string(nodeIndex) +
                                            ", which does not exist (" + std::to_string(model.nodes.size()) +
                                            " nodes)");
        if (visited[nodeIndex]++)
            fail(sceneFile, path, file, "node " + std::to_string(nodeIndex) +
                                            " is reached twice in the node hierarchy (a cycle, or a node "
                                            "with two parents); glTF nodes must form trees");
        const auto& node = model.nodes[nodeIndex];
        const glm::dmat4 world = parent * nodeMatrix(node);
        if (node.mesh >= 0) {
            if (std::size_t(node.mesh) >= model.meshes.size())
                fail(sceneFile, path, file, "node names mesh " + std::to_string(node.mesh) + ", which does not exist");
            auto& geometry = meshes[node.mesh];
            if (!geometry) {
                geometry = std::make_shared<TriangleMesh>();
                appendGltfMesh(model, node.mesh, *geometry, file, sceneFile, path);
            }
            out.push_back({geometry, world});
        }
        if (extras) collectCameraAndLight(model, node, world, *extras);
        for (auto c = node.children.rbegin(); c != node.children.rend(); ++c) stack.emplace_back(*c, world);
    }
}

// A transform that can place a mesh: finite, invertible linear part (a glTF node may scale by
// 0 to hide a mesh; such a placement is dropped like a degenerate triangle).
bool invertible(const glm::dmat4& m) {
    const double det = glm::determinant(glm::dmat3(m));
    if (!(std::abs(det) > 0) || !std::isfinite(det)) return false;
    for (int c = 0; c < 4; ++c)
        for (int r = 0; r < 3; ++r)
            if (!std::isfinite(m[c][r])) return false;
    return true;
}

// The file's instances with `transform` not yet applied (what the cache keeps).
std::vector<MeshInstance> readMeshFile(const fs::path& meshFile, const fs::path& sceneFile,
                                       const JsonPath& path, GltfExtras* extras) {
    std::error_code ec;
    if (!fs::is_regular_file(meshFile, ec)) fail(sceneFile, path, meshFile, "no such file");
    if (fs::file_size(meshFile, ec) == 0) fail(sceneFile, path, meshFile, "is empty (0 bytes)");
    std::vector<RawInstance> raw;
    std::string ext = meshFile.extension().string();
    std::transform(ext.begin(), ext.end(), ext.begin(), ::tolower);
    if (ext == ".obj") {
        raw.push_back({std::make_shared<TriangleMesh>(), glm::dmat4(1.0)});
        loadObj(meshFile, *raw.back().geometry, sceneFile, path);
    } else if (ext == ".gltf" || ext == ".glb") {
        loadGltf(meshFile, raw, sceneFile, path, extras);
    } else {
        fail(sceneFile, path, meshFile, "unsupported format '" + ext + "': a mesh is .obj, .gltf or .glb (convert the model, e.g. to .obj or .glb)");
    }
    // Degenerate triangles are judged in object space: an invertible affine map keeps a
    // triangle's area zero or non-zero.
    std::vector<TriangleMesh*> finalized;
    std::size_t dropped = 0, triangles = 0;
    std::vector<MeshInstance> out;
    for (RawInstance& r : raw) {
        if (std::find(finalized.begin(), finalized.end(), r.geometry.get()) == finalized.end()) {
            finalizeMesh(*r.geometry);
            finalized.push_back(r.geometry.get());
            dropped += r.geometry->droppedDegenerate;
            triangles += r.geometry->triangleCount();
        }
        if (r.geometry->indices.empty()) continue;
        if (!invertible(r.transform)) {
            dropped += r.geometry->triangleCount();
            continue;
        }
        out.push_back({r.geometry, affineOf(r.transform)});
    }
    if (triangles == 0 && dropped == 0) fail(sceneFile, path, meshFile, "has no triangles");
    if (out.empty())
        fail(sceneFile, path, meshFile, "has no triangles left after dropping " +
                                            std::to_string(dropped) + " degenerate ones");
    return out;
}

}  // namespace

glm::dmat4 objectTransform(const Vec3& translate, const Vec3& rotateDegrees, const Vec3& scale) {
    glm::dmat4 m = glm::translate(glm::dmat4(1.0), translate);
    m = glm::rotate(m, glm::radians(rotateDegrees.z), Vec3(0, 0, 1));
    m = glm::rotate(m, glm::radians(rotateDegrees.y), Vec3(0, 1, 0));
    m = glm::rotate(m, glm::radians(rotateDegrees.x), Vec3(1, 0, 0));
    return glm::scale(m, scale);
}

void finalizeMesh(TriangleMesh& mesh) {
    // Drop triangles with zero area (or non-finite arithmetic) so no NaN normal reaches a backend.
    std::vector<std::uint32_t> kept;
    kept.reserve(mesh.indices.size());
    for (std::size_t t = 0; t + 2 < mesh.indices.size(); t += 3) {
        const Vec3& a = mesh.positions[mesh.indices[t]];
        const Vec3& b = mesh.positions[mesh.indices[t + 1]];
        const Vec3& c = mesh.positions[mesh.indices[t + 2]];
        const double area2 = glm::length(glm::cross(b - a, c - a));
        if (!(area2 > 0.0) || !std::isfinite(area2)) {
            ++mesh.droppedDegenerate;
            continue;
        }
        kept.insert(kept.end(), {mesh.indices[t], mesh.indices[t + 1], mesh.indices[t + 2]});
    }
    mesh.indices = std::move(kept);

    bool normalsOk = mesh.normals.size() == mesh.positions.size();
    if (normalsOk)
        for (Vec3& n : mesh.normals) {
            const double len = glm::length(n);
            if (!(len > 0.0) || !std::isfinite(len)) { normalsOk = false; break; }
            n /= len;
        }
    if (!normalsOk) {
        // Area-weighted vertex normals: the unnormalized cross product weighs by area.
        mesh.normals.assign(mesh.positions.size(), Vec3(0.0));
        for (std::size_t t = 0; t < mesh.indices.size(); t += 3) {
            const auto i0 = mesh.indices[t], i1 = mesh.indices[t + 1], i2 = mesh.indices[t + 2];
            const Vec3 fn = glm::cross(mesh.positions[i1] - mesh.positions[i0],
                                       mesh.positions[i2] - mesh.positions[i0]);
            mesh.normals[i0] += fn; mesh.normals[i1] += fn; mesh.normals[i2] += fn;
        }
        for (Vec3& n : mesh.normals) {
            const double len = glm::length(n);
            n = len > 0.0 ? n / len : Vec3(0, 1, 0);  // unused vertex: any unit vector
        }
    }
}

std::vector<MeshInstance> loadMeshInstances(const fs::path& meshFile, const glm::dmat4& transform,
                                            const fs::path& sceneFile, const JsonPath& path,
                                            GltfExtras* extras, MeshCache* cache) {
    std::vector<MeshInstance> instances;
    std::string key;
    if (cache) {
        std::error_code ec;
        const fs::path canonical = fs::weakly_canonical(meshFile, ec);
        key = (ec ? meshFile : canonical).string();
        if (const auto it = cache->files.find(key); it != cache->files.end()) {
            instances = it->second;
            if (extras) *extras = cache->extras[key];  // the same cameras for every object naming the file
        }
    }
    if (instances.empty()) {
        GltfExtras own;
        instances = readMeshFile(meshFile, sceneFile, path, extras ? extras : (cache ? &own : nullptr));
        if (cache) {
            cache->files.emplace(key, instances);
            cache->extras[key] = extras ? *extras : own;
        }
    }
    std::vector<MeshInstance> out;
    for (MeshInstance& inst : instances) {
        const glm::dmat4 m = transform * glm::dmat4(inst.transform);
        if (!invertible(m)) continue;
        // The placed mesh must stay finite: its box's corners bound every placed vertex.
        Bounds b;
        for (const Vec3& p : inst.geometry->positions) b.extend(p);
        for (int corner = 0; corner < 8; ++corner) {
            const Vec3 c((corner & 1) ? b.max.x : b.min.x, (corner & 2) ? b.max.y : b.min.y,
                         (corner & 4) ? b.max.z : b.min.z);
            if (!finite(Vec3(m * glm::dvec4(c, 1.0))))
                fail(sceneFile, path, meshFile, "a vertex is not finite once placed");
        }
        out.push_back({inst.geometry, affineOf(m)});
    }
    if (out.empty()) fail(sceneFile, path, meshFile, "the object's transform is not invertible");
    return out;
}

TriangleMesh flattenInstances(const std::vector<MeshInstance>& instances) {
    TriangleMesh out;
    bool normals = true;
    for (const MeshInstance& inst : instances) normals = normals && !inst.geometry->normals.empty();
    for (const MeshInstance& inst : instances) {
        const TriangleMesh& g = *inst.geometry;
        const glm::dmat3 nm = normalMatrix(inst.transform);
        const std::uint32_t base = std::uint32_t(out.positions.size());
        for (const Vec3& p : g.positions) out.positions.push_back(transformPoint(inst.transform, p));
        if (normals)
            for (const Vec3& n : g.normals) out.normals.push_back(glm::normalize(nm * n));
        for (std::uint32_t i : g.indices) out.indices.push_back(base + i);
        out.droppedDegenerate += g.droppedDegenerate;
    }
    return out;
}

std::shared_ptr<const TriangleMesh> loadMesh(const fs::path& meshFile, const glm::dmat4& transform,
                                             const fs::path& sceneFile, const JsonPath& path,
                                             GltfExtras* extras) {
    return std::make_shared<TriangleMesh>(
        flattenInstances(loadMeshInstances(meshFile, transform, sceneFile, path, extras)));
}

}  // namespace shadowlab::scene
