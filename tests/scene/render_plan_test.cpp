// tests/scene/render_plan_test.cpp: the plan leaves out what the scene does not need.
#include "scene/render_plan.h"

#include <gtest/gtest.h>

namespace shadowlab::scene {
namespace {

Scene sphereOnPlane() {
    Scene s;
    s.materials.push_back({"m"});
    s.lights.push_back({});
    s.objects.push_back({"ball", Sphere{{0, 1, 0}, 1.0}, 0});
    Quad q;
    q.size = {20, 20};
    s.objects.push_back({"ground", q, 0});
    return s;
}

TEST(RenderPlan, OpaqueAnalyticSceneUsesAnyHitAndNoTriangleBvh) {
    const RenderPlan p = makeRenderPlan(sphereOnPlane(), {});
    EXPECT_TRUE(p.anyHitShadowRays);
    EXPECT_FALSE(p.needsTriangleBvh);
    EXPECT_FALSE(p.needsCubeMap);
    EXPECT_FALSE(p.needsTransmittanceMap);
    ASSERT_EQ(p.lights.size(), 1u);
    EXPECT_TRUE(p.lights[0].needsShadowTest);
    EXPECT_NE(p.explain().find("any-hit"), std::string::npos);
}

TEST(RenderPlan, SemiTransparentMaterialTurnsAnyHitOff) {
    Scene s = sphereOnPlane();
    s.materials.push_back({"glass", {0.9, 0.9, 0.9}, 0.3});
    s.objects[0].material = 1;
    const RenderPlan p = makeRenderPlan(s, {});
    EXPECT_FALSE(p.anyHitShadowRays);
    EXPECT_TRUE(p.needsTransmittanceMap);
}

TEST(RenderPlan, ASingleConvexObjectNeedsNoShadowPass) {
    Scene s = sphereOnPlane();
    s.objects.pop_back();
    const RenderPlan p = makeRenderPlan(s, {});
    EXPECT_FALSE(p.lights[0].needsShadowTest);
    EXPECT_NE(p.explain().find("skipped"), std::string::npos);
}

TEST(RenderPlan, ASpotWhoseConeHoldsNoObjectOrOneConvexObjectNeedsNoShadowPass) {
    Scene s = sphereOnPlane();  // sphere r=1 at (0,1,0); ground 20x20 at y=0
    Quad ground;
    ground.size = {20, 20};
    quadAxes(ground.normal, ground.uAxis, ground.vAxis);  // so that its bounds span the 20x20
    s.objects[1] = {"ground", ground, 0};
    Light spot;
    spot.type = LightType::Spot;
    spot.position = {0, 30, 0};
    spot.coneAngleDegrees = 20.0;
    spot.direction = {0, 1, 0};  // up, away from everything below it
    s.lights = {spot};
    // Both objects lie straight below the apex (180° off the axis); the ground's bounding sphere
    // (radius √(20²+20²)/2 ≈ 14.1, 30 away) spans asin(14.1/30) ≈ 28°, far from 180° − 20°.
    EXPECT_FALSE(makeRenderPlan(s, {}).lights[0].needsShadowTest);
    EXPECT_NE(makeRenderPlan(s, {}).explain().find("no object inside the spot's cone"), std::string::npos);
    // Pointed down: the sphere over the ground, both in the cone.
    s.lights[0].direction = {0, -1, 0};
    EXPECT_TRUE(makeRenderPlan(s, {}).lights[0].needsShadowTest);
    // The ground replaced by a ball at (50, 50, 50): from the apex (50, 20, 50), 106° off the
    // down axis (cos = −20/73.5), its sphere spanning asin(√3/73.5) ≈ 1.4°: outside. The sphere
    // alone in the cone cannot shadow itself.
    s.objects[1] = {"far ball", Sphere{{50, 50, 50}, 1.0}, 0};
    EXPECT_FALSE(makeRenderPlan(s, {}).lights[0].needsShadowTest);
    EXPECT_NE(makeRenderPlan(s, {}).explain().find("only one convex object"), std::string::npos);
    // A directional light in the same scene: two objects, tested.
    s.lights[0].type = LightType::Directional;
    EXPECT_TRUE(makeRenderPlan(s, {}).lights[0].needsShadowTest);
}

TEST(RenderPlan, CubeMapOnlyForAShadowedPointLight) {
    Scene s = sphereOnPlane();
    Light point;
    point.type = LightType::Point;
    point.position = {0, 5, 0};
    s.lights.push_back(point);
    EXPECT_TRUE(makeRenderPlan(s, {}).needsCubeMap);
    s.objects.pop_back();
    EXPECT_FALSE(makeRenderPlan(s, {}).needsCubeMap);
}

TEST(RenderPlan, CascadesApplyToADirectionalLightAndAreIgnoredWithoutOne) {
    Scene s = sphereOnPlane();
    RenderSettings settings;
    settings.raster.cascades = 3;
    EXPECT_EQ(makeRenderPlan(s, settings).cascades, 3);
    EXPECT_NE(makeRenderPlan(s, settings).explain().find("cascades: 3"), std::string::npos);
    for (Light& l : s.lights) {
        l.type = LightType::Point;
        l.position = {0, 5, 0};
    }
    const RenderPlan p = makeRenderPlan(s, settings);
    EXPECT_EQ(p.cascades, 1);
    EXPECT_NE(p.explain().find("cascades = 3 ignored: no shadowed directional light"), std::string::npos)
        << p.explain();
}

TEST(RenderPlan, MeshesNeedTheTriangleBvh) {
    Scene s = sphereOnPlane();
    s.objects.push_back({"mesh", Mesh{}, 0});
    EXPECT_TRUE(makeRenderPlan(s, {}).needsTriangleBvh);
}

}  // namespace
}  // namespace shadowlab::scene
