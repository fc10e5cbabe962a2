// tests/raster/test_scenes.h: scenes built in code for the raster tests (no loader needed) and
// the closed-form answers they are judged by: primary visibility by ray–sphere and ray–plane
// algebra, and the sphere's hard shadow by a ray–sphere test toward the light, written here
// independently of raster/ and raytrace/.
#pragma once

#include <cmath>
#include <optional>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "raster/renderer.h"
#include "scene/camera.h"
#include "scene/frame.h"
#include "scene/render_plan.h"
#include "scene/scene.h"
#include "scene/settings.h"

namespace shadowlab::raster::test {

using scene::Vec3;

inline constexpr double kPi = 3.14159265358979323846;

// The sphere-over-plane scene: sphere (id 1) above a square plane y = 0 (id 2), one directional
// light. Small image so a render takes well under a second on lavapipe.
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

// `shift` moves the whole scene (camera, sphere, plane), for tests far from the origin.
inline scene::Scene makeScene(const SphereOverPlane& p, const Vec3& shift = Vec3(0)) {
    scene::Scene s;
    s.camera.position = p.eye + shift;
    s.camera.lookAt = p.lookAt + shift;
    s.camera.up = Vec3(0, 1, 0);
    s.camera.fovYDegrees = 40.0;
    s.camera.width = p.width;
    s.camera.height = p.height;
    s.camera.near = 0.1;
    s.camera.far = 100.0;
    s.ambient = 0.05;
    scene::Material m;
    m.name = "matte";
    m.albedo = Vec3(0.8);
    s.materials.push_back(m);
    scene::Light l;
    l.type = scene::LightType::Directional;
    l.direction = glm::normalize(p.lightDirection);
    l.intensity = 3.0;
    s.lights.push_back(l);
    scene::Object sphere;
    sphere.name = "objects[0]";
    sphere.shape = scene::Sphere{p.center + shift, p.radius};
    s.objects.push_back(sphere);
    scene::Quad q;
    q.center = shift;
    q.normal = Vec3(0, 1, 0);
    q.size = scene::Vec2(p.planeSize, p.planeSize);
    scene::quadAxes(q.normal, q.uAxis, q.vAxis);
    scene::Object plane;
    plane.name = "objects[1]";
    plane.shape = q;
    s.objects.push_back(plane);
    return s;
}

// A large scene for cascades: a 200 x 200 plane (id 1; x in -100..100, z in -200..0) with spheres
// of radius 0.6 resting above it along the view (ids 2...), seen from a low camera at the plane's
// near edge looking down the length of it, so that the visible receivers span view depths from a
// few units to ~200 and every cascade's slice holds some of the plane.
inline scene::Scene makeLongPlane(int width = 160, int height = 90) {
    scene::Scene s;
    s.camera.position = Vec3(0, 2.5, 2);
    s.camera.lookAt = Vec3(0, 0.5, -20);
    s.camera.up = Vec3(0, 1, 0);
    s.camera.fovYDegrees = 40.0;
    s.camera.width = width;
    s.camera.height = height;
    s.camera.near = 0.1;
    s.camera.far = 400.0;
    s.ambient = 0.05;
    scene::Material m;
    m.name = "matte";
    m.albedo = Vec3(0.8);
    s.materials.push_back(m);
    scene::Light l;
    l.type = scene::LightType::Directional;
    l.direction = glm::normalize(Vec3(-1.0, -1.5, -0.6));
    l.intensity = 3.0;
    s.lights.push_back(l);
    scene::Quad q;
    q.center = Vec3(0, 0, -100);
    q.normal = Vec3(0, 1, 0);
    q.size = scene::Vec2(200, 200);
    scene::quadAxes(q.normal, q.uAxis, q.vAxis);
    scene::Object plane;
    plane.name = "objects[0]";
    plane.shape = q;
    s.objects.push_back(plane);
    const double zs[] = {-3, -5, -8, -12, -18, -27, -40, -60, -90, -135};
    for (std::size_t i = 0; i < std::size(zs); ++i) {
        scene::Object o;
        o.name = "objects[" + std::to_string(i + 1) + "]";
        o.shape = scene::Sphere{Vec3((i % 2 ? 1.5 : -1.5) * (1.0 - zs[i] / 40.0), 0.8, zs[i]), 0.6};
        s.objects.push_back(o);
    }
    return s;
}

// A direction for light arriving `elevationDegrees` above the horizon, travelling toward -x.
inline Vec3 lightFromElevation(double elevationDegrees) {
    const double a = elevationDegrees * kPi / 180.0;
    return Vec3(-std::cos(a), -std::sin(a), 0.0);
}

// Smallest t > 0 where o + t·d meets the sphere, if any (|d| need not be 1).
inline std::optional<double> raySphere(const Vec3& o, const Vec3& d, const Vec3& c, double r) {
    const Vec3 oc = o - c;
    const double a = glm::dot(d, d), b = glm::dot(oc, d), k = glm::dot(oc, oc) - r * r;
    const double disc = b * b - a * k;
    if (disc < 0) return std::nullopt;
    const double sq = std::sqrt(disc);
    const double t0 = (-b - sq) / a, t1 = (-b + sq) / a;
    if (t0 > 0) return t0;
    if (t1 > 0) return t1;
    return std::nullopt;
}

// What the camera sees through the center of pixel (x, y): 0 background, 1 sphere, 2 plane,
// and where. The ray through a pixel center is built here from the camera's basis:
// forward + sx·right + sy·up, sx = (2(x+0.5)/W − 1)·tan(fov/2)·aspect, sy = (1 − 2(y+0.5)/H)·tan(fov/2).
struct PrimaryHit {
    int id = 0;
    Vec3 p{0};
};

inline Vec3 pixelRay(const scene::CameraBasis& c, int x, int y) {
    const double sx = (2.0 * (x + 0.5) / c.width - 1.0) * c.tanHalfFovY * c.aspect;
    const double sy = (1.0 - 2.0 * (y + 0.5) / c.height) * c.tanHalfFovY;
    return c.forward + sx * c.right + sy * c.up;
}

// Calls fn(q, visibility) for every pixel that shows object id 1 (a floor at y = 0), q its point on
// the floor from the test's own ray–plane intersection, not the renderer's.
template <class Fn>
void forEachFloorPixel(const scene::Scene& s, const scene::Frame& f, Fn fn) {
    const scene::CameraBasis cam = scene::cameraBasis(s.camera);
    for (int y = 0; y < f.height; ++y)
        for (int x = 0; x < f.width; ++x) {
            const std::size_t i = std::size_t(y) * std::size_t(f.width) + std::size_t(x);
            if (f.objectId[i] != 1.0f) continue;
            const Vec3 d = pixelRay(cam, x, y);
            fn(cam.position + (-cam.position.y / d.y) * d, double(f.visibility[i]));
        }
}

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

// The plane point q (y = 0) is in the sphere's shadow when the ray from q toward the light
// (−lightDirection) meets the sphere.
inline bool planePointShadowed(const SphereOverPlane& p, const Vec3& q) {
    return raySphere(q, -glm::normalize(p.lightDirection), p.center, p.radius).has_value();
}

// How far the plane point q lies behind the sphere's light-facing surface, measured along the
// light: the farther root of the ray from q toward the light (that surface is what the shadow
// map stores). Infinity when q is not in the sphere's shadow.
inline double depthBehindCaster(const SphereOverPlane& p, const Vec3& q) {
    const Vec3 d = -glm::normalize(p.lightDirection);
    const Vec3 oc = q - p.center;
    const double b = glm::dot(oc, d), k = glm::dot(oc, oc) - p.radius * p.radius;
    const double disc = b * b - k;
    if (disc < 0) return INFINITY;
    const double tFar = -b + std::sqrt(disc);
    return tFar > 0 ? tFar : INFINITY;
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

inline scene::RenderPlan planFor(const scene::Scene& s, const scene::RasterSettings& raster) {
    scene::RenderSettings settings;
    settings.raster = raster;
    return scene::makeRenderPlan(s, settings);
}

// A raster render of `s` (settings.validate should be on), failing the test on any validation message.
inline scene::Frame renderChecked(const scene::Scene& s, const scene::RasterSettings& settings,
                                  RenderDebug* debug = nullptr) {
    scene::Frame f = render(s, planFor(s, settings), settings, debug);
    EXPECT_EQ(f.attributes["validation_messages"], "0") << "validation messages were printed above";
    return f;
}

// Every Vulkan test renders with the validation layer on.
inline scene::RasterSettings validatedSettings(int shadowMapSize, double depthBias, double slopeBias,
                                               scene::ShadowFilter filter) {
    scene::RasterSettings r;
    r.shadowMapSize = shadowMapSize;
    r.depthBias = depthBias;
    r.slopeBias = slopeBias;
    r.filter = filter;
    r.validate = true;
    return r;
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
inline scene::Light spotDown() {
    scene::Light l;
    l.type = scene::LightType::Spot;
    l.position = {0, 8, 0};
    l.direction = {0, -1, 0};
    l.coneAngleDegrees = 60;
    l.intensity = 800;
    return l;
}

}  // namespace shadowlab::raster::test
