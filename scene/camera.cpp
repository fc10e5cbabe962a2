// scene/camera.cpp: camera basis, view and reversed-Z projection shared by both backends.
#include "scene/camera.h"

#include <cmath>

namespace shadowlab::scene {

CameraBasis cameraBasis(const Camera& camera) {
    constexpr double kPi = 3.14159265358979323846;
    CameraBasis c;
    c.position = camera.position;
    c.forward = glm::normalize(camera.lookAt - camera.position);
    Vec3 up = glm::normalize(camera.up);
    // A look-at along `up` has no defined roll. Fall back to world Z, or X if that is parallel
    // too: the image is then rotated, but it renders (straight-down cameras are common).
    if (std::abs(glm::dot(up, c.forward)) > 1.0 - 1e-9)
        up = std::abs(c.forward.z) < 0.9 ? Vec3(0, 0, -1) : Vec3(1, 0, 0);
    c.right = glm::normalize(glm::cross(c.forward, up));
    c.up = glm::cross(c.right, c.forward);
    c.tanHalfFovY = std::tan(0.5 * camera.fovYDegrees * kPi / 180.0);
    c.width = camera.width;
    c.height = camera.height;
    c.aspect = double(camera.width) / double(camera.height);
    return c;
}

glm::dmat4 viewMatrix(const CameraBasis& c, const Vec3& origin) {
    // Camera space: x right, y up, looking down −z (right-handed).
    glm::dmat4 m(1.0);
    m[0][0] = c.right.x;
    m[1][0] = c.right.y;
    m[2][0] = c.right.z;
    m[0][1] = c.up.x;
    m[1][1] = c.up.y;
    m[2][1] = c.up.z;
    m[0][2] = -c.forward.x;
    m[1][2] = -c.forward.y;
    m[2][2] = -c.forward.z;
    const Vec3 eye = c.position - origin;
    m[3][0] = -glm::dot(c.right, eye);
    m[3][1] = -glm::dot(c.up, eye);
    m[3][2] = glm::dot(c.forward, eye);
    return m;
}

glm::dmat4 projectionMatrix(const CameraBasis& c, double near, double far) {
    // Reversed Z: z_ndc = near·(far − d) / (d·(far − near)) for view distance d, so z_ndc = 1 at
    // d = near and 0 at d = far; float depth then keeps its precision far away. Vulkan's framebuffer Y
    // points down, so clip y is negated: image row 0 is the top, as pixelDirection() assumes.
    glm::dmat4 p(0.0);
    p[0][0] = 1.0 / (c.tanHalfFovY * c.aspect);
    p[1][1] = -1.0 / c.tanHalfFovY;
    p[2][2] = near / (far - near);
    p[2][3] = -1.0;
    p[3][2] = far * near / (far - near);
    return p;
}

}  // namespace shadowlab::scene
