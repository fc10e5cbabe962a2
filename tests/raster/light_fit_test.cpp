// tests/raster/light_fit_test.cpp: spot maps and point-light cube faces fitted to what the camera
// sees (`fitLightFrustum`): the fitted spot window by hand, that it holds every visible
// receiver, does not swim, ignores unrelated far objects and renders no worse against the
// reference; a cube face's near/far by hand; the point light's map size from receiver detail by
// hand. Renders are on lavapipe with the validation layer.
#include <cmath>
#include <cstdio>
#include <string>
#include <variant>

#include <gtest/gtest.h>

#include "compare/compare.h"
#include "raster/debug_views.h"
#include "raster/light_frustum.h"
#include "raster/renderer.h"
#include "scene/camera.h"
#include "scene/render_plan.h"
#include "tests/kit/render_checked.h"
#include "tests/kit/test_scenes.h"

namespace shadowlab::raster {
namespace {

using test::kPi;
using test::Vec3;

double deg(double d) { return d * kPi / 180.0; }

// makeScene's sphere (r = 0.5) at `center` over a 20 x 20 ground, seen from `eye` toward `lookAt`.
scene::Scene sphereOnTheGround(const Vec3& center, const Vec3& eye, const Vec3& lookAt, int width, int height) {
    return test::makeScene(test::SphereOverPlane{.center = center,
                                                 .radius = 0.5,
                                                 .planeSize = 20.0,
                                                 .eye = eye,
                                                 .lookAt = lookAt,
                                                 .width = width,
                                                 .height = height});
}

// Spot at (0, 8, 0) straight down, cone 60° (the cone map's half-angle 61.2°, t0 = tan 61.2°),
// over a 20 x 20 ground at y = 0 with a sphere r = 0.5 at (2, 0.5, 0); the camera at (cameraX, 4, 0)
// looks straight down (up −z, fov 40°, 160 x 90), so it sees the ground x = cameraX ± 4·tan 20°·16/9,
// z = ±4·tan 20°. The map's basis (the axis is vertical, so right = dir × X): right = +z, up = +x,
// u = z/d, v = x/d with d = 8 − y.
scene::Scene spotScene(double cameraX = 2.0, int width = 160, int height = 90) {
    scene::Scene s = sphereOnTheGround({2, 0.5, 0}, {cameraX, 4, 0}, {cameraX, 0, 0}, width, height);
    s.camera.up = {0, 0, -1};
    s.lights = {test::spotDown()};
    return s;
}

scene::RasterSettings fitSettings(int size, bool fit) {
    scene::RasterSettings r = test::validatedSettings(size, 0.01, 1.0, scene::ShadowFilter::Pcf2x2);
    r.normalOffset = 0.0;
    r.fitLightFrustum = fit;
    return r;
}

using test::renderChecked;

// The window's half-size by hand. The visible receivers are the scene box (y 0..1) in the view:
// at y = 0 (d = 8) x = 2 ± 4·tan 20°·16/9, z = ±4·tan 20°; at y = 1 (d = 7) x = 2 ± 3·tan 20°·16/9.
// Their widest extent is in v at y = 0: 2·4·tan 20°·(16/9)/8 = tan 20°·16/9, half of it e. With a
// margin of m = 10 texels (pcf2x2, no normal offset) and half a texel for the snapped center,
// h ≥ e/(1 − 21/N), rounded up to a power of 2^(1/4).
double expectedHalf(int n) {
    const double e = 0.5 * std::tan(deg(20)) * 16.0 / 9.0;
    const double h = e / (1.0 - 21.0 / n);
    return std::exp2(std::ceil(4.0 * std::log2(h)) / 4.0);
}

TEST(RasterSpotFit, TheWindowIsTheHandComputedFractionOfTheCone) {
    // e = 0.3235; at N = 1024, h ≥ 0.3303 → 2^(−6/4) = 0.3536 (4·log2 0.3303 = −6.39, well clear
    // of −6); the cone's t0 = tan 61.2° = 1.823, so the texel is 0.194 of the cone map's.
    ASSERT_NEAR(expectedHalf(1024), std::exp2(-1.5), 1e-12);
    const scene::Scene s = spotScene();
    const LightFrustum f = spotLightFrustum(s, fitSettings(1024, true), s.lights[0], 1024);
    const LightFrustum cone = spotLightFrustum(s, fitSettings(1024, false), s.lights[0], 1024);
    EXPECT_NEAR(cone.tanHalfFov, std::tan(deg(61.2)), 1e-12);
    EXPECT_NEAR(f.tanHalfFov, std::exp2(-1.5), 1e-12);
    EXPECT_NEAR(f.texelWorldSize() / cone.texelWorldSize(), std::exp2(-1.5) / std::tan(deg(61.2)), 1e-12);
    // Centered on the receivers: u (z) around 0, v (x) around the middle of [(2 − 2.588)/8,
    // (2 + 2.588)/8] = 0.25, each to within half a texel, on whole texels.
    const double texel = 2.0 * f.tanHalfFov / 1024;
    EXPECT_NEAR(f.windowU, 0.0, 0.5 * texel);
    EXPECT_NEAR(f.windowV, 0.25, 0.5 * texel);
    EXPECT_NEAR(f.windowV / texel, std::round(f.windowV / texel), 1e-6);
    // The depth range: the farthest receiver is the ground (d = 8), grown by the margin's fraction
    // 10 texels · 2h/N and 1%: 8·(1 + 10·0.000691)·1.01 = 8.136; the nearest caster in the window
    // is the sphere's box top (y = 1, d = 7), less 1%: 6.931. Snapped outward to powers of 2^(1/4):
    // 4·log2 8.136 = 12.10, so far = 2^(13/4) = 9.51; 4·log2 6.931 = 11.17, so near = 2^(11/4) = 6.73.
    const double fitFar = 8.0 * (1.0 + 10.0 * texel) * 1.01, fitNear = 7.0 / 1.01;
    ASSERT_NEAR(4.0 * std::log2(fitFar), 12.10, 0.01);
    ASSERT_NEAR(4.0 * std::log2(fitNear), 11.17, 0.01);
    EXPECT_NEAR(f.far, std::exp2(13.0 / 4.0), 1e-12);
    EXPECT_NEAR(f.near, std::exp2(11.0 / 4.0), 1e-12);
    EXPECT_GT(cone.far, 1.5 * f.far);
    EXPECT_LT(cone.near, f.near);
}

TEST(RasterSpotFit, TheFittedWindowHoldsEveryVisibleReceiverWithTheMargin) {
    // Rendered: every pixel the camera sees, rebuilt from the Frame's depth, lies in the fitted
    // map (insideLightMap) and, through the matrix the shader uses (toTexture), at least the
    // margin (10 texels) inside its edges. The render's texel_world_size is the fitted map's.
    const scene::Scene s = spotScene();
    RenderDebug debug;
    const scene::Frame frame = renderChecked(s, fitSettings(1024, true), &debug);
    ASSERT_EQ(debug.layers.size(), 1u);
    const LightFrustum& f = debug.layers[0].frustum;
    EXPECT_NEAR(f.tanHalfFov, std::exp2(-1.5), 1e-12);
    char buf[64];
    std::snprintf(buf, sizeof buf, "%.9g*d", 2.0 * std::exp2(-1.5) / 1024);
    EXPECT_EQ(frame.attributes.at("texel_world_size"), buf);
    EXPECT_NE(frame.attributes.at("light_frustum").find("window_u="), std::string::npos);
    const scene::CameraBasis cam = scene::cameraBasis(s.camera);
    const glm::dmat4 toTexture = f.toTexture(Vec3(0.0));
    int seen = 0;
    double closest = INFINITY;  // texels from the nearest edge
    for (int y = 0; y < frame.height; ++y)
        for (int x = 0; x < frame.width; ++x) {
            const std::size_t i = std::size_t(y) * frame.width + x;
            if (!(frame.objectId[i] > 0.0f)) continue;
            const Vec3 p = cam.position + double(frame.depth[i]) * scene::pixelDirection(cam, x, y);
            ++seen;
            EXPECT_TRUE(insideLightMap(f, p)) << x << "," << y;
            const glm::dvec4 t = toTexture * glm::dvec4(p, 1.0);
            const double u = t.x / t.w * 1024, v = t.y / t.w * 1024;
            closest = std::min({closest, u, v, 1024 - u, 1024 - v});
        }
    EXPECT_EQ(seen, frame.width * frame.height);
    EXPECT_GE(closest, 10.0);
}

// spotScene's spot tilted toward +x, direction (1, −2, 0)/√5 (cone map 61.2°, its axis 26.6° off
// the vertical), and everything (camera, light, objects) moved by `offset`. A ground point
// (x, 0, z) lies at d = (x + 16)/√5 along the axis (relative to the offset), so the farthest
// visible receiver is the ground's visible edge x = cameraX + 4·tan 20°·16/9, and the fitted far
// plane before snapping moves with the camera.
scene::Scene tiltedSpotScene(double cameraX, const Vec3& offset = Vec3(0.0)) {
    scene::Scene s = spotScene(cameraX);
    s.lights[0].direction = glm::normalize(Vec3(1, -2, 0));
    s.lights[0].position += offset;
    s.camera.position += offset;
    s.camera.lookAt += offset;
    std::get<scene::Sphere>(s.objects[0].shape).center += offset;
    std::get<scene::Quad>(s.objects[1].shape).center += offset;
    return s;
}

// tiltedSpotScene's far plane before snapping: the farthest receiver's d, grown by the margin
// (10 texels of the window's 2h/N) and 1%.
double tiltedFitFar(double cameraX, double h, int n) {
    return (cameraX + 4.0 * std::tan(deg(20)) * 16.0 / 9.0 + 16.0) / std::sqrt(5.0) * (1.0 + 10.0 * 2.0 * h / n) * 1.01;
}

TEST(RasterSpotFit, SmallCameraMovesLeaveNearAndFarBitIdenticalAndLargeOnesStepAlongTheGrid) {
    // the fitted map must not swim. The window moves by whole texels (above); near and far
    // lie on powers of 2^(1/4), so stored depths do not change either while the camera moves a
    // little, though the unsnapped far moves with it (1/√5 · 1.01 per unit of camera x).
    const int n = 1024;
    const scene::RasterSettings settings = fitSettings(n, true);
    const double x0 = 0.6;
    const scene::Scene s0 = tiltedSpotScene(x0);
    const LightFrustum f0 = spotLightFrustum(s0, settings, s0.lights[0], n);
    const LightFrustum cone = spotLightFrustum(s0, fitSettings(n, false), s0.lights[0], n);
    ASSERT_LT(f0.tanHalfFov, 0.5 * cone.tanHalfFov);  // a fitted window
    // Far: (0.6 + 2.588 + 16)/√5 · (1 + 20h/N) · 1.01 = 8.72 (h = 2^(−1.5): 8.73), halfway between
    // the steps 2^(12/4) = 8 and 2^(13/4) = 9.51 (4·log2 = 12.5), so it snaps up to 2^(13/4).
    const double fitFar = tiltedFitFar(x0, f0.tanHalfFov, n);
    ASSERT_NEAR(4.0 * std::log2(fitFar), 12.5, 0.1);
    EXPECT_NEAR(f0.far, std::exp2(13.0 / 4.0), 1e-12);
    // Near: a power of 2^(1/4) (the nearest caster in the window less 1%, rounded down), above the
    // cone map's near and far/1000.
    EXPECT_NEAR(4.0 * std::log2(f0.near), std::round(4.0 * std::log2(f0.near)), 1e-9);
    EXPECT_GT(f0.near, cone.near);
    EXPECT_GT(f0.near, f0.far / 1000.0);
    // A texel of the window is 2h/N·d ≈ 0.0061 units at the ground; moves of 0.3 texel, a thousandth
    // of a unit and 0.25 units (the unsnapped far changes by up to 0.11, which 8.73 → 9.51 has room
    // for) keep near and far bit for bit.
    for (const double move : {0.3 * 0.0061, 1e-3, -0.25, 0.25}) {
        SCOPED_TRACE(move);
        const scene::Scene s1 = tiltedSpotScene(x0 + move);
        const LightFrustum f1 = spotLightFrustum(s1, settings, s1.lights[0], n);
        // (A precondition of this test, not a check of the program: the unsnapped far does move,
        // so it is the snapping that keeps f1.far.)
        ASSERT_NE(tiltedFitFar(x0 + move, f1.tanHalfFov, n), fitFar) << "precondition";
        EXPECT_EQ(f1.near, f0.near);
        EXPECT_EQ(f1.far, f0.far);
    }
    // A move of 3 units: the unsnapped far grows by 3/√5·1.01 = 1.36 to 10.1, past 2^(13/4), so
    // far steps to 2^(14/4) = 11.3.
    const scene::Scene s2 = tiltedSpotScene(x0 + 3.0);
    const LightFrustum f2 = spotLightFrustum(s2, settings, s2.lights[0], n);
    ASSERT_NEAR(4.0 * std::log2(tiltedFitFar(x0 + 3.0, f2.tanHalfFov, n)), 13.3, 0.1);
    EXPECT_NEAR(f2.far, std::exp2(14.0 / 4.0), 1e-12);
}

TEST(RasterSpotFit, TheSnappedDepthRangeStillHoldsEveryVisibleReceiverAndCaster) {
    // Rendered (validated) from the tilted spot: every visible point, rebuilt from the Frame's depth,
    // lies between near and far along the light's axis, and the sphere (the only caster above the
    // ground in the window) lies beyond near: its nearest point to the light along the axis is
    // (center − light)·axis − r = (2 + 15)/√5 − 0.5 = 7.10.
    const scene::Scene s = tiltedSpotScene(0.6);
    RenderDebug debug;
    const scene::Frame frame = renderChecked(s, fitSettings(1024, true), &debug);
    ASSERT_EQ(debug.layers.size(), 1u);
    const LightFrustum& f = debug.layers[0].frustum;
    const Vec3 axis = glm::normalize(Vec3(1, -2, 0));
    const scene::CameraBasis cam = scene::cameraBasis(s.camera);
    double nearest = INFINITY, farthest = 0.0;
    for (int y = 0; y < frame.height; ++y)
        for (int x = 0; x < frame.width; ++x) {
            const std::size_t i = std::size_t(y) * frame.width + x;
            if (!(frame.objectId[i] > 0.0f)) continue;
            const Vec3 p = cam.position + double(frame.depth[i]) * scene::pixelDirection(cam, x, y);
            const double d = glm::dot(p - s.lights[0].position, axis);
            nearest = std::min(nearest, d);
            farthest = std::max(farthest, d);
        }
    EXPECT_GE(nearest, f.near);
    EXPECT_LE(farthest, f.far);
    EXPECT_LE(f.near, 17.0 / std::sqrt(5.0) - 0.5);
}

TEST(RasterSpotFit, FarFromTheOriginTheFittedMapIsTheSame) {
    // The whole tilted scene moved 10⁶ units away: distances from the light are the same up to
    // rounding of the positions (~1e-10), far from any step of the grid or texel of the window, so
    // the window and the depth range are bit for bit the origin's; a small camera move there keeps
    // them too. The same for every face of a point light.
    const int n = 1024;
    const scene::RasterSettings settings = fitSettings(n, true);
    const Vec3 offset(1e6, 1e6, -1e6);
    const scene::Scene a = tiltedSpotScene(0.6), b = tiltedSpotScene(0.6, offset);
    const LightFrustum fa = spotLightFrustum(a, settings, a.lights[0], n);
    const LightFrustum fb = spotLightFrustum(b, settings, b.lights[0], n);
    EXPECT_EQ(fb.tanHalfFov, fa.tanHalfFov);
    EXPECT_EQ(fb.windowU, fa.windowU);
    EXPECT_EQ(fb.windowV, fa.windowV);
    EXPECT_EQ(fb.near, fa.near);
    EXPECT_EQ(fb.far, fa.far);
    const scene::Scene moved = tiltedSpotScene(0.6 + 1e-3, offset);
    const LightFrustum fm = spotLightFrustum(moved, settings, moved.lights[0], n);
    EXPECT_EQ(fm.near, fa.near);
    EXPECT_EQ(fm.far, fa.far);
}

TEST(RasterSpotFit, MovingTheCameraByAFractionOfATexelKeepsTheSizeAndMovesTheCenterByWholeTexels) {
    // A texel of the fitted map at the ground is 8·2h/N = 0.0055 units; the camera moves along x
    // (the map's v) by 0.3 texel, then by 20.3 texels. The half-size stays 2^(−1.5) and the center
    // moves by a whole number of texels (0 or 1 for the small move, about 20 for the larger).
    const int n = 1024;
    const double h = std::exp2(-1.5), texel = 2.0 * h / n, ground = 8.0 * texel;
    const scene::RasterSettings settings = fitSettings(n, true);
    const scene::Scene s0 = spotScene(2.0);
    const LightFrustum f0 = spotLightFrustum(s0, settings, s0.lights[0], n);
    ASSERT_NEAR(f0.tanHalfFov, h, 1e-12);
    for (const double move : {0.3, 20.3}) {
        SCOPED_TRACE(move);
        const scene::Scene s1 = spotScene(2.0 + move * ground);
        const LightFrustum f1 = spotLightFrustum(s1, settings, s1.lights[0], n);
        EXPECT_EQ(f1.tanHalfFov, f0.tanHalfFov);
        const double dv = (f1.windowV - f0.windowV) / texel;
        EXPECT_NEAR(dv, std::round(dv), 1e-6);
        EXPECT_NEAR(dv, move, 1.0);
        EXPECT_EQ(f1.windowU, f0.windowU);
    }
}

TEST(RasterSpotFit, AnUnrelatedFarObjectChangesNeitherTheTexelNorTheDepthRange) {
    // A sphere r = 1 at (40, 1, 40): out of the view and of the window's pyramid (its direction from
    // the light has v = 40/7 ≫ the window's 0.6), casting nothing into view. It stretches the scene's
    // bounds, so the cone map's far plane moves out (the control), but the fitted map is the same.
    const scene::Scene plain = spotScene();
    scene::Scene withFar = plain;
    scene::Object far = withFar.objects[0];
    far.name = "far";
    far.shape = scene::Sphere{Vec3(40, 1, 40), 1.0};
    withFar.objects.push_back(far);
    const scene::RasterSettings fit = fitSettings(1024, true), cone = fitSettings(1024, false);
    const LightFrustum a = spotLightFrustum(plain, fit, plain.lights[0], 1024);
    const LightFrustum b = spotLightFrustum(withFar, fit, withFar.lights[0], 1024);
    EXPECT_EQ(a.texelWorldSize(), b.texelWorldSize());
    EXPECT_EQ(a.windowU, b.windowU);
    EXPECT_EQ(a.windowV, b.windowV);
    EXPECT_EQ(a.near, b.near);
    EXPECT_EQ(a.far, b.far);
    // Cone map: far = 7.5 + 1.01·½·√(20² + 1 + 20²) = 21.8 without, 7 + 1.01·½·√(51² + 2² + 51²) =
    // 43.4 with the far sphere.
    EXPECT_GT(spotLightFrustum(withFar, cone, withFar.lights[0], 1024).far,
              1.9 * spotLightFrustum(plain, cone, plain.lights[0], 1024).far);
    // Rendered: the texel_world_size attribute is the same with and without the far sphere.
    EXPECT_EQ(renderChecked(plain, fit).attributes.at("texel_world_size"),
              renderChecked(withFar, fit).attributes.at("texel_world_size"));
}

TEST(RasterSpotFit, ReceiversBehindTheLightsPlaneKeepTheWholeCone) {
    // With the spot at y = 0.5, inside the scene box's height 0..1, the visible receivers at y = 1
    // lie behind the light's plane (its map could not hold them): the whole cone is kept.
    scene::Scene s = spotScene();
    s.lights[0].position = {0, 0.5, 0};
    const LightFrustum f = spotLightFrustum(s, fitSettings(1024, true), s.lights[0], 1024);
    EXPECT_NEAR(f.tanHalfFov, std::tan(deg(61.2)), 1e-12);
    EXPECT_EQ(f.windowU, 0.0);
    EXPECT_EQ(f.windowV, 0.0);
}

TEST(RasterSpotFit, TheFittedRenderIsNoWorseAgainstTheReference) {
    // The same map size (256, coarse for the whole cone): the fitted map's texel is ~5x finer, so
    // the sphere's shadow edge is closer to the reference's. Wrong pixels (false + missed) and the
    // mean |V − V_ref| must not grow; in fact the fitted map has clearly fewer. 320 x 180: the
    // camera looks down past the sphere onto its shadow, most of which the sphere hides.
    const scene::Scene s = spotScene(2.0, 320, 180);
    scene::RenderSettings settings;
    settings.raster = fitSettings(256, false);
    const scene::Frame ref = test::renderReference(s, settings);
    const scene::Frame cone = renderChecked(s, fitSettings(256, false));
    const scene::Frame fitted = renderChecked(s, fitSettings(256, true));
    const compare::Metrics a = compare::compareFrames(fitted, ref).metrics;
    const compare::Metrics b = compare::compareFrames(cone, ref).metrics;
    std::printf("reference shadowed %zu of %zu; wrong: fitted %zu, cone %zu; mean |dV| fitted %.4f, cone %.4f\n",
                a.shadowedReference, a.counted, a.falseShadow + a.missedShadow, b.falseShadow + b.missedShadow,
                a.meanAbsVisibilityError, b.meanAbsVisibilityError);
    ASSERT_GT(a.shadowedReference, 200u);  // the sphere's shadow is in view (~400 pixels)
    EXPECT_LE(a.falseShadow + a.missedShadow, b.falseShadow + b.missedShadow);
    EXPECT_LE(a.meanAbsVisibilityError, b.meanAbsVisibilityError);
    EXPECT_LT(a.meanAbsVisibilityError, 0.75 * b.meanAbsVisibilityError);
}

// Point light at (0, 4, 0) over the same ground and sphere (at (0, 0.5, 0) here), the camera at
// (0, 3, 6) looking at the origin.
scene::Scene pointScene(int width = 160, int height = 90) {
    scene::Scene s = sphereOnTheGround({0, 0.5, 0}, {0, 3, 6}, {0, 0, 0}, width, height);
    scene::Light l;
    l.type = scene::LightType::Point;
    l.position = {0, 4, 0};
    l.intensity = 400;
    s.lights = {l};
    return s;
}

TEST(RasterPointFit, EachFaceTakesItsNearAndFarFromItsCastersAndReceivers) {
    // N = 1024: t = N/(N − 24) = 1.0240, a texel 2t/N per unit of distance; margin 10 texels.
    // −Y (down): the farthest receiver is the ground, d = 4, so far = 4·(1 + 10·2t/N)·1.01; the
    // nearest caster in its pyramid is the sphere's box top (y = 1, d = 3), near = 3/1.01.
    // +X: the ground enters its pyramid where 4/x ≤ t, i.e. at x = 4/t, the sphere's box (x ≤ 0.5)
    // never does (it would need x ≥ 3/t): near = (4/t)/1.01. +Y: nothing visible lies above the
    // light, so its range stays the bounding sphere's.
    const int n = 1024;
    const double t = double(n) / (n - 24);
    const scene::Scene s = pointScene(320, 180);
    const scene::RasterSettings fit = fitSettings(n, true), plain = fitSettings(n, false);
    // Each snapped outward to a power of 2^(1/4): far 4·1.02·1.01 = 4.121 (4·log2 = 8.17) → 2^(9/4);
    // near 2.970 (6.28) → 2^(6/4); +X near 3.867 (7.81) → 2^(7/4).
    ASSERT_NEAR(4.0 * std::log2(4.0 * (1.0 + 10.0 * 2.0 * t / n) * 1.01), 8.17, 0.01);
    ASSERT_NEAR(4.0 * std::log2(3.0 / 1.01), 6.28, 0.01);
    ASSERT_NEAR(4.0 * std::log2(4.0 / t / 1.01), 7.81, 0.01);
    const LightFrustum down = pointLightFaceFrustum(s, fit, s.lights[0], 3, n);
    EXPECT_NEAR(down.far, std::exp2(9.0 / 4.0), 1e-12);
    EXPECT_NEAR(down.near, std::exp2(6.0 / 4.0), 1e-12);
    const LightFrustum plusX = pointLightFaceFrustum(s, fit, s.lights[0], 0, n);
    EXPECT_NEAR(plusX.near, std::exp2(7.0 / 4.0), 1e-12);
    const LightFrustum up = pointLightFaceFrustum(s, fit, s.lights[0], 2, n);
    const LightFrustum upPlain = pointLightFaceFrustum(s, plain, s.lights[0], 2, n);
    EXPECT_EQ(up.near, upPlain.near);
    EXPECT_EQ(up.far, upPlain.far);
    // The bounding sphere's range (near = far/1000 with the light inside the scene's box) is much
    // wider: the fitted near is over 100x farther.
    EXPECT_GT(down.near, 100.0 * pointLightFaceFrustum(s, plain, s.lights[0], 3, n).near);

    // Rendered (validated), with each face's range in the shader: the same shadows as the
    // bounding-sphere range, up to a few pixels on the sphere's shadow edge.
    RenderDebug debug;
    const scene::Frame fitted = renderChecked(s, fit, &debug);
    const scene::Frame wide = renderChecked(s, plain);
    ASSERT_EQ(debug.layers.size(), 6u);
    EXPECT_NEAR(debug.layers[3].frustum.near, down.near, 1e-12);
    int differ = 0, shadowed = 0;
    for (std::size_t i = 0; i < fitted.visibility.size(); ++i) {
        differ += std::abs(fitted.visibility[i] - wide.visibility[i]) > 0.5f;
        shadowed += wide.visibility[i] < 0.5f && wide.objectId[i] == 2.0f;
    }
    ASSERT_GT(shadowed, 100);
    EXPECT_LE(differ, shadowed / 50) << differ << " pixels differ, " << shadowed << " shadowed";

    // PCSS of a light of radius 0.3, whose taps go on into the neighbouring faces (each with its
    // own range there, lit.frag cubeTap). The blocker search's reach follows the face's near plane
    // (it is largest for blockers there), which the fit moves from far/1000 to the sphere, so the
    // penumbrae are not the same as before: against the reference (256 samples of the sphere
    // light) they must be no worse.
    scene::Scene soft = pointScene(160, 90);
    soft.lights[0].radius = 0.3;
    scene::RasterSettings pcssFit = fit, pcssPlain = plain;
    pcssFit.filter = pcssPlain.filter = scene::ShadowFilter::Pcss;
    scene::RenderSettings rs;
    rs.raster = pcssPlain;
    const scene::Frame ref = test::renderReference(soft, rs);
    const compare::Metrics a = compare::compareFrames(renderChecked(soft, pcssFit), ref).metrics;
    const compare::Metrics b = compare::compareFrames(renderChecked(soft, pcssPlain), ref).metrics;
    std::printf("pcss: mean |dV| fitted %.4f, bounding-sphere range %.4f; wrong %zu, %zu\n", a.meanAbsVisibilityError,
                b.meanAbsVisibilityError, a.falseShadow + a.missedShadow, b.falseShadow + b.missedShadow);
    EXPECT_LE(a.meanAbsVisibilityError, b.meanAbsVisibilityError * 1.05);
    EXPECT_LE(a.falseShadow + a.missedShadow, b.falseShadow + b.missedShadow + a.counted / 200);
}

TEST(RasterPointFit, SmallCameraMovesLeaveEveryFacesNearAndFarBitIdentical) {
    // The point scene's camera moved sideways by a thousandth and a hundredth of a unit: the visible
    // ground's edge, and with it the unsnapped far of the side faces, moves; the snapped ranges of
    // all six faces stay bit for bit. Moved 10⁶ units away (light and all), the same ranges.
    const int n = 1024;
    const scene::RasterSettings settings = fitSettings(n, true);
    const scene::Scene s0 = pointScene(320, 180);
    for (const double move : {1e-3, 1e-2}) {
        SCOPED_TRACE(move);
        scene::Scene s1 = s0;
        s1.camera.position.x += move;
        s1.camera.lookAt.x += move;
        scene::Scene far = s0;
        const Vec3 offset(-1e6, 1e6, 1e6);
        far.camera.position += offset + Vec3(move, 0, 0);
        far.camera.lookAt += offset + Vec3(move, 0, 0);
        far.lights[0].position += offset;
        std::get<scene::Sphere>(far.objects[0].shape).center += offset;
        std::get<scene::Quad>(far.objects[1].shape).center += offset;
        for (int face = 0; face < kCubeFaces; ++face) {
            SCOPED_TRACE(face);
            const LightFrustum f0 = pointLightFaceFrustum(s0, settings, s0.lights[0], face, n);
            for (const scene::Scene* s : {&s1, &far}) {
                const LightFrustum f1 = pointLightFaceFrustum(*s, settings, s->lights[0], face, n);
                EXPECT_EQ(f1.near, f0.near);
                EXPECT_EQ(f1.far, f0.far);
            }
        }
    }
}

// The point light's map size by hand: camera at (0, 10, 0) looking straight down (fov 40°) at the
// ground y = 0 (view depth 10) and a box [−1, 1] x [0, 2] x [−1, 1] (its top at view depth 8, all
// in view), point light at (0, 12, 0). ‖p − light‖∞ is 12 − y wherever |x|, |z| < 12 − y (the view
// reaches |x| ≤ 10·tan 20°·16/9 = 6.5 on the ground), so ‖p − light‖∞ / view depth = (12 − y)/(10 −
// y), largest on the box's top: 10/8. N ≥ 2·(10/8)/(2·tan 20°/H) + 24 = 3.434·H + 24: 333 at
// H = 90 → 512, 642 at H = 180 → 1024, 230 at H = 60 → 256, 1260 at H = 360 → 2048.
scene::Scene pointFromAbove(int height) {
    scene::Scene s = pointScene();
    test::boxUnderADownwardCamera(s, height);
    s.lights[0].position = {0, 12, 0};
    return s;
}

TEST(RasterMapSize, APointLightsMapIsSizedByTheFinestReceiverDetail) {
    auto expected = [](int height) {
        const double needed = 2.0 * (10.0 / 8.0) / (2.0 * std::tan(deg(20)) / height) + 24.0;
        int size = 256;
        while (size < needed && size < 2048) size *= 2;
        return size;
    };
    EXPECT_EQ(expected(60), 256);
    EXPECT_EQ(expected(90), 512);
    EXPECT_EQ(expected(180), 1024);
    EXPECT_EQ(expected(360), 2048);
    for (const int height : {60, 90, 180, 360}) {
        SCOPED_TRACE(height);
        const scene::Scene s = pointFromAbove(height);
        const ShadowMapSizeChoice c = chooseShadowMapSize(s, scene::resolveSettings(s, {}).raster);
        EXPECT_EQ(c.size, expected(height)) << c.reason;
        EXPECT_NE(c.reason.find("point 0"), std::string::npos) << c.reason;
    }
    // Forced sizes stay forced.
    scene::Scene s = pointFromAbove(90);
    scene::SettingsOverrides o;
    o.shadowMapSize = 2048;
    EXPECT_EQ(chooseShadowMapSize(s, scene::resolveSettings(s, o).raster).size, 2048);
    s.shadow.shadowMapSize = 1024;
    EXPECT_EQ(chooseShadowMapSize(s, scene::resolveSettings(s, {}).raster).size, 1024);
    // The render uses it (validated).
    const scene::Scene p = pointFromAbove(90);
    const scene::Frame f = renderChecked(p, scene::resolveSettings(p, {}));
    EXPECT_EQ(f.attributes.at("shadow_map_size"), "512");
}

}  // namespace
}  // namespace shadowlab::raster
