// scene/frame_identity.cpp: the scene hash, the OpenEXR camera matrices and the identity check.
#include "scene/frame_identity.h"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <cstring>
#include <deque>
#include <memory>
#include <mutex>
#include <type_traits>
#include <vector>

#include "scene/camera.h"

namespace shadowlab::scene {

namespace {

// FNV-1a, 64 bits (Fowler, Noll, Vo; the published offset basis and prime).
class Hasher {
public:
    void bytes(const void* data, std::size_t n) {
        const auto* p = static_cast<const unsigned char*>(data);
        for (std::size_t i = 0; i < n; ++i) h_ = (h_ ^ p[i]) * 0x100000001b3ull;
    }
    template <typename T>
    void value(const T& v) {
        static_assert(std::is_trivially_copyable_v<T>);
        bytes(&v, sizeof v);
    }
    void vec(const Vec3& v) { value(v.x), value(v.y), value(v.z); }
    std::uint64_t digest() const { return h_; }

private:
    std::uint64_t h_ = 0xcbf29ce484222325ull;
};

glm::mat4 toFloat(const glm::dmat4& m) { return glm::mat4(m); }

// One pass over the scene. With `bulk`, the meshes' positions, normals, UVs and indices and the
// alpha textures' texels are not hashed but their owners recorded there: the digest of the rest,
// the cache's key (sceneHash).
std::uint64_t digestOf(const Scene& scene, std::vector<std::shared_ptr<const void>>* bulk) {
    Hasher h;
    h.vec(scene.background);
    h.value(scene.ambient);
    h.value(scene.materials.size());
    for (const Material& m : scene.materials) {
        h.vec(m.albedo), h.value(m.opacity);
        // Alpha only where it is used, so that scenes without it keep their identities.
        if (m.alphaMode != AlphaMode::Opaque) {
            h.value(int(m.alphaMode)), h.value(m.alphaCutoff), h.value(m.alphaFactor), h.value(m.texCoord);
            if (m.alphaTexture) {
                h.value(m.alphaTexture->width), h.value(m.alphaTexture->height);
                h.value(int(m.alphaTexture->wrapS)), h.value(int(m.alphaTexture->wrapT));
                if (bulk)
                    bulk->push_back(m.alphaTexture);
                else
                    h.bytes(m.alphaTexture->alpha.data(), m.alphaTexture->alpha.size() * sizeof(float));
            }
        }
    }
    h.value(scene.lights.size());
    for (const Light& l : scene.lights) {
        h.value(int(l.type));
        h.vec(l.direction), h.vec(l.position), h.vec(l.color);
        h.value(l.intensity), h.value(l.radius), h.value(l.coneAngleDegrees);
        // (Only a soft edge is hashed: a hard cone's scene keeps the identity it had.)
        if (l.type == LightType::Spot && l.innerConeAngleDegrees < l.coneAngleDegrees) h.value(l.innerConeAngleDegrees);
    }
    h.value(scene.objects.size());
    for (const Object& o : scene.objects) {
        h.value(o.material);
        h.value(o.shape.index());
        if (const auto* s = std::get_if<Sphere>(&o.shape)) {
            h.vec(s->center), h.value(s->radius);
        } else if (const auto* q = std::get_if<Quad>(&o.shape)) {
            h.vec(q->center), h.vec(q->normal), h.value(q->size.x), h.value(q->size.y);
            if (q->uvMin != Vec2(0, 0) || q->uvMax != Vec2(1, 1)) h.vec(Vec3(q->uvMin, 0)), h.vec(Vec3(q->uvMax, 0));
        } else if (const auto* b = std::get_if<Box>(&o.shape)) {
            h.vec(b->min), h.vec(b->max);
        } else if (const auto* m = std::get_if<Mesh>(&o.shape)) {
            h.value(m->instances.size());
            for (const MeshInstance& inst : m->instances) {
                for (int c = 0; c < 4; ++c) h.vec(inst.transform[c]);
                const TriangleMesh& g = *inst.geometry;
                h.value(g.positions.size());
                if (bulk) {
                    bulk->push_back(inst.geometry);
                    h.value(g.indices.size());
                    continue;
                }
                h.bytes(g.positions.data(), g.positions.size() * sizeof(Vec3));
                h.bytes(g.normals.data(), g.normals.size() * sizeof(Vec3));
                if (!g.uvs.empty()) h.bytes(g.uvs.data(), g.uvs.size() * sizeof(Vec2));
                h.value(g.indices.size());
                h.bytes(g.indices.data(), g.indices.size() * sizeof(std::uint32_t));
            }
        }
    }
    return h.digest();
}

std::string hex(std::uint64_t digest) {
    char text[17];
    std::snprintf(text, sizeof text, "%016llx", static_cast<unsigned long long>(digest));
    return text;
}

// The last scenes hashed: the digest of everything but the bulk, the bulk's owners (a Scene's meshes
// and alpha textures are shared and never changed once loaded, so the same live one has the same
// bytes), and the full hash. A sweep or a camera path records the identity of every frame of one
// scene; hashing Sponza's 262k triangles each time cost a run about 2% of its CPU.
struct CachedHash {
    std::uint64_t key = 0;
    std::vector<std::weak_ptr<const void>> bulk;
    std::string hash;
};
std::mutex cacheMutex;
std::deque<CachedHash> cache;  // newest first
constexpr std::size_t kCachedScenes = 4;

}  // namespace

std::string sceneHash(const Scene& scene) {
    std::vector<std::shared_ptr<const void>> bulk;
    const std::uint64_t key = digestOf(scene, &bulk);
    if (bulk.empty()) return hex(key);  // nothing was left out: the key is the hash
    auto same = [&](const CachedHash& c) {
        if (c.key != key || c.bulk.size() != bulk.size()) return false;
        for (std::size_t i = 0; i < bulk.size(); ++i)
            if (c.bulk[i].lock() != bulk[i]) return false;  // gone, or another one
        return true;
    };
    {
        const std::lock_guard<std::mutex> lock(cacheMutex);
        for (const CachedHash& c : cache)
            if (same(c)) return c.hash;
    }
    CachedHash entry{key, {bulk.begin(), bulk.end()}, hex(digestOf(scene, nullptr))};
    const std::string hash = entry.hash;
    const std::lock_guard<std::mutex> lock(cacheMutex);
    cache.push_front(std::move(entry));
    if (cache.size() > kCachedScenes) cache.pop_back();
    return hash;
}

glm::dmat4 worldToCamera(const Camera& camera) {
    const CameraBasis c = cameraBasis(camera);
    glm::dmat4 m(1.0);  // m[column][row]
    const Vec3 rows[3] = {c.right, c.up, c.forward};
    for (int r = 0; r < 3; ++r) {
        m[0][r] = rows[r].x;
        m[1][r] = rows[r].y;
        m[2][r] = rows[r].z;
        m[3][r] = -glm::dot(rows[r], c.position);
    }
    return m;
}

glm::dmat4 worldToNDC(const Camera& camera) {
    const CameraBasis c = cameraBasis(camera);
    // From camera space (x, y, z, 1), z > 0 in front: w = z, and after the divide
    // x = 0.5 + 0.5·x/(z·tan·aspect), y = 0.5 − 0.5·y/(z·tan), the inverse of pixelDirection()'s
    // sx = (2(x+0.5)/W − 1)·tan·aspect; z = far·(z − near)/(z·(far − near)).
    const double sx = 0.5 / (c.tanHalfFovY * c.aspect), sy = -0.5 / c.tanHalfFovY;
    const double n = camera.near, f = camera.far;
    glm::dmat4 p(0.0);  // p[column][row]
    p[0][0] = sx;
    p[2][0] = 0.5;
    p[1][1] = sy;
    p[2][1] = 0.5;
    p[2][2] = f / (f - n);
    p[3][2] = -f * n / (f - n);
    p[2][3] = 1.0;
    return p * worldToCamera(camera);
}

void recordIdentity(Frame& frame, const Scene& scene) {
    frame.attributes["scene_hash"] = sceneHash(scene);
    frame.typedAttributes["worldToCamera"] = toFloat(worldToCamera(scene.camera));
    frame.typedAttributes["worldToNDC"] = toFloat(worldToNDC(scene.camera));
    frame.typedAttributes["light_count"] = int(scene.lights.size());
    static const char* kTypes[] = {"directional", "point", "spot"};
    for (std::size_t i = 0; i < scene.lights.size(); ++i) {
        const Light& l = scene.lights[i];
        const std::string k = "light." + std::to_string(i) + ".";
        frame.attributes[k + "type"] = kTypes[int(l.type)];
        frame.typedAttributes[k + "color"] = glm::vec3(l.color);
        frame.typedAttributes[k + "intensity"] = float(l.intensity);
        if (l.type != LightType::Point) frame.typedAttributes[k + "direction"] = glm::vec3(l.direction);
        if (l.type != LightType::Directional) {
            frame.typedAttributes[k + "position"] = glm::vec3(l.position);
            frame.typedAttributes[k + "radius"] = float(l.radius);
        }
        if (l.type == LightType::Spot) frame.typedAttributes[k + "cone_angle"] = float(l.coneAngleDegrees);
        if (l.type == LightType::Spot && l.innerConeAngleDegrees < l.coneAngleDegrees)
            frame.typedAttributes[k + "inner_cone_angle"] = float(l.innerConeAngleDegrees);
    }
}

std::string describeIdentityDifference(const Frame& method, const Frame& reference) {
    if (method.width != reference.width || method.height != reference.height)
        return "different image sizes (method " + std::to_string(method.width) + "x" + std::to_string(method.height) +
               ", reference " + std::to_string(reference.width) + "x" + std::to_string(reference.height) + ")";
    const auto a = method.attributes.find("scene_hash"), b = reference.attributes.find("scene_hash");
    if (a != method.attributes.end() && b != reference.attributes.end() && a->second != b->second) {
        auto name = [](const Frame& f) {
            const auto it = f.attributes.find("scene");
            return it == f.attributes.end() ? std::string("?") : it->second;
        };
        return "different scenes (scene_hash " + a->second + " of " + name(method) + ", " + b->second + " of " +
               name(reference) + ")";
    }
    for (const char* matrix : {"worldToCamera", "worldToNDC"}) {
        const auto ma = method.typedAttributes.find(matrix), mb = reference.typedAttributes.find(matrix);
        if (ma == method.typedAttributes.end() || mb == reference.typedAttributes.end()) continue;
        const auto* x = std::get_if<glm::mat4>(&ma->second);
        const auto* y = std::get_if<glm::mat4>(&mb->second);
        if (!x || !y) return std::string("different cameras (") + matrix + " is not a 4x4 matrix in both)";
        // The same camera gives the same floats; 1e-5 relative (a few float steps) allows a
        // matrix that another program wrote from the same camera in another order of operations.
        for (int c = 0; c < 4; ++c)
            for (int r = 0; r < 4; ++r) {
                const float u = (*x)[c][r], v = (*y)[c][r];
                if (!(std::abs(u - v) <= 1e-5f * std::max({1.0f, std::abs(u), std::abs(v)}))) {
                    char where[160];
                    // Row r, column c of the column-vector matrix is EXR's [c][r].
                    std::snprintf(where, sizeof where, "%s[%d][%d] is %.7g in the method, %.7g in the reference",
                                  matrix, c, r, double(u), double(v));
                    return std::string("different cameras (") + where + ")";
                }
            }
    }
    return "";
}

}  // namespace shadowlab::scene
