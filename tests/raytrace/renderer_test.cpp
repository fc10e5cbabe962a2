// tests/raytrace/renderer_test.cpp: whole frames against closed-form answers: the reference is
// exact on sphere-over-plane, the float method with no bias shows acne, a huge bias lifts the
// contact shadow, any-hit and closest-hit shadow rays agree, AOVs and metadata are filled.
#include "raytrace/renderer.h"

#include <algorithm>
#include <cmath>

#include <gtest/gtest.h>

#include "scene/settings.h"
#include "tests/kit/test_scenes.h"

namespace shadowlab::raytrace {
namespace {

using test::Analytic;
using test::Vec3;

TEST(ReferenceRender, SeedSceneVisibilityEqualsClosedFormAwayFromShadowEdge) {
    const scene::Scene s = test::seedScene();
    const scene::Frame f = renderReference(s, test::planFor(s), test::biasSettings(0, scene::Precision::Float));
    ASSERT_EQ(f.width, 160);
    ASSERT_EQ(f.height, 90);
    int judged = 0, shadowed = 0, wrong = 0, skipped = 0;
    for (int y = 0; y < f.height; ++y) {
        for (int x = 0; x < f.width; ++x) {
            const std::size_t i = std::size_t(y) * f.width + x;
            const Analytic a = test::analyticPixel(s, {}, x, y);
            if (a.nearEdge) {
                ++skipped;
                continue;
            }
            const int expectedId = a.kind == Analytic::Background ? 0 : (a.kind == Analytic::Sphere ? 1 : 2);
            ASSERT_EQ(int(f.objectId[i]), expectedId) << "pixel " << x << "," << y;
            if (a.kind == Analytic::Background) continue;
            ++judged;
            if (!a.lit) ++shadowed;
            const float expected = a.lit ? 1.0f : 0.0f;
            if (f.visibility[i] != expected) {
                ++wrong;
                ADD_FAILURE() << "pixel " << x << "," << y << " visibility " << f.visibility[i] << " expected "
                              << expected;
                if (wrong > 10) return;
            }
        }
    }
    // The scene must exercise both answers, and the margin must skip only a thin edge.
    EXPECT_GT(shadowed, 200);
    EXPECT_GT(judged - shadowed, 5000);
    EXPECT_LT(skipped, 50);
    EXPECT_EQ(f.attributes.at("backend"), "reference");
    EXPECT_EQ(f.attributes.at("precision"), "double");
    EXPECT_EQ(f.attributes.at("ray_bias"), "robust");
}

TEST(ReferenceRender, TwoLightsKeepEachLightsVisibilityAndCombineThem) {
    // The seed scene plus light B along (1, -1, 0) (intensity 1). On the plane (N = +Y), light
    // i's visibility is 1 where the ray toward it misses the sphere (closed form), else 0; the
    // total is (w_A v_A + w_B v_B) / (w_A + w_B), w = intensity·N·L: w_A = 3·2/√6, w_B = 1/√2.
    scene::Scene s = test::seedScene();
    test::addDirectional(s, Vec3(1, -1, 0), 1.0);
    const scene::Frame f = renderReference(s, test::planFor(s), test::biasSettings(0, scene::Precision::Float));
    ASSERT_EQ(f.lightVisibility.size(), 2u);
    const Vec3 lB = glm::normalize(Vec3(-1, 1, 0));
    const double wA = 3.0 * 2.0 / std::sqrt(6.0), wB = lB.y;
    int judged = 0, shadowed[2] = {0, 0};
    for (int y = 0; y < f.height; ++y)
        for (int x = 0; x < f.width; ++x) {
            const std::size_t i = std::size_t(y) * f.width + x;
            const Analytic a = test::analyticPixel(s, {}, x, y);
            if (a.kind != Analytic::Plane || a.nearEdge) continue;
            double rel = 0;
            const bool blockedB = test::rayMeetsSphere(a.p, lB, Vec3(0, 1, 0), 1.0, rel);
            if (std::abs(rel) < 1e-9) continue;  // tangent to the sphere toward B: not judged
            ++judged;
            const float vA = a.lit ? 1.0f : 0.0f, vB = blockedB ? 0.0f : 1.0f;
            shadowed[0] += !a.lit;
            shadowed[1] += blockedB;
            ASSERT_EQ(f.lightVisibility[0][i], vA) << "pixel " << x << "," << y;
            ASSERT_EQ(f.lightVisibility[1][i], vB) << "pixel " << x << "," << y;
            ASSERT_NEAR(f.visibility[i], (wA * vA + wB * vB) / (wA + wB), 1e-6) << "pixel " << x << "," << y;
        }
    EXPECT_GT(judged, 5000);
    EXPECT_GT(shadowed[0], 200);
    EXPECT_GT(shadowed[1], 200);
    // One light: no per-light channels (they would equal `visibility`).
    const scene::Scene one = test::seedScene();
    EXPECT_TRUE(renderReference(one, test::planFor(one), test::biasSettings(0, scene::Precision::Float))
                    .lightVisibility.empty());
}

// The seed's light made a spot 4 above the plane pointing down, cone 25°, intensity 100.
const Vec3 kSpotOverSeed(0.3, 4.0, 0.2);
scene::Scene seedUnderSpot() {
    scene::Scene s = test::seedScene();
    s.lights[0] = test::spotPointingDown(kSpotOverSeed, 25.0, 100.0);
    return s;
}

TEST(ReferenceRender, APointOutsideEverySpotsConeHasNoNdotLSoCompareLeavesItOut) {
    // The seed's light made a spot 4 above the plane pointing down, cone 25°: plane points at an
    // angle past the cone get no light, so ndotl is -1 there (as on a back face); inside it ndotl
    // is the closed-form N·L toward the spot.
    const Vec3 spot = kSpotOverSeed;
    scene::Scene s = seedUnderSpot();
    const scene::Frame f = renderReference(s, test::planFor(s), test::biasSettings(0, scene::Precision::Double));
    const double cosCone = std::cos(25.0 * 3.14159265358979323846 / 180.0);
    int outside = 0, inside = 0;
    for (int y = 0; y < f.height; ++y)
        for (int x = 0; x < f.width; ++x) {
            const std::size_t i = std::size_t(y) * f.width + x;
            const Analytic a = test::analyticPixel(s, {}, x, y);
            if (a.kind != Analytic::Plane || f.objectId[i] != 2.0f) continue;
            const Vec3 toLight = glm::normalize(spot - a.p);
            const double cosAngle = toLight.y;  // dot(-toLight, (0, -1, 0)): the angle off the axis
            if (cosAngle < cosCone - 0.01) {
                ++outside;
                ASSERT_EQ(f.ndotl[i], -1.0f) << "pixel " << x << "," << y;
                ASSERT_EQ(f.visibility[i], 0.0f) << "pixel " << x << "," << y;
            } else if (cosAngle > cosCone + 0.01) {
                ++inside;
                ASSERT_NEAR(f.ndotl[i], toLight.y, 1e-4) << "pixel " << x << "," << y;
            }
        }
    EXPECT_GT(outside, 1000);
    EXPECT_GT(inside, 1000);
    // Reaching is the cone's geometry, as in lit.frag, not the intensity: a spot of intensity 0
    // gives the same ndotl.
    s.lights[0].intensity = 0.0;
    const scene::Frame dark = renderReference(s, test::planFor(s), test::biasSettings(0, scene::Precision::Double));
    EXPECT_EQ(dark.ndotl, f.ndotl);
}

TEST(ReferenceRender, ASpotsInnerConeFallsOffAsKhrLightsPunctualSaysAndLeavesTheShadowAlone) {
    // The spot above with an inner cone of 18° inside its 25°: a plane point's beauty is the hard
    // spot's times ((cos θ − cos 25°) / (cos 18° − cos 25°))² clamped to [0, 1] (the curve of
    // KHR_lights_punctual's README), computed here; visibility, ndotl and blockers do not change.
    const Vec3 spot = kSpotOverSeed;
    scene::Scene s = seedUnderSpot();
    const auto settings = test::biasSettings(0, scene::Precision::Double);
    const scene::Frame hard = renderReference(s, test::planFor(s), settings);
    s.lights[0].innerConeAngleDegrees = 18.0;
    const scene::Frame soft = renderReference(s, test::planFor(s), settings);
    EXPECT_EQ(soft.visibility, hard.visibility);
    EXPECT_EQ(soft.ndotl, hard.ndotl);
    EXPECT_EQ(soft.blockerId, hard.blockerId);
    const double kPi = 3.14159265358979323846;
    const double cosOuter = std::cos(25.0 * kPi / 180.0), cosInner = std::cos(18.0 * kPi / 180.0);
    const double ambient = s.ambient * s.materialOf(s.objects[1]).albedo.r;  // the ground's (object id 2)
    int ramp = 0, full = 0;
    for (int y = 0; y < soft.height; ++y)
        for (int x = 0; x < soft.width; ++x) {
            const std::size_t i = std::size_t(y) * soft.width + x;
            const Analytic a = test::analyticPixel(s, {}, x, y);
            if (a.kind != Analytic::Plane || soft.objectId[i] != 2.0f || !(hard.beauty[3 * i] > ambient + 1e-6))
                continue;
            const double cosAngle = glm::normalize(spot - a.p).y;
            const double t = std::clamp((cosAngle - cosOuter) / (cosInner - cosOuter), 0.0, 1.0);
            (t < 1.0 ? ramp : full) += 1;
            ASSERT_NEAR(soft.beauty[3 * i] - ambient, (hard.beauty[3 * i] - ambient) * t * t, 1e-5)
                << "pixel " << x << "," << y;
        }
    EXPECT_GT(ramp, 500);
    EXPECT_GT(full, 100);
}

// Counts plane pixels that are lit in closed form but have visibility 0 in the frame.
int falseShadowsOnPlane(const scene::Scene& s, const test::Placement& at, const scene::Frame& f, int& litPlanePixels) {
    int acne = 0;
    litPlanePixels = 0;
    for (int y = 0; y < f.height; ++y)
        for (int x = 0; x < f.width; ++x) {
            const Analytic a = test::analyticPixel(s, at, x, y, 0.0, 1e-6);
            if (a.kind != Analytic::Plane || a.nearEdge || !a.lit) continue;
            // The tilted square's in-plane orientation follows quadAxes(), not the local frame
            // of the closed form: near its far edge the two may see different things.
            if (f.objectId[std::size_t(y) * f.width + x] != 2.0f) continue;
            ++litPlanePixels;
            if (f.visibility[std::size_t(y) * f.width + x] == 0.0f) ++acne;
        }
    return acne;
}

// The seed scene tilted 25° and moved ~1000 from the origin: the plane is no longer a float grid
// plane, so a rounded o + t·d lands below it about half the time and its shadow ray hits the
// plane itself. (An axis-aligned plane hides acne: o.y + t·d.y rounds to the plane's own float y.)
test::Placement tiltedFarAway() {
    test::Placement at;
    at.offset = Vec3(1000.3, 200.7, -800.1);
    at.rotation = test::rotation(Vec3(1, 0.5, 0.2), 25);
    return at;
}

TEST(MethodRender, FloatWithZeroBiasShowsAcneOnTheLitPlaneAndReferenceDoesNot) {
    const test::Placement at = tiltedFarAway();
    const scene::Scene s = test::seedScene(at);
    const scene::RenderPlan plan = test::planFor(s);
    const scene::Frame method = render(s, plan, test::biasSettings(0.0, scene::Precision::Float));
    int lit = 0;
    const int acne = falseShadowsOnPlane(s, at, method, lit);
    ASSERT_GT(lit, 5000);
    EXPECT_GT(acne, lit / 10) << acne << " of " << lit << " lit plane pixels are dark";
    // Self-shadowing: the blocker is the plane itself (object index 1, id 2), apart from a few
    // pixels at the shadow's edge, which float geometry ~1000 from the origin moves by ~1e-4.
    int selfBlocked = 0;
    for (std::size_t i = 0; i < method.pixelCount(); ++i)
        if (method.objectId[i] == 2.0f && method.blockerId[i] == 2.0f) ++selfBlocked;
    EXPECT_GE(selfBlocked, acne * 9 / 10);

    const scene::Frame ref = renderReference(s, plan, test::biasSettings(0.0, scene::Precision::Float));
    EXPECT_EQ(falseShadowsOnPlane(s, at, ref, lit), 0);
    // The method in float with robust offsets is acne-free too.
    scene::RaytraceSettings robust = test::biasSettings(0.0, scene::Precision::Float);
    robust.robustOffset = true;
    EXPECT_EQ(falseShadowsOnPlane(s, at, render(s, plan, robust), lit), 0);
}

TEST(MethodRender, ATinyBiasIsEnoughInDoubleButNotInFloat) {
    // The lesson's two fixes for acne: double precision, or a bias along the normal. The scene
    // above, ~1300 from the origin, a bias of 1e-8: a float hit point there is off the plane by up
    // to a few ulps of 1000 (2⁻¹³ ≈ 1.2e-4), far more than the bias, so acne stays; a double one
    // by ~1e-13, far less, so the bias alone clears it.
    const test::Placement at = tiltedFarAway();
    const scene::Scene s = test::seedScene(at);
    const scene::RenderPlan plan = test::planFor(s);
    int lit = 0;
    const int floatAcne =
        falseShadowsOnPlane(s, at, render(s, plan, test::biasSettings(1e-8, scene::Precision::Float)), lit);
    ASSERT_GT(lit, 5000);
    EXPECT_GT(floatAcne, lit / 10) << floatAcne << " of " << lit;
    EXPECT_EQ(falseShadowsOnPlane(s, at, render(s, plan, test::biasSettings(1e-8, scene::Precision::Double)), lit), 0);
}

TEST(MethodRender, HugeBiasLiftsTheContactShadowExactlyAsTheShiftedOriginPredicts) {
    // Bias 1.5·r moves the plane's shadow-ray origins to y = 1.5: points within 0.87 of the
    // contact start inside the sphere (still blocked), the rest of the shadow's far end sees
    // the light over the sphere. Closed form: the same ray test from p + 1.5·n.
    const scene::Scene s = test::seedScene();
    const scene::RenderPlan plan = test::planFor(s);
    const double bias = 1.5;
    for (scene::Precision precision : {scene::Precision::Double, scene::Precision::Float}) {
        const scene::Frame f = render(s, plan, test::biasSettings(bias, precision));
        int shadowedTruly = 0, liftedExpected = 0, liftedSeen = 0, mismatches = 0;
        for (int y = 0; y < f.height; ++y)
            for (int x = 0; x < f.width; ++x) {
                const std::size_t i = std::size_t(y) * f.width + x;
                const Analytic truth = test::analyticPixel(s, {}, x, y, 0.0, 1e-4);
                const Analytic biased = test::analyticPixel(s, {}, x, y, bias, 1e-4);
                if (truth.kind != Analytic::Plane || truth.nearEdge || biased.nearEdge) continue;
                if (!truth.lit) {
                    ++shadowedTruly;
                    if (biased.lit) ++liftedExpected;
                    if (f.visibility[i] == 1.0f) ++liftedSeen;
                }
                if (f.visibility[i] != (biased.lit ? 1.0f : 0.0f)) ++mismatches;
            }
        SCOPED_TRACE(scene::toString(precision));
        EXPECT_GT(shadowedTruly, 200);
        EXPECT_GT(liftedExpected, shadowedTruly / 5);  // the scene shows a big missed shadow
        EXPECT_EQ(liftedSeen, liftedExpected);
        EXPECT_EQ(mismatches, 0);
        EXPECT_EQ(f.attributes.at("ray_bias"), "1.5");
    }
}

TEST(MethodRender, TheDefaultBiasFollowsThePixelNotTheSizeOfTheScene) {
    // The seed's sphere and ground with a small box 3000 units behind the camera (out of view,
    // its shadow far away): the scene-scaled bias becomes 1e-4 × a diagonal over 3000, about
    // 0.3, which lifts the contact shadow visibly. The default offsets each point by half its
    // pixel's footprint instead (2·z·tan 20° / 90 at view depth z: 0.03 to 0.13), capped there.
    // Closed form: the shadow test from p + b(z)·n, with b computed here from the pixel.
    scene::Scene s = test::seedScene();
    test::addBox(s, Vec3(-0.5, 0, 2999.5), Vec3(0.5, 1, 3000.5));
    const scene::RenderSettings settings = scene::resolveSettings(s, {});
    const double cap = settings.raytrace.rayBias;
    ASSERT_GT(cap, 0.3);
    const scene::CameraBasis cam = scene::cameraBasis(s.camera);
    auto viewScaled = [&](const Vec3& p) {
        const double z = glm::dot(p - cam.position, cam.forward);
        return std::min(cap, 0.5 * 2.0 * z * std::tan(20.0 * test::kPi / 180.0) / s.camera.height);
    };
    const scene::Frame f = render(s, test::planFor(s), settings.raytrace);
    int shadowed = 0, liftedByCap = 0, mismatches = 0;
    for (int y = 0; y < f.height; ++y)
        for (int x = 0; x < f.width; ++x) {
            const std::size_t i = std::size_t(y) * f.width + x;
            const Analytic truth = test::analyticPixel(s, {}, x, y, 0.0, 1e-4);
            if (truth.kind != Analytic::Plane || truth.nearEdge) continue;
            const double b = viewScaled(truth.p);
            ASSERT_LT(b, cap / 2);  // every plane pixel here gets less than the scene-scaled bias
            const Analytic biased = test::analyticPixel(s, {}, x, y, b, 1e-4);
            const Analytic capped = test::analyticPixel(s, {}, x, y, cap, 1e-4);
            if (biased.nearEdge || capped.nearEdge) continue;
            if (!truth.lit) ++shadowed;
            if (!truth.lit && capped.lit) ++liftedByCap;
            if (f.visibility[i] != (biased.lit ? 1.0f : 0.0f)) ++mismatches;
        }
    EXPECT_GT(shadowed, 200);
    EXPECT_GT(liftedByCap, 20);  // what the scene-scaled bias alone would have lost
    EXPECT_EQ(mismatches, 0);
    EXPECT_EQ(f.attributes.at("ray_bias_pixels"), "0.5");
}

TEST(MeshRender, FlatConvexMeshIsAcneFreeInTheReferenceAndAcneRiddenInFloatWithoutBias) {
    // A flat-shaded icosphere (no vertex normals: N is the face normal) replaces the seed's
    // sphere. Convex, with the plane below it: every mesh pixel facing the light is lit.
    scene::Scene s = test::seedScene({}, 128, 72);
    auto mesh = test::icosphere(Vec3(0.37, 1.01, -0.23), 1.0, 3);
    mesh->normals.clear();
    s.objects[0].shape = scene::Mesh::single("icosphere", mesh);
    const scene::RenderPlan plan = test::planFor(s);
    const scene::Frame ref = renderReference(s, plan, test::biasSettings(0, scene::Precision::Float));
    const scene::Frame method = render(s, plan, test::biasSettings(0, scene::Precision::Float));
    EXPECT_EQ(ref.attributes.at("triangles"), "1280");  // 20·4³ faces
    int facing = 0, refDark = 0, acne = 0;
    for (std::size_t i = 0; i < ref.pixelCount(); ++i) {
        if (ref.objectId[i] != 1.0f || !(ref.ndotl[i] > 1e-3f)) continue;
        ++facing;
        if (ref.visibility[i] != 1.0f) ++refDark;
        if (method.objectId[i] == 1.0f && method.visibility[i] == 0.0f) ++acne;
    }
    EXPECT_GT(facing, 400);
    EXPECT_EQ(refDark, 0);
    EXPECT_GT(acne, facing / 10) << acne << " of " << facing;
}

scene::Scene busyOpaqueScene() {
    scene::Scene s = test::seedScene({}, 96, 64);
    test::addBox(s, Vec3(-2.5, 0, -1.5), Vec3(-1.5, 1.2, -0.5));
    test::addSphere(s, Vec3(1.6, 0.5, 0.8), 0.5);
    test::addQuad(s, Vec3(1.5, 2.2, -1), Vec3(0.3, -1, 0.2), 1.0, 0.7);
    scene::Light point;
    point.type = scene::LightType::Point;
    point.position = Vec3(2, 4, 2);
    point.intensity = 200;
    s.lights.push_back(point);
    scene::Light area = point;
    area.position = Vec3(-2, 3.5, 3);
    area.radius = 0.4;
    s.lights.push_back(area);
    return s;
}

TEST(MethodRender, AnyHitAndClosestHitShadowRaysAgreeOnOpaqueScenes) {
    const scene::Scene s = busyOpaqueScene();
    scene::RenderPlan anyHitPlan = test::planFor(s);
    ASSERT_TRUE(anyHitPlan.anyHitShadowRays);
    scene::RenderPlan closestPlan = anyHitPlan;
    closestPlan.anyHitShadowRays = false;
    for (scene::Precision precision : {scene::Precision::Float, scene::Precision::Double}) {
        for (bool robust : {false, true}) {
            scene::RaytraceSettings rs = test::biasSettings(robust ? 0.0 : 1e-4, precision);
            rs.robustOffset = robust;
            rs.samples = 9;
            const scene::Frame a = render(s, anyHitPlan, rs);
            const scene::Frame c = render(s, closestPlan, rs);
            ASSERT_EQ(a.attributes.at("shadow_rays"), "any-hit");
            ASSERT_EQ(c.attributes.at("shadow_rays"), "closest-hit");
            int partial = 0, zero = 0;
            for (std::size_t i = 0; i < a.pixelCount(); ++i) {
                ASSERT_EQ(a.visibility[i], c.visibility[i]) << "pixel " << i;
                ASSERT_EQ(a.beauty[3 * i], c.beauty[3 * i]);
                if (a.visibility[i] > 0 && a.visibility[i] < 1) ++partial;
                if (a.visibility[i] == 0 && a.objectId[i] > 0) ++zero;
            }
            EXPECT_GT(partial, 20);  // the area light's penumbra is in view
            EXPECT_GT(zero, 20);
        }
    }
}

TEST(MethodRender, FramesDoNotDependOnTheThreadCount) {
    // Area-light samples come from per-pixel random streams, so the schedule cannot change them.
    const scene::Scene s = busyOpaqueScene();
    scene::RaytraceSettings rs = test::biasSettings(1e-4, scene::Precision::Float);
    rs.samples = 16;
    rs.threads = 1;
    const scene::Frame one = render(s, test::planFor(s), rs);
    rs.threads = 2;
    const scene::Frame two = render(s, test::planFor(s), rs);
    EXPECT_EQ(one.attributes.at("threads"), "1");
    EXPECT_EQ(two.attributes.at("threads"), "2");
    EXPECT_EQ(one.visibility, two.visibility);
    EXPECT_EQ(one.beauty, two.beauty);
    EXPECT_EQ(one.blockerId, two.blockerId);
}

TEST(MethodRender, FillsEveryAovAndTheMetadata) {
    const scene::Scene s = test::seedScene({}, 64, 36);
    scene::RaytraceSettings rs = test::biasSettings(1e-4, scene::Precision::Float);
    rs.threads = 1;
    const scene::Frame f = render(s, test::planFor(s), rs);
    ASSERT_EQ(f.pixelCount(), 64u * 36u);
    ASSERT_EQ(f.blockerId.size(), f.pixelCount());
    const scene::CameraBasis cam = scene::cameraBasis(s.camera);
    for (int y = 0; y < f.height; ++y)
        for (int x = 0; x < f.width; ++x) {
            const std::size_t i = std::size_t(y) * f.width + x;
            const Analytic a = test::analyticPixel(s, {}, x, y);
            if (a.nearEdge) continue;
            if (a.kind == Analytic::Background) {
                EXPECT_EQ(f.objectId[i], 0.0f);
                EXPECT_EQ(f.depth[i], 0.0f);
                EXPECT_FLOAT_EQ(f.beauty[3 * i], float(s.background.x));
                continue;
            }
            // Depth along the camera axis and N·L from the closed-form point and normal.
            const double depth = glm::dot(a.p - cam.position, cam.forward);
            EXPECT_NEAR(f.depth[i], depth, 1e-4 * depth);
            const Vec3 L = -s.lights[0].direction;
            EXPECT_NEAR(f.ndotl[i], glm::dot(a.n, L), 1e-4);
            // Shading: albedo·(ambient + intensity·N·L·V).
            const double v = f.visibility[i];
            const double expected = 0.8 * (s.ambient + 3.0 * std::max(0.0, glm::dot(a.n, L)) * v);
            EXPECT_NEAR(f.beauty[3 * i], expected, 1e-4);
            if (v == 1.0f) {
                EXPECT_EQ(f.blockerId[i], 0.0f);
            }
        }
    for (const char* stage : {"setup", "primary", "shadow"}) EXPECT_GE(f.timing(stage), 0.0);
    EXPECT_EQ(f.timingsMs.size(), 3u);
    EXPECT_EQ(f.attributes.at("backend"), "raytrace");
    EXPECT_EQ(f.attributes.at("precision"), "float");
    EXPECT_EQ(f.attributes.at("threads"), "1");
    EXPECT_EQ(f.attributes.at("samples"), "1");
}

TEST(RaytraceRender, TheCameraSeesOnlyBetweenItsNearAndFarPlanesAsTheRasterPipelineClips) {
    // Camera at the origin looking down −Z (view depth = −z). A small quad at depth 0.05 over the
    // middle, a wall at depth 10 over the left half (x < 0), a wall at depth 30 over everything.
    // Near 0.1, far 20: the small quad is clipped (the left wall shows through it), the right
    // half sees nothing nearer than 30 and is background. Far 40 shows the far wall there; near
    // 0.01 brings the small quad back.
    scene::Scene s;
    s.camera.position = Vec3(0);
    s.camera.lookAt = Vec3(0, 0, -1);
    s.camera.fovYDegrees = 40;
    s.camera.width = 16;
    s.camera.height = 8;
    test::addMaterial(s, "m");
    test::addDirectional(s, Vec3(0, 0, -1));
    test::addQuad(s, Vec3(0, 0, -0.05), Vec3(0, 0, 1), 0.01, 0.01);  // id 1: pixels 7..8 across
    test::addQuad(s, Vec3(-50, 0, -10), Vec3(0, 0, 1), 100, 100);    // id 2: x < 0
    test::addQuad(s, Vec3(0, 0, -30), Vec3(0, 0, 1), 1000, 1000);    // id 3
    const auto idAt = [](const scene::Frame& f, int x, int y) { return int(f.objectId[std::size_t(y) * f.width + x]); };
    for (const auto& [near, far] : {std::pair{0.1, 20.0}, std::pair{0.1, 40.0}, std::pair{0.01, 20.0}}) {
        s.camera.near = near;
        s.camera.far = far;
        SCOPED_TRACE("near " + std::to_string(near) + ", far " + std::to_string(far));
        for (const bool reference : {false, true}) {
            const scene::Frame f =
                reference ? renderReference(s, test::planFor(s), test::biasSettings(0, scene::Precision::Double))
                          : render(s, test::planFor(s), test::biasSettings(1e-4, scene::Precision::Float));
            // Pixels 7 and 8 of rows 3 and 4 look through the small quad: its half-width 0.005 at
            // depth 0.05 covers directions within ±0.1, and their centres are ±0.046 off the axis
            // (a pixel is 2·tan 20°/8 = 0.091 across); pixel 7 leans left, onto the near wall.
            EXPECT_EQ(idAt(f, 7, 3), near < 0.05 ? 1 : 2);
            EXPECT_EQ(idAt(f, 0, 0), 2);
            EXPECT_EQ(idAt(f, 15, 7), far > 30 ? 3 : 0);
            EXPECT_EQ(idAt(f, 12, 3), far > 30 ? 3 : 0);
        }
    }
}

}  // namespace
}  // namespace shadowlab::raytrace
