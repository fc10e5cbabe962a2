// tests/raster/shadow_layers_test.cpp: the shadow-layer plan (raster/shadow_layers.h) on its own,
// without a device: which layers a scene gets and why, their frusta, biases and casters.
#include "raster/shadow_layers.h"

#include <cmath>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "raster/cascades.h"
#include "raster/tolerances.h"
#include "tests/kit/test_scenes.h"

namespace shadowlab::raster {
namespace {

using test::fixedSettings;
using test::Vec3;

scene::Light pointLightAt(const Vec3& position) {
    scene::Light l;
    l.type = scene::LightType::Point;
    l.position = position;
    l.intensity = 30.0;
    return l;
}

TEST(ShadowLayers, ADirectionalLightHasOneMapWithTheShaderBiasAsGiven) {
    const scene::Scene s = test::makeScene({});
    const scene::RasterSettings r = fixedSettings();
    const std::vector<ShadowLayer> layers = planShadowLayers(s, test::planFor(s, r), r);
    ASSERT_EQ(layers.size(), 1u);
    const ShadowLayer& l = layers[0];
    EXPECT_EQ(l.light, 0);
    EXPECT_EQ(l.reason, LayerReason::kDirectional);
    EXPECT_EQ(l.label, "L0");
    EXPECT_FALSE(l.frustum.perspective);
    EXPECT_EQ(l.frustum.mapSize, 512);
    // The map looks along the light (straight down).
    EXPECT_NEAR(l.frustum.direction.y, -1.0, 1e-12);
    // A bias the user gave is kept as given, and the lit shader applies it.
    EXPECT_EQ(l.depthBias, 0.01);
    EXPECT_EQ(l.shaderDepthBias, 0.01);
    EXPECT_EQ(l.shaderSlopeBias, 1.5);
    EXPECT_FALSE(l.biasInDepthPass);
    EXPECT_EQ(l.hardwareBias.constant, 0.0f);
    EXPECT_EQ(l.hardwareBias.slope, 0.0f);
}

TEST(ShadowLayers, TheMatrixIsTheFrustumsClipTransformRelativeToTheCamera) {
    // Camera-relative: the matrix takes p − eye; the map's center maps to clip (0, 0).
    const scene::Scene s = test::makeScene({});
    const scene::RasterSettings r = fixedSettings();
    const ShadowLayer l = planShadowLayers(s, test::planFor(s, r), r).at(0);
    const Vec3 eye = scene::cameraBasis(s.camera).position;
    const glm::dvec4 c = glm::dmat4(l.matrix) * glm::dvec4(l.frustum.center - eye, 1.0);
    EXPECT_NEAR(c.x / c.w, 0.0, 1e-5);
    EXPECT_NEAR(c.y / c.w, 0.0, 1e-5);
}

TEST(ShadowLayers, ADefaultBiasOnAFittedMapIsHalfItsTexel) {
    const scene::Scene s = test::makeScene({});
    scene::RasterSettings r = fixedSettings();
    r.depthBiasIsDefault = true;
    r.fitLightFrustum = true;
    const ShadowLayer l = planShadowLayers(s, test::planFor(s, r), r).at(0);
    EXPECT_EQ(l.depthBias, 0.5 * l.frustum.texelWorldSize());
    EXPECT_EQ(l.shaderDepthBias, l.depthBias);
    // The bounding-sphere map keeps the setting.
    r.fitLightFrustum = false;
    EXPECT_EQ(planShadowLayers(s, test::planFor(s, r), r).at(0).depthBias, 0.01);
}

TEST(ShadowLayers, TheHardwareBiasMovesBothTermsIntoTheDepthPassInUnitsOfR) {
    // Orthographic depth is linear: a world bias b is b / depthRange of the 0..1 depth, and the
    // rasterizer's constant factor counts r = 2^-24 of it; the slope factor is the slope in texels.
    const scene::Scene s = test::makeScene({});
    scene::RasterSettings r = fixedSettings();
    r.hardwareBias = true;
    const ShadowLayer l = planShadowLayers(s, test::planFor(s, r), r).at(0);
    EXPECT_TRUE(l.biasInDepthPass);
    EXPECT_EQ(l.shaderDepthBias, 0.0);
    EXPECT_EQ(l.shaderSlopeBias, 0.0);
    EXPECT_FLOAT_EQ(l.hardwareBias.constant, float(0.01 / l.frustum.depthRange() * 16777216.0));
    EXPECT_FLOAT_EQ(l.hardwareBias.slope, 1.5f);
}

TEST(ShadowLayers, ASpotLightKeepsTheShaderBiasEvenWithTheHardwareBias) {
    scene::Scene s = test::makeScene({});
    s.lights[0] = test::spotDown();
    scene::RasterSettings r = fixedSettings();
    r.hardwareBias = true;
    const std::vector<ShadowLayer> layers = planShadowLayers(s, test::planFor(s, r), r);
    ASSERT_EQ(layers.size(), 1u);
    EXPECT_EQ(layers[0].reason, LayerReason::kSpot);
    EXPECT_TRUE(layers[0].frustum.perspective);
    EXPECT_FALSE(layers[0].biasInDepthPass);
    EXPECT_EQ(layers[0].shaderDepthBias, 0.01);
    EXPECT_EQ(layers[0].shaderSlopeBias, 1.5);
}

TEST(ShadowLayers, APointLightHasSixCubeFacesOfNinetyDegreesAlongTheAxes) {
    scene::Scene s = test::makeScene({});
    s.lights[0] = pointLightAt({0, 3, 0});
    scene::RasterSettings r = fixedSettings(512);
    r.fitLightFrustum = false;  // the faces' whole 90° (plus the margin), not a fitted window
    const std::vector<ShadowLayer> layers = planShadowLayers(s, test::planFor(s, r), r);
    ASSERT_EQ(layers.size(), 6u);
    const char* const names[] = {"L0 +X", "L0 -X", "L0 +Y", "L0 -Y", "L0 +Z", "L0 -Z"};
    const Vec3 axes[] = {{1, 0, 0}, {-1, 0, 0}, {0, 1, 0}, {0, -1, 0}, {0, 0, 1}, {0, 0, -1}};
    // The face's 90° edge is tan 1 at (size/2) texels from the center; the map asks for
    // kPointFaceMarginTexels more on each side: tan = size / (size − 2·margin).
    const double tanHalf = 512.0 / (512.0 - 2.0 * kPointFaceMarginTexels);
    for (int k = 0; k < 6; ++k) {
        const ShadowLayer& l = layers[std::size_t(k)];
        EXPECT_EQ(l.light, 0);
        EXPECT_EQ(l.reason, LayerReason::kCubeFace);
        EXPECT_EQ(l.index, k);
        EXPECT_EQ(l.label, names[k]);
        EXPECT_TRUE(l.frustum.perspective);
        EXPECT_NEAR(glm::dot(l.frustum.direction, axes[k]), 1.0, 1e-12) << names[k];
        EXPECT_NEAR(l.frustum.tanHalfFov, tanHalf, 1e-12) << names[k];
        EXPECT_NEAR(l.frustum.windowU, 0.0, 1e-12);
        EXPECT_NEAR(l.frustum.windowV, 0.0, 1e-12);
        EXPECT_EQ(l.frustum.position, Vec3(0, 3, 0));
        // A point light keeps the shader's bias.
        EXPECT_EQ(l.shaderDepthBias, 0.01);
        EXPECT_FALSE(l.biasInDepthPass);
    }
}

TEST(ShadowLayers, CascadeSplitsFollowThePracticalSplitScheme) {
    // C_i = λ n (f/n)^(i/N) + (1 − λ)(n + (f − n) i/N) over the depth range [n, f] of the visible
    // receivers some caster can shade (the plane shades itself here, so all of it counts).
    scene::Scene s = test::makeLongPlane(64, 36);
    test::makeGroundShadeItself(s, 0);
    scene::RasterSettings r = fixedSettings(1024);
    r.cascades = 3;
    const std::vector<ShadowLayer> layers = planShadowLayers(s, test::planFor(s, r), r);
    ASSERT_EQ(layers.size(), 3u);
    const auto range = shadowableDepthRange(s, s.lights[0].direction);
    ASSERT_TRUE(range.has_value());
    const double n = (*range)[0], f = (*range)[1];
    for (int c = 0; c < 3; ++c) {
        const ShadowLayer& l = layers[std::size_t(c)];
        EXPECT_EQ(l.reason, LayerReason::kCascade);
        EXPECT_EQ(l.index, c);
        EXPECT_EQ(l.count, 3);
        EXPECT_EQ(l.label, "L0 C" + std::to_string(c));
        const double lambda = kCascadeSplitLambda;
        const double d0 = lambda * n * std::pow(f / n, c / 3.0) + (1 - lambda) * (n + (f - n) * c / 3.0);
        const double d1 = lambda * n * std::pow(f / n, (c + 1) / 3.0) + (1 - lambda) * (n + (f - n) * (c + 1) / 3.0);
        EXPECT_NEAR(l.sliceNear, d0, 1e-9 * f) << "cascade " << c;
        EXPECT_NEAR(l.sliceFar, d1, 1e-9 * f) << "cascade " << c;
    }
    const std::vector<double> splits = cascadeSplits(layers);
    ASSERT_EQ(splits.size(), 4u);
    EXPECT_EQ(splits[0], layers[0].sliceNear);
    for (std::size_t c = 0; c < 3; ++c) EXPECT_EQ(splits[c + 1], layers[c].sliceFar);
    // Nearer slices are narrower, so their maps' texels are finer.
    const std::vector<double> texels = cascadeTexels(layers);
    ASSERT_EQ(texels.size(), 3u);
    EXPECT_LT(texels[0], texels[1]);
    EXPECT_LT(texels[1], texels[2]);
}

TEST(ShadowLayers, ACasterOutsideALayersFrustumIsCulledThere) {
    // A point light at (0, 3, 0) over the plane: a sphere far out along +X (x = 3.5, at the
    // light's height) lies in the +X face only; it cannot cast into −X, ±Y, ±Z faces, whose
    // receivers it cannot shade, and the −Y face (down onto the plane) draws the plane's caster,
    // the sphere at the center.
    scene::Scene s = test::makeScene({});
    s.lights[0] = pointLightAt({0, 3, 0});
    scene::Object far;
    far.name = "objects[2]";
    far.shape = scene::Sphere{{3.5, 3, 0}, 0.2};
    s.objects.push_back(far);
    scene::RasterSettings r = fixedSettings(256);
    r.cullCasters = true;
    const std::vector<ShadowLayer> layers = planShadowLayers(s, test::planFor(s, r), r);
    ASSERT_EQ(layers.size(), 6u);
    const ShadowLayer& minusX = layers[1];
    ASSERT_EQ(minusX.casters.size(), 3u);
    EXPECT_FALSE(minusX.casters[2]) << "the sphere at x = 3.5 is behind the -X face";
    const ShadowLayer& down = layers[3];
    ASSERT_EQ(down.casters.size(), 3u);
    EXPECT_TRUE(down.casters[0]) << "the center sphere shades the plane below the light";
    int culled = 0;
    for (const bool c : minusX.casters) culled += c ? 0 : 1;
    EXPECT_EQ(minusX.culled, culled);
    // Without culling every layer draws every object.
    r.cullCasters = false;
    for (const ShadowLayer& l : planShadowLayers(s, test::planFor(s, r), r)) {
        EXPECT_TRUE(l.casters.empty());
        EXPECT_EQ(l.culled, 0);
    }
}

// layerReadWindow() by hand. An orthographic map along −z (setBasis: right = +x, up = +y) centered
// on the origin, half-width 10, 1000 texels: texel x = 50·x + 500, y = 50·y + 500. Receivers
// (1, 2, 0) and (3, −1, 5) project to x 550..650, y 450..600; a reach of 10.5 and a normal offset
// of 2 texels widen that by 12.5: texels 537..662 and 437..612 inclusive.
ShadowLayer handLayer() {
    ShadowLayer l;
    setBasis(l.frustum, {0, 0, -1});
    l.frustum.center = {0, 0, 0};
    l.frustum.halfWidth = 10.0;
    l.frustum.nearDepth = -10.0;
    l.frustum.farDepth = 10.0;
    l.frustum.mapSize = 1000;
    l.casters = {true};
    l.receivers = {{1, 2, 0}, {3, -1, 5}};
    l.cullReachTexels = 10.5;
    l.cullOffsetTexels = 2.0;
    return l;
}

bool same(const TexelRect& a, const TexelRect& b) {
    return a.x0 == b.x0 && a.y0 == b.y0 && a.x1 == b.x1 && a.y1 == b.y1;
}

TEST(ShadowLayers, TheReadWindowIsTheReceiversProjectionWidenedByTheReachInTexels) {
    ASSERT_EQ(handLayer().frustum.right, Vec3(1, 0, 0));
    ASSERT_EQ(handLayer().frustum.up, Vec3(0, 1, 0));
    const TexelRect w = layerReadWindow(handLayer());
    EXPECT_TRUE(same(w, TexelRect{537, 437, 663, 613})) << w.x0 << " " << w.y0 << " " << w.x1 << " " << w.y1;
    EXPECT_EQ(w.area(), 126u * 176u);
    // Clamped to the map: a receiver at x = 9.9 (texel 995) reaches past its edge.
    ShadowLayer edge = handLayer();
    edge.receivers.push_back({9.9, 0, 0});
    EXPECT_EQ(layerReadWindow(edge).x1, 1000u);
    EXPECT_EQ(layerReadWindow(edge).x0, 537u);
}

// A perspective map at the origin looking down −z (right = +x, up = +y: u = x/d, v = y/d with
// d = −z), tan 1, 1000 texels: texel x = 500·(u + 1), a texel 0.002 of tangent. Receivers
// (1, 2, −10) and (3, −1, −5): u 0.1..0.6, v −0.2..0.2. A reach of 10.3 texels, the slope bias's
// lifted texel in it counted as a normal offset (2·√(1 + t²) = 2√2 texels at t = 1): 9.3 + 2√2
// = 12.1284 texels, 0.024257 of tangent: texels 537.87..812.13 and 387.87..612.13, so 537..812 and
// 387..612 inclusive.
ShadowLayer handSpotLayer() {
    ShadowLayer l;
    l.frustum.perspective = true;
    setBasis(l.frustum, {0, 0, -1});
    l.frustum.position = {0, 0, 0};
    l.frustum.tanHalfFov = 1.0;
    l.frustum.mapSize = 1000;
    l.frustum.near = 0.1;
    l.frustum.far = 100.0;
    l.casters = {true};
    l.receivers = {{1, 2, -10}, {3, -1, -5}};
    l.cullReachTexels = 10.3;
    return l;
}

TEST(ShadowLayers, APerspectiveMapsReadWindowIsTheReceiversTangentsWidenedByTheReach) {
    const TexelRect w = layerReadWindow(handSpotLayer());
    EXPECT_TRUE(same(w, TexelRect{537, 387, 813, 613})) << w.x0 << " " << w.y0 << " " << w.x1 << " " << w.y1;
    // No receiver in front of the light: nothing reads the map, nothing is drawn.
    ShadowLayer behind = handSpotLayer();
    behind.receivers = {{1, 2, 10}, {3, -1, 5}};
    EXPECT_TRUE(layerReadWindow(behind).empty());
    // Receivers across the light's plane: unbounded toward the side the crossing lies on (here
    // x > 0 at the crossing: to the map's right edge).
    ShadowLayer across = handSpotLayer();
    across.receivers = {{1, 0, -10}, {3, 0, 5}};
    EXPECT_EQ(layerReadWindow(across).x1, 1000u);
    EXPECT_EQ(layerReadWindow(across).x0, 537u);
}

TEST(ShadowLayers, AFilterableMapsDepthPassDrawsTheLookupsTexelsWidenedByTheBlurRadius) {
    // handLayer()'s receivers with a blur radius of 3 counted in the reach (13.5): the lookups read
    // what the reach of 10.5 gives (texels 537..662 x 437..612), the moments there blur depths up
    // to 3 texels further (534..665 x 434..615).
    ShadowLayer l = handLayer();
    l.blurRadius = 3;
    l.cullReachTexels = 13.5;
    EXPECT_TRUE(same(layerLookupWindow(l), layerReadWindow(handLayer())));
    const TexelRect w = layerReadWindow(l);
    EXPECT_TRUE(same(w, TexelRect{534, 434, 666, 616})) << w.x0 << " " << w.y0 << " " << w.x1 << " " << w.y1;
    // Within the map: a receiver at x = −9.95 (texel 2.5) reads from texel 0, whose moments blur
    // texels 0..3 (the blur clamps to the map, not past it).
    l.receivers.push_back({-9.95, 0, 0});
    EXPECT_EQ(layerLookupWindow(l).x0, 0u);
    EXPECT_EQ(layerReadWindow(l).x0, 0u);
    EXPECT_EQ(layerReadWindow(l).x1, 666u);
    // No receivers: the whole map, whatever the radius.
    l.receivers.clear();
    EXPECT_TRUE(same(layerReadWindow(l), TexelRect{0, 0, 1000, 1000}));
    EXPECT_TRUE(same(layerLookupWindow(l), TexelRect{0, 0, 1000, 1000}));
}

TEST(ShadowLayers, GrownWithinWidensEachAxisByItsOwnAmountInsideTheMap) {
    const TexelRect w = grownWithin(TexelRect{2, 10, 50, 60}, 5, 1, 70);
    EXPECT_TRUE(same(w, TexelRect{0, 9, 55, 61})) << w.x0 << " " << w.y0 << " " << w.x1 << " " << w.y1;
    EXPECT_TRUE(grownWithin(TexelRect{}, 5, 5, 70).empty());
    EXPECT_EQ(grownWithin(TexelRect{60, 0, 68, 4}, 5, 5, 70).x1, 70u);  // clamped on the far side
}

TEST(ShadowLayers, TheReadWindowIsTheWholeMapWhereNothingBoundsTheReads) {
    const TexelRect whole{0, 0, 1000, 1000};
    // Culling off, or the camera sees none of the scene: no receivers recorded.
    ShadowLayer noReceivers = handLayer();
    noReceivers.receivers.clear();
    EXPECT_TRUE(same(layerReadWindow(noReceivers), whole));
    // A layer that culls no caster (a transmittance map) still has its window.
    ShadowLayer everyCaster = handLayer();
    everyCaster.casters.clear();
    EXPECT_TRUE(same(layerReadWindow(everyCaster), layerReadWindow(handLayer())));
    // A normal offset of 60 texels of 0.002 turns a perspective lookup by more than a tenth: not bounded.
    ShadowLayer turned = handSpotLayer();
    turned.cullOffsetTexels = 60.0;
    EXPECT_TRUE(same(layerReadWindow(turned), whole));
}

TEST(ShadowLayers, ALightThePlanGivesNoShadowTestHasNoLayer) {
    scene::Scene s = test::makeScene({});
    const scene::RasterSettings r = fixedSettings();
    scene::RenderPlan plan = test::planFor(s, r);
    ASSERT_FALSE(plan.lights.empty());
    plan.lights[0].needsShadowTest = false;
    EXPECT_TRUE(planShadowLayers(s, plan, r).empty());
    EXPECT_EQ(explainShadowLayers({}, s.objects.size()),
              "raster shadow-map layers: none (no light needs a shadow test)\n");
}

TEST(ShadowLayers, LayersOfTwoLightsFollowTheLightOrder) {
    scene::Scene s = test::makeScene({});
    s.lights.push_back(pointLightAt({0, 3, 0}));
    s.lights.push_back(test::spotDown());
    const scene::RasterSettings r = fixedSettings();
    const std::vector<ShadowLayer> layers = planShadowLayers(s, test::planFor(s, r), r);
    ASSERT_EQ(layers.size(), 1u + 6u + 1u);
    EXPECT_EQ(layers[0].label, "L0");
    EXPECT_EQ(layers[1].label, "L1 +X");
    EXPECT_EQ(layers[6].label, "L1 -Z");
    EXPECT_EQ(layers[7].label, "L2");
    EXPECT_EQ(layers[7].light, 2);
}

}  // namespace
}  // namespace shadowlab::raster
