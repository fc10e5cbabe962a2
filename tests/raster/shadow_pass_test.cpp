// tests/raster/shadow_pass_test.cpp: the depth pass alone: every texel of the shadow map holds
// the light-space depth of the surface its center sees, computed here in closed form, and the
// blocker-id map the id of that surface's object.
#include "raster/shadow_pass.h"

#include <gtest/gtest.h>
#include <glm/gtc/matrix_transform.hpp>

#include "raster/geometry.h"
#include "raster/light_frustum.h"
#include "raster/tolerances.h"
#include "tests/kit/test_scenes.h"

namespace shadowlab::raster {
namespace {

using test::Vec3;

TEST(ShadowPass, StoresTheClosedFormDepthOfWhatEachTexelSees) {
    // A 2x2 plane at y = 0 with a box [0.3,0.9]x[0,0.5]x[-0.4,0.2] on it, light from straight
    // above and slightly tilted so that u, v and depth all vary; the origin is off the scene
    // to exercise the camera-relative matrices.
    scene::Scene s = test::makeScene(test::SphereOverPlane{});
    s.objects.clear();
    test::addQuad(s, Vec3(0), Vec3(0, 1, 0), 2, 2);
    test::addBox(s, Vec3(0.3, 0, -0.4), Vec3(0.9, 0.5, 0.2));
    const Vec3 dir = glm::normalize(Vec3(0.05, -1, 0.02));
    const Vec3 origin(3, 4, 5);
    const int size = 128;

    ValidationLog log;
    {
        const Context ctx(ContextOptions{.validate = true, .log = &log});
        const SceneGeometry g = tessellateScene(s, origin);
        const Buffer vb = uploadBuffer(ctx, g.vertices, VK_BUFFER_USAGE_VERTEX_BUFFER_BIT);
        const Buffer ib = uploadBuffer(ctx, g.indices, VK_BUFFER_USAGE_INDEX_BUFFER_BIT);
        const LightFrustum f = fitDirectionalLight(s.bounds(), dir, size);
        const ShadowPipeline pipeline = createShadowPipeline(ctx);
        const ShadowMaps maps = createShadowMaps(ctx, size, 2);
        VkCommandBuffer commands = ctx.beginCommands();
        recordShadowPass(commands, pipeline, maps,
                         DrawGeometry{vb.buffer.get(), ib.buffer.get(), std::uint32_t(g.indices.size())},
                         {glm::mat4(f.toClip(origin))});
        ctx.submitAndWait(commands);
        const std::vector<float> depth = readShadowMap(ctx, maps, 0);
        const std::vector<std::uint32_t> ids = readBlockerIds(ctx, maps, 0);
        const std::vector<float> unused = readShadowMap(ctx, maps, 1);

        // Texel (i, j) center in world: center + (2u−1)·h·right + (2v−1)·h·up, u = (i+½)/size.
        // March along the light from there to the first surface: the box top (y = 0.5) or the
        // plane (y = 0); expected depth = (distance along dir from the center + h) / 2h.
        const double texel = f.texelWorldSize();
        int plane = 0, top = 0, empty = 0;
        for (int j = 0; j < size; ++j)
            for (int i = 0; i < size; ++i) {
                const double u = (i + 0.5) / size, v = (j + 0.5) / size;
                const Vec3 start = f.center + (2 * u - 1) * f.halfWidth * f.right + (2 * v - 1) * f.halfWidth * f.up;
                auto depthAtHeight = [&](double y, Vec3& hit) {
                    const double t = (y - start.y) / dir.y;  // start + t·dir reaches height y
                    hit = start + t * dir;
                    return (t + f.halfWidth) / (2 * f.halfWidth);
                };
                Vec3 onTop, onPlane;
                const double zTop = depthAtHeight(0.5, onTop);
                const double zPlane = depthAtHeight(0.0, onPlane);
                const float got = depth[std::size_t(j) * size + i];
                auto inside = [&](const Vec3& p, double x0, double x1, double z0, double z1, double margin) {
                    return p.x > x0 + margin && p.x < x1 - margin && p.z > z0 + margin && p.z < z1 - margin;
                };
                auto outside = [&](const Vec3& p, double x0, double x1, double z0, double z1, double margin) {
                    return p.x < x0 - margin || p.x > x1 + margin || p.z < z0 - margin || p.z > z1 + margin;
                };
                // Skip texels within a texel of an edge (the box's sides are seen there too).
                if (inside(onTop, 0.3, 0.9, -0.4, 0.2, texel)) {
                    ASSERT_NEAR(got, zTop, 1e-6) << i << "," << j;
                    ASSERT_EQ(ids[std::size_t(j) * size + i], 2u);  // the box (objects[1])
                    ++top;
                } else if (outside(onTop, 0.3, 0.9, -0.4, 0.2, texel) && outside(onPlane, 0.3, 0.9, -0.4, 0.2, texel) &&
                           inside(onPlane, -1, 1, -1, 1, texel)) {
                    ASSERT_NEAR(got, zPlane, 1e-6) << i << "," << j;
                    ASSERT_EQ(ids[std::size_t(j) * size + i], 1u);  // the plane (objects[0])
                    ++plane;
                } else if (outside(onPlane, -1, 1, -1, 1, texel)) {
                    ASSERT_EQ(got, 1.0f) << i << "," << j;  // cleared: nothing there
                    ASSERT_EQ(ids[std::size_t(j) * size + i], 0u);
                    ++empty;
                }
            }
        EXPECT_GT(top, 100);
        EXPECT_GT(plane, 1000);
        EXPECT_GT(empty, 1000);
        for (float d : unused) ASSERT_EQ(d, 1.0f);  // a layer without a light is only cleared
    }
    EXPECT_EQ(log.count.load(), 0);
}

// The transmittance window (raster/shadow_pass.h) of casters given by their boxes or triangles.
TransparentDraw boxCaster(const glm::vec3& lo, const glm::vec3& hi) {
    TransparentDraw d;
    d.boundsMin = lo;
    d.boundsMax = hi;
    return d;
}

TEST(TransmittanceWindow, HoldsTheCastersProjectionWithItsMarginAndNoMore) {
    // An orthographic light whose clip space is the world (x, y in [-1, 1] across the 64² map, z in
    // [0, 1] along it). The box x in [-0.5, 0.5], y in [-0.25, 0.25] projects to texels x in
    // [(−0.5 + 1)/2·64, (0.5 + 1)/2·64] = [16, 48] and y in [24, 40]; a texel i is covered when its
    // center i + 0.5 lies inside, so i in [16, 47] and [24, 39]. The window is floor(lo) − 2 to
    // floor(hi) + 1 + 2 (the margin of kTransmittanceWindowMarginTexels = 2, one texel more at an
    // edge that falls on a texel boundary): [14, 51) x [22, 43).
    static_assert(kTransmittanceWindowMarginTexels == 2);
    const glm::mat4 identity(1.0f);
    const TexelRect w = transmittanceWindow(identity, {boxCaster({-0.5f, -0.25f, 0.2f}, {0.5f, 0.25f, 0.3f})}, 64);
    EXPECT_EQ(w.x0, 14u);
    EXPECT_EQ(w.y0, 22u);
    EXPECT_EQ(w.x1, 51u);
    EXPECT_EQ(w.y1, 43u);
    // Two casters: the window of both; none: empty; off the map: empty; past its edge: clamped.
    const TexelRect both = transmittanceWindow(
        identity,
        {boxCaster({-0.5f, -0.25f, 0.2f}, {0.5f, 0.25f, 0.3f}), boxCaster({0.6f, 0.6f, 0.5f}, {0.7f, 0.7f, 0.6f})}, 64);
    // The second projects to x, y in [51.2, 54.4]: floor + 3 = 57, floor(51.2) − 2 = 49.
    EXPECT_EQ(both.x0, 14u);
    EXPECT_EQ(both.y0, 22u);
    EXPECT_EQ(both.x1, 57u);
    EXPECT_EQ(both.y1, 57u);
    EXPECT_TRUE(transmittanceWindow(identity, {}, 64).empty());
    EXPECT_TRUE(transmittanceWindow(identity, {boxCaster({2.0f, 2.0f, 0.5f}, {3.0f, 3.0f, 0.6f})}, 64).empty());
    const TexelRect edge = transmittanceWindow(identity, {boxCaster({0.9f, -0.1f, 0.5f}, {1.5f, 0.1f, 0.6f})}, 64);
    EXPECT_EQ(edge.x1, 64u);
    EXPECT_EQ(edge.x0, 58u);  // floor((0.9 + 1)/2·64 = 60.8) − 2
}

TEST(TransmittanceWindow, ACasterBehindAPerspectiveLightIsLeftOutAndOneAcrossItsPlaneIsCutThere) {
    // A spot at the origin looking down −z (glm's right-handed view), 90° field of view, near 0.1,
    // far 10, depth 0..1: its clip z is >= 0 only in front of the near plane.
    const glm::mat4 m = glm::perspectiveRH_ZO(glm::radians(90.0f), 1.0f, 0.1f, 10.0f);
    const std::uint32_t size = 256;
    // Wholly behind the light (z > 0): nothing of it is drawn.
    EXPECT_TRUE(transmittanceWindow(m, {boxCaster({-1.0f, -1.0f, 1.0f}, {1.0f, 1.0f, 2.0f})}, size).empty());
    // Across the light's plane, x in [0.55, 1.5], y in [-0.25, 0.25], z in [-2, 1]: its part in front
    // of the near plane (z <= -0.1) projects to u = x/(-z) in [0.55/2, 1.5/0.1] (clamped to the
    // map's right edge, 1) and v = y/(-z) in [-2.5, 2.5] (clamped: the whole height). Its left edge
    // is where x is least and -z largest, u = 0.275: texel (0.275 + 1)/2·256 = 163.2, floor − 2 = 161.
    const TexelRect across = transmittanceWindow(m, {boxCaster({0.55f, -0.25f, -2.0f}, {1.5f, 0.25f, 1.0f})}, size);
    EXPECT_EQ(across.x0, 161u);
    EXPECT_EQ(across.x1, size);
    EXPECT_EQ(across.y0, 0u);
    EXPECT_EQ(across.y1, size);
}

TEST(TransmittanceWindow, ACastersTrianglesGiveATighterWindowThanItsBox) {
    // One triangle (0, 0), (0.5, 0), (0, 0.5) at z 0.5 under the world-as-clip-space light of the
    // first test, 64²: texels x and y in [32, 48], window [30, 51); the caster's box, given larger
    // (to 0.9: texel 60.8, window to 63), is not what the window follows.
    TransparentDraw d = boxCaster({0.0f, 0.0f, 0.5f}, {0.9f, 0.9f, 0.5f});
    d.triangles = {{0.0f, 0.0f, 0.5f}, {0.5f, 0.0f, 0.5f}, {0.0f, 0.5f, 0.5f}};
    const TexelRect w = transmittanceWindow(glm::mat4(1.0f), {d}, 64);
    EXPECT_EQ(w.x0, 30u);
    EXPECT_EQ(w.y0, 30u);
    EXPECT_EQ(w.x1, 51u);
    EXPECT_EQ(w.y1, 51u);
    // A spot's view of a triangle crossing its plane: the triangles' part in front, like a box's.
    const glm::mat4 m = glm::perspectiveRH_ZO(glm::radians(90.0f), 1.0f, 0.1f, 10.0f);
    d.triangles = {{0.55f, 0.0f, -2.0f}, {0.55f, 0.2f, -2.0f}, {0.55f, 0.0f, 1.0f}};
    d.boundsMin = {0.55f, 0.0f, -2.0f};
    d.boundsMax = {0.55f, 0.2f, 1.0f};
    const TexelRect across = transmittanceWindow(m, {d}, 256);
    EXPECT_EQ(across.x0, 161u);  // u = 0.55/2 at its far end, as for the box above
    EXPECT_EQ(across.x1, 256u);
}

}  // namespace
}  // namespace shadowlab::raster
