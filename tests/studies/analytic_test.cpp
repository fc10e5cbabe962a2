// tests/studies/analytic_test.cpp: the analytic oracle against shadows derived by hand
// (a unit sphere under a vertical light casts the unit disk; a box's oblique shadow) and the
// checker's counting.
#include "studies/analytic.h"

#include <cmath>

#include <gtest/gtest.h>

#include "scene/camera.h"
#include "scene/error.h"

namespace shadowlab::studies {
namespace {

using scene::Vec3;

// The seed layout: 20 x 20 ground quad at y = 0 seen from (0, 2, 6), one directional light.
scene::Scene groundScene(const Vec3& lightDirection, const Vec3& offset = Vec3(0)) {
    scene::Scene s;
    s.camera.position = Vec3(0, 2, 6) + offset;
    s.camera.lookAt = Vec3(0, 0.7, 0) + offset;
    s.camera.width = 96;
    s.camera.height = 54;
    s.materials.push_back({});
    scene::Light l;
    l.direction = glm::normalize(lightDirection);
    s.lights.push_back(l);
    scene::Quad q;
    q.center = offset;
    q.normal = Vec3(0, 1, 0);
    q.size = {20, 20};
    scene::quadAxes(q.normal, q.uAxis, q.vAxis);
    s.objects.push_back({"ground", q, 0});
    return s;
}

scene::Scene sphereOverPlane(const Vec3& offset = Vec3(0)) {
    scene::Scene s = groundScene(Vec3(0, -1, 0), offset);
    s.objects.push_back({"sphere", scene::Sphere{Vec3(0, 1, 0) + offset, 1.0}, 0});
    return s;
}

// Where the camera ray of pixel (x, y) meets the plane y = 0 (written here, not the oracle's).
Vec3 groundPoint(const scene::Scene& s, int x, int y) {
    const scene::CameraBasis cam = scene::cameraBasis(s.camera);
    const Vec3 d = scene::pixelDirection(cam, x, y);
    const double t = -cam.position.y / d.y;
    return cam.position + t * d;
}

TEST(AnalyticTest, UnitSphereUnderVerticalLightShadowsTheUnitDisk) {
    const scene::Scene s = sphereOverPlane();
    const auto a = analyticAnswer(s);
    ASSERT_TRUE(a.has_value());
    std::size_t shadowed = 0, lit = 0, knife = 0;
    for (int y = 0; y < a->height; ++y)
        for (int x = 0; x < a->width; ++x) {
            const std::size_t i = std::size_t(y) * a->width + x;
            if (a->knifeEdge[i]) {
                ++knife;
                continue;
            }
            if (a->objectId[i] != 1) continue;
            const Vec3 p = groundPoint(s, x, y);
            const bool inDisk = p.x * p.x + p.z * p.z < 1.0;
            ASSERT_TRUE(a->lit[i]);  // the ground faces the light everywhere
            EXPECT_EQ(a->visibility[i], inDisk ? 0.0f : 1.0f) << x << "," << y;
            (inDisk ? shadowed : lit) += 1;
        }
    EXPECT_GT(shadowed, 20u);  // the front half of the disk is in view
    EXPECT_GT(lit, 1000u);
    // Knife edges are a thin set (silhouettes and the disk's rim), never a way to skip the image.
    EXPECT_LT(knife, a->pixelCount() / 50);
}

TEST(AnalyticTest, SpherePixelsAreTheSphereAndLitOnTheUpperHalf) {
    const scene::Scene s = sphereOverPlane();
    const auto a = analyticAnswer(s);
    ASSERT_TRUE(a.has_value());
    const scene::CameraBasis cam = scene::cameraBasis(s.camera);
    std::size_t spherePixels = 0;
    for (int y = 0; y < a->height; ++y)
        for (int x = 0; x < a->width; ++x) {
            const std::size_t i = std::size_t(y) * a->width + x;
            if (a->knifeEdge[i]) continue;
            // Ray-sphere in the test: |o + t d - c|^2 = 1 has a root iff the discriminant ≥ 0.
            const Vec3 d = glm::normalize(scene::pixelDirection(cam, x, y));
            const Vec3 oc = cam.position - Vec3(0, 1, 0);
            const double b = glm::dot(oc, d), disc = b * b - (glm::dot(oc, oc) - 1.0);
            if (disc < 0) {
                EXPECT_NE(a->objectId[i], 2);
                continue;
            }
            EXPECT_EQ(a->objectId[i], 2);
            ++spherePixels;
            const Vec3 p = cam.position + (-b - std::sqrt(disc)) * d;
            if (p.y > 1.0 + 1e-9) {
                EXPECT_TRUE(a->lit[i]);
                EXPECT_EQ(a->visibility[i], 1.0f);  // nothing is above the sphere
            }
        }
    EXPECT_GT(spherePixels, 100u);
}

TEST(AnalyticTest, BoxOnPlaneCastsTheSweptFootprint) {
    // Light travels along -(1, 2, 1): a ground point (x, 0, z) is shadowed iff (x+s, 2s, z+s)
    // lies in the box [-0.5, 0.5] x [0, 1] x [-0.5, 0.5] for some s > 0, i.e. iff
    // [0, 0.5] ∩ [-0.5-x, 0.5-x] ∩ [-0.5-z, 0.5-z] is non-empty (with s > 0).
    scene::Scene s = groundScene(Vec3(-1, -2, -1));
    s.objects.push_back({"box", scene::Box{Vec3(-0.5, 0, -0.5), Vec3(0.5, 1, 0.5)}, 0});
    const auto a = analyticAnswer(s);
    ASSERT_TRUE(a.has_value());
    std::size_t shadowed = 0;
    for (int y = 0; y < a->height; ++y)
        for (int x = 0; x < a->width; ++x) {
            const std::size_t i = std::size_t(y) * a->width + x;
            if (a->knifeEdge[i] || a->objectId[i] != 1) continue;
            const Vec3 p = groundPoint(s, x, y);
            const double lo = std::max({0.0, -0.5 - p.x, -0.5 - p.z});
            const double hi = std::min({0.5, 0.5 - p.x, 0.5 - p.z});
            const bool inShadow = lo < hi && hi > 0;
            EXPECT_EQ(a->visibility[i], inShadow ? 0.0f : 1.0f) << x << "," << y;
            shadowed += inShadow;
        }
    EXPECT_GT(shadowed, 20u);
}

TEST(AnalyticTest, FarFromOriginGivesTheSameAnswer) {
    // Translating everything by 1e7 (exact in double) must not change any judged pixel.
    const auto near = analyticAnswer(sphereOverPlane());
    const auto far = analyticAnswer(sphereOverPlane(Vec3(1e7, 1e7, 1e7)));
    ASSERT_TRUE(near && far);
    std::size_t judged = 0;
    for (std::size_t i = 0; i < near->pixelCount(); ++i) {
        if (near->knifeEdge[i] || far->knifeEdge[i]) continue;
        ++judged;
        EXPECT_EQ(near->objectId[i], far->objectId[i]);
        EXPECT_EQ(near->visibility[i], far->visibility[i]);
    }
    EXPECT_GT(judged, near->pixelCount() * 9 / 10);
}

TEST(AnalyticTest, NotAnalyticScenesHaveNoAnswer) {
    scene::Scene point = sphereOverPlane();
    point.lights[0].type = scene::LightType::Point;
    EXPECT_FALSE(analyticAnswer(point).has_value());
    EXPECT_NE(whyNotAnalytic(point).find("point light"), std::string::npos);

    scene::Scene mesh = sphereOverPlane();
    mesh.objects.push_back({"m", scene::Mesh{}, 0});
    EXPECT_FALSE(analyticAnswer(mesh).has_value());

    scene::Scene glass = sphereOverPlane();
    glass.materials[0].opacity = 0.5;
    EXPECT_FALSE(analyticAnswer(glass).has_value());

    EXPECT_TRUE(whyNotAnalytic(sphereOverPlane()).empty());
}

scene::Frame frameFrom(const AnalyticFrame& a) {
    scene::Frame f = scene::Frame::allocate(a.width, a.height, false);
    for (std::size_t i = 0; i < a.pixelCount(); ++i) {
        f.objectId[i] = float(a.objectId[i]);
        f.visibility[i] = a.visibility[i];
    }
    return f;
}

TEST(AnalyticTest, CheckCountsMismatchesOutsideKnifeEdges) {
    const auto a = analyticAnswer(sphereOverPlane());
    ASSERT_TRUE(a);
    scene::Frame f = frameFrom(*a);
    EXPECT_TRUE(checkAgainstAnalytic(f, *a).passed());

    // Flip one judged lit pixel's visibility and another judged pixel's id.
    std::size_t flipV = 0, flipId = 0;
    for (std::size_t i = 0; i < a->pixelCount(); ++i)
        if (!a->knifeEdge[i] && a->lit[i]) {
            flipV = i;
            break;
        }
    for (std::size_t i = a->pixelCount(); i-- > 0;)
        if (!a->knifeEdge[i] && i != flipV) {
            flipId = i;
            break;
        }
    f.visibility[flipV] = 1.0f - f.visibility[flipV];
    f.objectId[flipId] += 1.0f;
    const AnalyticCheck c = checkAgainstAnalytic(f, *a);
    EXPECT_FALSE(c.passed());
    EXPECT_EQ(c.visibilityMismatches, 1u);
    EXPECT_EQ(c.objectIdMismatches, 1u);

    // A knife-edge pixel may be anything.
    scene::Frame g = frameFrom(*a);
    for (std::size_t i = 0; i < a->pixelCount(); ++i)
        if (a->knifeEdge[i]) g.objectId[i] = 99.0f;
    EXPECT_TRUE(checkAgainstAnalytic(g, *a).passed());

    scene::Frame wrongSize = scene::Frame::allocate(3, 3, false);
    EXPECT_THROW(checkAgainstAnalytic(wrongSize, *a), scene::InputError);
}

}  // namespace
}  // namespace shadowlab::studies
