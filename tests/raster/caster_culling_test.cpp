// tests/raster/caster_culling_test.cpp: objects that cannot cast onto what the camera sees are
// left out of a directional light's depth pass (raster::castsIntoView), on the seed scene, on
// lavapipe with the validation layer.
#include <filesystem>

#include <gtest/gtest.h>

#include "raster/renderer.h"
#include "scene/loader.h"
#include "scene/render_plan.h"

namespace shadowlab::raster {
namespace {

scene::Scene seedWith(const scene::Vec3& center, double radius) {
    scene::Scene s = scene::loadScene(std::filesystem::path(SHADOWLAB_SOURCE_DIR) / "scenes" / "seed.json");
    s.camera.width = 160;
    s.camera.height = 90;
    scene::Object extra = s.objects[0];  // the sphere's material
    extra.name = "extra";
    extra.shape = scene::Sphere{center, radius};
    s.objects.push_back(extra);
    return s;
}

scene::Frame rasterRender(const scene::Scene& s, bool cull) {
    scene::RenderSettings settings = scene::resolveSettings(s, {});
    settings.raster.validate = true;
    settings.raster.cullCasters = cull;
    scene::Frame f = render(s, scene::makeRenderPlan(s, settings), settings.raster);
    EXPECT_EQ(f.attributes["validation_messages"], "0") << "validation messages were printed above";
    return f;
}

TEST(RasterCasterCulling, AFarObjectThatCannotShadowTheViewIsCulledAndTheImageIsUnchanged) {
    // A sphere at (60, 1, 60), behind and far to the side of the camera at (0, 2, 6) looking at
    // -z: light travelling along (-1, -2, -1) puts its shadow at about (59.5, 0, 59.5), and across
    // the light it lies ~68 units from the origin, where the visible ground is at most ~15 away.
    const scene::Scene s = seedWith({60, 1, 60}, 1.0);
    const scene::Frame culled = rasterRender(s, true);
    const scene::Frame all = rasterRender(s, false);
    EXPECT_EQ(culled.attributes.at("culled_casters"), "1");
    EXPECT_EQ(all.attributes.at("culled_casters"), "0");
    EXPECT_EQ(culled.visibility, all.visibility);
    EXPECT_EQ(culled.beauty, all.beauty);
    EXPECT_EQ(culled.blockerId, all.blockerId);
}

TEST(RasterCasterCulling, AnObjectOutsideTheViewThatCastsIntoItIsKept) {
    // A sphere of radius 0.5 at (4, 9, 4) = (0, 1, 0) + 4·(1, 2, 1): straight up the light from the
    // seed sphere, above the camera's view (the top of the view at that distance is below y = 4),
    // so its shadow falls around the seed sphere's, on the visible ground.
    const scene::Scene s = seedWith({4, 9, 4}, 0.5);
    const scene::Frame f = rasterRender(s, true);
    EXPECT_EQ(f.attributes.at("culled_casters"), "0");
    // And its blocker id (3) shows on some ground pixels: it does cast into the view.
    int byExtra = 0;
    for (const float id : f.blockerId) byExtra += id == 3.0f ? 1 : 0;
    EXPECT_GT(byExtra, 0);
}

}  // namespace
}  // namespace shadowlab::raster
