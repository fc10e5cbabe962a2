// tests/raster/transmittance_render_test.cpp: semi-transparent casters: the raster backend's
// transmittance map (raster/shadow_pass.cpp) against the double-precision ray-traced reference,
// which multiplies 1 − opacity once per object a shadow ray passes through, compared with
// compare's metrics, on lavapipe with the validation layer.
#include <cmath>
#include <cstdio>

#include <gtest/gtest.h>

#include "compare/compare.h"
#include "raster/renderer.h"
#include "tests/kit/render_checked.h"
#include "tests/kit/test_scenes.h"

namespace shadowlab::raster {
namespace {

using Vec3 = scene::Vec3;

scene::Object quad(const Vec3& center, double side, int material) {
    return test::horizontalQuad("quad", center, side, side, material);
}

// Two glass panes (opacity 0.5) at heights 2 and 1 overlapping in x, a glass sphere (0.6) and an
// opaque box on a floor, a slanted directional light: steps of 1, 0.5, 0.25 and 0.4 on the
// floor, the lower pane half-shadowed by the upper one.
scene::Scene glassScene() {
    scene::Scene s;
    s.camera = {
        .position = Vec3(5, 6, 7), .lookAt = Vec3(0, 0.5, 0), .width = 192, .height = 108};  // fov 40°, near 0.1
    test::addMaterial(s, "matte");
    test::addMaterial(s, "glass", 0.5);
    test::addMaterial(s, "tinted", 0.6);
    test::addDirectional(s, Vec3(-0.3, -2, -0.5), 1.1);
    s.objects.push_back(quad(Vec3(0, 0, 0), 12.0, 0));
    s.objects.push_back(quad(Vec3(-0.5, 2, 0), 3.0, 1));
    s.objects.push_back(quad(Vec3(0.8, 1, 0.5), 2.0, 1));
    s.objects.push_back({"sphere", scene::Sphere{Vec3(2.5, 1, -2), 0.8}, 2});
    s.objects.push_back({"box", scene::Box{Vec3(-3, 0, 1.5), Vec3(-2, 1, 2.5)}, 0});
    return s;
}

TEST(TransmittanceAgainstReference, RasterVisibilityMatchesTheReferenceAwayFromEdges) {
    const scene::Scene s = glassScene();
    scene::RenderSettings settings = scene::resolveSettings(s, {});
    settings.raster.shadowMapSize = 1024;
    ASSERT_TRUE(scene::makeRenderPlan(s, settings).needsTransmittanceMap);
    const scene::Frame raster = test::renderChecked(s, settings);
    EXPECT_EQ(raster.attributes.at("transmittance_map"), "made");
    const scene::Frame reference = test::renderReference(s, settings);
    const compare::Metrics m = compare::compareFrames(raster, reference).metrics;
    // Pixel by pixel where both see the same object lit from the front: the reference's
    // visibility takes the values 1, 0.5, 0.4, 0.25, 0.2, 0 here; the raster's must be the same
    // except in a band of shadow outlines (pcf2x2 ramps over a texel).
    std::size_t counted = 0, far = 0, intermediate = 0;
    for (std::size_t i = 0; i < reference.visibility.size(); ++i) {
        if (reference.objectId[i] == 0.0f || raster.objectId[i] != reference.objectId[i] || reference.ndotl[i] <= 0.0f)
            continue;
        ++counted;
        const float vr = reference.visibility[i];
        if (vr > 0.05f && vr < 0.95f) ++intermediate;
        if (std::abs(raster.visibility[i] - vr) > 0.02f) ++far;
    }
    std::printf("counted %zu, with partial light %zu, off by > 0.02: %zu; mean |dV| %.5f\n", counted, intermediate, far,
                m.meanAbsVisibilityError);
    ASSERT_GT(intermediate, 500u);  // the glass shadows are in view
    EXPECT_LT(double(far), 0.02 * double(counted));
    EXPECT_LT(m.meanAbsVisibilityError, 0.005);
}

}  // namespace
}  // namespace shadowlab::raster
