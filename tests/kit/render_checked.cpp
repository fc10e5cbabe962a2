// tests/kit/render_checked.cpp: the tests' render helpers (tests/kit/render_checked.h).
#include "tests/kit/render_checked.h"

#include <cstdlib>
#include <filesystem>

#include <gtest/gtest.h>

#include "raytrace/renderer.h"
#include "scene/frame_io.h"
#include "scene/loader.h"
#include "scene/render_plan.h"

namespace shadowlab::test {

namespace {

scene::Frame renderRasterChecked(const scene::Scene& s, const scene::RenderPlan& plan, scene::RasterSettings raster,
                                 raster::RenderDebug* debug) {
    raster.validate = true;
    scene::Frame f = raster::render(s, plan, raster, debug);
    EXPECT_EQ(f.attributes["validation_messages"], "0") << "validation messages were printed above";
    return f;
}

}  // namespace

scene::Frame renderChecked(const scene::Scene& s, const scene::RasterSettings& raster, raster::RenderDebug* debug) {
    scene::RenderSettings settings;
    settings.raster = raster;
    return renderChecked(s, settings, debug);
}

scene::Frame renderChecked(const scene::Scene& s, scene::RenderSettings settings, raster::RenderDebug* debug) {
    settings.raster.validate = true;
    return renderRasterChecked(s, scene::makeRenderPlan(s, settings), settings.raster, debug);
}

scene::Frame renderReference(const scene::Scene& s, const scene::RenderSettings& settings) {
    return raytrace::renderReference(s, scene::makeRenderPlan(s, settings),
                                     scene::referenceSettings(settings.raytrace));
}

scene::Frame renderReference(const scene::Scene& s) { return renderReference(s, scene::resolveSettings(s, {})); }

Frames renderAll(const scene::Scene& s, const scene::RenderSettings& settings) {
    scene::RenderSettings validated = settings;
    validated.raster.validate = true;
    const scene::RenderPlan plan = scene::makeRenderPlan(s, validated);
    Frames f;
    f.raster = renderRasterChecked(s, plan, validated.raster, nullptr);
    f.raytrace = raytrace::render(s, plan, validated.raytrace);
    f.reference = raytrace::renderReference(s, plan, scene::referenceSettings(validated.raytrace));
    return f;
}

void expectSamePixels(const scene::Frame& actual, const scene::Frame& expected, const std::string& what) {
    EXPECT_EQ(actual.beauty, expected.beauty) << what;
    EXPECT_EQ(actual.visibility, expected.visibility) << what;
    EXPECT_EQ(actual.objectId, expected.objectId) << what;
    EXPECT_EQ(actual.ndotl, expected.ndotl) << what;
    EXPECT_EQ(actual.depth, expected.depth) << what;
    EXPECT_EQ(actual.blockerId, expected.blockerId) << what;
    EXPECT_EQ(actual.lightVisibility, expected.lightVisibility) << what;
}

void writePngToLookAt(const scene::Frame& f, const std::string& name) {
    if (const char* dir = std::getenv("SHADOWLAB_TEST_PNG_DIR"))
        scene::writePngLinear(std::filesystem::path(dir) / (name + ".png"), f.width, f.height, f.beauty);
}

scene::Scene loadSeed(int width, int height) {
    scene::Scene s = scene::loadScene(std::filesystem::path(SHADOWLAB_SOURCE_DIR) / "scenes" / "seed.json");
    s.camera.width = width;
    s.camera.height = height;
    return s;
}

}  // namespace shadowlab::test
