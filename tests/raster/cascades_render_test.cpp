// tests/raster/cascades_render_test.cpp: raster/cascades.cpp against the double-precision
// reference: on a large scene (a 200-unit plane with spheres along the view), three cascades get
// no more shadow pixels wrong than one map over the whole scene (counted with compare's metrics),
// on lavapipe with the validation layer.
#include <cstdio>

#include <gtest/gtest.h>

#include "compare/compare.h"
#include "raster/renderer.h"
#include "tests/kit/render_checked.h"
#include "tests/kit/test_scenes.h"

namespace shadowlab::raster {
namespace {

using compare::compareFrames;
using compare::Metrics;

scene::Frame rasterWith(const scene::Scene& s, int cascades) {
    scene::RenderSettings settings = scene::resolveSettings(s, {});
    settings.raster.shadowMapSize = 512;
    settings.raster.depthBias = scene::defaultDepthBias(s, 512);
    settings.raster.cascades = cascades;
    settings.raster.cascadesIsDefault = false;  // as given, not chosen per view
    // One map over the whole scene: the bounding-sphere map, named (the default fits it to the view).
    settings.raster.fitLightFrustum = false;
    return test::renderChecked(s, settings);
}

TEST(CascadesAgainstReference, ThreeCascadesGetNoMoreShadowPixelsWrongThanOneMapOnALargeScene) {
    const scene::Scene s = test::makeLongPlane(160, 90);
    const scene::Frame reference = test::renderReference(s);
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
}  // namespace shadowlab::raster
