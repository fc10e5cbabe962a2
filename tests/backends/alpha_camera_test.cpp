// tests/backends/alpha_camera_test.cpp: what the camera sees through alpha (docs/raytrace.md,
// "What the camera sees"), in the raster lit pass (lavapipe, validation layer on), the float ray
// tracer and the double-precision reference, against the visible surface worked out by hand.
//
// The set-up: a 12×12 ground (object 0, id 1) at y = 0 and a 2×2 quad (object 1, id 2) at
// height 3 over the origin, seen head-on from (0, 10, 0) looking down (up −z), 160×160 pixels,
// 30° vertical field of view. A pixel's centre ray crosses the quad's plane at
// (x, 3, z) = eye + 7·d/|d_y|; there the quad's (u, v) is (x/2 + 1/2, −z/2 + 1/2) (uAxis +x,
// vAxis −z, scene/scene.h quadAxes), and an n×n texture's texel is (⌊u·n⌋, ⌊v·n⌋).
#include <cmath>
#include <memory>

#include <gtest/gtest.h>

#include "scene/camera.h"
#include "scene/settings.h"
#include "tests/kit/render_checked.h"
#include "tests/kit/test_scenes.h"

namespace shadowlab {
namespace {

using scene::Vec2;
using scene::Vec3;
using test::Frames;

constexpr double kHeight = 3.0;
constexpr int kPixels = 160;

scene::Object quad(const Vec3& center, double side, int material) {
    return test::horizontalQuad("quad", center, side, side, material);
}

scene::Scene stage(const scene::Material& card) {
    scene::Scene s;
    s.camera = {.position = Vec3(0, 10, 0),
                .lookAt = Vec3(0),
                .up = Vec3(0, 0, -1),
                .fovYDegrees = 30.0,
                .width = kPixels,
                .height = kPixels};  // near 0.1, far 100
    scene::Material ground;
    ground.name = "ground";
    s.materials = {ground, card};
    scene::Light l;
    l.direction = glm::normalize(Vec3(0.3, -1, 0.2));
    l.intensity = 1.0;
    s.lights.push_back(l);
    s.objects.push_back(quad(Vec3(0, 0, 0), 12.0, 0));
    s.objects.push_back(quad(Vec3(0, kHeight, 0), 2.0, 1));
    return s;
}

scene::Material card(scene::AlphaMode mode, std::shared_ptr<const scene::AlphaTexture> tex, double cutoff = 0.5) {
    return test::alphaMaterial("card", mode, std::move(tex), cutoff);
}

// The three backends with the scene's settings and a 1024 map.
Frames renderAll(const scene::Scene& s) {
    scene::RenderSettings settings = scene::resolveSettings(s, {});
    settings.raster.shadowMapSize = 1024;
    return test::renderAll(s, settings);
}

// Which object a pixel's centre ray sees, by hand: the quad's cell (i, j) of an n×n texture
// where `opaqueCell(i, j)`, else the ground. `edge` is set where the crossing is within one pixel
// footprint (7 · 2·tan 15° / 160 ≈ 0.023 at the quad) of a cell's or the quad's border: there a
// float UV, interpolated by the rasterizer or from barycentrics, may land in the next cell.
template <typename OpaqueCell>
float expectedId(const scene::Scene& s, int x, int y, int n, OpaqueCell opaqueCell, bool& edge) {
    const scene::CameraBasis c = scene::cameraBasis(s.camera);
    const Vec3 d = scene::pixelDirection(c, x, y);
    const Vec3 p = c.position + d * ((c.position.y - kHeight) / -d.y);
    const double footprint = (c.position.y - kHeight) * 2.0 * c.tanHalfFovY / kPixels;
    const double u = p.x / 2.0 + 0.5, v = -p.z / 2.0 + 0.5;
    edge = false;
    const double f = footprint / 2.0;                                 // in (u, v)
    if (u < -f || u > 1.0 + f || v < -f || v > 1.0 + f) return 1.0f;  // well past the quad: the ground
    for (double t : {u, v}) {
        const double cell = t * n;  // the borders are at the integers 0..n, in cells
        edge = edge || std::abs(cell - std::round(cell)) * (2.0 / n) < footprint;
    }
    if (u < 0.0 || u > 1.0 || v < 0.0 || v > 1.0) return 1.0f;  // past the quad: the ground
    const int i = std::min(int(std::floor(u * n)), n - 1), j = std::min(int(std::floor(v * n)), n - 1);
    return opaqueCell(i, j) ? 2.0f : 1.0f;
}

// Every pixel away from the borders shows the expected id in all three backends, with the depth
// (along the view, which is −y) of that surface: 7 on the quad, 10 on the ground. At the border
// band the three may differ, but only there.
template <typename OpaqueCell>
void expectVisible(const scene::Scene& s, const Frames& f, int n, OpaqueCell opaqueCell) {
    int quadPixels = 0, groundPixels = 0, band = 0;
    for (int y = 0; y < kPixels; ++y)
        for (int x = 0; x < kPixels; ++x) {
            const std::size_t px = std::size_t(y) * kPixels + std::size_t(x);
            bool edge = false;
            const float want = expectedId(s, x, y, n, opaqueCell, edge);
            if (edge) {
                ++band;
                continue;
            }
            (want == 2.0f ? quadPixels : groundPixels)++;
            const float depth = want == 2.0f ? 7.0f : 10.0f;
            for (const scene::Frame* frame : {&f.raster, &f.raytrace, &f.reference}) {
                const char* which = frame == &f.raster ? "raster" : frame == &f.raytrace ? "raytrace" : "reference";
                ASSERT_EQ(frame->objectId[px], want) << which << " at pixel " << x << "," << y;
                ASSERT_NEAR(frame->depth[px], depth, 1e-3) << which << " at pixel " << x << "," << y;
            }
        }
    // The quad spans 2/(2·7·tan 15°) ≈ 53% of the view, 85 pixels a side: its cells are ~21 pixels,
    // the band 2 pixels wide at each of the 2(n + 1) border lines.
    EXPECT_GT(quadPixels + groundPixels, kPixels * kPixels / 2);
    EXPECT_LT(band, 2 * (n + 1) * 4 * 90);
}

TEST(AlphaCamera, TheCameraSeesTheGroundThroughAMaskedCheckerboard) {
    // 4×4 checker of alpha 1 and 0, cutoff 0.5: the camera sees the card in the x + y even cells
    // and the ground (id 1, depth 10) in the others.
    const scene::Scene s = stage(card(scene::AlphaMode::Mask, test::checkerTexture(4, 1.0f, 0.0f)));
    const Frames f = renderAll(s);
    int opaque = 0;
    expectVisible(s, f, 4, [&](int i, int j) { return (i + j) % 2 == 0; });
    for (int j = 0; j < 4; ++j)
        for (int i = 0; i < 4; ++i) opaque += (i + j) % 2 == 0;
    EXPECT_EQ(opaque, 8);
    // The three agree on every pixel but a band at the borders: count the disagreements, which
    // must lie within one pixel of a border line (at most one pixel wide each).
    for (int y = 0; y < kPixels; ++y)
        for (int x = 0; x < kPixels; ++x) {
            const std::size_t px = std::size_t(y) * kPixels + std::size_t(x);
            bool edge = false;
            expectedId(
                s, x, y, 4, [](int i, int j) { return (i + j) % 2 == 0; }, edge);
            if (f.raster.objectId[px] != f.reference.objectId[px] ||
                f.raytrace.objectId[px] != f.reference.objectId[px]) {
                EXPECT_TRUE(edge) << "the backends disagree off the border band at pixel " << x << "," << y;
            }
        }
}

TEST(AlphaCamera, TheCutoffDecidesWhatTheCameraSees) {
    // Alphas 0.6 and 0.3: cutoff 0.5 shows the 0.6 cells only; cutoff 0.2 the whole card.
    const scene::Scene some = stage(card(scene::AlphaMode::Mask, test::checkerTexture(4, 0.6f, 0.3f), 0.5));
    expectVisible(some, renderAll(some), 4, [](int i, int j) { return (i + j) % 2 == 0; });
    const scene::Scene all = stage(card(scene::AlphaMode::Mask, test::checkerTexture(4, 0.6f, 0.3f), 0.2));
    expectVisible(all, renderAll(all), 4, [](int, int) { return true; });
}

TEST(AlphaCamera, OpaqueIgnoresTheAlphaForTheCamera) {
    // A texture of zeros and a cutoff that would cut every texel: OPAQUE shows the whole card.
    const scene::Scene s = stage(card(scene::AlphaMode::Opaque, test::checkerTexture(4, 0.0f, 0.1f), 0.9));
    expectVisible(s, renderAll(s), 4, [](int, int) { return true; });
}

TEST(AlphaCamera, BlendIsSeenWhereItsAlphaIsAtLeastOneHalf) {
    // BLEND (no cutoff in glTF): the camera sees the texels of alpha ≥ kBlendVisibleAlpha = 0.5
    // and looks through the others; 0.5 itself is seen.
    static_assert(scene::kBlendVisibleAlpha == 0.5);
    const scene::Scene s = stage(card(scene::AlphaMode::Blend, test::checkerTexture(4, 0.5f, 0.45f)));
    expectVisible(s, renderAll(s), 4, [](int i, int j) { return (i + j) % 2 == 0; });
    // Untextured BLEND: the factor alone decides, for the whole card.
    scene::Material faint = card(scene::AlphaMode::Blend, nullptr);
    faint.alphaFactor = 0.3;
    const scene::Scene through = stage(faint);
    expectVisible(through, renderAll(through), 4, [](int, int) { return false; });
    faint.alphaFactor = 0.8;
    const scene::Scene seen = stage(faint);
    expectVisible(seen, renderAll(seen), 4, [](int, int) { return true; });
}

}  // namespace
}  // namespace shadowlab
