// scene/camera.h: the one definition of the camera's rays and projection, shared by both
// backends so that primary visibility agrees except on silhouettes.
#pragma once

#include <glm/glm.hpp>

#include "scene/scene.h"

namespace shadowlab::scene {

// Orthonormal right-handed camera basis. When `up` is (anti)parallel to the view direction
// the look-at is degenerate; world Z (or X) is used as up instead, so a camera looking
// straight down still renders (see docs/decisions.md).
struct CameraBasis {
    Vec3 position{0, 0, 0};
    Vec3 forward{0, 0, -1};  // unit, toward look_at
    Vec3 right{1, 0, 0};     // unit
    Vec3 up{0, 1, 0};        // unit, = right × forward
    double tanHalfFovY = 0.0;
    double aspect = 1.0;  // width / height
    int width = 0;
    int height = 0;
};

CameraBasis cameraBasis(const Camera& camera);

// Direction (not normalized) of the ray through the center of pixel (x, y), row 0 at the top:
// forward + sx·right + sy·up with sx = (2(x+0.5)/W − 1)·tan(fovY/2)·aspect and
// sy = (1 − 2(y+0.5)/H)·tan(fovY/2).
inline Vec3 pixelDirection(const CameraBasis& c, int x, int y) {
    const double sx = (2.0 * (x + 0.5) / c.width - 1.0) * c.tanHalfFovY * c.aspect;
    const double sy = (1.0 - 2.0 * (y + 0.5) / c.height) * c.tanHalfFovY;
    return c.forward + sx * c.right + sy * c.up;
}

// View matrix that maps world to camera space with the eye at `origin` subtracted first
// (camera-relative rendering: callers pass world positions minus `origin` in float).
glm::dmat4 viewMatrix(const CameraBasis& c, const Vec3& origin);
// Vulkan projection (clip depth 0..1, Y down in framebuffer) with *reversed* depth: near maps
// to 1 and far to 0, which keeps float depth precise far away. Same pixel centers as
// pixelDirection().
glm::dmat4 projectionMatrix(const CameraBasis& c, double near, double far);

}  // namespace shadowlab::scene
