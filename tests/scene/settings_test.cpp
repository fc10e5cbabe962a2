// tests/scene/settings_test.cpp: command line over the scene's "shadow" block over defaults,
// scene-scaled defaults, and clear errors for bad values.
#include "scene/settings.h"

#include <cmath>

#include <gtest/gtest.h>

#include "scene/error.h"

namespace shadowlab::scene {
namespace {

Scene unitScene(double scale) {
    Scene s;
    s.materials.push_back({"m"});
    s.objects.push_back({"ball", Sphere{{0, scale, 0}, scale}, 0});
    return s;
}

TEST(Settings, DefaultRayBiasScalesWithTheScene) {
    // Bounds of a sphere of radius r: a cube of side 2r, diagonal 2r·sqrt(3).
    const double small = defaultRayBias(unitScene(1e-3));
    const double large = defaultRayBias(unitScene(1e4));
    EXPECT_NEAR(small, 1e-4 * 2e-3 * std::sqrt(3.0), 1e-12);
    EXPECT_NEAR(large / small, 1e7, 1e-3);
}

TEST(Settings, DefaultRayBiasCoversFloatRoundingFarFromTheOrigin) {
    Scene s = unitScene(1.0);
    std::get<Sphere>(s.objects[0].shape).center = {1e7, 0, 0};
    // A unit sphere 1e7 away: float spacing there is 1e7·2^-23 ≈ 1.19, far above 1e-4·extent.
    EXPECT_GT(defaultRayBias(s), 1e7 * 1.1920929e-7);
}

TEST(Settings, TheDefaultRayBiasIsHalfAPixelsFootprintCappedByTheScenesAndFloored) {
    Scene s = unitScene(1.0);
    RenderSettings r = resolveSettings(s, {});
    EXPECT_EQ(r.raytrace.rayBias, defaultRayBias(s));  // the cap
    EXPECT_EQ(r.raytrace.rayBiasPixels, 0.5);
    EXPECT_EQ(r.raytrace.rayBiasFloor, 16.0 * 1.1920929e-7 * 2.0);  // the sphere's top is at y = 2
    // A 90° field over 100 rows: one pixel spans 2·z·tan 45° / 100 = z / 50 at view depth z.
    RaytraceSettings t;
    t.rayBias = 0.05;
    t.rayBiasFloor = 0.001;
    t.rayBiasPixels = 0.5;
    EXPECT_NEAR(rayBiasAt(t, 2.0, 90.0, 100), 0.02, 1e-15);  // half of 2/50
    EXPECT_EQ(rayBiasAt(t, 20.0, 90.0, 100), 0.05);          // the cap
    EXPECT_EQ(rayBiasAt(t, 0.01, 90.0, 100), 0.001);         // the floor
    EXPECT_EQ(rayBiasAt(t, std::nan(""), 90.0, 100), 0.05);  // no depth: the cap
    t.rayBiasPixels = 0.0;
    EXPECT_EQ(rayBiasAt(t, 2.0, 90.0, 100), 0.05);  // a bias given by the user holds everywhere
    // Given on the command line or in the scene, the bias is the user's, not view-scaled.
    SettingsOverrides o;
    o.rayBias = "0.01";
    EXPECT_EQ(resolveSettings(s, o).raytrace.rayBiasPixels, 0.0);
    s.shadow.rayBias = 0.02;
    r = resolveSettings(s, {});
    EXPECT_EQ(r.raytrace.rayBias, 0.02);
    EXPECT_EQ(r.raytrace.rayBiasPixels, 0.0);
}

TEST(Settings, CommandLineBeatsTheSceneWhichBeatsTheDefault) {
    Scene s = unitScene(1.0);
    s.shadow.shadowMapSize = 512;
    s.shadow.filter = "none";
    SettingsOverrides o;
    RenderSettings r = resolveSettings(s, o);
    EXPECT_EQ(r.raster.shadowMapSize, 512);
    EXPECT_EQ(r.raster.filter, ShadowFilter::None);
    EXPECT_NEAR(r.raster.depthBias, 0.5 * 2 * std::sqrt(3.0) / 512, 1e-15);  // half a texel
    o.shadowMapSize = 1024;
    o.rayBias = "robust";
    r = resolveSettings(s, o);
    EXPECT_EQ(r.raster.shadowMapSize, 1024);
    EXPECT_TRUE(r.raytrace.robustOffset);
}

TEST(Settings, CascadesComeFromTheCommandLineThenTheSceneThenOne) {
    Scene s = unitScene(1.0);
    EXPECT_EQ(resolveSettings(s, {}).raster.cascades, 1);
    s.shadow.cascades = 3;
    EXPECT_EQ(resolveSettings(s, {}).raster.cascades, 3);
    SettingsOverrides o;
    o.cascades = 2;
    EXPECT_EQ(resolveSettings(s, o).raster.cascades, 2);
}

TEST(Settings, LightFrustumFittingIsOnUnlessTheCommandLineOrTheSceneTurnItOff) {
    Scene s = unitScene(1.0);
    RenderSettings r = resolveSettings(s, {});
    EXPECT_TRUE(r.raster.fitLightFrustum);
    EXPECT_TRUE(r.raster.fitLightFrustumIsDefault);
    s.shadow.fitLightFrustum = false;
    r = resolveSettings(s, {});
    EXPECT_FALSE(r.raster.fitLightFrustum);
    EXPECT_FALSE(r.raster.fitLightFrustumIsDefault);
    SettingsOverrides o;
    o.fitLightFrustum = true;
    EXPECT_TRUE(resolveSettings(s, o).raster.fitLightFrustum);
    s.shadow.fitLightFrustum.reset();
    o.fitLightFrustum = false;
    r = resolveSettings(s, o);
    EXPECT_FALSE(r.raster.fitLightFrustum);
    EXPECT_FALSE(r.raster.fitLightFrustumIsDefault);
}

TEST(Settings, ACascadeCountIsTheRasterBackendsToChooseOnlyWhenNobodySetIt) {
    Scene s = unitScene(1.0);
    EXPECT_TRUE(resolveSettings(s, {}).raster.cascadesIsDefault);
    SettingsOverrides o;
    o.cascades = 1;  // forcing one map is a choice too
    EXPECT_FALSE(resolveSettings(s, o).raster.cascadesIsDefault);
    s.shadow.cascades = 1;
    EXPECT_FALSE(resolveSettings(s, {}).raster.cascadesIsDefault);
}

TEST(Settings, CascadeBlendComesFromTheCommandLineThenTheSceneThenOff) {
    Scene s = unitScene(1.0);
    EXPECT_EQ(resolveSettings(s, {}).raster.cascadeBlend, 0.0);
    s.shadow.cascadeBlend = 0.25;
    EXPECT_EQ(resolveSettings(s, {}).raster.cascadeBlend, 0.25);
    SettingsOverrides o;
    o.cascadeBlend = 0.5;  // the upper end is allowed
    EXPECT_EQ(resolveSettings(s, o).raster.cascadeBlend, 0.5);
    o.cascadeBlend = 0.0;  // and 0 on the command line turns the scene's band off
    EXPECT_EQ(resolveSettings(s, o).raster.cascadeBlend, 0.0);
}

TEST(Settings, ReceiverPlaneBiasComesFromTheCommandLineThenTheSceneThenOff) {
    Scene s = unitScene(1.0);
    EXPECT_FALSE(resolveSettings(s, {}).raster.receiverPlaneBias);
    s.shadow.receiverPlaneBias = true;
    EXPECT_TRUE(resolveSettings(s, {}).raster.receiverPlaneBias);
    SettingsOverrides o;
    o.receiverPlaneBias = false;
    EXPECT_FALSE(resolveSettings(s, o).raster.receiverPlaneBias);
}

TEST(Settings, HardwareBiasComesFromTheCommandLineThenTheSceneThenOff) {
    Scene s = unitScene(1.0);
    EXPECT_FALSE(resolveSettings(s, {}).raster.hardwareBias);
    s.shadow.hardwareBias = true;
    EXPECT_TRUE(resolveSettings(s, {}).raster.hardwareBias);
    SettingsOverrides o;
    o.hardwareBias = false;
    EXPECT_FALSE(resolveSettings(s, o).raster.hardwareBias);
}

TEST(Settings, BadValuesNameTheOption) {
    const Scene s = unitScene(1.0);
    auto expectError = [&](SettingsOverrides o, const std::string& option) {
        try {
            resolveSettings(s, o);
            FAIL() << option;
        } catch (const InputError& e) {
            EXPECT_EQ(std::string(e.what()).rfind(option, 0), 0u) << e.what();
        }
    };
    SettingsOverrides o;
    o.shadowMapSize = -4;
    expectError(o, "--shadow-map-size");
    o = {};
    o.shadowMapSize = 1 << 20;
    expectError(o, "--shadow-map-size");
    o = {};
    o.rayBias = "tiny";
    expectError(o, "--ray-bias");
    o = {};
    o.rayBias = "-1";
    expectError(o, "--ray-bias");
    o = {};
    o.rayBias = "1e-3x";
    expectError(o, "--ray-bias");
    o = {};
    o.filter = "gauss";
    expectError(o, "--filter");
    o = {};
    o.precision = "half";
    expectError(o, "--precision");
    o = {};
    o.depthBias = -1.0;
    expectError(o, "--depth-bias");
    o = {};
    o.samples = 0;
    expectError(o, "--samples");
    o = {};
    o.threads = -2;
    expectError(o, "--threads");
    o = {};
    o.cascades = 0;
    expectError(o, "--cascades");
    o = {};
    o.cascades = kMaxCascades + 1;
    expectError(o, "--cascades");
    o = {};
    o.cascadeBlend = -0.01;
    expectError(o, "--cascade-blend");
    o = {};
    o.cascadeBlend = 0.51;
    expectError(o, "--cascade-blend");
    o = {};
    o.cascadeBlend = std::nan("");
    expectError(o, "--cascade-blend");
    o = {};
    o.minVariance = -1e-9;
    expectError(o, "--min-variance");
    o = {};
    o.bleedReduction = 1.0;
    expectError(o, "--bleeding-reduction");
    o = {};
    o.evsmPositive = kMaxEvsmExponent + 1;
    expectError(o, "--evsm-positive");
    o = {};
    o.evsmNegative = std::nan("");
    expectError(o, "--evsm-negative");
    o = {};
    o.esmExponent = kMaxEsmExponent + 1;
    expectError(o, "--esm-exponent");
    o = {};
    o.momentBias = -0.1;
    expectError(o, "--moment-bias");
    o = {};
    o.blurWidth = 6;
    expectError(o, "--blur-width");
    o = {};
    o.blurWidth = kMaxBlurWidth + 2;
    expectError(o, "--blur-width");
}

TEST(Settings, FilterableMapParametersComeFromTheCommandLineThenTheSceneThenTheDefaults) {
    Scene s = unitScene(1.0);
    s.shadow.filter = "evsm4";
    s.shadow.evsmPositive = 30.0;
    s.shadow.blurWidth = 7;
    SettingsOverrides o;
    o.blurWidth = 3;
    const RasterSettings r = resolveSettings(s, o).raster;
    EXPECT_EQ(r.filter, ShadowFilter::Evsm4);
    EXPECT_TRUE(isFilterable(r.filter));
    EXPECT_FALSE(isFilterable(ShadowFilter::Pcss));
    EXPECT_EQ(r.moments.evsmPositive, 30.0);                           // the scene's
    EXPECT_EQ(r.moments.blurWidth, 3);                                 // the command line's
    EXPECT_EQ(r.moments.evsmNegative, MomentSettings{}.evsmNegative);  // the default
    for (const char* name : {"vsm", "evsm2", "evsm4", "esm", "msm"}) {
        o.filter = name;
        EXPECT_STREQ(toString(resolveSettings(s, o).raster.filter), name);
    }
}

TEST(Settings, ReferenceIsDoubleRobustAndUnbiased) {
    RaytraceSettings base;
    base.rayBias = 0.5;
    base.precision = Precision::Float;
    const RaytraceSettings r = referenceSettings(base);
    EXPECT_EQ(r.precision, Precision::Double);
    EXPECT_TRUE(r.robustOffset);
    EXPECT_EQ(r.rayBias, 0.0);
}

}  // namespace
}  // namespace shadowlab::scene
