// tests/raster/geometry_test.cpp: tessellation against the shapes' closed forms.
#include "raster/geometry.h"

#include <cmath>

#include <gtest/gtest.h>

#include "raster/tolerances.h"
#include "tests/kit/test_scenes.h"

namespace shadowlab::raster {
namespace {

using test::kPi;
using test::Vec3;

scene::Scene oneObject(const scene::Shape& shape) {
    scene::Scene s = test::makeScene(test::SphereOverPlane{});
    s.objects.resize(1);
    s.objects[0].shape = shape;
    return s;
}

TEST(SphereSegments, ChordErrorIsBelowAQuarterPixelAndNoFinerThanNeeded) {
    // Pixel world size at distance D: 2·D·tan(fov/2)/H; chord error of n segments: r(1 − cos(π/n)).
    const double r = 1.0, d = 5.0, tanHalf = std::tan(20.0 * kPi / 180.0);
    const int h = 720;
    const int n = sphereSegments(r, d, tanHalf, h);
    const double quarterPixel = 0.25 * 2.0 * d * tanHalf / h;
    ASSERT_GT(n, kMinSphereSegments);
    ASSERT_LT(n, kMaxSphereSegments);
    EXPECT_LE(r * (1.0 - std::cos(kPi / n)), quarterPixel);
    EXPECT_GT(r * (1.0 - std::cos(kPi / (n - 2))), quarterPixel);  // n − 2 (even) would not do
    EXPECT_EQ(n % 2, 0);
}

TEST(SphereSegments, ClampsToTheLimits) {
    EXPECT_EQ(sphereSegments(1.0, 1e-6, 0.36, 100000), kMaxSphereSegments);  // huge on screen
    EXPECT_EQ(sphereSegments(1e-3, 1e3, 0.36, 90), kMinSphereSegments);      // a speck
}

TEST(Tessellate, SphereVerticesLieOnTheSphereWithRadialNormals) {
    const Vec3 c(1, 2, 3);
    const scene::Scene s = oneObject(scene::Sphere{c, 0.75});
    const Vec3 origin(0.5, 0.5, 0.5);
    const SceneGeometry g = tessellateScene(s, origin);
    ASSERT_GT(g.triangleCount(), 100u);
    for (const Vertex& v : g.vertices) {
        const Vec3 p = Vec3(v.position) + origin;
        ASSERT_NEAR(glm::length(p - c), 0.75, 1e-6);
        ASSERT_NEAR(glm::dot(Vec3(v.normal), glm::normalize(p - c)), 1.0, 1e-6);
        ASSERT_EQ(v.objectId, 1u);
    }
    for (std::size_t t = 0; t < g.indices.size(); t += 3) {  // no degenerate triangles at the poles
        const Vec3 a(g.vertices[g.indices[t]].position), b(g.vertices[g.indices[t + 1]].position),
            e(g.vertices[g.indices[t + 2]].position);
        ASSERT_GT(glm::length(glm::cross(b - a, e - a)), 0.0);
    }
}

TEST(Tessellate, QuadIsTwoTrianglesCoveringItsArea) {
    scene::Quad q;
    q.center = Vec3(0, 1, 0);
    q.normal = glm::normalize(Vec3(0, 1, 1));
    q.size = scene::Vec2(2.0, 3.0);
    scene::quadAxes(q.normal, q.uAxis, q.vAxis);
    const SceneGeometry g = tessellateScene(oneObject(q), Vec3(0));
    ASSERT_EQ(g.triangleCount(), 2u);
    double area = 0.0;
    for (std::size_t t = 0; t < 6; t += 3) {
        const Vec3 a(g.vertices[g.indices[t]].position), b(g.vertices[g.indices[t + 1]].position),
            c(g.vertices[g.indices[t + 2]].position);
        area += 0.5 * glm::length(glm::cross(b - a, c - a));
    }
    EXPECT_NEAR(area, 6.0, 1e-5);
    for (const Vertex& v : g.vertices) {
        EXPECT_NEAR(glm::dot(Vec3(v.position) - q.center, q.normal), 0.0, 1e-6);  // in the plane
        EXPECT_NEAR(glm::dot(Vec3(v.normal), q.normal), 1.0, 1e-6);
    }
}

TEST(Tessellate, BoxIsTwelveTrianglesWithOutwardFlatNormals) {
    const scene::Box box{Vec3(-1, 0, -2), Vec3(1, 3, 2)};
    const SceneGeometry g = tessellateScene(oneObject(box), Vec3(0));
    ASSERT_EQ(g.triangleCount(), 12u);
    const Vec3 center(0, 1.5, 0);
    double area = 0.0;
    for (std::size_t t = 0; t < g.indices.size(); t += 3) {
        const Vertex& va = g.vertices[g.indices[t]];
        const Vec3 a(va.position), b(g.vertices[g.indices[t + 1]].position), c(g.vertices[g.indices[t + 2]].position);
        area += 0.5 * glm::length(glm::cross(b - a, c - a));
        const Vec3 centroid = (a + b + c) / 3.0;
        EXPECT_GT(glm::dot(Vec3(va.normal), centroid - center), 0.0);  // outward
        // Flat: the normal is perpendicular to the triangle's edges.
        EXPECT_NEAR(glm::dot(Vec3(va.normal), b - a), 0.0, 1e-6);
        EXPECT_NEAR(glm::dot(Vec3(va.normal), c - a), 0.0, 1e-6);
    }
    EXPECT_NEAR(area, 2.0 * (2 * 3 + 2 * 4 + 3 * 4), 1e-4);  // the box's surface area
}

TEST(Tessellate, MeshIsTakenAsIsWithObjectIds) {
    auto mesh = std::make_shared<scene::TriangleMesh>();
    mesh->positions = {Vec3(0, 0, 0), Vec3(1, 0, 0), Vec3(0, 1, 0), Vec3(1, 1, 0)};
    mesh->normals = {Vec3(0, 0, 1), Vec3(0, 0, 1), Vec3(0, 0, 1), Vec3(0, 0, 1)};
    mesh->indices = {0, 1, 2, 1, 3, 2};
    scene::Scene s = oneObject(scene::Mesh::single("m.obj", mesh));
    s.objects.insert(s.objects.begin(), s.objects[0]);  // two copies: ids 1 and 2
    const SceneGeometry g = tessellateScene(s, Vec3(0));
    ASSERT_EQ(g.triangleCount(), 4u);
    ASSERT_EQ(g.vertices.size(), 8u);
    EXPECT_EQ(g.vertices[0].objectId, 1u);
    EXPECT_EQ(g.vertices[4].objectId, 2u);
    EXPECT_EQ(g.indices[6], 4u);  // the second copy's indices point at its own vertices
}

TEST(Tessellate, MeshWithoutNormalsIsDrawnFlatWithEachFaceNormal) {
    // A roof of two faces sharing the ridge, with no vertex normals, placed by a non-uniform scale
    // and a move. Each triangle gets its own three vertices whose normal is the placed face's:
    // the cross product of its placed edges (a shared vertex would blend the two faces).
    auto mesh = std::make_shared<scene::TriangleMesh>();
    mesh->positions = {Vec3(-1, 0, 0), Vec3(0, 1, 0), Vec3(0, 1, 1), Vec3(1, 0, 0)};
    mesh->indices = {0, 2, 1, 1, 2, 3};
    scene::Affine m(1.0);
    m[0][0] = 3.0;                 // x scaled by 3: the slopes flatten to 1:3
    m[3] = scene::Vec3(5, 2, -1);  // moved
    const SceneGeometry g = tessellateScene(oneObject(scene::Mesh::single("roof.obj", mesh, m)), Vec3(0));
    ASSERT_EQ(g.triangleCount(), 2u);
    ASSERT_EQ(g.vertices.size(), 6u);
    const Vec3 expected[2] = {glm::normalize(Vec3(-1, 3, 0)), glm::normalize(Vec3(1, 3, 0))};
    for (std::size_t t = 0; t < 2; ++t) {
        const Vec3 a(g.vertices[g.indices[3 * t]].position), b(g.vertices[g.indices[3 * t + 1]].position),
            c(g.vertices[g.indices[3 * t + 2]].position);
        EXPECT_NEAR(glm::dot(glm::normalize(glm::cross(b - a, c - a)), expected[t]), 1.0, 1e-6);  // winding kept
        for (int k = 0; k < 3; ++k) {
            const Vec3 n(g.vertices[g.indices[3 * t + k]].normal);
            EXPECT_NEAR(glm::dot(n, expected[t]), 1.0, 1e-6) << "triangle " << t << " vertex " << k;
        }
    }
}

TEST(Tessellate, MeshWithoutGeometryIsAnError) {
    EXPECT_THROW(tessellateScene(oneObject(scene::Mesh::single("missing.obj", nullptr)), Vec3(0)), std::runtime_error);
}

TEST(Tessellate, PositionsAreCameraRelativeAndKeepSmallOffsetsFarFromTheOrigin) {
    // At 1e6 a float step is 0.0625; relative to a nearby origin 1e-3 survives.
    const Vec3 origin(1.0e6, 0, 0);
    const scene::Box box{origin + Vec3(0.001, 0, 0), origin + Vec3(0.002, 0.001, 0.001)};
    const SceneGeometry g = tessellateScene(oneObject(box), origin);
    float minX = 1e9f, maxX = -1e9f;
    for (const Vertex& v : g.vertices) {
        minX = std::min(minX, v.position.x);
        maxX = std::max(maxX, v.position.x);
    }
    EXPECT_NEAR(minX, 0.001f, 1e-9f);
    EXPECT_NEAR(maxX, 0.002f, 1e-9f);
}

}  // namespace
}  // namespace shadowlab::raster
