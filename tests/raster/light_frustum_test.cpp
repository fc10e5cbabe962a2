// tests/raster/light_frustum_test.cpp: the directional light's orthographic frustum encloses the
// scene and maps depth along the light from 0 (light side) to 1.
#include "raster/light_frustum.h"

#include <gtest/gtest.h>

#include "raster/tolerances.h"
#include "tests/kit/test_scenes.h"

namespace shadowlab::raster {
namespace {

using test::Vec3;

glm::dvec4 apply(const glm::dmat4& m, const Vec3& p) { return m * glm::dvec4(p, 1.0); }

TEST(LightFrustum, EnclosesEveryCornerOfTheBounds) {
    scene::Bounds b;
    b.extend(Vec3(-4, -1, -2));
    b.extend(Vec3(3, 5, 7));
    const Vec3 origin(10, -3, 2);
    for (const Vec3 dir : {Vec3(0, -1, 0), glm::normalize(Vec3(-1, -2, -1)), Vec3(1, 0, 0)}) {
        const LightFrustum f = fitDirectionalLight(b, dir, 1024);
        const glm::dmat4 m = f.toClip(origin);
        for (int k = 0; k < 8; ++k) {
            const Vec3 corner((k & 1) ? b.max.x : b.min.x, (k & 2) ? b.max.y : b.min.y, (k & 4) ? b.max.z : b.min.z);
            const glm::dvec4 c = apply(m, corner - origin);
            EXPECT_LT(std::abs(c.x), 1.0);
            EXPECT_LT(std::abs(c.y), 1.0);
            EXPECT_GT(c.z, 0.0);
            EXPECT_LT(c.z, 1.0);
            EXPECT_EQ(c.w, 1.0);
        }
    }
}

TEST(LightFrustum, DepthGrowsAlongTheLightAndSpansTheDiameter) {
    scene::Bounds b;
    b.extend(Vec3(-1, -1, -1));
    b.extend(Vec3(1, 1, 1));
    const Vec3 dir = glm::normalize(Vec3(1, -2, 0.5));
    const LightFrustum f = fitDirectionalLight(b, dir, 512);
    const double h = std::sqrt(3.0) * kLightFrustumMargin;  // half the box diagonal, with the margin
    EXPECT_NEAR(f.halfWidth, h, 1e-12);
    EXPECT_NEAR(f.texelWorldSize(), 2.0 * h / 512, 1e-12);
    const glm::dmat4 m = f.toClip(Vec3(0));
    EXPECT_NEAR(apply(m, Vec3(0)).z, 0.5, 1e-12);                    // the center is mid-depth
    EXPECT_NEAR(apply(m, -h * dir).z, 0.0, 1e-12);                   // toward the light: depth 0
    EXPECT_NEAR(apply(m, h * dir).z, 1.0, 1e-12);                    // away from it: depth 1
    EXPECT_NEAR(apply(m, 0.3 * dir).z - 0.5, 0.3 / (2 * h), 1e-12);  // 1 / depthRange per world unit
    // Moving across the light does not change depth.
    EXPECT_NEAR(apply(m, f.right + f.up).z, 0.5, 1e-12);
}

TEST(LightFrustum, TextureMatrixMapsTheCenterToTheMapCenterAndRightToU) {
    scene::Bounds b;
    b.extend(Vec3(0, 0, 0));
    b.extend(Vec3(2, 2, 2));
    const LightFrustum f = fitDirectionalLight(b, Vec3(0, -1, 0), 256);
    const glm::dmat4 t = f.toTexture(Vec3(1, 1, 1));  // origin at the center: positions relative to it
    const glm::dvec4 c = apply(t, Vec3(0));
    EXPECT_NEAR(c.x, 0.5, 1e-12);
    EXPECT_NEAR(c.y, 0.5, 1e-12);
    const glm::dvec4 r = apply(t, f.halfWidth * f.right);
    EXPECT_NEAR(r.x, 1.0, 1e-12);
    EXPECT_NEAR(r.y, 0.5, 1e-12);
    EXPECT_NEAR(glm::dot(f.right, f.direction), 0.0, 1e-12);
    EXPECT_NEAR(glm::dot(f.up, f.direction), 0.0, 1e-12);
    // Right-handed like a camera: it looks down its −z axis, which is the light's direction.
    EXPECT_NEAR(glm::length(glm::cross(f.right, f.up) + f.direction), 0.0, 1e-12);
}

TEST(LightFrustum, PointLikeBoundsStillGetAValidFrustum) {
    scene::Bounds b;
    b.extend(Vec3(5, 5, 5));
    const LightFrustum f = fitDirectionalLight(b, Vec3(0, -1, 0), 64);
    EXPECT_GT(f.halfWidth, 0.0);
    EXPECT_TRUE(std::isfinite(f.toClip(Vec3(0))[0][0]));
}

TEST(LightFrustum, SpotMapSeesItsConeWithPerspectiveDepthFromNearToFar) {
    scene::Bounds b;
    b.extend(Vec3(-5, 0, -5));
    b.extend(Vec3(5, 2, 5));
    const Vec3 pos(1, 6, -1), dir = glm::normalize(Vec3(0.2, -1, 0.1));
    const double cone = 30.0;
    const LightFrustum f = fitSpotLight(b, pos, dir, cone, 512);
    ASSERT_TRUE(f.perspective);
    const Vec3 origin(2, 1, 3);
    const glm::dmat4 m = f.toClip(origin);
    // On the axis at distance d: x = y = 0, z/w = far/(far − near)·(1 − near/d), w = d.
    for (const double d : {f.near, 0.5 * (f.near + f.far), f.far}) {
        const glm::dvec4 c = apply(m, pos + d * dir - origin);
        EXPECT_NEAR(c.x / c.w, 0.0, 1e-12);
        EXPECT_NEAR(c.y / c.w, 0.0, 1e-12);
        EXPECT_NEAR(c.w, d, 1e-9);
        EXPECT_NEAR(c.z / c.w, f.far / (f.far - f.near) * (1.0 - f.near / d), 1e-12);
    }
    // The cone's rim lies inside the map, just (the 2% margin) short of its edge.
    const double a = cone * test::kPi / 180.0;
    const glm::dvec4 rim = apply(m, pos + 3.0 * (std::cos(a) * dir + std::sin(a) * f.right) - origin);
    EXPECT_LT(std::abs(rim.x / rim.w), 1.0);
    EXPECT_GT(std::abs(rim.x / rim.w), 0.95);
    // Near and far enclose the scene's bounding sphere along the axis (near: unless that
    // is closer than far/1000, as here where the light is inside the sphere).
    const double along = glm::dot(b.center() - pos, dir), radius = 0.5 * b.diagonal();
    EXPECT_LE(f.near, std::max(along - radius, f.far * kSpotMinNearOverFar) + 1e-9);
    EXPECT_GE(f.far, along + radius - 1e-9);
    // Texel size per unit distance: the map spans 2·tan(half fov) at distance 1.
    EXPECT_NEAR(f.texelWorldSize(), 2.0 * std::tan(a * 1.02) / 512, 1e-12);
}

TEST(LightFrustum, SpotNearPlaneStaysAFractionOfFarWhenTheLightIsInsideTheScene) {
    scene::Bounds b;
    b.extend(Vec3(-5, 0, -5));
    b.extend(Vec3(5, 5, 5));
    const LightFrustum f = fitSpotLight(b, Vec3(0, 2, 0), Vec3(0, -1, 0), 45.0, 256);
    EXPECT_NEAR(f.near, f.far * kSpotMinNearOverFar, 1e-12);
}

// A camera at (0, 2, 6) looking at the origin over a 200 x 200 plane with a small sphere (all of
// it moved by `shift`). The plane is a mesh that can shade itself, so every visible point of it is
// a receiver the fitted map must hold (a quad would leave only the part under the sphere).
scene::Scene bigPlaneScene(const Vec3& shift = Vec3(0)) {
    test::SphereOverPlane p;
    p.planeSize = 200.0;
    p.eye = Vec3(0, 2, 6);
    p.lookAt = Vec3(0, 0, 0);
    scene::Scene s = test::makeScene(p, shift);
    test::makeGroundShadeItself(s, 1);
    s.camera.far = 30.0;  // the visible part of the plane ends 30 units away
    return s;
}

TEST(LightFrustum, FittedToReceiversIsSmallerAndStillCoversEveryVisiblePoint) {
    const scene::Scene s = bigPlaneScene();
    const Vec3 dir = glm::normalize(Vec3(-1, -2, -1));
    const LightFrustum sphere = fitDirectionalLight(s.bounds(), dir, 1024);
    const LightFrustum fitted = fitDirectionalLightToReceivers(s, dir, 1024);
    EXPECT_LT(fitted.halfWidth, 0.5 * sphere.halfWidth);
    // Every plane point the camera sees (pixel rays up to the far plane) maps inside the map.
    const scene::CameraBasis cam = scene::cameraBasis(s.camera);
    const glm::dmat4 m = fitted.toClip(Vec3(0));
    int seen = 0;
    for (int y = 0; y < s.camera.height; y += 3)
        for (int x = 0; x < s.camera.width; x += 3) {
            const Vec3 d = test::pixelRay(cam, x, y);
            if (d.y >= 0) continue;
            const double t = -cam.position.y / d.y;
            if (t * glm::dot(d, cam.forward) > s.camera.far) continue;  // beyond the far plane
            const glm::dvec4 c = apply(m, cam.position + t * d);
            ++seen;
            ASSERT_LE(std::abs(c.x), 1.0);
            ASSERT_LE(std::abs(c.y), 1.0);
            ASSERT_GE(c.z, 0.0);
            ASSERT_LE(c.z, 1.0);
        }
    EXPECT_GT(seen, 100);
    // And the sphere, which casts onto visible receivers, is inside too.
    const glm::dvec4 top = apply(m, Vec3(0, 1.5, 0));
    EXPECT_GE(top.z, 0.0);
}

TEST(LightFrustum, FittedMapMovesByWholeTexelsAndKeepsItsSizeAndDepthsAsTheCameraMoves) {
    // "texel-snapped so the map does not swim". A camera move of a fraction of a texel
    // keeps the texel size and the depth range bit for bit, and the map's center stays on the
    // world-fixed grid (whole texels along right and up from the world origin), so every texel
    // that still covers the scene covers the same world square.
    const Vec3 dir = glm::normalize(Vec3(-1, -2, -1));
    for (const double far : {0.0, 1e6}) {
        const scene::Scene s = bigPlaneScene(Vec3(far, 0, far));
        const LightFrustum a = fitDirectionalLightToReceivers(s, dir, 1024);
        const double texel = a.texelWorldSize();
        ASSERT_LT(a.halfWidth, 0.5 * fitDirectionalLight(s.bounds(), dir, 1024).halfWidth) << "fitted at all";
        // On the grid: the center's coordinates across the light are whole texels.
        for (const Vec3& axis : {a.right, a.up}) {
            const double k = glm::dot(a.center, axis) / texel;
            EXPECT_NEAR(k, std::round(k), 1e-6 * std::max(1.0, std::abs(k))) << far;
        }
        // Moves of 0.3 texel and of 10⁻³ units along x.
        for (const double move : {0.3 * texel, 1e-3}) {
            scene::Scene moved = s;
            moved.camera.position.x += move;
            moved.camera.lookAt.x += move;
            const LightFrustum b = fitDirectionalLightToReceivers(moved, dir, 1024);
            EXPECT_EQ(b.halfWidth, a.halfWidth) << move;
            EXPECT_EQ(b.nearDepth, a.nearDepth) << move;
            EXPECT_EQ(b.farDepth, a.farDepth) << move;
            for (const Vec3& axis : {a.right, a.up}) {
                const double steps = glm::dot(b.center - a.center, axis) / texel;
                EXPECT_NEAR(steps, std::round(steps), 1e-6) << move;
                EXPECT_LE(std::abs(steps), 1.0 + 1e-6) << move;
            }
            EXPECT_NEAR(glm::dot(b.center - a.center, a.direction), 0.0, 1e-9 * std::max(1.0, far));
        }
        // A move of many texels moves the map by about as many whole texels.
        scene::Scene moved = s;
        moved.camera.position.x += 40.0 * texel;
        moved.camera.lookAt.x += 40.0 * texel;
        const LightFrustum c = fitDirectionalLightToReceivers(moved, dir, 1024);
        EXPECT_GT(glm::length(c.center - a.center), 10.0 * texel);
    }
}

TEST(LightFrustum, FittedMapIsNoWiderAtALargerMapSize) {
    // chooseShadowMapSize sizes a fitted directional map from its width at the smallest candidate
    // size, which must bound its width at every larger size (the N/(N − 1) growth shrinks with N,
    // and rounding up keeps the order), or the map chosen could be coarser than the receivers need.
    const Vec3 dir = glm::normalize(Vec3(-1, -2, -1));
    for (const double far : {6.0, 12.0, 30.0, 60.0}) {
        scene::Scene s = bigPlaneScene();
        s.camera.far = far;
        double previous = INFINITY;
        for (int n = kMinAutoShadowMapSize; n <= 4096; n *= 2) {
            const double half = fitDirectionalLightToReceivers(s, dir, n).halfWidth;
            EXPECT_LE(half, previous) << "far " << far << ", size " << n;
            previous = half;
        }
    }
}

TEST(LightFrustum, FittedFallsBackToTheBoundingSphereWhenTheCameraSeesNothing) {
    scene::Scene s = bigPlaneScene();
    s.camera.lookAt = Vec3(0, 10, 6);  // straight up, away from everything
    s.camera.up = Vec3(0, 0, -1);
    const Vec3 dir(0, -1, 0);
    EXPECT_EQ(fitDirectionalLightToReceivers(s, dir, 256).halfWidth,
              fitDirectionalLight(s.bounds(), dir, 256).halfWidth);
}

TEST(CubeFaces, EachFaceReachesTheMarginPastItsEdgeAndLooksAlongItsAxis) {
    for (const int size : {64, 512, 2048}) {
        const double t = cubeFaceTanHalfFov(size);
        // The 90° edge (tan = 1) lies (size/2)·(1 − 1/t) texels inside the face's border.
        EXPECT_NEAR(0.5 * size * (1.0 - 1.0 / t), kPointFaceMarginTexels, 1e-9) << size;
        const scene::Bounds bounds{Vec3(-3), Vec3(3)};
        const Vec3 light(0.5, 1.0, -0.25);
        for (int face = 0; face < kCubeFaces; ++face) {
            const LightFrustum f = fitPointLightFace(bounds, light, face, size);
            const Vec3 axis = cubeFaceDirection(face);
            EXPECT_DOUBLE_EQ(glm::dot(f.direction, axis), 1.0);
            // A point on the face's axis maps to the map center; one on the 90° edge (axis +
            // right) maps margin texels inside the border.
            const glm::dvec4 c = f.toTexture(Vec3(0)) * glm::dvec4(light + 2.0 * axis, 1.0);
            EXPECT_NEAR(c.x / c.w, 0.5, 1e-12);
            EXPECT_NEAR(c.y / c.w, 0.5, 1e-12);
            const glm::dvec4 e = f.toTexture(Vec3(0)) * glm::dvec4(light + 2.0 * axis + 2.0 * f.right, 1.0);
            EXPECT_NEAR((1.0 - e.x / e.w) * size, kPointFaceMarginTexels, 1e-6);
            // The whole scene lies between near and far.
            EXPECT_LE(f.near, 1e-3 * f.far + 1e-12);
            EXPECT_GE(f.far, glm::length(Vec3(3) - light));
        }
        // The six axes are distinct: +X −X +Y −Y +Z −Z.
        for (int a = 0; a < kCubeFaces; ++a)
            for (int b = a + 1; b < kCubeFaces; ++b)
                EXPECT_LT(glm::dot(cubeFaceDirection(a), cubeFaceDirection(b)), 0.5);
    }
}

TEST(CubeFaces, EveryPointOfTheBoundsInAFacesWindowLiesBetweenItsNearAndFar) {
    // A face's near and far are planes across its axis, so a point at distance r from the light in
    // a direction θ off the axis has depth r·cos θ, down to r/√(1 + 2t²) in the window's corners.
    // Light outside the bounds along their diagonal: the nearest corner is straight down the
    // cube's diagonal, 54.7° off every face's axis. Rays over each face's window (the test's own
    // slab intersection with the box) must enter and leave the box between near and far.
    const scene::Bounds bounds{Vec3(-1), Vec3(1)};
    for (const double distance : {2.0, 3.0, 10.0, 100.0}) {
        const Vec3 light = distance * glm::normalize(Vec3(1, 1, 1));
        for (int face = 0; face < kCubeFaces; ++face) {
            const LightFrustum f = fitPointLightFace(bounds, light, face, 512);
            int hits = 0;
            constexpr int n = 64;
            for (int j = 0; j <= n; ++j)
                for (int i = 0; i <= n; ++i) {
                    const double u = f.tanHalfFov * (2.0 * i / n - 1.0), v = f.tanHalfFov * (2.0 * j / n - 1.0);
                    const Vec3 d = f.direction + u * f.right + v * f.up;  // depth along the axis = λ
                    double enter = 0.0, leave = INFINITY;
                    for (int k = 0; k < 3; ++k) {
                        if (d[k] == 0.0) {
                            if (light[k] < -1.0 || light[k] > 1.0) leave = -1.0;
                            continue;
                        }
                        const double a = (-1.0 - light[k]) / d[k], b = (1.0 - light[k]) / d[k];
                        enter = std::max(enter, std::min(a, b));
                        leave = std::min(leave, std::max(a, b));
                    }
                    if (enter > leave) continue;
                    ++hits;
                    EXPECT_GE(enter, f.near * (1.0 - 1e-12)) << "distance " << distance << " face " << face;
                    EXPECT_LE(leave, f.far * (1.0 + 1e-12)) << "distance " << distance << " face " << face;
                }
            if (face % 2 == 1) {
                EXPECT_GT(hits, 0) << "the −X, −Y, −Z faces look at the box";
            }
        }
    }
}

}  // namespace
}  // namespace shadowlab::raster
