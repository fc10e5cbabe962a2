// tests/raster/transmittance_test.cpp: semi-transparent casters (issue 5): the transmittance map
// beside the depth map, against closed forms: each object a shadow ray passes through multiplies
// the light by 1 − opacity once (DESIGN.md), on lavapipe with the validation layer.
// Set SHADOWLAB_TEST_PNG_DIR to also write the beauty images there for a look.
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "raster/renderer.h"
#include "scene/frame_io.h"
#include "tests/raster/test_scenes.h"

namespace shadowlab::raster {
namespace {

using test::Vec3;

scene::Object quadObject(const std::string& name, const Vec3& center, double side, int material) {
    scene::Quad q;
    q.center = center;
    q.normal = Vec3(0, 1, 0);
    q.size = scene::Vec2(side, side);
    scene::quadAxes(q.normal, q.uAxis, q.vAxis);
    scene::Object o;
    o.name = name;
    o.shape = q;
    o.material = material;
    return o;
}

// Light straight down onto the floor y = 0 (20 x 20); a low camera looks at the floor under the
// casters from below their height, so it sees the floor and none of them in front of it.
scene::Scene floorScene() {
    scene::Scene s;
    s.camera.position = Vec3(0, 0.5, 6);
    s.camera.lookAt = Vec3(0, 0, 0);
    s.camera.up = Vec3(0, 1, 0);
    s.camera.fovYDegrees = 40.0;
    s.camera.width = 200;
    s.camera.height = 120;
    s.camera.near = 0.1;
    s.camera.far = 100.0;
    scene::Material matte;
    matte.name = "matte";
    s.materials.push_back(matte);
    scene::Material glass;
    glass.name = "glass";
    glass.opacity = 0.5;
    s.materials.push_back(glass);
    scene::Light l;
    l.type = scene::LightType::Directional;
    l.direction = Vec3(0, -1, 0);
    l.intensity = 3.0;
    s.lights.push_back(l);
    s.objects.push_back(quadObject("floor", Vec3(0, 0, 0), 20.0, 0));
    return s;
}

// Pane A (x in [-2, 1]) at height 2 and pane B (x in [-1, 2]) at height 1, both z in [-1.5, 1.5]
// and opacity 0.5: the floor gets 0.5 under one, 0.25 under both, 1 elsewhere.
scene::Scene twoPanes() {
    scene::Scene s = floorScene();
    s.objects.push_back(quadObject("A", Vec3(-0.5, 2, 0), 3.0, 1));
    s.objects.push_back(quadObject("B", Vec3(0.5, 1, 0), 3.0, 1));
    return s;
}

// Where camera pixel (x, y) meets the floor.
Vec3 floorPoint(const scene::CameraBasis& cam, int x, int y) {
    const Vec3 d = test::pixelRay(cam, x, y);
    return cam.position + (-cam.position.y / d.y) * d;
}

scene::Frame renderWith(const scene::Scene& s, scene::ShadowFilter filter, const std::string& name,
                        double depthBias = 0.02) {
    scene::RasterSettings r = test::validatedSettings(512, depthBias, 1.0, filter);
    r.pcfSize = 5;
    const scene::Frame f = render(s, test::planFor(s, r), r);
    EXPECT_EQ(f.attributes.at("validation_messages"), "0") << "validation messages were printed above";
    if (const char* dir = std::getenv("SHADOWLAB_TEST_PNG_DIR"))
        scene::writePngLinear(std::filesystem::path(dir) / (name + ".png"), f.width, f.height, f.beauty);
    return f;
}

const scene::ShadowFilter kFilters[] = {scene::ShadowFilter::None, scene::ShadowFilter::Pcf2x2,
                                        scene::ShadowFilter::Pcf, scene::ShadowFilter::Poisson};

TEST(RasterTransmittance, TwoHalfOpaquePanesLeaveAQuarterBehindBothAndAHalfBehindOne) {
    const scene::Scene s = twoPanes();
    const scene::CameraBasis cam = scene::cameraBasis(s.camera);
    for (const scene::ShadowFilter filter : kFilters) {
        const scene::Frame f = renderWith(s, filter, "transmittance_panes_" + std::to_string(int(filter)));
        EXPECT_EQ(f.attributes.at("transmittance_map"), "made");
        // Away from the panes' outlines (0.15: the texel is ~0.03, pcf 5 reaches 2.5 texels).
        constexpr double m = 0.15;
        int counted[3] = {0, 0, 0}, wrong = 0;
        for (int y = 0; y < f.height; ++y)
            for (int x = 0; x < f.width; ++x) {
                const std::size_t i = std::size_t(y) * std::size_t(f.width) + std::size_t(x);
                if (f.objectId[i] != 1.0f) continue;  // the floor
                const Vec3 q = floorPoint(cam, x, y);
                const bool inZ = std::abs(q.z) < 1.5 - m, outZ = std::abs(q.z) > 1.5 + m;
                const bool underA = inZ && q.x > -2 + m && q.x < 1 - m, underB = inZ && q.x > -1 + m && q.x < 2 - m;
                const bool clearA = outZ || q.x < -2 - m || q.x > 1 + m, clearB = outZ || q.x < -1 - m || q.x > 2 + m;
                double expected;
                if (underA && underB) expected = 0.25;
                else if ((underA && clearB) || (underB && clearA)) expected = 0.5;
                else if (clearA && clearB) expected = 1.0;
                else continue;  // near an outline
                ++counted[expected == 0.25 ? 0 : expected == 0.5 ? 1 : 2];
                if (std::abs(f.visibility[i] - expected) > 1e-5) ++wrong;
            }
        EXPECT_GT(counted[0], 200) << "filter " << int(filter);
        EXPECT_GT(counted[1], 200) << "filter " << int(filter);
        EXPECT_GT(counted[2], 200) << "filter " << int(filter);
        EXPECT_EQ(wrong, 0) << "filter " << int(filter);
    }
}

TEST(RasterTransmittance, ALowerPaneGetsTheUpperPanesShadowNotItsOwn) {
    // Seen from between the panes' heights: pane B's top under pane A gets 0.5 (A only; B's own
    // 1 − opacity is in the map's product and divided out), B beyond A gets 1.
    scene::Scene s = twoPanes();
    s.camera.position = Vec3(0, 1.5, 6);
    s.camera.lookAt = Vec3(0, 1, 0);
    const scene::CameraBasis cam = scene::cameraBasis(s.camera);
    for (const scene::ShadowFilter filter : kFilters) {
        const scene::Frame f = renderWith(s, filter, "transmittance_lower_pane_" + std::to_string(int(filter)));
        int under = 0, beyond = 0, wrong = 0;
        for (int y = 0; y < f.height; ++y)
            for (int x = 0; x < f.width; ++x) {
                const std::size_t i = std::size_t(y) * std::size_t(f.width) + std::size_t(x);
                if (f.objectId[i] != 3.0f || f.ndotl[i] <= 0.0f) continue;  // pane B's top
                const Vec3 d = test::pixelRay(cam, x, y);
                const Vec3 q = cam.position + ((1.0 - cam.position.y) / d.y) * d;
                if (std::abs(q.z) > 1.35) continue;
                double expected;
                if (q.x > -0.85 && q.x < 0.85) expected = 0.5;
                else if (q.x > 1.15 && q.x < 1.85) expected = 1.0;
                else continue;
                ++(expected == 0.5 ? under : beyond);
                if (std::abs(f.visibility[i] - expected) > 1e-5) ++wrong;
            }
        EXPECT_GT(under, 100) << "filter " << int(filter);
        EXPECT_GT(beyond, 30) << "filter " << int(filter);
        EXPECT_EQ(wrong, 0) << "filter " << int(filter);
    }
}

TEST(RasterTransmittance, AClosedSphereAttenuatesOnceNotOncePerSurface) {
    // A sphere of opacity 0.5: a ray from the light crosses its surface twice, and it must
    // multiply the light by 0.5 once (0.25 would be each surface counted).
    scene::Scene s = floorScene();
    scene::Object sphere;
    sphere.name = "glass sphere";
    sphere.shape = scene::Sphere{Vec3(0, 1.5, 0), 0.8};
    sphere.material = 1;
    s.objects.push_back(sphere);
    const scene::CameraBasis cam = scene::cameraBasis(s.camera);
    for (const scene::ShadowFilter filter : kFilters) {
        const scene::Frame f = renderWith(s, filter, "transmittance_sphere_" + std::to_string(int(filter)));
        // The same sphere opaque: four of its lit pixels near the top are shadowed there (the
        // camera sees the inside of the far side through the tessellation there, under the
        // near side); the glass sphere must darken no other lit pixel of its own.
        scene::Scene opaque = s;
        opaque.materials[1].opacity = 1.0;
        const scene::Frame o = renderWith(opaque, filter, "transmittance_sphere_opaque");
        int inside = 0, outside = 0, wrong = 0, litSphere = 0, darkSphere = 0;
        for (int y = 0; y < f.height; ++y)
            for (int x = 0; x < f.width; ++x) {
                const std::size_t i = std::size_t(y) * std::size_t(f.width) + std::size_t(x);
                if (f.objectId[i] == 2.0f && f.ndotl[i] > 0.3f && o.visibility[i] == 1.0f) {
                    // The sphere's own lit side is not shadowed by itself.
                    ++litSphere;
                    if (f.visibility[i] < 0.999f) {
                        ++darkSphere;
                    }
                }
                if (f.objectId[i] != 1.0f) continue;
                const Vec3 q = floorPoint(cam, x, y);
                const double rho = std::hypot(q.x, q.z);  // the shadow is the disk of radius 0.8
                double expected;
                if (rho < 0.6) expected = 0.5;  // (the tessellated outline lies inside the circle)
                else if (rho > 1.0) expected = 1.0;
                else continue;
                ++(expected == 0.5 ? inside : outside);
                if (std::abs(f.visibility[i] - expected) > 1e-5) {
                    ++wrong;
                }
            }
        EXPECT_GT(inside, 50) << "filter " << int(filter);
        EXPECT_GT(outside, 200) << "filter " << int(filter);
        EXPECT_EQ(wrong, 0) << "filter " << int(filter);
        EXPECT_GT(litSphere, 100) << "filter " << int(filter);
        EXPECT_EQ(darkSphere, 0) << "filter " << int(filter);
    }
}

TEST(RasterTransmittance, OpaqueAndSemiTransparentCastersCombine) {
    // An opaque box above pane A (x in [-2, 1], z in [-1.5, 1.5], opacity 0.5): the floor under
    // the box is dark (0), under the pane alone 0.5. The pane lies behind the box toward the
    // light; where the box covers it the transmittance pass depth-tests it away.
    scene::Scene s = floorScene();
    s.objects.push_back(quadObject("A", Vec3(-0.5, 1, 0), 3.0, 1));
    scene::Object box;
    box.name = "box";
    box.shape = scene::Box{Vec3(-0.4, 2, -0.4), Vec3(0.4, 2.4, 0.4)};
    s.objects.push_back(box);
    const scene::CameraBasis cam = scene::cameraBasis(s.camera);
    const scene::Frame f = renderWith(s, scene::ShadowFilter::Pcf2x2, "transmittance_box_over_pane");
    int dark = 0, half = 0, wrong = 0;
    for (int y = 0; y < f.height; ++y)
        for (int x = 0; x < f.width; ++x) {
            const std::size_t i = std::size_t(y) * std::size_t(f.width) + std::size_t(x);
            if (f.objectId[i] != 1.0f) continue;
            const Vec3 q = floorPoint(cam, x, y);
            const bool underBox = std::abs(q.x) < 0.3 && std::abs(q.z) < 0.3;
            const bool underPaneOnly = std::abs(q.z) < 1.3 && q.x > -1.8 && q.x < 0.8 &&
                                       (std::abs(q.x) > 0.55 || std::abs(q.z) > 0.55);
            if (underBox) {
                ++dark;
                if (f.visibility[i] > 1e-5) ++wrong;
            } else if (underPaneOnly) {
                ++half;
                if (std::abs(f.visibility[i] - 0.5) > 1e-5) ++wrong;
            }
        }
    EXPECT_GT(dark, 20);
    EXPECT_GT(half, 200);
    EXPECT_EQ(wrong, 0);
}

TEST(RasterTransmittance, ACasterOfOpacityZeroChangesNoPixel) {
    // The transmittance path multiplies by exactly 1 where nothing attenuates: an opacity-0 quad
    // hidden inside an opaque sphere (inside the scene bounds, so every map stays the same) turns
    // the transmittance map on and changes no pixel of the sphere-over-plane render.
    test::SphereOverPlane p;
    p.lightDirection = Vec3(-1, -2, -1);
    scene::Scene opaque = test::makeScene(p);
    scene::Scene with = opaque;
    scene::Material clear;
    clear.name = "clear";
    clear.opacity = 0.0;
    with.materials.push_back(clear);
    with.objects.push_back(quadObject("hidden", p.center, 0.5 * p.radius, 1));
    for (const scene::ShadowFilter filter : kFilters) {
        const scene::Frame a = renderWith(opaque, filter, "transmittance_off");
        const scene::Frame b = renderWith(with, filter, "transmittance_on");
        EXPECT_EQ(a.attributes.at("transmittance_map"), "none");
        EXPECT_EQ(b.attributes.at("transmittance_map"), "made");
        EXPECT_EQ(a.visibility, b.visibility) << "filter " << int(filter);
        EXPECT_EQ(a.beauty, b.beauty) << "filter " << int(filter);
    }
}

TEST(RasterTransmittance, APointLightsCubeFacesCarryTheTransmittanceToo) {
    // A point light 4 above the floor and a 0.5 pane 2 x 2 at height 2: the pane's shadow is the
    // pane scaled by 4 / (4 − 2) = 2, |x|, |z| < 2 on the floor (in the −Y face; the wider floor
    // in the side faces, lit), 0.5 inside and 1 outside.
    scene::Scene s = floorScene();
    s.lights[0].type = scene::LightType::Point;
    s.lights[0].position = Vec3(0, 4, 0);
    s.lights[0].intensity = 200.0;
    s.objects.push_back(quadObject("pane", Vec3(0, 2, 0), 2.0, 1));
    s.camera.position = Vec3(0, 1.5, 7);
    const scene::CameraBasis cam = scene::cameraBasis(s.camera);
    for (const scene::ShadowFilter filter : kFilters) {
        const scene::Frame f = renderWith(s, filter, "transmittance_point_" + std::to_string(int(filter)));
        EXPECT_EQ(f.attributes.at("transmittance_map"), "made");
        int inside = 0, outside = 0, wrong = 0;
        for (int y = 0; y < f.height; ++y)
            for (int x = 0; x < f.width; ++x) {
                const std::size_t i = std::size_t(y) * std::size_t(f.width) + std::size_t(x);
                if (f.objectId[i] != 1.0f) continue;
                const Vec3 q = floorPoint(cam, x, y);
                const double m = std::max(std::abs(q.x), std::abs(q.z));
                double expected;
                if (m < 1.8) expected = 0.5;
                else if (m > 2.2 && m < 6.0) expected = 1.0;
                else continue;
                ++(expected == 0.5 ? inside : outside);
                if (std::abs(f.visibility[i] - expected) > 1e-5) ++wrong;
            }
        EXPECT_GT(inside, 200) << "filter " << int(filter);
        EXPECT_GT(outside, 200) << "filter " << int(filter);
        EXPECT_EQ(wrong, 0) << "filter " << int(filter);
    }
}

TEST(RasterTransmittance, ExplainSaysWhetherTheMapIsMade) {
    const scene::RasterSettings r = test::validatedSettings(256, 0.02, 1.0, scene::ShadowFilter::Pcf2x2);
    const std::string withPanes = test::planFor(twoPanes(), r).explain();
    const std::string opaque = test::planFor(floorScene(), r).explain();
    EXPECT_NE(withPanes.find("transmittance map: needed"), std::string::npos) << withPanes;
    EXPECT_NE(opaque.find("transmittance map: not needed"), std::string::npos) << opaque;
}

}  // namespace
}  // namespace shadowlab::raster
