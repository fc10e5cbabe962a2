// tests/raster/view_cull_test.cpp: the lit pass's view culling (raster/view_cull.h): the box test
// against a camera worked out by hand, the clusters and the cut ranges, then frames with and without
// culling bit for bit and the number of triangles drawn for a scene whose visible quads are counted.
#include "raster/view_cull.h"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <memory>
#include <random>
#include <string>
#include <vector>

#include <gtest/gtest.h>
#include <glm/glm.hpp>

#include "raster/renderer.h"
#include "raster/tolerances.h"
#include "scene/camera.h"
#include "tests/kit/render_checked.h"
#include "tests/kit/test_scenes.h"

namespace shadowlab::raster {
namespace {

using namespace test;

// A camera at the origin looking down −z with a 90° vertical field of view on a square image,
// near 1, far 100 (scene/camera.cpp): clip x = x, y = −y, w = −z, z_clip = (z + 100)/99. A point at
// view depth d = −z is inside when |x| ≤ d, |y| ≤ d and 1 ≤ d ≤ 100.
glm::mat4 squareCamera() {
    scene::Camera c;
    c.position = Vec3(0, 0, 0);
    c.lookAt = Vec3(0, 0, -1);
    c.fovYDegrees = 90.0;
    c.width = c.height = 100;
    const scene::CameraBasis basis = scene::cameraBasis(c);
    return glm::mat4(scene::projectionMatrix(basis, 1.0, 100.0) * scene::viewMatrix(basis, c.position));
}

TEST(ViewCull, BoxesOutsideOnePlaneAreCulledAndNoOtherOnes) {
    const glm::mat4 m = squareCamera();
    auto outside = [&](glm::vec3 lo, glm::vec3 hi) { return boxOutsideClipVolume(lo, hi, m); };
    // Left of the view: at depth 3 the left plane is x = −3; the box's nearest corner to the view
    // (x = −3.01 at depth 3) is 0.01 outside, 100 times the margin (1e-5 · a few units).
    EXPECT_TRUE(outside({-3.5f, -0.1f, -3.0f}, {-3.01f, 0.1f, -2.9f}));
    // The same box reaching 0.01 into the view at depth 3: drawn.
    EXPECT_FALSE(outside({-3.5f, -0.1f, -3.0f}, {-2.99f, 0.1f, -2.9f}));
    // Outside by 1e-6 of a unit only (less than the margin): drawn, conservatively.
    EXPECT_FALSE(outside({-3.5f, -0.1f, -3.0f}, {-3.000001f, 0.1f, -3.0f}));
    // Right, above, below: each by 0.5 at depth 2.
    EXPECT_TRUE(outside({2.5f, -0.1f, -2.0f}, {3.0f, 0.1f, -2.0f}));
    EXPECT_TRUE(outside({-0.1f, 2.5f, -2.0f}, {0.1f, 3.0f, -2.0f}));
    EXPECT_TRUE(outside({-0.1f, -3.0f, -2.0f}, {0.1f, -2.5f, -2.0f}));
    // Behind the camera, and between the camera and the near plane (depth 0.5): outside the near plane.
    EXPECT_TRUE(outside({-1.0f, -1.0f, 1.0f}, {1.0f, 1.0f, 2.0f}));
    EXPECT_TRUE(outside({-0.1f, -0.1f, -0.6f}, {0.1f, 0.1f, -0.4f}));
    // Past the far plane (depth 150..200).
    EXPECT_TRUE(outside({-1.0f, -1.0f, -200.0f}, {1.0f, 1.0f, -150.0f}));
    // Straddling the near plane, straddling the far plane, around the camera, and a box that lies
    // outside the view's corner region yet outside no single plane (left of the left plane at depth
    // 1 and right of the right plane at depth 10 need different planes): all drawn.
    EXPECT_FALSE(outside({-0.1f, -0.1f, -2.0f}, {0.1f, 0.1f, -0.5f}));
    EXPECT_FALSE(outside({-1.0f, -1.0f, -150.0f}, {1.0f, 1.0f, -50.0f}));
    EXPECT_FALSE(outside({-1.0f, -1.0f, -1.0f}, {1.0f, 1.0f, 1.0f}));
    EXPECT_FALSE(outside({-5.0f, 2.0f, -10.0f}, {5.0f, 2.0f, -1.0f}));
    // An empty box (lo > hi) is never culled.
    EXPECT_FALSE(outside({1.0f, 1.0f, 1.0f}, {0.0f, 0.0f, 0.0f}));
}

TEST(ViewCull, ClustersStayWithinTheirPieceAndHoldTheirVerticesBoxes) {
    // Five triangles over vertices at x = 0..6; pieces of three and two triangles, two per cluster.
    std::vector<Vertex> vertices;
    for (int i = 0; i < 7; ++i) vertices.push_back(Vertex{.position = glm::vec3(float(i), float(-i), 1.0f)});
    const std::vector<std::uint32_t> indices = {0, 1, 2, 1, 2, 3, 4, 5, 6, 0, 6, 3, 2, 2, 2};
    const std::vector<IndexRange> pieces = {{0, 9}, {9, 6}};
    const std::vector<IndexCluster> c = indexClusters(vertices, indices, pieces, 2);
    ASSERT_EQ(c.size(), 3u);
    EXPECT_EQ(c[0].first, 0u);
    EXPECT_EQ(c[0].count, 6u);
    EXPECT_EQ(c[0].lo, glm::vec3(0, -3, 1));
    EXPECT_EQ(c[0].hi, glm::vec3(3, 0, 1));
    EXPECT_EQ(c[1].first, 6u);
    EXPECT_EQ(c[1].count, 3u);
    EXPECT_EQ(c[1].lo, glm::vec3(4, -6, 1));
    EXPECT_EQ(c[1].hi, glm::vec3(6, -4, 1));
    EXPECT_EQ(c[2].first, 9u);
    EXPECT_EQ(c[2].count, 6u);
    EXPECT_EQ(c[2].lo, glm::vec3(0, -6, 1));
    EXPECT_EQ(c[2].hi, glm::vec3(6, 0, 1));
}

TEST(ViewCull, RangesAreCutToTheVisibleRunsKeepingTheirFlags) {
    const std::vector<IndexRange> ranges = {{0, 30, true, false}, {30, 60, false, true}};
    const std::vector<IndexRange> visible = {{9, 30}, {75, 15}};
    const std::vector<IndexRange> cut = intersectRanges(ranges, visible);
    ASSERT_EQ(cut.size(), 3u);
    EXPECT_EQ(cut[0].first, 9u);
    EXPECT_EQ(cut[0].count, 21u);
    EXPECT_TRUE(cut[0].alpha);
    EXPECT_EQ(cut[1].first, 30u);
    EXPECT_EQ(cut[1].count, 9u);
    EXPECT_TRUE(cut[1].liftFree);
    EXPECT_FALSE(cut[1].alpha);
    EXPECT_EQ(cut[2].first, 75u);
    EXPECT_EQ(cut[2].count, 15u);
    EXPECT_TRUE(cut[2].liftFree);
    EXPECT_TRUE(intersectRanges(ranges, {}).empty());
    // Visible runs of adjacent clusters come merged.
    const std::vector<IndexCluster> clusters = {{0, 6, glm::vec3(0, 0, -2), glm::vec3(0, 0, -2)},
                                                {6, 6, glm::vec3(0, 0, -2), glm::vec3(0, 0, -2)},
                                                {12, 3, glm::vec3(0, 0, 2), glm::vec3(0, 0, 2)},
                                                {15, 3, glm::vec3(0, 0, -2), glm::vec3(0, 0, -2)}};
    const std::vector<IndexRange> runs = visibleIndexRuns(clusters, squareCamera());
    ASSERT_EQ(runs.size(), 2u);
    EXPECT_EQ(runs[0].first, 0u);
    EXPECT_EQ(runs[0].count, 12u);
    EXPECT_EQ(runs[1].first, 15u);
    EXPECT_EQ(runs[1].count, 3u);
}

// A ground of cells x cells quads (two triangles each, row by row along z) over [−half, half]².
std::shared_ptr<scene::TriangleMesh> groundGrid(int cells, double half) {
    auto mesh = std::make_shared<scene::TriangleMesh>();
    for (int j = 0; j <= cells; ++j)
        for (int i = 0; i <= cells; ++i) {
            mesh->positions.emplace_back(-half + 2.0 * half * i / cells, 0.0, -half + 2.0 * half * j / cells);
            mesh->normals.emplace_back(0.0, 1.0, 0.0);
        }
    const auto at = [&](int i, int j) { return std::uint32_t(j * (cells + 1) + i); };
    for (int j = 0; j < cells; ++j)
        for (int i = 0; i < cells; ++i)
            for (std::uint32_t v : {at(i, j), at(i, j + 1), at(i + 1, j + 1), at(i, j), at(i + 1, j + 1), at(i + 1, j)})
                mesh->indices.push_back(v);
    return mesh;
}

// The all-channel, float-beauty and display frames of a Renderer with view culling and one without,
// bit for bit, twice each (the second frames with the lift-free draws); returns the lit pass's
// triangles with culling (the last frame's) and the scene's, and checks that without culling every
// triangle is drawn.
// An empty scene with the material "matte" and a 160x90 camera at `position` looking at `lookAt`.
scene::Scene smallView(const Vec3& position, const Vec3& lookAt) {
    scene::Scene s;
    s.camera.position = position;
    s.camera.lookAt = lookAt;
    s.camera.width = 160;
    s.camera.height = 90;
    addMaterial(s, "matte");
    return s;
}

struct Drawn {
    std::size_t culled = 0, all = 0;
};
Drawn expectSameFramesCulled(const scene::Scene& s, const scene::RasterSettings& settings) {
    Renderer culled(s, planFor(s, settings), settings),
        whole(s, planFor(s, settings), settings, RendererOptions{.viewCull = false});
    Drawn drawn;
    for (int round = 0; round < 2; ++round)
        for (const scene::ChannelMask channels :
             {scene::kAllChannels, scene::kChannelBeauty, scene::kChannelBeauty | scene::kBeautyForDisplay}) {
            RenderDebug withCull, without;
            const scene::Frame a = culled.render(channels, &withCull), b = whole.render(channels, &without);
            test::expectSamePixels(a, b, "view culling against none");
            EXPECT_EQ(std::to_string(without.litTriangles), b.attributes.at("triangles"));
            EXPECT_EQ(withCull.liftFreeTriangles > 0, without.liftFreeTriangles > 0);
            drawn = {withCull.litTriangles, std::stoul(b.attributes.at("triangles"))};
        }
    EXPECT_EQ(culled.validationMessages(), 0);
    EXPECT_EQ(whole.validationMessages(), 0);
    return drawn;
}

TEST(ViewCull, CulledFramesAreTheSameBitForBit) {
    // A tessellated ground reaching 40 units behind and beside the camera, a sphere in view, boxes
    // behind the camera and beside the view (one of them casts into the view under the low sun).
    scene::Scene s = smallView(Vec3(0, 2, 0), Vec3(0, 0.5, -6));
    constexpr int kCells = 40;  // 2-unit cells, 80 triangles a row, rows along +z from z = −40
    addMesh(s, groundGrid(kCells, 40.0));
    addSphere(s, Vec3(0, 1, -6), 1.0);
    addBox(s, Vec3(-1, 0, 3), Vec3(1, 3, 5));       // behind the camera
    addBox(s, Vec3(-31, 0, -6), Vec3(-29, 2, -4));  // far left of the view
    addBox(s, Vec3(8, 0, -9), Vec3(10, 4, -7));     // right of the view, its shadow toward it
    addDirectional(s, Vec3(-0.6, -0.5, -0.3));
    const Drawn drawn = expectSameFramesCulled(s, validatedSettings(512, 0.01, 1.0, scene::ShadowFilter::Pcf2x2));
    // What is left out: the camera looks 14° down (atan(1.5/6)) with a 20° half field of view, so
    // the ground enters the view 2/tan 34° = 2.97 units ahead (z = −2.97); nearer ground, and all
    // ground behind, lies below the bottom plane. A ground cluster is left out when its box (every
    // row it touches, x over the whole width) starts at z ≥ −2 (rows are 2 units deep). The three
    // boxes are outside the near, left and right planes (half width 0.647 × depth: 3.4 at depth 5,
    // 6.6 at 10); the sphere (depth 5–7, 0.08 rad below the axis, 0.17 wide) is inside.
    std::size_t ground = 0;
    const std::uint32_t rowTriangles = 2 * kCells;
    for (std::uint32_t first = 0; first < rowTriangles * kCells; first += kViewCullClusterTriangles)
        if (-40 + 2 * int(first / rowTriangles) >= -2)
            ground += std::min<std::uint32_t>(kViewCullClusterTriangles, rowTriangles * kCells - first);
    ASSERT_GT(ground, 0u);
    EXPECT_EQ(drawn.culled, drawn.all - ground - 3 * 12);
}

TEST(ViewCull, SeedFramesAreTheSameBitForBit) {
    expectSameFramesCulled(loadSeed(), validatedSettings(512, 0.01, 1.0, scene::ShadowFilter::Pcf2x2));
}

TEST(ViewCull, DrawsTheQuadsInViewAndOnlyThose) {
    // Unit quads facing +z along the camera's axis: four ahead (depth 5, 10, 15, 20), three behind
    // (z = 5, 10, 15), one far left at depth 5, and one at depth 5 whose right edge reaches 0.1 into
    // the view past its left edge (half width 5 · tan 20° · 16/9 = 3.235). Each quad is an object of
    // two triangles and so a cluster of its own.
    scene::Scene s = smallView(Vec3(0, 1, 0), Vec3(0, 1, -1));
    for (int i = 1; i <= 4; ++i) addQuad(s, Vec3(0, 1, -5.0 * i), Vec3(0, 0, 1), 1, 1);
    for (int i = 1; i <= 3; ++i) addQuad(s, Vec3(0, 1, 5.0 * i), Vec3(0, 0, 1), 1, 1);
    addQuad(s, Vec3(-20, 1, -5), Vec3(0, 0, 1), 1, 1);
    const double halfWidth = 5.0 * std::tan(20.0 * kPi / 180.0) * 16.0 / 9.0;
    addQuad(s, Vec3(-halfWidth - 0.4, 1, -5), Vec3(0, 0, 1), 1, 1);
    addDirectional(s, Vec3(-0.3, -1.0, -0.4));
    const scene::RasterSettings settings = validatedSettings(512, 0.01, 1.0, scene::ShadowFilter::Pcf2x2);
    EXPECT_EQ(expectSameFramesCulled(s, settings).culled, 2u * (4 + 1));
    // The edge quad shows: its sliver of 0.1 units is 0.1 / (2 · 3.235) · 160 ≈ 2.5 pixels wide.
    {
        Renderer culled(s, planFor(s, settings), settings);
        const scene::Frame f = culled.render(scene::kAllChannels);
        bool seen = false;
        for (float id : f.objectId) seen = seen || id == 9.0f;
        EXPECT_TRUE(seen) << "the quad at the view's left edge is not in the image";
    }
    // Turned around by update(): the three quads behind come into view, the others leave it.
    scene::Scene back = s;
    back.camera.lookAt = Vec3(0, 1, 1);
    Renderer culled(s, planFor(s, settings), settings),
        whole(s, planFor(s, settings), settings, RendererOptions{.viewCull = false});
    culled.update(back);
    whole.update(back);
    RenderDebug debug;
    const scene::Frame a = culled.render(scene::kAllChannels, &debug), b = whole.render(scene::kAllChannels);
    EXPECT_EQ(debug.litTriangles, 2u * 3);
    test::expectSamePixels(a, b, "view culling against none, after update()");
    EXPECT_EQ(culled.validationMessages(), 0);
}

// Random views of a finely tessellated ground with objects around: culled frames against unculled
// ones, bit for bit, through update() (views near the ground, looking in every direction, near
// planes cutting clusters).
TEST(ViewCull, RandomViewsThroughUpdateAreTheSameBitForBit) {
    scene::Scene s = smallView(Vec3(0, 2, 0), Vec3(0, 0.5, -6));
    s.camera.near = 0.5;
    s.camera.far = 30.0;
    addMesh(s, groundGrid(60, 20.0));
    addSphere(s, Vec3(0, 1, -6), 1.0);
    addSphere(s, Vec3(5, 0.5, 4), 0.5);
    addBox(s, Vec3(-1, 0, 3), Vec3(1, 3, 5));
    addBox(s, Vec3(-12, 0, -6), Vec3(-10, 2, -4));
    addBox(s, Vec3(8, 0, -9), Vec3(10, 4, -7));
    addDirectional(s, Vec3(-0.6, -0.5, -0.3));
    const scene::RasterSettings settings = validatedSettings(512, 0.01, 1.0, scene::ShadowFilter::Pcf2x2);
    Renderer culled(s, planFor(s, settings), settings),
        whole(s, planFor(s, settings), settings, RendererOptions{.viewCull = false});
    std::mt19937 rng(7);
    std::uniform_real_distribution<double> u(-1.0, 1.0);
    std::size_t sumCulled = 0, sumAll = 0;
    int compared = 0;
    for (int i = 0; i < 24; ++i) {
        scene::Scene v = s;
        v.camera.position = Vec3(12 * u(rng), 0.3 + 2.0 * (u(rng) + 1.0), 12 * u(rng));
        v.camera.lookAt = v.camera.position + Vec3(u(rng), 0.6 * u(rng) - 0.3, u(rng));
        v.camera.fovYDegrees = 30.0 + 30.0 * (u(rng) + 1.0);
        try {
            culled.update(v);
            whole.update(v);
        } catch (const std::exception&) {
            continue;  // a view whose plan needs other maps than the renderer was made with
        }
        for (int round = 0; round < 2; ++round) {
            RenderDebug a, b;
            const scene::Frame fa = culled.render(scene::kAllChannels, &a), fb = whole.render(scene::kAllChannels, &b);
            test::expectSamePixels(fa, fb, "random view " + std::to_string(i));
            sumCulled += a.litTriangles;
            sumAll += b.litTriangles;
        }
        ++compared;
    }
    EXPECT_GT(compared, 12);
    EXPECT_LT(sumCulled, sumAll);
    EXPECT_EQ(culled.validationMessages(), 0);
    EXPECT_EQ(whole.validationMessages(), 0);
}

}  // namespace
}  // namespace shadowlab::raster
