// tests/raster/lift_free_test.cpp: which triangles the lit pass draws without the slope bias's lift
// past its cap (raster/lift_free.h), and that drawing them so changes no frame.
#include "raster/lift_free.h"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <random>
#include <tuple>
#include <vector>

#include <gtest/gtest.h>
#include <glm/geometric.hpp>

#include "raster/renderer.h"
#include "raster/tolerances.h"
#include "tests/kit/render_checked.h"
#include "tests/kit/test_scenes.h"

namespace shadowlab::raster {
namespace {

using namespace test;
using scene::ShadowFilter;

// Unit vector at angle `degrees` from +y toward +x: N·L = cos(degrees) against the light (0, 1, 0).
glm::vec3 tilted(double degrees) {
    const double a = degrees * kPi / 180.0;
    return glm::vec3(float(std::sin(a)), float(std::cos(a)), 0.0f);
}
const std::vector<glm::vec3> kUp = {glm::vec3(0, 1, 0)};
const std::uint32_t kOtherLights = ~3u;  // the bits of lights that are not there, always set

// A range as (first index, index count, lift-free), to compare whole splits at once.
using LiftRun = std::tuple<std::uint32_t, std::uint32_t, bool>;
std::vector<LiftRun> runs(const std::vector<IndexRange>& ranges) {
    std::vector<LiftRun> out;
    for (const IndexRange& r : ranges) out.emplace_back(r.first, r.count, r.liftFree);
    return out;
}

TEST(LiftFree, TheThresholdIsTheCapsCosinePlusTheMargin) {
    // tan θ = 10 ⇔ cos θ = 1/√101 = 0.0995.
    EXPECT_DOUBLE_EQ(liftFreeThreshold(10.0), 1.0 / std::sqrt(101.0) + kLiftFreeMargin);
    EXPECT_NEAR(liftFreeThreshold(kMaxSlopeTan), 0.0995 + kLiftFreeMargin, 1e-4);
}

TEST(LiftFree, VertexBitsSayOnWhichSideOfTheThresholdEachNormalLies) {
    const double t = liftFreeThreshold(kMaxSlopeTan);  // 0.1495: θ = 81.4°
    const std::vector<glm::vec3> normals = {tilted(0),       tilted(80),        tilted(83),
                                            tilted(97),      tilted(100),       tilted(180),
                                            glm::vec3(0.0f), 2.0f * tilted(60), glm::vec3(NAN, 1.0f, 0.0f)};
    const std::vector<std::uint32_t> bits = liftFreeVertexBits(normals, kUp, t);
    EXPECT_EQ(bits[0], kOtherLights | 1u);  // N·L = 1
    EXPECT_EQ(bits[1], kOtherLights | 1u);  // cos 80° = 0.174
    EXPECT_EQ(bits[2], kOtherLights);       // cos 83° = 0.122: past the cap, within the margin
    EXPECT_EQ(bits[3], kOtherLights);       // −0.122
    EXPECT_EQ(bits[4], kOtherLights | 2u);  // −0.174
    EXPECT_EQ(bits[5], kOtherLights | 2u);  // −1
    EXPECT_EQ(bits[6], kOtherLights);       // no normal
    EXPECT_EQ(bits[7], kOtherLights | 1u);  // |N| = 2: N·L/|N| = cos 60°
    EXPECT_EQ(bits[8], kOtherLights);       // not finite
}

// Triangle k of `normals` taken three at a time, each of weight 1, one range of every index.
std::vector<IndexRange> split(const std::vector<glm::vec3>& normals, const std::vector<glm::vec3>& lights,
                              double minTriangles, const std::vector<IndexRange>& ranges = {}) {
    std::vector<std::uint32_t> indices(normals.size());
    for (std::uint32_t i = 0; i < indices.size(); ++i) indices[i] = i;
    const std::vector<std::uint32_t> bits = liftFreeVertexBits(normals, lights, liftFreeThreshold(kMaxSlopeTan));
    const std::vector<float> weights(indices.size() / 3, 1.0f);
    return splitByLift(bits, indices, ranges, weights, minTriangles);
}

TEST(LiftFree, ATriangleIsLiftFreeWhenItsVerticesAllLieOnOneSideForEveryLight) {
    const glm::vec3 lit = tilted(30), grazing = tilted(85), away = tilted(150);
    // Triangles: all lit; one vertex grazing; all facing away (lit when two-sided shading turns
    // them); lit and away mixed (the interpolated normal turns through grazing between them).
    const std::vector<glm::vec3> normals = {lit, lit, lit, lit, lit, grazing, away, away, away, lit, lit, away};
    const std::vector<IndexRange> r = split(normals, kUp, 1);
    EXPECT_EQ(runs(r), (std::vector<LiftRun>{{0, 3, true}, {3, 3, false}, {6, 3, true}, {9, 3, false}}));
    // A second light at right angles to the first triangle's normals (30° from +y toward +x; the
    // light 60° from +y toward −x) takes it out: lift-free means lift-free for every light.
    const std::vector<glm::vec3> two = {glm::vec3(0, 1, 0), tilted(-60)};
    const std::vector<IndexRange> r2 = split(normals, two, 1);
    ASSERT_FALSE(r2.empty());
    EXPECT_FALSE(r2[0].liftFree);
    EXPECT_EQ(r2[0].count, 6u);  // the first two triangles, merged
}

TEST(LiftFree, PixelAreasAreTheTrianglesOnTheImage) {
    // An orthographic viewProj that maps x, y in [0, 4] onto NDC [−1, 1]: a 64 x 32 image, so one
    // world unit is 16 x 8 pixels. The triangle (0,0) (2,0) (0,1) covers 1 unit², 128 pixels; one
    // with w = 0 counts as the whole image.
    glm::mat4 m(1.0f);
    m[0][0] = m[1][1] = 0.5f;
    m[3][0] = m[3][1] = -1.0f;
    const std::vector<glm::vec3> p = {{0, 0, 0}, {2, 0, 0}, {0, 1, 0}};
    const std::vector<std::uint32_t> indices = {0, 1, 2, 2, 1, 0};
    const std::vector<float> a = pixelAreas(p, indices, m, 64, 32);
    ASSERT_EQ(a.size(), 2u);
    EXPECT_FLOAT_EQ(a[0], 128.0f);
    EXPECT_FLOAT_EQ(a[1], 128.0f);
    m[3][3] = 0.0f;  // w = 0
    EXPECT_FLOAT_EQ(pixelAreas(p, indices, m, 64, 32)[0], 64.0f * 32.0f);
}

TEST(LiftFree, ShortRunsStayWithTheLiftAndAlphaRangesAreNeverLiftFree) {
    const glm::vec3 lit = tilted(0), grazing = tilted(89);
    std::vector<glm::vec3> normals;
    auto add = [&](int triangles, glm::vec3 n) { normals.insert(normals.end(), std::size_t(3 * triangles), n); };
    add(4, lit);      // triangles 0..3: a run of 4
    add(1, grazing);  // 4
    add(2, lit);      // 5..6: a run of 2, too short for minTriangles 3
    add(1, grazing);  // 7
    add(3, lit);      // 8..10: a run of 3
    const std::vector<IndexRange> r = split(normals, kUp, 3);
    ASSERT_EQ(r.size(), 3u);
    EXPECT_TRUE(r[0].liftFree);
    EXPECT_EQ(r[0].count, 12u);
    EXPECT_FALSE(r[1].liftFree);
    EXPECT_EQ(r[1].first, 12u);
    EXPECT_EQ(r[1].count, 12u);  // triangles 4..7
    EXPECT_TRUE(r[2].liftFree);
    EXPECT_EQ(r[2].first, 24u);
    EXPECT_EQ(r[2].count, 9u);
    // The same indices as two ranges, the second alpha-tested: it is drawn whole with the lift.
    const std::vector<IndexRange> ranges = {{0, 21, false}, {21, 12, true}};
    const std::vector<IndexRange> ra = split(normals, kUp, 3, ranges);
    ASSERT_EQ(ra.size(), 3u);
    EXPECT_TRUE(ra[0].liftFree);
    EXPECT_EQ(ra[0].count, 12u);
    EXPECT_FALSE(ra[1].liftFree);
    EXPECT_FALSE(ra[1].alpha);
    EXPECT_EQ(ra[1].count, 9u);
    EXPECT_TRUE(ra[2].alpha);
    EXPECT_FALSE(ra[2].liftFree);
    EXPECT_EQ(ra[2].first, 21u);
    EXPECT_EQ(ra[2].count, 12u);
}

// The argument of raster/lift_free.cpp checked in the shader's arithmetic: random triangles whose
// vertex normals (random lengths) all pass the threshold, at random points inside (barycentric
// weights), the normalized interpolated normal, in float as lit.frag forms it, has N·L past the cap,
// and lit.frag's lift factor max(sin θ − maxTan·cos θ, 0) is exactly 0 there, also negated (the
// two-sided turn) where N·L > 0 only after the turn.
TEST(LiftFree, NoPointOfALiftFreeTriangleTakesTheLift) {
    std::mt19937 rng(7);
    std::uniform_real_distribution<float> u(-1.0f, 1.0f), len(0.5f, 2.0f), w(0.0f, 1.0f);
    const glm::vec3 l = glm::normalize(glm::vec3(0.3f, 0.9f, -0.2f));
    const float maxTan = float(kMaxSlopeTan);
    const double t = liftFreeThreshold(kMaxSlopeTan);
    int triangles = 0;
    while (triangles < 2000) {
        glm::vec3 n[3];
        for (glm::vec3& v : n) v = len(rng) * glm::normalize(glm::vec3(u(rng), u(rng), u(rng)));
        const std::vector<glm::vec3> normals(std::begin(n), std::end(n));
        const std::vector<IndexRange> r = split(normals, {l}, 1);
        if (r.size() != 1 || !r[0].liftFree) continue;
        ++triangles;
        for (int k = 0; k < 50; ++k) {
            float b0 = w(rng), b1 = w(rng);
            if (b0 + b1 > 1.0f) b0 = 1.0f - b0, b1 = 1.0f - b1;
            const glm::vec3 m = glm::normalize(b0 * n[0] + b1 * n[1] + (1.0f - b0 - b1) * n[2]);
            for (const float side : {1.0f, -1.0f}) {
                const float ndotl = glm::dot(side * m, l);
                if (!(ndotl > 0.0f)) continue;
                EXPECT_GE(double(ndotl), t - 1e-6);
                const float sinTheta = std::sqrt(std::max(1.0f - ndotl * ndotl, 0.0f));
                EXPECT_EQ(std::max(sinTheta - maxTan * ndotl, 0.0f), 0.0f);
            }
        }
    }
}

// Frames with lift-free draws (each kind's second frame: the first makes the pipelines and draws
// every triangle with the lift) against a Renderer without them, every channel of the all-channel,
// float-beauty and display frames bit for bit; `expectSplit`: some triangles were drawn without the
// lift (only with the *_sun modules).
void expectSameFrames(const scene::Scene& s, const scene::RasterSettings& settings, bool expectSplit,
                      const RendererOptions& options = {}) {
    Renderer split(s, planFor(s, settings), settings, options);
    Renderer whole(s, planFor(s, settings), settings, RendererOptions{.liftFreeDraws = false});
    const scene::ChannelMask kinds[] = {scene::kAllChannels, scene::kChannelBeauty,
                                        scene::kChannelBeauty | scene::kBeautyForDisplay};
    for (const scene::ChannelMask channels : kinds) {
        RenderDebug first;
        split.render(channels, &first);
        EXPECT_EQ(first.liftFreeTriangles, 0u);
    }
    for (const scene::ChannelMask channels : kinds) {
        RenderDebug debug;
        const scene::Frame a = split.render(channels, &debug), b = whole.render(channels);
        EXPECT_EQ(debug.liftFreeTriangles > 0, expectSplit);
        test::expectSamePixels(a, b, "lift-free draws against none");
    }
    EXPECT_EQ(split.validationMessages(), 0);
    EXPECT_EQ(whole.validationMessages(), 0);
}

TEST(LiftFree, LiftFreeDrawsGiveTheSameFramesBitForBit) {
    // A light 40° from the vertical: the plane and the lit side of the sphere are lift-free, the
    // sphere's terminator is not; its shadow falls on the lift-free plane.
    SphereOverPlane oblique;
    oblique.lightDirection = Vec3(-std::sin(0.7), -std::cos(0.7), -0.2);
    const scene::RasterSettings pcf = validatedSettings(512, 0.01, 1.0, ShadowFilter::Pcf2x2);
    expectSameFrames(makeScene(oblique), pcf, true);
    expectSameFrames(makeScene(oblique), validatedSettings(512, 0.01, 1.0, ShadowFilter::None), true);
    // The general lit modules (a pipeline there takes about 46 ms of CPU to make): no lift-free draws.
    expectSameFrames(makeScene(oblique), validatedSettings(512, 0.01, 1.0, ShadowFilter::Pcf), false);
    scene::RasterSettings plane = pcf;
    plane.receiverPlaneBias = true;
    expectSameFrames(makeScene(oblique), plane, false);
    expectSameFrames(makeScene(oblique), pcf, false, RendererOptions{.oneLightModules = false});
    // Cascades with blend bands (*_sun modules).
    scene::Scene cascaded = makeLongPlane();
    scene::RasterSettings cascades = validatedSettings(512, 0.0, 1.0, ShadowFilter::Pcf2x2);
    cascades.depthBias = scene::defaultDepthBias(cascaded, 512);
    cascades.cascades = 3;
    cascades.cascadeBlend = 0.3;
    expectSameFrames(cascaded, cascades, true);
    // Two directional lights: the general modules.
    scene::Scene two = makeScene(oblique);
    addDirectional(two, Vec3(0.5, -1.0, 0.3), 1.0);
    expectSameFrames(two, pcf, false);
    // An alpha-tested leaf over the plane: its range keeps the alpha pipeline with the lift.
    scene::Scene leaf = makeScene(oblique);
    leaf.materials.push_back(alphaMaterial("leaf", scene::AlphaMode::Mask, checkerTexture(2, 1.0f, 0.0f)));
    addQuad(leaf, Vec3(0, 2, 0), Vec3(0, 1, 0), 1, 1, 1);
    expectSameFrames(leaf, pcf, true);
    // A normal offset asked for: every triangle takes the offset path, none is split off.
    scene::RasterSettings offset = pcf;
    offset.normalOffset = 1.0;
    expectSameFrames(makeScene(oblique), offset, false);
}

}  // namespace
}  // namespace shadowlab::raster
