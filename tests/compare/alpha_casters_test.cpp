// tests/compare/alpha_casters_test.cpp: alpha-tested (MASK) and blended (BLEND) casters in the
// raster depth and transmittance passes (lavapipe, validation layer on), the float ray tracer and
// the double-precision reference, against what the glTF 2.0 alpha rules give by hand.
//
// The set-up of every test: a ground at y = 0, a 2×2 caster at height 3 centred at the origin,
// a directional light travelling along (1, −1, 0), so a caster point (x, 3, z) shadows the ground
// point (x + 3, 0, z); a camera straight above the shadow at (3, 10, 0), which sees the ground
// there past the caster (a ray to a ground point with x ≥ 2 crosses height 3 at x ≥ 2.3 > 1).
#include <cmath>
#include <memory>

#include <gtest/gtest.h>

#include "raster/renderer.h"
#include "raytrace/renderer.h"
#include "scene/camera.h"
#include "scene/render_plan.h"
#include "scene/settings.h"

namespace shadowlab::compare {
namespace {

using scene::Vec2;
using scene::Vec3;

constexpr double kHeight = 3.0;
constexpr double kSide = 2.0;

std::shared_ptr<scene::AlphaTexture> texture(int w, int h, std::vector<float> alpha,
                                             scene::TextureWrap s = scene::TextureWrap::Repeat,
                                             scene::TextureWrap t = scene::TextureWrap::Repeat) {
    auto tex = std::make_shared<scene::AlphaTexture>();
    tex->file = "test-texture";
    tex->width = w;
    tex->height = h;
    tex->alpha = std::move(alpha);
    tex->wrapS = s;
    tex->wrapT = t;
    return tex;
}

// An N×N checkerboard of alpha `a` (texel x + y even) and `b`.
std::shared_ptr<scene::AlphaTexture> checker(int n, float a, float b) {
    std::vector<float> alpha;
    for (int y = 0; y < n; ++y)
        for (int x = 0; x < n; ++x) alpha.push_back((x + y) % 2 == 0 ? a : b);
    return texture(n, n, alpha);
}

scene::Object quad(const Vec3& center, double side, int material, Vec2 uvMin = Vec2(0), Vec2 uvMax = Vec2(1)) {
    scene::Quad q;
    q.center = center;
    q.normal = Vec3(0, 1, 0);
    q.size = Vec2(side, side);
    q.uvMin = uvMin;
    q.uvMax = uvMax;
    scene::quadAxes(q.normal, q.uAxis, q.vAxis);
    return {"quad", q, material};
}

// Ground (material 0) and the caster material `caster` (index 1) on the 2×2 quad at height 3.
scene::Scene stage(const scene::Material& caster, Vec2 uvMin = Vec2(0), Vec2 uvMax = Vec2(1)) {
    scene::Scene s;
    s.camera.position = Vec3(3, 10, 0);
    s.camera.lookAt = Vec3(3, 0, 0);
    s.camera.up = Vec3(0, 0, -1);
    s.camera.fovYDegrees = 30.0;
    s.camera.width = 160;
    s.camera.height = 160;
    s.camera.near = 0.1;
    s.camera.far = 100.0;
    scene::Material ground;
    ground.name = "ground";
    s.materials = {ground, caster};
    scene::Light l;
    l.direction = glm::normalize(Vec3(1, -1, 0));
    l.intensity = 1.0;
    s.lights.push_back(l);
    s.objects.push_back(quad(Vec3(3, 0, 0), 12.0, 0));
    s.objects.push_back(quad(Vec3(0, kHeight, 0), kSide, 1, uvMin, uvMax));
    return s;
}

// The pixel that sees ground point p (inverse of scene::pixelDirection).
std::size_t pixelOf(const scene::Scene& s, const Vec3& p) {
    const scene::CameraBasis c = scene::cameraBasis(s.camera);
    const Vec3 d = p - c.position;
    const double f = glm::dot(d, c.forward);
    const double sx = glm::dot(d, c.right) / f / (c.tanHalfFovY * c.aspect);
    const double sy = glm::dot(d, c.up) / f / c.tanHalfFovY;
    const int x = int(std::floor((sx + 1.0) * 0.5 * c.width));
    const int y = int(std::floor((1.0 - sy) * 0.5 * c.height));
    return std::size_t(y) * std::size_t(c.width) + std::size_t(x);
}

// The ground point under the centre of the caster's texel cell (i, j) of an n×m grid over the
// quad's (u, v) (u along uAxis = +x, v along vAxis = −z for a normal +y; scene/scene.h quadAxes).
Vec3 groundUnderCell(int i, int j, int n, int m) {
    const double u = (i + 0.5) / n, v = (j + 0.5) / m;
    const Vec3 onCaster(kSide * (u - 0.5), kHeight, -kSide * (v - 0.5));
    return onCaster + Vec3(kHeight, -kHeight, 0);
}

struct Frames {
    scene::Frame raster, raytrace, reference;
};

Frames renderAll(const scene::Scene& s) {
    scene::RenderSettings settings = scene::resolveSettings(s, {});
    settings.raster.shadowMapSize = 1024;
    settings.raster.validate = true;
    settings.raster.filter = scene::ShadowFilter::None;
    const scene::RenderPlan plan = scene::makeRenderPlan(s, settings);
    Frames f;
    f.raster = raster::render(s, plan, settings.raster);
    EXPECT_EQ(f.raster.attributes.at("validation_messages"), "0") << "validation messages were printed above";
    f.raytrace = raytrace::render(s, plan, settings.raytrace);
    f.reference = raytrace::renderReference(s, plan, scene::referenceSettings(settings.raytrace));
    return f;
}

// Every backend's visibility at the ground under each cell of an n×m grid equals expected(i, j).
template <typename Expected>
void expectCells(const scene::Scene& s, const Frames& f, int n, int m, Expected expected, double tolerance = 1e-4) {
    for (int j = 0; j < m; ++j)
        for (int i = 0; i < n; ++i) {
            const std::size_t px = pixelOf(s, groundUnderCell(i, j, n, m));
            ASSERT_EQ(f.reference.objectId[px], 1.0f) << "the camera must see the ground there";
            const double want = expected(i, j);
            EXPECT_NEAR(f.raster.visibility[px], want, tolerance) << "raster, cell " << i << "," << j;
            EXPECT_NEAR(f.raytrace.visibility[px], want, tolerance) << "raytrace, cell " << i << "," << j;
            EXPECT_NEAR(f.reference.visibility[px], want, tolerance) << "reference, cell " << i << "," << j;
        }
}

scene::Material alphaMaterial(scene::AlphaMode mode, std::shared_ptr<const scene::AlphaTexture> tex, double cutoff = 0.5) {
    scene::Material m;
    m.name = "caster";
    m.alphaMode = mode;
    m.alphaCutoff = cutoff;
    m.alphaTexture = std::move(tex);
    return m;
}

TEST(AlphaCasters, AMaskedCheckerboardCastsTheCheckerboardAndAlphaAtTheCutoffIsOpaque) {
    // 4×4 checker of alpha 0.5 and 0.25, cutoff 0.5: glTF 3.9.4 says alpha < cutoff is
    // transparent, so the 0.5 cells (x + y even) cast and the 0.25 cells let the light through:
    // 8 shadowed and 8 lit cells on the ground, in the checker's pattern.
    const scene::Scene s = stage(alphaMaterial(scene::AlphaMode::Mask, checker(4, 0.5f, 0.25f), 0.5));
    const Frames f = renderAll(s);
    int shadowed = 0;
    expectCells(s, f, 4, 4, [&](int i, int j) {
        shadowed += (i + j) % 2 == 0;
        return (i + j) % 2 == 0 ? 0.0 : 1.0;
    });
    EXPECT_EQ(shadowed, 8);
    EXPECT_EQ(f.raster.attributes.at("alpha_casters"), "alpha-tested in the depth pass");
}

TEST(AlphaCasters, ACutoffJustAboveEveryAlphaLetsAllTheLightThrough) {
    // Both alphas (0.5, 0.25) below a cutoff of 0.50001: no cell casts.
    const scene::Scene s = stage(alphaMaterial(scene::AlphaMode::Mask, checker(4, 0.5f, 0.25f), 0.50001));
    expectCells(s, renderAll(s), 4, 4, [](int, int) { return 1.0; });
}

TEST(AlphaCasters, OpaqueIgnoresTheAlpha) {
    // The same texture in OPAQUE (and a cutoff that would cut every texel): the whole quad casts.
    const scene::Scene s = stage(alphaMaterial(scene::AlphaMode::Opaque, checker(4, 0.0f, 0.25f), 0.9));
    expectCells(s, renderAll(s), 4, 4, [](int, int) { return 0.0; });
}

TEST(AlphaCasters, BlendWithConstantAlphaLetsOneMinusAlphaThroughPerLayer) {
    // BLEND, alpha factor 0.3, no texture: one layer lets 0.7 through; a second such quad at
    // height 2 (its shadow on the ground is shifted by 1 in x against the first's) gives
    // 0.7² = 0.49 where both shadows overlap (ground x in [3, 4]) and 0.7 where only one is.
    scene::Material blend = alphaMaterial(scene::AlphaMode::Blend, nullptr);
    blend.alphaFactor = 0.3;
    scene::Scene s = stage(blend);
    const Frames one = renderAll(s);
    expectCells(s, one, 4, 4, [](int, int) { return 0.7; });
    s.objects.push_back(quad(Vec3(0, 2, 0), kSide, 1));
    const Frames two = renderAll(s);
    for (double x : {2.25, 2.75, 3.25, 3.75, 4.25, 4.75})
        for (double z : {-0.5, 0.5}) {
            const std::size_t px = pixelOf(s, Vec3(x, 0, z));
            // A quad at height h over x in [−1, 1] shadows ground x in [h − 1, h + 1]: the upper
            // [2, 4], the lower [1, 3]. Overlap [2, 3) → 0.49; [3, 4) the upper only → 0.7.
            const double want = x < 3.0 ? 0.49 : x < 4.0 ? 0.7 : 1.0;
            EXPECT_NEAR(two.raster.visibility[px], want, 1e-4) << "raster at x " << x;
            EXPECT_NEAR(two.raytrace.visibility[px], want, 1e-4) << "raytrace at x " << x;
            EXPECT_NEAR(two.reference.visibility[px], want, 1e-4) << "reference at x " << x;
        }
}

TEST(AlphaCasters, BlendWithATextureLetsOneMinusTheTexelsAlphaThrough) {
    // BLEND with the 0.5 / 0.25 checker: 0.5 and 0.75 of the light in the checker's pattern.
    const scene::Scene s = stage(alphaMaterial(scene::AlphaMode::Blend, checker(4, 0.5f, 0.25f)));
    expectCells(s, renderAll(s), 4, 4, [](int i, int j) { return (i + j) % 2 == 0 ? 0.5 : 0.75; });
}

TEST(AlphaCasters, WrapModesRepeatClampAndMirrorAKnownPattern) {
    // A 2×1 texture, alpha (1, 0), MASK, u over [0, 2] on the quad: four cells of u width 0.5
    // at u centres 0.25, 0.75, 1.25, 1.75, i.e. unwrapped texel coordinates
    // floor(u·2) = 0, 1, 2, 3: REPEAT → texels 0 1 0 1 (cast, lit, cast, lit); CLAMP_TO_EDGE →
    // 0 1 1 1; MIRRORED_REPEAT → 0 1 1 0 (texel 0 casts, texel 1 is cut out).
    const std::vector<std::vector<double>> want = {{0, 1, 0, 1}, {0, 1, 1, 1}, {0, 1, 1, 0}};
    const scene::TextureWrap modes[] = {scene::TextureWrap::Repeat, scene::TextureWrap::ClampToEdge,
                                        scene::TextureWrap::MirroredRepeat};
    for (int k = 0; k < 3; ++k) {
        SCOPED_TRACE(k);
        const scene::Scene s = stage(alphaMaterial(scene::AlphaMode::Mask, texture(2, 1, {1.0f, 0.0f}, modes[k])),
                                     Vec2(0, 0), Vec2(2, 1));
        expectCells(s, renderAll(s), 4, 2, [&](int i, int) { return want[std::size_t(k)][std::size_t(i)]; });
    }
}

}  // namespace
}  // namespace shadowlab::compare
