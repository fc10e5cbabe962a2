// tests/raster/transmittance_test.cpp: semi-transparent casters: the transmittance map
// beside the depth map, against closed forms: each object a shadow ray passes through multiplies
// the light by 1 − opacity once (DESIGN.md), on lavapipe with the validation layer.
// Set SHADOWLAB_TEST_PNG_DIR to also write the beauty images there for a look.
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "raster/renderer.h"
#include "tests/kit/render_checked.h"
#include "tests/kit/test_scenes.h"

namespace shadowlab::raster {
namespace {

using test::Vec3;

scene::Object quadObject(const std::string& name, const Vec3& center, double side, int material) {
    return test::horizontalQuad(name, center, side, side, material);
}

// Light straight down onto the floor y = 0 (20 x 20); a low camera looks at the floor under the
// casters from below their height, so it sees the floor and none of them in front of it.
scene::Scene floorScene() {
    scene::Scene s;
    s.camera = {.position = Vec3(0, 0.5, 6), .lookAt = Vec3(0), .width = 200, .height = 120};  // fov 40°, near 0.1
    test::addMaterial(s, "matte");
    test::addMaterial(s, "glass", 0.5);
    test::addDirectional(s, Vec3(0, -1, 0), 3.0);
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

scene::Frame renderWith(const scene::Scene& s, scene::ShadowFilter filter, const std::string& name,
                        double depthBias = 0.02) {
    scene::RasterSettings r = test::validatedSettings(512, depthBias, 1.0, filter);
    r.pcfSize = 5;
    const scene::Frame f = test::renderChecked(s, r);
    test::writePngToLookAt(f, name);
    return f;
}

const scene::ShadowFilter kFilters[] = {scene::ShadowFilter::None, scene::ShadowFilter::Pcf2x2,
                                        scene::ShadowFilter::Pcf, scene::ShadowFilter::Poisson};

TEST(RasterTransmittance, TwoHalfOpaquePanesLeaveAQuarterBehindBothAndAHalfBehindOne) {
    const scene::Scene s = twoPanes();
    for (const scene::ShadowFilter filter : kFilters) {
        const scene::Frame f = renderWith(s, filter, "transmittance_panes_" + std::to_string(int(filter)));
        EXPECT_EQ(f.attributes.at("transmittance_map"), "made");
        // Away from the panes' outlines (0.15: the texel is ~0.03, pcf 5 reaches 2.5 texels).
        constexpr double m = 0.15;
        int counted[3] = {0, 0, 0}, wrong = 0;
        test::forEachFloorPixel(s, f, [&](const Vec3& q, double v) {
            const bool inZ = std::abs(q.z)<1.5 - m, outZ = std::abs(q.z)> 1.5 + m;
            const bool underA = inZ && q.x > -2 + m && q.x < 1 - m, underB = inZ && q.x > -1 + m && q.x < 2 - m;
            const bool clearA = outZ || q.x < -2 - m || q.x > 1 + m, clearB = outZ || q.x < -1 - m || q.x > 2 + m;
            double expected;
            if (underA && underB)
                expected = 0.25;
            else if ((underA && clearB) || (underB && clearA))
                expected = 0.5;
            else if (clearA && clearB)
                expected = 1.0;
            else
                return;  // near an outline
            ++counted[expected == 0.25 ? 0 : expected == 0.5 ? 1 : 2];
            if (std::abs(v - expected) > 1e-5) ++wrong;
        });
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
                const Vec3 q = test::floorPoint(cam, x, y, 1.0);            // on pane B's plane
                if (std::abs(q.z) > 1.35) continue;
                double expected;
                if (q.x > -0.85 && q.x < 0.85)
                    expected = 0.5;
                else if (q.x > 1.15 && q.x < 1.85)
                    expected = 1.0;
                else
                    continue;
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
                const Vec3 q = test::floorPoint(cam, x, y);
                const double rho = std::hypot(q.x, q.z);  // the shadow is the disk of radius 0.8
                double expected;
                if (rho < 0.6)
                    expected = 0.5;  // (the tessellated outline lies inside the circle)
                else if (rho > 1.0)
                    expected = 1.0;
                else
                    continue;
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
    const scene::Frame f = renderWith(s, scene::ShadowFilter::Pcf2x2, "transmittance_box_over_pane");
    int dark = 0, half = 0, wrong = 0;
    test::forEachFloorPixel(s, f, [&](const Vec3& q, double v) {
        const bool underBox = std::abs(q.x) < 0.3 && std::abs(q.z) < 0.3;
        const bool underPaneOnly =
            std::abs(q.z) < 1.3 && q.x > -1.8 && q.x < 0.8 && (std::abs(q.x) > 0.55 || std::abs(q.z) > 0.55);
        if (underBox) {
            ++dark;
            if (v > 1e-5) ++wrong;
        } else if (underPaneOnly) {
            ++half;
            if (std::abs(v - 0.5) > 1e-5) ++wrong;
        }
    });
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
    for (const scene::ShadowFilter filter : kFilters) {
        const scene::Frame f = renderWith(s, filter, "transmittance_point_" + std::to_string(int(filter)));
        EXPECT_EQ(f.attributes.at("transmittance_map"), "made");
        int inside = 0, outside = 0, wrong = 0;
        test::forEachFloorPixel(s, f, [&](const Vec3& q, double v) {
            const double m = std::max(std::abs(q.x), std::abs(q.z));
            double expected;
            if (m < 1.8)
                expected = 0.5;
            else if (m > 2.2 && m < 6.0)
                expected = 1.0;
            else
                return;
            ++(expected == 0.5 ? inside : outside);
            if (std::abs(v - expected) > 1e-5) ++wrong;
        });
        EXPECT_GT(inside, 200) << "filter " << int(filter);
        EXPECT_GT(outside, 200) << "filter " << int(filter);
        EXPECT_EQ(wrong, 0) << "filter " << int(filter);
    }
}

// The repro of the transmittance map's first limit, light straight down: a 3 x 3 pane
// of opacity 0.5 at height 5, a glass sphere (opacity 0.5, radius 1) at height 2.5, another 3 x 3
// pane of 0.5 at height 0.8, over the floor. Objects: floor 1, top pane 2, sphere 3, low pane 4.
scene::Scene paneSpherePane() {
    scene::Scene s = floorScene();
    s.objects.push_back(quadObject("top pane", Vec3(0, 5, 0), 3.0, 1));
    scene::Object sphere;
    sphere.name = "middle glass";
    sphere.shape = scene::Sphere{Vec3(0, 2.5, 0), 1.0};
    sphere.material = 1;
    s.objects.push_back(sphere);
    s.objects.push_back(quadObject("low pane", Vec3(0, 0.8, 0), 3.0, 1));
    return s;
}

TEST(RasterTransmittance, AGlassSphereBetweenTwoPanesGetsOnlyTheUpperPanesFactor) {
    // The sphere's lit top lies behind the top pane only: 0.5. Its texels hold T_all = 0.125
    // (pane, sphere, pane), D1 the top pane, and behind that T_rest = 0.25 with D2 the sphere's
    // top itself, so T_all / T_rest = 0.5 (the first version divided T_all by the sphere's own 0.5
    // and gave 0.25). Seen from (0, 4, 9), below the top pane, as the repro's camera.
    scene::Scene s = paneSpherePane();
    s.camera.position = Vec3(0, 4, 9);
    s.camera.lookAt = Vec3(0, 2, 0);
    // Counted: the pixels that the same scene with an opaque sphere gives exactly the top pane's
    // 0.5 (its lit side away from the few tessellation-shadowed pixels near its outline).
    scene::Scene opaque = s;
    scene::Material solid = s.materials[1];
    solid.name = "solid glass";
    solid.opacity = 1.0;
    opaque.materials.push_back(solid);
    opaque.objects[2].material = 2;
    for (const scene::ShadowFilter filter : kFilters) {
        const scene::Frame f = renderWith(s, filter, "transmittance_between_" + std::to_string(int(filter)));
        const scene::Frame o = renderWith(opaque, filter, "transmittance_between_opaque");
        EXPECT_EQ(f.attributes.at("transmittance_map"), "made");
        int top = 0, wrong = 0;
        for (std::size_t i = 0; i < f.visibility.size(); ++i) {
            if (f.objectId[i] != 3.0f || f.ndotl[i] <= 0.2f || o.visibility[i] != 0.5f) continue;
            ++top;
            if (std::abs(f.visibility[i] - 0.5) > 1e-5) ++wrong;
        }
        EXPECT_GT(top, 300) << "filter " << int(filter);
        EXPECT_EQ(wrong, 0) << "filter " << int(filter);
    }
}

TEST(RasterTransmittance, TheFloorUnderPaneSpherePaneGetsEveryFactorOnce) {
    // The floor (seen from below the low pane): under all three 0.5³ = 0.125 (the sphere's shadow
    // is the unit disk: its tessellated outline lies inside, so ρ < 0.8), under the two panes only
    // 0.25 (|x|, |z| < 1.5, outside the disk), 1 beyond the panes.
    const scene::Scene s = paneSpherePane();
    for (const scene::ShadowFilter filter : kFilters) {
        const scene::Frame f = renderWith(s, filter, "transmittance_between_floor_" + std::to_string(int(filter)));
        // Away from outlines by the widest kernel's reach: Poisson's 2.4 texels plus half a texel
        // (nearest), 3 texels of 29.0 / 512 (the scene's bounding sphere, radius 14.36, × 1.01) = 0.17.
        constexpr double m = 0.2;
        int counted[3] = {0, 0, 0}, wrong = 0;
        test::forEachFloorPixel(s, f, [&](const Vec3& q, double v) {
            const double rho = std::hypot(q.x, q.z);
            const double box = std::max(std::abs(q.x), std::abs(q.z));
            double expected;
            if (rho < 0.8)
                expected = 0.125;
            else if (rho > 1.0 + m && box < 1.5 - m)
                expected = 0.25;
            else if (box > 1.5 + m)
                expected = 1.0;
            else
                return;
            ++counted[expected == 0.125 ? 0 : expected == 0.25 ? 1 : 2];
            if (std::abs(v - expected) > 1e-5) ++wrong;
        });
        EXPECT_GT(counted[0], 100) << "filter " << int(filter);
        EXPECT_GT(counted[1], 100) << "filter " << int(filter);
        EXPECT_GT(counted[2], 200) << "filter " << int(filter);
        EXPECT_EQ(wrong, 0) << "filter " << int(filter);
    }
}

// Four stacked 3 x 3 panes, light straight down: A at height 4 (opacity 0.2, 1 − opacity 0.8),
// B at 3 (0.5), C at 2 (0.4, 1 − opacity 0.6), D at 1 (0.5). Objects: floor 1, A 2, B 3, C 4, D 5.
scene::Scene fourPanes() {
    scene::Scene s = floorScene();
    const double opacities[] = {0.2, 0.5, 0.4, 0.5};
    for (int k = 0; k < 4; ++k) {
        scene::Material m;
        m.name = std::string("glass ") + char('A' + k);
        m.opacity = opacities[k];
        s.materials.push_back(m);
        s.objects.push_back(
            quadObject(std::string(1, char('A' + k)), Vec3(0, 4 - k, 0), 3.0, int(s.materials.size()) - 1));
    }
    return s;
}

// Every lit pixel of the top of the horizontal quad `object` at `height`, |x|, |z| < 1.35 (away
// from its outline), seen from just above it, has visibility `expected` (to 1e-5).
void expectPaneTop(const scene::Scene& base, float object, double height, scene::ShadowFilter filter, double expected,
                   const std::string& name) {
    scene::Scene s = base;
    s.camera.position = Vec3(0, height + 0.5, 6);
    s.camera.lookAt = Vec3(0, height, 0);
    const scene::CameraBasis cam = scene::cameraBasis(s.camera);
    const scene::Frame f = renderWith(s, filter, name + "_" + std::to_string(int(filter)));
    int counted = 0, wrong = 0;
    for (int y = 0; y < f.height; ++y)
        for (int x = 0; x < f.width; ++x) {
            const std::size_t i = std::size_t(y) * std::size_t(f.width) + std::size_t(x);
            if (f.objectId[i] != object || f.ndotl[i] <= 0.0f) continue;
            const Vec3 q = test::floorPoint(cam, x, y, height);
            if (std::max(std::abs(q.x), std::abs(q.z)) > 1.35) continue;
            ++counted;
            if (std::abs(f.visibility[i] - expected) > 1e-5) ++wrong;
        }
    EXPECT_GT(counted, 150) << name << " filter " << int(filter);
    EXPECT_EQ(wrong, 0) << name << " filter " << int(filter);
}

TEST(RasterTransmittance, FourLayersTheThirdAlsoGetsTheFourthsFactorTheKnownLimit) {
    // Per texel: T_all = 0.8·0.5·0.6·0.5 = 0.12, D1 = A; behind A, T_rest = 0.5·0.6·0.5 = 0.15,
    // D2 = B. Two layers are kept, so:
    // - B (second layer, ref <= D2): T_all / T_rest = 0.8, exact;
    // - C (third, ref > D2): T_all / (1 − opacity of C) = 0.12 / 0.6 = 0.2, where the ray tracer
    //   gives 0.8·0.5 = 0.4: it also gets D's 0.5, the factor of the layer behind it (the limit);
    // - D (fourth, the deepest): 0.12 / 0.5 = 0.24 = 0.8·0.5·0.6, exact; the floor 0.12.
    const scene::Scene s = fourPanes();
    for (const scene::ShadowFilter filter : kFilters) expectPaneTop(s, 4.0f, 2.0, filter, 0.2, "transmittance_four_C");
    expectPaneTop(s, 3.0f, 3.0, scene::ShadowFilter::Pcf2x2, 0.8, "transmittance_four_B");
    expectPaneTop(s, 5.0f, 1.0, scene::ShadowFilter::Pcf2x2, 0.24, "transmittance_four_D");
    expectPaneTop(s, 1.0f, 0.0, scene::ShadowFilter::Pcf2x2, 0.12, "transmittance_four_floor");
}

TEST(RasterTransmittance, MapsDrawnOnlyInTheCastersWindowsGiveTheFramesOfWholeMaps) {
    // Each layer's transmittance maps are drawn and cleared only in the window the semi-transparent
    // casters project to, and lit.frag takes texels outside it as "nothing semi-transparent": the
    // frames must be those of maps drawn whole, bit for bit, under a spot and a
    // point light (whose cube faces hold the casters in some faces, part of them in others, none
    // in the rest), two glass layers (pane, sphere, pane) and an opaque caster, also after the
    // lights move (the windows follow them).
    scene::Scene s = paneSpherePane();
    s.objects.push_back(quadObject("opaque", Vec3(2.5, 1.5, 1.0), 1.0, 0));
    s.lights[0].type = scene::LightType::Point;
    s.lights[0].position = Vec3(0.5, 7, 0.5);
    s.lights[0].intensity = 300.0;
    s.lights[0].radius = 0.3;
    scene::Light spot;
    spot.type = scene::LightType::Spot;
    spot.position = Vec3(-4, 6, 3);
    spot.direction = glm::normalize(Vec3(4, -6, -3));
    spot.coneAngleDegrees = 35.0;
    spot.intensity = 300.0;
    spot.radius = 0.2;
    s.lights.push_back(spot);
    s.camera.position = Vec3(0, 3, 8);
    // The three ways lit.frag reads the maps: one tap (none; pcf, poisson and the filterable maps
    // take the same), the gather of pcf2x2, and PCSS's blocker search over the nearest depths.
    for (const scene::ShadowFilter filter :
         {scene::ShadowFilter::None, scene::ShadowFilter::Pcf2x2, scene::ShadowFilter::Pcss}) {
        scene::RasterSettings r = test::validatedSettings(512, 0.02, 1.0, filter);
        Renderer windowed(s, test::planFor(s, r), r);
        Renderer whole(s, test::planFor(s, r), r, RendererOptions{.transmittanceWindows = false});
        scene::Scene moved = s;
        moved.lights[0].position += Vec3(1.0, -1.0, 0.5);
        moved.lights[1].position += Vec3(0.5, 0.5, -0.5);
        for (int frame = 0; frame < 2; ++frame) {
            if (frame == 1) {
                windowed.update(moved);
                whole.update(moved);
            }
            const scene::Frame a = windowed.render();
            const scene::Frame b = whole.render();
            const std::string windows = a.attributes.at("transmittance_windows");
            // Both kinds of layer are there: with no window (a face seeing no glass) and with one
            // smaller than the map.
            EXPECT_NE(windows.find("none"), std::string::npos) << windows;
            EXPECT_NE(windows.find(','), std::string::npos) << windows;
            EXPECT_EQ(windows.find("0,0,512,512"), std::string::npos) << windows;
            EXPECT_EQ(a.beauty, b.beauty) << "filter " << int(filter) << " frame " << frame;
            EXPECT_EQ(a.visibility, b.visibility) << "filter " << int(filter) << " frame " << frame;
            EXPECT_EQ(a.lightVisibility, b.lightVisibility) << "filter " << int(filter) << " frame " << frame;
            EXPECT_EQ(a.blockerId, b.blockerId) << "filter " << int(filter) << " frame " << frame;
            // The glass does shadow: some floor pixel gets a factor strictly between 0 and 1.
            EXPECT_TRUE(
                std::any_of(a.visibility.begin(), a.visibility.end(), [](float v) { return v > 0.05f && v < 0.95f; }));
        }
        EXPECT_EQ(windowed.validationMessages(), 0);
        EXPECT_EQ(whole.validationMessages(), 0);
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
