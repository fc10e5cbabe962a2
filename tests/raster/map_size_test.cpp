// tests/raster/map_size_test.cpp: the shadow-map size from the receivers' detail
// (raster::chooseShadowMapSize): a small render of the seed scene gets a smaller map with the same
// shadow classification against the double-precision reference; a forced size is kept.
#include <cmath>

#include <gtest/gtest.h>

#include "compare/compare.h"
#include "raster/renderer.h"
#include "scene/render_plan.h"
#include "tests/kit/render_checked.h"
#include "tests/kit/test_scenes.h"

namespace shadowlab::raster {
namespace {

using test::kPi;
using test::loadSeed;

scene::Frame rasterRender(const scene::Scene& s, const scene::SettingsOverrides& o) {
    return test::renderChecked(s, scene::resolveSettings(s, o));
}

// The widths of the seed's maps. Bounding sphere (not fitted): of the ±10 x 0..2 x ±10 box, 1.01
// margin, 1.01·√804. Fitted: the only receivers a caster can shade are the ground under the sphere's
// sweep, [−2, 1] x {0} x [−2, 1] (the sphere's box swept along (−1, −2, −1) to the ground), all of it
// in view. Across the light (right = (1, 0, −1)/√2, up = (−1, 1, −1)/√3) it spans 6/√2 by 6/√3, so
// the half-width is 0.5·(6/√2)·1.01·256/255 = 2.151 (chooseShadowMapSize fits at 256), rounded up
// to 1/16 of 2: 2.25, a width of 4.5.
const double kSphereMapWidth = 1.01 * std::sqrt(804.0);
const double kFittedMapWidth = 4.5;

// The size the seed scene's receivers need at `height` rows for a map `width` wide, worked out from
// its numbers: camera at (0, 2, 6) looking at (0, 0.7, 0), fov 40°. The nearest visible receiver is
// where the image's bottom edge meets the ground y = 0: that ray is 20° + atan(1.3/6) below the
// horizon, hits the ground 2/sin(that) away, at view depth (distance)·cos 20°. A pixel there is
// 2·tan 20°·z/height wide.
double neededTexels(int height, double width = kFittedMapWidth) {
    const double below = (20.0 * kPi / 180.0) + std::atan(1.3 / 6.0);
    const double z = 2.0 / std::sin(below) * std::cos(20.0 * kPi / 180.0);
    const double pixel = 2.0 * std::tan(20.0 * kPi / 180.0) * z / height;
    return width / pixel;
}
int expectedSize(int height) {
    int size = 256;
    while (size < neededTexels(height) && size < 2048) size *= 2;
    return size;
}

TEST(RasterMapSize, ASmallRenderGetsASmallerMapWithTheSameShadows) {
    ASSERT_EQ(expectedSize(36), 256);  // 4.5 / 0.0713 ≈ 63 texels, the sphere's feature asks 4·4.5/2 = 9
    const scene::Scene s = loadSeed(64, 36);
    scene::Frame automatic = rasterRender(s, {});
    EXPECT_EQ(automatic.attributes["shadow_map_size"], "256");
    EXPECT_NE(automatic.attributes["shadow_map_size_reason"].find("receiver detail"), std::string::npos);
    // The receivers ask for what the fitted map's width over the nearest pixel gives; 256 is the least.
    // (The Frame records it rounded up to a whole texel.)
    EXPECT_NEAR(std::stod(automatic.attributes["shadow_map_size_needed"]), neededTexels(36), 1.0);
    scene::SettingsOverrides forced;
    forced.shadowMapSize = 2048;
    scene::Frame full = rasterRender(s, forced);
    EXPECT_EQ(full.attributes["shadow_map_size"], "2048");
    EXPECT_NE(full.attributes["shadow_map_size_reason"].find("set by"), std::string::npos);
    EXPECT_EQ(full.attributes.count("shadow_map_size_needed"), 0u);

    const scene::Frame ref = test::renderReference(s);
    const compare::Metrics a = compare::compareFrames(automatic, ref).metrics;
    const compare::Metrics b = compare::compareFrames(full, ref).metrics;
    std::printf("counted %zu, reference shadowed %zu; wrong: auto %zu, 2048 %zu\n", a.counted, a.shadowedReference,
                a.falseShadow + a.missedShadow, b.falseShadow + b.missedShadow);
    ASSERT_GT(a.shadowedReference, 25u);  // 38 at 64x36: the sphere's shadow is ~3% of the image
    // The same classification within a small tolerance: at most 1% of the counted pixels more wrong.
    EXPECT_LE(a.falseShadow + a.missedShadow, b.falseShadow + b.missedShadow + a.counted / 100);
}

TEST(RasterMapSize, AFullSizeRenderKeepsTheDefault) {
    // At 720 rows the receivers need ≈ 1260 texels of the fitted map: rounded up to the default.
    EXPECT_EQ(expectedSize(720), 2048);
    const scene::Scene s = loadSeed(1280, 720);
    const ShadowMapSizeChoice c = chooseShadowMapSize(s, scene::resolveSettings(s, {}).raster);
    EXPECT_EQ(c.size, 2048);
}

TEST(RasterMapSize, TheTexelsAskedForAreRecordedAndTheCapIsNamedOnlyWhenTheyExceedIt) {
    // The bounding-sphere map (not fitted, so its width is 1.01·√804 as above). The sphere
    // (diameter 2) asks for 4 texels across it, 4·28.6/2 = 57: the receivers decide. At 36 rows
    // they ask for ≈ 402 texels, rounded up to 512; at 360 rows for ≈ 4000, more than the
    // default 2048, which caps it.
    scene::SettingsOverrides unfitted;
    unfitted.fitLightFrustum = false;
    const scene::Scene small = loadSeed(64, 36);
    const ShadowMapSizeChoice a = chooseShadowMapSize(small, scene::resolveSettings(small, unfitted).raster);
    EXPECT_EQ(a.size, 512);
    EXPECT_NEAR(a.needed, neededTexels(36, kSphereMapWidth), 0.01 * neededTexels(36, kSphereMapWidth));
    EXPECT_EQ(a.reason.find("capped"), std::string::npos) << a.reason;
    EXPECT_NE(a.reason.find("rounded up to a power of two"), std::string::npos) << a.reason;
    const scene::Scene large = loadSeed(640, 360);
    scene::RenderSettings settings = scene::resolveSettings(large, unfitted);
    settings.raster.cascades = 1;  // one map, so the size follows the receivers
    const ShadowMapSizeChoice b = chooseShadowMapSize(large, settings.raster);
    ASSERT_GT(neededTexels(360, kSphereMapWidth), 2048.0);
    EXPECT_EQ(b.size, 2048);
    EXPECT_NEAR(b.needed, neededTexels(360, kSphereMapWidth), 0.01 * neededTexels(360, kSphereMapWidth));
    EXPECT_NE(b.reason.find("capped at the default"), std::string::npos) << b.reason;
    // A forced size asks for nothing.
    scene::SettingsOverrides forced = unfitted;
    forced.shadowMapSize = 1024;
    EXPECT_EQ(chooseShadowMapSize(small, scene::resolveSettings(small, forced).raster).needed, 0.0);
}

TEST(RasterMapSize, ASizeFromTheSceneIsKept) {
    scene::Scene s = loadSeed(64, 36);
    s.shadow.shadowMapSize = 2048;
    EXPECT_EQ(chooseShadowMapSize(s, scene::resolveSettings(s, {}).raster).size, 2048);
    s.shadow.shadowMapSize.reset();
    EXPECT_EQ(chooseShadowMapSize(s, scene::resolveSettings(s, {}).raster).size, expectedSize(36));
}

TEST(RasterMapSize, OnlyLightsWithAShadowPassAskForTexels) {
    // The seed at 64x36 needs 256 for its directional light (above). A point light 500 above the
    // scene asks for far more: its texels are 2/(N − 24) per unit of axial distance (~500) and a
    // pixel at view depth ~6 is 6·2·tan 20°/36 = 0.12, so N ≈ 2·500/0.12 ≫ 2048, capped at the
    // default. When the plan gives that light no shadow pass, it asks for nothing.
    scene::Scene s = loadSeed(64, 36);
    scene::Light point;
    point.type = scene::LightType::Point;
    point.position = scene::Vec3(0, 500, 0);
    s.lights.push_back(point);
    const scene::RasterSettings settings = scene::resolveSettings(s, {}).raster;
    scene::RenderPlan plan = scene::makeRenderPlan(s, scene::resolveSettings(s, {}));
    ASSERT_TRUE(plan.lights[1].needsShadowTest);
    const int withPoint = chooseShadowMapSize(s, settings, &plan).size;
    EXPECT_EQ(withPoint, 2048);
    EXPECT_EQ(chooseShadowMapSize(s, settings).size, withPoint);  // no plan: every light counts
    plan.lights[1].needsShadowTest = false;
    EXPECT_EQ(chooseShadowMapSize(s, settings, &plan).size, expectedSize(36));
}

}  // namespace
}  // namespace shadowlab::raster
