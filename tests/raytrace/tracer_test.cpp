// tests/raytrace/tracer_test.cpp: per-shape hits and surface points against closed form.
#include "raytrace/tracer.h"

#include <gtest/gtest.h>

#include "tests/kit/test_scenes.h"

namespace shadowlab::raytrace {
namespace {

using test::Vec3;

template <typename Real>
class TracerTest : public ::testing::Test {};
using Reals = ::testing::Types<float, double>;
TYPED_TEST_SUITE(TracerTest, Reals);

TYPED_TEST(TracerTest, ClosestHitFindsTheNearestOfSphereQuadAndBox) {
    using Real = TypeParam;
    using V = Vec3T<Real>;
    scene::Scene s;
    test::addMaterial(s, "matte");
    test::addSphere(s, Vec3(0, 0, -10), 2.0);               // front at z = -8
    test::addQuad(s, Vec3(0, 0, -5), Vec3(0, 0, 1), 1, 1);  // z = -5, |x|,|y| <= 0.5
    test::addBox(s, Vec3(2, -1, -7), Vec3(4, 1, -6));       // front face z = -6
    const Tracer<Real> tracer(s);
    for (bool robust : {false, true}) {
        Hit<Real> h;
        // Down -z through the quad: quad first (t = 5).
        ASSERT_TRUE(tracer.closestHit(Ray<Real>(V(0), V(0, 0, -1)), Real(1e30), robust, h));
        EXPECT_EQ(h.object, 1);
        EXPECT_NEAR(h.t, 5.0, 1e-5);
        // Beside the quad (x = 0.7): the sphere at z = -10 + sqrt(4 − 0.49).
        ASSERT_TRUE(tracer.closestHit(Ray<Real>(V(0.7, 0, 0), V(0, 0, -1)), Real(1e30), robust, h));
        EXPECT_EQ(h.object, 0);
        EXPECT_NEAR(h.t, 10.0 - std::sqrt(4.0 - 0.49), 1e-5);
        SurfacePoint<Real> sp = tracer.surfacePoint(Ray<Real>(V(0.7, 0, 0), V(0, 0, -1)), h, robust);
        const Vec3 n = glm::normalize(Vec3(sp.p) - Vec3(0, 0, -10));
        EXPECT_NEAR(glm::dot(Vec3(sp.ng), n), 1.0, 1e-6);
        // The box's front face, normal +z (toward the ray's origin).
        ASSERT_TRUE(tracer.closestHit(Ray<Real>(V(3, 0, 0), V(0, 0, -1)), Real(1e30), robust, h));
        EXPECT_EQ(h.object, 2);
        EXPECT_NEAR(h.t, 6.0, 1e-5);
        sp = tracer.surfacePoint(Ray<Real>(V(3, 0, 0), V(0, 0, -1)), h, robust);
        EXPECT_EQ(Vec3(sp.ng), Vec3(0, 0, 1));
        if (robust) {
            EXPECT_EQ(sp.p.z, Real(-6));  // snapped to the face
        }
        // tMax cuts the quad off.
        EXPECT_FALSE(tracer.closestHit(Ray<Real>(V(0), V(0, 0, -1)), Real(4.9), robust, h));
        // Missing everything.
        EXPECT_FALSE(tracer.closestHit(Ray<Real>(V(0), V(0, 1, 0)), Real(1e30), robust, h));
    }
}

TYPED_TEST(TracerTest, AMeshWithoutNormalsMergedWithOneWithNormalsLeavesTheirsAlone) {
    // One object placing two geometries once each (merged into one world-space mesh): a unit
    // square at y = 0 whose vertex normals all lean to (0, 1, 1)/sqrt 2, and a triangle at
    // y = 0 beside it with no normals, turned by a placement that tilts it 45° about z. The
    // square keeps its normals; the triangle is shaded with its placed face normal.
    using Real = TypeParam;
    using V = Vec3T<Real>;
    auto square = std::make_shared<scene::TriangleMesh>();
    square->positions = {Vec3(0, 0, 0), Vec3(1, 0, 0), Vec3(1, 0, 1), Vec3(0, 0, 1)};
    square->normals.assign(4, glm::normalize(Vec3(0, 1, 1)));
    square->indices = {0, 2, 1, 0, 3, 2};
    auto triangle = std::make_shared<scene::TriangleMesh>();
    triangle->positions = {Vec3(0, 0, 0), Vec3(1, 0, 0), Vec3(0, 0, 1)};
    triangle->indices = {0, 2, 1};
    const double c = std::sqrt(0.5);
    scene::Affine tilt(1.0);  // x' = c·x − c·y + 5, y' = c·x + c·y: the plane y = 0 tilted 45° about z
    tilt[0][0] = c, tilt[0][1] = c, tilt[1][0] = -c, tilt[1][1] = c, tilt[3] = Vec3(5, 0, 0);
    scene::Scene s;
    test::addMaterial(s, "matte");
    scene::Object o;
    o.name = "two";
    o.shape = scene::Mesh{"generated", {{square, scene::Affine(1.0)}, {triangle, tilt}}};
    s.objects.push_back(o);
    const Tracer<Real> tracer(s);
    Hit<Real> h;
    const Ray<Real> onSquare(V(0.5, 5, 0.5), V(0, -1, 0));
    ASSERT_TRUE(tracer.closestHit(onSquare, Real(1e30), false, h));
    EXPECT_NEAR(glm::dot(Vec3(tracer.surfacePoint(onSquare, h, false).ns), glm::normalize(Vec3(0, 1, 1))), 1.0, 1e-6);
    // The tilted triangle's point (0.2, 0, 0.2) lies at (5 + 0.2c, 0.2c, 0.2); its face normal
    // is the tilt of (0, 1, 0): (−c, c, 0), turned toward the ray by the facing rule.
    const Ray<Real> onTriangle(V(5 + 0.2 * c - c, 0.2 * c + c, 0.2), V(c, -c, 0));  // along the normal
    ASSERT_TRUE(tracer.closestHit(onTriangle, Real(1e30), false, h));
    EXPECT_NEAR(std::abs(glm::dot(Vec3(tracer.surfacePoint(onTriangle, h, false).ns), Vec3(-c, c, 0))), 1.0, 1e-6);
}

TYPED_TEST(TracerTest, QuadsAreTwoSidedAndFaceTheViewer) {
    using Real = TypeParam;
    using V = Vec3T<Real>;
    scene::Scene s;
    test::addMaterial(s, "matte");
    test::addQuad(s, Vec3(0), Vec3(0, 1, 0), 2, 2);
    const Tracer<Real> tracer(s);
    for (Real side : {Real(1), Real(-1)}) {
        const Ray<Real> ray(V(0.3, 3 * side, 0.2), V(0, -side, 0));
        Hit<Real> h;
        ASSERT_TRUE(tracer.closestHit(ray, Real(100), false, h));
        EXPECT_NEAR(h.t, 3.0, 1e-6);
        const SurfacePoint<Real> sp = tracer.surfacePoint(ray, h, false);
        EXPECT_EQ(sp.ns.y, side);
        EXPECT_EQ(sp.ng.y, side);
    }
    // Outside the rectangle (|x| > 1) there is no hit.
    Hit<Real> h;
    EXPECT_FALSE(tracer.closestHit(Ray<Real>(V(1.2, 3, 0), V(0, -1, 0)), Real(100), false, h));
}

TYPED_TEST(TracerTest, RobustSurfacePointsLieWithinTheirErrorBounds) {
    // What the robust offset needs: the computed point's distance to the exact (Real) surface,
    // measured in long double (64-bit mantissa, so exact enough to judge even double), is at
    // most errorAlongNormal. Sphere: | |p − c| − r |; quad: |n·(p − c)| / |n|.
    using Real = TypeParam;
    using V = Vec3T<Real>;
    using LD = long double;
    scene::Scene s;
    test::addMaterial(s, "matte");
    const Vec3 c(1234.5, -987.25, 55.125);
    test::addSphere(s, c, 3.0);
    test::addQuad(s, c + Vec3(0, 0, 20), glm::normalize(Vec3(0.3, -0.2, 1)), 40, 40);
    const Tracer<Real> tracer(s);
    const V cr(c);  // the sphere's center as Real stores it
    const V qc(c + Vec3(0, 0, 20));
    const V qn(glm::normalize(Vec3(0.3, -0.2, 1)));
    int checked[2] = {0, 0};
    for (int k = 0; k < 400; ++k) {
        const double a = 0.1 * k;
        const Vec3 target = Vec3(cr) + (k % 2 ? Vec3(0, 0, 20) : Vec3(0));
        const Vec3 from = target + Vec3(10 * std::cos(a), 10 * std::sin(a), 6 * std::sin(3 * a) - 8);
        const Ray<Real> ray(V(from), V(target - from));
        Hit<Real> h;
        if (!tracer.closestHit(ray, Real(1e30), true, h)) continue;
        const SurfacePoint<Real> sp = tracer.surfacePoint(ray, h, true);
        LD dist = 0;
        if (h.object == 0) {
            LD d2 = 0;
            for (int i = 0; i < 3; ++i) d2 += (LD(sp.p[i]) - LD(cr[i])) * (LD(sp.p[i]) - LD(cr[i]));
            dist = std::abs(std::sqrt(d2) - LD(Real(3)));
        } else {
            LD num = 0, nn = 0;
            for (int i = 0; i < 3; ++i) {
                num += LD(qn[i]) * (LD(sp.p[i]) - LD(qc[i]));
                nn += LD(qn[i]) * LD(qn[i]);
            }
            // errorAlongNormal is how far to move along the stored (nearly unit) normal n:
            // that changes n·(p − c) by errorAlongNormal·|n|².
            dist = std::abs(num) / nn;
        }
        ++checked[h.object];
        EXPECT_LE(dist, LD(sp.errorAlongNormal)) << "object " << h.object << " ray " << k;
        EXPECT_GT(sp.errorAlongNormal, Real(0));
    }
    EXPECT_GT(checked[0], 100);
    EXPECT_GT(checked[1], 100);
}

}  // namespace
}  // namespace shadowlab::raytrace
