// tests/backends/alpha_casters_test.cpp: alpha-tested (MASK) and blended (BLEND) casters in the
// raster depth and transmittance passes (lavapipe, validation layer on), the float ray tracer and
// the double-precision reference, against what the glTF 2.0 alpha rules give by hand.
//
// The set-up of every test: a ground at y = 0, a 2×2 caster at height 3 centred at the origin,
// a directional light travelling along (1, −1, 0), so a caster point (x, 3, z) shadows the ground
// point (x + 3, 0, z); a camera straight above the shadow at (3, 10, 0), which sees the ground
// there past the caster (a ray to a ground point with x ≥ 2 crosses height 3 at x ≥ 2.3 > 1).
#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <memory>

#include <gtest/gtest.h>

#include "scene/camera.h"
#include "scene/frame_io.h"
#include "scene/loader.h"
#include "scene/settings.h"
#include "tests/kit/render_checked.h"
#include "tests/kit/test_scenes.h"

namespace shadowlab {
namespace {

using scene::Vec2;
using scene::Vec3;
using test::Frames;

constexpr double kHeight = 3.0;
constexpr double kSide = 2.0;

using test::alphaTexture;
using test::checkerTexture;

scene::Object quad(const Vec3& center, double side, int material, Vec2 uvMin = Vec2(0), Vec2 uvMax = Vec2(1)) {
    scene::Object o = test::horizontalQuad("quad", center, side, side, material);
    std::get<scene::Quad>(o.shape).uvMin = uvMin;
    std::get<scene::Quad>(o.shape).uvMax = uvMax;
    return o;
}

// Ground (material 0) and the caster material `caster` (index 1) on the 2×2 quad at height 3.
scene::Scene stage(const scene::Material& caster, Vec2 uvMin = Vec2(0), Vec2 uvMax = Vec2(1)) {
    scene::Scene s;
    s.camera = {.position = Vec3(3, 10, 0),
                .lookAt = Vec3(3, 0, 0),
                .up = Vec3(0, 0, -1),
                .fovYDegrees = 30.0,
                .width = 160,
                .height = 160};  // near 0.1, far 100
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

// The ground point under the centre of the caster's texel cell (i, j) of an n×m grid over the
// quad's (u, v) (u along uAxis = +x, v along vAxis = −z for a normal +y; scene/scene.h quadAxes).
Vec3 groundUnderCell(int i, int j, int n, int m) {
    const double u = (i + 0.5) / n, v = (j + 0.5) / m;
    const Vec3 onCaster(kSide * (u - 0.5), kHeight, -kSide * (v - 0.5));
    return onCaster + Vec3(kHeight, -kHeight, 0);
}

// The three backends with the scene's settings, a 1024 map and hard raster shadows.
Frames renderAll(const scene::Scene& s) {
    scene::RenderSettings settings = scene::resolveSettings(s, {});
    settings.raster.shadowMapSize = 1024;
    settings.raster.filter = scene::ShadowFilter::None;
    return test::renderAll(s, settings);
}

// Every backend's visibility at the ground under each cell of an n×m grid equals expected(i, j).
template <typename Expected>
void expectCells(const scene::Scene& s, const Frames& f, int n, int m, Expected expected, double tolerance = 1e-4) {
    for (int j = 0; j < m; ++j)
        for (int i = 0; i < n; ++i) {
            const std::size_t px = test::pixelIndexOf(s, groundUnderCell(i, j, n, m));
            ASSERT_EQ(f.reference.objectId[px], 1.0f) << "the camera must see the ground there";
            const double want = expected(i, j);
            EXPECT_NEAR(f.raster.visibility[px], want, tolerance) << "raster, cell " << i << "," << j;
            EXPECT_NEAR(f.raytrace.visibility[px], want, tolerance) << "raytrace, cell " << i << "," << j;
            EXPECT_NEAR(f.reference.visibility[px], want, tolerance) << "reference, cell " << i << "," << j;
        }
}

scene::Material alphaMaterial(scene::AlphaMode mode, std::shared_ptr<const scene::AlphaTexture> tex,
                              double cutoff = 0.5) {
    return test::alphaMaterial("caster", mode, std::move(tex), cutoff);
}

TEST(AlphaCasters, AMaskedCheckerboardCastsTheCheckerboardAndAlphaAtTheCutoffIsOpaque) {
    // 4×4 checker of alpha 0.5 and 0.25, cutoff 0.5: glTF 3.9.4 says alpha < cutoff is
    // transparent, so the 0.5 cells (x + y even) cast and the 0.25 cells let the light through:
    // 8 shadowed and 8 lit cells on the ground, in the checker's pattern.
    const scene::Scene s = stage(alphaMaterial(scene::AlphaMode::Mask, checkerTexture(4, 0.5f, 0.25f), 0.5));
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
    const scene::Scene s = stage(alphaMaterial(scene::AlphaMode::Mask, checkerTexture(4, 0.5f, 0.25f), 0.50001));
    expectCells(s, renderAll(s), 4, 4, [](int, int) { return 1.0; });
}

TEST(AlphaCasters, OpaqueIgnoresTheAlpha) {
    // The same texture in OPAQUE (and a cutoff that would cut every texel): the whole quad casts.
    const scene::Scene s = stage(alphaMaterial(scene::AlphaMode::Opaque, checkerTexture(4, 0.0f, 0.25f), 0.9));
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
            const std::size_t px = test::pixelIndexOf(s, Vec3(x, 0, z));
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
    const scene::Scene s = stage(alphaMaterial(scene::AlphaMode::Blend, checkerTexture(4, 0.5f, 0.25f)));
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
        const scene::Scene s = stage(alphaMaterial(scene::AlphaMode::Mask, alphaTexture(2, 1, {1.0f, 0.0f}, modes[k])),
                                     Vec2(0, 0), Vec2(2, 1));
        expectCells(s, renderAll(s), 4, 2, [&](int i, int) { return want[std::size_t(k)][std::size_t(i)]; });
    }
}

// Möller–Trumbore in double: the ray o + t·d (t > 0) against one triangle, with its barycentrics.
bool hitTriangle(const Vec3& o, const Vec3& d, const Vec3& a, const Vec3& b, const Vec3& c, double& b1, double& b2) {
    const Vec3 e1 = b - a, e2 = c - a, p = glm::cross(d, e2);
    const double det = glm::dot(e1, p);
    if (std::abs(det) < 1e-12) return false;
    const Vec3 s = o - a;
    b1 = glm::dot(s, p) / det;
    const Vec3 q = glm::cross(s, e1);
    b2 = glm::dot(d, q) / det;
    const double t = glm::dot(e2, q) / det;
    return b1 >= 0 && b2 >= 0 && b1 + b2 <= 1 && t > 1e-6;
}

TEST(AlphaCasters, AlphaBlendModeTestCastsWhatTheGltfAlphaRulesSay) {
    // The glTF sample model: five test cards (OPAQUE, BLEND, MASK at cutoffs 0.25, 0.5, 0.75)
    // standing in front of a bed whose back board catches their shadows. For each bed pixel the test traces, in double and on its own, the shadow
    // ray from the pixel's surface point against the cards' triangles, interpolates their UVs and
    // applies glTF §3.9.4 (OPAQUE casts, MASK casts where alpha ≥ cutoff, BLEND lets 1 − alpha through);
    // every backend must give that, except within a band of texel and pixel edges.
    const std::filesystem::path file =
        std::filesystem::path(SHADOWLAB_SHARED_SCENES) / "AlphaBlendModeTest" / "AlphaBlendModeTest.gltf";
    if (!std::filesystem::exists(file)) GTEST_SKIP() << file << " is not here";
    scene::Scene s = scene::loadScene(file);
    // The cards stand 0.47 in front of the bed's back board (z = −0.47), facing +z; a light from
    // the front left casts them onto the board shifted by +0.47 in x, and a camera in front to the
    // right sees each card shifted the other way, so the shadows show beside the cards.
    s.camera.position = Vec3(6, 1.2, 5);
    s.camera.lookAt = Vec3(0, 1.0, -0.5);
    s.camera.up = Vec3(0, 1, 0);
    s.camera.fovYDegrees = 40;
    s.camera.width = 480;
    s.camera.height = 270;
    s.camera.near = 0.5;
    s.camera.far = 30;
    const Vec3 toward = glm::normalize(Vec3(1.0, -0.3, -1));
    s.lights.assign(1, scene::Light{});
    s.lights[0].direction = toward;
    int bed = -1;
    std::vector<int> cards;
    for (std::size_t i = 0; i < s.objects.size(); ++i) {
        const std::string& m = s.materialOf(s.objects[i]).name;
        if (m == "MatBed") bed = int(i);
        if (m == "MatBlend" || m.rfind("MatCutoff", 0) == 0 || m == "MatOpaque") cards.push_back(int(i));
    }
    ASSERT_GE(bed, 0);
    const Frames f = renderAll(s);
    if (const char* dir = std::getenv("SHADOWLAB_ALPHA_PNG_DIR")) {  // to look at them
        scene::writeFrame(f.raster, std::filesystem::path(dir) / "abm-raster.png");
        scene::writeFrame(f.raytrace, std::filesystem::path(dir) / "abm-raytrace.png");
        scene::writeFrame(f.reference, std::filesystem::path(dir) / "abm-reference.png");
    }
    const scene::CameraBasis cam = scene::cameraBasis(s.camera);
    std::size_t counted = 0, mismatched[3] = {0, 0, 0}, cut = 0, cast = 0, blended = 0;
    for (int y = 0; y < s.camera.height; ++y)
        for (int x = 0; x < s.camera.width; ++x) {
            const std::size_t px = std::size_t(y) * std::size_t(s.camera.width) + std::size_t(x);
            if (f.reference.objectId[px] != float(bed + 1) || f.reference.ndotl[px] <= 0.0f) continue;
            const Vec3 dir = scene::pixelDirection(cam, x, y);
            const Vec3 p = cam.position + dir * (double(f.reference.depth[px]) / glm::dot(dir, cam.forward));
            // Visibility through the cards only (other parts of the model may shadow too: such
            // pixels, where the reference is darker than the cards allow, are left out).
            double want = 1.0;
            bool crossed = false;
            for (const int c : cards) {
                const scene::Material& m = s.materialOf(s.objects[std::size_t(c)]);
                for (const scene::MeshInstance& inst :
                     std::get<scene::Mesh>(s.objects[std::size_t(c)].shape).instances) {
                    const scene::TriangleMesh& g = *inst.geometry;
                    for (std::size_t t = 0; t + 2 < g.indices.size(); t += 3) {
                        const std::uint32_t* ix = &g.indices[t];
                        double b1, b2;
                        if (!hitTriangle(p, -toward, scene::transformPoint(inst.transform, g.positions[ix[0]]),
                                         scene::transformPoint(inst.transform, g.positions[ix[1]]),
                                         scene::transformPoint(inst.transform, g.positions[ix[2]]), b1, b2))
                            continue;
                        crossed = true;
                        double alpha = 1.0;
                        if (m.alphaTexture) {
                            const scene::Vec2 uv = (1 - b1 - b2) * g.uvs[ix[0]] + b1 * g.uvs[ix[1]] + b2 * g.uvs[ix[2]];
                            const int w = m.alphaTexture->width, h = m.alphaTexture->height;
                            const int tx = std::clamp(int(std::floor(uv.x * w)), 0, w - 1);  // UVs lie in 0..1 here
                            const int ty = std::clamp(int(std::floor(uv.y * h)), 0, h - 1);
                            alpha = m.alphaTexture->alpha[std::size_t(ty) * std::size_t(w) + std::size_t(tx)];
                        }
                        if (m.alphaMode == scene::AlphaMode::Opaque)
                            want = 0.0;
                        else if (m.alphaMode == scene::AlphaMode::Blend)
                            want *= 1.0 - alpha, ++blended;
                        else if (alpha >= m.alphaCutoff)
                            want = 0.0, ++cast;
                        else
                            ++cut;
                    }
                }
            }
            if (!crossed || f.reference.visibility[px] < want - 0.5) continue;
            ++counted;
            const scene::Frame* frames[3] = {&f.raster, &f.raytrace, &f.reference};
            for (int k = 0; k < 3; ++k) mismatched[k] += std::abs(frames[k]->visibility[px] - want) > 0.05;
        }
    // Every rule is exercised: MASK texels that cast and that are cut out, and BLEND texels.
    EXPECT_GT(cut, 200u);
    EXPECT_GT(cast, 200u);
    EXPECT_GT(blended, 200u);
    ASSERT_GT(counted, 2000u);
    // Edges: a shadow-map texel (raster) or a texture texel on either side of a cut-out's edge.
    EXPECT_LT(double(mismatched[0]) / double(counted), 0.03) << mismatched[0] << " of " << counted;
    EXPECT_LT(double(mismatched[1]) / double(counted), 0.01) << mismatched[1] << " of " << counted;
    EXPECT_LT(double(mismatched[2]) / double(counted), 0.01) << mismatched[2] << " of " << counted;
}

}  // namespace
}  // namespace shadowlab
