// tests/raster/receiver_plane_test.cpp: the receiver-plane depth bias (lit.frag receiverPlane) on
// the seed scene at grazing light, judged with compare's metrics against the double-precision
// reference (raytrace::renderReference), on lavapipe with the validation layer.
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <filesystem>

#include <gtest/gtest.h>

#include "compare/compare.h"
#include "raster/renderer.h"
#include "raytrace/renderer.h"
#include "scene/frame_io.h"
#include "scene/loader.h"
#include "scene/render_plan.h"

namespace shadowlab::raster {
namespace {

// The seed scene (sphere on a plane) at 160x90, its light lowered to `elevationDegrees` above
// the plane, keeping the seed's azimuth (-1, ·, -1).
scene::Scene grazingSeed(double elevationDegrees) {
    scene::Scene s = scene::loadScene(std::filesystem::path(SHADOWLAB_SOURCE_DIR) / "scenes" / "seed.json");
    s.camera.width = 160;
    s.camera.height = 90;
    const double e = elevationDegrees * 3.14159265358979323846 / 180.0;
    s.lights[0].direction = glm::normalize(scene::Vec3(-std::cos(e) / std::sqrt(2.0), -std::sin(e),
                                                       -std::cos(e) / std::sqrt(2.0)));
    return s;
}

scene::Frame rasterRender(const scene::Scene& s, scene::RasterSettings settings, const std::string& name) {
    settings.validate = true;
    scene::RenderSettings all;
    all.raster = settings;
    scene::Frame f = render(s, scene::makeRenderPlan(s, all), settings);
    EXPECT_EQ(f.attributes["validation_messages"], "0") << "validation messages were printed above";
    if (const char* dir = std::getenv("SHADOWLAB_TEST_PNG_DIR"))
        scene::writePngLinear(std::filesystem::path(dir) / (name + ".png"), f.width, f.height, f.beauty);
    return f;
}

scene::Frame reference(const scene::Scene& s) {
    const scene::RenderSettings settings = scene::resolveSettings(s, {});
    return raytrace::renderReference(s, scene::makeRenderPlan(s, settings), scene::referenceSettings(settings.raytrace));
}

// pcf 5x5, no slope bias, the default constant bias (half a texel of the bounding-sphere map).
scene::RasterSettings pcf5(const scene::Scene& s, bool receiverPlane) {
    scene::RasterSettings r = scene::resolveSettings(s, {}).raster;
    r.shadowMapSize = 1024;
    r.depthBias = scene::defaultDepthBias(s, r.shadowMapSize);
    r.depthBiasIsDefault = false;
    r.slopeBias = 0.0;
    r.filter = scene::ShadowFilter::Pcf;
    r.pcfSize = 5;
    r.receiverPlaneBias = receiverPlane;
    return r;
}

TEST(RasterReceiverPlane, RemovesThePcfAcneThatTheSameConstantBiasShowsAtGrazingLight) {
    // Light 8° above the plane: tan(82°) ≈ 7.1, so the plane's light depth changes by about 7
    // texels' worth per texel, and a 5x5 tap 2 texels from the point compares against a surface
    // up to ~14 texels nearer the light than the point; half a texel of constant bias cannot
    // cover that, so off-center taps shadow the lit plane (self-shadow acne). The receiver plane
    // compares each tap against the plane's own depth at the tap's texel center: the plane no
    // longer shadows itself, while the sphere's shadow (≫ a texel deep) stays.
    const scene::Scene s = grazingSeed(8.0);
    const scene::Frame ref = reference(s);
    const compare::Metrics off = compare::compareFrames(rasterRender(s, pcf5(s, false), "rpb-off"), ref).metrics;
    const compare::Metrics on = compare::compareFrames(rasterRender(s, pcf5(s, true), "rpb-on"), ref).metrics;
    std::printf("counted %zu, reference shadowed %zu; off: false %zu (self acne %zu) missed %zu; "
                "on: false %zu (self acne %zu) missed %zu\n",
                off.counted, off.shadowedReference, off.falseShadow, off.selfShadowAcne, off.missedShadow,
                on.falseShadow, on.selfShadowAcne, on.missedShadow);
    ASSERT_TRUE(off.hasBlockerIds && on.hasBlockerIds);
    ASSERT_GT(off.counted, 5000u);
    ASSERT_GT(off.shadowedReference, 300u);
    // Without: widespread acne on the lit plane.
    EXPECT_GT(off.selfShadowAcne, off.counted / 10);
    // With: (almost) none; what may remain sits where the derivatives break (the sphere's
    // silhouette and terminator, a few pixels).
    EXPECT_LT(on.selfShadowAcne, on.counted / 500);
    EXPECT_LT(on.falseShadow, off.falseShadow / 20);
    // And the shadow is not bought by leaking: missed shadow stays an outline band.
    EXPECT_LT(on.missedShadow, on.shadowedReference / 10);
}

TEST(RasterReceiverPlane, IsRecordedAndTheSameFrameTwice) {
    const scene::Scene s = grazingSeed(8.0);
    scene::RasterSettings settings = pcf5(s, true);
    settings.filter = scene::ShadowFilter::Pcf2x2;
    scene::Frame a = rasterRender(s, settings, "rpb-2x2");
    scene::Frame b = rasterRender(s, settings, "rpb-2x2");
    EXPECT_EQ(a.attributes["receiver_plane_bias"], "true");
    EXPECT_EQ(a.visibility, b.visibility);
    settings.receiverPlaneBias = false;
    EXPECT_EQ(rasterRender(s, settings, "rpb-2x2-off").attributes["receiver_plane_bias"], "false");
}

}  // namespace
}  // namespace shadowlab::raster
