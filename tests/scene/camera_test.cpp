// tests/scene/camera_test.cpp: the shared camera math puts ray-tracer rays and rasterized pixel
// centers at the same place, with reversed depth, and survives a degenerate look-at.
#include "scene/camera.h"

#include <gtest/gtest.h>

namespace shadowlab::scene {
namespace {

Camera testCamera() {
    Camera c;
    c.position = {1, 2, 6};
    c.lookAt = {0, 0.5, 0};
    c.fovYDegrees = 40;
    c.width = 64;
    c.height = 36;
    c.near = 0.1;
    c.far = 100;
    return c;
}

TEST(Camera, RayThroughEachPixelCenterProjectsBackOntoThatCenter) {
    const Camera cam = testCamera();
    const CameraBasis b = cameraBasis(cam);
    const glm::dmat4 vp = projectionMatrix(b, cam.near, cam.far) * viewMatrix(b, cam.position);
    for (int y : {0, 7, 35})
        for (int x : {0, 31, 63}) {
            const Vec3 p = 3.7 * pixelDirection(b, x, y);  // a point on the ray, camera-relative
            const glm::dvec4 clip = vp * glm::dvec4(p, 1.0);
            // Vulkan viewport: framebuffer x = (ndc.x + 1)/2·W, y = (ndc.y + 1)/2·H.
            EXPECT_NEAR((clip.x / clip.w + 1) * 0.5 * cam.width, x + 0.5, 1e-9);
            EXPECT_NEAR((clip.y / clip.w + 1) * 0.5 * cam.height, y + 0.5, 1e-9);
        }
}

TEST(Camera, DepthIsReversedNearOneFarZero) {
    const Camera cam = testCamera();
    const CameraBasis b = cameraBasis(cam);
    const glm::dmat4 vp = projectionMatrix(b, cam.near, cam.far) * viewMatrix(b, cam.position);
    auto depthAt = [&](double d) {
        const glm::dvec4 clip = vp * glm::dvec4(d * b.forward, 1.0);
        return clip.z / clip.w;
    };
    EXPECT_NEAR(depthAt(cam.near), 1.0, 1e-12);
    EXPECT_NEAR(depthAt(cam.far), 0.0, 1e-12);
    EXPECT_GT(depthAt(1.0), depthAt(2.0));
}

TEST(Camera, CenterRayIsForwardAndRowZeroIsTop) {
    Camera cam = testCamera();
    cam.width = 3;
    cam.height = 3;
    const CameraBasis b = cameraBasis(cam);
    const Vec3 center = glm::normalize(pixelDirection(b, 1, 1));
    EXPECT_NEAR(glm::dot(center, b.forward), 1.0, 1e-15);
    EXPECT_GT(glm::dot(pixelDirection(b, 1, 0), b.up), 0.0);  // row 0 looks up
    EXPECT_GT(glm::dot(pixelDirection(b, 2, 1), b.right), 0.0);
}

TEST(Camera, LookingStraightDownAlongUpStillGivesAnOrthonormalBasis) {
    Camera cam = testCamera();
    cam.position = {0, 10, 0};
    cam.lookAt = {0, 0, 0};
    cam.up = {0, 1, 0};
    const CameraBasis b = cameraBasis(cam);
    for (const Vec3& v : {b.forward, b.right, b.up}) {
        EXPECT_TRUE(std::isfinite(v.x) && std::isfinite(v.y) && std::isfinite(v.z));
        EXPECT_NEAR(glm::length(v), 1.0, 1e-12);
    }
    EXPECT_NEAR(glm::dot(b.forward, b.right), 0.0, 1e-12);
    EXPECT_NEAR(glm::dot(b.forward, b.up), 0.0, 1e-12);
    EXPECT_NEAR(b.forward.y, -1.0, 1e-15);
}

}  // namespace
}  // namespace shadowlab::scene
