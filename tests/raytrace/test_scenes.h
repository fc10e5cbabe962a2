// tests/raytrace/test_scenes.h: scenes built in code for the ray tracer's tests, and the
// closed-form answer for the sphere-over-plane scene (ray–sphere and ray–plane algebra written
// here independently of raytrace/).
#pragma once

#include <cmath>
#include <map>
#include <memory>
#include <string>
#include <vector>

#include "scene/camera.h"
#include "scene/render_plan.h"
#include "scene/scene.h"
#include "scene/settings.h"

namespace shadowlab::raytrace::test {

using scene::Vec3;

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

inline void addQuad(scene::Scene& s, const Vec3& c, const Vec3& n, double sizeU, double sizeV,
                    int material = 0) {
    scene::Quad q;
    q.center = c;
    q.normal = glm::normalize(n);
    q.size = scene::Vec2(sizeU, sizeV);
    scene::quadAxes(q.normal, q.uAxis, q.vAxis);
    scene::Object o;
    o.name = "objects[" + std::to_string(s.objects.size()) + "]";
    o.shape = q;
    o.material = material;
    s.objects.push_back(o);
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

// Where the seed scene is placed: world = rotation · local + offset.
struct Placement {
    Vec3 offset{0};
    glm::dmat3 rotation{1.0};
    Vec3 toWorld(const Vec3& local) const { return rotation * local + offset; }
    Vec3 dirToWorld(const Vec3& local) const { return rotation * local; }
    Vec3 toLocal(const Vec3& world) const { return glm::transpose(rotation) * (world - offset); }
    Vec3 dirToLocal(const Vec3& world) const { return glm::transpose(rotation) * world; }
};

// A rotation about a unit axis by `degrees` (Rodrigues' formula).
inline glm::dmat3 rotation(const Vec3& axis, double degrees) {
    const Vec3 k = glm::normalize(axis);
    const double a = degrees * 3.14159265358979323846 / 180.0, c = std::cos(a), s = std::sin(a);
    const glm::dmat3 K(0, k.z, -k.y, -k.z, 0, k.x, k.y, -k.x, 0);  // column-major cross matrix
    return glm::dmat3(1.0) + s * K + (1 - c) * K * K;
}

// The seed scene (the lesson's): sphere r=1 at (0,1,0) on the 20x20 plane y=0, light along
// (-1,-2,-1), camera at (0,2,6) looking at (0,0.7,0), fov 40; placed by `at`.
inline scene::Scene sphereOverPlane(const Placement& at = {}, int width = 160, int height = 90) {
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

inline scene::RenderPlan planFor(const scene::Scene& s) {
    return scene::makeRenderPlan(s, scene::RenderSettings{});
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

// Closed-form answer for one pixel of sphereOverPlane(offset): which surface the pixel sees
// and whether that point is lit, in double, written from the algebra:
//   ray x = o + t·d hits sphere |x − c|² = r² where t² |d|² + 2t (d·f) + |f|² − r² = 0, f = o − c;
//   and the plane y = y0 at t = (y0 − o.y) / d.y.
struct Analytic {
    enum Kind { Background, Sphere, Plane } kind = Background;
    Vec3 p{0};
    Vec3 n{0};
    bool lit = false;
    bool nearEdge = false;  // a discriminant or N·L within the margin of 0: not judged
    double shadowDiscriminant = 0;
};

// Does the ray from p along unit w meet the sphere (c, r) at some t > 0? Returns the
// discriminant (f·w)² − (|f|² − r²) relative to (f·w)² + r², so callers can skip near-tangent
// cases.
inline bool rayMeetsSphere(const Vec3& p, const Vec3& w, const Vec3& c, double r,
                           double& relativeDiscriminant) {
    const Vec3 f = p - c;
    const double b = glm::dot(f, w);
    const double cc = glm::dot(f, f) - r * r;
    const double disc = b * b - cc;
    relativeDiscriminant = disc / (b * b + r * r);
    if (disc < 0) return false;
    const double far = -b + std::sqrt(disc);
    return far > 0;  // origin inside (cc < 0) or sphere ahead
}

// Everything below is in the scene's local frame (plane y = 0); p and n are returned in world.
inline Analytic analyticPixel(const scene::Scene& s, const Placement& at, int x, int y,
                              double bias = 0.0, double margin = 1e-9) {
    const scene::CameraBasis cam = scene::cameraBasis(s.camera);
    const Vec3 o = at.toLocal(cam.position);
    const Vec3 d = at.dirToLocal(scene::pixelDirection(cam, x, y));
    const Vec3 offset(0);
    const Vec3 c = Vec3(0, 1, 0);
    const double r = 1.0;
    const Vec3 L = -glm::normalize(Vec3(-1, -2, -1));
    Analytic a;
    double tBest = INFINITY;
    // Sphere, nearer root.
    {
        const Vec3 f = o - c;
        const double A = glm::dot(d, d), B = glm::dot(d, f), C = glm::dot(f, f) - r * r;
        const double disc = B * B - A * C;
        if (disc >= 0) {
            const double t = (-B - std::sqrt(disc)) / A;
            if (t > 0) {
                tBest = t;
                a.kind = Analytic::Sphere;
                a.p = o + t * d;
                a.n = (a.p - c) / r;
                if (disc < margin * B * B) a.nearEdge = true;  // silhouette
            }
        }
    }
    // Plane y = offset.y, |x|, |z| <= 10 around the offset.
    if (d.y != 0) {
        const double t = (offset.y - o.y) / d.y;
        const Vec3 p = o + t * d;
        const double u = std::abs(p.x - offset.x), v = std::abs(p.z - offset.z);
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

}  // namespace shadowlab::raytrace::test

namespace shadowlab::raytrace::test {

// A closed, convex triangle mesh: an icosahedron subdivided `levels` times and pushed onto the
// sphere (center, radius). Shared vertices are shared indices, so every edge has exactly two
// triangles.
inline std::shared_ptr<scene::TriangleMesh> icosphere(const Vec3& center, double radius,
                                                      int levels) {
    auto mesh = std::make_shared<scene::TriangleMesh>();
    const double t = (1.0 + std::sqrt(5.0)) / 2.0;
    std::vector<Vec3> v = {{-1, t, 0}, {1, t, 0}, {-1, -t, 0}, {1, -t, 0},
                           {0, -1, t}, {0, 1, t}, {0, -1, -t}, {0, 1, -t},
                           {t, 0, -1}, {t, 0, 1}, {-t, 0, -1}, {-t, 0, 1}};
    std::vector<std::uint32_t> f = {0, 11, 5, 0, 5,  1,  0,  1,  7,  0,  7,  10, 0, 10, 11,
                                    1, 5,  9, 5, 11, 4,  11, 10, 2,  10, 7,  6,  7, 1,  8,
                                    3, 9,  4, 3, 4,  2,  3,  2,  6,  3,  6,  8,  3, 8,  9,
                                    4, 9,  5, 2, 4,  11, 6,  2,  10, 8,  6,  7,  9, 8,  1};
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

inline void addMesh(scene::Scene& s, std::shared_ptr<const scene::TriangleMesh> geometry,
                    int material = 0) {
    scene::Object o;
    o.name = "objects[" + std::to_string(s.objects.size()) + "]";
    o.shape = scene::Mesh::single("generated", std::move(geometry));
    o.material = material;
    s.objects.push_back(o);
}

}  // namespace shadowlab::raytrace::test
