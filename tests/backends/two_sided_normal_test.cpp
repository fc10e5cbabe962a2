// tests/backends/two_sided_normal_test.cpp: which way a two-sided surface's shading normal
// faces, in the raster lit pass (lavapipe, validation layer on), the float ray tracer and the
// double-precision reference, against N·L worked out by hand. The rule (raytrace/tracer.cpp,
// surfacePoint): the facet's normal turned toward the viewer, the shading normal into its
// half-space. A shading normal that leans away from the viewer while its facet faces the viewer
// (smooth normals near a silhouette, a rough mesh's normals) keeps its side; turned toward the
// viewer by itself it would cross the facet and negate N·L.
//
// The set-up: a 2×2 square of two triangles in the plane y = 0, seen from (0, 2, 2√3), 30° above
// the plane (the view ray d ≈ (0, −0.5, −0.87) at the centre), its vertex normals all
// n = (0, 0.3, −1)/√1.09. The facet faces the viewer (+y: d·(0, 1, 0) < 0), n lies on its side
// (n·(0, 1, 0) = 0.287 > 0) and leans away from the viewer at every point p = (x, 0, z) of the
// square: with d ∝ p − eye = (x, −2, z − 2√3), d·(0, 0.3, −1) = 2√3 − 0.6 − z ≥ 1.86 for z ≤ 1.
// Under light travelling straight down, N·L = n·(0, 1, 0) = 0.3/√1.09 = 0.2873 at every pixel,
// whichever way the triangles wind.
#include <cmath>
#include <memory>

#include <gtest/gtest.h>

#include "compare/compare.h"
#include "scene/camera.h"
#include "scene/settings.h"
#include "tests/kit/render_checked.h"
#include "tests/kit/test_scenes.h"

namespace shadowlab {
namespace {

using scene::Vec3;

scene::Scene leaningNormals(bool reversedWinding) {
    scene::Scene s;
    s.camera = {.position = Vec3(0, 2, 2 * std::sqrt(3.0)),
                .lookAt = Vec3(0),
                .up = Vec3(0, 1, 0),
                .fovYDegrees = 40.0,
                .width = 160,
                .height = 90};
    scene::Material m;
    m.name = "matte";
    s.materials = {m};
    test::addDirectional(s, Vec3(0, -1, 0), 1.0);
    auto mesh = std::make_shared<scene::TriangleMesh>();
    mesh->positions = {Vec3(-1, 0, -1), Vec3(1, 0, -1), Vec3(1, 0, 1), Vec3(-1, 0, 1)};
    const Vec3 n = glm::normalize(Vec3(0, 0.3, -1));
    mesh->normals = {n, n, n, n};
    // (0, 2, 1), (0, 3, 2): cross(p1 − p0, p2 − p0) = (0, 4, 0), the facet normal +y; reversed, −y.
    mesh->indices =
        reversedWinding ? std::vector<std::uint32_t>{0, 1, 2, 0, 2, 3} : std::vector<std::uint32_t>{0, 2, 1, 0, 3, 2};
    test::addMesh(s, mesh);
    return s;
}

class TwoSidedNormal : public ::testing::TestWithParam<bool> {};

TEST_P(TwoSidedNormal, AShadingNormalLeaningAwayFromTheViewerKeepsItsFacetsSide) {
    const scene::Scene s = leaningNormals(GetParam());
    const double expected = 0.3 / std::sqrt(1.09);
    const test::Frames f = test::renderAll(s, scene::resolveSettings(s, {}));
    std::size_t onSquare = 0;
    for (const scene::Frame* frame : {&f.raster, &f.raytrace, &f.reference}) {
        std::size_t n = 0;
        for (std::size_t i = 0; i < frame->pixelCount(); ++i) {
            if (frame->objectId[i] != 1.0f) continue;
            ++n;
            EXPECT_NEAR(frame->ndotl[i], expected, 1e-4) << frame->attributes.at("backend") << " pixel " << i;
            EXPECT_EQ(frame->visibility[i], 1.0f) << frame->attributes.at("backend") << " pixel " << i;
        }
        EXPECT_GT(n, 1000u) << frame->attributes.at("backend");
        onSquare = std::max(onSquare, n);
    }
    // The classes agree on which side faces the light: no pixel where one frame has N·L > 0 and
    // the other not, and every pixel of the square counted.
    const compare::Metrics m = compare::compareFrames(f.raster, f.reference).metrics;
    EXPECT_EQ(m.ndotlSignMismatch, 0u);
    EXPECT_GE(m.counted + 2 * 160, onSquare);  // up to a silhouette row of pixels either way
}

INSTANTIATE_TEST_SUITE_P(BothWindings, TwoSidedNormal, ::testing::Bool(), [](const ::testing::TestParamInfo<bool>& p) {
    return p.param ? "Reversed" : "Counterclockwise";
});

}  // namespace
}  // namespace shadowlab
