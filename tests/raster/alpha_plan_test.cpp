// tests/raster/alpha_plan_test.cpp: which alpha tests and alpha data the raster renderer plans
// for a scene (raster::planAlpha), against the glTF alpha rules worked by hand, and the memory
// estimate counting the alpha data exactly where the renderer makes it.
#include "raster/alpha_casters.h"

#include <gtest/gtest.h>

#include "raster/memory.h"
#include "tests/kit/render_checked.h"
#include "tests/kit/test_scenes.h"

namespace shadowlab::raster {
namespace {

using test::alphaMaterial;
using test::checkerTexture;

// The sphere over the plane with a 1x1 quad of material `m` above it (the last material).
scene::Scene withLeaf(const scene::Material& m, double height = 2.0) {
    return test::withLeaf(test::makeScene(test::SphereOverPlane{}), height, m);
}

// A MASK material of opacity 0.5 (a semi-transparent caster: drawn by the transmittance passes).
scene::Material semiMaskOf(std::shared_ptr<const scene::AlphaTexture> tex = nullptr) {
    scene::Material m = alphaMaterial("leaf", scene::AlphaMode::Mask, std::move(tex));
    m.opacity = 0.5;
    return m;
}

scene::Material blendOf(double factor, std::shared_ptr<const scene::AlphaTexture> tex = nullptr) {
    scene::Material m = alphaMaterial("leaf", scene::AlphaMode::Blend, std::move(tex));
    m.alphaFactor = factor;
    return m;
}

TEST(AlphaPlan, EachPassTestsAlphaOnlyWhereItCanCut) {
    struct Case {
        const char* what;
        scene::Material material;
        bool transmittance;
        AlphaTests tests;
        bool transmittanceReads, data;
    };
    const Case cases[] = {
        // MASK: alpha 1 never falls below the cutoff 0.5; a checker texel 0 does. An opaque MASK
        // caster is drawn by the depth pass only, a semi-transparent one by the transmittance passes.
        {"MASK without a texture",
         alphaMaterial("leaf", scene::AlphaMode::Mask, nullptr),
         true,
         {false, false},
         false,
         false},
        {"MASK with texels 1 and 0",
         alphaMaterial("leaf", scene::AlphaMode::Mask, checkerTexture(2, 1.0f, 0.0f)),
         true,
         {true, true},
         false,
         true},
        {"MASK of opacity 0.5 without a texture", semiMaskOf(), true, {false, false}, false, false},
        {"MASK of opacity 0.5 with texels 1 and 0",
         semiMaskOf(checkerTexture(2, 1.0f, 0.0f)),
         true,
         {true, true},
         true,
         true},
        {"MASK of opacity 0.5 with texels 1 and 0, no transmittance passes",
         semiMaskOf(checkerTexture(2, 1.0f, 0.0f)),
         false,
         {true, true},
         false,
         true},
        // BLEND: the camera looks through alpha under 0.5 (0.3 does, 0.6 does not); the depth pass
        // never tests it.
        {"BLEND of alpha 0.3", blendOf(0.3), true, {false, true}, false, true},
        {"BLEND of alpha 0.6", blendOf(0.6), true, {false, false}, false, false},
        // A textured BLEND caster lets 1 − alpha(uv) through: the transmittance passes read its
        // texels even where the camera's test cannot cut; without those passes nothing does.
        {"BLEND with texels 1 and 0.6, transmittance passes",
         blendOf(1.0, checkerTexture(2, 1.0f, 0.6f)),
         true,
         {false, false},
         true,
         true},
        {"BLEND with texels 1 and 0.6, no transmittance passes",
         blendOf(1.0, checkerTexture(2, 1.0f, 0.6f)),
         false,
         {false, false},
         false,
         false},
    };
    for (const Case& c : cases) {
        const scene::Scene s = withLeaf(c.material);
        const AlphaPlan plan = planAlpha(s, c.transmittance);
        ASSERT_EQ(plan.byMaterial.size(), s.materials.size()) << c.what;
        EXPECT_EQ(plan.byMaterial.back().depth, c.tests.depth) << c.what;
        EXPECT_EQ(plan.byMaterial.back().camera, c.tests.camera) << c.what;
        EXPECT_FALSE(plan.byMaterial.front().depth || plan.byMaterial.front().camera) << c.what << ": the opaque plane";
        EXPECT_EQ(plan.transmittanceReads, c.transmittanceReads) << c.what;
        EXPECT_EQ(plan.data, c.data) << c.what;
        // With idle tests kept, every MASK material is tested in both passes, every BLEND one by
        // the camera, and the transmittance passes read a semi-transparent MASK caster's alpha.
        const AlphaPlan all = planAlpha(s, c.transmittance, false);
        const scene::AlphaMode mode = c.material.alphaMode;
        EXPECT_EQ(all.byMaterial.back().depth, mode == scene::AlphaMode::Mask) << c.what;
        EXPECT_TRUE(all.byMaterial.back().camera) << c.what;
        EXPECT_EQ(all.transmittanceReads,
                  c.transmittanceReads || (c.transmittance && mode == scene::AlphaMode::Mask && !c.material.opaque()))
            << c.what;
        EXPECT_TRUE(all.data) << c.what;
    }
}

TEST(AlphaPlan, AMaterialNoObjectUsesPlansNothing) {
    scene::Scene s = test::makeScene(test::SphereOverPlane{});
    s.materials.push_back(alphaMaterial("unused", scene::AlphaMode::Mask, checkerTexture(2, 1.0f, 0.0f)));
    const AlphaPlan plan = planAlpha(s, true);
    EXPECT_FALSE(plan.byMaterial.back().depth || plan.byMaterial.back().camera);
    EXPECT_FALSE(plan.transmittanceReads);
    EXPECT_FALSE(plan.data);
}

TEST(AlphaPlan, TheMemoryEstimateCountsTheAlphaDataWhereTheRendererMakesIt) {
    const scene::RasterSettings settings = test::validatedSettings(512, 0.01, 1.0, scene::ShadowFilter::Pcf2x2);
    auto estimate = [&](const scene::Scene& s) { return estimateMemoryBytes(s, test::planFor(s, settings), settings); };
    // A BLEND leaf the camera looks through (alpha 0.3) gets UVs and alpha records; one it cannot
    // (0.6) none. Both are semi-transparent casters, so everything else is the same: the difference
    // is at least one record per object id (and the unused 0) and a UV for each vertex of the
    // quad's two triangles.
    const scene::Scene seen = withLeaf(blendOf(0.3)), unseen = withLeaf(blendOf(0.6));
    ASSERT_TRUE(test::planFor(seen, settings).needsTransmittanceMap);
    ASSERT_TRUE(test::planFor(unseen, settings).needsTransmittanceMap);
    EXPECT_GE(estimate(seen) - estimate(unseen), (seen.objects.size() + 1) * 32 + 2 * 24);
    // A MASK leaf that cannot cut, under a BLEND pane (transmittance passes): the alpha data is
    // left out, so it costs what an opaque leaf does.
    auto underPane = [](scene::Material leaf) { return test::withLeaf(withLeaf(blendOf(0.6), 2.5), 2.0, leaf); };
    const scene::Scene idleMask = underPane(alphaMaterial("leaf", scene::AlphaMode::Mask, nullptr));
    const scene::Scene opaque = underPane(alphaMaterial("leaf", scene::AlphaMode::Opaque, nullptr));
    EXPECT_EQ(estimate(idleMask), estimate(opaque));
    const scene::Scene cutting =
        underPane(alphaMaterial("leaf", scene::AlphaMode::Mask, checkerTexture(2, 1.0f, 0.0f)));
    EXPECT_GT(estimate(cutting), estimate(opaque));
}

}  // namespace
}  // namespace shadowlab::raster
