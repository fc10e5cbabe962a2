// tests/raster/renderer_test.cpp: whole raster renders of the sphere-over-plane scene on
// lavapipe with the validation layer on, judged against closed-form visibility and shadows.
// Set SHADOWLAB_TEST_PNG_DIR to also write each render's beauty image there for a look.
#include "raster/renderer.h"

#include <malloc.h>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <initializer_list>
#include <limits>
#include <string>
#include <tuple>
#include <utility>

#include <gtest/gtest.h>

#include "raster/alpha_casters.h"
#include "raster/cascades.h"
#include "scene/frame_io.h"
#include "tests/kit/render_checked.h"
#include "tests/kit/test_scenes.h"

namespace shadowlab::raster {
namespace {

using namespace test;
using scene::ShadowFilter;

// renderChecked (validation on, no messages), and the beauty written to look at when asked.
scene::Frame renderValidated(const scene::Scene& s, const scene::RasterSettings& settings, const std::string& name) {
    scene::Frame f = renderChecked(s, settings);
    writePngToLookAt(f, name);
    return f;
}

// The attributes print numbers with %.9g; compare against the same rounding.
std::string formatForTest(double v) {
    char buf[64];
    std::snprintf(buf, sizeof buf, "%.9g", v);
    return buf;
}

std::size_t at(const scene::Frame& f, int x, int y) { return std::size_t(y) * f.width + x; }

TEST(RasterRender, SphereOverPlaneRendersWithoutValidationMessages) {
    const SphereOverPlane p;
    const scene::Scene s = makeScene(p);
    const scene::Frame f = renderValidated(s, validatedSettings(512, 0.01, 1.0, ShadowFilter::Pcf2x2), "basic");
    ASSERT_EQ(f.width, p.width);
    ASSERT_EQ(f.height, p.height);
    const auto [lo, hi] = std::minmax_element(f.beauty.begin(), f.beauty.end());
    EXPECT_LT(*lo + 0.1f, *hi) << "the image is (nearly) constant";
    bool seen[3] = {false, false, false};
    for (float id : f.objectId) {
        ASSERT_TRUE(id == 0.0f || id == 1.0f || id == 2.0f) << "object id " << id;
        seen[int(id)] = true;
    }
    EXPECT_TRUE(seen[0] && seen[1] && seen[2]) << "background, sphere and plane must all be visible";
    EXPECT_EQ(f.attributes.at("backend"), "raster");
    EXPECT_NE(f.attributes.at("device").find("llvmpipe"), std::string::npos);
    ASSERT_EQ(f.timingsMs.size(), 4u);
    EXPECT_EQ(f.timingsMs[0].first, "setup");
    EXPECT_EQ(f.timingsMs[1].first, "shadow_pass");
    EXPECT_EQ(f.timingsMs[2].first, "lit_pass");
    EXPECT_EQ(f.timingsMs[3].first, "readback");
}

TEST(RasterRender, BackgroundPixelsHaveTheBackgroundColorAndZeroAovs) {
    const SphereOverPlane p;
    const scene::Scene s = makeScene(p);
    const scene::Frame f = renderValidated(s, validatedSettings(256, 0.01, 1.0, ShadowFilter::None), "background");
    std::size_t background = 0;
    for (std::size_t i = 0; i < f.pixelCount(); ++i) {
        if (f.objectId[i] != 0.0f) continue;
        ++background;
        for (int c = 0; c < 3; ++c) ASSERT_EQ(f.beauty[3 * i + c], float(s.background[c]));
        ASSERT_EQ(f.visibility[i], 0.0f);
        ASSERT_EQ(f.depth[i], 0.0f);
        ASSERT_EQ(f.ndotl[i], 0.0f);
    }
    EXPECT_GT(background, 0u);
}

TEST(RasterRender, PointUnderSphereIsShadowedAndPointFarAwayIsLit) {
    // Light straight down: the sphere's shadow on y = 0 is the disk x² + z² < r² below it.
    const SphereOverPlane p;
    const scene::Scene s = makeScene(p);
    const scene::CameraBasis cam = scene::cameraBasis(s.camera);
    const scene::Frame f = renderValidated(s, validatedSettings(512, 0.01, 1.0, ShadowFilter::None), "under");

    const Vec3 under(0.0, 0.0, 0.3);  // 0.3 < r = 0.5 from the axis: inside the disk
    const Vec3 far(2.5, 0.0, 0.3);    // 2.5 > r: outside
    ASSERT_TRUE(planePointShadowed(p, under));
    ASSERT_FALSE(planePointShadowed(p, far));
    for (const auto& [q, shadowed] : {std::pair{under, true}, std::pair{far, false}}) {
        const auto [x, y] = projectToPixel(cam, q);
        ASSERT_TRUE(x >= 0 && x < f.width && y >= 0 && y < f.height);
        // The chosen point must be what that pixel sees (not hidden behind the sphere).
        ASSERT_EQ(primaryHit(p, cam, x, y).id, 2);
        const std::size_t i = at(f, x, y);
        EXPECT_EQ(f.objectId[i], 2.0f);
        EXPECT_NEAR(f.ndotl[i], 1.0f, 1e-5f);  // plane normal (0,1,0) · L (0,1,0)
        EXPECT_EQ(f.visibility[i], shadowed ? 0.0f : 1.0f) << "pixel " << x << "," << y;
        // Shading: ambient·albedo in shadow; + albedo·intensity·N·L when lit.
        const float expected = shadowed ? 0.05f * 0.8f : 0.05f * 0.8f + 0.8f * 3.0f;
        EXPECT_NEAR(f.beauty[3 * i], expected, 1e-4f);
        // View depth: distance along the camera's forward axis.
        const Vec3 hit = primaryHit(p, cam, x, y).p;
        EXPECT_NEAR(f.depth[i], glm::dot(hit - cam.position, cam.forward), 1e-3);
    }
}

// Counts, over plane pixels that the closed form says face the light, those the raster calls
// shadowed although the closed form says lit (false shadow) and the reverse (missed shadow).
struct ShadowErrors {
    int counted = 0, analyticShadowed = 0, falseShadow = 0, missedShadow = 0;
    // Shadowed pixels whose receiver lies less than `bias` behind the caster along the light
    // (so a constant depth bias of that size lights them), counted only where the answer is
    // clear: more than 5% of the bias away from the boundary.
    int predictedLeak = 0, predictedKept = 0, leakedOfPredicted = 0, keptOfPredicted = 0;
};

ShadowErrors shadowErrors(const SphereOverPlane& p, const scene::Scene& s, const scene::Frame& f, double bias = 0.0) {
    ShadowErrors e;
    forEachPlanePixel(p, s, f, [&](std::size_t i, const Vec3& q) {
        ++e.counted;
        const bool shadowed = planePointShadowed(p, q);
        e.analyticShadowed += shadowed;
        if (!shadowed && f.visibility[i] < 0.5f) ++e.falseShadow;
        if (shadowed && f.visibility[i] > 0.5f) ++e.missedShadow;
        const double behind = depthBehindCaster(p, q);
        if (shadowed && behind < 0.95 * bias) {
            ++e.predictedLeak;
            e.leakedOfPredicted += f.visibility[i] > 0.5f;
        } else if (shadowed && behind > 1.05 * bias) {
            ++e.predictedKept;
            e.keptOfPredicted += f.visibility[i] < 0.5f;
        }
    });
    return e;
}

// The sphere over the plane at 320x180, light `elevation`° above the plane.
SphereOverPlane litFrom(double elevation) {
    SphereOverPlane p;
    p.width = 320;
    p.height = 180;
    p.lightDirection = lightFromElevation(elevation);
    return p;
}

// The same with the sphere resting on the plane (center at its radius, 0.5).
SphereOverPlane restingSphere(double elevation) {
    SphereOverPlane p = litFrom(elevation);
    p.center = Vec3(0, 0.5, 0);
    return p;
}

TEST(RasterRender, ZeroBiasAtGrazingLightGivesAcneOnTheLitPlane) {
    // Light 10° above the horizon: across one texel the plane's light depth changes by
    // texel·tan(80°) ≈ 5.7 texels' worth, so without bias about half the plane compares
    // against its own, nearer texel center and shadows itself.
    SphereOverPlane p;
    p.lightDirection = lightFromElevation(10.0);
    const scene::Scene s = makeScene(p);
    const scene::Frame f = renderValidated(s, validatedSettings(512, 0.0, 0.0, ShadowFilter::None), "acne");
    const ShadowErrors e = shadowErrors(p, s, f);
    ASSERT_GT(e.counted, 5000);
    EXPECT_GT(e.falseShadow, e.counted / 5) << "expected widespread acne, got " << e.falseShadow << " of " << e.counted;
}

TEST(RasterRender, HugeDepthBiasShrinksTheContactShadow) {
    // The sphere rests on the plane, light from 60° elevation. A constant bias b lights every
    // receiver less than b behind the caster's light-facing surface along the light; with
    // b = 2r that is the shadow near the contact point (the plane is at most
    // 2r/sin(60°) ≈ 2.3r behind the sphere, at the shadow's far tip). The closed form says
    // which pixels: they must leak, and the others must stay shadowed.
    SphereOverPlane p;
    p.center = Vec3(0, 0.5, 0);
    p.lightDirection = lightFromElevation(60.0);
    p.width = 320;
    p.height = 180;
    const scene::Scene s = makeScene(p);
    const double bias = 2.0 * p.radius;
    const scene::Frame f = renderValidated(s, validatedSettings(1024, bias, 0.0, ShadowFilter::None), "huge-bias");
    const ShadowErrors e = shadowErrors(p, s, f, bias);
    ASSERT_GT(e.analyticShadowed, 200);
    // About half of the visible shadow is near enough to the contact (the closed form below
    // says exactly which pixels).
    EXPECT_GT(e.missedShadow, e.analyticShadowed / 3)
        << "expected much of the shadow to leak, got " << e.missedShadow << " of " << e.analyticShadowed;
    EXPECT_GT(e.leakedOfPredicted, e.predictedLeak * 95 / 100) << e.leakedOfPredicted << " of " << e.predictedLeak;
    EXPECT_GT(e.keptOfPredicted, e.predictedKept * 95 / 100) << e.keptOfPredicted << " of " << e.predictedKept;
}

TEST(RasterRender, SaneBiasHasFewFalseAndMissedShadows) {
    // Half a texel of constant bias plus one texel of slope bias (the program's default).
    for (double elevation : {10.0, 40.0}) {
        SphereOverPlane p;
        p.center = Vec3(0, 0.5, 0);
        p.width = 320;
        p.height = 180;
        p.lightDirection = lightFromElevation(elevation);
        const scene::Scene s = makeScene(p);
        const int size = 1024;
        const double texel = s.bounds().diagonal() / size;
        const scene::Frame f = renderValidated(s, validatedSettings(size, 0.5 * texel, 1.0, ShadowFilter::Pcf2x2),
                                               "sane-" + std::to_string(int(elevation)));
        const ShadowErrors e = shadowErrors(p, s, f);
        ASSERT_GT(e.analyticShadowed, 200);
        // Only the shadow's outline may differ (a band about a texel wide).
        EXPECT_LT(e.falseShadow, e.counted / 100) << "elevation " << elevation;
        EXPECT_LT(e.missedShadow, e.analyticShadowed / 10) << "elevation " << elevation;
    }
}

TEST(RasterBias, BiasSeriesAtGrazingLightTradeAcneForMissedOrDisplacedShadow) {
    // Light 5° above the plane (tan θ ≈ 11.4 at the plane, past the slope clamp of 10), the
    // sphere resting on it. For each bias kind alone, a growing series: the plane's false
    // shadows (acne) never increase and the missed shadow (the contact region leaking) never
    // decreases, and both change substantially end to end. With the nearest filter each pixel's
    // answer is a compare of one stored depth against the receiver depth minus the bias, so
    // for a depth bias the counts are monotone pixel by pixel; the normal offset moves the
    // lookup point, so its counts get a small slack, and so does the shader's slope bias past
    // its cap (a lift along the normal, below).
    const SphereOverPlane p = restingSphere(5.0);
    const scene::Scene s = makeScene(p);
    const int size = 512;
    // The bounding-sphere map's texel: 2 · 1.01 · half the diagonal / size.
    const double texel = 1.01 * s.bounds().diagonal() / size;
    // HardwareDepth, HardwareSlope: the same two biases through the rasterizer's depth-bias state
    // (--hardware-bias): the stored depths grow instead of the references shrinking, so the counts
    // are monotone pixel by pixel too (the stored depth of a texel is the least over the primitives
    // drawn there, each raised by more as the factor grows).
    enum Kind { Depth, Slope, NormalOffset, HardwareDepth, HardwareSlope };
    auto series = [&](Kind kind, const std::vector<double>& steps) {
        std::vector<ShadowErrors> out;
        for (const double k : steps) {
            scene::RasterSettings settings = validatedSettings(size, 0.0, 0.0, ShadowFilter::None);
            settings.hardwareBias = kind == HardwareDepth || kind == HardwareSlope;
            if (kind == Depth || kind == HardwareDepth) settings.depthBias = k * texel;
            if (kind == Slope || kind == HardwareSlope) settings.slopeBias = k;
            if (kind == NormalOffset) settings.normalOffset = k;
            const scene::Frame f = renderValidated(s, settings, "bias-series");
            EXPECT_EQ(f.attributes.at("bias_mode"), settings.hardwareBias ? "hardware" : "shader");
            out.push_back(shadowErrors(p, s, f));
        }
        return out;
    };
    std::vector<ShadowErrors> depthSeries;
    for (const Kind kind : {Depth, Slope, HardwareDepth, HardwareSlope}) {
        const std::vector<ShadowErrors> e = series(kind, {0.0, 1.0, 4.0, 16.0, 64.0});
        for (std::size_t i = 1; i < e.size(); ++i) {
            EXPECT_GE(e[i].missedShadow, e[i - 1].missedShadow) << "kind " << kind << " step " << i;
            if (kind != Slope) {
                EXPECT_LE(e[i].falseShadow, e[i - 1].falseShadow) << "kind " << kind << " step " << i;
                continue;
            }
            // The shader's slope bias s goes past the cap as a lift along the normal of
            // s·texel·(sin 85° − 10 cos 85°) = 0.125·s texel, which displaces the shadow as the
            // normal offset below does (false shadow at its rim), so false shadow is not monotone
            // in s; but every s ≥ 1 covers the plane: 10·s texels of depth along the light plus
            // s·(tan 85° − 10) from the lift is 11.4·s texels, more than the nearest texel's
            // (√2/2)·11.4.
            EXPECT_LT(e[i].falseShadow, e[0].counted / 1000) << "slope step " << i;
        }
        ASSERT_GT(e[0].analyticShadowed, 500);
        EXPECT_GT(e[0].falseShadow, e[0].counted / 5) << "kind " << kind << ": no acne at zero bias";
        EXPECT_LT(e.back().falseShadow, e[0].counted / 1000) << "kind " << kind;
        if (kind == Depth) depthSeries = e;
        if (kind != HardwareDepth) {
            EXPECT_GT(e.back().missedShadow, e[0].missedShadow + e[0].analyticShadowed / 10) << "kind " << kind;
            continue;
        }
        // The hardware constant bias is converted in units of r = 2^-24, D32_SFLOAT's step for
        // depths in [0.5, 1); the sphere's light-facing triangles lie in [0.46, 0.5) (its radius
        // 0.5 against the map's depth range of 1.01 · 11.4), where r is 2^-25: they are raised by
        // half the bias, and the leak (their shadow's contact region) is that of a shader bias
        // between b/2 and b: at b = 64 texels, at least the shader's at 16 and at most its at 64.
        // (Measured: 99 missed; the shader's 50 at 16 texels and 303 at 64; 10 without bias.)
        EXPECT_GE(e.back().missedShadow, depthSeries[3].missedShadow);
        EXPECT_LE(e.back().missedShadow, depthSeries[4].missedShadow);
        EXPECT_GT(e.back().missedShadow, e[0].missedShadow);
    }
    // The normal offset at grazing light moves the lookup point mostly *across* the light
    // (the normal is 85° from it), so past the offset that removes acne ((√2/2)·sin 85° ≈ 0.7
    // texel, see NormalOffsetRemovesAcneWithoutDepthBias) it does not make the shadow leak: it
    // displaces the shadow away from the light, which shows as false shadow growing with the
    // offset while the missed shadow does not grow. That is its trade, asserted as such.
    const std::vector<ShadowErrors> e = series(NormalOffset, {0.0, 0.25, 0.5, 1.0, 2.0, 4.0});
    EXPECT_GT(e[0].falseShadow, e[0].counted / 5);
    EXPECT_LT(e[1].falseShadow, e[0].falseShadow);
    EXPECT_LT(e[2].falseShadow, e[0].counted / 1000) << "acne gone at 0.5 texel";
    for (std::size_t i = 3; i < e.size(); ++i) {
        EXPECT_GT(e[i].falseShadow, e[i - 1].falseShadow) << "displacement grows, step " << i;
        EXPECT_LE(e[i].missedShadow, e[0].missedShadow) << "no leak, step " << i;
    }
}

TEST(RasterHardwareBias, FactorsAreTheWorldAndTexelBiasesInTheRasterizersUnits) {
    // The bounding-sphere map of a directional light spans 1.01 · the bounds' diagonal in depth
    // (orthographic, depth 0..1 linear), so a world bias b is b / (1.01·diagonal) in depth, which
    // in units of r = 2^-24 (D32_SFLOAT at depths in [0.5, 1)) is that times 2^24; the slope factor
    // is the slope bias in texels as given (the rasterizer's slope is depth per texel).
    SphereOverPlane p;
    p.lightDirection = lightFromElevation(40.0);
    const scene::Scene s = makeScene(p);
    scene::RasterSettings settings = validatedSettings(512, 0.01, 1.5, ShadowFilter::Pcf2x2);
    settings.hardwareBias = true;
    const scene::Frame f = renderValidated(s, settings, "hardware-factors");
    const double range = 1.01 * s.bounds().diagonal();
    EXPECT_EQ(f.attributes.at("bias_mode"), "hardware");
    EXPECT_NEAR(std::stod(f.attributes.at("hardware_depth_bias_constant_factor")), 0.01 / range * 16777216.0,
                1e-6 * 0.01 / range * 16777216.0);
    EXPECT_EQ(f.attributes.at("hardware_depth_bias_slope_factor"), "1.5");
    // The world values stay recorded beside them.
    EXPECT_EQ(f.attributes.at("depth_bias"), "0.01");
    EXPECT_EQ(f.attributes.at("slope_bias"), "1.5");
    // The rasterizer's slope term has no cap, so the shader lifts nothing past it.
    EXPECT_EQ(f.attributes.at("grazing_normal_offset"), "0");
    settings.hardwareBias = false;
    const scene::Frame shader = renderValidated(s, settings, "shader-factors");
    EXPECT_EQ(shader.attributes.at("bias_mode"), "shader");
    EXPECT_EQ(shader.attributes.count("hardware_depth_bias_constant_factor"), 0u);
    EXPECT_EQ(shader.attributes.at("grazing_normal_offset"), "1.5");
}

TEST(RasterHardwareBias, AConstantBiasInTheDepthPassComparesAsTheSameBiasInTheShader) {
    // Nearest filter, no slope bias, a constant bias of 2 texels: lit when ref − b ≤ stored
    // (shader) or ref ≤ stored + b (hardware) is the same test up to rounding, wherever the
    // stored primitive's depths reach [0.5, 1), where r = 2^-24 is the unit the factor was
    // converted in. The seed sphere's map puts the plane's visible part and the sphere's
    // light-facing side around the middle of the depth range; a primitive wholly below 0.5 gets
    // half the bias (or less) and may differ. So: the two agree on nearly every counted pixel,
    // and both match the closed form's shadow as well.
    const SphereOverPlane p = restingSphere(40.0);
    const scene::Scene s = makeScene(p);
    const int size = 1024;
    const double texel = 1.01 * s.bounds().diagonal() / size;
    scene::RasterSettings settings = validatedSettings(size, 2.0 * texel, 0.0, ShadowFilter::None);
    const scene::Frame shader = renderValidated(s, settings, "constant-shader");
    settings.hardwareBias = true;
    const scene::Frame hardware = renderValidated(s, settings, "constant-hardware");
    std::size_t counted = 0, differ = 0;
    for (std::size_t i = 0; i < shader.pixelCount(); ++i) {
        if (shader.objectId[i] == 0.0f || shader.ndotl[i] <= 0.0f) continue;
        ++counted;
        differ += shader.visibility[i] != hardware.visibility[i];
    }
    ASSERT_GT(counted, 20000u);
    EXPECT_LT(differ, counted / 200) << differ << " of " << counted;
    const ShadowErrors a = shadowErrors(p, s, shader), b = shadowErrors(p, s, hardware);
    EXPECT_LT(std::abs(a.falseShadow - b.falseShadow), a.counted / 200);
    EXPECT_LT(std::abs(a.missedShadow - b.missedShadow), a.analyticShadowed / 20 + 1);
}

// `s` with its light a spot at `position` aimed along `direction` (half-angle 45°, intensity 300).
scene::Scene withSpot(scene::Scene s, const Vec3& position, const Vec3& direction) {
    s.lights[0].type = scene::LightType::Spot;
    s.lights[0].position = position;
    s.lights[0].direction = glm::normalize(direction);
    s.lights[0].coneAngleDegrees = 45;
    s.lights[0].intensity = 300;
    return s;
}

// `s` with its first light a point light at `position` (intensity 300, as withSpot's).
scene::Scene withPoint(scene::Scene s, const Vec3& position) {
    s.lights[0].type = scene::LightType::Point;
    s.lights[0].position = position;
    s.lights[0].intensity = 300;
    return s;
}

TEST(RasterHardwareBias, SpotAndPointMapsKeepTheShaderBiasAndCascadesTakeTheirOwnFactors) {
    // Perspective depth is not linear in distance, so one constant factor cannot be one world bias:
    // spot and point layers keep the shader's bias (factors 0, the same pixels as without the
    // option). Cascades: each layer's factor is its own world bias over its own depth range.
    scene::Scene s = withSpot(makeScene(SphereOverPlane{}), Vec3(2, 5, 2), Vec3(-2, -5, -2));
    scene::RasterSettings settings = validatedSettings(512, 0.01, 1.0, ShadowFilter::Pcf2x2);
    const scene::Frame shader = renderValidated(s, settings, "spot-shader");
    settings.hardwareBias = true;
    const scene::Frame hardware = renderValidated(s, settings, "spot-hardware");
    EXPECT_EQ(hardware.attributes.at("hardware_depth_bias_constant_factor"), "0");
    EXPECT_EQ(hardware.visibility, shader.visibility);
    EXPECT_EQ(hardware.blockerId, shader.blockerId);
    s.lights[0].type = scene::LightType::Point;
    const scene::Frame point = renderValidated(s, settings, "point-hardware");
    EXPECT_EQ(point.attributes.at("hardware_depth_bias_constant_factor"), "0;0;0;0;0;0");
    settings.hardwareBias = false;
    EXPECT_EQ(point.visibility, renderValidated(s, settings, "point-shader").visibility);

    const scene::Scene sun = makeScene(SphereOverPlane{});
    scene::RasterSettings cascaded = validatedSettings(512, 0.01, 1.0, ShadowFilter::Pcf2x2);
    cascaded.cascades = 3;
    cascaded.hardwareBias = true;
    const scene::Frame c = renderValidated(sun, cascaded, "cascades-hardware");
    ASSERT_EQ(c.attributes.at("cascades"), "3");
    // Each factor is 0.01 over that cascade's depth range in units of 2^-24; the ranges come from
    // the same cascade fit the renderer uses.
    const CascadeSet set = fitCascades(sun, sun.lights[0].direction, 3, 512, 0.0);
    std::string expected;
    for (std::size_t k = 0; k < set.frusta.size(); ++k) {
        if (k) expected += ';';
        expected += formatForTest(float(0.01 / set.frusta[k].depthRange() * 16777216.0));
    }
    EXPECT_EQ(c.attributes.at("hardware_depth_bias_constant_factor"), expected);
}

TEST(RasterFittedFrustum, DefaultDepthBiasBecomesHalfTheFittedTexel) {
    // resolveSettings() marks a bias nobody gave as the default; with a fitted map the backend
    // uses half of that map's texel instead of half a bounding-sphere texel. A given bias stays.
    SphereOverPlane p;
    p.lightDirection = lightFromElevation(40.0);
    const scene::Scene s = makeScene(p);
    scene::SettingsOverrides o;
    o.shadowMapSize = 256;
    o.fitLightFrustum = true;
    o.validate = true;
    scene::RenderSettings rs = scene::resolveSettings(s, o);
    ASSERT_TRUE(rs.raster.depthBiasIsDefault);
    EXPECT_DOUBLE_EQ(rs.raster.depthBias, 0.5 * s.bounds().diagonal() / 256);
    scene::Frame f = renderValidated(s, rs.raster, "default-bias-fitted");
    const double texel = std::stod(f.attributes.at("texel_world_size"));
    EXPECT_DOUBLE_EQ(std::stod(f.attributes.at("depth_bias")), std::stod(formatForTest(0.5 * texel)));
    EXPECT_LT(0.5 * texel, 0.75 * rs.raster.depthBias);  // smaller than the bounding-sphere default
    EXPECT_EQ(f.attributes.at("depth_bias_default"), "true");
    // A given bias is kept.
    o.depthBias = 0.03;
    rs = scene::resolveSettings(s, o);
    EXPECT_FALSE(rs.raster.depthBiasIsDefault);
    f = renderValidated(s, rs.raster, "given-bias-fitted");
    EXPECT_EQ(f.attributes.at("depth_bias"), "0.03");
}

TEST(RasterFittedFrustum, DoublingAnUnrelatedFarExtentKeepsTheTexelSize) {
    // A small sphere far off to the side (out of view, casting nothing into it) stretches the
    // scene's bounds; moving it twice as far doubles that extent. The fitted map covers only the
    // receivers in view and their casters, so its texel must not change; the bounding-sphere
    // map's texel grows with the bounds (the control: the test can tell them apart).
    auto texelWith = [](double farX, bool fit) {
        SphereOverPlane p;
        scene::Scene s = makeScene(p);
        scene::Object far;
        far.name = "far";
        far.shape = scene::Sphere{Vec3(farX, 0.5, 0), 0.5};
        s.objects.push_back(far);
        scene::RasterSettings settings = validatedSettings(256, 0.01, 1.0, ShadowFilter::None);
        settings.fitLightFrustum = fit;
        s.lights[0].direction = glm::normalize(Vec3(0.3, -1, 0.2));
        const scene::Frame f = renderValidated(s, settings, "fit-far");
        return std::stod(f.attributes.at("texel_world_size"));
    };
    const double fitted = texelWith(50.0, true), fittedFarther = texelWith(100.0, true);
    EXPECT_NEAR(fittedFarther, fitted, 1e-9 * fitted);
    const double plain = texelWith(50.0, false), plainFarther = texelWith(100.0, false);
    EXPECT_GT(plainFarther, 1.8 * plain);
    EXPECT_LT(fitted, 0.5 * plain);
}

TEST(RasterRender, ObjectIdsMatchClosedFormPrimaryVisibilityExceptOnSilhouettes) {
    const SphereOverPlane p;
    const scene::Scene s = makeScene(p);
    const scene::CameraBasis cam = scene::cameraBasis(s.camera);
    const scene::Frame f = renderValidated(s, validatedSettings(256, 0.01, 1.0, ShadowFilter::None), "ids");
    int differ = 0;
    for (int y = 0; y < f.height; ++y)
        for (int x = 0; x < f.width; ++x) differ += f.objectId[at(f, x, y)] != float(primaryHit(p, cam, x, y).id);
    EXPECT_LT(differ, int(f.pixelCount() / 100)) << differ << " of " << f.pixelCount() << " pixels differ";
}

TEST(RasterRender, FarFromOriginSceneKeepsItsPrecision) {
    // The same scene moved 1e6 units away: camera-relative vertices keep the silhouettes where
    // they were (float world coordinates there would be 0.0625 apart, over a pixel wide).
    SphereOverPlane p;
    const Vec3 offset(1.0e6, 0.0, -1.0e6);
    SphereOverPlane moved = p;
    moved.center += offset;
    moved.eye += offset;
    moved.lookAt += offset;
    scene::Scene s = makeScene(moved);
    std::get<scene::Quad>(s.objects[1].shape).center += offset;
    const scene::CameraBasis cam = scene::cameraBasis(makeScene(p).camera);
    const scene::Frame f = renderValidated(s, validatedSettings(256, 0.01, 1.0, ShadowFilter::None), "far");
    int differ = 0;
    for (int y = 0; y < f.height; ++y)
        for (int x = 0; x < f.width; ++x) differ += f.objectId[at(f, x, y)] != float(primaryHit(p, cam, x, y).id);
    EXPECT_LT(differ, int(f.pixelCount() / 100));
}

TEST(RasterRender, RecordsSettingsAndTexelSize) {
    const SphereOverPlane p;
    const scene::Scene s = makeScene(p);
    const scene::Frame f = renderValidated(s, validatedSettings(256, 0.02, 1.5, ShadowFilter::None), "attrs");
    EXPECT_EQ(f.attributes.at("shadow_map_size"), "256");
    EXPECT_EQ(f.attributes.at("normal_offset"), "0");
    EXPECT_EQ(f.attributes.at("grazing_normal_offset"), "1.5");  // the slope bias past its cap
    EXPECT_EQ(f.attributes.at("light_frustum_fit"), "bounding-sphere");
    EXPECT_EQ(f.attributes.at("filter"), "none");
    EXPECT_EQ(std::stod(f.attributes.at("depth_bias")), 0.02);
    EXPECT_EQ(std::stod(f.attributes.at("slope_bias")), 1.5);
    // An orthographic map over the bounding sphere (diameter = the bounds' diagonal, 1% margin).
    EXPECT_NEAR(std::stod(f.attributes.at("texel_world_size")), 1.01 * s.bounds().diagonal() / 256, 1e-9);
    EXPECT_FALSE(f.attributes.at("light_frustum").empty());
    // Lavapipe has timestamps on its graphics queue.
    EXPECT_GE(std::stod(f.attributes.at("gpu_shadow_pass_ms")), 0.0);
    EXPECT_GT(std::stod(f.attributes.at("gpu_lit_pass_ms")), 0.0);
}

// Plane pixels (in both the closed form and the render) more than `band` world units across
// the light from the sphere's shadow outline must have exactly the closed-form visibility;
// returns how many pixels (of those nearer) are fractional. The outline: plane points whose ray
// toward the light passes exactly r from the center, so |(c − q) × L| − r is the distance
// across the light.
struct EdgeStats {
    int exactWrong = 0, fractional = 0, farFromEdge = 0;
};

// How far the plane point q lies across the light from the sphere's shadow outline (negative
// inside the shadow): |(c − q) × L| − r.
double acrossTheOutline(const SphereOverPlane& p, const Vec3& q) {
    return glm::length(glm::cross(p.center - q, -glm::normalize(p.lightDirection))) - p.radius;
}

EdgeStats edgeStats(const SphereOverPlane& p, const scene::Scene& s, const scene::Frame& f, double band) {
    EdgeStats e;
    forEachPlanePixel(p, s, f, [&](std::size_t i, const Vec3& q) {
        const float v = f.visibility[i];
        if (v > 0.0f && v < 1.0f) ++e.fractional;
        if (std::abs(acrossTheOutline(p, q)) <= band) return;
        ++e.farFromEdge;
        const float expected = planePointShadowed(p, q) ? 0.0f : 1.0f;
        if (v != expected) ++e.exactWrong;
    });
    return e;
}

scene::RasterSettings filterSettings(ShadowFilter filter, int pcfSize) {
    scene::RasterSettings r = validatedSettings(256, 0.02, 1.0, filter);
    r.pcfSize = pcfSize;
    return r;
}

TEST(RasterFilters, PcfOfSizeOneIsTheNearestTexel) {
    // One tap at offset 0 is the `none` filter, pixel for pixel.
    SphereOverPlane p;
    p.lightDirection = lightFromElevation(60.0);
    const scene::Scene s = makeScene(p);
    const scene::Frame none = renderValidated(s, filterSettings(ShadowFilter::None, 1), "filter-none");
    const scene::Frame pcf1 = renderValidated(s, filterSettings(ShadowFilter::Pcf, 1), "filter-pcf1");
    EXPECT_EQ(none.visibility, pcf1.visibility);
    EXPECT_EQ(pcf1.attributes.at("filter"), "pcf");
    EXPECT_EQ(pcf1.attributes.at("pcf_size"), "1");
}

TEST(RasterFilters, FiltersSoftenOnlyABandAroundTheShadowOutline) {
    // Light from 60° over a floating sphere: the plane is far behind the sphere, so biases do
    // not matter and every pixel's answer is decided by the taps' positions across the light.
    // Taps reach at most (N−1)/2 texels (pcf) or N/2 texels (poisson) from the point, plus half a
    // texel of nearest-texel rounding: outside a band of N/2 + 1.5 texels around the outline
    // the visibility must be exactly 0 or 1, and inside it filtering makes fractions.
    const SphereOverPlane p = litFrom(60.0);
    const scene::Scene s = makeScene(p);
    const double texel = 1.01 * s.bounds().diagonal() / 256;
    struct Case {
        ShadowFilter filter;
        int size;
        double reach;  // texels
    };
    int previousFractional = -1;
    for (const Case c : {Case{ShadowFilter::Pcf2x2, 2, 1.0}, Case{ShadowFilter::Pcf, 3, 1.5},
                         Case{ShadowFilter::Pcf, 5, 2.5}, Case{ShadowFilter::Poisson, 7, 3.5}}) {
        const scene::Frame f =
            renderValidated(s, filterSettings(c.filter, c.size),
                            std::string("filter-") + scene::toString(c.filter) + std::to_string(c.size));
        const EdgeStats e = edgeStats(p, s, f, (c.reach + 1.5) * texel);
        EXPECT_GT(e.farFromEdge, 10000);
        EXPECT_EQ(e.exactWrong, 0) << f.attributes.at("filter") << " " << c.size;
        EXPECT_GT(e.fractional, 100) << f.attributes.at("filter") << " " << c.size;
        EXPECT_GT(e.fractional, previousFractional) << "a wider kernel must widen the penumbra";
        previousFractional = e.fractional;
    }
}

TEST(RasterFilters, Pcf2x2LiesBetweenTheHardResultsOfTheNeighbouringTexels) {
    // pcf2x2 is the bilinear mix of the compare results of the four texels around the lookup
    // point, and the hard (none) result is the compare of the nearest of those four, whose
    // bilinear weight is at least 1/4 (both fractions ≤ 1/2 from it). With slope bias 0 both
    // filters compare against the same reference, so per pixel: hard lit ⇒ pcf ≥ 1/4, hard
    // shadowed ⇒ pcf ≤ 3/4, and a pcf of exactly 0 or 1 (all four agree) equals the hard one.
    // A few pixels may see float rounding pick a different nearest texel: at most 0.1%.
    const SphereOverPlane p = litFrom(40.0);
    const scene::Scene s = makeScene(p);
    const scene::Frame hard = renderValidated(s, validatedSettings(256, 0.02, 0.0, ShadowFilter::None), "between-hard");
    const scene::Frame soft =
        renderValidated(s, validatedSettings(256, 0.02, 0.0, ShadowFilter::Pcf2x2), "between-pcf");
    int outside = 0, fractional = 0, shadowed = 0;
    for (std::size_t i = 0; i < hard.pixelCount(); ++i) {
        if (hard.objectId[i] != 2.0f || hard.ndotl[i] <= 0.0f) continue;
        const float h = hard.visibility[i], v = soft.visibility[i];
        fractional += v > 0.0f && v < 1.0f;
        shadowed += h == 0.0f;
        const bool ok = h == 1.0f ? v >= 0.25f - 1e-4f : v <= 0.75f + 1e-4f;
        outside += !ok;
    }
    EXPECT_GT(shadowed, 1000);
    EXPECT_GT(fractional, 100) << "the shadow outline should give fractional pcf values";
    EXPECT_LE(outside, int(hard.pixelCount() / 1000)) << outside << " pixels outside the neighbours' range";
}

TEST(RasterFilters, NoneHasNoFractionalVisibility) {
    // The nearest-texel lookup answers 0 or 1 even where a filter answers a fraction: on the plane
    // pixels within two texels (across the light) of the sphere's shadow outline, where pcf2x2 of
    // the same scene is fractional, `none` must be exactly 0 or 1, and it must give both there
    // (the band straddles the outline). The bounding-sphere map's texel is 1.01·diagonal/256.
    const SphereOverPlane p = litFrom(60.0);
    const scene::Scene s = makeScene(p);
    const double texel = 1.01 * s.bounds().diagonal() / 256;
    const scene::Frame none = renderValidated(s, filterSettings(ShadowFilter::None, 3), "filter-none-only");
    const scene::Frame pcf = renderValidated(s, filterSettings(ShadowFilter::Pcf2x2, 3), "filter-pcf2x2-contrast");
    int band = 0, lit = 0, shadowed = 0, fractional = 0, pcfFractional = 0;
    forEachPlanePixel(p, s, none, [&](std::size_t i, const Vec3& q) {
        if (std::abs(acrossTheOutline(p, q)) > 2.0 * texel) return;
        ++band;
        const float v = none.visibility[i], w = pcf.visibility[i];
        fractional += v > 0.0f && v < 1.0f;
        lit += v == 1.0f;
        shadowed += v == 0.0f;
        pcfFractional += w > 0.0f && w < 1.0f;
    });
    // pcf2x2 is fractional where its 2x2 texels straddle the outline, a strip about one texel
    // wide in this four-texel band: about a quarter of it; without those fractions the band could
    // not tell a lookup from a filter.
    ASSERT_GT(pcfFractional, band / 8) << "of " << band << " pixels at the outline";
    EXPECT_EQ(fractional, 0) << "of " << band << " pixels at the outline";
    EXPECT_GT(lit, band / 10);
    EXPECT_GT(shadowed, band / 10);
}

TEST(RasterNormalOffset, NormalOffsetRemovesAcneWithoutDepthBias) {
    // Light 30° above the plane, no depth or slope bias. Without offset the plane shadows itself
    // on about half its pixels. Moving the lookup point δ = k·texel along the normal puts it
    // δ/cos(θ) in front of the plane along the light, while the stored depth of a neighbouring
    // texel center differs from the plane's by at most (√2/2)·texel·tan(θ) (nearest texel, half a
    // diagonal away): k > (√2/2)·sin(θ) ≈ 0.61 suffices at θ = 60°; k = 1.5 leaves margin.
    const SphereOverPlane p = litFrom(30.0);
    const scene::Scene s = makeScene(p);
    scene::RasterSettings settings = validatedSettings(512, 0.0, 0.0, ShadowFilter::None);
    const ShadowErrors without = shadowErrors(p, s, renderValidated(s, settings, "no-offset"));
    settings.normalOffset = 1.5;
    const scene::Frame f = renderValidated(s, settings, "normal-offset");
    const ShadowErrors with = shadowErrors(p, s, f);
    EXPECT_GT(without.falseShadow, without.counted / 5);
    EXPECT_LT(with.falseShadow, with.counted / 1000) << with.falseShadow << " of " << with.counted;
    ASSERT_GT(with.analyticShadowed, 200);
    EXPECT_LT(with.missedShadow, with.analyticShadowed / 20);
    EXPECT_EQ(f.attributes.at("normal_offset"), "1.5");
}

TEST(RasterBlockerId, ShadowedPlanePixelsNameTheSphereAndAcneNamesThePlaneItself) {
    // Light straight down: the plane's shadowed pixels are blocked by the sphere (id 1), lit
    // ones by nothing (0). With zero bias at grazing light the false shadows are the plane
    // shadowing itself (id 2): self-shadow acne.
    {
        const SphereOverPlane p;
        const scene::Scene s = makeScene(p);
        const scene::Frame f = renderValidated(s, validatedSettings(512, 0.01, 1.0, ShadowFilter::Pcf2x2), "blocker");
        ASSERT_EQ(f.blockerId.size(), f.pixelCount());
        int shadowedChecked = 0;
        forEachPlanePixel(p, s, f, [&](std::size_t i, const Vec3&) {
            if (f.visibility[i] == 0.0f) {
                EXPECT_EQ(f.blockerId[i], 1.0f);
                ++shadowedChecked;
            }
            if (f.visibility[i] == 1.0f) {
                EXPECT_EQ(f.blockerId[i], 0.0f);
            }
        });
        EXPECT_GT(shadowedChecked, 50);
    }
    {
        SphereOverPlane p;
        p.lightDirection = lightFromElevation(10.0);
        const scene::Scene s = makeScene(p);
        const scene::Frame f = renderValidated(s, validatedSettings(512, 0.0, 0.0, ShadowFilter::None), "blocker-acne");
        int acne = 0, selfBlocked = 0;
        forEachPlanePixel(p, s, f, [&](std::size_t i, const Vec3& q) {
            if (planePointShadowed(p, q) || f.visibility[i] >= 0.5f) return;
            ++acne;
            selfBlocked += f.blockerId[i] == 2.0f;
        });
        ASSERT_GT(acne, 1000);
        EXPECT_EQ(selfBlocked, acne);
    }
}

// A spot 4 units above SphereOverPlane's plane at 320x180, pointing down, cone 40°, intensity 300.
const Vec3 kSpotOverPlane(0.3, 4.0, 0.2);
scene::Scene underSpot(SphereOverPlane& p) {
    p.width = 320;
    p.height = 180;
    scene::Scene s = makeScene(p);
    s.lights[0] = test::spotPointingDown(kSpotOverPlane, 40.0, 300.0);
    return s;
}

TEST(RasterSpotLight, AnInnerConeFallsOffAsKhrLightsPunctualSays) {
    // The same spot with an inner cone of 15° inside its 40°: the lit plane's beauty is
    // I/(4π d²)·N·L times KHR_lights_punctual's falloff, ((cos θ − cos 40°) / (cos 15° − cos 40°))²
    // clamped to [0, 1], computed here; the shadow is the hard cone's (the falloff shades, it
    // does not move what is lit), so where the plane is lit the visibility stays 1.
    SphereOverPlane p;
    scene::Scene s = underSpot(p);
    const Vec3 lightPos = kSpotOverPlane;
    s.lights[0].innerConeAngleDegrees = 15.0;
    const scene::Frame f = renderValidated(s, validatedSettings(1024, 0.01, 1.0, ShadowFilter::Pcf2x2), "spot-inner");
    const double cosOuter = std::cos(40.0 * kPi / 180.0), cosInner = std::cos(15.0 * kPi / 180.0);
    int full = 0, ramp = 0;
    forEachPlanePixel(p, s, f, [&](std::size_t i, const Vec3& q) {
        const Vec3 toLight = lightPos - q;
        const double cosAngle = glm::dot(-glm::normalize(toLight), Vec3(0, -1, 0));
        if (cosAngle < cosOuter + 0.01 || f.visibility[i] != 1.0f) return;  // the rim, or shadowed
        const double t = std::clamp((cosAngle - cosOuter) / (cosInner - cosOuter), 0.0, 1.0);
        (t < 1.0 ? ramp : full) += 1;
        const double d2 = glm::dot(toLight, toLight);
        const double ndotl = toLight.y / std::sqrt(d2);
        EXPECT_NEAR(f.beauty[3 * i], 0.8 * 300.0 / (4 * kPi * d2) * ndotl * t * t + 0.05 * 0.8, 2e-4) << i;
    });
    EXPECT_GT(full, 300);
    EXPECT_GT(ramp, 3000);
}

TEST(RasterSpotLight, PerspectiveShadowMatchesTheClosedForm) {
    // A spot 4 units above the plane pointing down, cone 40°, over a floating sphere. Closed
    // form: a plane point inside the cone is shadowed when the segment to the light meets the
    // sphere; its irradiance is I/(4π d²) (scene/shading.h).
    SphereOverPlane p;
    const scene::Scene s = underSpot(p);
    const Vec3 lightPos = kSpotOverPlane;
    const double cone = 40.0;
    const scene::Frame f = renderValidated(s, validatedSettings(1024, 0.01, 1.0, ShadowFilter::Pcf2x2), "spot");
    const double cosCone = std::cos(cone * kPi / 180.0);
    int counted = 0, shadowed = 0, wrong = 0, dark = 0;
    forEachPlanePixel(p, s, f, [&](std::size_t i, const Vec3& q) {
        const Vec3 toLight = lightPos - q;
        const double cosAngle = glm::dot(-glm::normalize(toLight), Vec3(0, -1, 0));
        if (cosAngle < cosCone - 0.01) {  // well outside the cone: no light at all
            ++dark;
            EXPECT_EQ(f.visibility[i], 0.0f);
            EXPECT_EQ(f.ndotl[i], -1.0f);  // no light reaches it: compare does not count it
            EXPECT_NEAR(f.beauty[3 * i], 0.05 * 0.8, 1e-5);
            return;
        }
        if (cosAngle < cosCone + 0.01) return;  // the rim
        ++counted;
        const auto t = raySphere(q, toLight, p.center, p.radius);
        const bool inShadow = t && *t < 1.0;
        shadowed += inShadow;
        if ((f.visibility[i] > 0.5f) == inShadow) ++wrong;
        if (!inShadow && f.visibility[i] == 1.0f) {
            const double d2 = glm::dot(toLight, toLight);
            const double ndotl = toLight.y / std::sqrt(d2);
            EXPECT_NEAR(f.beauty[3 * i], 0.8 * 300.0 / (4 * kPi * d2) * ndotl + 0.05 * 0.8, 2e-4);
        }
    });
    EXPECT_GT(dark, 1000);
    EXPECT_GT(counted, 5000);
    EXPECT_GT(shadowed, 300);
    EXPECT_LT(wrong, shadowed / 20) << wrong << " of " << counted << " pixels in the cone are wrong";
    EXPECT_NE(f.attributes.at("light_frustum").find("perspective"), std::string::npos);
}

TEST(RasterFittedFrustum, FittedMapIsFinerAndKeepsShadowsFromCastersOutsideTheView) {
    // A large plane seen from close by, and a second sphere behind the camera that shadows
    // the visible plane: the fitted map covers only what matters, so its texels are smaller,
    // and the unseen caster still casts.
    SphereOverPlane p;
    p.planeSize = 40.0;
    p.lightDirection = glm::normalize(Vec3(0.0, -1.0, -2.0));  // travels away from the camera
    p.width = 320;
    p.height = 180;
    scene::Scene s = makeScene(p);
    scene::Object behind = s.objects[0];
    // Behind the camera at (0, 4, 6) (it looks toward −z); its shadow lands at about (0, 0, 0.5),
    // in view, apart from the first sphere's at (0, 0, −2).
    const Vec3 behindCenter(0.0, 3.5, 7.5);
    behind.shape = scene::Sphere{behindCenter, 0.8};
    behind.name = "objects[2]";
    s.objects.push_back(behind);
    scene::RasterSettings settings = validatedSettings(1024, 0.0, 1.0, ShadowFilter::None);
    settings.depthBias = 0.5 * s.bounds().diagonal() / 1024;
    const scene::Frame sphereFit = renderValidated(s, settings, "fit-sphere");
    settings.fitLightFrustum = true;
    const scene::Frame fitted = renderValidated(s, settings, "fit-receivers");
    EXPECT_EQ(fitted.attributes.at("light_frustum_fit"), "receivers");
    EXPECT_LT(std::stod(fitted.attributes.at("texel_world_size")),
              0.75 * std::stod(sphereFit.attributes.at("texel_world_size")));
    // Closed form with both spheres.
    const Vec3 l = -glm::normalize(p.lightDirection);
    int counted = 0, shadowed = 0, shadowedByBehind = 0, wrong = 0;
    forEachPlanePixel(p, s, fitted, [&](std::size_t i, const Vec3& q) {
        const bool byFirst = raySphere(q, l, p.center, p.radius).has_value();
        const bool byBehind = raySphere(q, l, behindCenter, 0.8).has_value();
        ++counted;
        shadowed += byFirst || byBehind;
        shadowedByBehind += byBehind;
        if ((fitted.visibility[i] > 0.5f) == (byFirst || byBehind)) ++wrong;
    });
    ASSERT_GT(shadowedByBehind, 100) << "the test needs the unseen sphere's shadow in view";
    EXPECT_LT(wrong, shadowed / 20) << wrong << " wrong of " << counted;
}

// makeScene(p) with a second light, a copy of the first arriving from 40° above the plane.
scene::Scene withASecondLightFrom40Degrees(const SphereOverPlane& p, double intensity = 3.0) {
    scene::Scene s = makeScene(p);
    scene::Light b = s.lights[0];
    b.direction = lightFromElevation(40.0);
    b.intensity = intensity;
    s.lights.push_back(b);
    return s;
}

TEST(RasterRender, TwoLightsWeighVisibilityByTheirUnshadowedIrradiance) {
    // Light A straight down (intensity 3) is blocked under the sphere; light B from 40°
    // elevation (intensity 1) reaches the point under the sphere. There the visibility is
    // w_B / (w_A + w_B) with w = intensity·N·L (docs/decisions.md), and the color is
    // ambient·albedo + albedo·1·N·L_B; N·L is the larger of the two.
    SphereOverPlane p;
    const scene::Scene s = withASecondLightFrom40Degrees(p, 1.0);
    const scene::Light& b = s.lights[1];
    const scene::CameraBasis cam = scene::cameraBasis(s.camera);
    const scene::Frame f = renderValidated(s, validatedSettings(512, 0.01, 1.0, ShadowFilter::None), "two-lights");
    const Vec3 under(0.0, 0.0, 0.3);
    ASSERT_TRUE(planePointShadowed(p, under));
    SphereOverPlane pb = p;
    pb.lightDirection = b.direction;
    ASSERT_FALSE(planePointShadowed(pb, under));
    const auto [x, y] = projectToPixel(cam, under);
    ASSERT_EQ(primaryHit(p, cam, x, y).id, 2);
    const std::size_t i = at(f, x, y);
    const double ndotlB = std::sin(40.0 * kPi / 180.0);
    EXPECT_NEAR(f.visibility[i], ndotlB / (3.0 + ndotlB), 1e-5);
    EXPECT_NEAR(f.ndotl[i], 1.0, 1e-5);
    EXPECT_NEAR(f.beauty[3 * i], 0.05 * 0.8 + 0.8 * ndotlB, 1e-4);
    EXPECT_EQ(f.attributes.at("shadow_maps"), "2");
}

// Renders the sphere over the plane of `p` under `s`'s lights (hard shadows: filter none) and
// checks each light's visibility on the plane (N = +Y) against the closed form, 1 where the ray
// from the point toward the light misses the sphere and 0 where it meets it, and the total against
// the shading rule's weighted mean Σ w_i v_i / Σ w_i, w_i = intensity_i · N·L_i. The lights are
// kept four to an RGBA32F target: `targets` is how many the render must have used.
void expectEachLightsVisibilityAndTheirMean(const SphereOverPlane& p, const scene::Scene& s, std::size_t targets,
                                            const std::string& name) {
    const std::size_t n = s.lights.size();
    std::vector<SphereOverPlane> each(n, p);
    std::vector<double> w(n);
    double wSum = 0.0;
    for (std::size_t l = 0; l < n; ++l) {
        each[l].lightDirection = s.lights[l].direction;
        w[l] = s.lights[l].intensity * -glm::normalize(s.lights[l].direction).y;
        wSum += w[l];
    }
    const scene::CameraBasis cam = scene::cameraBasis(s.camera);
    RenderDebug debug;
    const scene::Frame f = renderChecked(s, validatedSettings(1024, 0.01, 1.0, ShadowFilter::None), &debug);
    writePngToLookAt(f, name);
    EXPECT_EQ(debug.lightTargets, targets);
    ASSERT_EQ(f.lightVisibility.size(), n);
    std::size_t plane = 0;
    std::vector<std::size_t> wrong(n, 0), shadowed(n, 0);
    for (int y = 0; y < f.height; ++y)
        for (int x = 0; x < f.width; ++x) {
            const PrimaryHit hit = primaryHit(p, cam, x, y);
            const std::size_t i = at(f, x, y);
            if (hit.id != 2 || f.objectId[i] != 2.0f) continue;
            ++plane;
            double mean = 0.0;
            for (std::size_t l = 0; l < n; ++l) {
                const float v = f.lightVisibility[l][i];
                ASSERT_TRUE(v == 0.0f || v == 1.0f) << "hard shadows are 0 or 1: light " << l << ", " << v;
                mean += w[l] * v / wSum;
                const bool shadow = planePointShadowed(each[l], hit.p);
                shadowed[l] += shadow;
                wrong[l] += (v == 0.0f) != shadow;
            }
            ASSERT_NEAR(f.visibility[i], mean, 1e-6) << "pixel " << x << "," << y;
        }
    ASSERT_GT(plane, 5000u);
    for (std::size_t l = 0; l < n; ++l) {
        EXPECT_GT(shadowed[l], 100u) << "light " << l << " must shadow part of the plane in view";
        // Only texels on the shadow's outline may differ from the closed form.
        EXPECT_LT(double(wrong[l]), 0.1 * double(shadowed[l])) << "light " << l;
    }
}

TEST(RasterRender, TwoLightsKeepEachLightsVisibilityAndCombineThem) {
    // Light A straight down (intensity 3), light B from 40° elevation (intensity 1): one target.
    SphereOverPlane p;
    p.width = 320;
    p.height = 180;
    expectEachLightsVisibilityAndTheirMean(p, withASecondLightFrom40Degrees(p, 1.0), 1, "per-light");
}

TEST(RasterRender, FiveLightsKeepEachLightsVisibilityInTwoTargets) {
    // Five suns from around the sphere at 40° to 70° elevation: lights 0 to 3 in the first
    // target's four components, light 4 in the second target's first.
    SphereOverPlane p;
    p.width = 320;
    p.height = 180;
    scene::Scene s = withASecondLightFrom40Degrees(p, 1.0);
    const double elevation[3] = {55.0, 70.0, 45.0}, azimuth[3] = {100.0, 200.0, 290.0}, intensity[3] = {0.8, 0.6, 1.2};
    for (int k = 0; k < 3; ++k) {
        scene::Light l = s.lights[1];
        l.direction = rotation(Vec3(0.0, 1.0, 0.0), azimuth[k]) * lightFromElevation(elevation[k]);
        l.intensity = intensity[k];
        s.lights.push_back(l);
    }
    expectEachLightsVisibilityAndTheirMean(p, s, 2, "five-lights");
}

// Light 0's visibility at pixel i in `a` (one light) against `b` (light 0 and a dim one):
// `differ` counts pixels more than 1e-3 apart, `worst` is the largest difference among the rest.
struct LightZeroAgreement {
    std::size_t differ = 0;
    double worst = 0.0;
    void add(const scene::Frame& a, const scene::Frame& b, std::size_t i) {
        const double d = std::abs(double(a.visibility[i]) - double(b.lightVisibility[0][i]));
        if (d <= 1e-3) worst = std::max(worst, d);
        differ += d > 1e-3;
    }
};

// The scene `one` rendered alone and with `dim` added (a second light takes lit.frag from the one
// light's baked matrix, cascade 0's constants, to every light's baked values, each light's own
// slots), normal offset 1.5 texels.
std::pair<scene::Frame, scene::Frame> aloneAndWithADimLight(const scene::Scene& one, const scene::Light& dim,
                                                            scene::RasterSettings settings) {
    settings.normalOffset = 1.5;
    scene::Scene two = one;
    two.lights.push_back(dim);
    std::pair<scene::Frame, scene::Frame> frames{renderValidated(one, settings, "one light"),
                                                 renderValidated(two, settings, "two lights")};
    return frames;
}

// The sphere over the plane at 320x180 under a directional light 50° above the plane, the whole
// scene moved by (offset, 0, −offset).
scene::Scene sunAt50Degrees(double offset) {
    SphereOverPlane p;
    p.width = 320;
    p.height = 180;
    p.lightDirection = lightFromElevation(50.0);
    return makeScene(p, Vec3(offset, 0.0, -offset));
}

// A spot at (2.5, 3, 1.5) + shift aimed past the sphere of sunAt50Degrees (moved by the same shift)
// onto the plane: a second light whose shadow falls apart from the sun's. Intensity 200, cone 45°.
scene::Light spotOverTheSphere(const Vec3& shift = Vec3(0.0)) {
    scene::Light spot;
    spot.type = scene::LightType::Spot;
    spot.position = Vec3(2.5, 3.0, 1.5) + shift;
    spot.direction = glm::normalize(Vec3(-2.5, -2.2, -1.5));
    spot.coneAngleDegrees = 45.0;
    spot.intensity = 200.0;
    return spot;
}

TEST(RasterRender, OneMapLightsBakedMatrixMatchesEveryLightsBakedValues) {
    // With one directional light lit.frag forms the map coordinates with that light's matrix as
    // the one-map light's baked rows (kOneMapLight: cascade 0's constants, packLightConstants);
    // with a second light, with every light's baked values (each light's own slots, the *_every
    // modules). Both multiply the normal-offset point by toShadow per fragment, so light 0's
    // visibility must agree between the two (the second light is a dim copy from elsewhere, so
    // light 0's map is the same), near the origin and 10^7 units from it (camera-relative floats),
    // with the normal offset on and a slope bias small enough that the offset decides the shadow's
    // edge: a row or column of either packing out of place moves the shadow. The bounds leave room
    // for Mesa's NIR folding the two modules' constants into their arithmetic in different orders
    // (rounding at the map coordinates' scale, ≈1e-7 of the map): pcf2x2's bilinear weights may move
    // by that much, and at most a few edge texels may flip.
    for (const double offset : {0.0, 1.0e7})
        for (ShadowFilter filter : {ShadowFilter::None, ShadowFilter::Pcf2x2, ShadowFilter::Poisson}) {
            scene::Scene one = sunAt50Degrees(offset);
            scene::Light dim = one.lights[0];
            dim.direction = lightFromElevation(70.0);
            dim.intensity = 0.1;
            const auto [a, b] = aloneAndWithADimLight(one, dim, validatedSettings(512, 0.002, 0.1, filter));
            ASSERT_EQ(b.lightVisibility.size(), 2u);
            std::size_t lit = 0, shadowed = 0;
            LightZeroAgreement agree;
            for (std::size_t i = 0; i < a.pixelCount(); ++i) {
                if (a.objectId[i] == 0.0f) continue;
                ASSERT_EQ(a.objectId[i], b.objectId[i]);
                agree.add(a, b, i);
                lit += a.visibility[i] > 0.99f;
                shadowed += a.visibility[i] < 0.01f;
            }
            EXPECT_GT(shadowed, 500u) << "the sphere shadows the plane";
            EXPECT_GT(lit, 10000u);
            EXPECT_LE(agree.differ, 3u) << "offset " << offset << ", filter " << int(filter);
            EXPECT_LE(agree.worst, 2e-4) << "offset " << offset << ", filter " << int(filter);
        }
}

TEST(RasterRender, OneSpotsBakedMatrixMatchesEveryLightsBakedValues) {
    // The same comparison for one spot light: alone, its matrix's first three rows are cascade 0's
    // constants and its last row (the perspective divide's w) rides in the light slots' spare
    // components; with a second (dim) spot, every light's values are baked in their own slots.
    // Both multiply the normal-offset point by toShadow per fragment and divide by w, so light 0's
    // visibility must agree up to the rounding of constants folded in different orders: the divided
    // (u, v) ≈1e-7 of the map, < 1e-4 of a 512² texel, so pcf2x2's weights move by ≲ 1e-4 and at
    // most a few edge texels may flip. The spot shines at ≈40° to the plane, so the offset (along
    // the plane's normal) moves u, v as well as the axial distance; PCSS (a light of radius 0.1)
    // also takes the axial distance and the texel size into its blocker search and kernel width.
    // Near the origin and 10^7 units away.
    // The closed form (the unshifted scene: the pixels see the same) counts the plane pixels well
    // inside the cone whose segment to the light meets the sphere, so the comparison covers a shadow.
    const SphereOverPlane base{.width = 320, .height = 180};
    const scene::CameraBasis cam = scene::cameraBasis(makeScene(base).camera);
    const Vec3 spotPosition(2.5, 3.0, 1.5), spotDirection = glm::normalize(Vec3(-2.5, -2.2, -1.5));
    const double cone = 45.0;
    for (const double offset : {0.0, 1.0e7})
        for (const ShadowFilter filter :
             {ShadowFilter::None, ShadowFilter::Pcf2x2, ShadowFilter::Poisson, ShadowFilter::Pcss}) {
            SphereOverPlane p = base;
            const Vec3 shift(offset, 0.0, -offset);
            scene::Scene one = makeScene(p, shift);
            scene::Light& spot = one.lights[0];
            spot.type = scene::LightType::Spot;
            spot.position = spotPosition + shift;
            spot.direction = spotDirection;
            spot.coneAngleDegrees = cone;
            spot.radius = 0.1;
            spot.intensity = 300.0;
            scene::Light dim = one.lights[0];
            dim.position = Vec3(-2.0, 5.0, 1.0) + shift;
            dim.direction = glm::normalize(Vec3(0.4, -1.0, -0.2));
            dim.intensity = 30.0;
            const auto [a, b] = aloneAndWithADimLight(one, dim, validatedSettings(512, 0.004, 0.1, filter));
            ASSERT_EQ(b.lightVisibility.size(), 2u);
            std::size_t lit = 0, shadowedInCone = 0;
            LightZeroAgreement agree;
            for (int y = 0; y < a.height; ++y)
                for (int x = 0; x < a.width; ++x) {
                    const std::size_t i = at(a, x, y);
                    if (a.objectId[i] == 0.0f) continue;
                    ASSERT_EQ(a.objectId[i], b.objectId[i]);
                    agree.add(a, b, i);
                    lit += a.visibility[i] > 0.99f;
                    const PrimaryHit h = primaryHit(base, cam, x, y);
                    const Vec3 toLight = spotPosition - h.p;
                    if (h.id == 2 &&
                        glm::dot(-glm::normalize(toLight), spotDirection) > std::cos(cone * kPi / 180.0) + 0.01) {
                        const auto t = raySphere(h.p, toLight, base.center, base.radius);
                        shadowedInCone += t && *t < 1.0;
                    }
                }
            EXPECT_GT(shadowedInCone, 500u) << "the sphere shadows the plane inside the cone";
            EXPECT_GT(lit, 10000u);
            EXPECT_LE(agree.differ, 3u) << "offset " << offset << ", filter " << int(filter);
            EXPECT_LE(agree.worst, 2e-4) << "offset " << offset << ", filter " << int(filter);
        }
}

TEST(RasterRender, OneLightKeepsNoPerLightVisibility) {
    const scene::Scene s = makeScene(SphereOverPlane{});
    const scene::Frame f = renderValidated(s, validatedSettings(256, 0.01, 1.0, ShadowFilter::None), "one-light");
    EXPECT_TRUE(f.lightVisibility.empty());
}

TEST(RasterRenderer, RepeatedFramesAreIdenticalAndPayTheSetupOnce) {
    // A Renderer renders the same scene again: the same pixels, "setup" only in the first frame.
    const scene::Scene s = makeScene(SphereOverPlane{});
    const scene::RasterSettings settings = validatedSettings(512, 0.01, 1.0, ShadowFilter::Pcf2x2);
    Renderer renderer(s, planFor(s, settings), settings);
    const scene::Frame first = renderer.render();
    const scene::Frame second = renderer.render();
    EXPECT_GT(first.timing("setup"), 0.0);
    EXPECT_EQ(second.timing("setup"), 0.0);
    EXPECT_GE(renderer.setupMs(), 0.0);
    EXPECT_EQ(first.beauty, second.beauty);
    EXPECT_EQ(first.visibility, second.visibility);
    EXPECT_EQ(first.objectId, second.objectId);
    EXPECT_EQ(first.blockerId, second.blockerId);
    EXPECT_EQ(second.attributes.at("validation_messages"), "0");
    EXPECT_EQ(renderer.validationMessages(), 0);
}

TEST(RasterRenderer, ChannelsNotAskedForAreLeftOutAndTheRestIsUnchanged) {
    // Beauty only (`render -o x.png`): the depth-only shadow pass and the lit variant without
    // blocker ids must give exactly the pixels of a full render; the other AOVs stay empty.
    // Visibility + ids without blocker ids: the same visibility too.
    const scene::Scene s = withASecondLightFrom40Degrees(SphereOverPlane{});
    for (ShadowFilter filter : {ShadowFilter::None, ShadowFilter::Pcf2x2, ShadowFilter::Pcf, ShadowFilter::Poisson}) {
        scene::RasterSettings settings = validatedSettings(512, 0.01, 1.0, filter);
        settings.pcfSize = 3;
        Renderer renderer(s, planFor(s, settings), settings);
        const scene::Frame all = renderer.render(scene::kAllChannels);
        const scene::Frame beauty = renderer.render(scene::kChannelBeauty);
        const scene::Frame noIds =
            renderer.render(scene::kChannelVisibility | scene::kChannelObjectId | scene::kChannelLightVisibility);
        ASSERT_EQ(all.beauty.size(), 3 * all.pixelCount());
        EXPECT_EQ(beauty.beauty, all.beauty) << "filter " << int(filter);
        EXPECT_TRUE(beauty.visibility.empty() && beauty.objectId.empty() && beauty.ndotl.empty() &&
                    beauty.depth.empty() && beauty.blockerId.empty() && beauty.lightVisibility.empty());
        EXPECT_EQ(noIds.visibility, all.visibility) << "filter " << int(filter);
        EXPECT_EQ(noIds.objectId, all.objectId);
        EXPECT_EQ(noIds.lightVisibility, all.lightVisibility);
        EXPECT_TRUE(noIds.beauty.empty() && noIds.blockerId.empty() && noIds.depth.empty());
        EXPECT_GT(std::count(all.blockerId.begin(), all.blockerId.end(), 1.0f), 0) << "the sphere blocks somewhere";
        EXPECT_EQ(renderer.validationMessages(), 0);
    }
}

TEST(RasterRenderer, DisplayFramesGiveThePngCodesOfTheFloatBeautyWithinOne) {
    // `render -o x.png` (kBeautyForDisplay): lavapipe renders into an 8-bit sRGB target and the
    // Frame holds the decoded codes. The same shading as the float beauty, so the PNG codes may
    // differ only where the device's sRGB encoding and the writer's (float pow, round to nearest)
    // round the same value to neighbouring codes: by one code at most, and rarely; the
    // background (a clear, converted by the device) and black are exact.
    scene::Scene s = withASecondLightFrom40Degrees(SphereOverPlane{});
    s.lights[1].color = {0.3, 0.6, 0.9};
    s.background = {0.05, 0.1, 0.2};
    for (int lights : {1, 2})
        for (ShadowFilter filter : {ShadowFilter::None, ShadowFilter::Pcf2x2, ShadowFilter::Poisson}) {
            scene::Scene sc = s;
            sc.lights.resize(std::size_t(lights));
            const scene::RasterSettings settings = validatedSettings(512, 0.01, 1.0, filter);
            Renderer renderer(sc, planFor(sc, settings), settings);
            const scene::Frame all = renderer.render(scene::kAllChannels);
            const scene::Frame display = renderer.render(scene::kChannelBeauty | scene::kBeautyForDisplay);
            EXPECT_EQ(display.attributes.at("beauty_precision"), "srgb8");
            EXPECT_EQ(all.attributes.count("beauty_precision"), 0u);
            ASSERT_EQ(display.beauty.size(), all.beauty.size());
            EXPECT_TRUE(display.visibility.empty() && display.objectId.empty() && display.depth.empty() &&
                        display.lightVisibility.empty());
            std::size_t off = 0, lit = 0;
            for (std::size_t i = 0; i < all.beauty.size(); ++i) {
                const int want = scene::linearToSrgbCode(all.beauty[i]);
                const int got = scene::linearToSrgbCode(display.beauty[i]);
                ASSERT_LE(std::abs(got - want), 1) << "value " << all.beauty[i] << " at " << i;
                off += got != want;
                lit += all.objectId[i / 3] != 0.0f && want > 16;
                if (all.objectId[i / 3] == 0.0f) {
                    ASSERT_EQ(got, want) << "background at " << i;
                }
                if (want == 0) {
                    ASSERT_EQ(got, 0) << "black at " << i;
                }
                // The decoded value is the linear value of its code, not a rounding of it.
                ASSERT_EQ(display.beauty[i], scene::srgbCodeToLinear(std::uint8_t(got)));
            }
            EXPECT_GT(lit, all.beauty.size() / 4) << "the objects are mostly dark: the test would show little";
            // (Measured on Mesa 22.3.6: 12-14 of 43,200 values, 0.03%.)
            EXPECT_LT(double(off), 0.005 * double(all.beauty.size())) << lights << " lights, filter " << int(filter);
            EXPECT_EQ(renderer.validationMessages(), 0);
        }
    // Where the float targets are copied (real GPUs) there is no display target: the float
    // beauty, and the PNG codes exactly those of a full render.
    const scene::RasterSettings settings = validatedSettings(512, 0.01, 1.0, ShadowFilter::Pcf2x2);
    Renderer copied(s, planFor(s, settings), settings, RendererOptions{.readTargetsInPlace = false});
    const scene::Frame c = copied.render(scene::kChannelBeauty | scene::kBeautyForDisplay);
    EXPECT_EQ(c.attributes.count("beauty_precision"), 0u);
    EXPECT_EQ(c.beauty, copied.render(scene::kAllChannels).beauty);
    // Asking for visibility as well keeps the float target (the sRGB target has no room for it).
    Renderer renderer(s, planFor(s, settings), settings);
    const scene::Frame v =
        renderer.render(scene::kChannelBeauty | scene::kChannelVisibility | scene::kBeautyForDisplay);
    EXPECT_EQ(v.attributes.count("beauty_precision"), 0u);
    EXPECT_EQ(v.visibility.size(), v.pixelCount());
    EXPECT_EQ(renderer.validationMessages(), 0);
    EXPECT_EQ(copied.validationMessages(), 0);
}

TEST(RasterRenderer, RenderingIntoTheFrameReadingTheTargetsInPlaceAndCopyingThemGiveTheSameFrame) {
    // On lavapipe the lit pass renders each channel asked for straight into the Frame's vector
    // (images over its memory); without that it reads its own targets in place; other devices
    // copy them into buffers. All three paths, on lavapipe, for several channel sets, with two
    // lights (per-light targets too), into a new Frame and into one reused with other channels
    // before (its vectors keep their memory, or are reallocated, between frames). 160x90: the
    // driver pads a linear image's rows to a multiple of 4, beyond the 90 of the Frame, which
    // the Frame's vector must hold room for.
    const scene::Scene s = withASecondLightFrom40Degrees(SphereOverPlane{});
    const scene::RasterSettings settings = validatedSettings(512, 0.01, 1.0, ShadowFilter::Pcf2x2);
    Renderer intoFrame(s, planFor(s, settings), settings);
    Renderer inPlace(s, planFor(s, settings), settings, RendererOptions{.renderIntoFrame = false});
    Renderer copied(s, planFor(s, settings), settings, RendererOptions{.readTargetsInPlace = false});
    scene::Frame reused;
    for (scene::ChannelMask channels :
         {scene::kAllChannels, scene::kChannelBeauty, scene::kChannelVisibility | scene::kChannelDepth,
          scene::kAllChannels, scene::kChannelObjectId | scene::kChannelBlockerId}) {
        const scene::Frame f = intoFrame.render(channels);
        intoFrame.render(reused, channels);
        const scene::Frame a = inPlace.render(channels);
        const scene::Frame c = copied.render(channels);
        EXPECT_EQ(f.attributes.at("readback"), "into-frame");
        EXPECT_EQ(reused.attributes.at("readback"), "into-frame");
        EXPECT_EQ(a.attributes.at("readback"), "in-place");
        EXPECT_EQ(c.attributes.at("readback"), "copy");
        test::expectSamePixels(f, a, "into a new Frame");
        test::expectSamePixels(reused, a, "into a reused Frame");
        test::expectSamePixels(c, a, "copied");
        // What was asked for, and only that.
        EXPECT_EQ(a.beauty.size(), channels & scene::kChannelBeauty ? 3 * a.pixelCount() : 0u);
        EXPECT_EQ(a.depth.size(), channels & scene::kChannelDepth ? a.pixelCount() : 0u);
        EXPECT_EQ(a.blockerId.size(), channels & scene::kChannelBlockerId ? a.pixelCount() : 0u);
    }
    // A moved camera: Z is measured from the new camera while the geometry stays relative to the
    // first one, so the readback adds the difference to every covered pixel's Z (the background's
    // stays 0), with the object ids from the Frame or, when they are not asked for, the target.
    scene::Scene moved = s;
    moved.camera.position += scene::Vec3(0.3, 0.2, -0.5);
    for (Renderer* r : {&intoFrame, &inPlace, &copied}) r->update(moved);
    const scene::Frame all = inPlace.render(scene::kAllChannels);
    const scene::Frame fresh = render(moved, planFor(moved, settings), settings);
    for (scene::ChannelMask channels : {scene::kAllChannels, scene::kChannelDepth}) {
        EXPECT_EQ(intoFrame.render(channels).depth, all.depth);
        EXPECT_EQ(inPlace.render(channels).depth, all.depth);
        EXPECT_EQ(copied.render(channels).depth, all.depth);
    }
    std::size_t background = 0, compared = 0;
    for (std::size_t i = 0; i < all.pixelCount(); ++i) {
        if (all.objectId[i] == 0.0f) {
            ++background;
            EXPECT_EQ(all.depth[i], 0.0f) << i;
        } else if (all.objectId[i] == fresh.objectId[i]) {
            // The Z of a renderer made for the moved camera, to the float rounding of the offset.
            ++compared;
            EXPECT_NEAR(all.depth[i], fresh.depth[i], 1e-5f * std::max(1.0f, fresh.depth[i])) << i;
        }
    }
    EXPECT_GT(background, 0u) << "the test would not see the background's Z";
    EXPECT_GT(compared, all.pixelCount() / 2);
    EXPECT_EQ(intoFrame.validationMessages(), 0);
    EXPECT_EQ(inPlace.validationMessages(), 0);
    EXPECT_EQ(copied.validationMessages(), 0);
}

TEST(RasterRenderer, ANewFrameHoldsTheBackgroundAndAReusedOneGetsTheBackgroundPass) {
    // Where every lit-pass attachment is a new plane of the Frame (or a per-light target before
    // its first frame, zeroed on the host), the planes' zeros (resize() value-initializes) with the
    // beauty set to the background color are the background, and the background pipeline is not
    // drawn; into a reused Frame (here holding NaN everywhere, so that a pixel left unwritten
    // shows), into per-light targets a frame has written and into the Renderer's own targets
    // read back by copies it is. All give the same frame bit for bit, and the background pixels
    // are the scene's color with zero AOVs, each light's visibility too (the background pass's
    // values, docs/raster.md). Black (nothing to fill) and a color; all channels and the float
    // beauty; one light and two (per-light targets); and a new Frame after the camera moved, so
    // that pixels the targets last held objects in are background now.
    const float nan = std::numeric_limits<float>::quiet_NaN();
    for (const scene::Vec3& color : {scene::Vec3(0.0, 0.0, 0.0), scene::Vec3(0.05, 0.1, 0.2)})
        for (int lights : {1, 2}) {
            scene::Scene s = withASecondLightFrom40Degrees(SphereOverPlane{});
            s.lights.resize(std::size_t(lights));
            s.background = color;
            const scene::RasterSettings settings = validatedSettings(512, 0.01, 1.0, ShadowFilter::Pcf2x2);
            Renderer renderer(s, planFor(s, settings), settings);
            Renderer copied(s, planFor(s, settings), settings, RendererOptions{.readTargetsInPlace = false});
            for (scene::ChannelMask channels : {scene::kAllChannels, scene::kChannelBeauty}) {
                RenderDebug fromNew, fromReused, fromCopied;
                const scene::Frame fresh = renderer.render(channels, &fromNew);
                EXPECT_TRUE(fromNew.backgroundFromFrame);
                scene::Frame reused;
                for (std::vector<float>* v : {&reused.beauty, &reused.visibility, &reused.objectId, &reused.ndotl,
                                              &reused.depth, &reused.blockerId})
                    v->assign(fresh.pixelCount() * (v == &reused.beauty ? 3 : 1), nan);
                renderer.render(reused, channels, &fromReused);
                EXPECT_FALSE(fromReused.backgroundFromFrame);
                const scene::Frame c = copied.render(channels, &fromCopied);
                EXPECT_FALSE(fromCopied.backgroundFromFrame);
                test::expectSamePixels(reused, fresh, "into a reused Frame");
                test::expectSamePixels(c, fresh, "copied");
                if (channels != scene::kAllChannels) continue;
                std::size_t background = 0;
                for (std::size_t i = 0; i < fresh.pixelCount(); ++i) {
                    if (fresh.objectId[i] != 0.0f) continue;
                    ++background;
                    for (int k = 0; k < 3; ++k) ASSERT_EQ(fresh.beauty[3 * i + k], float(color[k])) << i;
                    ASSERT_EQ(fresh.visibility[i], 0.0f) << i;
                    ASSERT_EQ(fresh.ndotl[i], 0.0f) << i;
                    ASSERT_EQ(fresh.depth[i], 0.0f) << i;
                    ASSERT_EQ(fresh.blockerId[i], 0.0f) << i;
                    for (const std::vector<float>& light : fresh.lightVisibility) ASSERT_EQ(light[i], 0.0f) << i;
                }
                EXPECT_GT(background, 0u) << "the test would not see the background";
                EXPECT_LT(background, fresh.pixelCount() / 2) << "nor the objects";
                EXPECT_EQ(fresh.lightVisibility.size(), lights == 1 ? 0u : 2u);
            }
            // The camera turned aside: the per-light targets hold the last frame's objects where
            // the new frame's background is, so a new Frame gets the background pass with two lights.
            const scene::Frame before = renderer.render(scene::kAllChannels);
            scene::Scene turned = s;
            turned.camera.lookAt += scene::Vec3(3.0, 0.0, 0.0);
            renderer.update(turned);
            copied.update(turned);
            RenderDebug afterTurn;
            const scene::Frame moved = renderer.render(scene::kAllChannels, &afterTurn);
            EXPECT_EQ(afterTurn.backgroundFromFrame, lights == 1);
            test::expectSamePixels(moved, copied.render(scene::kAllChannels), "after the camera turned, copied");
            std::size_t litBefore = 0;  // background now, a lit object in the targets' last frame
            for (std::size_t i = 0; i < moved.pixelCount(); ++i) {
                if (moved.objectId[i] != 0.0f) continue;
                for (std::size_t k = 0; k < moved.lightVisibility.size(); ++k) {
                    ASSERT_EQ(moved.lightVisibility[k][i], 0.0f) << i;
                    litBefore += before.lightVisibility[k][i] != 0.0f;
                }
            }
            if (lights == 2) EXPECT_GT(litBefore, 100u) << "the turn must uncover pixels the targets held lit";
            // A Frame with one plane from before and the others new: the pass draws the background.
            scene::Frame mixed = renderer.render(scene::kChannelBeauty);
            RenderDebug fromMixed;
            renderer.render(mixed, scene::kAllChannels, &fromMixed);
            EXPECT_FALSE(fromMixed.backgroundFromFrame);
            const scene::Frame all = renderer.render(scene::kAllChannels);
            EXPECT_EQ(mixed.beauty, all.beauty);
            EXPECT_EQ(mixed.objectId, all.objectId);
            EXPECT_EQ(mixed.depth, all.depth);
            EXPECT_EQ(renderer.validationMessages(), 0);
            EXPECT_EQ(copied.validationMessages(), 0);
        }
}

TEST(RasterRenderer, PerLightTargetsInReusedHeapMemoryStillGiveTheBackgroundZeroVisibility) {
    // A new Frame's first render takes its per-light targets' background from zeros the host
    // writes, not from fresh pages: the process keeps the heap a renderer freed for the next
    // (scene/memory.h), so a target may land on another frame's values. Here the heap holds NaN:
    // blocks under malloc's mmap threshold (raised to its maximum, so that the targets come from
    // the heap too), freed but for the highest, which keeps them off the heap's top. The test
    // checks that the target did take that memory.
#ifdef __SANITIZE_ADDRESS__
    GTEST_SKIP() << "AddressSanitizer's allocator is not glibc's";
#endif
    const SphereOverPlane p;
    const scene::Scene s = withASecondLightFrom40Degrees(p, 1.0);
    const std::size_t targetBytes = std::size_t(s.camera.width) * s.camera.height * 4 * sizeof(float);
    std::vector<float*> blocks((64u << 20) / targetBytes);  // well past what the Renderer takes first
    struct Heap {
        std::vector<float*>& blocks;
        // Setting either threshold ends glibc's dynamic thresholds in this process: these are
        // its initial values, for the tests after this one when they share the process.
        ~Heap() {
            for (float* b : blocks) std::free(b);
            ::mallopt(M_MMAP_THRESHOLD, 128 * 1024);
            ::mallopt(M_TRIM_THRESHOLD, 128 * 1024);
        }
    } heap{blocks};
    ASSERT_EQ(::mallopt(M_MMAP_THRESHOLD, 32 << 20), 1);
    ASSERT_EQ(::mallopt(M_TRIM_THRESHOLD, 1 << 30), 1);
    for (float*& b : blocks) {
        b = static_cast<float*>(std::malloc(targetBytes));
        ASSERT_NE(b, nullptr);
        std::fill(b, b + targetBytes / sizeof(float), std::numeric_limits<float>::quiet_NaN());
    }
    auto address = [](const void* q) { return reinterpret_cast<std::uintptr_t>(q); };
    std::swap(
        *std::max_element(blocks.begin(), blocks.end(), [&](float* x, float* y) { return address(x) < address(y); }),
        blocks.back());
    const std::uintptr_t lowest = address(
        *std::min_element(blocks.begin(), blocks.end(), [&](float* x, float* y) { return address(x) < address(y); }));
    const std::uintptr_t fence = address(blocks.back());
    for (std::size_t i = 0; i + 1 < blocks.size(); ++i) {
        std::free(blocks[i]);
        blocks[i] = nullptr;
    }
    const scene::RasterSettings settings = validatedSettings(512, 0.01, 1.0, ShadowFilter::Pcf2x2);
    Renderer renderer(s, planFor(s, settings), settings);
    RenderDebug debug;
    const scene::Frame f = renderer.render(scene::kAllChannels, &debug);
    ASSERT_GE(address(debug.lightTargetTexels), lowest) << "the target did not take the freed memory";
    ASSERT_LT(address(debug.lightTargetTexels), fence) << "the target did not take the freed memory";
    EXPECT_TRUE(debug.backgroundFromFrame);
    ASSERT_EQ(f.lightVisibility.size(), 2u);
    std::size_t background = 0;
    for (std::size_t i = 0; i < f.pixelCount(); ++i) {
        if (f.objectId[i] != 0.0f) continue;
        ++background;
        for (const std::vector<float>& light : f.lightVisibility) ASSERT_EQ(light[i], 0.0f) << i;
    }
    EXPECT_GT(background, 0u) << "the test would not see the background";
    EXPECT_EQ(renderer.validationMessages(), 0);
}

// `s` with a 1x1 alpha-masked checkered quad (half its texels cut out) `height` above the origin,
// facing up: an alpha-tested caster.
scene::Scene withAlphaLeaf(scene::Scene s, double height) {
    return withLeaf(std::move(s), height, alphaMaterial("leaf", scene::AlphaMode::Mask, checkerTexture(2, 1.0f, 0.0f)));
}

TEST(RasterRenderer, AlphaTestsThatCanNeverCutAreLeftOutAndTheFramesStayTheSame) {
    // A MASK material whose alpha never falls below its cutoff (no texture and a factor at or
    // above it, or a texture whose every texel passes) and a BLEND one never below the camera's
    // cutoff: their triangles take the pipelines without the alpha test, in the depth pass and the
    // lit pass, and the frames are the alpha-tested pipelines' bit for bit
    // (RendererOptions::idleAlphaTestsLeftOut false). Every channel of the all-channel,
    // float-beauty and display frames, each rendered twice (the second frame draws the lift-free
    // triangles, the plain leaf's among them, with their own pipeline); a sun, a spot and a point
    // light (their modules differ). The leaf hangs over the sphere, so its square shadows what lies
    // below. The textured BLEND leaf still needs its texels in the transmittance passes (1 −
    // opacity · alpha per texel), though the camera's test is left out; a MASK leaf that cannot
    // cut under a BLEND pane needs none.
    const scene::Scene sun = makeScene(SphereOverPlane{});
    const scene::Scene spot = withSpot(makeScene(SphereOverPlane{}), Vec3(2, 5, 2), Vec3(-2, -5, -2));
    const scene::Scene point = withPoint(makeScene(SphereOverPlane{}), Vec3(1.5, 5.0, 1.0));
    const scene::Material opaqueTexels = alphaMaterial("leaf", scene::AlphaMode::Mask, checkerTexture(2, 1.0f, 0.6f));
    scene::Material blend = alphaMaterial("leaf", scene::AlphaMode::Blend, nullptr);
    blend.opacity = 0.6;
    scene::Material semiMask = alphaMaterial("leaf", scene::AlphaMode::Mask, nullptr);
    semiMask.opacity = 0.6;
    scene::Material blendTexels = alphaMaterial("leaf", scene::AlphaMode::Blend, checkerTexture(2, 1.0f, 0.6f));
    blendTexels.opacity = 0.6;
    const std::tuple<const char*, scene::Scene> cases[] = {
        {"sun, MASK without a texture", withLeaf(sun, 2.0, alphaMaterial("leaf", scene::AlphaMode::Mask, nullptr))},
        {"sun, MASK with every texel above the cutoff", withLeaf(sun, 2.0, opaqueTexels)},
        {"sun, BLEND without a texture", withLeaf(sun, 2.0, blend)},
        {"sun, BLEND with every texel above the camera's cutoff", withLeaf(sun, 2.0, blendTexels)},
        // (no alpha data at all: the transmittance passes take their plain pipelines too)
        {"sun, MASK without a texture under a BLEND pane",
         withLeaf(withLeaf(sun, 2.5, blend), 2.0, alphaMaterial("leaf", scene::AlphaMode::Mask, nullptr))},
        // (drawn by the transmittance passes, which the alpha tests would put on their alpha shaders)
        {"sun, MASK of opacity 0.6 without a texture", withLeaf(sun, 2.0, semiMask)},
        {"spot, MASK with every texel above the cutoff", withLeaf(spot, 2.5, opaqueTexels)},
        {"point, MASK with every texel above the cutoff", withLeaf(point, 2.5, opaqueTexels)}};
    const scene::RasterSettings settings = validatedSettings(512, 0.01, 1.0, ShadowFilter::Pcf2x2);
    for (const auto& [what, s] : cases) {
        Renderer leftOut(s, planFor(s, settings), settings);
        Renderer tested(s, planFor(s, settings), settings, RendererOptions{.idleAlphaTestsLeftOut = false});
        for (const scene::ChannelMask channels :
             {scene::kAllChannels, scene::kChannelBeauty, scene::kChannelBeauty | scene::kBeautyForDisplay})
            for (int repeat = 0; repeat < 2; ++repeat) {
                RenderDebug testedDebug, leftOutDebug;
                const scene::Frame a = tested.render(channels, &testedDebug),
                                   b = leftOut.render(channels, &leftOutDebug);
                test::expectSamePixels(b, a, std::string(what) + ": without the alpha tests against with them");
                EXPECT_GT(testedDebug.alphaTestedLitTriangles, 0u) << what;
                EXPECT_EQ(leftOutDebug.alphaTestedLitTriangles, 0u) << what;
                if (channels != scene::kAllChannels || repeat > 0) continue;
                // Each Renderer makes the alpha data and shaders its plan names, and the plan
                // without the alpha tests none where no test can cut.
                const bool transmittance = planFor(s, settings).needsTransmittanceMap;
                const AlphaPlan plan = planAlpha(s, transmittance), all = planAlpha(s, transmittance, false);
                EXPECT_EQ(leftOutDebug.alphaData, plan.data) << what;
                EXPECT_EQ(leftOutDebug.transmittanceAlpha, plan.transmittanceReads) << what;
                EXPECT_EQ(testedDebug.alphaData, all.data) << what;
                EXPECT_EQ(testedDebug.transmittanceAlpha, all.transmittanceReads) << what;
                const scene::Material& leafMaterial = s.materials.back();
                const bool texturedBlend =
                    leafMaterial.alphaMode == scene::AlphaMode::Blend && leafMaterial.alphaTexture;
                const bool semiTransparentMask =
                    leafMaterial.alphaMode == scene::AlphaMode::Mask && !leafMaterial.opaque();
                EXPECT_EQ(plan.data, texturedBlend && transmittance) << what;
                EXPECT_EQ(all.transmittanceReads, transmittance && (texturedBlend || semiTransparentMask)) << what;
                // (the attribute names the depth pass's test: an opaque MASK caster's)
                const bool mask = s.materials.back().alphaMode == scene::AlphaMode::Mask && s.materials.back().opaque();
                EXPECT_EQ(a.attributes.count("alpha_casters"), mask ? 1u : 0u) << what;
                EXPECT_EQ(b.attributes.count("alpha_casters"), 0u) << what;
                std::size_t shadowedBelow = 0;  // the leaf (the highest id) shadows what lies under it
                const float leaf = *std::max_element(a.objectId.begin(), a.objectId.end());
                for (std::size_t i = 0; i < a.pixelCount(); ++i)
                    shadowedBelow += a.visibility[i] < 0.5f && a.objectId[i] != 0.0f && a.objectId[i] != leaf;
                EXPECT_GT(shadowedBelow, 100u) << what << ": the frame must hold the leaf's shadow";
            }
        EXPECT_EQ(leftOut.validationMessages(), 0) << what;
        EXPECT_EQ(tested.validationMessages(), 0) << what;
    }
    // Where a texel can cut, the tests stay: the checkered leaf is alpha-tested in both passes.
    const scene::Scene cut = withAlphaLeaf(sun, 2.0);
    Renderer renderer(cut, planFor(cut, settings), settings);
    RenderDebug debug;
    EXPECT_EQ(renderer.render(scene::kAllChannels, &debug).attributes.count("alpha_casters"), 1u);
    EXPECT_GT(debug.alphaTestedLitTriangles, 0u);
}

TEST(RasterRenderer, AnUntexturedBlendCastersTransmittanceIsItsConstantUnderTheAlphaShadersToo) {
    // A BLEND pane of opacity 0.6 lets float(1 − 0.6) = 0.40000001 through, rounded once from
    // double as the plain transmittance shaders write it. A textured BLEND leaf under the ground
    // (seen by no one, shadowing nothing in view) puts the transmittance passes on their alpha
    // shaders, where the float product 1 − 0.6f would give 0.39999998; the same leaf untextured
    // does not. The frames must be the same bit for bit: the pane's shadow does not depend on
    // which shaders some other caster needs.
    scene::Material pane = alphaMaterial("pane", scene::AlphaMode::Blend, nullptr);
    pane.opacity = 0.6;
    auto withHiddenLeaf = [&](std::shared_ptr<const scene::AlphaTexture> texels) {
        scene::Scene s = withLeaf(makeScene(SphereOverPlane{}), 2.5, pane);
        scene::Material leaf = alphaMaterial("leaf", scene::AlphaMode::Blend, std::move(texels));
        leaf.opacity = 0.5;
        return withLeaf(s, -3.0, leaf);
    };
    const scene::Scene textured = withHiddenLeaf(checkerTexture(2, 1.0f, 0.6f)), plain = withHiddenLeaf(nullptr);
    const scene::RasterSettings settings = validatedSettings(512, 0.01, 1.0, ShadowFilter::Pcf2x2);
    Renderer withAlpha(textured, planFor(textured, settings), settings);
    Renderer without(plain, planFor(plain, settings), settings);
    RenderDebug alphaDebug, plainDebug;
    const scene::Frame a = withAlpha.render(scene::kAllChannels, &alphaDebug);
    const scene::Frame b = without.render(scene::kAllChannels, &plainDebug);
    ASSERT_TRUE(alphaDebug.transmittanceAlpha);
    ASSERT_FALSE(plainDebug.transmittanceAlpha);
    test::expectSamePixels(a, b, "with the alpha shaders against without");
    const float constant = float(1.0 - 0.6);
    ASSERT_NE(constant, 1.0f - 0.6f);
    EXPECT_GT(std::count(b.visibility.begin(), b.visibility.end(), constant), 100)
        << "the frame must hold the pane's shadow";
    EXPECT_EQ(withAlpha.validationMessages(), 0);
    EXPECT_EQ(without.validationMessages(), 0);
}

TEST(RasterRenderer, SizeOptimizedOneLightModulesGiveTheGeneralModulesFramesBitForBit) {
    // One light with none or pcf2x2 gets its kind's modules (*_sun, *_spot, *_point: constants
    // fixed in the source, spirv-opt's size passes); the general *_taps modules, built with the same
    // size passes, are the reference: every channel of the all-channel, float-beauty and display
    // frames the same, bit for bit. A sun with one map (*_sun_map) and with three cascades and blend
    // bands (*_sun), a spot, a point light; filter none, a normal offset, and an alpha-tested caster
    // (the *_alpha_* modules, and the beauty-only modules without the object id input).
    scene::Scene cascaded = makeLongPlane();
    scene::RasterSettings cascades = validatedSettings(512, 0.0, 1.0, ShadowFilter::Pcf2x2);
    cascades.depthBias = scene::defaultDepthBias(cascaded, 512);
    cascades.cascades = 3;
    cascades.cascadeBlend = 0.3;
    const scene::Scene sun = makeScene(SphereOverPlane{});
    const scene::Scene point = withPoint(makeScene(SphereOverPlane{}), Vec3(1.5, 5.0, 1.0));
    const scene::Scene spot = withSpot(makeScene(SphereOverPlane{}), Vec3(2, 5, 2), Vec3(-2, -5, -2));
    scene::RasterSettings offset = validatedSettings(512, 0.01, 1.0, ShadowFilter::Pcf2x2);
    offset.normalOffset = 1.0;
    const scene::RasterSettings pcf2x2 = validatedSettings(512, 0.01, 1.0, ShadowFilter::Pcf2x2);
    const scene::RasterSettings none = validatedSettings(512, 0.01, 1.0, ShadowFilter::None);
    const std::tuple<const char*, scene::Scene, scene::RasterSettings> cases[] = {
        {"sun pcf2x2", sun, pcf2x2},
        {"sun none", sun, none},
        {"sun normal offset", sun, offset},
        {"sun cascades", cascaded, cascades},
        {"sun alpha-tested caster", withAlphaLeaf(sun, 2.0), pcf2x2},
        {"spot pcf2x2", spot, pcf2x2},
        {"spot none", spot, none},
        {"spot normal offset", spot, offset},
        {"spot alpha-tested caster", withAlphaLeaf(spot, 2.5), pcf2x2},
        {"point pcf2x2", point, pcf2x2},
        {"point none", point, none},
        {"point normal offset", point, offset},
        {"point alpha-tested caster", withAlphaLeaf(point, 2.5), pcf2x2}};
    for (const auto& [what, s, settings] : cases) {
        Renderer sized(s, planFor(s, settings), settings);
        Renderer general(s, planFor(s, settings), settings, RendererOptions{.oneLightModules = false});
        for (const scene::ChannelMask channels :
             {scene::kAllChannels, scene::kChannelBeauty, scene::kChannelBeauty | scene::kBeautyForDisplay}) {
            const scene::Frame a = general.render(channels), b = sized.render(channels);
            test::expectSamePixels(b, a, std::string(what) + ": size-optimized against general modules");
            if (channels != scene::kAllChannels) continue;
            std::size_t shadowed = 0;
            for (std::size_t i = 0; i < a.visibility.size(); ++i)
                shadowed += a.visibility[i] < 0.5f && a.objectId[i] != 0.0f;
            EXPECT_GT(shadowed, 100u) << what << ": the frame must hold a shadow";
        }
        EXPECT_EQ(sized.validationMessages(), 0) << what;
        EXPECT_EQ(general.validationMessages(), 0) << what;
    }
}

TEST(RasterRenderer, SetBiasesDrawsWhatANewRendererGivenThoseBiasesDraws) {
    // A bias search renders its points with one Renderer (setBiases): each frame must be the one a
    // new Renderer made with those biases draws, bit for bit, although the layers' culling margin,
    // the lit pipelines' baked constants and their normal-offset path (the slope bias's lift past
    // its cap; none with slope 0) all follow the biases. One sun with one map (the *_sun modules,
    // lift-free draws), three cascades (per-cascade biases), a spot with a wide kernel (the
    // general modules), a sun 4° above the ground with its constants read from the uniform buffer
    // and no slope bias at first (its pipelines are not baked and have no normal-offset path, which
    // the ground needs once a slope bias lifts it past the cap: only setBiases() makes them
    // again); each through a sequence that switches the slope bias off and on again.
    const scene::Scene spot = withSpot(sunAt50Degrees(0.0), Vec3(2.5, 3.0, 1.5), Vec3(-2.5, -2.2, -1.5));
    scene::RasterSettings cascades = validatedSettings(512, 0.01, 1.0, ShadowFilter::Pcf2x2);
    cascades.cascades = 3;
    SphereOverPlane grazing;
    grazing.lightDirection = Vec3(-1.0, -0.07, 0.0);  // 4° above the ground: past the slope cap
    // A low sphere: its shadow begins in view, 0.7 past it, and the lift moves where it begins (a
    // renderer that kept the pipelines without the lift draws it elsewhere).
    grazing.center = Vec3(0, 0.3, 0);
    grazing.radius = 0.25;
    const scene::Scene lowSun = makeScene(grazing);
    struct Case {
        scene::Scene scene;
        scene::RasterSettings settings;
        LightConstants constants = LightConstants::kSpecialization;
    };
    const Case cases[] = {
        {sunAt50Degrees(0.0), validatedSettings(512, 0.01, 1.0, ShadowFilter::Pcf2x2)},
        {lowSun, validatedSettings(512, 0.01, 0.0, ShadowFilter::Pcf2x2), LightConstants::kUniformBuffer},
        {makeLongPlane(), cascades},
        {spot, validatedSettings(512, 0.01, 1.0, ShadowFilter::Pcf)}};
    const std::pair<double, double> biases[] = {{0.0, 0.0}, {0.05, 4.0}, {0.002, 0.0}, {0.01, 1.0}};
    for (const auto& [s, first, constants] : cases) {
        const RendererOptions options{.lightConstants = constants};
        Renderer reused(s, planFor(s, first), first, options);
        const scene::Frame before = reused.render();
        bool anyDiffers = false;
        for (const auto& [depth, slope] : biases) {
            scene::RasterSettings settings = first;
            settings.depthBias = depth;
            settings.slopeBias = slope;
            const std::string what = s.lights[0].type == scene::LightType::Spot ? "spot" : "sun";
            reused.setBiases(s, depth, slope);
            const scene::Frame f = reused.render();
            Renderer fresh(s, planFor(s, settings), settings, options);
            const scene::Frame expected = fresh.render();
            const std::string at = what + ", depth " + std::to_string(depth) + ", slope " + std::to_string(slope);
            test::expectSamePixels(f, expected, at);
            const auto attribute = [](const scene::Frame& frame, const char* key) {
                const auto it = frame.attributes.find(key);
                return it == frame.attributes.end() ? std::string("(none)") : it->second;
            };
            for (const char* key : {"depth_bias", "slope_bias", "light_constants", "culled_casters"})
                EXPECT_EQ(attribute(f, key), attribute(expected, key)) << at << ": " << key;
            anyDiffers = anyDiffers || f.visibility != before.visibility;
            EXPECT_EQ(fresh.validationMessages(), 0);
        }
        EXPECT_TRUE(anyDiffers) << "the biases change the shadows";
        EXPECT_EQ(reused.validationMessages(), 0);
    }
}

// The frames of three renderers for the same channels: one reading light 0's constants from the
// uniform buffer, one taking them as flat outputs of the vertex shader, one with them baked into
// its pipelines as specialization constants.
std::array<scene::Frame, 3> withEveryLightConstantSource(const scene::Scene& s, const scene::RasterSettings& settings,
                                                         scene::ChannelMask channels) {
    std::array<scene::Frame, 3> frames;
    const LightConstants sources[3] = {LightConstants::kUniformBuffer, LightConstants::kVertexOutputs,
                                       LightConstants::kSpecialization};
    for (int i = 0; i < 3; ++i) {
        Renderer r(s, planFor(s, settings), settings, RendererOptions{.lightConstants = sources[i]});
        frames[std::size_t(i)] = r.render(channels);
        EXPECT_EQ(r.validationMessages(), 0);
    }
    return frames;
}

TEST(RasterRenderer, LightConstantsFromTheVertexShaderOrBakedInGiveTheSameFrameBitForBit) {
    // lit.frag can read the one light's constants (direction or position, radiance, biases,
    // filter parameters, a spot's cone and size), the ambient and the map side from the uniform
    // buffer, as flat inputs from lit.vert or as specialization constants (shaders/lit_constants.glsl).
    // Each carries the same floats into the same arithmetic, so every channel must be the same bit
    // for bit: a field passed wrongly or not at all (a zero) changes shadows, shading or both, and a
    // compiler that folded the constants into the arithmetic in another order would change bits. One
    // directional light and one spot, the normal offset on (its code reads the most fields),
    // every filter the light kind has, near the origin and 10^7 units away; the PNG's display
    // target too.
    for (const double offset : {0.0, 1.0e7})
        for (const bool spot : {false, true})
            for (const ShadowFilter filter : {ShadowFilter::None, ShadowFilter::Pcf2x2, ShadowFilter::Pcf,
                                              ShadowFilter::Poisson, ShadowFilter::Pcss}) {
                if (filter == ShadowFilter::Pcss && !spot) continue;  // PCSS needs a light with a size
                const Vec3 shift(offset, 0.0, -offset);
                scene::Scene s = sunAt50Degrees(offset);
                if (spot) {
                    scene::Light& l = s.lights[0];
                    l.type = scene::LightType::Spot;
                    l.position = Vec3(2.5, 3.0, 1.5) + shift;
                    l.direction = glm::normalize(Vec3(-2.5, -2.2, -1.5));
                    l.coneAngleDegrees = 45.0;
                    l.innerConeAngleDegrees = 30.0;  // (its cosine rides in a spare slot of its own)
                    l.radius = 0.1;
                    l.intensity = 300.0;
                }
                scene::RasterSettings settings = validatedSettings(512, 0.004, 0.5, filter);
                settings.normalOffset = 0.5;
                const std::string what = std::string(spot ? "spot" : "directional") + ", filter " +
                                         std::to_string(int(filter)) + ", offset " + std::to_string(offset);
                // A spot's baked constants take the *_spot module with none and pcf2x2: its frames
                // must be the uniform buffer's general modules' too.
                const auto frames = withEveryLightConstantSource(s, settings, scene::kAllChannels);
                const scene::Frame& a = frames[0];
                EXPECT_EQ(a.attributes.at("light_constants"), "uniform-buffer");
                EXPECT_EQ(frames[1].attributes.at("light_constants"), "vertex-outputs");
                EXPECT_EQ(frames[2].attributes.at("light_constants"), "specialization");
                std::size_t shadowed = 0;
                for (std::size_t i = 0; i < a.pixelCount(); ++i)
                    shadowed += a.objectId[i] == 2.0f && a.visibility[i] < 0.5f;  // plane pixels (id 2) only
                EXPECT_GT(shadowed, 500u)
                    << what << ": the sphere shadows the plane (a spot: or its cone leaves it dark)";
                for (int k = 1; k < 3; ++k) {
                    const scene::Frame& b = frames[std::size_t(k)];
                    const std::string which = what + (k == 1 ? ", flat inputs" : ", specialization constants");
                    EXPECT_TRUE(a.beauty == b.beauty) << which;
                    EXPECT_TRUE(a.visibility == b.visibility) << which;
                    EXPECT_TRUE(a.ndotl == b.ndotl) << which;
                    EXPECT_TRUE(a.depth == b.depth) << which;
                    EXPECT_TRUE(a.objectId == b.objectId) << which;
                    EXPECT_TRUE(a.blockerId == b.blockerId) << which;
                }
                if (offset == 0.0 && filter == ShadowFilter::Pcf2x2) {
                    const auto display =
                        withEveryLightConstantSource(s, settings, scene::kChannelBeauty | scene::kBeautyForDisplay);
                    ASSERT_EQ(display[0].attributes.count("beauty_precision"), 1u);
                    EXPECT_TRUE(display[0].beauty == display[1].beauty) << what << ", display target";
                    EXPECT_TRUE(display[0].beauty == display[2].beauty) << what << ", display target, baked in";
                }
            }
}

TEST(RasterRenderer, AlphaTestedCastersGiveTheSameFramesFromEveryLightConstantSource) {
    // The alpha-tested pipelines pair their own lit.vert builds with the light's constants and map
    // matrix from each source: lit_vert_alpha_sun (the matrix in the slots a sun leaves spare) with
    // the *_sun_map modules, lit_vert_alpha (the matrix in locations of its own, every location a
    // device must take) with the general ones, lit_vert_alpha_baked with the baked ones. Every
    // channel of the all-channel, float-beauty and display frames the same bit for bit. Only the
    // alpha-tested object takes those pipelines, so the leaf lies just above the plane in the
    // sphere's shadow, where its own lookups decide what it shows.
    const scene::Scene sun = withAlphaLeaf(makeScene(SphereOverPlane{}), 0.05);
    const scene::Scene spot =
        withAlphaLeaf(withSpot(makeScene(SphereOverPlane{}), Vec3(2, 5, 2), Vec3(-2, -5, -2)), 0.05);
    const std::tuple<const char*, scene::Scene, ShadowFilter> cases[] = {{"sun pcf2x2", sun, ShadowFilter::Pcf2x2},
                                                                         {"sun pcf", sun, ShadowFilter::Pcf},
                                                                         {"spot pcf2x2", spot, ShadowFilter::Pcf2x2}};
    for (const auto& [what, s, filter] : cases) {
        const scene::RasterSettings settings = validatedSettings(512, 0.01, 1.0, filter);
        for (const scene::ChannelMask channels :
             {scene::kAllChannels, scene::kChannelBeauty, scene::kChannelBeauty | scene::kBeautyForDisplay}) {
            const auto frames = withEveryLightConstantSource(s, settings, channels);
            EXPECT_EQ(frames[1].attributes.at("light_constants"), "vertex-outputs") << what;
            test::expectSamePixels(frames[1], frames[0], std::string(what) + ": flat inputs against the buffer");
            test::expectSamePixels(frames[2], frames[0], std::string(what) + ": baked against the buffer");
            if (channels != scene::kAllChannels) continue;
            std::size_t leafShadowed = 0;  // the leaf is the last object added: the highest id
            const float leaf = *std::max_element(frames[0].objectId.begin(), frames[0].objectId.end());
            for (std::size_t i = 0; i < frames[0].pixelCount(); ++i)
                leafShadowed += frames[0].visibility[i] < 0.5f && frames[0].objectId[i] == leaf;
            EXPECT_GT(leafShadowed, 10u) << what << ": the sphere must shadow the leaf";
        }
    }
}

TEST(RasterRenderer, CascadedLightConstantsBakedInGiveTheUniformBuffersFrameBitForBit) {
    // One cascaded sun: its constants and every cascade's map, slice end, texel size, depth scale
    // and bias baked into the lit pipelines (shaders/lit_constants.glsl kSpecializedCascades), which
    // pick a pixel's cascade by selects instead of indexing the uniform buffer. The same floats in
    // the same arithmetic: every channel the same bit for bit as the uniform buffer's frame. A
    // cascade's value packed into another's place, or a row of its matrix into another's, moves the
    // shadows of that slice. Three cascades with blend bands (two cascades read per pixel there),
    // four without; pcf2x2 (the size-optimized *_sun modules) and poisson (the general modules).
    // And without any bias: acne over every lit surface, whose pattern follows each cascade's texel
    // grid and depths, so a slice end or a matrix entry off by a little changes many pixels.
    const scene::Scene s = test::makeLongPlane(320, 180);
    struct Case {
        int cascades;
        double blend;
        ShadowFilter filter;
        bool biased;
    };
    for (const Case c : {Case{3, 0.3, ShadowFilter::Pcf2x2, true}, Case{4, 0.0, ShadowFilter::Pcf2x2, true},
                         Case{4, 0.2, ShadowFilter::Poisson, true}, Case{4, 0.2, ShadowFilter::None, false}}) {
        scene::RasterSettings settings = validatedSettings(512, 0.0, c.biased ? 1.0 : 0.0, c.filter);
        if (c.biased) settings.depthBias = scene::defaultDepthBias(s, 512);
        settings.cascades = c.cascades;
        settings.cascadeBlend = c.blend;
        const std::string what = std::to_string(c.cascades) + " cascades, blend " + std::to_string(c.blend) +
                                 ", filter " + std::to_string(int(c.filter)) + (c.biased ? "" : ", no bias");
        Renderer buffer(s, planFor(s, settings), settings,
                        RendererOptions{.lightConstants = LightConstants::kUniformBuffer});
        Renderer baked(s, planFor(s, settings), settings);
        const scene::Frame a = buffer.render(), b = baked.render();
        EXPECT_EQ(a.attributes.at("light_constants"), "uniform-buffer") << what;
        EXPECT_EQ(b.attributes.at("light_constants"), "specialization") << what;
        EXPECT_EQ(b.attributes.at("cascades"), std::to_string(c.cascades)) << what;
        // Shadows in the near and the far half of the view depths (different cascades).
        float nearest = INFINITY, farthest = 0.0f;
        for (std::size_t i = 0; i < a.pixelCount(); ++i)
            if (a.objectId[i] > 0.0f) {
                nearest = std::min(nearest, a.depth[i]);
                farthest = std::max(farthest, a.depth[i]);
            }
        std::size_t nearShadow = 0, farShadow = 0;
        const float middle = std::sqrt(nearest * farthest);
        for (std::size_t i = 0; i < a.pixelCount(); ++i)
            if (a.objectId[i] > 0.0f && a.visibility[i] < 0.5f) ++(a.depth[i] < middle ? nearShadow : farShadow);
        EXPECT_GT(nearShadow, 200u) << what;
        EXPECT_GT(farShadow, 20u) << what;
        test::expectSamePixels(a, b, what.c_str());
        EXPECT_EQ(buffer.validationMessages(), 0);
        EXPECT_EQ(baked.validationMessages(), 0);
    }
}

TEST(RasterRenderer, EveryLightsConstantsBakedInGiveTheUniformBuffersFrameBitForBit) {
    // Where no one light's map coordinates come from lit.vert (several lights, a point light alone,
    // the receiver-plane bias), the default bakes every light's constants into the lit pipelines
    // (shaders/lit_constants.glsl kEveryLightBaked) and each light's kind with them. The same floats
    // in the same arithmetic: every channel, each light's visibility included, the same bit for bit
    // as the uniform buffer's frame. A member packed into another's place, or a light's values into
    // another light's, moves that light's shadow or its shading. A sun, a spot and a point light,
    // each with a size (PCSS reads it) and with the normal offset on; every filter kind; near the
    // origin and 10^7 units away; the point light alone; the receiver plane; and a cascaded sun
    // beside the spot (its cascades stay in the buffer).
    struct Case {
        const char* name;
        ShadowFilter filter;
        double offset;
    };
    auto threeLights = [](double offset) {
        const Vec3 shift(offset, 0.0, -offset);
        scene::Scene s = sunAt50Degrees(offset);
        s.lights[0].intensity = 0.7;
        scene::Light spot = spotOverTheSphere(shift);
        spot.radius = 0.1;
        spot.innerConeAngleDegrees = 0.5 * spot.coneAngleDegrees;
        s.lights.push_back(spot);
        scene::Light point;
        point.type = scene::LightType::Point;
        point.position = Vec3(-2.0, 2.5, 1.0) + shift;
        point.radius = 0.1;
        point.intensity = 150.0;
        s.lights.push_back(point);
        return s;
    };
    auto expectTheSame = [](const scene::Scene& s, const scene::RasterSettings& settings, const std::string& what) {
        Renderer buffer(s, planFor(s, settings), settings,
                        RendererOptions{.lightConstants = LightConstants::kUniformBuffer});
        Renderer baked(s, planFor(s, settings), settings);
        const scene::Frame a = buffer.render(scene::kAllChannels), b = baked.render(scene::kAllChannels);
        EXPECT_EQ(a.attributes.at("light_constants"), "uniform-buffer") << what;
        EXPECT_EQ(b.attributes.at("light_constants"), "specialization") << what;
        // Each light shadows some of what it lights.
        ASSERT_EQ(a.lightVisibility.size(), s.lights.size() > 1 ? s.lights.size() : 0u) << what;
        for (std::size_t k = 0; k < a.lightVisibility.size(); ++k) {
            std::size_t lit = 0, shadowed = 0;
            for (const float v : a.lightVisibility[k]) (v > 0.5f ? lit : v == 0.0f ? shadowed : lit) += 1;
            EXPECT_GT(lit, 500u) << what << ", light " << k;
            EXPECT_GT(shadowed, 500u) << what << ", light " << k;
        }
        if (s.lights.size() == 1) {
            std::size_t shadowed = 0;
            for (std::size_t i = 0; i < a.pixelCount(); ++i) shadowed += a.objectId[i] > 0.0f && a.visibility[i] < 0.5f;
            EXPECT_GT(shadowed, 200u) << what;
        }
        test::expectSamePixels(a, b, what);
        // The beauty alone (float and the display target: the *_every beauty builds).
        for (const scene::ChannelMask beauty :
             {scene::kChannelBeauty, scene::kChannelBeauty | scene::kBeautyForDisplay})
            EXPECT_TRUE(buffer.render(beauty).beauty == baked.render(beauty).beauty) << what << ", beauty " << beauty;
        EXPECT_EQ(buffer.validationMessages(), 0);
        EXPECT_EQ(baked.validationMessages(), 0);
    };
    for (const Case c : {Case{"none", ShadowFilter::None, 0.0}, Case{"pcf2x2", ShadowFilter::Pcf2x2, 0.0},
                         Case{"pcf2x2 far", ShadowFilter::Pcf2x2, 1.0e7}, Case{"pcf", ShadowFilter::Pcf, 0.0},
                         Case{"poisson", ShadowFilter::Poisson, 0.0}, Case{"pcss", ShadowFilter::Pcss, 0.0},
                         Case{"pcss far", ShadowFilter::Pcss, 1.0e7}, Case{"vsm", ShadowFilter::Vsm, 0.0}}) {
        scene::RasterSettings settings = validatedSettings(512, 0.004, 0.5, c.filter);
        settings.normalOffset = 0.5;
        expectTheSame(threeLights(c.offset), settings, std::string("three lights, ") + c.name);
    }
    // Eight lights (each unrolled iteration reads its own constants): five more suns around the
    // sphere, at other elevations and azimuths, with a normal offset and a PCF size of their own
    // settings' (the same for all lights) but their own map texels and biases.
    scene::Scene eight = threeLights(0.0);
    for (int k = 0; k < 5; ++k) {
        scene::Light sun = eight.lights[0];
        const double azimuth = glm::radians(40.0 + 65.0 * k), elevation = glm::radians(38.0 + 5.0 * k);
        sun.direction = -Vec3(std::cos(elevation) * std::cos(azimuth), std::sin(elevation),
                              std::cos(elevation) * std::sin(azimuth));
        sun.intensity = 0.2 + 0.1 * k;
        eight.lights.push_back(sun);
    }
    ASSERT_EQ(eight.lights.size(), 8u);  // SHADOWLAB_MAX_LIGHTS
    expectTheSame(eight, validatedSettings(512, 0.004, 0.5, ShadowFilter::Pcf), "eight lights");
    // A semi-transparent sphere: the transmittance maps' taps in every light's test.
    scene::Scene glass = threeLights(0.0);
    glass.objects[0].material = test::addMaterial(glass, "glass", 0.5);
    expectTheSame(glass, validatedSettings(512, 0.004, 0.5, ShadowFilter::Pcf2x2), "three lights, a glass sphere");
    scene::Scene point = threeLights(0.0);
    point.lights.erase(point.lights.begin(), point.lights.begin() + 2);
    // Each face fitted to its receivers: six depth ranges of their own, which a face packed in
    // another's place would change.
    scene::RasterSettings fitted = validatedSettings(512, 0.004, 0.5, ShadowFilter::Pcf);
    fitted.fitLightFrustum = true;
    expectTheSame(point, fitted, "the point light alone");
    scene::RasterSettings plane = validatedSettings(512, 0.004, 0.5, ShadowFilter::Pcf);
    plane.receiverPlaneBias = true;
    expectTheSame(sunAt50Degrees(0.0), plane, "one sun with the receiver plane");
    scene::Scene longPlane = test::makeLongPlane(320, 180);
    scene::Light spot = test::spotDown();
    spot.position = {0, 8, -6};
    longPlane.lights.push_back(spot);
    scene::RasterSettings cascaded = validatedSettings(512, 0.0, 1.0, ShadowFilter::Pcf2x2);
    cascaded.depthBias = scene::defaultDepthBias(longPlane, 512);
    cascaded.cascades = 3;
    cascaded.cascadeBlend = 0.2;
    expectTheSame(longPlane, cascaded, "a cascaded sun and a spot");
    // Two cascaded suns: light 1's cascades (the same slices, its own maps) baked in beside light 0's.
    scene::Scene twoSuns = test::makeLongPlane(320, 180);
    scene::Light second = twoSuns.lights[0];
    second.direction = Vec3(0.8, -1.2, -0.9);
    second.intensity = 0.6;
    twoSuns.lights.push_back(second);
    cascaded.cascades = 4;
    expectTheSame(twoSuns, cascaded, "two cascaded suns");
}

// One step of expectSameFramesThroughUpdates: both Renderers update() to `scene` (none for a null
// one), then render; `baked` reads its light constants from `source`.
struct UpdateStep {
    const char* what;
    const scene::Scene* scene;
    const char* source;
};
// The same frames bit for bit from `baked` and `other` after each step, with no validation message.
void expectSameFramesThroughUpdates(Renderer& baked, Renderer& other, std::initializer_list<UpdateStep> steps) {
    for (const UpdateStep& step : steps) {
        if (step.scene) {
            baked.update(*step.scene);
            other.update(*step.scene);
        }
        const scene::Frame a = baked.render(), b = other.render();
        EXPECT_EQ(a.attributes.at("light_constants"), step.source) << step.what;
        test::expectSamePixels(a, b, step.what);
    }
    EXPECT_EQ(baked.validationMessages(), 0);
    EXPECT_EQ(other.validationMessages(), 0);
}

TEST(RasterRenderer, AnUpdateThatChangesTheBakedLightConstantsSwitchesToFlatInputsWithTheSameFrames) {
    // A Renderer keeps its baked-in pipelines through an update() that leaves the light's constants
    // as they are, and one that changes them (a moved sun, then a moved camera: the view axis is one
    // of them) takes them from lit.vert from then on: each frame the same bit for bit as a Renderer
    // that always did (updated the same way), with no validation message.
    const scene::RasterSettings settings = validatedSettings(256, 0.01, 1.0, ShadowFilter::Pcf2x2);
    const scene::Scene s = makeScene(SphereOverPlane{});
    Renderer baked(s, planFor(s, settings), settings);
    Renderer flat(s, planFor(s, settings), settings, RendererOptions{.lightConstants = LightConstants::kVertexOutputs});
    scene::Scene sun = s;
    sun.lights[0].direction = lightFromElevation(35.0);
    scene::Scene camera = sun;
    camera.camera.position += scene::Vec3(0.4, 0.1, -0.3);
    expectSameFramesThroughUpdates(baked, flat,
                                   {{"before any update", nullptr, "specialization"},
                                    {"after an update to the same scene", &s, "specialization"},
                                    {"after the sun moved", &sun, "vertex-outputs"},
                                    {"after the camera moved", &camera, "vertex-outputs"}});
}

TEST(RasterRenderer, AnUpdateThatMovesTheCascadesSwitchesToTheUniformBufferWithTheSameFrames) {
    // Cascades follow the camera: a moved camera changes the baked cascades, and the Renderer reads
    // them from the uniform buffer from then on, each frame the same bit for bit as a Renderer that
    // always did.
    const scene::Scene s = test::makeLongPlane(160, 90);
    scene::RasterSettings settings = validatedSettings(512, 0.0, 1.0, ShadowFilter::Pcf2x2);
    settings.depthBias = scene::defaultDepthBias(s, 512);
    settings.cascades = 3;
    Renderer baked(s, planFor(s, settings), settings);
    Renderer buffer(s, planFor(s, settings), settings,
                    RendererOptions{.lightConstants = LightConstants::kUniformBuffer});
    scene::Scene moved = s;
    moved.camera.position += scene::Vec3(1.5, 0.2, -4.0);
    expectSameFramesThroughUpdates(baked, buffer,
                                   {{"before any update", nullptr, "specialization"},
                                    {"after an update to the same scene", &s, "specialization"},
                                    {"after the camera moved", &moved, "uniform-buffer"}});
}

TEST(RasterRenderer, EveryLightBakedInDiffersFromTheBufferOnlyByRounding) {
    // Baked in, a value the buffer loads becomes a constant that Mesa's NIR folds: a sun of radiance
    // exactly 1 multiplies by 1, and the albedo's products with the ambient and with that light's
    // term are then regrouped (a·b + a·c into a·(b + c)), which rounds the beauty differently in its
    // last bit or two where a second light follows such a sun. The filterable maps' reconstruction
    // carries such a difference in their inputs into each light's visibility, at 1e-5. No compare
    // metric moves by it (docs/raster.md); this test bounds it. The object ids, depths and blocker
    // ids do not depend on it and stay exact.
    scene::Scene s = sunAt50Degrees(0.0);
    s.lights[0].color = Vec3(1.0);
    s.lights[0].intensity = 1.0;
    s.lights.push_back(spotOverTheSphere());
    for (const ShadowFilter filter : {ShadowFilter::Pcf2x2, ShadowFilter::Evsm2}) {
        const scene::RasterSettings settings = validatedSettings(512, 0.004, 0.5, filter);
        Renderer buffer(s, planFor(s, settings), settings,
                        RendererOptions{.lightConstants = LightConstants::kUniformBuffer});
        Renderer baked(s, planFor(s, settings), settings);
        const scene::Frame a = buffer.render(scene::kAllChannels), b = baked.render(scene::kAllChannels);
        ASSERT_EQ(b.attributes.at("light_constants"), "specialization");
        const std::string what = "filter " + std::to_string(int(filter));
        EXPECT_EQ(a.objectId, b.objectId) << what;
        EXPECT_EQ(a.depth, b.depth) << what;
        EXPECT_EQ(a.blockerId, b.blockerId) << what;
        // Beauty: within four units in the last place of a float in [1, 2).
        for (std::size_t i = 0; i < a.beauty.size(); ++i)
            ASSERT_LE(std::abs(a.beauty[i] - b.beauty[i]), 4.8e-7f * std::max(1.0f, std::abs(a.beauty[i])))
                << what << ", beauty value " << i;
        const float visibilityBound = filter == ShadowFilter::Pcf2x2 ? 1e-6f : 1e-4f;
        auto expectClose = [&](const std::vector<float>& x, const std::vector<float>& y, const char* channel) {
            ASSERT_EQ(x.size(), y.size()) << what << ", " << channel;
            for (std::size_t i = 0; i < x.size(); ++i)
                ASSERT_LE(std::abs(x[i] - y[i]), visibilityBound) << what << ", " << channel << " pixel " << i;
        };
        expectClose(a.visibility, b.visibility, "visibility");
        expectClose(a.ndotl, b.ndotl, "N·L");
        ASSERT_EQ(a.lightVisibility.size(), 2u);
        for (std::size_t k = 0; k < 2; ++k)
            expectClose(a.lightVisibility[k], b.lightVisibility[k], "a light's visibility");
        EXPECT_EQ(buffer.validationMessages(), 0);
        EXPECT_EQ(baked.validationMessages(), 0);
    }
}

TEST(RasterRenderer, AnUpdateThatMovesEveryBakedLightSwitchesToTheUniformBufferWithTheSameFrames) {
    // Every light baked in (two lights): a moved light changes its baked values, as a moved camera
    // changes the view axis (baked too) and the maps fitted to the view; the Renderer reads the
    // uniform buffer from then on, each frame the same bit for bit as a Renderer that always did.
    scene::Scene s = sunAt50Degrees(0.0);
    s.lights.push_back(spotOverTheSphere());
    const scene::RasterSettings settings = validatedSettings(512, 0.004, 0.5, ShadowFilter::Pcf2x2);
    Renderer baked(s, planFor(s, settings), settings);
    Renderer buffer(s, planFor(s, settings), settings,
                    RendererOptions{.lightConstants = LightConstants::kUniformBuffer});
    scene::Scene spotMoved = s;
    spotMoved.lights[1].position += scene::Vec3(-0.3, 0.2, 0.1);
    scene::Scene moved = spotMoved;
    moved.camera.position += scene::Vec3(0.6, 0.3, -0.5);
    expectSameFramesThroughUpdates(baked, buffer,
                                   {{"before any update", nullptr, "specialization"},
                                    {"after an update to the same scene", &s, "specialization"},
                                    {"after the second light moved", &spotMoved, "uniform-buffer"},
                                    {"after the camera moved", &moved, "uniform-buffer"}});
}

TEST(RasterRenderer, LightConstantsAreBakedInByDefault) {
    // By default lit.frag takes the lights' constants as specialization constants: the one light's
    // where the scene has one directional light (one map or cascades) or one spot, and no
    // receiver-plane bias; every light's with a second light or the receiver-plane bias.
    const scene::RasterSettings settings = validatedSettings(256, 0.01, 1.0, ShadowFilter::Pcf2x2);
    const scene::Scene one = makeScene(SphereOverPlane{});
    auto source = [](const scene::Scene& s, const scene::RasterSettings& r) {
        Renderer renderer(s, planFor(s, r), r);
        const scene::Frame f = renderer.render(scene::kChannelBeauty);
        EXPECT_EQ(renderer.validationMessages(), 0);
        return f.attributes.at("light_constants");
    };
    EXPECT_EQ(source(one, settings), "specialization");
    scene::Scene spot = one;
    spot.lights[0].type = scene::LightType::Spot;
    spot.lights[0].position = Vec3(2.5, 3.0, 1.5);
    spot.lights[0].direction = glm::normalize(Vec3(-2.5, -2.2, -1.5));
    spot.lights[0].coneAngleDegrees = 45.0;
    EXPECT_EQ(source(spot, settings), "specialization");
    scene::Scene two = one;
    two.lights.push_back(two.lights[0]);
    two.lights[1].direction = lightFromElevation(40.0);
    EXPECT_EQ(source(two, settings), "specialization");
    scene::RasterSettings plane = settings;
    plane.receiverPlaneBias = true;
    EXPECT_EQ(source(one, plane), "specialization");
    scene::RasterSettings cascades = settings;
    cascades.cascades = 3;
    EXPECT_EQ(source(one, cascades), "specialization");
    cascades.receiverPlaneBias = true;
    EXPECT_EQ(source(one, cascades), "specialization");
}

TEST(RasterRender, BadPcfSizeIsRejected) {
    const scene::Scene s = makeScene(SphereOverPlane{});
    scene::RasterSettings settings = filterSettings(ShadowFilter::Pcf, 0);
    EXPECT_THROW(render(s, planFor(s, settings), settings), RasterError);
    settings.pcfSize = 16;
    EXPECT_THROW(render(s, planFor(s, settings), settings), RasterError);
}

TEST(RasterRender, ImageTooLargeForTheDeviceIsAClearError) {
    // 16384² pixels need 68 bytes each (two RGBA32F targets, D32 depth, two RGBA32F readback
    // buffers): 17 GiB, more than lavapipe's 2 GiB heap.
    SphereOverPlane p;
    p.width = 16384;
    p.height = 16384;
    const scene::Scene s = makeScene(p);
    const scene::RasterSettings settings = validatedSettings(256, 0.01, 1.0, ShadowFilter::None);
    try {
        render(s, planFor(s, settings), settings);
        FAIL() << "expected RasterError";
    } catch (const RasterError& e) {
        EXPECT_NE(std::string(e.what()).find("MiB of device memory"), std::string::npos) << e.what();
    }
}

TEST(RasterPointLight, SphereCastsTheTangentConeShadow) {
    // A point light straight above the sphere: the shadow is the cone from the light tangent to
    // the sphere, half-angle asin(r / (h − c_y)), cut by the plane y = 0: a disk of radius
    // h·tan(half-angle) around the light's foot. The plane is wide enough that its outer parts
    // are seen through the side faces of the cube map, not only the −Y face.
    SphereOverPlane p;
    p.width = 320;
    p.height = 180;
    scene::Scene s = makeScene(p);
    const double h = 2.5;
    s.lights[0].type = scene::LightType::Point;
    s.lights[0].position = Vec3(0, h, 0);
    s.lights[0].intensity = 300.0;
    const double alpha = std::asin(p.radius / (h - p.center.y));
    const double shadowRadius = h * std::tan(alpha);
    const scene::Frame f = renderValidated(s, validatedSettings(1024, 0.01, 1.0, ShadowFilter::None), "point_sphere");
    // One texel of the −Y face at the plane is 2·t/1024·h ≈ 0.005; skip a band of 0.03 around the rim.
    const double band = 0.03;
    int inside = 0, outside = 0, wrong = 0, sideFaces = 0;
    forEachPlanePixel(p, s, f, [&](std::size_t i, const Vec3& q) {
        const double rho = std::hypot(q.x, q.z);
        if (std::abs(rho - shadowRadius) < band) return;
        const bool shadowed = rho < shadowRadius;
        (shadowed ? inside : outside) += 1;
        if (std::max(std::abs(q.x), std::abs(q.z)) > h) ++sideFaces;
        if ((f.visibility[i] < 0.5f) != shadowed) ++wrong;
        if (!shadowed && f.visibility[i] == 1.0f) {
            const Vec3 toLight = s.lights[0].position - q;
            const double d2 = glm::dot(toLight, toLight);
            EXPECT_NEAR(f.beauty[3 * i], 0.8 * 300.0 / (4 * kPi * d2) * (toLight.y / std::sqrt(d2)) + 0.05 * 0.8, 2e-4);
        }
    });
    EXPECT_GT(inside, 500);
    EXPECT_GT(outside, 5000);
    EXPECT_GT(sideFaces, 1000) << "the view should reach the side faces";
    EXPECT_EQ(wrong, 0) << wrong << " plane pixels disagree with the tangent-cone shadow";
    EXPECT_EQ(f.attributes.at("shadow_maps"), "6");
}

TEST(RasterPointLight, OffAxisSphereShadowOnASideFaceMatchesTheSegmentTest) {
    // The light beside the sphere, so its shadow lies in the +X face and nothing is symmetric
    // about that face's axes (a mirrored or transposed face lookup would misplace it). Closed
    // form: a plane point is shadowed when the segment to the light meets the sphere.
    SphereOverPlane p;
    p.width = 320;
    p.height = 180;
    p.center = Vec3(1.2, 0.7, 0.3);
    p.lookAt = Vec3(1.0, 0.3, 0.3);
    scene::Scene s = makeScene(p);
    const Vec3 lightPos(0.0, 1.5, -0.1);
    s.lights[0].type = scene::LightType::Point;
    s.lights[0].position = lightPos;
    s.lights[0].intensity = 100.0;
    const scene::Frame f = renderValidated(s, validatedSettings(1024, 0.01, 1.0, ShadowFilter::None), "point_off_axis");
    int shadowed = 0, plusX = 0, counted = 0, wrong = 0;
    forEachPlanePixel(p, s, f, [&](std::size_t i, const Vec3& q) {
        const Vec3 toLight = lightPos - q;
        // Skip the rim: plane points whose segment passes within 0.01 of the sphere's surface.
        const Vec3 c = p.center - q;
        const double t = std::clamp(glm::dot(c, toLight) / glm::dot(toLight, toLight), 0.0, 1.0);
        const double dist = glm::length(c - t * toLight);
        if (std::abs(dist - p.radius) < 0.01) return;
        const bool inShadow = dist < p.radius;
        ++counted;
        if (inShadow) {
            ++shadowed;
            const Vec3 d = -toLight;
            if (d.x > std::abs(d.y) && d.x > std::abs(d.z)) ++plusX;
        }
        if ((f.visibility[i] < 0.5f) != inShadow) ++wrong;
    });
    EXPECT_GT(counted, 5000);
    EXPECT_GT(shadowed, 1000);
    EXPECT_GT(plusX, shadowed / 2) << "the shadow should lie mostly in the +X face";
    EXPECT_LE(wrong, counted / 1000) << wrong << " of " << counted << " plane pixels disagree with the segment test";
}

TEST(RasterPointLight, CubeMapSeamsMakeNoFalseShadows) {
    // A lone plane under (then over) a point light close to it: its pixels are seen through
    // five faces each time and through every boundary between them (the −Y or +Y face meets the
    // four side faces at |x| = h or |z| = h, the side faces meet each other on |x| = |z|).
    // Nothing casts, so every pixel the light reaches must be fully lit, with every filter.
    for (const double side : {1.0, -1.0}) {
        for (const ShadowFilter filter :
             {ShadowFilter::None, ShadowFilter::Pcf2x2, ShadowFilter::Pcf, ShadowFilter::Poisson}) {
            SphereOverPlane p;
            p.center = Vec3(0, -100, 0);  // keeps primaryHit() off the sphere we remove
            p.eye = Vec3(0, 4 * side, 6);
            p.lookAt = Vec3(0, 0.5 * side, 0);
            scene::Scene s = makeScene(p);
            s.objects.erase(s.objects.begin());  // the plane is now object 1
            const double h = 1.2;
            s.lights[0].type = scene::LightType::Point;
            s.lights[0].position = Vec3(0.1, h * side, -0.2);
            s.lights[0].intensity = 50.0;
            scene::RasterSettings settings = validatedSettings(512, 0.01, 1.0, filter);
            settings.pcfSize = 5;
            const std::string name =
                std::string("point_seams_") + (side > 0 ? "floor_" : "ceiling_") + scene::toString(filter);
            const scene::Frame f = renderValidated(s, settings, name);
            int counted = 0, falseShadow = 0, nearSeam = 0;
            forEachPlanePixel(
                p, s, f,
                [&](std::size_t i, const Vec3& q) {
                    ++counted;
                    const Vec3 d = q - s.lights[0].position;
                    // Within 0.1 of a boundary between faces (where two axes are equally major).
                    const double ax = std::abs(d.x), ay = std::abs(d.y), az = std::abs(d.z);
                    const double m = std::max({ax, ay, az});
                    const double second = ax + ay + az - m - std::min({ax, ay, az});
                    if (m - second < 0.1) ++nearSeam;
                    if (f.visibility[i] != 1.0f) ++falseShadow;
                },
                1.0f);  // the plane is object 1 here
            EXPECT_GT(counted, 5000) << name;
            EXPECT_GT(nearSeam, 300) << name << ": the view should cross the face boundaries";
            EXPECT_EQ(falseShadow, 0) << name << ": " << falseShadow << " of " << counted << " pixels falsely shadowed";
        }
    }
}

TEST(RasterRender, UnmatchedDeviceGivesAnErrorListingTheDevices) {
    const scene::Scene s = makeScene(SphereOverPlane{});
    scene::RasterSettings settings = validatedSettings(256, 0.01, 1.0, ShadowFilter::None);
    settings.device = "no-such-gpu-xyz";
    try {
        render(s, planFor(s, settings), settings);
        FAIL() << "expected RasterError";
    } catch (const RasterError& e) {
        const std::string what = e.what();
        EXPECT_NE(what.find("no-such-gpu-xyz"), std::string::npos) << what;
        EXPECT_NE(what.find("llvmpipe"), std::string::npos) << what;  // the device list
    }
}

}  // namespace
}  // namespace shadowlab::raster
