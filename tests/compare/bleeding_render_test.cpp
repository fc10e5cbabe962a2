// tests/compare/bleeding_render_test.cpp: light bleeding told from bias leaks on real renders
// (lavapipe with the validation layer, against the double-precision reference and its blocker
// distances): two casters at different heights under VSM bleed where the upper one's edge
// crosses the lower one's shadow, EVSM4 bleeds less there, and a box's contact leak under a large
// constant bias is a bias leak, not bleeding.
#include <cmath>
#include <cstdio>

#include <gtest/gtest.h>

#include "compare/compare.h"
#include "compare/thresholds.h"
#include "raster/renderer.h"
#include "raytrace/renderer.h"
#include "scene/camera.h"

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
    settings.raster.validate = true;
    const scene::RenderPlan plan = scene::makeRenderPlan(s, settings);
    raster::RenderDebug debug;
    Renders r;
    r.raster = raster::render(s, plan, settings.raster, scene::kAllChannels, &debug);
    EXPECT_EQ(r.raster.attributes.at("validation_messages"), "0") << "validation messages were printed above";
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
    const scene::Scene s = lit({horizontal("A", Vec3(0.4, 1, 0), 0.8, 4.0), horizontal("B", Vec3(5.2, 8, 0), 4.4, 4.0)},
                               Vec3(-0.6, 0, 0));
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
    std::printf("vsm: missed %zu, bleeding %zu, bias leak %zu, far-blocker missed on the floor %zu (%zu between x -0.62 and -0.2), D %.4f\n",
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

TEST(BleedingAgainstReference, AContactLeakUnderALargeConstantBiasIsABiasLeak) {
    // A unit box on the floor. A floor point (x, 0, z) with x in −1.5..−0.5 and |z| < 0.5 is
    // shadowed by the box's face x = −0.5, d = √2·(−0.5 − x) away along the ray to the light
    // (light at 45°). A constant bias b = 0.3 compares the receiver b nearer the light than it
    // is, so the map lets light through where d < b: the band x in (−0.5 − b/√2, −0.5) =
    // (−0.712, −0.5) leaks, the rest of the shadow stays. The face's depth varies by a texel per
    // texel here (45°), so nearest texel and the 2x2 filter blur that edge by up to 2 texels of
    // depth each side: δ = 2·√2·texel along the ray. Every leak lies within the contact distance
    // D = b + 4 texels (compare/thresholds.h; tanθ = 1), so none of it may be read as light bleeding.
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
    const double b = 0.3, delta = 2.0 * std::sqrt(2.0) * r.texel;
    std::size_t band = 0, bandLit = 0, rest = 0, restShadowed = 0;
    for (std::size_t i = 0; i < r.c.classes.size(); ++i) {
        if (r.reference.objectId[i] != 1.0f) continue;
        const Vec3 p = floorPoint(s, i);
        if (std::abs(p.z) > 0.45 || p.x > -0.5 - delta || p.x < -1.5 + delta) continue;  // clear of the side faces
        const double d = std::sqrt(2.0) * (-0.5 - p.x);
        ASSERT_EQ(r.reference.visibility[i], 0.0f) << "the reference shadows the whole box shadow, at x " << p.x;
        if (d < b - delta) {
            ++band;
            bandLit += r.raster.visibility[i] == 1.0f;
        } else if (d > b + delta) {
            ++rest;
            restShadowed += r.raster.visibility[i] == 0.0f;
        }
    }
    std::printf("pcf2x2, bias 0.3: band %zu (%zu lit), rest %zu (%zu shadowed); missed %zu, bleeding %zu, bias leak %zu, "
                "D %.4f, texel %.4f\n",
                band, bandLit, rest, restShadowed, m.missedShadow, m.bleeding, m.biasLeak, m.contactDistance, r.texel);
    EXPECT_GT(band, 200u) << "the camera must see the band";
    EXPECT_EQ(bandLit, band) << "the bias lets light through wherever the face is nearer than b";
    EXPECT_GT(rest, 1000u);
    EXPECT_EQ(restShadowed, rest) << "and nowhere else";
    EXPECT_NEAR(m.contactDistance, b + kContactTexels * r.texel, 1e-3 * r.texel);  // its value for N·L = 1
    EXPECT_GT(m.biasLeak, 0u);
    EXPECT_EQ(m.bleeding, 0u);
}

}  // namespace
}  // namespace shadowlab::compare
