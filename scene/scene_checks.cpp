// scene/scene_checks.cpp: light values and scene extent (see scene_checks.h).
#include "scene/scene_checks.h"

#include <algorithm>
#include <cmath>
#include <cstdio>

namespace shadowlab::scene {

namespace {

bool finite(const Vec3& v) { return std::isfinite(v.x) && std::isfinite(v.y) && std::isfinite(v.z); }

std::string number(double v) {
    char buf[32];
    std::snprintf(buf, sizeof buf, "%.6g", v);
    return buf;
}

double largest(const Vec3& v) { return std::max({std::abs(v.x), std::abs(v.y), std::abs(v.z)}); }

}  // namespace

ValueProblem lightProblem(const Light& l) {
    if (!finite(l.color) || l.color.x < 0 || l.color.y < 0 || l.color.z < 0)
        return {"color", "color components must be finite and >= 0"};
    if (!std::isfinite(l.intensity) || l.intensity < 0)
        return {"intensity", "must be finite and >= 0, got " + number(l.intensity)};
    if (const double power = l.intensity * std::max({l.color.x, l.color.y, l.color.z}); !(power <= kMaxLightPower))
        return {"intensity", "intensity times colour is " + number(power) + ", more than " + number(kMaxLightPower) +
                                 " (float shading would overflow)"};
    if (l.type != LightType::Point) {
        const double len = glm::length(l.direction);
        if (!finite(l.direction) || !(std::abs(len - 1.0) < 1e-6))
            return {"direction", "must be a finite, non-zero direction"};
    }
    if (l.type != LightType::Directional) {
        if (!finite(l.position) || largest(l.position) > kMaxSceneCoordinate)
            return {"position", "must be finite and within +-" + number(kMaxSceneCoordinate) +
                                    ", got a coordinate of " + number(largest(l.position))};
        if (!std::isfinite(l.radius) || l.radius < 0 || l.radius > kMaxSceneCoordinate)
            return {"radius", "must be in 0.." + number(kMaxSceneCoordinate) + ", got " + number(l.radius)};
    }
    if (l.type == LightType::Spot && !(l.coneAngleDegrees > 0 && l.coneAngleDegrees < 90))
        return {"cone_angle", "must be in (0, 90) degrees, got " + number(l.coneAngleDegrees)};
    if (l.type == LightType::Spot && !(l.innerConeAngleDegrees >= 0))
        return {"inner_cone_angle", "must be >= 0 degrees, got " + number(l.innerConeAngleDegrees)};
    return {};
}

void checkSceneExtent(const Scene& scene, bool jsonPaths) {
    const JsonPath root;
    auto beyond = [](double v) { return !(v <= kMaxSceneCoordinate); };  // NaN too
    auto fail = [&](const JsonPath& at, const std::string& what, double reach) {
        throw SceneError(scene.file, jsonPaths ? at : root,
                         what + " reaches a coordinate of " + number(reach) + ", beyond the +-" +
                             number(kMaxSceneCoordinate) +
                             " a scene may span (the renderers' float arithmetic would overflow); scale the "
                             "scene down");
    };
    for (std::size_t i = 0; i < scene.objects.size(); ++i) {
        const Bounds b = boundsOf(scene.objects[i].shape);
        if (!b.empty() && beyond(b.maxAbsCoordinate()))
            fail(root / "objects" / i, jsonPaths ? "the object" : "the model", b.maxAbsCoordinate());
    }
    const Camera& c = scene.camera;
    if (beyond(largest(c.position))) fail(root / "camera" / "position", "the camera", largest(c.position));
    if (beyond(largest(c.lookAt))) fail(root / "camera" / "look_at", "the camera's look_at", largest(c.lookAt));
    if (beyond(c.far)) fail(root / "camera" / "far", "the camera's far plane", c.far);
    for (std::size_t i = 0; i < scene.lights.size(); ++i)
        if (scene.lights[i].type != LightType::Directional && beyond(largest(scene.lights[i].position)))
            fail(root / "lights" / i / "position", "the light", largest(scene.lights[i].position));
}

}  // namespace shadowlab::scene
