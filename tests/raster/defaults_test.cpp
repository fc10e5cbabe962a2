// tests/raster/defaults_test.cpp: the raster defaults keep the shadow on scenes they were not tuned
// for: a low sun over a large ground (the fitted map and the automatic cascades), two stacked
// semi-transparent panes over a large ground (their transmittance), and the automatic map size
// that resolves the casters' smallest features; each against answers worked out from geometry.
#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <memory>
#include <string>

#include <gtest/gtest.h>

#include "raster/cascades.h"
#include "raster/light_frustum.h"
#include "raster/renderer.h"
#include "scene/camera.h"
#include "scene/render_plan.h"
#include "scene/settings.h"
#include "tests/kit/render_checked.h"
#include "tests/kit/test_scenes.h"

namespace shadowlab::raster {
namespace {

using scene::Vec3;
using test::kPi;

scene::Material material(const std::string& name, double opacity = 1.0) {
    scene::Material m;
    m.name = name;
    m.albedo = Vec3(0.8);
    m.opacity = opacity;
    return m;
}

scene::Object quad(const Vec3& center, double sx, double sz, int materialIndex) {
    return test::horizontalQuad("quad", center, sx, sz, materialIndex);
}

// A 1000 x 1000 ground (y = 0) under a sun `elevation` degrees above the horizon along +x, the
// camera at `eye` looking at `at`, 320 x 180.
scene::Scene largeGround(double elevationDegrees, const Vec3& eye, const Vec3& at) {
    scene::Scene s = test::matteScene(eye, at, 320, 180, 1000.0);
    const double e = elevationDegrees * kPi / 180.0;
    scene::Light l;
    l.type = scene::LightType::Directional;
    l.direction = Vec3(std::cos(e), -std::sin(e), 0.0);
    l.intensity = 3.0;
    s.lights.push_back(l);
    s.objects.push_back(quad(Vec3(0), 1000, 1000, 0));
    return s;
}

// The world point of pixel (x, y) on the ground y = 0 (the pixel center's ray), if it hits it.
std::optional<Vec3> groundPoint(const scene::Scene& s, int x, int y) {
    const scene::CameraBasis c = scene::cameraBasis(s.camera);
    if (!(test::pixelRay(c, x, y).y < 0.0)) return std::nullopt;
    return test::floorPoint(c, x, y);
}

scene::Frame renderDefaults(const scene::Scene& s, const scene::SettingsOverrides& o = {}) {
    return test::renderChecked(s, scene::resolveSettings(s, o));
}

// Ground pixels the sphere's shadow covers and how the raster frame classifies them, judged by
// the exact shadow: P is shadowed when the ray from P toward the light, P − tL (t > 0), passes
// within r of the sphere's center C: |(P − C) − ((P − C)·L)L| < r with (P − C)·L > 0. On the
// ground that set is the ellipse with semi-axes r across the light and r / sin(elevation) along
// it. Pixels within `margin` of the ellipse's edge (in distance from the axis) are left out.
struct ShadowCount {
    int inside = 0, insideShadowed = 0, outside = 0, outsideShadowed = 0;
};
ShadowCount countSphereShadow(const scene::Scene& s, const scene::Frame& f, const Vec3& c, double r, double margin) {
    const Vec3 L = s.lights[0].direction;
    ShadowCount n;
    for (int y = 0; y < f.height; ++y)
        for (int x = 0; x < f.width; ++x) {
            const std::size_t i = std::size_t(y) * std::size_t(f.width) + std::size_t(x);
            if (f.objectId[i] != float(s.objects.size())) continue;  // the ground is the last object
            const auto p = groundPoint(s, x, y);
            if (!p) continue;
            const Vec3 d = *p - c;
            const double along = glm::dot(d, L);
            const double across = glm::length(d - along * L);
            const bool shadowed = f.visibility[i] < 0.5f;
            if (along > 0.0 && across < r - margin) {
                ++n.inside;
                n.insideShadowed += shadowed ? 1 : 0;
            } else if (along < -margin || across > r + margin) {
                ++n.outside;
                n.outsideShadowed += shadowed ? 1 : 0;
            }
        }
    return n;
}

// A sphere of radius 0.5 resting on the 1000-unit ground under a sun 2° high, the camera looking
// along its shadow: the ellipse is 0.5 x 14.3 and starts at the contact point. The scene's bounding
// sphere is 1414 units across, so its map's texel at 2048 is 0.70 and its slope bias at grazing
// light (10 texels) 7 units, far more than the sphere's depth along the light: that map loses the
// shadow. The defaults (fitted, cascades by view) must keep it.
TEST(RasterDefaults, ALowSunOverALargeGroundKeepsTheSmallSpheresEllipse) {
    const Vec3 c(0, 0.5, 0);
    const double r = 0.5;
    scene::Scene s = largeGround(2.0, Vec3(-4, 3, 6), Vec3(6, 0, 0));
    scene::Object sphere;
    sphere.name = "sphere";
    sphere.shape = scene::Sphere{c, r};
    s.objects.insert(s.objects.begin(), sphere);

    const scene::Frame f = renderDefaults(s);
    const ShadowCount n = countSphereShadow(s, f, c, r, 0.05);
    ASSERT_GT(n.inside, 500);  // the ellipse covers a good part of the image
    EXPECT_GE(n.insideShadowed, int(0.97 * n.inside)) << n.insideShadowed << " of " << n.inside;
    EXPECT_LE(n.outsideShadowed, int(0.002 * n.outside) + 5) << n.outsideShadowed << " of " << n.outside;
    EXPECT_EQ(f.attributes.at("light_frustum_fit"), "receivers");
    EXPECT_EQ(f.attributes.at("light_frustum_fit_reason"), "default");

    // The bounding-sphere map, forced, misses most of it (what the defaults were before).
    scene::SettingsOverrides bounding;
    bounding.fitLightFrustum = false;
    bounding.cascades = 1;
    const ShadowCount b = countSphereShadow(s, renderDefaults(s, bounding), c, r, 0.05);
    EXPECT_LT(b.insideShadowed, n.inside / 2) << b.insideShadowed << " of " << b.inside;
}

// The same sphere under a sun 1° high, at the defaults: the ground must be lit wherever the sphere
// does not shadow it. The ground's depth along the light changes by texel·tan θ per texel of the
// map (tan 89° = 57.3). pcf2x2 mixes the four texels around the lookup point bilinearly; a texel
// center at offset o (texels, |o_x|, |o_y| < 1) stores the ground o·ĝ·texel·tan θ nearer than the
// point (ĝ the unit gradient). The defaults give each of the four a margin of half a texel plus
// 2·min(tan θ, 10) texels of slope bias (the gather's texels reach one texel further than the
// point) plus the slope bias past its cap along the normal: a lookup point lifted by
// texel·(sin θ − 10 cos θ) lies texel·(tan θ − 10) in front of its own plane. In all
// texel·(tan θ + 10.5) ≥ texel·tan θ, so a texel compares false only where o·ĝ > 1, i.e.
// o_x² + o_y² > 1, where its weight (1 − |o_x|)(1 − |o_y|) is at most (1 − 1/√2)² = 0.086; only
// the one texel diagonally toward the light can be that far. So every lit ground pixel keeps
// V ≥ 1 − 0.086. (Without the part past the cap the margin is 20.5 texels of depth against 57.3:
// stripes across the ground where V < 0.5, 13% of scenes/extreme/grazing-1deg.)
const Vec3 kOneDegreeSphereCenter(0, 0.5, 0);
const double kOneDegreeSphereRadius = 0.5;
scene::Scene oneDegreeSun() {
    scene::Scene s = largeGround(1.0, Vec3(-4, 3, 6), Vec3(6, 0, 0));
    scene::Object sphere;
    sphere.name = "sphere";
    sphere.shape = scene::Sphere{kOneDegreeSphereCenter, kOneDegreeSphereRadius};
    s.objects.insert(s.objects.begin(), sphere);
    return s;
}
void expectOneDegreeGroundLitAndShadowed(const scene::Scene& s, const scene::Frame& f) {
    const Vec3 c = kOneDegreeSphereCenter;
    const double r = kOneDegreeSphereRadius;

    // Pixels within three texels of the ellipse's edge (in distance from the light's axis through
    // the sphere's center, a distance across the map) are left out: pcf2x2 spreads an edge over a
    // texel, the lift (at most one texel) widens the shadow by about as much, and the sphere's
    // facets move its outline a little more. The whole ellipse (28.6 long, at most ~33 from the
    // camera) lies in the first map, whose texel is the first texel_world_size.
    const double texel = std::stod(f.attributes.at("texel_world_size"));
    const double margin = 3.0 * texel;
    ASSERT_LT(margin, 0.5 * r);
    const double bound = 1.0 - (1.0 - 1.0 / std::sqrt(2.0)) * (1.0 - 1.0 / std::sqrt(2.0));
    const Vec3 L = s.lights[0].direction;
    int lit = 0, below = 0, inside = 0, insideShadowed = 0;
    float worst = 1.0f;
    for (int y = 0; y < f.height; ++y)
        for (int x = 0; x < f.width; ++x) {
            const std::size_t i = std::size_t(y) * std::size_t(f.width) + std::size_t(x);
            if (f.objectId[i] != 2.0f) continue;  // the ground
            const auto p = groundPoint(s, x, y);
            if (!p) continue;
            const Vec3 d = *p - c;
            const double along = glm::dot(d, L);
            const double across = glm::length(d - along * L);
            if (along > 0.0 && across < r - margin) {
                ++inside;
                insideShadowed += f.visibility[i] < 0.5f ? 1 : 0;
            } else if (along < -margin || across > r + margin) {
                ++lit;
                worst = std::min(worst, f.visibility[i]);
                below += f.visibility[i] < float(bound) ? 1 : 0;
            }
        }
    ASSERT_GT(lit, f.width * f.height / 4);
    ASSERT_GT(inside, 200);  // the ribbon of shadow seen from its side
    EXPECT_EQ(below, 0) << "lit ground pixels under " << bound << " (acne): " << below << " of " << lit
                        << ", least visibility " << worst;
    EXPECT_GE(insideShadowed, int(0.97 * inside)) << insideShadowed << " of " << inside;
    EXPECT_EQ(f.attributes.at("slope_bias"), "1");
    EXPECT_EQ(f.attributes.at("grazing_normal_offset"), "1");
}
TEST(RasterDefaults, ASunOneDegreeHighLeavesTheLitGroundLitAndKeepsTheShadow) {
    const scene::Scene s = oneDegreeSun();
    scene::RenderSettings settings = scene::resolveSettings(s, {});
    settings.raster.validate = true;
    expectOneDegreeGroundLitAndShadowed(s, test::renderChecked(s, settings.raster));
}

// The same scene with a wall, drawn from a Renderer's second frame on: the triangles whose every
// vertex has N·L past the slope bias's cap by the margin go through the lit pipeline without the
// lift (raster/lift_free.h), the ground (N·L = sin 1°, a receiver past tan θ = 10) through the one
// with it. The ground keeps the bounds worked out above, and every channel of
// every frame kind is a Renderer's without lift-free draws, bit for bit (its first frame too, drawn
// all with the lift).
TEST(RasterDefaults, LiftFreeDrawsFromTheSecondFrameKeepTheOneDegreeGroundAndEveryChannel) {
    scene::Scene s = oneDegreeSun();
    // A wall across the far end of the view, facing the sun (N·L = cos 1°): large lift-free faces
    // beside the grazing ground. It is taller than the camera (3 above the ground), so the ground
    // it shadows, all beyond it along the light (+x), is hidden behind it; the ground pixels the test
    // judges are object 2 and unchanged.
    scene::Object wall;
    wall.name = "wall";
    wall.shape = scene::Box{{30, 0, -100}, {31, 4, 100}};
    s.objects.push_back(wall);
    scene::RenderSettings settings = scene::resolveSettings(s, {});
    settings.raster.validate = true;
    const scene::RenderPlan plan = scene::makeRenderPlan(s, settings);
    Renderer split(s, plan, settings.raster);
    Renderer whole(s, plan, settings.raster, RendererOptions{.liftFreeDraws = false});
    for (const scene::ChannelMask channels :
         {scene::kAllChannels, scene::kChannelBeauty, scene::kChannelBeauty | scene::kBeautyForDisplay}) {
        RenderDebug first, second, reference;
        const scene::Frame a = split.render(channels, &first), b = split.render(channels, &second);
        whole.render(channels);
        const scene::Frame w = whole.render(channels, &reference);
        EXPECT_GT(second.liftFreeTriangles, 0u) << "nothing was drawn without the lift";
        EXPECT_EQ(reference.liftFreeTriangles, 0u);
        if (channels == scene::kAllChannels) {
            EXPECT_EQ(first.liftFreeTriangles, 0u);  // a Renderer's first frame: every triangle with the lift
            expectOneDegreeGroundLitAndShadowed(s, b);
            test::writePngToLookAt(b, "one-degree-lift-free");
        }
        test::expectSamePixels(a, w, "first frame, every triangle with the lift");
        test::expectSamePixels(b, w, "second frame, lift-free draws");
    }
    EXPECT_EQ(split.validationMessages(), 0);
    EXPECT_EQ(whole.validationMessages(), 0);
}

// update() finds the lift-free triangles again for the new light. A Renderer made under a sun 63°
// high, where the ground (N·L = sin 63°) is lift-free, then moved to the 1° sun, where it is a
// receiver past tan θ = 10, must draw the ground with the lift again: the 1° bounds above hold, and
// every channel is that of a Renderer made for the 1° sun without lift-free draws. Keeping the high
// sun's split would draw the ground without the lift, and its acne would fail both.
TEST(RasterDefaults, LiftFreeDrawsFollowTheLightThroughUpdate) {
    const scene::Scene low = oneDegreeSun();
    scene::Scene high = low;
    high.lights[0].direction = glm::normalize(Vec3(1.0, -2.0, 0.0));
    scene::RenderSettings settings = scene::resolveSettings(low, {});
    settings.raster.validate = true;
    const scene::RenderPlan plan = scene::makeRenderPlan(low, settings);
    Renderer moved(high, plan, settings.raster);
    Renderer whole(low, plan, settings.raster, RendererOptions{.liftFreeDraws = false});
    RenderDebug underHigh, underLow;
    moved.render(scene::kAllChannels);
    moved.render(scene::kAllChannels, &underHigh);
    moved.update(low);
    const scene::Frame f = moved.render(scene::kAllChannels, &underLow);
    EXPECT_GT(underHigh.liftFreeTriangles, underLow.liftFreeTriangles)
        << "the ground is lift-free only under the high sun";
    expectOneDegreeGroundLitAndShadowed(low, f);
    test::expectSamePixels(f, whole.render(scene::kAllChannels), "moved to the low sun against made for it");
    EXPECT_EQ(moved.validationMessages(), 0);
    EXPECT_EQ(whole.validationMessages(), 0);
}

// The cascade rule: one map is kept while its texel is at most 2 pixels at the nearest visible
// receiver. On the low-sun ground the single fitted map is at least as wide, across the light, as
// the distance across the light between two visible ground points, and the nearest receiver is no
// farther than any visible point; so its texels per pixel are at least
// (that width / 2048) / pixel(view depth of the nearer point), which here exceeds 2: the rule must
// split the view. At 64 x 36 of a small scene the scene's whole bounding-sphere map (which the
// fitted one never exceeds) is already under 2 pixels a texel: one map.
TEST(RasterDefaults, CascadesAreChosenWhenOneMapsTexelExceedsTwoPixels) {
    // The camera looks across the light (along −z), so the ground it sees spans hundreds of units
    // across the map. The ground shades itself (a mesh), so all of it that the camera sees is a
    // receiver the maps must cover.
    scene::Scene s = largeGround(2.0, Vec3(0, 3, 8), Vec3(0, 0, -10));
    test::makeGroundShadeItself(s, 0);
    scene::Object caster;  // something to shadow the ground, so the light gets a map
    caster.shape = scene::Sphere{Vec3(0, 0.5, -5), 0.5};
    s.objects.push_back(caster);
    const scene::RenderSettings settings = scene::resolveSettings(s, {});
    ASSERT_TRUE(settings.raster.cascadesIsDefault);
    // Two visible ground points: the pixel centers of the bottom-left corner and of the image's
    // middle column a few rows below the horizon (the camera looks atan(3/18) = 9.5° down, the horizon
    // 9.5° above the image's center: row 90·(1 − tan 9.5°/tan 20°) = 48.8).
    const auto a = groundPoint(s, 0, s.camera.height - 1), b = groundPoint(s, s.camera.width / 2, 51);
    ASSERT_TRUE(a && b);
    const scene::CameraBasis cam = scene::cameraBasis(s.camera);
    ASSERT_LT(glm::dot(*b - cam.position, cam.forward), s.camera.far);  // inside the view
    LightFrustum basis;
    setBasis(basis, s.lights[0].direction);
    const double across = std::max(std::abs(glm::dot(*a - *b, basis.right)), std::abs(glm::dot(*a - *b, basis.up)));
    const double zNear = std::min(glm::dot(*a - cam.position, cam.forward), glm::dot(*b - cam.position, cam.forward));
    const double pixel = 2.0 * std::tan(20.0 * kPi / 180.0) * zNear / s.camera.height;
    ASSERT_GT(across / 2048.0 / pixel, 2.0)
        << across << " across, nearest " << zNear;  // one map's texels per pixel, at least
    const CascadeChoice chosen = chooseCascades(s, settings.raster);
    EXPECT_GE(chosen.count, 2) << chosen.reason;
    EXPECT_LE(chosen.count, scene::kMaxCascades);

    // Forced, it is kept, and the Frame records the reason.
    scene::SettingsOverrides one;
    one.cascades = 1;
    const scene::RenderSettings forced = scene::resolveSettings(s, one);
    EXPECT_EQ(chooseCascades(s, forced.raster).count, 1);

    // A small scene at a small image: the 20 x 20 ground with a unit sphere, whose bounding sphere
    // is 1.01·√(20² + 20² + 2²) = 28.6 wide: 0.014 a texel at 2048, against a pixel of
    // 2·tan 20°·z/36 ≥ 0.07 at any view depth z ≥ 3.5 (the camera 6 from the sphere): one map.
    scene::Scene small = largeGround(45.0, Vec3(0, 2, 6), Vec3(0, 0.7, 0));
    std::get<scene::Quad>(small.objects[0].shape).size = scene::Vec2(20, 20);
    scene::Object sphere;
    sphere.shape = scene::Sphere{Vec3(0, 1, 0), 1.0};
    small.objects.push_back(sphere);
    small.camera.width = 64;
    small.camera.height = 36;
    const CascadeChoice smallChoice = chooseCascades(small, scene::resolveSettings(small, {}).raster);
    EXPECT_EQ(smallChoice.count, 1) << smallChoice.reason;
    EXPECT_NE(smallChoice.reason.find("within 2 pixels"), std::string::npos) << smallChoice.reason;

    const scene::Frame f = renderDefaults(s);
    EXPECT_EQ(f.attributes.at("cascades"), std::to_string(chosen.count));
    EXPECT_EQ(f.attributes.at("cascades_reason"), chosen.reason);
}

// Two horizontal 2 x 2 panes of opacity 0.5 at heights 1 and 1.6 over the 1000-unit ground, the
// sun 40° high along +x: a ground point P lies under pane k when P − tL reaches height h_k inside
// it, i.e. at P + (h_k / tan 40°)·(−x̂) + h_k·ŷ, within ±1 of its center in x and z. Where both
// hold, the ground receives (1 − 0.5)² = 0.25 of the light; the defaults must give that within
// ±0.03 on average. (The bounding-sphere map's texel, 0.7, is a third of a pane.)
TEST(RasterDefaults, TwoStackedHalfPanesOverALargeGroundTransmitAQuarter) {
    scene::Scene s = largeGround(40.0, Vec3(-5, 5, 7), Vec3(1, 0, 0));
    s.materials.push_back(material("pane", 0.5));
    const Vec3 centers[] = {{0, 1, 0}, {-0.4, 1.6, 0}};
    s.objects.insert(s.objects.begin(), quad(centers[1], 2, 2, 1));
    s.objects.insert(s.objects.begin(), quad(centers[0], 2, 2, 1));
    const double t = std::tan(40.0 * kPi / 180.0);
    auto underBoth = [&](const Vec3& p, double margin) {
        for (const Vec3& c : centers) {
            const Vec3 q = p + Vec3(-c.y / t, c.y, 0);
            if (std::abs(q.x - c.x) > 1 - margin || std::abs(q.z - c.z) > 1 - margin) return false;
        }
        return true;
    };
    auto meanUnderBoth = [&](const scene::Frame& f, int& count) {
        double sum = 0.0;
        count = 0;
        for (int y = 0; y < f.height; ++y)
            for (int x = 0; x < f.width; ++x) {
                const std::size_t i = std::size_t(y) * std::size_t(f.width) + std::size_t(x);
                if (f.objectId[i] != 3.0f) continue;  // the ground
                const auto p = groundPoint(s, x, y);
                if (!p || !underBoth(*p, 0.1)) continue;
                sum += f.visibility[i];
                ++count;
            }
        return count ? sum / count : -1.0;
    };
    int n = 0;
    const double mean = meanUnderBoth(renderDefaults(s), n);
    ASSERT_GT(n, 300);
    EXPECT_NEAR(mean, 0.25, 0.03) << n << " pixels";

    scene::SettingsOverrides bounding;
    bounding.fitLightFrustum = false;
    bounding.cascades = 1;
    int nb = 0;
    EXPECT_GT(meanUnderBoth(renderDefaults(s, bounding), nb), 0.28);  // the reproduction: too light
}

// The casters' smallest feature in the map-size rule: a bar 0.08 wide standing on a 10 x 10 ground
// under a sun, the bounding-sphere map forced (its width is known): 1.01·√(10² + 3² + 10²) =
// 14.60. The bar needs 4 texels across 0.08: 4·14.60/0.08 = 730 texels, a 1024 map, while at 32 x 18
// the receivers alone need at most 14.60 / (2·tan 20°·z/18) ≤ 14.60/0.31 = 48 texels (every point of
// the scene's box lies at view depth z ≥ 7.6, its corners (±5, 3, 5) seen from (0, 6, 12) toward the
// origin): 256. So the size is 1024 from the caster.
TEST(RasterDefaults, TheAutomaticMapSizeResolvesTheThinnestCaster) {
    scene::Scene s = largeGround(50.0, Vec3(0, 6, 12), Vec3(0, 0, 0));
    std::get<scene::Quad>(s.objects[0].shape).size = scene::Vec2(10, 10);
    scene::Object bar;
    bar.name = "bar";
    bar.shape = scene::Box{{-0.04, 0, -2}, {0.04, 3, 2}};
    s.objects.push_back(bar);
    s.camera.width = 32;
    s.camera.height = 18;
    EXPECT_DOUBLE_EQ(casterFeatureSize(s.objects[1]), 0.08);
    scene::SettingsOverrides o;
    o.fitLightFrustum = false;
    const scene::RenderSettings settings = scene::resolveSettings(s, o);
    const double width = 2.0 * 1.01 * 0.5 * std::sqrt(10.0 * 10.0 + 3.0 * 3.0 + 10.0 * 10.0);
    ASSERT_NEAR(4.0 * width / 0.08, 730.0, 1.0);
    const ShadowMapSizeChoice c = chooseShadowMapSize(s, settings.raster);
    EXPECT_EQ(c.size, 1024) << c.reason;
    EXPECT_NE(c.reason.find("'bar'"), std::string::npos) << c.reason;

    // Without the bar the receivers decide: 256.
    s.objects.pop_back();
    EXPECT_EQ(chooseShadowMapSize(s, scene::resolveSettings(s, o).raster).size, 256);
}

// The same rule for a spot: a texel at distance d along the axis is d·2t/N, so a caster of width w
// whose farthest point lies d along the axis needs N ≥ 4·2t·d/w. A spot 8 above the ground pointing
// down, cone 60° (the unfitted map's half-angle 1.02·60° = 61.2°, t = tan 61.2° = 1.8190), over a
// bar 0.2 wide standing on the ground (d = 8): 4·2·1.8190·8/0.2 = 582 texels → 1024. The camera, 10
// above the ground looking down at 32 x 18, needs far fewer for the receivers.
TEST(RasterDefaults, TheAutomaticSpotMapSizeResolvesTheThinnestCasterAtItsDistance) {
    scene::Scene s = largeGround(90.0, Vec3(0, 10, 0.001), Vec3(0, 0, 0));
    std::get<scene::Quad>(s.objects[0].shape).size = scene::Vec2(10, 10);
    s.lights = {test::spotDown()};
    s.camera.width = 32;
    s.camera.height = 18;
    scene::Object bar;
    bar.name = "bar";
    bar.shape = scene::Box{{-0.1, 0, -1}, {0.1, 1, 1}};
    s.objects.push_back(bar);
    scene::SettingsOverrides o;
    o.fitLightFrustum = false;
    const double t = std::tan(61.2 * kPi / 180.0);
    ASSERT_NEAR(4.0 * 2.0 * t * 8.0 / 0.2, 582.1, 0.5);
    const ShadowMapSizeChoice c = chooseShadowMapSize(s, scene::resolveSettings(s, o).raster);
    EXPECT_EQ(c.size, 1024) << c.reason;
    EXPECT_NE(c.reason.find("'bar'"), std::string::npos) << c.reason;
    s.objects.pop_back();
    EXPECT_EQ(chooseShadowMapSize(s, scene::resolveSettings(s, o).raster).size, 256);
}

// A sphere's feature is its diameter, a quad's its shorter side; a mesh's the median width (twice
// the area over the longest edge) of its triangles: a strip of right triangles with legs 0.01 and
// 1 (width 0.01/√(1 + 0.0001)) and one larger triangle (legs 1, 1: width 1/√2) has the strip's.
TEST(RasterDefaults, CasterFeatureSizesAreTheShapesSmallestDimensions) {
    scene::Object o;
    o.shape = scene::Sphere{Vec3(0), 0.3};
    EXPECT_DOUBLE_EQ(casterFeatureSize(o), 0.6);
    o = quad(Vec3(0), 3, 0.2, 0);
    EXPECT_DOUBLE_EQ(casterFeatureSize(o), 0.2);
    auto mesh = std::make_shared<scene::TriangleMesh>();
    for (int k = 0; k < 3; ++k) {
        const auto base = std::uint32_t(mesh->positions.size());
        mesh->positions.push_back(Vec3(k, 0, 0));
        mesh->positions.push_back(Vec3(k + 1, 0, 0));
        mesh->positions.push_back(Vec3(k, 0.01, 0));
        mesh->indices.insert(mesh->indices.end(), {base, base + 1, base + 2});
    }
    const auto base = std::uint32_t(mesh->positions.size());
    mesh->positions.insert(mesh->positions.end(), {Vec3(0, 0, 5), Vec3(1, 0, 5), Vec3(0, 1, 5)});
    mesh->indices.insert(mesh->indices.end(), {base, base + 1, base + 2});
    // Placed at twice the size: widths double.
    o.shape = scene::Mesh::single("strip", mesh, scene::Affine(glm::dmat4(2.0)));
    EXPECT_NEAR(casterFeatureSize(o), 2.0 * 0.01 / std::sqrt(1.0 + 1e-4), 1e-12);
}

}  // namespace
}  // namespace shadowlab::raster
