// tests/kit/render_checked.h: the one way the tests render with the backends: the raster backend
// always with VK_LAYER_KHRONOS_validation, failing the test on any validation message, and where a
// test judges several backends, the ray tracer and the double-precision reference beside it.
#pragma once

#include <optional>
#include <string>

#include <gtest/gtest.h>

#include "raster/context.h"
#include "raster/renderer.h"
#include "scene/frame.h"
#include "scene/scene.h"
#include "scene/settings.h"

namespace shadowlab::test {

// Raster settings for a validated render (the other fields at their defaults).
inline scene::RasterSettings validatedSettings(int shadowMapSize, double depthBias, double slopeBias,
                                               scene::ShadowFilter filter) {
    scene::RasterSettings r;
    r.shadowMapSize = shadowMapSize;
    r.depthBias = depthBias;
    r.slopeBias = slopeBias;
    r.filter = filter;
    r.validate = true;
    return r;
}

// A raster render of `s` with the validation layer on (whatever settings.validate says), failing
// the test when the layer printed anything (the messages are above, on stderr). The plan is made
// from `settings`; the first form makes it from RenderSettings{} with `raster` as its raster part.
scene::Frame renderChecked(const scene::Scene& s, const scene::RasterSettings& raster,
                           raster::RenderDebug* debug = nullptr);
scene::Frame renderChecked(const scene::Scene& s, scene::RenderSettings settings, raster::RenderDebug* debug = nullptr);

// The double-precision reference of `s`: plan and base settings from `settings`, or from
// resolveSettings(s, {}).
scene::Frame renderReference(const scene::Scene& s, const scene::RenderSettings& settings);
scene::Frame renderReference(const scene::Scene& s);

// One scene through all three: renderChecked, the float ray tracer and the reference, each with
// the one plan made from `settings`.
struct Frames {
    scene::Frame raster, raytrace, reference;
};
Frames renderAll(const scene::Scene& s, const scene::RenderSettings& settings);

// Every per-pixel channel of `actual` (beauty, visibility, object id, N·L, Z, blocker ids,
// per-light visibility) equal to `expected`'s, bit for bit; `what` names the pair in a failure.
void expectSamePixels(const scene::Frame& actual, const scene::Frame& expected, const std::string& what = "");

// With SHADOWLAB_TEST_PNG_DIR set, writes the frame's beauty there as NAME.png, to look at.
void writePngToLookAt(const scene::Frame& f, const std::string& name);

// For tests that drive raster/ below the Renderer: a Context with the validation layer, whose
// destruction (the device's and instance's included) fails the test if the layer said anything.
class ValidatedContext {
public:
    ValidatedContext() { ctx_.emplace(raster::ContextOptions{.validate = true, .log = &log_}); }
    ~ValidatedContext() {
        ctx_.reset();
        EXPECT_EQ(log_.count.load(), 0) << "validation messages were printed above";
    }
    ValidatedContext(const ValidatedContext&) = delete;
    ValidatedContext& operator=(const ValidatedContext&) = delete;
    raster::Context& get() { return *ctx_; }
    int messages() const { return log_.count.load(); }

private:
    raster::ValidationLog log_;
    std::optional<raster::Context> ctx_;
};

// scenes/seed.json at width x height (the shipped seed, its materials and shadow block included).
scene::Scene loadSeed(int width = 160, int height = 90);

}  // namespace shadowlab::test
