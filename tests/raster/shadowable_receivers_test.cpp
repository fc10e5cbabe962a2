// tests/raster/shadowable_receivers_test.cpp: directional maps and cascades fitted to the visible
// receivers some caster can shade (raster/light_frustum.h shadowableReceiverBoxes), against boxes
// and depths derived by hand, and renders of a large ground against the closed form.
#include <gtest/gtest.h>

#include <cmath>
#include <random>

#include "raster/cascades.h"
#include "raster/light_frustum.h"
#include "tests/kit/render_checked.h"
#include "tests/kit/test_scenes.h"

namespace shadowlab::raster {
namespace {

using scene::Vec3;

// The seed scene (sphere r = 1 at (0, 1, 0), light along (−1, −2, −1)) on a 2000 x 2000 ground,
// far plane 3000: the ground reaches far past anything the sphere can shade.
scene::Scene largeGroundSeed(int width = 160, int height = 90) {
    scene::Scene s = test::seedScene({}, width, height);
    s.objects[1].shape = test::quadShape(Vec3(0), Vec3(0, 1, 0), 2000, 2000);
    s.camera.far = 3000;
    return s;
}

const Vec3 kSeedLight = Vec3(-1, -2, -1);

void expectBox(const scene::Bounds& b, const Vec3& lo, const Vec3& hi, double tol) {
    for (int k = 0; k < 3; ++k) {
        EXPECT_NEAR(b.min[k], lo[k], tol) << "min axis " << k;
        EXPECT_NEAR(b.max[k], hi[k], tol) << "max axis " << k;
    }
}

// Scene bounds [−1000, 1000] x [0, 2] x [−1000, 1000], d = (−1, −2, −1)/√6. The sphere's box
// [−1, 1] x [0, 2] x [−1, 1] leaves the scene first through y = 0: t = 2/(2/√6) = √6, an offset
// of (−1, −2, −1), so its sweep is [−2, 1] x [−2, 2] x [−2, 1], and the ground (y = 0) under it is
// [−2, 1] x {0} x [−2, 1]. The ground's own sweep ends at once (t = 0, it lies on the scene's
// bottom face): only its padded plane, which holds the sphere's bottom [−1, 1] x {0} x [−1, 1].
// Neither shape shades itself.
TEST(ShadowableReceivers, SeedOnALargeGroundGivesTheBoxesUnderTheSphereDerivedByHand) {
    const scene::Scene s = largeGroundSeed();
    const std::vector<scene::Bounds> boxes = shadowableReceiverBoxes(s, kSeedLight);
    ASSERT_EQ(boxes.size(), 2u);
    const double pad = 1e-5;  // kShadowSweepPad of the scene's size (a diagonal of 2828): 2.8e-6
    expectBox(boxes[0], Vec3(-1, 0, -1), Vec3(1, 0, 1), pad);
    expectBox(boxes[1], Vec3(-2, 0, -2), Vec3(1, 0, 1), pad);
    // Their view depths: camera at (0, 2, 6) looking at (0, 0.7, 0), forward (0, −1.3, −6)/√37.69;
    // a ground point (x, 0, z) lies at (2.6 + 6·(6 − z))/√37.69: z = 1 gives 32.6/√37.69, z = −2
    // gives 50.6/√37.69; every corner of [−2, 1]² is in view (|x_c| ≤ 2 < 0.647·5.31, the rows
    // within tan 20°).
    const auto range = shadowableDepthRange(s, kSeedLight);
    ASSERT_TRUE(range);
    EXPECT_NEAR((*range)[0], 32.6 / std::sqrt(37.69), pad);
    EXPECT_NEAR((*range)[1], 50.6 / std::sqrt(37.69), pad);
}

scene::Object objectOf(scene::Shape shape) { return {"o", std::move(shape), 0}; }

// A convex shape facing the light is not self-shadowed (and N·L ≤ 0 is unlit without a test); a
// mesh can shade itself, unless all of it lies in one plane.
TEST(ShadowableReceivers, AMeshShadesItselfButAConvexShapeOrAPlanarMeshDoesNot) {
    EXPECT_FALSE(shadesItself(objectOf(scene::Sphere{Vec3(0), 1})));
    EXPECT_FALSE(shadesItself(objectOf(scene::Box{Vec3(0), Vec3(1)})));
    EXPECT_FALSE(shadesItself(objectOf(test::quadShape(Vec3(0), Vec3(0, 1, 0), 2, 2))));
    EXPECT_TRUE(shadesItself(objectOf(scene::Mesh::single("m", test::icosphere(Vec3(0), 1, 1)))));
    auto plane = std::make_shared<scene::TriangleMesh>();
    plane->positions = {{-5, 0, -5}, {5, 0, -5}, {5, 0, 5}, {-5, 0, 5}};
    plane->indices = {0, 1, 2, 0, 2, 3};
    // Tilted and moved, it is still one plane.
    const glm::dmat3 r = test::rotation(Vec3(1, 0, 0), 30.0);
    const scene::Affine tilt(r[0], r[1], r[2], Vec3(3, 7, -2));
    EXPECT_FALSE(shadesItself(objectOf(scene::Mesh::single("plane", plane, tilt))));

    // In a scene, the mesh's own box is then shadowable wherever nothing else is near.
    scene::Scene s = largeGroundSeed();
    s.objects[0].shape = scene::Mesh::single("ico", test::icosphere(Vec3(0, 1, 0), 1, 1));
    const scene::Bounds ico = scene::boundsOf(s.objects[0].shape);
    const std::vector<scene::Bounds> boxes = shadowableReceiverBoxes(s, kSeedLight);
    expectBox(boxes[0], ico.min, ico.max, 1e-9);
}

// The boxes as the header defines them, by testing every receiver against every caster: each
// caster's box swept along the light until it lies past one of the scene's faces, padded, met
// with each other box (its own where shadesItself).
std::vector<scene::Bounds> boxesEveryPair(const scene::Scene& s, const Vec3& direction) {
    const scene::Bounds scene = s.bounds();
    const Vec3 d = glm::normalize(direction);
    const double pad = kShadowSweepPad * std::max(scene.diagonal(), scene.maxAbsCoordinate());
    const std::size_t n = s.objects.size();
    std::vector<scene::Bounds> out(n);
    for (std::size_t j = 0; j < n; ++j) {
        const scene::Bounds b = scene::boundsOf(s.objects[j].shape);
        double t = INFINITY;
        for (int k = 0; k < 3; ++k)
            if (d[k] != 0.0) t = std::min(t, ((d[k] > 0 ? scene.max[k] - b.min[k] : scene.min[k] - b.max[k])) / d[k]);
        t = std::max(t, 0.0);
        scene::Bounds swept{glm::min(b.min, b.min + t * d) - pad, glm::max(b.max, b.max + t * d) + pad};
        for (std::size_t i = 0; i < n; ++i) {
            if (i == j && !shadesItself(s.objects[i])) continue;
            const scene::Bounds r = scene::boundsOf(s.objects[i].shape);
            const scene::Bounds c{glm::max(r.min, swept.min), glm::min(r.max, swept.max)};
            if (glm::all(glm::lessThanEqual(c.min, c.max))) out[i].extend(c);
        }
    }
    return out;
}

// A thousand spheres, boxes and small meshes of sizes over three orders of magnitude, scattered
// over a ground and in the air, under a high and a low light: the tree's query finds the same
// boxes as every pair.
TEST(ShadowableReceivers, ManyObjectsGiveTheSameBoxesAsTestingEveryPair) {
    scene::Scene s = largeGroundSeed();
    s.objects.resize(1);
    s.objects[0].shape = test::quadShape(Vec3(0), Vec3(0, 1, 0), 200, 200);
    std::mt19937 rng(7);
    std::uniform_real_distribution<double> across(-100, 100), up(0, 30), size(-2, 1);
    for (int i = 0; i < 1000; ++i) {
        const Vec3 c(across(rng), up(rng), across(rng));
        const double r = std::pow(10.0, size(rng));
        if (i % 3 == 0)
            s.objects.push_back(objectOf(scene::Sphere{c, r}));
        else if (i % 3 == 1)
            s.objects.push_back(objectOf(scene::Box{c - r, c + Vec3(r, 2 * r, r)}));
        else
            s.objects.push_back(objectOf(scene::Mesh::single("ico", test::icosphere(c, r, 0))));
    }
    for (const Vec3& light : {kSeedLight, Vec3(-1, -0.05, 0.3)}) {
        const std::vector<scene::Bounds> got = shadowableReceiverBoxes(s, light);
        const std::vector<scene::Bounds> want = boxesEveryPair(s, light);
        ASSERT_EQ(got.size(), want.size());
        int shadowable = 0;
        for (std::size_t i = 0; i < got.size(); ++i) {
            ASSERT_EQ(got[i].empty(), want[i].empty()) << "object " << i;
            if (got[i].empty()) continue;
            ++shadowable;
            expectBox(got[i], want[i].min, want[i].max, 1e-12 * 200);
        }
        // Both outcomes occur: some objects are shaded, some stand alone.
        EXPECT_GT(shadowable, 1);
        EXPECT_LT(shadowable, int(got.size()));
    }
}

// The cascades split the shadowable depths 5.31..8.242 (above): with λ = 0.75 the first split is
// 0.75·5.31·(8.242/5.31)^(1/4) + 0.25·(5.31 + 0.733) ≈ 5.956. That slice's sphere (k² = tan²20°·(1 +
// (16/9)²) = 0.5512) has its center at the far end and radius 5.956·√0.5512 ≈ 4.42; with the 1%
// margin and 8 texels a side, 4.50, quantized up to 1/16 of 4: at most 4.75, a texel of at most
// 9.5/2048. Over all visible receivers the first slice starts at 3.52 and ends past 70 (the
// range reaches ~984), and a sphere through a slice is at least half its length across.
TEST(ShadowableReceivers, TheFirstCascadeCoversOnlyTheShadowableDepthsAndIsFiner) {
    const scene::Scene s = largeGroundSeed(1280, 720);
    const CascadeSet set = fitCascades(s, kSeedLight, 4, 2048);
    ASSERT_EQ(set.frusta.size(), 4u);
    EXPECT_NEAR(set.splits.front(), 32.6 / std::sqrt(37.69), 1e-5);  // the pad, as above
    EXPECT_NEAR(set.splits.back(), 50.6 / std::sqrt(37.69), 1e-5);
    EXPECT_NEAR(set.splits[1], 5.956, 2e-3);
    const double texel = set.frusta[0].texelWorldSize();
    EXPECT_LE(texel, 9.5 / 2048 * (1 + 1e-12));
    const auto all = visibleDepthRange(s);
    ASSERT_TRUE(all);
    const double unrestricted = (practicalSplits((*all)[0], (*all)[1], 4)[1] - (*all)[0]) / 2048;
    EXPECT_GT(unrestricted, 4.0 * texel);
}

// With default settings the large-ground seed gets one map fitted to the region under the sphere;
// its floor matches the closed form except at pixels the shadow's outline crosses (the closed
// form differs among the pixel's corners).
TEST(ShadowableReceivers, DefaultRenderOfTheLargeGroundMatchesTheClosedForm) {
    const scene::Scene s = largeGroundSeed();
    const CascadeChoice choice = chooseCascades(s, scene::resolveSettings(s, {}).raster);
    EXPECT_EQ(choice.count, 1) << choice.reason;
    const scene::Frame f = test::renderChecked(s, scene::resolveSettings(s, {}));
    const scene::CameraBasis cam = scene::cameraBasis(s.camera);
    const Vec3 L = -glm::normalize(kSeedLight);
    auto shadowedThrough = [&](double px, double py) {
        const double sx = (2.0 * px / f.width - 1.0) * cam.tanHalfFovY * cam.aspect;
        const double sy = (1.0 - 2.0 * py / f.height) * cam.tanHalfFovY;
        const Vec3 d = cam.forward + sx * cam.right + sy * cam.up;
        const Vec3 q = cam.position + (-cam.position.y / d.y) * d;
        double rel = 0.0;
        return test::rayMeetsSphere(q, L, Vec3(0, 1, 0), 1.0, rel);
    };
    int judged = 0, wrong = 0;
    for (int y = 0; y < f.height; ++y)
        for (int x = 0; x < f.width; ++x) {
            const std::size_t i = std::size_t(y) * std::size_t(f.width) + std::size_t(x);
            if (f.objectId[i] != 2.0f) continue;
            const bool c = shadowedThrough(x + 0.5, y + 0.5);
            if (shadowedThrough(x, y) != c || shadowedThrough(x + 1, y) != c || shadowedThrough(x, y + 1) != c ||
                shadowedThrough(x + 1, y + 1) != c)
                continue;  // the outline crosses this pixel
            ++judged;
            if ((f.visibility[i] < 0.5f) != c) ++wrong;
        }
    EXPECT_GT(judged, 5000);
    EXPECT_EQ(wrong, 0);
}

// A 30 x 30 x 30 box behind the camera (z in 10..40) shades the ground in front of it: from
// q = (1.5, 0, 2) toward the light (1, 2, 1)/√6 the ray reaches z = 10 at (9.5, 16, 10), inside
// the box. Its sweep covers the visible ground there, so the maps reach it.
TEST(ShadowableReceivers, ACasterBehindTheCameraStillShadesTheVisibleGround) {
    scene::Scene s = largeGroundSeed();
    test::addBox(s, Vec3(-15, 0, 10), Vec3(15, 30, 40));
    const Vec3 q(1.5, 0, 2);
    const std::size_t i = test::pixelIndexOf(s, q);
    for (const int cascades : {1, 3}) {
        scene::RenderSettings settings = scene::resolveSettings(s, {});
        if (cascades > 1) settings.raster.cascades = cascades;
        const scene::Frame f = test::renderChecked(s, settings);
        ASSERT_EQ(f.objectId[i], 2.0f);
        EXPECT_EQ(f.visibility[i], 0.0f) << cascades << " cascades";
    }
}

// Ground no caster can shade (outside [−2, 1]², padded by a margin for the filter) is lit with
// visibility exactly 1, in the single fitted map and past the last of 3 cascades' splits alike.
TEST(ShadowableReceivers, GroundOutsideTheShadowableRegionIsExactlyLit) {
    const scene::Scene s = largeGroundSeed();
    for (const int cascades : {1, 3}) {
        scene::RenderSettings settings = scene::resolveSettings(s, {});
        if (cascades > 1) settings.raster.cascades = cascades;
        const scene::Frame f = test::renderChecked(s, settings);
        int outside = 0, notLit = 0;
        test::forEachFloorPixel(
            s, f,
            [&](const Vec3& q, double v) {
                if (q.x >= -2.1 && q.x <= 1.1 && q.z >= -2.1 && q.z <= 1.1) return;
                ++outside;
                if (v != 1.0) ++notLit;
            },
            2.0f);
        EXPECT_GT(outside, 5000);
        EXPECT_EQ(notLit, 0) << cascades << " cascades";
    }
}

}  // namespace
}  // namespace shadowlab::raster
