// tests/raster/shadow_pass_test.cpp: the depth pass alone: every texel of the shadow map holds
// the light-space depth of the surface its center sees, computed here in closed form, and the
// blocker-id map the id of that surface's object.
#include "raster/shadow_pass.h"

#include <gtest/gtest.h>

#include "raster/geometry.h"
#include "raster/light_frustum.h"
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

}  // namespace
}  // namespace shadowlab::raster
