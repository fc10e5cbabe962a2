// tests/compare/transmittance_render_test.cpp: semi-transparent casters: the raster
// backend's transmittance map against the double-precision ray-traced reference, which multiplies
// 1 − opacity once per object a shadow ray passes through, on lavapipe with the validation layer.
#include <cmath>
#include <cstdio>

#include <gtest/gtest.h>

#include "compare/compare.h"
#include "raster/renderer.h"
#include "raytrace/renderer.h"

namespace shadowlab::compare {
namespace {

using Vec3 = scene::Vec3;

scene::Object quad(const Vec3& center, double side, int material) {
    scene::Quad q;
    q.center = center;
    q.normal = Vec3(0, 1, 0);
    q.size = scene::Vec2(side, side);
    scene::quadAxes(q.normal, q.uAxis, q.vAxis);
    return {"quad", q, material};
}

// Two glass panes (opacity 0.5) at heights 2 and 1 overlapping in x, a glass sphere (0.6) and an
// opaque box on a floor, a slanted directional light: steps of 1, 0.5, 0.25 and 0.4 on the
// floor, the lower pane half-shadowed by the upper one.
scene::Scene glassScene() {
    scene::Scene s;
    s.camera.position = Vec3(5, 6, 7);
    s.camera.lookAt = Vec3(0, 0.5, 0);
    s.camera.up = Vec3(0, 1, 0);
    s.camera.fovYDegrees = 40.0;
    s.camera.width = 192;
    s.camera.height = 108;
    s.camera.near = 0.1;
    s.camera.far = 100.0;
    scene::Material matte;
    matte.name = "matte";
    scene::Material glass;
    glass.name = "glass";
    glass.opacity = 0.5;
    scene::Material tinted;
    tinted.name = "tinted";
    tinted.opacity = 0.6;
    s.materials = {matte, glass, tinted};
    scene::Light l;
    l.type = scene::LightType::Directional;
    l.direction = glm::normalize(Vec3(-0.3, -2, -0.5));
    l.intensity = 1.1;
    s.lights.push_back(l);
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
    settings.raster.validate = true;
    const scene::RenderPlan plan = scene::makeRenderPlan(s, settings);
    ASSERT_TRUE(plan.needsTransmittanceMap);
    const scene::Frame raster = raster::render(s, plan, settings.raster);
    EXPECT_EQ(raster.attributes.at("validation_messages"), "0") << "validation messages were printed above";
    EXPECT_EQ(raster.attributes.at("transmittance_map"), "made");
    const scene::Frame reference =
        raytrace::renderReference(s, plan, scene::referenceSettings(settings.raytrace));
    const Metrics m = compareFrames(raster, reference).metrics;
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
    std::printf("counted %zu, with partial light %zu, off by > 0.02: %zu; mean |dV| %.5f\n", counted, intermediate,
                far, m.meanAbsVisibilityError);
    ASSERT_GT(intermediate, 500u);  // the glass shadows are in view
    EXPECT_LT(double(far), 0.02 * double(counted));
    EXPECT_LT(m.meanAbsVisibilityError, 0.005);
}

}  // namespace
}  // namespace shadowlab::compare
