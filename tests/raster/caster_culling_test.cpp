// tests/raster/caster_culling_test.cpp: objects that cannot cast onto what the camera sees are
// left out of the depth passes (raster::castsOnto) of directional, spot and point-light maps and
// of each cascade, on the seed scene, on lavapipe with the validation layer; culling never changes
// the image. Also the spot map's size from receiver detail (raster::chooseShadowMapSize).
#include <algorithm>
#include <cmath>
#include <map>
#include <memory>
#include <sstream>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "raster/cascades.h"
#include "raster/renderer.h"
#include "scene/render_plan.h"
#include "tests/kit/render_checked.h"
#include "tests/kit/test_scenes.h"

namespace shadowlab::raster {
namespace {

scene::Scene seedWith(const scene::Vec3& center, double radius) {
    scene::Scene s = test::loadSeed(160, 90);
    scene::Object extra = s.objects[0];  // the sphere's material
    extra.name = "extra";
    extra.shape = scene::Sphere{center, radius};
    s.objects.push_back(extra);
    return s;
}

scene::Frame rasterRender(const scene::Scene& s, bool cull, int cascades = 1) {
    scene::SettingsOverrides o;
    o.cascades = cascades;
    scene::RenderSettings settings = scene::resolveSettings(s, o);
    settings.raster.cullCasters = cull;
    return test::renderChecked(s, settings);
}

int countOf(const std::vector<float>& ids, int id) { return int(std::count(ids.begin(), ids.end(), float(id))); }

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

// The seed scene (camera at (0, 2, 6) looking at (0, 0.7, 0), fov 40°, ground ±10 at y = 0, sphere
// r = 1 at (0, 1, 0)) lit by one spot or point light instead of the sun, and two more spheres:
// object 2 `far` (never visible, its shadow neither) and object 3 `kept` (outside the view, its
// shadow inside it).
scene::Scene seedLitBy(const scene::Light& light, const scene::Vec3& far, double farRadius, const scene::Vec3& kept,
                       double keptRadius) {
    scene::Scene s = seedWith(far, farRadius);
    scene::Object k = s.objects[0];
    k.name = "kept";
    k.shape = scene::Sphere{kept, keptRadius};
    s.objects.push_back(k);
    s.lights = {light};
    return s;
}

scene::Light pointAbove() {
    scene::Light l;
    l.type = scene::LightType::Point;
    l.position = {0, 8, 0};
    l.intensity = 800;
    return l;
}

// Spot: `far` at (0, 1, 12) r = 1, behind the camera but inside the cone (59.7° off the axis): its
// box's directions have u = z/(8 − y) ≥ 11/8 = 1.375. The visible receivers (the scene's box in the
// camera frustum, which reaches back only to the near plane at z ≈ 5.9, y ≈ 2.04) have u ≤ 5.9/5.96
// < 1, and the margin (10 texels + 2·√(1 + t²)·normal offset: under 0.2 in u on any map of 256 or
// more with the default offset) leaves them
// short of 1.375: culled. `kept` at (2, 6, −2) r = 0.5 is 26° above the horizon seen from the
// camera, whose view reaches 7.8° above it: outside the view; the light's ray through its center
// meets the ground at (0, 8, 0) + 4·(2, −2, −2) = (8, 0, −8), 27° to the side and 8° below the
// horizon: inside the view (half-angles 32.9° and 20° around a view 12.2° down), and clear of the
// seed sphere.
scene::Scene spotScene() { return seedLitBy(test::spotDown(), {0, 1, 12}, 1.0, {2, 6, -2}, 0.5); }

TEST(RasterCasterCulling, ASpotMapLeavesOutWhatCannotShadowTheViewAndKeepsWhatDoes) {
    const scene::Scene s = spotScene();
    const scene::Frame culled = rasterRender(s, true);
    const scene::Frame all = rasterRender(s, false);
    EXPECT_EQ(culled.attributes.at("culled_casters"), "1");  // `far` only
    EXPECT_EQ(all.attributes.at("culled_casters"), "0");
    EXPECT_EQ(culled.visibility, all.visibility);
    EXPECT_EQ(culled.beauty, all.beauty);
    EXPECT_EQ(culled.blockerId, all.blockerId);
    // `kept` (id 4) shadows visible ground in the culled render, and nothing shows `far` (id 3).
    EXPECT_GT(countOf(culled.blockerId, 4), 0);
    EXPECT_EQ(countOf(culled.objectId, 3) + countOf(culled.objectId, 4), 0);
    const std::vector<LightCulling> c = culledCasters(s, scene::resolveSettings(s, {}).raster);
    ASSERT_EQ(c.size(), 1u);
    ASSERT_EQ(c[0].culled.size(), 1u);
    EXPECT_EQ(c[0].culled[0], 1);
}

// Point light at (0, 8, 0). The visible receivers all lie below y ≈ 4.2 (the view's top edge rises
// 7.8° over at most 16 units), so no receiver is in front of the +Y face: it draws nothing. `far`
// at (3, 1, 40) r = 1 is behind the camera: wholly behind the light's planes of −X (x > 0), −Z
// (z > 0) and +Y (y < 8); for +X its directions have z/x ≥ 39/4, for −Y z/(8 − y) ≥ 39/8, both far past the face's edge
// (t ≈ 1.01) where the receivers' rectangle is clamped; for +Z its nearest depth 39 is beyond every
// receiver's (z ≤ 5.91). Culled from all six faces. `kept` at (1.5, 6, −1.5)
// r = 0.4 is 27.6° above the horizon from the camera (outside the view); the light's ray through
// it meets the ground at (0, 8, 0) + 4·(1.5, −2, −1.5) = (6, 0, −6), inside the view, in the −Y
// face, where its box (u = z/d in [−1.19, −0.46], v = x/d in [0.46, 1.19], d = 8 − y) overlaps
// the ground's visible part.
scene::Scene pointScene() { return seedLitBy(pointAbove(), {3, 1, 40}, 1.0, {1.5, 6, -1.5}, 0.4); }

TEST(RasterCasterCulling, EachCubeFaceDrawsOnlyItsOwnCastersAndTheImageIsUnchanged) {
    const scene::Scene s = pointScene();
    const scene::RasterSettings settings = scene::resolveSettings(s, {}).raster;
    const std::vector<LightCulling> c = culledCasters(s, settings);
    ASSERT_EQ(c.size(), 1u);
    ASSERT_EQ(c[0].layers, (std::vector<std::string>{"+X", "-X", "+Y", "-Y", "+Z", "-Z"}));
    EXPECT_EQ(c[0].culled[2], 4);  // +Y: every object
    const std::vector<scene::Vec3> receivers = visibleReceiverPoints(s);
    for (int face = 0; face < kCubeFaces; ++face) {
        SCOPED_TRACE(face);
        const LightFrustum f = fitPointLightFace(s.bounds(), s.lights[0].position, face, settings.shadowMapSize);
        const std::vector<bool> casts = layerCasters(s, settings, s.lights[0], f, receivers);
        EXPECT_FALSE(casts[2]);  // `far`
        if (face == 3) {
            EXPECT_TRUE(casts[3]);  // `kept` in −Y
        }
        EXPECT_EQ(c[0].culled[std::size_t(face)], int(std::count(casts.begin(), casts.end(), false)));
    }
    const scene::Frame culled = rasterRender(s, true);
    const scene::Frame all = rasterRender(s, false);
    EXPECT_EQ(culled.attributes.at("culled_casters"), std::to_string(c[0].total()));
    EXPECT_EQ(culled.attributes.at("culled_casters_per_layer"),
              std::to_string(c[0].culled[0]) + ";" + std::to_string(c[0].culled[1]) + ";" +
                  std::to_string(c[0].culled[2]) + ";" + std::to_string(c[0].culled[3]) + ";" +
                  std::to_string(c[0].culled[4]) + ";" + std::to_string(c[0].culled[5]));
    EXPECT_EQ(all.attributes.at("culled_casters"), "0");
    EXPECT_EQ(culled.visibility, all.visibility);
    EXPECT_EQ(culled.beauty, all.beauty);
    EXPECT_EQ(culled.blockerId, all.blockerId);
    EXPECT_GT(countOf(culled.blockerId, 4), 0);  // `kept` shadows the visible ground
}

TEST(RasterCasterCulling, PcssOfAnAreaPointLightReachesFartherAndStillLeavesTheImageUnchanged) {
    // PCSS taps of a point light reach up to 1/16 of the map and wrap into the next face; with a
    // light of radius 0.5 the soft shadows read far more texels than a pcf kernel.
    scene::Scene s = pointScene();
    s.lights[0].radius = 0.5;
    s.shadow.filter = "pcss";
    const scene::Frame culled = rasterRender(s, true);
    const scene::Frame all = rasterRender(s, false);
    EXPECT_NE(culled.attributes.at("culled_casters"), "0");
    EXPECT_EQ(culled.visibility, all.visibility);
    EXPECT_EQ(culled.blockerId, all.blockerId);
    // Equal frames say something only where they hold soft shadows: `kept` (id 4) shadows the
    // visible ground, and the light's radius gives its shadow a penumbra.
    EXPECT_GT(countOf(culled.blockerId, 4), 0);
    EXPECT_GT(
        std::count_if(culled.visibility.begin(), culled.visibility.end(), [](float v) { return v > 0.0f && v < 1.0f; }),
        0);
}

TEST(RasterCasterCulling, EachCascadeDrawsOnlyTheCastersOfItsOwnSlice) {
    // Three cascades under the seed's sun (light along (−1, −2, −1)). An extra sphere r = 0.5 at
    // (8, 1, −9) shadows the ground at (8, 1, −9) + 0.5·(−1, −2, −1) = (7.5, 0, −9.5), view depth
    // ≈ 15.6: the last slice (the splits over the visible depths ≈ 3.5..16.9 are ≈ 6.4 and 10.6).
    // Toward the light its shadow line (8 + s, 1 + 2s, −9 + s) reaches the first slice's z > −0.4
    // (the slice ends ≈ 6.4 from the camera at z = 6) only for s > 8.6, at y > 18 and x > 16, where
    // no receiver is: it cannot cast onto cascade 0's receivers, only onto the last one's.
    const scene::Scene s = seedWith({8, 1, -9}, 0.5);
    scene::SettingsOverrides o;
    o.cascades = 3;
    const scene::RasterSettings settings = scene::resolveSettings(s, o).raster;
    const CascadeSet cs = fitCascades(s, s.lights[0].direction, 3, settings.shadowMapSize);
    ASSERT_EQ(cs.frusta.size(), 3u);
    const std::vector<bool> first =
        layerCasters(s, settings, s.lights[0], cs.frusta[0], cascadeReceivers(s, cs.splits, 0));
    const std::vector<bool> last =
        layerCasters(s, settings, s.lights[0], cs.frusta[2], cascadeReceivers(s, cs.splits, 2));
    EXPECT_FALSE(first[2]);
    EXPECT_TRUE(last[2]);
    const std::vector<LightCulling> c = culledCasters(s, settings);
    ASSERT_EQ(c[0].layers, (std::vector<std::string>{"C0", "C1", "C2"}));
    EXPECT_GE(c[0].culled[0], 1);

    const scene::Frame culled = rasterRender(s, true, 3);
    const scene::Frame all = rasterRender(s, false, 3);
    EXPECT_EQ(culled.attributes.at("cascades"), "3");
    EXPECT_EQ(culled.attributes.at("culled_casters"), std::to_string(c[0].total()));
    EXPECT_EQ(all.attributes.at("culled_casters"), "0");
    EXPECT_EQ(culled.visibility, all.visibility);
    EXPECT_EQ(culled.beauty, all.beauty);
    EXPECT_EQ(culled.blockerId, all.blockerId);
    EXPECT_GT(countOf(culled.blockerId, 3), 0);  // the extra sphere's shadow is seen, from cascade 2
}

TEST(RasterCasterCulling, EachCascadeDrawsOnlyTheClustersOfALongMeshThatCanCastOntoItsSlice) {
    // A shelf 0.6 high along x from −60 to 60 at z = −3..−2.7 (2,400 quads of 0.05, 4,800 triangles in
    // the index buffer's order, so each cluster of 256 triangles spans 6.4 units of x), beside the
    // seed, under its sun (light along (−1, −2, −1)/√6) with three cascades. Its box reaches every
    // slice's receivers, so the object stays in every layer. Cascade 0 serves view depths up to
    // ≈ 6.4 from the camera at (0, 2, 6): receivers within about 5 units of x = 0 (the view's half
    // width there ≈ 4.1). Across the light a point x units along the shelf lies x·√(5/6) ≈ 0.91·x
    // from x = 0's, so the shelf beyond |x| = 20 (two thirds of it, 3,200 triangles) is 18 units
    // across the light from x = 0's point, at least 13 from any of those receivers, far past the 10-texel margin of a
    // cascade texel: those clusters cannot shade the slice, and cascade 0 draws at least 2,400 of
    // the shelf's triangles fewer than without culling (whole clusters at the cut). The image is
    // the same bit for bit. Its shadow falls 0.3 toward −x and −z, on ground the camera sees under it.
    scene::Scene s = test::loadSeed(160, 90);
    auto shelf = std::make_shared<scene::TriangleMesh>();
    constexpr int kQuads = 2400;
    for (int i = 0; i < kQuads; ++i) {
        const double x0 = -60.0 + 0.05 * i, x1 = x0 + 0.05;
        const auto base = std::uint32_t(shelf->positions.size());
        for (const scene::Vec3& p : {scene::Vec3(x0, 0.6, -2.7), scene::Vec3(x1, 0.6, -2.7), scene::Vec3(x1, 0.6, -3),
                                     scene::Vec3(x0, 0.6, -3)}) {
            shelf->positions.push_back(p);
            shelf->normals.push_back({0, 1, 0});
        }
        for (const std::uint32_t k : {0u, 1u, 2u, 0u, 2u, 3u}) shelf->indices.push_back(base + k);
    }
    test::addMesh(s, shelf, s.objects[0].material);
    const scene::Frame culled = rasterRender(s, true, 3);
    const scene::Frame all = rasterRender(s, false, 3);
    ASSERT_EQ(culled.attributes.at("cascades"), "3");
    const auto perLayer = [](const scene::Frame& f) {
        std::vector<int> n;
        std::istringstream in(f.attributes.at("shadow_triangles_per_layer"));
        for (std::string item; std::getline(in, item, ';');) n.push_back(std::stoi(item));
        return n;
    };
    const std::vector<int> drawn = perLayer(culled), every = perLayer(all);
    ASSERT_EQ(drawn.size(), 3u);
    ASSERT_EQ(every.size(), 3u);
    EXPECT_EQ(every[0], every[2]);  // without culling each layer draws every opaque triangle
    EXPECT_GE(every[0], 2 * kQuads);
    EXPECT_LE(drawn[0], every[0] - 2400);
    for (std::size_t k = 0; k < 3; ++k) EXPECT_LE(drawn[k], every[k]) << k;
    // Each cascade's depth pass also clears and draws only the texels its slice's receivers can
    // read (layerReadWindow): fewer than its map holds in all, the whole map without culling.
    const auto texels = [](const scene::Frame& f) {
        std::vector<long long> n;
        std::istringstream in(f.attributes.at("shadow_texels_per_layer"));
        for (std::string item; std::getline(in, item, ';');) n.push_back(std::stoll(item));
        return n;
    };
    const long long mapArea =
        std::stoll(culled.attributes.at("shadow_map_size")) * std::stoll(culled.attributes.at("shadow_map_size"));
    const std::vector<long long> window = texels(culled), whole = texels(all);
    ASSERT_EQ(window.size(), 3u);
    ASSERT_EQ(whole.size(), 3u);
    long long windowSum = 0;
    for (std::size_t k = 0; k < 3; ++k) {
        EXPECT_EQ(whole[k], mapArea) << k;
        EXPECT_LE(window[k], mapArea) << k;
        windowSum += window[k];
    }
    EXPECT_LT(windowSum, 3 * mapArea);
    EXPECT_EQ(culled.visibility, all.visibility);
    EXPECT_EQ(culled.beauty, all.beauty);
    EXPECT_EQ(culled.blockerId, all.blockerId);
    EXPECT_GT(countOf(culled.blockerId, int(s.objects.size())), 0);  // the shelf's shadow is seen
}

// A 60 x 60 ground with a sphere at (20, 1, 17) under light along (−1, −2, −1), its shadow around
// (19.5, 0, 16.5), seen from close by: the camera sees a few units of the ground, the unfitted
// map spans the ground's bounding sphere (radius ≈ 42, a texel ≈ 0.17 at 512). The sphere's
// radius 0.8 unless given (its center then that much above 0.2).
scene::Scene groundSeenFromCloseBy(double radius = 0.8) {
    test::SphereOverPlane p;
    p.planeSize = 60.0;
    p.center = {20, 0.2 + radius, 17};
    p.radius = radius;
    p.lightDirection = {-1, -2, -1};
    p.eye = {20, 4, 23};
    p.lookAt = {19, 0, 17};
    return test::makeScene(p);
}

// The widest PCF kernel (15 taps: 7 texels each way) and a normal offset of 3 texels: the image's
// border pixels read texels well past their own.
scene::RasterSettings wideReachSettings() {
    scene::RasterSettings r = test::fixedSettings(512);
    r.fitLightFrustum = false;
    r.filter = scene::ShadowFilter::Pcf;
    r.pcfSize = 15;
    r.normalOffset = 3.0;
    r.cullCasters = true;
    return r;
}

// The texels each layer drew, windowed and whole, and the windowed frame's attributes.
struct Windows {
    std::vector<long long> windowed, whole;
    std::map<std::string, std::string> attributes;
    std::vector<float> visibility;
};

// Renders `s` with the depth pass in each layer's read window (culling on) and with whole layers
// (culling off), expects the same frames bit for bit with the caster's shadow (its blocker id,
// unless `shadowIds` is false: a shadow too soft for ids) and lit ground in view.
Windows windowedAndWhole(const scene::Scene& s, scene::RasterSettings r, bool shadowIds = true) {
    const auto texels = [](const scene::Frame& f) {
        std::vector<long long> n;
        std::istringstream in(f.attributes.at("shadow_texels_per_layer"));
        for (std::string item; std::getline(in, item, ';');) n.push_back(std::stoll(item));
        return n;
    };
    r.cullCasters = true;
    const scene::Frame windowed = test::renderChecked(s, r);
    r.cullCasters = false;
    const scene::Frame whole = test::renderChecked(s, r);
    EXPECT_EQ(windowed.visibility, whole.visibility);
    EXPECT_EQ(windowed.beauty, whole.beauty);
    EXPECT_EQ(windowed.blockerId, whole.blockerId);
    if (shadowIds) EXPECT_GT(countOf(windowed.blockerId, 1), 100);  // the sphere's shadow is seen
    EXPECT_GT(countOf(windowed.blockerId, 0), 100);                 // and lit ground
    return {texels(windowed), texels(whole), windowed.attributes, windowed.visibility};
}

TEST(RasterCasterCulling, TheDepthPassDrawsOnlyTheTexelsTheViewCanReadAndTheImageIsUnchanged) {
    // The window's margin must hold the border pixels' reads: the image is the same bit for bit as
    // with whole layers, drawn into a tenth of the map or less.
    const scene::Scene s = groundSeenFromCloseBy();
    const auto [windowed, whole, attributes, visibility] = windowedAndWhole(s, wideReachSettings());
    EXPECT_EQ(whole, std::vector<long long>{512 * 512});
    ASSERT_EQ(windowed.size(), 1u);
    EXPECT_LE(windowed[0], 512 * 512 / 10);
}

TEST(RasterCasterCulling, AnOverheadSunsWindowKeepsTheImage) {
    // A sun straight down (the map's basis then takes world X as its reference: setBasis) over a
    // low sphere: the window is the visible receivers' footprint widened by the margin, and the
    // image is the same bit for bit as with the whole map.
    test::SphereOverPlane p;
    p.planeSize = 60.0;
    p.center = {20, 0.35, 17};
    p.radius = 0.3;
    p.lightDirection = {0, -1, 0};
    p.eye = {20, 4, 23};
    p.lookAt = {19, 0, 17};
    const auto [windowed, whole, attributes, visibility] = windowedAndWhole(test::makeScene(p), wideReachSettings());
    ASSERT_EQ(windowed.size(), 1u);
    EXPECT_LT(windowed[0], whole[0]);
}

// A camera 10 above the ground looking straight down (up −z): it sees the ground for
// |x| ≤ 10·tan 20°·16/9 ≈ 6.47 and |z| ≤ 3.64, a rectangle whose sides run along the map's axes for
// a light in the x-y plane, so the receivers' hull (the scene's box in the view) ends where the
// image does on the right, and the window's edge is the image's right edge widened by the margin.
// The image's right column reads texels past that edge with the widest kernel; a window narrower
// than that reach leaves them as the depth pass found them (Vulkan: undefined outside the render
// area). Whatever they hold, one of two scenes tells: one with a caster's shadow across the edge
// (the whole map holds the caster there: a texel left far is lit), one with lit ground there (a
// texel left near, as zeroed memory is, shadows). Without a normal offset: the offset moves a
// lookup the way the light travels, inward for light from the right, and would hide a short margin.
// Pixels of 0.02: the border pixel's center lies under a texel inside the edge (the spot's 0.012).
constexpr int kEdgeWidth = 640, kEdgeHeight = 360;
scene::Scene rightEdgeScene(const scene::Light& light, const scene::Vec3& sphere, double radius) {
    scene::Scene s = test::matteScene({0, 10, 0}, {0, 0, 0}, kEdgeWidth, kEdgeHeight);
    s.camera.up = {0, 0, -1};
    s.lights.push_back(light);
    test::addSphere(s, sphere, radius);
    test::addQuad(s, {0, 0, 0}, {0, 1, 0}, 60, 60);
    return s;
}

// The image's right column: how many of its pixels are mostly shadowed, and whether its middle
// third (|z| < 1.2: inside the spot's cone too) is lit.
int shadowedInTheRightColumn(const std::vector<float>& visibility) {
    int n = 0;
    for (std::size_t y = 0; y < kEdgeHeight; ++y) n += visibility[(y + 1) * kEdgeWidth - 1] < 0.5f;
    return n;
}
bool rightColumnLit(const std::vector<float>& visibility) {
    for (std::size_t y = kEdgeHeight / 3; y < 2 * kEdgeHeight / 3; ++y)
        if (visibility[(y + 1) * kEdgeWidth - 1] != 1.0f) return false;
    return true;
}

// The widest kernel without the normal offset (the edge tests: see rightEdgeScene).
scene::RasterSettings edgeSettings() {
    scene::RasterSettings r = wideReachSettings();
    r.normalOffset = 0.0;
    return r;
}

// The edge's two scenes for `light`: windowed and whole the same bit for bit.
void expectTheEdgeHolds(const scene::Light& light, const scene::Vec3& across, double acrossRadius,
                        const scene::Vec3& inside, double insideRadius,
                        const scene::RasterSettings& r = edgeSettings()) {
    {
        SCOPED_TRACE("a shadow across the edge");
        const auto [windowed, whole, attributes, visibility] =
            windowedAndWhole(rightEdgeScene(light, across, acrossRadius), r);
        ASSERT_EQ(windowed.size(), 1u);
        EXPECT_LT(windowed[0], whole[0]);
        EXPECT_GT(shadowedInTheRightColumn(visibility), 20);
    }
    SCOPED_TRACE("lit ground across the edge");
    const auto [windowed, whole, attributes, visibility] =
        windowedAndWhole(rightEdgeScene(light, inside, insideRadius), r);
    ASSERT_EQ(windowed.size(), 1u);
    EXPECT_LT(windowed[0], whole[0]);
    EXPECT_TRUE(rightColumnLit(visibility));
}

TEST(RasterCasterCulling, TheWindowsMarginHoldsTheWidestKernelAtTheImagesEdge) {
    {
        // Sun at 45° toward −x, texels of 0.17: the border's lookups reach 8 texels (7 taps, the
        // bilinear one more) of the margin's 10.5. A sphere at (8.47, 2, 0), radius 1.6 (box
        // x ≥ 6.87, y ≥ 0.4, where the frustum reaches x ≤ 6.21: no receiver of its own) shadows
        // x = 6.47 ± 2.26, z = ±1.6, wide enough to stay dark under the 15-tap kernel; or at
        // (0, 2, 0), x = −2 ± 2.26, inside the view.
        SCOPED_TRACE("sun");
        scene::Light sun;
        sun.direction = glm::normalize(scene::Vec3(-1, -1, 0));
        sun.intensity = 3.0;
        expectTheEdgeHolds(sun, {8.47, 2, 0}, 1.6, {0, 2, 0}, 1.6);
    }
    // A spot right of the view aimed at the edge, half-angle 20° (≈ 0.012 units a texel there, its
    // cone ≈ 3 units wide on the ground; a wider cone's margin counts more for the offset): a
    // sphere on its axis at height 1.2 (box x ≥ 6.25 at y ≥ 0.6, the frustum x ≤ 6.08), or at
    // height 5 (its shadow ≈ 1.4 left of the edge).
    SCOPED_TRACE("spot");
    scene::Light spot = test::spotDown();
    spot.position = {9, 8, 0};
    spot.direction = glm::normalize(scene::Vec3(-2.53, -8, 0));
    spot.coneAngleDegrees = 20;
    expectTheEdgeHolds(spot, {6.85, 1.2, 0}, 0.6, {8.05 - 1.0, 5, 0}, 0.6);
}

// VSM with a blur of `width` texels: a lookup reads moments blurred over depths (width − 1)/2
// texels further than its own texels, which the depth pass must draw (layerReadWindow) and the
// moment passes must blur from (layerLookupWindow widened along y, then read along x).
scene::RasterSettings blurSettings(int width) {
    scene::RasterSettings r = edgeSettings();
    r.filter = scene::ShadowFilter::Vsm;
    r.moments.blurWidth = width;
    return r;
}

TEST(RasterCasterCulling, AFilterableMapsPassesStayInTheWindowAndTheImageIsUnchanged) {
    // The ground seen from close by under the sun, a spot and a point light, a 9-texel blur (the
    // sun's ±0.7 units, under the sphere's shadow of ±1.2): the same frames bit for bit as whole
    // layers (culling off), drawn into part of each map.
    SCOPED_TRACE("sun");
    const scene::Scene sun = groundSeenFromCloseBy(1.2);
    const auto [sunWindowed, sunWhole, sunAttributes, sunVisibility] = windowedAndWhole(sun, blurSettings(9));
    ASSERT_EQ(sunWindowed.size(), 1u);
    EXPECT_LE(sunWindowed[0], 512 * 512 / 10);
    SCOPED_TRACE("spot");
    scene::Scene spot = groundSeenFromCloseBy(1.2);
    spot.lights[0] = test::spotDown();
    spot.lights[0].position = {20, 8, 17};
    const auto [spotWindowed, spotWhole, spotAttributes, spotVisibility] = windowedAndWhole(spot, blurSettings(9));
    ASSERT_EQ(spotWindowed.size(), 1u);
    EXPECT_LT(spotWindowed[0], 512 * 512);
    SCOPED_TRACE("point");
    scene::Scene point = groundSeenFromCloseBy(1.2);
    point.lights[0].type = scene::LightType::Point;
    point.lights[0].position = {20, 8, 17};
    point.lights[0].intensity = 800;
    const auto [pointWindowed, pointWhole, pointAttributes, pointVisibility] = windowedAndWhole(point, blurSettings(9));
    ASSERT_EQ(pointWindowed.size(), 6u);
    EXPECT_EQ(pointWindowed[2], 0);  // +Y: no moment pass either
    EXPECT_LT(pointWindowed[3], 512 * 512);
}

TEST(RasterCasterCulling, AFilterableMapsWindowHoldsTheBlurAtTheImagesEdge) {
    // rightEdgeScene's camera and sun with VSM and the widest blur, 63 texels (±31 texels, about
    // ±7 units of ground along x): the border pixels' lookups read moments that average depths far
    // past the margin's slack, and a window without the blur's radius blurs depths no pass drew.
    // A slab at height 4 over x 8..30 (outside the view) shadows x ≥ 3.9, about two thirds of the
    // right column's box; a sphere at (−2, 2, 0) shadows x ≤ −1.7, more than the box away from the
    // edge, which stays lit. The ground's own depth varies across so wide a box (the sun is at 45°),
    // so VSM's bound leaves these shadows soft: too light for blocker ids.
    scene::Light sun;
    sun.direction = glm::normalize(scene::Vec3(-1, -1, 0));
    sun.intensity = 3.0;
    const scene::RasterSettings r = blurSettings(63);
    const auto rightColumn = [](const std::vector<float>& visibility) {
        std::vector<float> column;
        for (std::size_t y = 0; y < kEdgeHeight; ++y) column.push_back(visibility[(y + 1) * kEdgeWidth - 1]);
        return column;
    };
    {
        SCOPED_TRACE("a shadow across the edge");
        scene::Scene s = test::matteScene({0, 10, 0}, {0, 0, 0}, kEdgeWidth, kEdgeHeight);
        s.camera.up = {0, 0, -1};
        s.lights.push_back(sun);
        test::addBox(s, {8, 4, -15}, {30, 4.1, 15});
        test::addQuad(s, {0, 0, 0}, {0, 1, 0}, 60, 60);
        const auto [windowed, whole, attributes, visibility] = windowedAndWhole(s, r, false);
        ASSERT_EQ(windowed.size(), 1u);
        EXPECT_LT(windowed[0], whole[0]);
        const std::vector<float> column = rightColumn(visibility);
        EXPECT_LT(*std::max_element(column.begin(), column.end()), 0.8f);
    }
    SCOPED_TRACE("lit ground across the edge");
    const auto [windowed, whole, attributes, visibility] =
        windowedAndWhole(rightEdgeScene(sun, {-2, 2, 0}, 1.6), r, false);
    ASSERT_EQ(windowed.size(), 1u);
    EXPECT_LT(windowed[0], whole[0]);
    EXPECT_TRUE(rightColumnLit(visibility));
    EXPECT_LT(*std::min_element(visibility.begin(), visibility.end()), 0.9f);  // the sphere's shadow
}

TEST(RasterCasterCulling, SpotAndPointLightMapsAreDrawnOnlyWhereTheViewReads) {
    // The same ground and sphere under a spot straight above the sphere (cone 60°, its unfitted map
    // reaching ≈ 14 units across the ground, of which the camera sees the part in front of it and
    // beside the sphere, not the ground behind the camera) and under a point light there (the +Y
    // face looks away from everything: no receiver in front of it, nothing drawn).
    scene::Scene spot = groundSeenFromCloseBy();
    spot.lights[0] = test::spotDown();
    spot.lights[0].position = {20, 8, 17};
    const auto [spotWindowed, spotWhole, spotAttributes, spotVisibility] = windowedAndWhole(spot, wideReachSettings());
    EXPECT_EQ(spotWhole, std::vector<long long>{512 * 512});
    ASSERT_EQ(spotWindowed.size(), 1u);
    EXPECT_LT(spotWindowed[0], 512 * 512);

    scene::Scene point = groundSeenFromCloseBy();
    point.lights[0].type = scene::LightType::Point;
    point.lights[0].position = {20, 8, 17};
    point.lights[0].intensity = 800;
    const auto [pointWindowed, pointWhole, pointAttributes, pointVisibility] =
        windowedAndWhole(point, wideReachSettings());
    ASSERT_EQ(pointWindowed.size(), 6u);
    ASSERT_EQ(pointWhole.size(), 6u);
    for (std::size_t face = 0; face < 6; ++face) {
        EXPECT_EQ(pointWhole[face], 512 * 512) << face;
        EXPECT_LE(pointWindowed[face], pointWhole[face]) << face;
    }
    EXPECT_EQ(pointWindowed[2], 0);  // +Y
}

TEST(RasterCasterCulling, WithATransmittanceMapEveryCasterIsDrawnButOnlyWithinTheReadWindow) {
    // The ground and sphere above with a glass sphere (opacity 0.5) beside the opaque one: the
    // transmittance map culls no caster (an opaque one left out would let glass behind it into
    // the map), but the window leaves out texels, not casters, and holds for every pass.
    scene::Scene s = groundSeenFromCloseBy();
    const int glass = test::addMaterial(s, "glass", 0.5);
    test::addSphere(s, {21.8, 1, 17.5}, 0.6, glass);
    const auto [windowed, whole, attributes, visibility] = windowedAndWhole(s, wideReachSettings());
    EXPECT_EQ(attributes.at("transmittance_map"), "made");
    // The glass's shadow is seen (the widest kernel spreads it over ≈ 2.6 units: no plateau at 0.5).
    EXPECT_NE(visibility, test::renderChecked(groundSeenFromCloseBy(), wideReachSettings()).visibility);
    EXPECT_EQ(attributes.at("culled_casters"), "0");
    EXPECT_EQ(whole, std::vector<long long>{512 * 512});
    ASSERT_EQ(windowed.size(), 1u);
    EXPECT_LE(windowed[0], 512 * 512 / 10);
}

TEST(RasterCasterCulling, AHeldViewDrawsWholeLayers) {
    // update(scene, view) with another view than scene.camera draws the maps planned for
    // scene.camera from `view`, which sees receivers the window was not made for: whole layers.
    const scene::Scene s = groundSeenFromCloseBy();
    const scene::RasterSettings r = wideReachSettings();
    Renderer renderer(s, test::planFor(s, r), r);
    const auto texels = [&] { return std::stoll(renderer.render().attributes.at("shadow_texels_per_layer")); };
    EXPECT_LE(texels(), 512 * 512 / 10);
    scene::Scene moved = s;
    moved.camera.position.x += 4.0;
    moved.camera.lookAt.x += 4.0;
    renderer.update(moved, s.camera);  // the maps of the moved camera, seen from the first
    EXPECT_EQ(texels(), 512 * 512);
    renderer.update(moved);  // seen from the moved camera itself: windowed again
    EXPECT_LE(texels(), 512 * 512 / 10);
    RenderDebug capture;  // a capture of the maps draws (and reports) whole layers
    capture.captureShadowMaps = true;
    EXPECT_EQ(renderer.render(scene::kAllChannels, &capture).attributes.at("shadow_texels_per_layer"),
              std::to_string(512 * 512));
    EXPECT_EQ(renderer.validationMessages(), 0) << "validation messages were printed above";
}

// castsOnto() for a perspective map at the origin looking down −z (basis right = +x, up = +y, so
// u = x/d, v = y/d, d = −z), t = 1, 1000 texels (0.002 in u per texel; the 10-texel margin is
// 0.02), without normal offset.
LightFrustum lookingDownMinusZ() {
    LightFrustum f;
    f.perspective = true;
    setBasis(f, {0, 0, -1});
    f.position = {0, 0, 0};
    f.tanHalfFov = 1.0;
    f.mapSize = 1000;
    f.near = 0.1;
    f.far = 100;
    return f;
}

scene::Scene boxes(const std::vector<scene::Box>& list) {
    scene::Scene s;
    for (const scene::Box& b : list) {
        scene::Object o;
        o.shape = b;
        s.objects.push_back(o);
    }
    return s;
}

TEST(RasterCasterCulling, PerspectiveDecisionsIncludingBoxesAcrossTheLightsPlane) {
    const LightFrustum f = lookingDownMinusZ();
    ASSERT_DOUBLE_EQ(f.right.x, 1.0);
    ASSERT_DOUBLE_EQ(f.up.y, 1.0);
    // Receivers: the square x, y in ±1 at z = −5: u, v in ±0.2, depth 5.
    std::vector<scene::Vec3> receivers;
    for (const double x : {-1.0, 1.0})
        for (const double y : {-1.0, 1.0}) receivers.push_back({x, y, -5});
    const scene::Scene s = boxes({
        {{-0.1, -0.1, -3}, {0.1, 0.1, -2}},  // between light and receivers: kept
        {{2, -0.1, -3}, {3, 0.1, -2}},       // u ≥ 2/3 > 0.2 + 0.02: culled
        {{-0.1, -0.1, -9}, {0.1, 0.1, -8}},  // behind the receivers (depth 8 > 5·1.02): culled
        {{5, -0.1, -1}, {6, 0.1, 1}},        // across the light's plane: kept
        {{-1, -1, -1}, {1, 1, 1}},           // holds the light: kept
        {{-0.1, -0.1, 1}, {0.1, 0.1, 2}},    // wholly behind the light: culled
        {{0.21, -0.1, -1}, {0.3, 0.1, -1}},  // u from 0.21: within the margin of 0.2: kept
        {{0.23, -0.1, -1}, {0.3, 0.1, -1}},  // u from 0.23: past it: culled
    });
    EXPECT_EQ(castsOnto(s, f, receivers, kCullMarginTexels, 0.0),
              (std::vector<bool>{true, false, false, true, true, false, true, false}));
    // No receiver in front of the map: nothing reads it.
    EXPECT_EQ(castsOnto(s, f, {{0, 0, 5}, {1, 1, 6}}, kCullMarginTexels, 0.0), std::vector<bool>(8, false));
    // No receivers at all (the camera sees nothing): everything kept.
    EXPECT_EQ(castsOnto(s, f, {}, kCullMarginTexels, 0.0), std::vector<bool>(8, true));
}

TEST(RasterCasterCulling, ReceiversPartlyBehindTheLightReachTheMapsEdgeOnlyOnTheirSide) {
    const LightFrustum f = lookingDownMinusZ();
    // Receivers x in [1, 2], y in ±1, z in ±5: the hull crosses the light's plane z = 0 at x in
    // [1, 2] > 0, so in u it runs from 1/5 (the front corners' least x/d) out to +∞, clamped to the
    // map's edge t = 1; in v the crossing has y of both signs: the whole map.
    std::vector<scene::Vec3> receivers;
    for (const double x : {1.0, 2.0})
        for (const double y : {-1.0, 1.0})
            for (const double z : {-5.0, 5.0}) receivers.push_back({x, y, z});
    const scene::Scene s = boxes({
        {{2, 3, -3}, {2.5, 4, -2}},         // u in [0.67, 1.25], v in [1, 2]: overlaps (v from 1 = t): kept
        {{4, -0.1, -3}, {5, 0.1, -2}},      // u ≥ 4/3, past the clamped edge 1 + 0.02: culled
        {{-3, -0.1, -3}, {-2, 0.1, -2}},    // u ≤ −2/3: on the side away from the crossing: culled
        {{0.5, -0.1, -3}, {0.6, 0.1, -2}},  // u in [0.17, 0.3]: kept
    });
    EXPECT_EQ(castsOnto(s, f, receivers, kCullMarginTexels, 0.0), (std::vector<bool>{true, false, false, true}));
}

// The spot map's size from receiver detail, by hand: camera at (0, 10, 0) looking straight down
// (fov 40°), spot at (0, 12, 0) straight down with a 30° cone (map half-angle 30.6°). Objects: the
// ground (y = 0, view depth 10, distance along the spot's axis 12) and a box [−1, 1] x [0, 2] x
// [−1, 1] whose top (view depth 8: the view there is ±2.9 high, ±5.2 wide, so all of it is seen) is
// at distance 10. Both depths are 10 − y and 12 − y, so distance / view depth is largest where y is:
// 10/8 on the box's top. N ≥ 2·tan 30.6°·(10/8) / (2·tan 20°/H) = 2.031·H texels: 365.6 at H = 180,
// so 512; 731 at H = 360, so 1024; 4062 at H = 2000, capped at 2048.
scene::Scene spotFromAbove(int height) {
    scene::Scene s = seedWith({0, 1, 0}, 1.0);
    s.objects.pop_back();
    test::boxUnderADownwardCamera(s, height);
    scene::Light l = test::spotDown();
    l.position = {0, 12, 0};
    l.coneAngleDegrees = 30;
    s.lights = {l};
    return s;
}

int expectedSpotSize(int height) {
    using test::kPi;
    const double needed =
        2.0 * std::tan(30.6 * kPi / 180.0) * (10.0 / 8.0) / (2.0 * std::tan(20.0 * kPi / 180.0) / height);
    int size = 256;
    while (size < needed && size < 2048) size *= 2;
    return size;
}

TEST(RasterMapSize, ASpotMapIsSizedByTheFinestReceiverDetailUnderIt) {
    EXPECT_EQ(expectedSpotSize(180), 512);
    EXPECT_EQ(expectedSpotSize(360), 1024);
    EXPECT_EQ(expectedSpotSize(2000), 2048);
    for (const int height : {180, 360, 2000}) {
        SCOPED_TRACE(height);
        const scene::Scene s = spotFromAbove(height);
        const ShadowMapSizeChoice c = chooseShadowMapSize(s, scene::resolveSettings(s, {}).raster);
        EXPECT_EQ(c.size, expectedSpotSize(height)) << c.reason;
        EXPECT_NE(c.reason.find(height < 2000 ? "from receiver detail" : "capped at the default"), std::string::npos)
            << c.reason;
    }
    // The render uses it.
    scene::Scene s = spotFromAbove(180);
    EXPECT_EQ(rasterRender(s, true).attributes.at("shadow_map_size"), "512");
}

TEST(RasterMapSize, ForcedSizesStayForcedWithSpotAndPointLights) {
    scene::Scene s = spotFromAbove(180);
    s.shadow.shadowMapSize = 2048;
    EXPECT_EQ(chooseShadowMapSize(s, scene::resolveSettings(s, {}).raster).size, 2048);
    s.shadow.shadowMapSize.reset();
    scene::SettingsOverrides o;
    o.shadowMapSize = 1024;
    EXPECT_EQ(chooseShadowMapSize(s, scene::resolveSettings(s, o).raster).size, 1024);
    // And with a point light (its size from receiver detail: light_fit_test.cpp).
    scene::Scene p = pointScene();
    p.shadow.shadowMapSize = 1024;
    const ShadowMapSizeChoice c = chooseShadowMapSize(p, scene::resolveSettings(p, {}).raster);
    EXPECT_EQ(c.size, 1024);
    EXPECT_NE(c.reason.find("set by"), std::string::npos) << c.reason;
}

}  // namespace
}  // namespace shadowlab::raster
