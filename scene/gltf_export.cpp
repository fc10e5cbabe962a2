// scene/gltf_export.cpp: writes a Scene as glTF 2.0. One node per scene object, its vertices
// relative to the node's translation (float precision follows the object's size, not its distance
// from the origin); one glTF material per object, so that a shadowlab load (one object per glTF
// material) gives back one object per scene object.
#include "scene/gltf_export.h"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <fstream>
#include <limits>
#include <map>
#include <sstream>

#include <OpenImageIO/filesystem.h>
#include <OpenImageIO/imageio.h>
#include <glm/gtc/quaternion.hpp>
#include <nlohmann/json.hpp>

#include "scene/error.h"
#include "scene/frame_io.h"
#include "scene/input_file.h"
#include "scene/mesh_loader.h"

namespace shadowlab::scene {

namespace {

namespace fs = std::filesystem;
using Json = nlohmann::json;
constexpr double kPi = 3.14159265358979323846;

// One object's triangles in its node's space (positions relative to `translation`).
struct Geometry {
    std::vector<glm::vec3> positions, normals;
    std::vector<glm::vec2> uvs;  // empty: none
    std::vector<std::uint32_t> indices;
};

// The closest point of triangle abc to p (Ericson, Real-Time Collision Detection, 5.1.5).
glm::dvec3 closestOnTriangle(const glm::dvec3& p, const glm::dvec3& a, const glm::dvec3& b, const glm::dvec3& c) {
    const glm::dvec3 ab = b - a, ac = c - a, ap = p - a;
    const double d1 = glm::dot(ab, ap), d2 = glm::dot(ac, ap);
    if (d1 <= 0 && d2 <= 0) return a;
    const glm::dvec3 bp = p - b;
    const double d3 = glm::dot(ab, bp), d4 = glm::dot(ac, bp);
    if (d3 >= 0 && d4 <= d3) return b;
    const double vc = d1 * d4 - d3 * d2;
    if (vc <= 0 && d1 >= 0 && d3 <= 0) return a + ab * (d1 / (d1 - d3));
    const glm::dvec3 cp = p - c;
    const double d5 = glm::dot(ab, cp), d6 = glm::dot(ac, cp);
    if (d6 >= 0 && d5 <= d6) return c;
    const double vb = d5 * d2 - d1 * d6;
    if (vb <= 0 && d2 >= 0 && d6 <= 0) return a + ac * (d2 / (d2 - d6));
    const double va = d3 * d6 - d5 * d4;
    if (va <= 0 && (d4 - d3) >= 0 && (d5 - d6) >= 0) return b + (c - b) * ((d4 - d3) / ((d4 - d3) + (d5 - d6)));
    const double denom = 1.0 / (va + vb + vc);
    return a + ab * (vb * denom) + ac * (vc * denom);
}

// Unit-sphere vertex of ring r (0 = north pole) and segment s.
glm::dvec3 uvVertex(int r, int s, int segments, int rings) {
    const double theta = kPi * r / rings, phi = 2.0 * kPi * s / segments;
    return {std::sin(theta) * std::cos(phi), std::cos(theta), -std::sin(theta) * std::sin(phi)};
}

// The two triangles of a cell of ring r (any segment: the corners are named a..d as below),
// counter-clockwise seen from outside; at the poles one of them is degenerate and left out.
template <typename Emit>
void uvCell(int r, int rings, Emit&& emit) {
    const int a = 0, b = 1, c = 2, d = 3;  // (r, s), (r+1, s), (r+1, s+1), (r, s+1)
    if (r != 0) emit(a, b, d);
    if (r != rings - 1) emit(b, c, d);
    (void)a;
    (void)c;
}

Geometry sphereGeometry(const Sphere& sp, int segments, int rings) {
    Geometry g;
    for (int r = 0; r <= rings; ++r)
        for (int s = 0; s <= segments; ++s) {
            const glm::dvec3 n = uvVertex(r, s, segments, rings);
            g.positions.emplace_back(glm::vec3(sp.radius * n));
            g.normals.emplace_back(glm::vec3(n));
        }
    const auto at = [&](int r, int s) { return std::uint32_t(r * (segments + 1) + s); };
    for (int r = 0; r < rings; ++r)
        for (int s = 0; s < segments; ++s) {
            const std::uint32_t v[4] = {at(r, s), at(r + 1, s), at(r + 1, s + 1), at(r, s + 1)};
            uvCell(r, rings, [&](int i, int j, int k) { g.indices.insert(g.indices.end(), {v[i], v[j], v[k]}); });
        }
    return g;
}

Geometry quadGeometry(const Quad& q) {
    Geometry g;
    const glm::dvec3 hu = 0.5 * q.size.x * q.uAxis, hv = 0.5 * q.size.y * q.vAxis;
    const glm::dvec3 corner[4] = {-hu - hv, hu - hv, hu + hv, -hu + hv};
    const glm::dvec2 uv[4] = {
        {q.uvMin.x, q.uvMin.y}, {q.uvMax.x, q.uvMin.y}, {q.uvMax.x, q.uvMax.y}, {q.uvMin.x, q.uvMax.y}};
    for (int i = 0; i < 4; ++i) {
        g.positions.emplace_back(glm::vec3(corner[i]));
        g.normals.emplace_back(glm::vec3(q.normal));
        g.uvs.emplace_back(glm::vec2(uv[i]));
    }
    // Counter-clockwise around the normal: uAxis × vAxis = normal.
    g.indices = {0, 1, 2, 0, 2, 3};
    return g;
}

Geometry boxGeometry(const Box& b) {
    Geometry g;
    const glm::dvec3 h = 0.5 * (b.max - b.min);
    for (int axis = 0; axis < 3; ++axis)
        for (int sign = -1; sign <= 1; sign += 2) {
            glm::dvec3 n(0.0);
            n[axis] = sign;
            const glm::dvec3 u = glm::dvec3(axis == 1 ? 1 : 0, axis == 1 ? 0 : 1, 0) * h;
            const glm::dvec3 w = glm::cross(n, glm::normalize(u)) * h;  // completes a right-handed (u, w, n)
            const glm::dvec3 c = n * h;
            const std::uint32_t base = std::uint32_t(g.positions.size());
            for (const glm::dvec3& p : {c - u - w, c + u - w, c + u + w, c - u + w}) {
                g.positions.emplace_back(glm::vec3(p));
                g.normals.emplace_back(glm::vec3(n));
            }
            g.indices.insert(g.indices.end(), {base, base + 1, base + 2, base, base + 2, base + 3});
        }
    return g;
}

Geometry meshGeometry(const Mesh& m, const glm::dvec3& translation) {
    const TriangleMesh flat = flattenInstances(m.instances);
    Geometry g;
    for (const Vec3& p : flat.positions) g.positions.emplace_back(glm::vec3(p - translation));
    for (const Vec3& n : flat.normals) g.normals.emplace_back(glm::vec3(n));
    for (const Vec2& uv : flat.uvs) g.uvs.emplace_back(glm::vec2(uv));
    g.indices = flat.indices;
    return g;
}

// Rotation taking a glTF node's local −Z to `forward` and +Y toward `up` (cameras and lights).
glm::dquat orientation(const glm::dvec3& forward, const glm::dvec3& upHint) {
    const glm::dvec3 f = glm::normalize(forward);
    glm::dvec3 up = upHint - glm::dot(upHint, f) * f;
    if (!(glm::length(up) > 1e-9)) {
        const glm::dvec3 other = std::abs(f.y) < 0.9 ? glm::dvec3(0, 1, 0) : glm::dvec3(1, 0, 0);
        up = other - glm::dot(other, f) * f;
    }
    up = glm::normalize(up);
    const glm::dvec3 right = glm::cross(f, up);
    return glm::normalize(glm::quat_cast(glm::dmat3(right, up, -f)));
}

Json quatJson(const glm::dquat& q) { return Json::array({q.x, q.y, q.z, q.w}); }
Json vecJson(const glm::dvec3& v) { return Json::array({v.x, v.y, v.z}); }

// The binary buffer and its views and accessors.
class BufferWriter {
public:
    explicit BufferWriter(Json& doc) : doc_(doc) {}
    // A view of `bytes` (4-byte aligned) and an accessor over it.
    int accessor(const void* data, std::size_t bytes, std::size_t count, int componentType, const char* type,
                 int target, const Json& min = {}, const Json& max = {}) {
        const int view = this->view(data, bytes, target);
        Json a = {{"bufferView", view}, {"componentType", componentType}, {"count", count}, {"type", type}};
        if (!min.is_null()) a["min"] = min;
        if (!max.is_null()) a["max"] = max;
        doc_["accessors"].push_back(a);
        return int(doc_["accessors"].size()) - 1;
    }
    int view(const void* data, std::size_t bytes, int target = 0) {
        while (bin_.size() % 4) bin_.push_back(0);
        Json v = {{"buffer", 0}, {"byteOffset", bin_.size()}, {"byteLength", bytes}};
        if (target) v["target"] = target;
        const auto* p = static_cast<const unsigned char*>(data);
        bin_.insert(bin_.end(), p, p + bytes);
        doc_["bufferViews"].push_back(v);
        return int(doc_["bufferViews"].size()) - 1;
    }
    std::vector<unsigned char>& bytes() { return bin_; }

private:
    Json& doc_;
    std::vector<unsigned char> bin_;
};

std::string base64(const std::vector<unsigned char>& in) {
    static const char* kTable = "ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz0123456789+/";
    std::string out;
    out.reserve((in.size() + 2) / 3 * 4);
    for (std::size_t i = 0; i < in.size(); i += 3) {
        const unsigned v = unsigned(in[i]) << 16 | (i + 1 < in.size() ? unsigned(in[i + 1]) << 8 : 0u) |
                           (i + 2 < in.size() ? unsigned(in[i + 2]) : 0u);
        out += kTable[(v >> 18) & 63];
        out += kTable[(v >> 12) & 63];
        out += i + 1 < in.size() ? kTable[(v >> 6) & 63] : '=';
        out += i + 2 < in.size() ? kTable[v & 63] : '=';
    }
    return out;
}

int wrapCode(TextureWrap w) {
    return w == TextureWrap::ClampToEdge ? 33071 : w == TextureWrap::MirroredRepeat ? 33648 : 10497;
}

}  // namespace

double uvSphereSagitta(int segments, int rings) {
    // Every segment is the same strip turned about the axis: one strip is measured.
    double worst = 0.0;
    for (int r = 0; r < rings; ++r) {
        const glm::dvec3 v[4] = {uvVertex(r, 0, segments, rings), uvVertex(r + 1, 0, segments, rings),
                                 uvVertex(r + 1, 1, segments, rings), uvVertex(r, 1, segments, rings)};
        uvCell(r, rings, [&](int i, int j, int k) {
            worst = std::max(worst, 1.0 - glm::length(closestOnTriangle(glm::dvec3(0.0), v[i], v[j], v[k])));
        });
    }
    return worst;
}

void checkExportOptions(const fs::path& file, const ExportOptions& options) {
    const std::string ext = lowercaseExtension(file);
    if (ext != ".glb" && ext != ".gltf")
        throw InputError(file.string() + ": unknown export type '" + file.extension().string() +
                         "' (use .glb or .gltf)");
    if (!(options.tolerance >= kMinExportTolerance && options.tolerance < 0.5)) {
        std::ostringstream got;
        got << options.tolerance;
        throw InputError(
            "--tolerance: must be in [1e-05, 0.5) (a fraction of a sphere's radius; finer needs more "
            "than 250,000 triangles a sphere), got " +
            got.str());
    }
}

namespace {

// The alpha shadowlab samples as an RGBA PNG (white, with that alpha): what another engine needs
// to cut the same shadow, whatever the source was (an image inside a glTF, WebP, a file since
// moved).
std::vector<unsigned char> alphaPng(const AlphaTexture& t, const std::string& material) {
    std::vector<unsigned char> bytes;
    OIIO::Filesystem::IOVecOutput proxy(bytes);
    auto out = OIIO::ImageOutput::create("alpha.png", &proxy);
    std::vector<unsigned char> pixels(std::size_t(t.width) * std::size_t(t.height) * 4, 255);
    for (std::size_t i = 0; i < t.alpha.size(); ++i)
        pixels[4 * i + 3] = (unsigned char)std::lround(std::clamp(t.alpha[i], 0.0f, 1.0f) * 255.0f);
    const OIIO::ImageSpec spec(t.width, t.height, 4, OIIO::TypeDesc::UINT8);
    if (!out || !out->open("alpha.png", spec) || !out->write_image(OIIO::TypeDesc::UINT8, pixels.data()) ||
        !out->close())
        throw InputError("material '" + material + "': cannot encode its alpha texture as PNG" +
                         (out ? ": " + out->geterror() : std::string()));
    return bytes;
}

}  // namespace

ExportResult exportGltf(const Scene& scene, const fs::path& file, const ExportOptions& options) {
    checkExportOptions(file, options);
    const std::string ext = lowercaseExtension(file);

    // The coarsest UV sphere within the tolerance: a single chord of angle θ has sagitta
    // 1 − cos(θ/2); the middle of a cell is deeper than its edges, so the count is raised until
    // the measured sagitta fits.
    const double theta = 2.0 * std::acos(1.0 - options.tolerance);
    int segments = std::max(8, int(std::ceil(2.0 * kPi / theta)));
    int rings = std::max(4, int(std::ceil(kPi / theta)));
    double sagitta = uvSphereSagitta(segments, rings);
    while (sagitta > options.tolerance) {
        segments = int(std::ceil(segments * 1.1));
        rings = int(std::ceil(rings * 1.1));
        sagitta = uvSphereSagitta(segments, rings);
    }

    ExportResult result;
    Json doc;
    doc["asset"] = {{"version", "2.0"}, {"generator", std::string("shadowlab ") + SHADOWLAB_VERSION}};
    doc["scene"] = 0;
    doc["scenes"] = Json::array({Json::object({{"nodes", Json::array()}})});
    BufferWriter buffer(doc);
    Json& roots = doc["scenes"][0]["nodes"];
    auto addNode = [&](Json node) {
        doc["nodes"].push_back(std::move(node));
        roots.push_back(int(doc["nodes"].size()) - 1);
        ++result.nodes;
    };

    // Textures: each alpha texture file embedded once, with its sampler.
    std::map<std::pair<const AlphaTexture*, int>, int> textureIndex;
    auto textureOf = [&](const Material& m) -> int {
        const AlphaTexture* t = m.alphaTexture.get();
        const auto key = std::make_pair(t, wrapCode(t->wrapS) * 65536 + wrapCode(t->wrapT));
        if (const auto it = textureIndex.find(key); it != textureIndex.end()) return it->second;
        // A PNG or JPEG file on disk is embedded as it is (colour and all); anything else (an image
        // inside a glTF, WebP) as the alpha shadowlab decoded from it.
        const std::string text = lowercaseExtension(t->file);
        const char* mime = text == ".png" ? "image/png" : text == ".jpg" || text == ".jpeg" ? "image/jpeg" : nullptr;
        std::vector<unsigned char> bytes;
        std::error_code ec;
        if (mime && fs::is_regular_file(t->file, ec)) {
            const std::string read = readInputFile(t->file, kMaxMeshFileBytes);
            bytes.assign(read.begin(), read.end());
        } else {
            bytes = alphaPng(*t, m.name);
            mime = "image/png";
        }
        doc["images"].push_back({{"bufferView", buffer.view(bytes.data(), bytes.size())}, {"mimeType", mime}});
        doc["samplers"].push_back({{"wrapS", wrapCode(t->wrapS)},
                                   {"wrapT", wrapCode(t->wrapT)},
                                   {"magFilter", 9728},
                                   {"minFilter", 9728}});  // nearest, as shadowlab samples
        doc["textures"].push_back(
            {{"source", int(doc["images"].size()) - 1}, {"sampler", int(doc["samplers"].size()) - 1}});
        return textureIndex[key] = int(doc["textures"].size()) - 1;
    };

    for (const Object& o : scene.objects) {
        const Material& m = scene.materialOf(o);
        glm::dvec3 translation(0.0);
        Geometry g;
        if (const auto* s = std::get_if<Sphere>(&o.shape)) {
            translation = s->center;
            g = sphereGeometry(*s, segments, rings);
            result.achievedTolerance = std::max(result.achievedTolerance, sagitta);
        } else if (const auto* q = std::get_if<Quad>(&o.shape)) {
            translation = q->center;
            g = quadGeometry(*q);
        } else if (const auto* b = std::get_if<Box>(&o.shape)) {
            translation = 0.5 * (b->min + b->max);
            g = boxGeometry(*b);
        } else {
            translation = boundsOf(o.shape).center();
            g = meshGeometry(std::get<Mesh>(o.shape), translation);
        }
        // The material, one per object (see the file comment). Shadowlab's alpha (scene.h): MASK
        // keeps its cutoff and factor; opacity < 1 becomes BLEND with alpha = opacity × factor,
        // which a shadowlab load reads back as transmittance 1 − alpha (the same light through).
        Json mat = {{"name", m.name}, {"doubleSided", true}};
        const bool blend = m.alphaMode == AlphaMode::Blend || (m.opacity < 1.0 && m.alphaMode != AlphaMode::Mask);
        const double alpha = blend ? m.opacity * m.alphaFactor : m.alphaFactor;
        mat["pbrMetallicRoughness"] = {{"baseColorFactor", {m.albedo.x, m.albedo.y, m.albedo.z, alpha}},
                                       {"metallicFactor", 0.0},
                                       {"roughnessFactor", 1.0}};
        if (m.alphaMode == AlphaMode::Mask) {
            if (m.opacity < 1.0)
                throw InputError(scene.file.string() + ": material '" + m.name +
                                 "' is alpha-masked and has opacity < 1, which one glTF material cannot say");
            mat["alphaMode"] = "MASK";
            mat["alphaCutoff"] = m.alphaCutoff;
        } else if (blend) {
            mat["alphaMode"] = "BLEND";
        }
        const bool textured = m.alphaTextured() && !g.uvs.empty();
        if (textured) mat["pbrMetallicRoughness"]["baseColorTexture"] = {{"index", textureOf(m)}, {"texCoord", 0}};
        if (!textured) g.uvs.clear();
        doc["materials"].push_back(mat);
        const int materialIndex = int(doc["materials"].size()) - 1;

        glm::vec3 lo(std::numeric_limits<float>::max()), hi(-std::numeric_limits<float>::max());
        for (const glm::vec3& p : g.positions) {
            lo = glm::min(lo, p);
            hi = glm::max(hi, p);
        }
        Json attributes;
        attributes["POSITION"] = buffer.accessor(g.positions.data(), g.positions.size() * 12, g.positions.size(), 5126,
                                                 "VEC3", 34962, {lo.x, lo.y, lo.z}, {hi.x, hi.y, hi.z});
        attributes["NORMAL"] =
            buffer.accessor(g.normals.data(), g.normals.size() * 12, g.normals.size(), 5126, "VEC3", 34962);
        if (!g.uvs.empty())
            attributes["TEXCOORD_0"] =
                buffer.accessor(g.uvs.data(), g.uvs.size() * 8, g.uvs.size(), 5126, "VEC2", 34962);
        const int indices =
            buffer.accessor(g.indices.data(), g.indices.size() * 4, g.indices.size(), 5125, "SCALAR", 34963);
        doc["meshes"].push_back(
            {{"name", o.name},
             {"primitives",
              Json::array(
                  {{{"attributes", attributes}, {"indices", indices}, {"material", materialIndex}, {"mode", 4}}})}});
        addNode({{"name", o.name}, {"mesh", int(doc["meshes"].size()) - 1}, {"translation", vecJson(translation)}});
        result.triangles += g.indices.size() / 3;
    }

    // The camera; its image size in extras, which a shadowlab load keeps (the aspect ratio alone
    // would give the height only up to rounding at another width).
    const Camera& c = scene.camera;
    doc["cameras"] = Json::array({{{"type", "perspective"},
                                   {"perspective",
                                    {{"yfov", c.fovYDegrees * kPi / 180.0},
                                     {"aspectRatio", double(c.width) / double(c.height)},
                                     {"znear", c.near},
                                     {"zfar", c.far}}},
                                   {"extras", {{"shadowlab", {{"resolution", {c.width, c.height}}}}}}}});
    addNode({{"name", "camera"},
             {"camera", 0},
             {"translation", vecJson(c.position)},
             {"rotation", quatJson(orientation(c.lookAt - c.position, c.up))}});

    // Lights: the inverse of the glTF loader's conversions (scene/loader.cpp, loadModelScene).
    Json lights = Json::array();
    for (std::size_t i = 0; i < scene.lights.size(); ++i) {
        const Light& l = scene.lights[i];
        Json gl = {{"name", "light" + std::to_string(i)}, {"color", vecJson(l.color)}};
        Json node = {{"name", "light" + std::to_string(i)}};
        if (l.type == LightType::Directional) {
            gl["type"] = "directional";
            gl["intensity"] = l.intensity;  // lux; the loader reads it as it is
        } else {
            gl["type"] = l.type == LightType::Spot ? "spot" : "point";
            // Ours is I/(4π d²), glTF's candela I/d²: the loader multiplies by 4π.
            gl["intensity"] = l.intensity / (4.0 * kPi);
            node["translation"] = vecJson(l.position);
            if (l.type == LightType::Spot) {
                const double outer = l.coneAngleDegrees * kPi / 180.0;
                // glTF needs inner < outer: a hard cone's inner angle is just inside it.
                const double inner = l.innerConeAngleDegrees < l.coneAngleDegrees
                                         ? l.innerConeAngleDegrees * kPi / 180.0
                                         : outer * kExportHardConeInnerRatio;
                gl["spot"] = {{"outerConeAngle", outer}, {"innerConeAngle", inner}};
            }
        }
        if (l.radius > 0) gl["extras"] = {{"shadowlab", {{"radius", l.radius}}}};
        if (l.type != LightType::Point) node["rotation"] = quatJson(orientation(l.direction, glm::dvec3(0, 1, 0)));
        node["extensions"] = {{"KHR_lights_punctual", {{"light", int(i)}}}};
        lights.push_back(gl);
        addNode(node);
    }
    doc["extensionsUsed"] = Json::array({"KHR_lights_punctual"});
    doc["extensions"] = {{"KHR_lights_punctual", {{"lights", lights}}}};
    doc["asset"]["extras"] = {{"shadowlab",
                               {{"source", scene.file.filename().string()},
                                {"tolerance", options.tolerance},
                                {"achieved_tolerance", result.achievedTolerance},
                                {"sphere_segments", segments},
                                {"sphere_rings", rings},
                                {"ambient", scene.ambient},
                                {"background", vecJson(scene.background)}}}};

    std::vector<unsigned char>& bin = buffer.bytes();
    while (bin.size() % 4) bin.push_back(0);
    Json bufferJson = {{"byteLength", bin.size()}};
    if (ext == ".gltf") bufferJson["uri"] = "data:application/octet-stream;base64," + base64(bin);
    doc["buffers"] = Json::array({bufferJson});

    const fs::path tmp = temporarySibling(file);
    try {
        std::ofstream out(tmp, std::ios::binary | std::ios::trunc);
        if (!out) throw InputError(file.string() + ": cannot open for writing");
        if (ext == ".gltf") {
            out << doc.dump(1);
        } else {
            std::string json = doc.dump();
            while (json.size() % 4) json.push_back(' ');
            auto put32 = [&](std::uint32_t v) { out.write(reinterpret_cast<const char*>(&v), 4); };
            // GLB (glTF 2.0, 4.4): header, JSON chunk, BIN chunk; little-endian, as x86-64 is.
            put32(0x46546C67);
            put32(2);
            put32(std::uint32_t(12 + 8 + json.size() + 8 + bin.size()));
            put32(std::uint32_t(json.size()));
            put32(0x4E4F534A);
            out.write(json.data(), std::streamsize(json.size()));
            put32(std::uint32_t(bin.size()));
            put32(0x004E4942);
            out.write(reinterpret_cast<const char*>(bin.data()), std::streamsize(bin.size()));
        }
        out.close();
        if (!out) throw InputError(file.string() + ": write failed");
        fs::rename(tmp, file);
    } catch (...) {
        std::error_code ignored;
        fs::remove(tmp, ignored);
        throw;
    }
    return result;
}

}  // namespace shadowlab::scene
