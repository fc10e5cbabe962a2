// tests/compare/cascades_render_test.cpp: on a large scene (a 200-unit plane with spheres along
// the view), three cascades get no more shadow pixels wrong against the double-precision reference
// than one map over the whole scene, on lavapipe with the validation layer.
#include <cstdio>

#include <gtest/gtest.h>

#include "compare/compare.h"
#include "raster/renderer.h"
#include "raytrace/renderer.h"
#include "scene/frame_io.h"
#include "tests/raster/test_scenes.h"

namespace shadowlab::compare {
namespace {

scene::Frame rasterWith(const scene::Scene& s, int cascades) {
    scene::RenderSettings settings = scene::resolveSettings(s, {});
    settings.raster.shadowMapSize = 512;
    settings.raster.depthBias = scene::defaultDepthBias(s, 512);
    settings.raster.cascades = cascades;
    settings.raster.cascadesIsDefault = false;  // as given, not chosen per view
    // One map over the whole scene: the bounding-sphere map, named (the default fits it to the view).
    settings.raster.fitLightFrustum = false;
    settings.raster.validate = true;
    scene::Frame f = raster::render(s, scene::makeRenderPlan(s, settings), settings.raster);
    EXPECT_EQ(f.attributes["validation_messages"], "0") << "validation messages were printed above";
    return f;
}

TEST(CascadesAgainstReference, ThreeCascadesGetNoMoreShadowPixelsWrongThanOneMapOnALargeScene) {
    const scene::Scene s = raster::test::makeLongPlane(160, 90);
    const scene::RenderSettings settings = scene::resolveSettings(s, {});
    const scene::Frame reference = raytrace::renderReference(s, scene::makeRenderPlan(s, settings),
                                                             scene::referenceSettings(settings.raytrace));
    const Metrics one = compareFrames(rasterWith(s, 1), reference).metrics;
    const Metrics three = compareFrames(rasterWith(s, 3), reference).metrics;
    const std::size_t wrongOne = one.falseShadow + one.missedShadow;
    const std::size_t wrongThree = three.falseShadow + three.missedShadow;
    std::printf("counted %zu, reference shadowed %zu; wrong: 1 cascade %zu (IoU %.3f), 3 cascades %zu (IoU %.3f)\n",
                one.counted, one.shadowedReference, wrongOne, one.shadowIoU, wrongThree, three.shadowIoU);
    // Both frames see the same pixels; the reference has shadows to get wrong.
    ASSERT_EQ(one.counted, three.counted);
    ASSERT_GT(one.shadowedReference, 100u);
    EXPECT_LE(wrongThree, wrongOne) << "1 cascade: " << wrongOne << " wrong, 3 cascades: " << wrongThree;
    // One 512 map over a 283-unit scene has 0.56-unit texels against spheres of radius 0.6: most
    // of their shadows are lost, so the gain is large, not a pixel or two.
    EXPECT_LT(2 * wrongThree, wrongOne);
    EXPECT_GT(three.shadowIoU, one.shadowIoU);
}

}  // namespace
}  // namespace shadowlab::compare
