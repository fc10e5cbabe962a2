// tests/compare/bleeding_render_test.cpp: light bleeding told from bias leaks on real renders
// (lavapipe with the validation layer, against the double-precision reference and its blocker
// distances): two casters at different heights under VSM bleed where the upper one's edge
// crosses the lower one's shadow, EVSM4 bleeds less there, a wall's contact leak under a large
// constant bias is a bias leak, not bleeding, and a box keeps its contact shadow under the same bias
// (the map holds its top, not the face the reference's blocker distance measures).
#include <cmath>
#include <cstdio>

#include <gtest/gtest.h>

#include "compare/compare.h"
#include "compare/report.h"
#include "compare/thresholds.h"
#include "raster/renderer.h"
#include "raytrace/renderer.h"
#include "scene/camera.h"
#include "tests/kit/render_checked.h"

namespace shadowlab::compare {
namespace {

using Vec3 = scene::Vec3;

scene::Object horizontal(const std::string& name, const Vec3& center, double sx, double sz) {
    scene::Quad q;
    q.center = center;
    q.normal = Vec3(0, 1, 0);
    q.size = scene::Vec2(sx, sz);
    scene::quadAxes(q.normal, q.uAxis, q.vAxis);  // for +y: u = +x, v = z, so size is (x, z)
    return {name, q, 0};
}

// A floor (id 1) under a directional light travelling along (−1, −1, 0)/√2, seen from above at
// `target` (320×180), with `casters` (ids 2...).
scene::Scene lit(std::vector<scene::Object> casters, const Vec3& target) {
    scene::Scene s;
    s.camera.position = target + Vec3(0, 5, 2);
    s.camera.lookAt = target;
    s.camera.up = Vec3(0, 1, 0);
    s.camera.fovYDegrees = 40.0;
    s.camera.width = 320;
    s.camera.height = 180;
    s.camera.near = 0.1;
    s.camera.far = 100.0;
    scene::Material m;
    m.name = "matte";
    s.materials.push_back(m);
    scene::Light l;
    l.type = scene::LightType::Directional;
    l.direction = glm::normalize(Vec3(-1, -1, 0));
    l.intensity = 2.0;
    s.lights.push_back(l);
    s.objects.push_back(horizontal("floor", Vec3(-1, 0, 0), 10.0, 8.0));
    for (scene::Object& o : casters) s.objects.push_back(o);
    return s;
}

struct Renders {
    Comparison c;
    scene::Frame raster, reference;
    double texel = 0;  // the shadow map's texel, world units
};

Renders compareRaster(const scene::Scene& s, const scene::SettingsOverrides& o) {
    scene::SettingsOverrides ov = o;
    ov.fitLightFrustum = false;  // the bounding-sphere map: its texel is known below
    ov.cascades = 1;
    scene::RenderSettings settings = scene::resolveSettings(s, ov);
    const scene::RenderPlan plan = scene::makeRenderPlan(s, settings);
    raster::RenderDebug debug;
    Renders r;
    r.raster = test::renderChecked(s, settings, &debug);
    if (!debug.layers.empty()) r.texel = debug.layers[0].frustum.texelWorldSize();
    r.reference = raytrace::renderReference(s, plan, scene::referenceSettings(settings.raytrace));
    r.c = compareFrames(r.raster, r.reference);
    return r;
}

// The floor point of pixel i (y = 0), from the camera ray.
Vec3 floorPoint(const scene::Scene& s, std::size_t i) {
    const scene::CameraBasis cam = scene::cameraBasis(s.camera);
    const int x = int(i % std::size_t(s.camera.width)), y = int(i / std::size_t(s.camera.width));
    const Vec3 d = scene::pixelDirection(cam, x, y);
    return cam.position + (-cam.position.y / d.y) * d;
}

TEST(BleedingAgainstReference, VsmBleedsWhereTheUpperCastersEdgeCrossesTheLowerOnesShadow) {
    // A (id 2) at height 1 over x 0..0.8 shadows the floor at x −1..−0.2 (the light moves 1 in −x
    // per unit of height); B (id 3) at height 8 over x 3..7.4 shadows it at x −5..−0.6. On the
    // floor at x −0.6..−0.2 only A blocks, √2 ≈ 1.41 away along the ray: the light-space texels
    // there hold A's depth, those of B's side B's. Near B's edge the blurred window mixes a share
    // w of B: Chebyshev gives p = w(1−w)Δ² / (w(1−w)Δ² + (g + wΔ)²) with the gaps g = √2 (floor
    // to A) and Δ = 7√2 (A to B): 0.67 at w = 0.1, 0.55 at w = 0.3, lit where the reference is in
    // shadow. The contact distance is half a texel plus 4 texels (tanθ = 1): about 0.15 at 512²
    // over the scene's 17.5-wide bounding-sphere map, far below 1.41: bleeding.
    const scene::Scene s =
        lit({horizontal("A", Vec3(0.4, 1, 0), 0.8, 4.0), horizontal("B", Vec3(5.2, 8, 0), 4.4, 4.0)}, Vec3(-0.6, 0, 0));
    scene::SettingsOverrides o;
    o.shadowMapSize = 512;
    o.filter = "vsm";
    const Renders vsm = compareRaster(s, o);
    const Metrics& m = vsm.c.metrics;
    ASSERT_TRUE(m.hasBlockerDistance);
    EXPECT_LT(m.contactDistance, 0.3);
    // Where the bleeding pixels are: on the floor between B's shadow edge and A's.
    std::size_t inBand = 0, far = 0;
    for (std::size_t i = 0; i < vsm.c.classes.size(); ++i) {
        if (vsm.c.classes[i] != PixelClass::MissedShadow || vsm.reference.objectId[i] != 1.0f) continue;
        if (double(vsm.reference.blockerDistance[i]) <= 1.0) continue;
        ++far;
        const Vec3 p = floorPoint(s, i);
        if (p.x > -0.62 && p.x < -0.2) ++inBand;
    }
    std::printf(
        "vsm: missed %zu, bleeding %zu, bias leak %zu, far-blocker missed on the floor %zu (%zu between x -0.62 and "
        "-0.2), D %.4f\n",
        m.missedShadow, m.bleeding, m.biasLeak, far, inBand, m.contactDistance);
    EXPECT_GT(m.bleeding, 50u);
    EXPECT_GT(double(inBand), 0.9 * double(far));
    // Their blocker is A, at √2 along the ray (the reference's nearest blocker, not B).
    for (std::size_t i = 0; i < vsm.c.classes.size(); ++i)
        if (vsm.c.classes[i] == PixelClass::MissedShadow && vsm.reference.objectId[i] == 1.0f &&
            vsm.reference.blockerDistance[i] > 1.0f) {
            EXPECT_EQ(vsm.reference.blockerId[i], 2.0f);
            EXPECT_NEAR(vsm.reference.blockerDistance[i], std::sqrt(2.0), 0.01);
        }

    // EVSM4 warps the depths exponentially: the gap g weighs e^{2c·g} against Δ and the bound
    // falls under 0.5 there.
    o.filter = "evsm4";
    const Metrics e = compareRaster(s, o).c.metrics;
    std::printf("evsm4: missed %zu, bleeding %zu, bias leak %zu\n", e.missedShadow, e.bleeding, e.biasLeak);
    EXPECT_LT(e.bleeding, m.bleeding);
}

// A floor point (x, 0, z) with x in −1.5..−0.5 and |z| < 0.5 lies in the shadow of a unit-high
// caster standing on the floor along x = −0.5, |z| < 0.5: its ray to the light (45°) meets the
// plane x = −0.5 at height −0.5 − x, d = √2·(−0.5 − x) away, which is the reference's blocker
// distance. The constant bias b moves the receiver b along the light toward it (lit.frag
// reference(): bias·depth-per-world-unit of the orthographic map, not clamped, and the value given
// is kept, not re-derived for the map), so the map answers "lit" where the surface it holds on that
// ray, the one nearest the light, is within b of the receiver. pcf2x2 with no slope bias reads
// texels up to 1.5 texels from the point, and a surface seen at 45° moves a texel in depth per
// texel: the answer is exact outside δ = 2·√2·texel of where that distance equals b.
struct ContactBand {
    std::size_t band = 0, bandLit = 0, rest = 0, restShadowed = 0;
};
ContactBand contactBand(const scene::Scene& s, const Renders& r, double b) {
    const double delta = 2.0 * std::sqrt(2.0) * r.texel;
    ContactBand c;
    for (std::size_t i = 0; i < r.c.classes.size(); ++i) {
        if (r.reference.objectId[i] != 1.0f) continue;
        const Vec3 p = floorPoint(s, i);
        if (std::abs(p.z) > 0.45 || p.x > -0.5 - delta || p.x < -1.5 + delta) continue;  // clear of the side faces
        const double d = std::sqrt(2.0) * (-0.5 - p.x);
        EXPECT_EQ(r.reference.visibility[i], 0.0f) << "the reference shadows the whole shadow, at x " << p.x;
        if (d < b - delta) {
            ++c.band;
            c.bandLit += r.raster.visibility[i] == 1.0f;
        } else if (d > b + delta) {
            ++c.rest;
            c.restShadowed += r.raster.visibility[i] == 0.0f;
        }
    }
    return c;
}

TEST(BleedingAgainstReference, AContactLeakUnderALargeConstantBiasIsABiasLeak) {
    // A wall (a vertical quad, x = −0.5, 1 high, |z| < 0.5) is the only surface on those rays, so
    // the map holds the wall itself, d from the receiver: a bias b = 0.3 lets light through where
    // d < b, the band x in (−0.5 − b/√2, −0.5) = (−0.712, −0.5), and nowhere else. Every such leak
    // lies within the contact distance D = b + 4 texels (compare/thresholds.h; tanθ = 1) of its
    // blocker, so it is a bias leak and none of it may be read as light bleeding.
    scene::Quad wall;
    wall.center = Vec3(-0.5, 0.5, 0.0);
    wall.normal = Vec3(1, 0, 0);
    scene::quadAxes(wall.normal, wall.uAxis, wall.vAxis);
    wall.size = scene::Vec2(1.0, 1.0);  // square, so the order of quadAxes' u and v does not matter
    const scene::Scene s = lit({{"wall", wall, 0}}, Vec3(-1, 0, 0));
    scene::SettingsOverrides o;
    o.shadowMapSize = 1024;
    o.filter = "pcf2x2";
    o.depthBias = 0.3;
    o.slopeBias = 0.0;
    const Renders r = compareRaster(s, o);
    const Metrics& m = r.c.metrics;
    ASSERT_TRUE(m.hasBlockerDistance);
    ASSERT_GT(r.texel, 0.0);
    const double b = 0.3;
    const ContactBand c = contactBand(s, r, b);
    std::printf(
        "wall, pcf2x2, bias 0.3: band %zu (%zu lit), rest %zu (%zu shadowed); missed %zu (%zu near an edge), "
        "bleeding %zu, bias leak %zu, D %.4f, texel %.4f\n",
        c.band, c.bandLit, c.rest, c.restShadowed, m.missedShadow, m.missedShadowNearEdge, m.bleeding, m.biasLeak,
        m.contactDistance, r.texel);
    EXPECT_GT(c.band, 200u) << "the camera must see the band";
    EXPECT_EQ(c.bandLit, c.band) << "the bias lets light through wherever the wall is nearer than b";
    EXPECT_GT(c.rest, 1000u);
    EXPECT_EQ(c.restShadowed, c.rest) << "and nowhere else";
    EXPECT_NEAR(m.contactDistance, b + kContactTexels * r.texel, 1e-3 * r.texel);  // its value for N·L = 1
    // Every lit band pixel is a missed shadow whose blocker lies within d < b < D.
    EXPECT_GE(m.biasLeak, c.bandLit);
    EXPECT_EQ(m.bleeding, 0u);
}

TEST(BleedingAgainstReference, ABoxKeepsItsContactShadowUnderTheSameBias) {
    // The same rays through a unit box [−0.5, 0.5]³ on the floor (top at y = 1) meet its face
    // x = −0.5 first (the reference's blocker, d away), but the map holds the surface nearest the
    // light, where the ray leaves the box: its top, at height 1, √2 from every receiver of the
    // shadow (x + 1 < 0.5, so the ray leaves through the top, not the face x = 0.5). b = 0.3 < √2:
    // the whole shadow stays, the band included. What is missed lies at the shadow's edges (the
    // texel grid's stair steps), none of it bleeding.
    const scene::Scene s = lit({{"box", scene::Box{Vec3(-0.5, 0, -0.5), Vec3(0.5, 1, 0.5)}, 0}}, Vec3(-1, 0, 0));
    scene::SettingsOverrides o;
    o.shadowMapSize = 1024;
    o.filter = "pcf2x2";
    o.depthBias = 0.3;
    o.slopeBias = 0.0;
    const Renders r = compareRaster(s, o);
    const Metrics& m = r.c.metrics;
    ASSERT_TRUE(m.hasBlockerDistance);
    ASSERT_GT(r.texel, 0.0);
    const ContactBand c = contactBand(s, r, 0.3);
    std::printf(
        "box, pcf2x2, bias 0.3: band %zu (%zu lit), rest %zu (%zu shadowed); missed %zu (%zu near an edge), "
        "bleeding %zu, bias leak %zu\n",
        c.band, c.bandLit, c.rest, c.restShadowed, m.missedShadow, m.missedShadowNearEdge, m.bleeding, m.biasLeak);
    EXPECT_GT(c.band, 200u);
    EXPECT_EQ(c.bandLit, 0u) << "the map holds the box's top, √2 > b from the receivers";
    EXPECT_EQ(c.restShadowed, c.rest);
    EXPECT_EQ(m.missedShadow, m.missedShadowNearEdge) << "missed shadow only along the shadow's edges";
    EXPECT_EQ(m.bleeding, 0u);
}

TEST(BleedingAgainstReference, ALowCurbsThinShadowLostToTheDefaultBiasIsABiasLeakNotAliasing) {
    // A curb h high, [−0.1, 0] × [0, h] × [−0.5, 0.5], under the 45° light: the reference shadows
    // the floor strip x in (−0.1 − h, −0.1), its blocker the face x = −0.1, √2·(−0.1 − x) ≤ √2·h
    // away. The map holds the curb's top on those rays (the ray leaves through it), √2·h from the
    // receiver; the default biases move the receiver half a texel plus 1 texel × tanθ (= 1) toward
    // the light, 1.5 texels, so with √2·h < 1.5 texels the whole strip is lit: a shadow a step
    // casts, lost to the bias (the milk truck's window trim on its glass). The strip is two pixels
    // wide, so each of its pixels lies within 2 px of its edge, yet none is aliasing: every
    // blocker is within the contact distance D = 0.5 + 5 texels.
    const double h = 0.02;
    scene::Scene s = lit({{"curb", scene::Box{Vec3(-0.1, 0, -0.5), Vec3(0, h, 0.5)}, 0}}, Vec3(-0.3, 0, 0));
    s.camera.width = 640;
    s.camera.height = 360;
    scene::SettingsOverrides o;
    o.shadowMapSize = 256;  // defaults otherwise: half a texel of constant bias, slope bias 1, pcf2x2
    const Renders r = compareRaster(s, o);
    const Metrics& m = r.c.metrics;
    ASSERT_TRUE(m.hasBlockerDistance);
    ASSERT_LT(std::sqrt(2.0) * h, 1.5 * r.texel) << "the curb must be lower than the bias reaches";
    std::size_t strip = 0, stripMissed = 0, elsewhere = 0;
    for (std::size_t i = 0; i < r.c.classes.size(); ++i) {
        if (r.reference.objectId[i] != 1.0f || r.reference.visibility[i] != 0.0f) continue;
        const Vec3 p = floorPoint(s, i);
        if (p.x > -0.1 - h - 0.01 && p.x < -0.1 + 0.01 && std::abs(p.z) < 0.51) {
            ++strip;
            stripMissed += r.c.classes[i] == PixelClass::MissedShadow;
        } else {
            ++elsewhere;
        }
    }
    std::printf(
        "curb h %.3f, texel %.4f: strip %zu px (%zu missed); missed %zu (%zu near an edge), bias leak %zu "
        "(%zu near an edge), aliasing %zu, D %.4f\n",
        h, r.texel, strip, stripMissed, m.missedShadow, m.missedShadowNearEdge, m.biasLeak, m.biasLeakNearEdge,
        m.aliasingPixels, m.contactDistance);
    EXPECT_GT(strip, 100u) << "the camera must see the strip";
    EXPECT_EQ(elsewhere, 0u) << "the reference shadows the strip and nothing else";
    EXPECT_GE(double(stripMissed), 0.9 * double(strip)) << "the bias loses the strip";
    EXPECT_EQ(m.biasLeak, m.missedShadow) << "every blocker within D";
    EXPECT_GE(double(m.missedShadowNearEdge), 0.9 * double(m.missedShadow)) << "a strip narrower than the edge radius";
    EXPECT_EQ(m.biasLeakNearEdge, m.missedShadowNearEdge);
    EXPECT_EQ(m.aliasingPixels, m.falseShadowNearEdge) << "no missed pixel of the strip is aliasing";
    // The findings say so.
    ReportInput in;
    in.sceneName = "curb";
    in.objectNames = {"floor", "curb"};
    in.reference = {"reference", "reference.png", r.reference};
    in.methods.push_back({"raster", "raster.png", "diff-raster.png", r.raster, m});
    const std::string text = describeFindings(in);
    EXPECT_NE(text.find("of it within the contact distance of its blocker"), std::string::npos) << text;
    EXPECT_EQ(text.find("aliasing rather than bias"), std::string::npos) << text;
}

}  // namespace
}  // namespace shadowlab::compare
