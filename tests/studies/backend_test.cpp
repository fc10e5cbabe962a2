// tests/studies/backend_test.cpp: the backend seam. A renderer made once and reused across frames
// draws what the backend's one-shot entry point draws for each frame's scene; the raster one on
// lavapipe with the validation layer, which must stay silent.
#include "studies/backend.h"

#include <stdexcept>

#include <gtest/gtest.h>

#include "scene/loader.h"

namespace shadowlab::studies {
namespace {

scene::Scene smallSeed() {
    scene::Scene s = scene::loadScene(scene::findScene("seed"));
    s.camera.width = 64;
    s.camera.height = 36;
    return s;
}

void expectSamePixels(const scene::Frame& a, const scene::Frame& b) {
    ASSERT_EQ(a.width, b.width);
    ASSERT_EQ(a.height, b.height);
    EXPECT_EQ(a.visibility, b.visibility);
    EXPECT_EQ(a.objectId, b.objectId);
    EXPECT_EQ(a.beauty, b.beauty);
}

TEST(BackendSeam, AReusedReferenceRendererDrawsEachFrameAsTheOneShotReference) {
    scene::Scene first = smallSeed();
    const scene::RenderSettings settings = scene::resolveSettings(first, {});
    const scene::RenderPlan plan = scene::makeRenderPlan(first, settings);
    const std::unique_ptr<BackendRenderer> r = makeRenderer(scene::Backend::Reference, first, plan, settings);
    const scene::Frame a = r->render();
    EXPECT_EQ(a.attributes.at("backend"), "reference");
    expectSamePixels(a, renderFrame(scene::Backend::Reference, first, plan, settings));

    // The next frame: the camera moves a quarter of the way to the look-at point, so the
    // sphere covers other pixels; the renderer's trees stay, the frame follows the new camera.
    scene::Scene next = first;
    next.camera.position += 0.25 * (next.camera.lookAt - next.camera.position);
    r->update(next);
    const scene::Frame b = r->render();
    const scene::Frame expected =
        renderFrame(scene::Backend::Reference, next, scene::makeRenderPlan(next, settings), settings);
    expectSamePixels(b, expected);
    EXPECT_NE(a.objectId, b.objectId);  // not vacuous: the two frames differ
    EXPECT_EQ(b.timing("setup"), 0.0);  // the setup was the constructor's
}

TEST(BackendSeam, TheRayTracerHasNoHeldView) {
    const scene::Scene s = smallSeed();
    const scene::RenderSettings settings = scene::resolveSettings(s, {});
    const std::unique_ptr<BackendRenderer> r =
        makeRenderer(scene::Backend::Raytrace, s, scene::makeRenderPlan(s, settings), settings);
    EXPECT_THROW(r->update(s, s.camera), std::logic_error);
    EXPECT_EQ(r->render().attributes.at("backend"), "raytrace");
}

TEST(BackendSeam, TheRasterRendererDrawsWhatTheOneShotRasterDraws) {
    const scene::Scene s = smallSeed();
    scene::SettingsOverrides o;
    o.validate = true;
    const scene::RenderSettings settings = scene::resolveSettings(s, o);
    const scene::RenderPlan plan = scene::makeRenderPlan(s, settings);
    const scene::Frame once = renderFrame(scene::Backend::Raster, s, plan, settings);
    EXPECT_EQ(once.attributes.at("backend"), "raster");
    EXPECT_EQ(once.attributes.at("validation_messages"), "0");
    const std::unique_ptr<BackendRenderer> r = makeRenderer(scene::Backend::Raster, s, plan, settings);
    r->update(s);
    expectSamePixels(r->render(), once);
    EXPECT_EQ(r->validationMessages(), 0);
}

}  // namespace
}  // namespace shadowlab::studies
