// scene/mesh_loader.cpp: tinyobjloader / tinygltf readers feeding one TriangleMesh format.
#include "scene/mesh_loader.h"
#include "scene/ply_loader.h"

#include <algorithm>
#include <array>
#include <cctype>
#include <cerrno>
#include <climits>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <cstring>
#include <fstream>
#include <limits>
#include <map>
#include <sstream>
#include <string_view>

#include <tiny_gltf.h>
#include <tiny_obj_loader.h>
#include <glm/gtc/matrix_transform.hpp>
#include <glm/gtc/quaternion.hpp>
#include <nlohmann/json.hpp>

#include "scene/gltf_extensions.h"
#include "scene/input_file.h"
#include "scene/json_input.h"
#include "scene/memory.h"
#include "scene/scene_checks.h"
#include "scene/texture.h"

namespace shadowlab::scene {

namespace {

namespace fs = std::filesystem;

[[noreturn]] void fail(const fs::path& sceneFile, const JsonPath& path, const fs::path& mesh, const std::string& what) {
    // (a glTF given as the scene is both: named once)
    throw SceneError(sceneFile, path, mesh == sceneFile ? what : mesh.string() + ": " + what);
}

bool finite(const Vec3& v) { return std::isfinite(v.x) && std::isfinite(v.y) && std::isfinite(v.z); }

// What tinyobjloader does not check, found first so a broken export is reported with its line
// rather than silently reshaped: "nan" or "inf" numbers (read as 0), and face indices beyond
// the 32-bit range (wrapped to other, possibly valid, vertices). Lines are read as tinyobjloader
// reads them, after leading spaces and tabs.
// A positive vertex index may name a vertex defined further down, so it is checked against the
// file's count: where one exceeds it, a second pass (`limits`: vertices, texture coordinates,
// normals) names the first such line. (A texture coordinate or normal index past the file's is not
// an error: the mesh then goes without UVs or normals, as readObj does, and still casts.) A vertex
// needs three coordinates and a face three corners: tinyobjloader drops a shorter face, or reads
// a missing coordinate as 0.
void checkObjText(const std::string& text, const fs::path& file, const fs::path& sceneFile, const JsonPath& path,
                  const std::array<std::size_t, 3>& limits = {SIZE_MAX, SIZE_MAX, SIZE_MAX}) {
    std::size_t vertices = 0, texcoords = 0, normals = 0;
    std::size_t lineNo = 0;
    std::array<long long, 3> largest = {0, 0, 0};
    for (std::size_t begin = 0; begin < text.size();) {
        std::size_t end = text.find('\n', begin);
        if (end == std::string::npos) end = text.size();
        std::string_view line(text.data() + begin, end - begin);
        begin = end + 1;
        ++lineNo;
        while (!line.empty() && (line.front() == ' ' || line.front() == '\t')) line.remove_prefix(1);
        if (!line.empty() && line.back() == '\r') line.remove_suffix(1);
        auto at = [&] { return "line " + std::to_string(lineNo) + ": "; };
        const std::size_t space = line.find_first_of(" \t");
        const std::string_view keyword = line.substr(0, space);
        if (line == "f") fail(sceneFile, path, file, at() + "a face of 0 corners (a face needs 3 or more)");
        if (space == std::string_view::npos) continue;
        std::istringstream fields{std::string(line.substr(space + 1))};
        std::string token;
        if (keyword == "v" || keyword == "vn" || keyword == "vt") {
            (keyword == "v" ? vertices : keyword == "vn" ? normals : texcoords) += 1;
            int coordinates = 0;
            for (int i = 0; i < 3 && fields >> token; ++i) {
                ++coordinates;
                char* stop = nullptr;
                const double v = std::strtod(token.c_str(), &stop);
                if (stop == token.c_str() || *stop != '\0' || !std::isfinite(v))
                    fail(sceneFile, path, file,
                         at() +
                             (keyword == "v"    ? "vertex"
                              : keyword == "vn" ? "normal"
                                                : "texture") +
                             " coordinate '" + excerpt(token) + "' is not a finite number");
            }
            if ((keyword == "v" || keyword == "vn") && coordinates < 3)
                fail(sceneFile, path, file,
                     at() + (keyword == "v" ? "a vertex" : "a normal") + " of " + std::to_string(coordinates) +
                         " coordinate" + (coordinates == 1 ? "" : "s") + " (it needs x, y and z)");
        } else if (keyword == "f" || keyword == "l" || keyword == "p") {
            int corners = 0;
            while (fields >> token) {
                ++corners;
                // v, v/vt, v//vn or v/vt/vn; each counted from 1, or back from the latest when negative.
                std::size_t part = 0;
                for (std::size_t from = 0; from <= token.size(); ++part) {
                    std::size_t slash = token.find('/', from);
                    if (slash == std::string::npos) slash = token.size();
                    const std::string number = token.substr(from, slash - from);
                    from = slash + 1;
                    if (number.empty()) continue;
                    errno = 0;
                    char* stop = nullptr;
                    const long long index = std::strtoll(number.c_str(), &stop, 10);
                    const std::size_t defined = part == 0 ? vertices : part == 1 ? texcoords : normals;
                    const char* what = part == 0 ? "vertices" : part == 1 ? "texture coordinates" : "normals";
                    if (stop == number.c_str() || *stop != '\0')
                        fail(sceneFile, path, file,
                             at() + "face index '" + excerpt(number) + "' is not a whole number");
                    if (index == 0 || errno == ERANGE || index > std::int64_t(INT32_MAX) ||
                        (index < 0 && std::uint64_t(-(index + 1)) >= defined))
                        fail(sceneFile, path, file,
                             at() + "face index " + excerpt(number) + " is out of range (" + std::to_string(defined) +
                                 " " + what + " defined so far)");
                    if (part < 3 && std::uint64_t(std::max(index, 0LL)) > limits[part])
                        fail(sceneFile, path, file,
                             at() + "face index " + excerpt(number) + " is out of range (" +
                                 std::to_string(limits[part]) + " " + what + " in the file)");
                    if (part < 3) largest[part] = std::max(largest[part], index);
                }
            }
            if (keyword == "f" && corners < 3)
                fail(sceneFile, path, file,
                     at() + "a face of " + std::to_string(corners) + " corner" + (corners == 1 ? "" : "s") +
                         " (a face needs 3 or more)");
        }
    }
    if (limits[0] == SIZE_MAX && std::uint64_t(largest[0]) > vertices)
        checkObjText(text, file, sceneFile, path, {vertices, SIZE_MAX, SIZE_MAX});
}

// OBJ material libraries name other files, which tinyobjloader would open itself (a FIFO hung
// it, /dev/zero grew without bound). Shadows need no material, so a library is only checked
// through the one input opener, never parsed: a missing one is ignored as before, one that is
// not a regular file of a sane size is an error.
class MaterialCheck : public tinyobj::MaterialReader {
public:
    explicit MaterialCheck(fs::path dir) : dir_(std::move(dir)) {}
    bool operator()(const std::string& name, std::vector<tinyobj::material_t>*, std::map<std::string, int>*,
                    std::string*, std::string*) override {
        const fs::path lib = dir_ / name;
        if (!problem_.empty() || !inputFileExists(lib)) return false;
        try {
            checkInputFile(lib, kMaxJsonFileBytes);
        } catch (const InputFileError& e) {
            problem_ = "mtllib " + excerpt(name) + ": " + e.what();
        }
        return false;
    }
    const std::string& problem() const { return problem_; }

private:
    fs::path dir_;
    std::string problem_;
};

void loadObj(const fs::path& file, const std::string& text, TriangleMesh& mesh, const fs::path& sceneFile,
             const JsonPath& path, bool wantUvs) {
    checkObjText(text, file, sceneFile, path);
    tinyobj::attrib_t attribStorage;
    std::vector<tinyobj::shape_t> shapes;
    std::vector<tinyobj::material_t> materials;
    std::string warn, err;
    std::istringstream stream(text);
    MaterialCheck materialCheck(file.has_parent_path() ? file.parent_path() : fs::path("."));
    const bool ok =
        tinyobj::LoadObj(&attribStorage, &shapes, &materials, &warn, &err, &stream, &materialCheck, true, false);
    if (!materialCheck.problem().empty()) fail(sceneFile, path, file, materialCheck.problem());
    if (!ok) fail(sceneFile, path, file, "not a readable OBJ file: " + excerpt(err, 200));
    const auto& attrib = attribStorage;
    const std::size_t vertexCount = attrib.vertices.size() / 3;
    const std::size_t normalCount = attrib.normals.size() / 3;
    bool allHaveNormals = normalCount > 0;
    std::size_t faces = 0;
    for (const auto& shape : shapes) {
        for (const auto& idx : shape.mesh.indices) {
            if (idx.vertex_index < 0 || std::size_t(idx.vertex_index) >= vertexCount)
                fail(sceneFile, path, file,
                     "face index " + std::to_string(std::int64_t(idx.vertex_index) + 1) + " is out of range (" +
                         std::to_string(vertexCount) + " vertices)");
            if (idx.normal_index < 0 || std::size_t(idx.normal_index) >= normalCount) allHaveNormals = false;
        }
        faces += shape.mesh.num_face_vertices.size();
    }
    if (faces == 0) fail(sceneFile, path, file, "has no faces");
    // One output vertex per OBJ corner keeps per-corner normals; fine for the sizes we load.
    std::size_t corners = 0;
    for (const auto& shape : shapes) corners += shape.mesh.indices.size();
    if (corners > std::size_t(UINT32_MAX))
        fail(sceneFile, path, file, "has " + std::to_string(corners) + " face corners, more than 32-bit indices hold");
    for (const auto& shape : shapes) {
        for (const auto& idx : shape.mesh.indices) {
            const Vec3 p(attrib.vertices[3 * std::size_t(idx.vertex_index)],
                         attrib.vertices[3 * std::size_t(idx.vertex_index) + 1],
                         attrib.vertices[3 * std::size_t(idx.vertex_index) + 2]);
            if (!finite(p))
                fail(sceneFile, path, file, "vertex " + std::to_string(idx.vertex_index + 1) + " is not finite");
            mesh.indices.push_back(std::uint32_t(mesh.positions.size()));
            mesh.positions.push_back(p);
            if (wantUvs) {
                // OBJ's vt has v up from the image's bottom; glTF's (and ours) runs down from its top.
                if (idx.texcoord_index < 0 || 2 * std::size_t(idx.texcoord_index) + 1 >= attrib.texcoords.size())
                    fail(sceneFile, path, file,
                         "a face corner has no texture coordinate (vt), which the object's "
                         "alpha texture needs");
                mesh.uvs.emplace_back(attrib.texcoords[2 * std::size_t(idx.texcoord_index)],
                                      1.0 - attrib.texcoords[2 * std::size_t(idx.texcoord_index) + 1]);
            }
            if (allHaveNormals)
                mesh.normals.emplace_back(attrib.normals[3 * std::size_t(idx.normal_index)],
                                          attrib.normals[3 * std::size_t(idx.normal_index) + 1],
                                          attrib.normals[3 * std::size_t(idx.normal_index) + 2]);
        }
    }
    if (!allHaveNormals) mesh.normals.clear();
}

// a + b and a * b on sizes taken from a file, or nothing when they overflow.
bool addChecked(std::uint64_t a, std::uint64_t b, std::uint64_t& out) { return !__builtin_add_overflow(a, b, &out); }
bool mulChecked(std::uint64_t a, std::uint64_t b, std::uint64_t& out) { return !__builtin_mul_overflow(a, b, &out); }

// `count` elements of `nComp` components of `componentType` from buffer view `viewIndex`,
// starting `byteOffset` into it, `stride` bytes apart (0: the view's stride, or packed), as
// doubles. Every offset, count and stride is the file's, so each sum and product is checked for
// overflow and against the lengths of the view and its buffer (glTF 2.0, 3.6.2.4: byteOffset +
// (count - 1) * stride + element size must fit the view); `where` names the field at fault.
std::vector<double> readElements(const tinygltf::Model& model, int viewIndex, std::uint64_t byteOffset,
                                 std::uint64_t count, int componentType, int nComp, bool packed,
                                 const std::string& where, const fs::path& file, const fs::path& sceneFile,
                                 const JsonPath& path) {
    auto bad = [&](const std::string& at, const std::string& what) { fail(sceneFile, path, file, at + ": " + what); };
    if (viewIndex < 0 || std::size_t(viewIndex) >= model.bufferViews.size())
        bad(where + ".bufferView", "names buffer view " + std::to_string(viewIndex) + ", which does not exist (" +
                                       std::to_string(model.bufferViews.size()) + " buffer views)");
    const std::string viewAt = "bufferViews[" + std::to_string(viewIndex) + "]";
    const auto& view = model.bufferViews[std::size_t(viewIndex)];
    if (view.buffer < 0 || std::size_t(view.buffer) >= model.buffers.size())
        bad(viewAt + ".buffer", "names buffer " + std::to_string(view.buffer) + ", which does not exist");
    const auto& buffer = model.buffers[std::size_t(view.buffer)];
    const int compSize = tinygltf::GetComponentSizeInBytes(componentType);
    if (compSize <= 0) bad(where + ".componentType", "unsupported component type " + std::to_string(componentType));
    const std::uint64_t element = std::uint64_t(compSize) * std::uint64_t(nComp);
    const std::uint64_t stride = !packed && view.byteStride ? std::uint64_t(view.byteStride) : element;
    if (stride < element)
        bad(viewAt + ".byteStride",
            std::to_string(stride) + " is smaller than one element (" + std::to_string(element) + " bytes)");
    std::uint64_t viewEnd = 0;
    if (!addChecked(view.byteOffset, view.byteLength, viewEnd) || viewEnd > buffer.data.size())
        bad(viewAt, "byteOffset " + std::to_string(view.byteOffset) + " + byteLength " +
                        std::to_string(view.byteLength) + " reaches past the end of buffer " +
                        std::to_string(view.buffer) + " (" + std::to_string(buffer.data.size()) + " bytes)");
    std::uint64_t span = 0, last = 0, end = 0;
    if (count > 0 && (!mulChecked(stride, count - 1, span) || !addChecked(span, element, last) ||
                      !addChecked(last, byteOffset, end) || end > view.byteLength))
        bad(where, "byteOffset " + std::to_string(byteOffset) + " + " + std::to_string(count) + " elements of stride " +
                       std::to_string(stride) + " reach past the end of " + viewAt + " (" +
                       std::to_string(view.byteLength) + " bytes)");
    // The doubles read: at most 8 a byte of the buffer, but that may still be more than the
    // machine has.
    const std::uint64_t values = count * std::uint64_t(nComp);
    if (const std::uint64_t available = availableMemoryBytes(); available != 0 && values * sizeof(double) > available)
        bad(where, "reading its " + std::to_string(count) + " elements needs " +
                       std::to_string(values * sizeof(double) / kMiB) + " MiB, more than the " +
                       std::to_string(available / kMiB) + " MiB available");
    std::vector<double> out(values);
    // No element: the offsets were not checked against the view and may point anywhere.
    if (count == 0) return out;
    const unsigned char* base = buffer.data.data() + view.byteOffset + byteOffset;
    for (std::size_t i = 0; i < count; ++i) {
        for (int c = 0; c < nComp; ++c) {
            const unsigned char* p = base + i * stride + std::size_t(c) * compSize;
            double v = 0;
            switch (componentType) {
                case TINYGLTF_COMPONENT_TYPE_FLOAT: {
                    float f;
                    std::memcpy(&f, p, 4);
                    v = f;
                    break;
                }
                case TINYGLTF_COMPONENT_TYPE_UNSIGNED_INT: {
                    std::uint32_t u;
                    std::memcpy(&u, p, 4);
                    v = u;
                    break;
                }
                case TINYGLTF_COMPONENT_TYPE_UNSIGNED_SHORT: {
                    std::uint16_t u;
                    std::memcpy(&u, p, 2);
                    v = u;
                    break;
                }
                case TINYGLTF_COMPONENT_TYPE_UNSIGNED_BYTE: v = *p; break;
                // Signed types: KHR_mesh_quantization's positions, normals and texture coordinates.
                case TINYGLTF_COMPONENT_TYPE_SHORT: {
                    std::int16_t u;
                    std::memcpy(&u, p, 2);
                    v = u;
                    break;
                }
                case TINYGLTF_COMPONENT_TYPE_BYTE: v = double(std::int8_t(*p)); break;
                default: bad(where + ".componentType", "unsupported component type " + std::to_string(componentType));
            }
            out[i * std::size_t(nComp) + std::size_t(c)] = v;
        }
    }
    return out;
}

// A normalized integer accessor's values as glTF 2.0, 3.11 maps them: unsigned c / (2^n - 1),
// signed max(c / (2^(n-1) - 1), -1), so both -128 and -127 are -1.
void normalize(std::vector<double>& values, int componentType, const std::string& at, const fs::path& file,
               const fs::path& sceneFile, const JsonPath& path) {
    double scale = 0, lowest = 0;
    switch (componentType) {
        case TINYGLTF_COMPONENT_TYPE_BYTE:
            scale = 127.0;
            lowest = -1.0;
            break;
        case TINYGLTF_COMPONENT_TYPE_UNSIGNED_BYTE: scale = 255.0; break;
        case TINYGLTF_COMPONENT_TYPE_SHORT:
            scale = 32767.0;
            lowest = -1.0;
            break;
        case TINYGLTF_COMPONENT_TYPE_UNSIGNED_SHORT: scale = 65535.0; break;
        default:
            fail(sceneFile, path, file,
                 at + ".normalized: must not be true for component type " + std::to_string(componentType) +
                     " (only bytes and shorts are normalized)");
    }
    for (double& v : values) v = std::max(v / scale, lowest);
}

// Reads one accessor as doubles (`components` per element): its buffer view's elements, or
// zeros where it has none, with a sparse accessor's replacements applied (glTF 2.0, 3.6.2.3:
// `count` strictly increasing indices into the accessor, and as many packed values), and
// normalized integers mapped to -1..1 or 0..1.
// `referrer`: the JSON path of the property that names the accessor, for the error where it names none.
std::vector<double> readAccessor(const tinygltf::Model& model, int accessorIndex, int components, const fs::path& file,
                                 const fs::path& sceneFile, const JsonPath& path, const std::string& referrer) {
    const std::string at = "accessors[" + std::to_string(accessorIndex) + "]";
    auto bad = [&](const std::string& where, const std::string& what) {
        fail(sceneFile, path, file, where + ": " + what);
    };
    if (accessorIndex < 0 || std::size_t(accessorIndex) >= model.accessors.size())
        fail(sceneFile, path, file,
             referrer + ": names accessor " + std::to_string(accessorIndex) + ", which does not exist (" +
                 std::to_string(model.accessors.size()) + " accessors)");
    const auto& acc = model.accessors[std::size_t(accessorIndex)];
    const int nComp = tinygltf::GetNumComponentsInType(acc.type);
    if (tinygltf::GetComponentSizeInBytes(acc.componentType) <= 0 || nComp != components)
        bad(at, "has an unexpected type (expected " + std::to_string(components) + " component(s) per element)");
    std::vector<double> out;
    if (acc.bufferView >= 0 || !acc.sparse.isSparse) {
        out = readElements(model, acc.bufferView, acc.byteOffset, acc.count, acc.componentType, nComp, false, at, file,
                           sceneFile, path);
    } else {
        // No buffer view: zeros (bounded like any read: by the memory there is).
        const std::uint64_t values = std::uint64_t(acc.count) * std::uint64_t(nComp);
        if (const std::uint64_t available = availableMemoryBytes();
            available != 0 && values * sizeof(double) > available)
            bad(at + ".count", std::to_string(acc.count) + " elements need more than the " +
                                   std::to_string(available / kMiB) + " MiB available");
        out.assign(values, 0.0);
    }
    if (acc.normalized) normalize(out, acc.componentType, at, file, sceneFile, path);
    if (!acc.sparse.isSparse) return out;
    const auto& sparse = acc.sparse;
    const std::string sparseAt = at + ".sparse";
    if (sparse.count < 1 || std::uint64_t(sparse.count) > acc.count)
        bad(sparseAt + ".count",
            "must be in 1.." + std::to_string(acc.count) + ", got " + std::to_string(sparse.count));
    const int indexType = sparse.indices.componentType;
    if (indexType != TINYGLTF_COMPONENT_TYPE_UNSIGNED_BYTE && indexType != TINYGLTF_COMPONENT_TYPE_UNSIGNED_SHORT &&
        indexType != TINYGLTF_COMPONENT_TYPE_UNSIGNED_INT)
        bad(sparseAt + ".indices.componentType",
            "must be an unsigned byte, short or int, got " + std::to_string(indexType));
    if (sparse.indices.byteOffset < 0 || sparse.values.byteOffset < 0) bad(sparseAt, "a byteOffset is negative");
    const std::vector<double> indices =
        readElements(model, sparse.indices.bufferView, std::uint64_t(sparse.indices.byteOffset),
                     std::uint64_t(sparse.count), indexType, 1, true, sparseAt + ".indices", file, sceneFile, path);
    std::vector<double> values = readElements(model, sparse.values.bufferView, std::uint64_t(sparse.values.byteOffset),
                                              std::uint64_t(sparse.count), acc.componentType, nComp, true,
                                              sparseAt + ".values", file, sceneFile, path);
    if (acc.normalized) normalize(values, acc.componentType, at, file, sceneFile, path);
    for (std::size_t k = 0; k < indices.size(); ++k) {
        const double index = indices[k];
        if (index >= double(acc.count) || (k > 0 && !(index > indices[k - 1])))
            bad(sparseAt + ".indices", "index " + std::to_string(std::uint64_t(index)) + " (element " +
                                           std::to_string(k) + ") is out of range or not increasing (" +
                                           std::to_string(acc.count) + " elements)");
        for (int c = 0; c < nComp; ++c)
            out[std::size_t(index) * std::size_t(nComp) + std::size_t(c)] =
                values[k * std::size_t(nComp) + std::size_t(c)];
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

// The animations that move a camera's node (`cameraNodes`: node → its index in out.cameras and its
// parents' transform): translation and rotation channels, read as curves; scale and weights are left
// out (they do not move a camera). A channel on a camera node that cannot be sampled is an error.
void collectCameraAnimations(const tinygltf::Model& model, const std::map<int, std::pair<int, glm::dmat4>>& cameraNodes,
                             GltfExtras& out, const fs::path& file, const fs::path& sceneFile, const JsonPath& path) {
    for (std::size_t a = 0; a < model.animations.size(); ++a) {
        const tinygltf::Animation& anim = model.animations[a];
        std::map<int, CameraAnimation> byNode;
        for (std::size_t c = 0; c < anim.channels.size(); ++c) {
            const tinygltf::AnimationChannel& ch = anim.channels[c];
            const auto node = cameraNodes.find(ch.target_node);
            if (node == cameraNodes.end() || (ch.target_path != "translation" && ch.target_path != "rotation"))
                continue;
            const std::string at = "animations[" + std::to_string(a) + "].channels[" + std::to_string(c) + "]";
            if (ch.sampler < 0 || std::size_t(ch.sampler) >= anim.samplers.size())
                fail(sceneFile, path, file,
                     at + ".sampler: names no sampler (" + std::to_string(anim.samplers.size()) + ")");
            const tinygltf::AnimationSampler& sampler = anim.samplers[std::size_t(ch.sampler)];
            const std::string sat =
                "animations[" + std::to_string(a) + "].samplers[" + std::to_string(ch.sampler) + "]";
            AnimationCurve curve;
            if (sampler.interpolation == "LINEAR" || sampler.interpolation.empty())
                curve.interpolation = AnimationCurve::Interpolation::Linear;
            else if (sampler.interpolation == "STEP")
                curve.interpolation = AnimationCurve::Interpolation::Step;
            else if (sampler.interpolation == "CUBICSPLINE")
                curve.interpolation = AnimationCurve::Interpolation::CubicSpline;
            else
                fail(sceneFile, path, file,
                     sat + ".interpolation: expected LINEAR, STEP or CUBICSPLINE, got '" +
                         excerpt(sampler.interpolation) + "'");
            curve.times = readAccessor(model, sampler.input, 1, file, sceneFile, path, sat + ".input");
            if (curve.times.empty()) fail(sceneFile, path, file, sat + ".input: has no keys");
            for (std::size_t k = 0; k < curve.times.size(); ++k)
                if (!std::isfinite(curve.times[k]) || (k > 0 && !(curve.times[k] > curve.times[k - 1])))
                    fail(sceneFile, path, file,
                         sat + ".input: key times must be finite and increasing (key " + std::to_string(k) + ")");
            const bool rotation = ch.target_path == "rotation";
            const int components = rotation ? 4 : 3;
            const std::vector<double> v =
                readAccessor(model, sampler.output, components, file, sceneFile, path, sat + ".output");
            const std::size_t perKey = curve.interpolation == AnimationCurve::Interpolation::CubicSpline ? 3 : 1;
            if (v.size() != curve.times.size() * perKey * std::size_t(components))
                fail(sceneFile, path, file,
                     sat + ".output: holds " + std::to_string(v.size() / std::size_t(components)) + " values for " +
                         std::to_string(curve.times.size()) + " keys (expected " +
                         std::to_string(curve.times.size() * perKey) + ")");
            for (std::size_t i = 0; i < v.size(); i += std::size_t(components)) {
                glm::dvec4 value(v[i], v[i + 1], v[i + 2], rotation ? v[i + 3] : 0.0);
                for (int k = 0; k < 4; ++k)
                    if (!std::isfinite(value[k])) fail(sceneFile, path, file, sat + ".output: a value is not finite");
                curve.values.push_back(value);
            }
            CameraAnimation& ca = byNode[ch.target_node];
            (rotation ? ca.rotationCurve : ca.translationCurve) = std::move(curve);
        }
        for (auto& [nodeIndex, ca] : byNode) {
            const tinygltf::Node& node = model.nodes[std::size_t(nodeIndex)];
            if (node.matrix.size() == 16)
                fail(sceneFile, path, file,
                     "nodes[" + std::to_string(nodeIndex) +
                         "]: an animated node must have translation/rotation/scale, not a matrix");
            ca.name = anim.name;
            ca.index = int(a);
            ca.camera = cameraNodes.at(nodeIndex).first;
            ca.parent = cameraNodes.at(nodeIndex).second;
            if (node.translation.size() == 3)
                ca.translation = Vec3(node.translation[0], node.translation[1], node.translation[2]);
            if (node.rotation.size() == 4)
                ca.rotation = glm::dvec4(node.rotation[0], node.rotation[1], node.rotation[2], node.rotation[3]);
            if (node.scale.size() == 3) ca.scale = Vec3(node.scale[0], node.scale[1], node.scale[2]);
            ca.start = std::numeric_limits<double>::infinity();
            ca.end = -ca.start;
            for (const auto* curve : {&ca.translationCurve, &ca.rotationCurve})
                if (*curve) {
                    ca.start = std::min(ca.start, (*curve)->times.front());
                    ca.end = std::max(ca.end, (*curve)->times.back());
                }
            out.cameraAnimations.push_back(std::move(ca));
        }
    }
}

// Images are decoded only where a MASK or BLEND material needs one's alpha (readMaterials), so
// any image is accepted here, even a missing one; with `user` (a GltfImages) the bytes are kept.
using GltfImages = std::map<int, std::vector<unsigned char>>;
bool ignoreImage(tinygltf::Image*, const int index, std::string*, std::string*, int, int, const unsigned char* bytes,
                 int size, void* user) {
    if (user && bytes && size > 0) (*static_cast<GltfImages*>(user))[index].assign(bytes, bytes + size);
    return true;
}

TextureWrap wrapOf(int glWrap) {
    return glWrap == 33071   ? TextureWrap::ClampToEdge
           : glWrap == 33648 ? TextureWrap::MirroredRepeat
                             : TextureWrap::Repeat;
}

// The file's materials as scene materials (grey albedo: shadows do not need its colours), with the
// alpha texture of each MASK and BLEND material that has a baseColorTexture, and in `uvTransforms`
// that texture's KHR_texture_transform (one per material).
std::vector<Material> readMaterials(const tinygltf::Model& model, const GltfImages& images, const fs::path& file,
                                    const fs::path& sceneFile, const JsonPath& path, std::vector<std::string>& notes,
                                    std::vector<UvTransform>& uvTransforms) {
    std::vector<Material> out;
    uvTransforms.assign(model.materials.size(), UvTransform{});
    std::map<std::tuple<int, int, int>, std::shared_ptr<const AlphaTexture>> decoded;
    for (std::size_t i = 0; i < model.materials.size(); ++i) {
        const tinygltf::Material& gm = model.materials[i];
        const std::string at = "materials[" + std::to_string(i) + "]";
        Material m;
        m.name = gm.name.empty() ? at : gm.name;
        m.alphaMode = gm.alphaMode == "MASK"    ? AlphaMode::Mask
                      : gm.alphaMode == "BLEND" ? AlphaMode::Blend
                                                : AlphaMode::Opaque;
        if (gm.alphaMode != "OPAQUE" && gm.alphaMode != "MASK" && gm.alphaMode != "BLEND")
            fail(sceneFile, path, file,
                 at + ".alphaMode: unknown mode '" + excerpt(gm.alphaMode) + "' (expected OPAQUE, MASK or BLEND)");
        m.alphaCutoff = gm.alphaCutoff;
        if (!(m.alphaCutoff >= 0.0))
            fail(sceneFile, path, file, at + ".alphaCutoff: must be >= 0, got " + describeJson(gm.alphaCutoff));
        const auto& factor = gm.pbrMetallicRoughness.baseColorFactor;
        m.alphaFactor = factor.size() == 4 ? factor[3] : 1.0;
        if (!(m.alphaFactor >= 0.0 && m.alphaFactor <= 1.0))
            fail(sceneFile, path, file, at + ".pbrMetallicRoughness.baseColorFactor[3]: must be in 0..1");
        const auto& info = gm.pbrMetallicRoughness.baseColorTexture;
        if (m.alphaMode != AlphaMode::Opaque && info.index >= 0) {
            const std::string texAt = at + ".pbrMetallicRoughness.baseColorTexture";
            if (std::size_t(info.index) >= model.textures.size())
                fail(sceneFile, path, file,
                     texAt + ".index: names texture " + std::to_string(info.index) + ", which does not exist");
            const tinygltf::Texture& tex = model.textures[std::size_t(info.index)];
            int source = tex.source;
            const std::string texturesAt = "textures[" + std::to_string(info.index) + "]";
            // An image only in another format (the texture's own source is the fallback): WebP
            // is decoded like PNG; KTX2 (Basis Universal) is not, nor AVIF (OpenImageIO 2.4
            // reads it from files only, and a glTF image may be in a buffer).
            for (const char* format : {"EXT_texture_webp", "EXT_texture_avif", "KHR_texture_basisu"}) {
                const auto it = tex.extensions.find(format);
                if (source >= 0 || it == tex.extensions.end() || !it->second.Has("source")) continue;
                if (std::string(format) != "EXT_texture_webp")
                    fail(sceneFile, path, file,
                         texturesAt + ".extensions." + format + ": the alpha of " + m.name + " (" + gm.alphaMode +
                             ") is only in a" + (std::string(format) == "EXT_texture_avif" ? "n AVIF" : " KTX2") +
                             " image, which shadowlab does not decode "
                             "(give the texture a PNG or JPEG source)");
                const tinygltf::Value& v = it->second.Get("source");
                const double d = v.IsNumber() || v.IsInt() ? v.GetNumberAsDouble() : -1.0;
                source = d >= 0 && d < double(model.images.size()) && d == std::floor(d) ? int(d) : -1;
            }
            if (source < 0 || std::size_t(source) >= model.images.size())
                fail(sceneFile, path, file, texturesAt + ".source: names no image");
            TextureWrap s = TextureWrap::Repeat, t = TextureWrap::Repeat;
            if (tex.sampler >= 0 && std::size_t(tex.sampler) < model.samplers.size()) {
                s = wrapOf(model.samplers[std::size_t(tex.sampler)].wrapS);
                t = wrapOf(model.samplers[std::size_t(tex.sampler)].wrapT);
            }
            const tinygltf::Image& image = model.images[std::size_t(source)];
            const std::string imageAt =
                "images[" + std::to_string(source) + "]" +
                (image.uri.empty() || image.uri.rfind("data:", 0) == 0 ? "" : " (" + excerpt(image.uri) + ")");
            const auto key = std::make_tuple(source, int(s), int(t));
            const auto bytes = images.find(source);
            if (!decoded.count(key) && bytes == images.end()) {
                // A model passed on without its image files is common (and the shadow of the
                // rest of it is still worth grading): the material keeps its factor's alpha,
                // and the user is told. An image that is there but broken is still an error.
                notes.push_back(imageAt + " of " + file.filename().string() + " is missing, so " + m.name + " (" +
                                gm.alphaMode + ") casts with its baseColorFactor alpha " + describeJson(m.alphaFactor) +
                                " alone, without its texture's alpha");
                out.push_back(std::move(m));
                continue;
            }
            if (!decoded.count(key)) {
                std::string ext = image.mimeType == "image/jpeg"   ? ".jpg"
                                  : image.mimeType == "image/png"  ? ".png"
                                  : image.mimeType == "image/webp" ? ".webp"
                                                                   : "";
                if (ext.empty()) ext = fs::path(image.uri).extension().string();
                try {
                    decoded[key] = loadAlphaTextureFromMemory(file.string() + "#" + imageAt, ext, bytes->second, s, t);
                } catch (const InputFileError& e) {
                    fail(sceneFile, path, file, imageAt + ": " + e.problem());
                }
            }
            m.alphaTexture = decoded[key];
            try {
                uvTransforms[i] = readTextureTransform(info, texAt, m.texCoord);
            } catch (const GltfExtensionError& e) {
                fail(sceneFile, path, file, e.what());
            }
            if (m.texCoord < 0 || m.texCoord > 64)
                fail(sceneFile, path, file, texAt + ".texCoord: must be in 0..64, got " + std::to_string(m.texCoord));
        }
        out.push_back(std::move(m));
    }
    return out;
}

// One glTF mesh's triangle primitives in the mesh's own space: all of them (material -2), or
// those of one material; with TEXCOORD_`uvSet` per vertex when uvSet >= 0, moved by
// `uvTransform` (the material's alpha texture's KHR_texture_transform).
void appendGltfMesh(const tinygltf::Model& model, int meshIndex, TriangleMesh& out, const fs::path& file,
                    const fs::path& sceneFile, const JsonPath& path, int material = -2, int uvSet = -1,
                    const UvTransform& uvTransform = {}) {
    if (meshIndex < 0 || std::size_t(meshIndex) >= model.meshes.size())
        fail(sceneFile, path, file, "node names mesh " + std::to_string(meshIndex) + ", which does not exist");
    for (std::size_t primIndex = 0; primIndex < model.meshes[meshIndex].primitives.size(); ++primIndex) {
        const auto& prim = model.meshes[meshIndex].primitives[primIndex];
        if (prim.mode != TINYGLTF_MODE_TRIANGLES && prim.mode != -1) continue;  // points/lines cast nothing
        if (material != -2 && prim.material != material) continue;
        const std::string primAt =
            "meshes[" + std::to_string(meshIndex) + "].primitives[" + std::to_string(primIndex) + "]";
        const auto pos = prim.attributes.find("POSITION");
        if (pos == prim.attributes.end()) fail(sceneFile, path, file, primAt + ".attributes: has no POSITION");
        const std::vector<double> p =
            readAccessor(model, pos->second, 3, file, sceneFile, path, primAt + ".attributes.POSITION");
        const std::size_t count = p.size() / 3;
        std::vector<double> n;
        if (const auto it = prim.attributes.find("NORMAL"); it != prim.attributes.end()) {
            n = readAccessor(model, it->second, 3, file, sceneFile, path, primAt + ".attributes.NORMAL");
            if (n.size() != p.size()) n.clear();
        }
        std::vector<double> uv;
        if (uvSet >= 0) {
            const std::string name = "TEXCOORD_" + std::to_string(uvSet);
            const auto it = prim.attributes.find(name);
            if (it == prim.attributes.end())
                fail(sceneFile, path, file, primAt + ": has no " + name + ", which its material's alpha texture needs");
            uv = readAccessor(model, it->second, 2, file, sceneFile, path, primAt + ".attributes." + name);
            if (uv.size() != 2 * count)
                fail(sceneFile, path, file, primAt + ": " + name + " has not one element per vertex");
            for (std::size_t i = 0; i < uv.size(); i += 2) {
                // KHR_texture_transform moves where the alpha is sampled; both backends
                // interpolate these per-vertex coordinates, and the transform is affine.
                const Vec2 t = uvTransform.apply(Vec2(uv[i], uv[i + 1]));
                uv[i] = t.x;
                uv[i + 1] = t.y;
                if (!std::isfinite(t.x) || !std::isfinite(t.y))
                    fail(sceneFile, path, file, primAt + ": " + name + " holds a non-finite value");
            }
        }
        std::vector<double> idx;
        if (prim.indices >= 0) {
            if (std::size_t(prim.indices) < model.accessors.size()) {
                // glTF 2.0, 3.7.2.1: unsigned and not normalized (the signed types of
                // KHR_mesh_quantization are for attributes only).
                const tinygltf::Accessor& ia = model.accessors[std::size_t(prim.indices)];
                const std::string iaAt = "accessors[" + std::to_string(prim.indices) + "]";
                if (ia.componentType != TINYGLTF_COMPONENT_TYPE_UNSIGNED_BYTE &&
                    ia.componentType != TINYGLTF_COMPONENT_TYPE_UNSIGNED_SHORT &&
                    ia.componentType != TINYGLTF_COMPONENT_TYPE_UNSIGNED_INT)
                    fail(sceneFile, path, file,
                         iaAt + ".componentType: indices must be an unsigned byte, short or int, got " +
                             std::to_string(ia.componentType));
                if (ia.normalized) fail(sceneFile, path, file, iaAt + ".normalized: indices must not be normalized");
            }
            idx = readAccessor(model, prim.indices, 1, file, sceneFile, path, primAt + ".indices");
        } else {
            idx.resize(count);
            for (std::size_t i = 0; i < count; ++i) idx[i] = double(i);
        }
        const std::size_t corners = idx.size() / 3 * 3;  // a trailing partial triangle is ignored
        for (std::size_t i = 0; i < corners; ++i)
            if (idx[i] >= double(count))
                fail(sceneFile, path, file,
                     "meshes[" + std::to_string(meshIndex) + "].primitives[" + std::to_string(primIndex) +
                         "].indices (accessors[" + std::to_string(prim.indices) + "]): index " +
                         std::to_string(std::uint64_t(idx[i])) + " is out of range (" + std::to_string(count) +
                         " vertices)");
        for (std::size_t i = 0; i < count; ++i)
            if (!finite(Vec3(p[3 * i], p[3 * i + 1], p[3 * i + 2])))
                fail(sceneFile, path, file,
                     "meshes[" + std::to_string(meshIndex) + "].primitives[" + std::to_string(primIndex) +
                         "].attributes.POSITION: vertex " + std::to_string(i) + " is not finite");
        const bool flat = n.empty();
        const std::size_t added = flat ? corners : count;
        if (out.positions.size() + added > std::size_t(UINT32_MAX))
            fail(sceneFile, path, file,
                 "mesh " + std::to_string(meshIndex) + " has more vertices than 32-bit indices hold");
        const std::uint32_t base = std::uint32_t(out.positions.size());
        auto at = [&](std::size_t j) { return Vec3(p[3 * j], p[3 * j + 1], p[3 * j + 2]); };
        if (flat) {
            // glTF 2.0, 3.7.2.1: without NORMAL, "client implementations MUST calculate flat
            // normals": each triangle gets its own three vertices with its face normal, written
            // straight into the mesh (no second copy of the corners beside it while loading).
            for (std::size_t t = 0; t < corners; t += 3) {
                const std::size_t j[3] = {std::size_t(idx[t]), std::size_t(idx[t + 1]), std::size_t(idx[t + 2])};
                const Vec3 face = glm::cross(at(j[1]) - at(j[0]), at(j[2]) - at(j[0]));
                const double len = glm::length(face);
                // A degenerate triangle is dropped later; its vertices need only a unit normal.
                const Vec3 unit = len > 0.0 && std::isfinite(len) ? face / len : Vec3(0, 1, 0);
                for (std::size_t k = 0; k < 3; ++k) {
                    out.positions.push_back(at(j[k]));
                    out.normals.push_back(unit);
                    if (uvSet >= 0) out.uvs.emplace_back(uv[2 * j[k]], uv[2 * j[k] + 1]);
                    out.indices.push_back(base + std::uint32_t(t + k));
                }
            }
            continue;
        }
        for (std::size_t i = 0; i < count; ++i) {
            out.positions.push_back(at(i));
            out.normals.emplace_back(n[3 * i], n[3 * i + 1], n[3 * i + 2]);
            if (uvSet >= 0) out.uvs.emplace_back(uv[2 * i], uv[2 * i + 1]);
        }
        for (std::size_t i = 0; i < corners; ++i) out.indices.push_back(base + std::uint32_t(idx[i]));
    }
}

// A node's camera and KHR_lights_punctual light, placed by the node's world transform (glTF
// cameras and lights look down their local −Z with +Y up).
void collectCameraAndLight(const tinygltf::Model& model, const tinygltf::Node& node, int nodeIndex,
                           const glm::dmat4& world, GltfExtras& out, const fs::path& file, const fs::path& sceneFile,
                           const JsonPath& path) {
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
        // A shadowlab export's image size (scene/gltf_export.cpp); anything else there is ignored.
        const tinygltf::Value& extra = model.cameras[node.camera].extras;
        if (extra.IsObject() && extra.Has("shadowlab") && extra.Get("shadowlab").Has("resolution")) {
            const tinygltf::Value& res = extra.Get("shadowlab").Get("resolution");
            if (res.IsArray() && res.ArrayLen() == 2 && res.Get(0).IsNumber() && res.Get(1).IsNumber()) {
                const double w = res.Get(0).GetNumberAsDouble(), h = res.Get(1).GetNumberAsDouble();
                if (w >= 1 && h >= 1 && w <= 16384 && h <= 16384 && w == std::floor(w) && h == std::floor(h)) {
                    c.width = int(w);
                    c.height = int(h);
                }
            }
        }
        out.cameras.push_back(c);
    }
    const auto ext = node.extensions.find("KHR_lights_punctual");
    if (ext == node.extensions.end() || !ext->second.Has("light")) return;
    // The index is the file's: any number (GetNumberAsInt of 1e15 is undefined behaviour, found
    // by fuzzing), so it is checked as a double first.
    const tinygltf::Value& v = ext->second.Get("light");
    const double number = v.IsNumber() || v.IsInt() ? v.GetNumberAsDouble() : -1.0;
    if (!(number >= 0 && number < double(model.lights.size()) && number == std::floor(number)))
        fail(sceneFile, path, file,
             "nodes[" + std::to_string(nodeIndex) + "].extensions.KHR_lights_punctual.light: names no light (" +
                 std::to_string(model.lights.size()) + " lights)");
    const int index = int(number);
    const tinygltf::Light& l = model.lights[std::size_t(index)];
    if (l.type != "directional" && l.type != "point" && l.type != "spot")
        fail(sceneFile, path, file,
             "extensions.KHR_lights_punctual.lights[" + std::to_string(index) + "].type: unknown light type '" +
                 excerpt(l.type) + "' (expected directional, point or spot)");
    GltfLight light;
    light.index = index;
    light.type = l.type;
    light.position = origin;
    light.direction = forward;
    if (l.color.size() == 3) light.color = Vec3(l.color[0], l.color[1], l.color[2]);
    light.intensity = l.intensity;
    light.outerConeRadians = l.spot.outerConeAngle;
    light.innerConeRadians = l.spot.innerConeAngle;
    // glTF's range cuts a light off (smoothly) at a distance; shadowlab's lights reach every
    // distance at 1/d². Said once per light, since it brightens what lies beyond.
    if (l.range > 0 && std::isfinite(l.range)) {
        char range[32];
        std::snprintf(range, sizeof range, "%g", l.range);
        const std::string note = "extensions.KHR_lights_punctual.lights[" + std::to_string(index) + "].range " +
                                 std::string(range) +
                                 " is not applied: shadowlab's point and spot lights fall off as 1/d² at every "
                                 "distance, so points beyond the range are lit (in every backend and the reference "
                                 "alike, so the shadows compare the same)";
        if (std::find(out.notes.begin(), out.notes.end(), note) == out.notes.end()) out.notes.push_back(note);
    }
    if (l.extras.IsObject() && l.extras.Has("shadowlab") && l.extras.Get("shadowlab").Has("radius") &&
        l.extras.Get("shadowlab").Get("radius").IsNumber())
        light.radius = l.extras.Get("shadowlab").Get("radius").GetNumberAsDouble();
    out.lights.push_back(light);
}

// Placements of the file's geometries; `geometry` is still mutable while loading.
struct RawInstance {
    std::shared_ptr<TriangleMesh> geometry;
    glm::dmat4 transform;
    int material = -1;  // glTF material index (MeshRequest::perMaterial)
};

// Every file a glTF names (buffers, images) is read through the one input opener, relative to
// the glTF's own folder only.
struct GltfFiles {
    std::string baseDir;
};

bool gltfFileExists(const std::string& name, void* user) {
    const auto* files = static_cast<const GltfFiles*>(user);
    // tinygltf also tries the current folder; a URI is relative to the glTF file alone.
    const std::string prefix = files->baseDir.empty() ? "" : files->baseDir + "/";
    if (name.compare(0, prefix.size(), prefix) != 0) return false;
    return inputFileExists(name);
}

std::string gltfExpandPath(const std::string& name, void*) { return name; }  // no ~ or $VAR expansion

bool gltfReadFile(std::vector<unsigned char>* out, std::string* err, const std::string& name, void*) {
    try {
        const std::string bytes = readInputFile(name, kMaxMeshFileBytes);
        out->assign(bytes.begin(), bytes.end());
        return true;
    } catch (const InputFileError& e) {
        if (err) *err += e.problem();
        return false;
    }
}

bool gltfWriteFile(std::string* err, const std::string&, const std::vector<unsigned char>&, void*) {
    if (err) *err += "shadowlab writes no glTF files";
    return false;
}

// After a failed load: the first buffer whose file is missing, unreadable or shorter than its
// byteLength, by its JSON path (tinygltf names the file but not which buffer wants it); "" when
// the buffers are not the problem.
std::string bufferFileProblem(std::string_view json, const std::string& baseDir) {
    const nlohmann::json doc = nlohmann::json::parse(json, nullptr, false);
    if (!doc.is_object() || !doc.contains("buffers") || !doc["buffers"].is_array()) return "";
    const nlohmann::json& buffers = doc["buffers"];
    for (std::size_t i = 0; i < buffers.size(); ++i) {
        const nlohmann::json& b = buffers[i];
        if (!b.is_object() || !b.contains("uri") || !b["uri"].is_string()) continue;
        const std::string uri = b["uri"].get<std::string>();
        if (uri.rfind("data:", 0) == 0) continue;
        std::string name;  // a URI's %XX escapes decoded, as the loader reads them
        for (std::size_t k = 0; k < uri.size(); ++k) {
            if (uri[k] == '%' && k + 2 < uri.size() && std::isxdigit(static_cast<unsigned char>(uri[k + 1])) &&
                std::isxdigit(static_cast<unsigned char>(uri[k + 2]))) {
                name.push_back(char(std::stoi(uri.substr(k + 1, 2), nullptr, 16)));
                k += 2;
            } else {
                name.push_back(uri[k]);
            }
        }
        const fs::path at = baseDir.empty() ? fs::path(name) : fs::path(baseDir) / name;
        const std::string where = "buffers[" + std::to_string(i) + "].uri \"" + excerpt(uri, 80) + "\"";
        std::uint64_t size = 0;
        try {
            size = checkInputFile(at, kMaxMeshFileBytes);
        } catch (const InputFileError& e) {
            return where + ": " + e.problem() + " (" + excerpt(at.string(), 200) + ")";
        }
        const nlohmann::json length = b.value("byteLength", nlohmann::json());
        if (length.is_number_unsigned() && size < length.get<std::uint64_t>())
            return where + ": the file holds " + std::to_string(size) + " bytes, fewer than the buffer's byteLength " +
                   std::to_string(length.get<std::uint64_t>()) + " (a truncated or different file)";
    }
    return "";
}

// What tinygltf reads leniently, checked on the file's JSON once tinygltf has accepted it: a
// value of the wrong type it drops without a word (indices "0" read the primitive without its
// indices, a transform of strings placed the node at the origin) and values out of the range the
// glTF 2.0 specification gives. The first problem, by its JSON path ("" if none).
std::string gltfValueProblem(std::string_view json) {
    const nlohmann::json doc = nlohmann::json::parse(json, nullptr, false);
    if (!doc.is_object()) return "";
    auto count = [&](const char* key) {
        return doc.contains(key) && doc[key].is_array() ? doc[key].size() : std::size_t(0);
    };
    auto items = [&](const nlohmann::json& parent, const char* key) -> const nlohmann::json* {
        return parent.is_object() && parent.contains(key) && parent[key].is_array() ? &parent[key] : nullptr;
    };
    // An index into the top-level array `of` (its entries named `one`); "" when it is one.
    auto index = [&](const nlohmann::json& v, const std::string& at, const char* of, const char* one) -> std::string {
        if (!v.is_number_integer() || v.get<std::int64_t>() < 0)
            return at + ": must be an index (a whole number >= 0), got " + describeJson(v);
        if (std::uint64_t(v.get<std::int64_t>()) >= count(of))
            return at + ": names " + std::string(one) + " " + std::to_string(v.get<std::int64_t>()) +
                   ", which does not exist (" + std::to_string(count(of)) + " " + of + ")";
        return "";
    };
    auto numbers = [&](const nlohmann::json& v, const std::string& at, std::size_t n) -> std::string {
        bool ok = v.is_array() && v.size() == n;
        for (std::size_t i = 0; ok && i < n; ++i) ok = v[i].is_number() && std::isfinite(v[i].get<double>());
        return ok ? "" : at + ": must be an array of " + std::to_string(n) + " finite numbers, got " + describeJson(v);
    };
    auto number = [&](const nlohmann::json& v, const std::string& at, double lo, double hi, bool loOpen,
                      const char* range) -> std::string {
        const bool ok = v.is_number() && std::isfinite(v.get<double>()) &&
                        (loOpen ? v.get<double>() > lo : v.get<double>() >= lo) && v.get<double>() <= hi;
        return ok ? "" : at + ": must be a number " + range + ", got " + describeJson(v);
    };
    const double inf = std::numeric_limits<double>::infinity(), pi = 3.14159265358979323846;
    std::string p;
    if (doc.contains("scene") && !(p = index(doc["scene"], "scene", "scenes", "scene")).empty()) return p;
    if (const nlohmann::json* meshes = items(doc, "meshes"))
        for (std::size_t m = 0; m < meshes->size(); ++m)
            if (const nlohmann::json* prims = items((*meshes)[m], "primitives"))
                for (std::size_t k = 0; k < prims->size(); ++k) {
                    const nlohmann::json& prim = (*prims)[k];
                    const std::string at = "meshes[" + std::to_string(m) + "].primitives[" + std::to_string(k) + "]";
                    if (!prim.is_object()) continue;
                    if (prim.contains("indices") &&
                        !(p = index(prim["indices"], at + ".indices", "accessors", "accessor")).empty())
                        return p;
                    if (prim.contains("attributes") && prim["attributes"].is_object())
                        for (const auto& [name, value] : prim["attributes"].items())
                            if (!(p = index(value, at + ".attributes." + name, "accessors", "accessor")).empty())
                                return p;
                    if (prim.contains("material") &&
                        !(p = index(prim["material"], at + ".material", "materials", "material")).empty())
                        return p;
                    if (prim.contains("mode") && !(prim["mode"].is_number_integer() && prim["mode"].get<int>() >= 0 &&
                                                   prim["mode"].get<int>() <= 6))
                        return at +
                               ".mode: must be 0 to 6 (points, lines, line loop, line strip, triangles, "
                               "triangle strip, triangle fan), got " +
                               describeJson(prim["mode"]);
                }
    if (const nlohmann::json* nodes = items(doc, "nodes"))
        for (std::size_t n = 0; n < nodes->size(); ++n) {
            const nlohmann::json& node = (*nodes)[n];
            if (!node.is_object()) continue;
            const std::string at = "nodes[" + std::to_string(n) + "]";
            const std::pair<const char*, std::size_t> shapes[] = {
                {"matrix", 16}, {"translation", 3}, {"rotation", 4}, {"scale", 3}};
            for (const auto& [key, n3] : shapes)
                if (node.contains(key) && !(p = numbers(node[key], at + "." + key, n3)).empty()) return p;
            const std::pair<const char*, const char*> refs[] = {
                {"mesh", "meshes"}, {"camera", "cameras"}, {"skin", "skins"}};
            for (const auto& [key, of] : refs)
                if (node.contains(key) && !(p = index(node[key], at + "." + key, of, key)).empty()) return p;
        }
    if (const nlohmann::json* cameras = items(doc, "cameras"))
        for (std::size_t c = 0; c < cameras->size(); ++c) {
            const nlohmann::json& cam = (*cameras)[c];
            if (!cam.is_object() || !cam.contains("perspective") || !cam["perspective"].is_object()) continue;
            const nlohmann::json& per = cam["perspective"];
            const std::string at = "cameras[" + std::to_string(c) + "].perspective";
            if (per.contains("yfov") &&
                !(p = number(per["yfov"], at + ".yfov", 0.0, pi, true, "in (0, π) radians")).empty())
                return p;
            if (per.contains("znear") && !(p = number(per["znear"], at + ".znear", 0.0, inf, true, "> 0")).empty())
                return p;
            if (per.contains("aspectRatio") &&
                !(p = number(per["aspectRatio"], at + ".aspectRatio", 0.0, inf, true, "> 0")).empty())
                return p;
        }
    if (const nlohmann::json* materials = items(doc, "materials"))
        for (std::size_t m = 0; m < materials->size(); ++m) {
            const nlohmann::json& mat = (*materials)[m];
            if (!mat.is_object()) continue;
            const std::string at = "materials[" + std::to_string(m) + "]";
            if (mat.contains("alphaCutoff") &&
                !(p = number(mat["alphaCutoff"], at + ".alphaCutoff", 0.0, inf, false, ">= 0")).empty())
                return p;
            if (mat.contains("pbrMetallicRoughness") && mat["pbrMetallicRoughness"].is_object() &&
                mat["pbrMetallicRoughness"].contains("baseColorFactor") &&
                !(p = numbers(mat["pbrMetallicRoughness"]["baseColorFactor"],
                              at + ".pbrMetallicRoughness.baseColorFactor", 4))
                     .empty())
                return p;
        }
    if (doc.contains("extensions") && doc["extensions"].is_object() &&
        doc["extensions"].contains("KHR_lights_punctual"))
        if (const nlohmann::json* lights = items(doc["extensions"]["KHR_lights_punctual"], "lights"))
            for (std::size_t l = 0; l < lights->size(); ++l) {
                const nlohmann::json& light = (*lights)[l];
                if (!light.is_object()) continue;
                const std::string at = "extensions.KHR_lights_punctual.lights[" + std::to_string(l) + "]";
                // Its range is the light checks' (scene::lightProblem, after the conversion); the type here.
                if (light.contains("intensity") && !light["intensity"].is_number())
                    return at + ".intensity: must be a number, got " + describeJson(light["intensity"]);
                if (light.contains("color") && !(p = numbers(light["color"], at + ".color", 3)).empty()) return p;
                if (light.contains("spot") && light["spot"].is_object() && light["spot"].contains("outerConeAngle") &&
                    !(p = number(light["spot"]["outerConeAngle"], at + ".spot.outerConeAngle", 0.0, pi / 2, true,
                                 "in (0, π/2] radians"))
                         .empty())
                    return p;
                if (light.contains("spot") && light["spot"].is_object() && light["spot"].contains("innerConeAngle")) {
                    const nlohmann::json& spot = light["spot"];
                    const double outer = spot.contains("outerConeAngle") && spot["outerConeAngle"].is_number()
                                             ? spot["outerConeAngle"].get<double>()
                                             : pi / 4;  // the specification's default
                    if (!(p = number(spot["innerConeAngle"], at + ".spot.innerConeAngle", 0.0, outer, false,
                                     "in [0, outerConeAngle] radians"))
                             .empty())
                        return p;
                }
            }
    return "";
}

// Where tinygltf refused a file: the first accessor a mesh primitive or an animation sampler names
// that the file does not hold, by its JSON path ("" if none). tinygltf's own message names
// neither the primitive nor the property.
std::string accessorReferenceProblem(std::string_view json) {
    const nlohmann::json doc = nlohmann::json::parse(json, nullptr, false);
    if (!doc.is_object()) return "";
    const std::size_t accessors =
        doc.contains("accessors") && doc["accessors"].is_array() ? doc["accessors"].size() : 0;
    auto check = [&](const nlohmann::json& value, const std::string& at) -> std::string {
        if (!value.is_number_integer()) return "";
        const std::int64_t index = value.get<std::int64_t>();
        if (index >= 0 && std::uint64_t(index) < accessors) return "";
        return at + ": names accessor " + std::to_string(index) + ", which does not exist (" +
               std::to_string(accessors) + " accessors)";
    };
    auto array = [&](const nlohmann::json& parent, const char* key) -> const nlohmann::json* {
        return parent.is_object() && parent.contains(key) && parent[key].is_array() ? &parent[key] : nullptr;
    };
    if (const nlohmann::json* meshes = array(doc, "meshes"))
        for (std::size_t m = 0; m < meshes->size(); ++m)
            if (const nlohmann::json* prims = array((*meshes)[m], "primitives"))
                for (std::size_t p = 0; p < prims->size(); ++p) {
                    const nlohmann::json& prim = (*prims)[p];
                    if (!prim.is_object()) continue;
                    const std::string at = "meshes[" + std::to_string(m) + "].primitives[" + std::to_string(p) + "]";
                    if (prim.contains("attributes") && prim["attributes"].is_object())
                        for (const auto& [name, value] : prim["attributes"].items())
                            if (std::string problem = check(value, at + ".attributes." + name); !problem.empty())
                                return problem;
                    if (prim.contains("indices"))
                        if (std::string problem = check(prim["indices"], at + ".indices"); !problem.empty())
                            return problem;
                }
    if (const nlohmann::json* animations = array(doc, "animations"))
        for (std::size_t a = 0; a < animations->size(); ++a)
            if (const nlohmann::json* samplers = array((*animations)[a], "samplers"))
                for (std::size_t k = 0; k < samplers->size(); ++k) {
                    const std::string at = "animations[" + std::to_string(a) + "].samplers[" + std::to_string(k) + "]";
                    for (const char* key : {"input", "output"})
                        if ((*samplers)[k].is_object() && (*samplers)[k].contains(key))
                            if (std::string problem = check((*samplers)[k][key], at + "." + key); !problem.empty())
                                return problem;
                }
    return "";
}

// `decodedBytes`: what decoding compressed geometry added to the file's buffers.
void loadGltf(const fs::path& file, const std::string& fileBytes, std::vector<RawInstance>& out,
              const fs::path& sceneFile, const JsonPath& path, GltfExtras* extras, const MeshRequest& request,
              std::uint64_t& decodedBytes) {
    const std::string ext = lowercaseExtension(file);
    const bool binary = ext == ".glb";
    // tinygltf parses extras and extensions recursively: nesting is bounded before it sees them.
    if (binary)
        if (const std::string problem = glbLayoutProblem(fileBytes); !problem.empty())
            fail(sceneFile, path, file, problem);
    if (const std::string problem = jsonNestingProblem(gltfJsonChunk(fileBytes, binary)); !problem.empty())
        fail(sceneFile, path, file, problem);
    GltfPrepared prepared;
    try {
        prepared = prepareGltf(fileBytes, binary);
    } catch (const GltfExtensionError& e) {
        fail(sceneFile, path, file, e.what());
    }
    const std::string& bytes = prepared.rewritten.empty() ? fileBytes : prepared.rewritten;
    tinygltf::TinyGLTF loader;
    GltfImages images;  // kept only where materials may need them
    loader.SetImageLoader(ignoreImage, request.perMaterial ? &images : nullptr);
    GltfFiles files{file.has_parent_path() ? file.parent_path().string() : std::string()};
    loader.SetFsCallbacks({gltfFileExists, gltfExpandPath, gltfReadFile, gltfWriteFile, &files});
    tinygltf::Model model;
    std::string err, warn;
    const bool ok =
        binary ? loader.LoadBinaryFromMemory(&model, &err, &warn, reinterpret_cast<const unsigned char*>(bytes.data()),
                                             unsigned(std::min<std::size_t>(bytes.size(), UINT_MAX)), files.baseDir)
               : loader.LoadASCIIFromString(&model, &err, &warn, bytes.data(),
                                            unsigned(std::min<std::size_t>(bytes.size(), UINT_MAX)), files.baseDir);
    if (!ok) {
        if (const std::string problem = bufferFileProblem(gltfJsonChunk(fileBytes, binary), files.baseDir);
            !problem.empty())
            fail(sceneFile, path, file, problem);
        if (const std::string problem = accessorReferenceProblem(gltfJsonChunk(fileBytes, binary)); !problem.empty())
            fail(sceneFile, path, file, problem);
        fail(sceneFile, path, file, "not a readable glTF file: " + excerpt(err.empty() ? warn : err, 400));
    }
    if (const std::string problem = gltfValueProblem(gltfJsonChunk(fileBytes, binary)); !problem.empty())
        fail(sceneFile, path, file, problem);
    prepared.rewritten.clear();
    prepared.rewritten.shrink_to_fit();
    try {
        decodedBytes = decodeCompressedGeometry(model, prepared);
    } catch (const GltfExtensionError& e) {
        fail(sceneFile, path, file, e.what());
    }

    std::vector<Material> materials;
    std::vector<UvTransform> uvTransforms;
    std::vector<std::string> notes = prepared.notes;
    if (request.perMaterial) materials = readMaterials(model, images, file, sceneFile, path, notes, uvTransforms);
    images.clear();
    if (extras) extras->materials = materials;
    if (extras) extras->notes = notes;
    if (extras) extras->shadowlabExport = model.asset.extras.IsObject() && model.asset.extras.Has("shadowlab");
    // Walk the default scene's node tree (depth first, in document order) so each node that
    // uses a mesh places it once; a mesh used by several nodes is read once and shared.
    std::vector<int> roots;
    const int sceneIndex = model.defaultScene >= 0 ? model.defaultScene : 0;
    if (std::size_t(sceneIndex) < model.scenes.size())
        roots = model.scenes[sceneIndex].nodes;
    else
        for (std::size_t i = 0; i < model.nodes.size(); ++i) roots.push_back(int(i));
    std::vector<std::shared_ptr<TriangleMesh>> meshes(model.meshes.size());
    std::map<std::pair<int, int>, std::shared_ptr<TriangleMesh>> perMaterial;  // (mesh, material)
    std::vector<std::pair<int, glm::dmat4>> stack;
    for (auto r = roots.rbegin(); r != roots.rend(); ++r) stack.emplace_back(*r, glm::dmat4(1.0));
    // glTF nodes form a forest (glTF 2.0 spec, 3.5.3: a node has at most one parent and no
    // cycles), so a walk reaches each node once; a second visit means a cycle or a shared child,
    // which would otherwise loop forever or grow exponentially (found by fuzzing).
    std::vector<char> visited(model.nodes.size(), 0);
    std::map<int, std::pair<int, glm::dmat4>> cameraNodes;  // node → camera index, parents' transform
    while (!stack.empty()) {
        auto [nodeIndex, parent] = stack.back();
        stack.pop_back();
        if (nodeIndex < 0 || std::size_t(nodeIndex) >= model.nodes.size())
            fail(sceneFile, path, file,
                 "the node hierarchy names node " + std::to_string(nodeIndex) + ", which does not exist (" +
                     std::to_string(model.nodes.size()) + " nodes)");
        if (visited[nodeIndex]++)
            fail(sceneFile, path, file,
                 "node " + std::to_string(nodeIndex) +
                     " is reached twice in the node hierarchy (a cycle, or a node "
                     "with two parents); glTF nodes must form trees");
        const auto& node = model.nodes[nodeIndex];
        const glm::dmat4 world = parent * nodeMatrix(node);
        // A scale of 0 hides a mesh (dropped below), but one that overflows is not a placement.
        for (int c = 0; c < 4; ++c)
            for (int r = 0; r < 4; ++r)
                if (!std::isfinite(world[c][r]))
                    fail(sceneFile, path, file,
                         "nodes[" + std::to_string(nodeIndex) +
                             "]: its transform, applied after its parents', is not finite "
                             "(a scale or translation overflows)");
        if (node.mesh >= 0) {
            if (std::size_t(node.mesh) >= model.meshes.size())
                fail(sceneFile, path, file, "node names mesh " + std::to_string(node.mesh) + ", which does not exist");
            if (!request.perMaterial) {
                auto& geometry = meshes[node.mesh];
                if (!geometry) {
                    geometry = std::make_shared<TriangleMesh>();
                    appendGltfMesh(model, node.mesh, *geometry, file, sceneFile, path, -2, request.uvSet);
                }
                out.push_back({geometry, world});
            } else {
                // One geometry per material the mesh uses, in the order its primitives name them.
                std::vector<int> used;
                for (const auto& prim : model.meshes[std::size_t(node.mesh)].primitives)
                    if (std::find(used.begin(), used.end(), prim.material) == used.end()) used.push_back(prim.material);
                for (const int material : used) {
                    if (material >= int(materials.size()))
                        fail(sceneFile, path, file,
                             "a primitive of mesh " + std::to_string(node.mesh) + " names material " +
                                 std::to_string(material) + ", which does not exist");
                    auto& geometry = perMaterial[{node.mesh, material}];
                    if (!geometry) {
                        geometry = std::make_shared<TriangleMesh>();
                        const Material* m = material >= 0 ? &materials[std::size_t(material)] : nullptr;
                        appendGltfMesh(model, node.mesh, *geometry, file, sceneFile, path, material,
                                       m && m->alphaTextured() ? m->texCoord : -1,
                                       m && m->alphaTextured() ? uvTransforms[std::size_t(material)] : UvTransform{});
                    }
                    out.push_back({geometry, world, material});
                }
            }
        }
        if (extras) {
            const std::size_t before = extras->cameras.size();
            collectCameraAndLight(model, node, nodeIndex, world, *extras, file, sceneFile, path);
            if (extras->cameras.size() > before) cameraNodes[nodeIndex] = {int(before), parent};
        }
        for (auto c = node.children.rbegin(); c != node.children.rend(); ++c) stack.emplace_back(*c, world);
    }
    if (extras && !cameraNodes.empty()) collectCameraAnimations(model, cameraNodes, *extras, file, sceneFile, path);
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
// `loadBytes`: an upper estimate of what reading the file held at its peak beside the result:
// its bytes, tinyobjloader's arrays (about three times an OBJ's text), or tinygltf's JSON tree
// (twice: its parse tree and the model's copies), buffers and the accessors read as doubles.
std::vector<MeshInstance> readMeshFile(const fs::path& meshFile, const fs::path& sceneFile, const JsonPath& path,
                                       GltfExtras* extras, std::uint64_t& loadBytes, const MeshRequest& request) {
    std::string bytes;
    try {
        bytes = readInputFile(meshFile, kMaxMeshFileBytes);
    } catch (const InputFileError& e) {
        fail(sceneFile, path, meshFile, e.problem());
    }
    if (bytes.empty()) fail(sceneFile, path, meshFile, "is empty (0 bytes)");
    std::vector<RawInstance> raw;
    const std::string ext = lowercaseExtension(meshFile);
    loadBytes = ext == ".obj" || ext == ".ply"
                    ? 4 * std::uint64_t(bytes.size())
                    : 5 * std::uint64_t(bytes.size()) + 2 * jsonTreeBytes(gltfJsonChunk(bytes, ext == ".glb"));
    if (const std::uint64_t available = availableMemoryBytes(); available != 0 && loadBytes > available)
        fail(sceneFile, path, meshFile,
             "reading it needs about " + std::to_string(loadBytes / kMiB) + " MiB, more than the " +
                 std::to_string(available / kMiB) + " MiB available");
    if (ext == ".obj") {
        raw.push_back({std::make_shared<TriangleMesh>(), glm::dmat4(1.0)});
        loadObj(meshFile, bytes, *raw.back().geometry, sceneFile, path, request.uvSet >= 0);
    } else if (ext == ".gltf" || ext == ".glb") {
        std::uint64_t decodedBytes = 0;
        loadGltf(meshFile, bytes, raw, sceneFile, path, extras, request, decodedBytes);
        // Decoded geometry is held beside the file like its buffers, and read as doubles (at
        // most 8 a byte, for byte components).
        loadBytes += 9 * decodedBytes;
        // The meshes grow primitive by primitive, and a vector that grows holds its old buffer
        // beside the new one: at most the result's own size more (a flat primitive, without
        // NORMAL, has three vertices a triangle, far more than its accessors).
        std::vector<const TriangleMesh*> counted;
        for (const RawInstance& r : raw)
            if (std::find(counted.begin(), counted.end(), r.geometry.get()) == counted.end()) {
                counted.push_back(r.geometry.get());
                const TriangleMesh& g = *r.geometry;
                loadBytes += (g.positions.capacity() + g.normals.capacity()) * sizeof(Vec3) +
                             g.indices.capacity() * sizeof(std::uint32_t) + g.uvs.capacity() * sizeof(Vec2);
            }
    } else if (ext == ".ply") {
        if (request.uvSet >= 0)
            fail(sceneFile, path, meshFile,
                 "a PLY mesh has no texture coordinates, which the object's alpha texture needs");
        raw.push_back({std::make_shared<TriangleMesh>(), glm::dmat4(1.0)});
        try {
            loadPly(bytes, *raw.back().geometry);
        } catch (const PlyError& e) {
            fail(sceneFile, path, meshFile, e.what());
        }
    } else {
        fail(sceneFile, path, meshFile,
             "unsupported format '" + excerpt(ext) +
                 "': a mesh is .obj, .ply, .gltf or .glb (convert the model, e.g. to .obj or .glb)");
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
        out.push_back({r.geometry, affineOf(r.transform), r.material});
    }
    if (triangles == 0 && dropped == 0) fail(sceneFile, path, meshFile, "has no triangles");
    if (out.empty())
        fail(sceneFile, path, meshFile,
             "has no triangles left after dropping " + std::to_string(dropped) + " degenerate ones");
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
            if (!(len > 0.0) || !std::isfinite(len)) {
                normalsOk = false;
                break;
            }
            n /= len;
        }
    if (!normalsOk) {
        // Area-weighted vertex normals: the unnormalized cross product weighs by area.
        mesh.normals.assign(mesh.positions.size(), Vec3(0.0));
        for (std::size_t t = 0; t < mesh.indices.size(); t += 3) {
            const auto i0 = mesh.indices[t], i1 = mesh.indices[t + 1], i2 = mesh.indices[t + 2];
            const Vec3 fn =
                glm::cross(mesh.positions[i1] - mesh.positions[i0], mesh.positions[i2] - mesh.positions[i0]);
            mesh.normals[i0] += fn;
            mesh.normals[i1] += fn;
            mesh.normals[i2] += fn;
        }
        for (Vec3& n : mesh.normals) {
            const double len = glm::length(n);
            n = len > 0.0 ? n / len : Vec3(0, 1, 0);  // unused vertex: any unit vector
        }
    }
}

std::vector<MeshInstance> loadMeshInstances(const fs::path& meshFile, const glm::dmat4& transform,
                                            const fs::path& sceneFile, const JsonPath& path, GltfExtras* extras,
                                            MeshCache* cache, const MeshRequest& request) {
    std::vector<MeshInstance> instances;
    std::string key;
    if (cache) {
        std::error_code ec;
        const fs::path canonical = fs::weakly_canonical(meshFile, ec);
        key = (ec ? meshFile : canonical).string();
        // The same file read with texture coordinates is another set of geometries.
        if (request.uvSet >= 0 || request.perMaterial)
            key += "\n" + std::to_string(request.uvSet) + (request.perMaterial ? "m" : "");
        if (const auto it = cache->files.find(key); it != cache->files.end()) {
            instances = it->second;
            if (extras) *extras = cache->extras[key];  // the same cameras for every object naming the file
        }
    }
    if (instances.empty()) {
        GltfExtras own;
        std::uint64_t loadBytes = 0;
        instances =
            readMeshFile(meshFile, sceneFile, path, extras ? extras : (cache ? &own : nullptr), loadBytes, request);
        if (cache) {
            cache->files.emplace(key, instances);
            cache->extras[key] = extras ? *extras : own;
            cache->peakLoadBytes = std::max(cache->peakLoadBytes, loadBytes);
        }
        if (extras) extras->loadBytes = std::max(extras->loadBytes, loadBytes);
    }
    std::vector<MeshInstance> out;
    bool overflowed = false;
    for (MeshInstance& inst : instances) {
        const glm::dmat4 m = transform * glm::dmat4(inst.transform);
        if (!invertible(m)) {
            // Zero scale hides a mesh; a determinant that overflows is a transform too large.
            overflowed = overflowed || !std::isfinite(glm::determinant(glm::dmat3(m)));
            continue;
        }
        // The placed mesh must stay finite: its box's corners bound every placed vertex.
        Bounds b;
        for (const Vec3& p : inst.geometry->positions) b.extend(p);
        for (int corner = 0; corner < 8; ++corner) {
            const Vec3 c((corner & 1) ? b.max.x : b.min.x, (corner & 2) ? b.max.y : b.min.y,
                         (corner & 4) ? b.max.z : b.min.z);
            if (!finite(Vec3(m * glm::dvec4(c, 1.0))))
                fail(sceneFile, path, meshFile, "a vertex is not finite once placed");
        }
        out.push_back({inst.geometry, affineOf(m), inst.fileMaterial});
    }
    if (out.empty())
        fail(sceneFile, path, meshFile,
             overflowed ? "the object's transform overflows (its scale is too large for "
                          "double precision)"
                        : "the object's transform is not invertible");
    return out;
}

TriangleMesh flattenInstances(const std::vector<MeshInstance>& instances) {
    TriangleMesh out;
    bool normals = true;
    bool uvs = true;
    for (const MeshInstance& inst : instances) normals = normals && !inst.geometry->normals.empty();
    for (const MeshInstance& inst : instances)
        uvs = uvs && inst.geometry->uvs.size() == inst.geometry->positions.size();
    for (const MeshInstance& inst : instances) {
        const TriangleMesh& g = *inst.geometry;
        const glm::dmat3 nm = normalMatrix(inst.transform);
        const std::uint32_t base = std::uint32_t(out.positions.size());
        for (const Vec3& p : g.positions) out.positions.push_back(transformPoint(inst.transform, p));
        if (normals)
            for (const Vec3& n : g.normals) out.normals.push_back(glm::normalize(nm * n));
        for (std::uint32_t i : g.indices) out.indices.push_back(base + i);
        if (uvs) out.uvs.insert(out.uvs.end(), g.uvs.begin(), g.uvs.end());
        out.droppedDegenerate += g.droppedDegenerate;
    }
    return out;
}

std::shared_ptr<const TriangleMesh> loadMesh(const fs::path& meshFile, const glm::dmat4& transform,
                                             const fs::path& sceneFile, const JsonPath& path, GltfExtras* extras) {
    return std::make_shared<TriangleMesh>(
        flattenInstances(loadMeshInstances(meshFile, transform, sceneFile, path, extras)));
}

}  // namespace shadowlab::scene
