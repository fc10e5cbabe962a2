// tests/kit/test_scenes.h: the scenes the backend tests build in code (no loader needed) and the
// closed-form answers they are judged by, shared by tests/raster, tests/raytrace, tests/backends
// and tests/studies. The oracles (ray–sphere and ray–plane algebra, the sphere's hard shadow, the
// floor point behind a pixel) are written here independently of raster/ and raytrace/.
#pragma once

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <map>
#include <memory>
#include <optional>
#include <random>
#include <string>
#include <utility>
#include <variant>
#include <vector>

#include "scene/camera.h"
#include "scene/frame.h"
#include "scene/render_plan.h"
#include "scene/scene.h"
#include "scene/settings.h"

namespace shadowlab::test {

using scene::Vec3;

inline constexpr double kPi = 3.14159265358979323846;

// ---------------------------------------------------------------------------------------------
// Building scenes

inline int addMaterial(scene::Scene& s, const std::string& name, double opacity = 1.0) {
    scene::Material m;
    m.name = name;
    m.opacity = opacity;
    s.materials.push_back(m);
    return int(s.materials.size()) - 1;
}

inline void addSphere(scene::Scene& s, const Vec3& c, double r, int material = 0) {
    scene::Object o;
    o.name = "objects[" + std::to_string(s.objects.size()) + "]";
    o.shape = scene::Sphere{c, r};
    o.material = material;
    s.objects.push_back(o);
}

// A quad centred at c with normal n, sizeU along its uAxis and sizeV along its vAxis (quadAxes).
inline scene::Quad quadShape(const Vec3& c, const Vec3& n, double sizeU, double sizeV) {
    scene::Quad q;
    q.center = c;
    q.normal = glm::normalize(n);
    q.size = scene::Vec2(sizeU, sizeV);
    scene::quadAxes(q.normal, q.uAxis, q.vAxis);
    return q;
}

inline void addQuad(scene::Scene& s, const Vec3& c, const Vec3& n, double sizeU, double sizeV, int material = 0) {
    scene::Object o;
    o.name = "objects[" + std::to_string(s.objects.size()) + "]";
    o.shape = quadShape(c, n, sizeU, sizeV);
    o.material = material;
    s.objects.push_back(o);
}

// `s` with a 1x1 quad of material `m` (added as the last material) `height` above the origin,
// facing up: a leaf over a test scene.
inline scene::Scene withLeaf(scene::Scene s, double height, scene::Material m) {
    s.materials.push_back(std::move(m));
    addQuad(s, Vec3(0, height, 0), Vec3(0, 1, 0), 1, 1, int(s.materials.size()) - 1);
    return s;
}

// A horizontal quad (normal +y) named `name`: for +y, quadAxes gives u = +x and v = −z, so its
// size is (x extent, z extent).
inline scene::Object horizontalQuad(const std::string& name, const Vec3& center, double sizeX, double sizeZ,
                                    int material = 0) {
    return {name, quadShape(center, Vec3(0, 1, 0), sizeX, sizeZ), material};
}

inline void addBox(scene::Scene& s, const Vec3& lo, const Vec3& hi, int material = 0) {
    scene::Object o;
    o.name = "objects[" + std::to_string(s.objects.size()) + "]";
    o.shape = scene::Box{lo, hi};
    o.material = material;
    s.objects.push_back(o);
}

inline void addDirectional(scene::Scene& s, const Vec3& direction, double intensity = 3.0) {
    scene::Light l;
    l.type = scene::LightType::Directional;
    l.direction = glm::normalize(direction);
    l.intensity = intensity;
    s.lights.push_back(l);
}

inline void addMesh(scene::Scene& s, std::shared_ptr<const scene::TriangleMesh> geometry, int material = 0) {
    scene::Object o;
    o.name = "objects[" + std::to_string(s.objects.size()) + "]";
    o.shape = scene::Mesh::single("generated", std::move(geometry));
    o.material = material;
    s.objects.push_back(o);
}

// A scene of one mesh with the one material "matte" (no lights, no camera): what a tracer test needs.
inline scene::Scene matteMeshScene(std::shared_ptr<const scene::TriangleMesh> geometry) {
    scene::Scene s;
    addMaterial(s, "matte");
    addMesh(s, std::move(geometry));
    return s;
}

// An alpha texture w x h (row 0 at the top) with the given wrap modes.
inline std::shared_ptr<scene::AlphaTexture> alphaTexture(int w, int h, std::vector<float> alpha,
                                                         scene::TextureWrap s = scene::TextureWrap::Repeat,
                                                         scene::TextureWrap t = scene::TextureWrap::Repeat) {
    auto tex = std::make_shared<scene::AlphaTexture>();
    tex->file = "test-texture";
    tex->width = w;
    tex->height = h;
    tex->alpha = std::move(alpha);
    tex->wrapS = s;
    tex->wrapT = t;
    return tex;
}

// An n x n checkerboard of alpha `a` (texel x + y even) and `b`.
inline std::shared_ptr<scene::AlphaTexture> checkerTexture(int n, float a, float b) {
    std::vector<float> alpha;
    for (int y = 0; y < n; ++y)
        for (int x = 0; x < n; ++x) alpha.push_back((x + y) % 2 == 0 ? a : b);
    return alphaTexture(n, n, alpha);
}

// A material named `name` with a glTF alpha mode, alpha texture (or none) and cutoff.
inline scene::Material alphaMaterial(const std::string& name, scene::AlphaMode mode,
                                     std::shared_ptr<const scene::AlphaTexture> tex, double cutoff = 0.5) {
    scene::Material m;
    m.name = name;
    m.alphaMode = mode;
    m.alphaCutoff = cutoff;
    m.alphaTexture = std::move(tex);
    return m;
}

// Makes quad object `index` of `s` a mesh that can shade itself (raster/light_frustum.h
// shadesItself), so that its whole visible part is a shadowable receiver and directional maps
// and cascades are fitted over all of it: the quad's two triangles (the same plane, normal and
// object id) plus a sliver hanging below its (−u, −v) corner, 1e-3 of its size deep, under the
// quad where a camera above it does not see it. The bounds grow by that depth below it.
inline void makeGroundShadeItself(scene::Scene& s, std::size_t index) {
    const scene::Quad q = std::get<scene::Quad>(s.objects[index].shape);
    const Vec3 hu = 0.5 * q.size.x * q.uAxis, hv = 0.5 * q.size.y * q.vAxis;
    const double depth = 1e-3 * std::max(q.size.x, q.size.y);
    auto mesh = std::make_shared<scene::TriangleMesh>();
    const Vec3 corner = q.center - hu - hv;
    mesh->positions = {corner,
                       q.center + hu - hv,
                       q.center + hu + hv,
                       q.center - hu + hv,
                       corner + 1e-3 * (q.center - corner),
                       corner - depth * q.normal};
    mesh->indices = {0, 1, 2, 0, 2, 3, 0, 4, 5};
    const Vec3 side = glm::normalize(glm::cross(mesh->positions[4] - corner, mesh->positions[5] - corner));
    mesh->normals = {q.normal, q.normal, q.normal, q.normal, side, side};
    s.objects[index].shape = scene::Mesh::single("ground-shading-itself", std::move(mesh));
}

// A closed, convex triangle mesh: an icosahedron subdivided `levels` times and pushed onto the
// sphere (center, radius). Shared vertices are shared indices, so every edge has exactly two
// triangles.
inline std::shared_ptr<scene::TriangleMesh> icosphere(const Vec3& center, double radius, int levels) {
    auto mesh = std::make_shared<scene::TriangleMesh>();
    const double t = (1.0 + std::sqrt(5.0)) / 2.0;
    std::vector<Vec3> v = {{-1, t, 0},  {1, t, 0},  {-1, -t, 0}, {1, -t, 0}, {0, -1, t},  {0, 1, t},
                           {0, -1, -t}, {0, 1, -t}, {t, 0, -1},  {t, 0, 1},  {-t, 0, -1}, {-t, 0, 1}};
    std::vector<std::uint32_t> f = {0, 11, 5,  0, 5,  1, 0, 1, 7, 0, 7,  10, 0, 10, 11, 1, 5, 9, 5, 11,
                                    4, 11, 10, 2, 10, 7, 6, 7, 1, 8, 3,  9,  4, 3,  4,  2, 3, 2, 6, 3,
                                    6, 8,  3,  8, 9,  4, 9, 5, 2, 4, 11, 6,  2, 10, 8,  6, 7, 9, 8, 1};
    for (Vec3& p : v) p = glm::normalize(p);
    for (int l = 0; l < levels; ++l) {
        std::map<std::pair<std::uint32_t, std::uint32_t>, std::uint32_t> mid;
        auto midpoint = [&](std::uint32_t a, std::uint32_t b) {
            const auto key = std::minmax(a, b);
            auto it = mid.find(key);
            if (it != mid.end()) return it->second;
            v.push_back(glm::normalize(v[a] + v[b]));
            const std::uint32_t i = std::uint32_t(v.size() - 1);
            mid.emplace(key, i);
            return i;
        };
        std::vector<std::uint32_t> g;
        for (std::size_t k = 0; k < f.size(); k += 3) {
            const std::uint32_t a = f[k], b = f[k + 1], c = f[k + 2];
            const std::uint32_t ab = midpoint(a, b), bc = midpoint(b, c), ca = midpoint(c, a);
            for (std::uint32_t x : {a, ab, ca, b, bc, ab, c, ca, bc, ab, bc, ca}) g.push_back(x);
        }
        f.swap(g);
    }
    for (const Vec3& p : v) {
        mesh->positions.push_back(center + radius * p);
        mesh->normals.push_back(p);
    }
    mesh->indices = f;
    return mesh;
}

// `count` random small boxes in [−100, 100]³ (seeded), every tenth sharing one centroid (5, 5, 5):
// no SAH split exists among those, so a BVH build's halve-by-count path runs too.
inline std::vector<scene::Bounds> randomBoxes(int count, std::uint64_t seed) {
    std::mt19937_64 g(seed);
    std::uniform_real_distribution<double> pos(-100, 100), size(0.01, 3);
    std::vector<scene::Bounds> out(static_cast<std::size_t>(count));
    for (std::size_t i = 0; i < out.size(); ++i) {
        const Vec3 c = i % 10 == 0 ? Vec3(5, 5, 5) : Vec3(pos(g), pos(g), pos(g));
        const Vec3 h(size(g), size(g), size(g));
        out[i].extend(c - h);
        out[i].extend(c + h);
    }
    return out;
}

// A direction for light arriving `elevationDegrees` above the horizon, travelling toward -x.
inline Vec3 lightFromElevation(double elevationDegrees) {
    const double a = elevationDegrees * kPi / 180.0;
    return Vec3(-std::cos(a), -std::sin(a), 0.0);
}

// A rotation about a unit axis by `degrees` (Rodrigues' formula).
inline glm::dmat3 rotation(const Vec3& axis, double degrees) {
    const Vec3 k = glm::normalize(axis);
    const double a = degrees * kPi / 180.0, c = std::cos(a), s = std::sin(a);
    const glm::dmat3 K(0, k.z, -k.y, -k.z, 0, k.x, k.y, -k.x, 0);  // column-major cross matrix
    return glm::dmat3(1.0) + s * K + (1 - c) * K * K;
}

// Where a scene is placed: world = rotation · local + offset.
struct Placement {
    Vec3 offset{0};
    glm::dmat3 rotation{1.0};
    Vec3 toWorld(const Vec3& local) const { return rotation * local + offset; }
    Vec3 dirToWorld(const Vec3& local) const { return rotation * local; }
    Vec3 toLocal(const Vec3& world) const { return glm::transpose(rotation) * (world - offset); }
    Vec3 dirToLocal(const Vec3& world) const { return glm::transpose(rotation) * world; }
};

// ---------------------------------------------------------------------------------------------
// The scenes

// The seed scene (the lesson's, as scenes/seed.json): sphere r=1 at (0,1,0) on the 20x20 plane
// y=0, light along (-1,-2,-1), camera at (0,2,6) looking at (0,0.7,0), fov 40; placed by `at`.
inline scene::Scene seedScene(const Placement& at = {}, int width = 160, int height = 90) {
    scene::Scene s;
    s.camera.position = at.toWorld(Vec3(0, 2, 6));
    s.camera.lookAt = at.toWorld(Vec3(0, 0.7, 0));
    s.camera.up = at.dirToWorld(Vec3(0, 1, 0));
    s.camera.fovYDegrees = 40;
    s.camera.width = width;
    s.camera.height = height;
    addMaterial(s, "matte");
    addDirectional(s, at.dirToWorld(Vec3(-1, -2, -1)));
    addSphere(s, at.toWorld(Vec3(0, 1, 0)), 1.0);
    addQuad(s, at.toWorld(Vec3(0)), at.dirToWorld(Vec3(0, 1, 0)), 20, 20);
    return s;
}

// The sphere-over-plane scene of the raster tests: sphere (id 1) above a square plane y = 0
// (id 2), one directional light. Small image so a render takes well under a second on lavapipe.
struct SphereOverPlane {
    Vec3 center{0, 1, 0};
    double radius = 0.5;
    double planeSize = 8.0;
    Vec3 lightDirection{0, -1, 0};
    Vec3 eye{0, 4, 6};
    Vec3 lookAt{0, 0.5, 0};
    int width = 160;
    int height = 90;
};

// A scene without objects or lights seen from `eye` toward `lookAt` (up +y, fov 40°, near 0.1,
// `far`), ambient 0.05, and one material "matte" of albedo 0.8.
inline scene::Scene matteScene(const Vec3& eye, const Vec3& lookAt, int width, int height, double far = 100.0) {
    scene::Scene s;
    s.camera = {.position = eye, .lookAt = lookAt, .width = width, .height = height, .far = far};
    s.ambient = 0.05;
    addMaterial(s, "matte");
    s.materials[0].albedo = Vec3(0.8);
    return s;
}

// `shift` moves the whole scene (camera, sphere, plane), for tests far from the origin.
inline scene::Scene makeScene(const SphereOverPlane& p, const Vec3& shift = Vec3(0)) {
    scene::Scene s = matteScene(p.eye + shift, p.lookAt + shift, p.width, p.height);
    addDirectional(s, p.lightDirection);
    addSphere(s, p.center + shift, p.radius);
    addQuad(s, shift, Vec3(0, 1, 0), p.planeSize, p.planeSize);
    return s;
}

// A large scene for cascades: a 200 x 200 plane (id 1; x in -100..100, z in -200..0) with spheres
// of radius 0.6 resting above it along the view (ids 2...), seen from a low camera at the plane's
// near edge looking down the length of it, so that the visible receivers span view depths from a
// few units to ~200 and every cascade's slice holds some of the plane.
inline scene::Scene makeLongPlane(int width = 160, int height = 90) {
    scene::Scene s = matteScene(Vec3(0, 2.5, 2), Vec3(0, 0.5, -20), width, height, 400.0);
    addDirectional(s, Vec3(-1.0, -1.5, -0.6));
    addQuad(s, Vec3(0, 0, -100), Vec3(0, 1, 0), 200, 200);
    const double zs[] = {-3, -5, -8, -12, -18, -27, -40, -60, -90, -135};
    for (std::size_t i = 0; i < std::size(zs); ++i)
        addSphere(s, Vec3((i % 2 ? 1.5 : -1.5) * (1.0 - zs[i] / 40.0), 0.8, zs[i]), 0.6);
    return s;
}

// The map-size scenes: the first object becomes the box [−1, 1] x [0, 2] x [−1, 1] on the ground
// y = 0, and the camera at (0, 10, 0) looks straight down at it (up −z, the scene's fov), `height`
// rows at 16:9. The box's top lies at view depth 8, the ground at 10.
inline void boxUnderADownwardCamera(scene::Scene& s, int height) {
    s.objects[0].shape = scene::Box{{-1, 0, -1}, {1, 2, 1}};
    s.camera.position = {0, 10, 0};
    s.camera.lookAt = {0, 0, 0};
    s.camera.up = {0, 0, -1};
    s.camera.width = height * 16 / 9;
    s.camera.height = height;
}

// A spot at (0, 8, 0) straight down, cone 60° (the map's half-angle 61.2°, tan ≈ 1.82), intensity
// 800. Its map's basis (setBasis: the axis is vertical, so right = dir × X) is right = +z, up = +x:
// u = z/d, v = x/d with d = 8 − y.
// A spot at `position` pointing straight down (−y), a hard cone of this half-angle.
inline scene::Light spotPointingDown(const scene::Vec3& position, double coneDegrees, double intensity) {
    scene::Light l;
    l.type = scene::LightType::Spot;
    l.position = position;
    l.direction = {0, -1, 0};
    l.coneAngleDegrees = coneDegrees;
    l.intensity = intensity;
    return l;
}

inline scene::Light spotDown() { return spotPointingDown({0, 8, 0}, 60, 800); }

// Raster settings with every automatic choice already made (as resolveAutomaticChoices leaves
// them): a square map of `mapSize`, one cascade, depth bias 0.01 and slope bias 1.5.
inline scene::RasterSettings fixedSettings(int mapSize = 512) {
    scene::RasterSettings r;
    r.shadowMapSize = mapSize;
    r.shadowMapSizeIsDefault = false;
    r.cascades = 1;
    r.cascadesIsDefault = false;
    r.depthBias = 0.01;
    r.depthBiasIsDefault = false;
    r.slopeBias = 1.5;
    return r;
}

// The plan of `s` with RenderSettings{} (and `raster` in place of its raster part).
inline scene::RenderPlan planFor(const scene::Scene& s) { return scene::makeRenderPlan(s, scene::RenderSettings{}); }
inline scene::RenderPlan planFor(const scene::Scene& s, const scene::RasterSettings& raster) {
    scene::RenderSettings settings;
    settings.raster = raster;
    return scene::makeRenderPlan(s, settings);
}

inline scene::RaytraceSettings biasSettings(double bias, scene::Precision precision) {
    scene::RaytraceSettings r;
    r.rayBias = bias;
    r.robustOffset = false;
    r.precision = precision;
    r.samples = 1;
    r.threads = 2;
    return r;
}

// ---------------------------------------------------------------------------------------------
// The oracles

// The ray–sphere oracle: the line o + t·d against the sphere |x − c|² = r² gives
// a t² + 2 b t + k = 0 with a = d·d, b = d·(o − c), k = |o − c|² − r², so t = (−b ∓ √disc) / a with
// disc = b² − a·k; disc < 0: the line misses. (|d| need not be 1.)
struct SphereRoots {
    double a = 0, b = 0, k = 0, disc = -1;
    bool meets() const { return disc >= 0; }
    double tNear() const { return (-b - std::sqrt(disc)) / a; }
    double tFar() const { return (-b + std::sqrt(disc)) / a; }
};

inline SphereRoots sphereRoots(const Vec3& o, const Vec3& d, const Vec3& c, double r) {
    const Vec3 f = o - c;
    SphereRoots s;
    s.a = glm::dot(d, d);
    s.b = glm::dot(f, d);
    s.k = glm::dot(f, f) - r * r;
    s.disc = s.b * s.b - s.a * s.k;
    return s;
}

// Smallest t > 0 where o + t·d meets the sphere, if any.
inline std::optional<double> raySphere(const Vec3& o, const Vec3& d, const Vec3& c, double r) {
    const SphereRoots s = sphereRoots(o, d, c, r);
    if (!s.meets()) return std::nullopt;
    if (const double t0 = s.tNear(); t0 > 0) return t0;
    if (const double t1 = s.tFar(); t1 > 0) return t1;
    return std::nullopt;
}

// Does the ray from p along unit w meet the sphere (c, r) at some t > 0 (p inside it counts)?
// `relativeDiscriminant` gets disc / (b² + r²), so callers can skip near-tangent cases.
inline bool rayMeetsSphere(const Vec3& p, const Vec3& w, const Vec3& c, double r, double& relativeDiscriminant) {
    const SphereRoots s = sphereRoots(p, w, c, r);
    relativeDiscriminant = s.disc / (s.b * s.b + r * r);
    return s.meets() && s.tFar() > 0;
}

// The ray through the centre of pixel (x, y), built here from the camera's basis:
// forward + sx·right + sy·up, sx = (2(x+0.5)/W − 1)·tan(fov/2)·aspect, sy = (1 − 2(y+0.5)/H)·tan(fov/2).
inline Vec3 pixelRay(const scene::CameraBasis& c, int x, int y) {
    const double sx = (2.0 * (x + 0.5) / c.width - 1.0) * c.tanHalfFovY * c.aspect;
    const double sy = (1.0 - 2.0 * (y + 0.5) / c.height) * c.tanHalfFovY;
    return c.forward + sx * c.right + sy * c.up;
}

// Where the ray through the centre of pixel (x, y) meets the horizontal plane y = height (the
// line's crossing: the caller makes sure the pixel sees that plane).
inline Vec3 floorPoint(const scene::CameraBasis& c, int x, int y, double height = 0.0) {
    const Vec3 d = pixelRay(c, x, y);
    return c.position + ((height - c.position.y) / d.y) * d;
}

// Calls fn(q, visibility) for every pixel that shows object id `floorId` (a floor at y = 0), q its
// point on the floor from the test's own ray–plane intersection, not the renderer's.
template <class Fn>
void forEachFloorPixel(const scene::Scene& s, const scene::Frame& f, Fn fn, float floorId = 1.0f) {
    const scene::CameraBasis cam = scene::cameraBasis(s.camera);
    for (int y = 0; y < f.height; ++y)
        for (int x = 0; x < f.width; ++x) {
            const std::size_t i = std::size_t(y) * std::size_t(f.width) + std::size_t(x);
            if (f.objectId[i] != floorId) continue;
            fn(floorPoint(cam, x, y), double(f.visibility[i]));
        }
}

// The pixel whose center is nearest to the projection of world point q: with camera-space
// coordinates (x_c, y_c, z_c) = ((q−eye)·right, (q−eye)·up, (q−eye)·forward), the image-plane
// position is sx = x_c / (z_c·tan(fov/2)·aspect), sy = y_c / (z_c·tan(fov/2)), and column
// (sx + 1)/2·W, row (1 − sy)/2·H, rounded down.
inline std::pair<int, int> projectToPixel(const scene::CameraBasis& c, const Vec3& q) {
    const Vec3 d = q - c.position;
    const double zc = glm::dot(d, c.forward);
    const double sx = glm::dot(d, c.right) / (zc * c.tanHalfFovY * c.aspect);
    const double sy = glm::dot(d, c.up) / (zc * c.tanHalfFovY);
    return {int(std::floor((sx + 1.0) * 0.5 * c.width)), int(std::floor((1.0 - sy) * 0.5 * c.height))};
}

// The same as an index into a Frame's per-pixel vectors (the point must be in view).
inline std::size_t pixelIndexOf(const scene::Scene& s, const Vec3& q) {
    const auto [x, y] = projectToPixel(scene::cameraBasis(s.camera), q);
    return std::size_t(y) * std::size_t(s.camera.width) + std::size_t(x);
}

// What the camera sees through the center of pixel (x, y) of makeScene(p): 0 background,
// 1 sphere, 2 plane, and where.
struct PrimaryHit {
    int id = 0;
    Vec3 p{0};
};

inline PrimaryHit primaryHit(const SphereOverPlane& p, const scene::CameraBasis& c, int x, int y) {
    const Vec3 d = pixelRay(c, x, y);
    PrimaryHit hit;
    double best = INFINITY;
    if (const auto t = raySphere(c.position, d, p.center, p.radius)) {
        best = *t;
        hit.id = 1;
    }
    if (d.y != 0.0) {
        const double t = -c.position.y / d.y;  // plane y = 0
        const Vec3 q = c.position + t * d;
        if (t > 0 && t < best && std::abs(q.x) <= 0.5 * p.planeSize && std::abs(q.z) <= 0.5 * p.planeSize) {
            best = t;
            hit.id = 2;
        }
    }
    if (hit.id) hit.p = c.position + best * d;
    return hit;
}

// Calls fn(i, q) for every pixel of f, a frame of `s` (makeScene(p) or a variant), where the
// closed form sees the plane and the frame object id `frameId` (the plane's, 2 in makeScene(p)):
// i the pixel's index, q the closed form's point on the plane.
template <class Fn>
void forEachPlanePixel(const SphereOverPlane& p, const scene::Scene& s, const scene::Frame& f, Fn fn,
                       float frameId = 2.0f) {
    const scene::CameraBasis cam = scene::cameraBasis(s.camera);
    for (int y = 0; y < f.height; ++y)
        for (int x = 0; x < f.width; ++x) {
            const std::size_t i = std::size_t(y) * std::size_t(f.width) + std::size_t(x);
            const PrimaryHit h = primaryHit(p, cam, x, y);
            if (h.id == 2 && f.objectId[i] == frameId) fn(i, h.p);
        }
}

// The plane point q (y = 0) is in the sphere's shadow when the ray from q toward the light
// (−lightDirection) meets the sphere.
inline bool planePointShadowed(const SphereOverPlane& p, const Vec3& q) {
    return raySphere(q, -glm::normalize(p.lightDirection), p.center, p.radius).has_value();
}

// How far the plane point q lies behind the sphere's light-facing surface, measured along the
// light: the farther root of the ray from q toward the light (that surface is what the shadow
// map stores). Infinity when q is not in the sphere's shadow.
inline double depthBehindCaster(const SphereOverPlane& p, const Vec3& q) {
    const SphereRoots s = sphereRoots(q, -glm::normalize(p.lightDirection), p.center, p.radius);
    if (!s.meets()) return INFINITY;
    const double tFar = s.tFar();
    return tFar > 0 ? tFar : INFINITY;
}

// Closed-form answer for one pixel of seedScene(at): which surface the pixel sees and whether
// that point is lit, in double, from the algebra: the sphere's nearer root (sphereRoots) and the
// plane y = 0 at t = −o.y / d.y, in the scene's local frame; p and n are returned in world.
struct Analytic {
    enum Kind { Background, Sphere, Plane } kind = Background;
    Vec3 p{0};
    Vec3 n{0};
    bool lit = false;
    bool nearEdge = false;  // a discriminant or N·L within the margin of 0: not judged
    double shadowDiscriminant = 0;
};

inline Analytic analyticPixel(const scene::Scene& s, const Placement& at, int x, int y, double bias = 0.0,
                              double margin = 1e-9) {
    const scene::CameraBasis cam = scene::cameraBasis(s.camera);
    const Vec3 o = at.toLocal(cam.position);
    const Vec3 d = at.dirToLocal(scene::pixelDirection(cam, x, y));
    const Vec3 c = Vec3(0, 1, 0);
    const double r = 1.0;
    const Vec3 L = -glm::normalize(Vec3(-1, -2, -1));
    Analytic a;
    double tBest = INFINITY;
    if (const SphereRoots sphere = sphereRoots(o, d, c, r); sphere.meets()) {
        const double t = sphere.tNear();
        if (t > 0) {
            tBest = t;
            a.kind = Analytic::Sphere;
            a.p = o + t * d;
            a.n = (a.p - c) / r;
            if (sphere.disc < margin * sphere.b * sphere.b) a.nearEdge = true;  // silhouette
        }
    }
    // Plane y = 0, |x|, |z| <= 10.
    if (d.y != 0) {
        const double t = -o.y / d.y;
        const Vec3 p = o + t * d;
        const double u = std::abs(p.x), v = std::abs(p.z);
        if (t > 0 && t < tBest && u <= 10 && v <= 10) {
            tBest = t;
            a.kind = Analytic::Plane;
            a.p = p;
            a.n = Vec3(0, 1, 0);
            a.nearEdge = std::abs(u - 10) < 1e-6 || std::abs(v - 10) < 1e-6;
        }
    }
    if (a.kind == Analytic::Background) return a;
    const double ndotl = glm::dot(a.n, L);  // local normal, local light
    a.p = at.toWorld(a.p);
    a.n = at.dirToWorld(a.n);
    if (std::abs(ndotl) < margin) a.nearEdge = true;
    if (ndotl <= 0) return a;  // unlit: visibility 0
    if (a.kind == Analytic::Sphere) {
        a.lit = true;  // convex, and the plane is below it: nothing else can block
        return a;
    }
    double rel = 0;
    const bool blocked = rayMeetsSphere(at.toLocal(a.p) + bias * Vec3(0, 1, 0), L, c, r, rel);
    a.shadowDiscriminant = rel;
    if (std::abs(rel) < margin) a.nearEdge = true;
    a.lit = !blocked;
    return a;
}

}  // namespace shadowlab::test
