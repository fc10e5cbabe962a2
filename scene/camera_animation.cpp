// scene/camera_animation.cpp: glTF animation sampling for camera paths.
#include "scene/camera_animation.h"

#include <algorithm>
#include <cmath>

#include <glm/gtc/matrix_transform.hpp>
#include <glm/gtc/quaternion.hpp>

#include "scene/error.h"

namespace shadowlab::scene {

namespace {

glm::dquat quat(const glm::dvec4& v) { return glm::dquat(v.w, v.x, v.y, v.z); }
glm::dvec4 vec(const glm::dquat& q) { return {q.x, q.y, q.z, q.w}; }

}  // namespace

glm::dvec4 sampleCurve(const AnimationCurve& c, double time, bool rotation) {
    const bool cubic = c.interpolation == AnimationCurve::Interpolation::CubicSpline;
    const std::size_t n = c.times.size();
    auto value = [&](std::size_t k) { return cubic ? c.values[3 * k + 1] : c.values[k]; };
    if (n == 0) return rotation ? glm::dvec4(0, 0, 0, 1) : glm::dvec4(0);
    if (n == 1 || time <= c.times.front()) return value(0);
    if (time >= c.times.back()) return value(n - 1);
    // The key interval [k, k + 1] holding `time`.
    const std::size_t k = std::size_t(std::upper_bound(c.times.begin(), c.times.end(), time) - c.times.begin()) - 1;
    const double t0 = c.times[k], t1 = c.times[k + 1], dt = t1 - t0;
    const double s = dt > 0 ? (time - t0) / dt : 0.0;
    switch (c.interpolation) {
        case AnimationCurve::Interpolation::Step: return value(k);
        case AnimationCurve::Interpolation::Linear:
            if (rotation) {
                glm::dquat a = quat(value(k)), b = quat(value(k + 1));
                if (glm::dot(a, b) < 0) b = -b;  // the shorter arc
                return vec(glm::normalize(glm::slerp(a, b, s)));
            }
            return value(k) + (value(k + 1) - value(k)) * s;
        case AnimationCurve::Interpolation::CubicSpline: {
            // Hermite spline (glTF 2.0, Appendix C): tangents are scaled by the interval's length.
            const double s2 = s * s, s3 = s2 * s;
            const glm::dvec4 p0 = value(k), m0 = dt * c.values[3 * k + 2];
            const glm::dvec4 p1 = value(k + 1), m1 = dt * c.values[3 * (k + 1)];
            const glm::dvec4 v =
                (2 * s3 - 3 * s2 + 1) * p0 + (s3 - 2 * s2 + s) * m0 + (-2 * s3 + 3 * s2) * p1 + (s3 - s2) * m1;
            return rotation ? vec(glm::normalize(quat(v))) : v;
        }
    }
    return value(k);
}

glm::dmat4 animatedNodeMatrix(const CameraAnimation& a, double time) {
    const Vec3 t = a.translationCurve ? Vec3(sampleCurve(*a.translationCurve, time, false)) : a.translation;
    const glm::dvec4 r = a.rotationCurve ? sampleCurve(*a.rotationCurve, time, true) : a.rotation;
    glm::dmat4 m = glm::translate(glm::dmat4(1.0), t);
    m = m * glm::mat4_cast(glm::normalize(quat(r)));
    return a.parent * glm::scale(m, a.scale);
}

Camera animatedCamera(const Scene& scene, const CameraAnimation& a, double time) {
    const glm::dmat4 world = animatedNodeMatrix(a, time);
    Camera cam = a.camera >= 0 && std::size_t(a.camera) < scene.origin.cameras.size()
                     ? scene.origin.cameras[std::size_t(a.camera)].camera
                     : scene.camera;
    cam.width = scene.camera.width;
    cam.height = scene.camera.height;
    cam.position = Vec3(world * glm::dvec4(0, 0, 0, 1));
    cam.lookAt = cam.position + glm::normalize(Vec3(world * glm::dvec4(0, 0, -1, 0)));
    cam.up = glm::normalize(Vec3(world * glm::dvec4(0, 1, 0, 0)));
    return cam;
}

const CameraAnimation& findCameraAnimation(const Scene& scene, const std::string& which) {
    const auto& all = scene.origin.cameraAnimations;
    std::string names;
    for (const CameraAnimation& a : all)
        names += (names.empty() ? "" : ", ") + std::to_string(a.index) + (a.name.empty() ? "" : " '" + a.name + "'");
    if (all.empty())
        throw InputError("--camera-animation: " + scene.file.string() +
                         " has no animation that moves a camera (read from a .gltf/.glb given as the scene)");
    if (which.empty()) return all.front();
    for (const CameraAnimation& a : all)
        if (a.name == which) return a;
    if (!which.empty() && std::all_of(which.begin(), which.end(), ::isdigit) && which.size() < 9)
        for (const CameraAnimation& a : all)
            if (a.index == std::stoi(which)) return a;
    throw InputError("--camera-animation: no camera animation '" + which + "' in " + scene.file.string() +
                     " (it has: " + names + ")");
}

}  // namespace shadowlab::scene
