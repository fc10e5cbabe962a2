// tests/raytrace/bvh_test.cpp: the BVH's structure, BVH traversal against brute force, and the
// watertight triangle test on the shared edges and vertices of a closed mesh.
#include "raytrace/bvh.h"

#include <random>

#include <gtest/gtest.h>

#include "raytrace/tracer.h"
#include "tests/kit/test_scenes.h"

namespace shadowlab::raytrace {
namespace {

using test::Vec3;

std::shared_ptr<scene::TriangleMesh> triangleSoup(int count, std::mt19937_64& g) {
    std::uniform_real_distribution<double> pos(-10, 10), edge(-1.5, 1.5);
    auto m = std::make_shared<scene::TriangleMesh>();
    for (int i = 0; i < count; ++i) {
        const Vec3 a(pos(g), pos(g), pos(g));
        for (int k = 0; k < 3; ++k) {
            m->positions.push_back(k == 0 ? a : a + Vec3(edge(g), edge(g), edge(g)));
            m->indices.push_back(std::uint32_t(m->positions.size() - 1));
        }
    }
    return m;
}

TEST(Bvh, NodesAre32BytesAndBoundEverythingBelowThem) {
    std::mt19937_64 g(7);
    const auto soup = triangleSoup(3000, g);
    std::vector<scene::Bounds> bounds(soup->triangleCount());
    for (std::size_t t = 0; t < bounds.size(); ++t)
        for (int k = 0; k < 3; ++k) bounds[t].extend(soup->positions[soup->indices[3 * t + k]]);
    const Bvh bvh = Bvh::build(bounds);
    EXPECT_EQ(sizeof(BvhNode), 32u);
    ASSERT_FALSE(bvh.empty());
    std::vector<int> seen(bounds.size(), 0);
    // Walk the tree: each node's box contains its children's boxes / its primitives' bounds.
    std::vector<std::uint32_t> stack = {0};
    int leaves = 0;
    auto contains = [](const BvhNode& n, const scene::Bounds& b) {
        for (int k = 0; k < 3; ++k)
            if (!(n.lo[k] <= b.min[k] && b.max[k] <= n.hi[k])) return false;
        return true;
    };
    auto boundsOf = [](const BvhNode& n) {
        scene::Bounds b;
        b.extend(Vec3(n.lo[0], n.lo[1], n.lo[2]));
        b.extend(Vec3(n.hi[0], n.hi[1], n.hi[2]));
        return b;
    };
    while (!stack.empty()) {
        const std::uint32_t i = stack.back();
        stack.pop_back();
        const BvhNode& n = bvh.nodes()[i];
        if (n.count > 0) {
            ++leaves;
            EXPECT_LE(n.count, 8);
            for (std::uint32_t k = 0; k < n.count; ++k) {
                const std::uint32_t p = bvh.primitives()[n.offset + k];
                ++seen[p];
                EXPECT_TRUE(contains(n, bounds[p]));
            }
        } else {
            EXPECT_TRUE(contains(n, boundsOf(bvh.nodes()[i + 1])));
            EXPECT_TRUE(contains(n, boundsOf(bvh.nodes()[n.offset])));
            stack.push_back(i + 1);
            stack.push_back(n.offset);
        }
    }
    for (int s : seen) ASSERT_EQ(s, 1);  // every triangle in exactly one leaf
    EXPECT_GT(leaves, 3000 / 8);
    // SAH on a uniform soup stays shallow: far below the traversal stack.
    EXPECT_LT(bvh.depth(), 40);
}

// Möller–Trumbore with strict inside tests, in Real: the common non-watertight test, used only
// to show that the rays below do run along edges where a test can leak.
template <typename Real>
bool naiveHit(const Vec3T<Real>& o, const Vec3T<Real>& d, const Vec3T<Real>& a, const Vec3T<Real>& b,
              const Vec3T<Real>& c) {
    const Vec3T<Real> e1 = b - a, e2 = c - a, pv = glm::cross(d, e2);
    const Real det = glm::dot(e1, pv);
    if (det == 0) return false;
    const Real inv = Real(1) / det;
    const Vec3T<Real> tv = o - a;
    const Real u = glm::dot(tv, pv) * inv;
    if (!(u > 0 && u < 1)) return false;
    const Vec3T<Real> qv = glm::cross(tv, e1);
    const Real v = glm::dot(d, qv) * inv;
    if (!(v > 0 && u + v < 1)) return false;
    return glm::dot(e2, qv) * inv > 0;
}

template <typename Real>
class BvhTraversal : public ::testing::Test {};
using Reals = ::testing::Types<float, double>;
TYPED_TEST_SUITE(BvhTraversal, Reals);

TYPED_TEST(BvhTraversal, ClosestAndAnyHitEqualBruteForceOnRandomRays) {
    using Real = TypeParam;
    using V = Vec3T<Real>;
    std::mt19937_64 g(11);
    const auto soup = triangleSoup(2000, g);
    scene::Scene s = test::matteMeshScene(soup);
    const Tracer<Real> tracer(s);
    std::vector<V> p(soup->positions.size());
    for (std::size_t i = 0; i < p.size(); ++i) p[i] = V(soup->positions[i]);
    std::uniform_real_distribution<double> u(-14, 14);
    int hits = 0;
    for (int r = 0; r < 3000; ++r) {
        const Vec3 from(u(g), u(g), u(g)), to(u(g) / 2, u(g) / 2, u(g) / 2);
        const Ray<Real> ray(V(from), V(to - from));
        const Real tMax = r % 3 == 0 ? Real(0.7) : std::numeric_limits<Real>::infinity();
        // Brute force: every triangle with the same test.
        Real best = tMax;
        int bestTri = -1;
        for (std::size_t t = 0; t < soup->triangleCount(); ++t) {
            Real th, b0, b1, b2;
            if (intersectTriangle(ray, p[3 * t], p[3 * t + 1], p[3 * t + 2], best, false, th, b0, b1, b2)) {
                best = th;
                bestTri = int(t);
            }
        }
        Hit<Real> h;
        const bool found = tracer.closestHit(ray, tMax, false, h);
        ASSERT_EQ(found, bestTri >= 0) << "ray " << r;
        int blocker = -1;
        ASSERT_EQ(tracer.anyHit(ray, tMax, false, blocker), found) << "ray " << r;
        if (!found) continue;
        ++hits;
        EXPECT_EQ(h.t, best) << "ray " << r;
        EXPECT_EQ(h.prim, bestTri) << "ray " << r;
    }
    EXPECT_GT(hits, 500);  // the rays do test the tree
}

TYPED_TEST(BvhTraversal, RaysThroughSharedEdgesAndVerticesOfAClosedMeshNeverMiss) {
    // Every ray from outside the closed icosphere toward a point inside must hit it. The rays
    // pass exactly through vertices and edge points (as exactly as Real can aim), where a
    // non-watertight test lets rays slip between two triangles.
    using Real = TypeParam;
    using V = Vec3T<Real>;
    const Vec3 center(3.25, -1.5, 7.75);
    const auto sphere = test::icosphere(center, 2.0, 3);
    scene::Scene s = test::matteMeshScene(sphere);
    const Tracer<Real> tracer(s);
    std::mt19937_64 g(5);
    std::uniform_real_distribution<double> u(-0.5, 0.5);
    std::vector<Vec3> targets;
    for (const Vec3& p : sphere->positions) targets.push_back(Vec3(V(p)));
    for (std::size_t t = 0; t < sphere->indices.size(); t += 3)
        for (int e = 0; e < 3; ++e) {
            const Vec3 a(V(sphere->positions[sphere->indices[t + e]]));
            const Vec3 b(V(sphere->positions[sphere->indices[t + (e + 1) % 3]]));
            targets.push_back(0.5 * (a + b));
            targets.push_back(a + 0.25 * (b - a));
        }
    std::vector<V> pr;
    for (const Vec3& p : sphere->positions) pr.push_back(V(p));
    int misses = 0, rays = 0, naiveMisses = 0;
    auto shoot = [&](const Ray<Real>& ray, Real tMax) {
        for (bool conservative : {false, true}) {
            Hit<Real> h;
            ++rays;
            if (!tracer.closestHit(ray, tMax, conservative, h)) ++misses;
        }
        bool naive = false;
        for (std::size_t t = 0; t < sphere->indices.size() && !naive; t += 3)
            naive =
                naiveHit(ray.o, ray.d, pr[sphere->indices[t]], pr[sphere->indices[t + 1]], pr[sphere->indices[t + 2]]);
        if (!naive) ++naiveMisses;
    };
    for (const Vec3& target : targets) {
        for (int k = 0; k < 4; ++k) {
            const Vec3 inside = center + Vec3(u(g), u(g), u(g));
            // Origin on the line inside → target, beyond the target: outside the sphere.
            const Vec3 from = target + (target - inside) * (2.0 + k);
            shoot(Ray<Real>(V(from), V(inside) - V(from)), Real(1));
        }
        // Axis-aligned rays pass exactly through the target's Real coordinates: a ray that
        // arrives where the surface faces it (|n_k| > 0.3) enters the sphere there.
        const Vec3 n = glm::normalize(target - center);
        for (int axis = 0; axis < 3; ++axis) {
            if (std::abs(n[axis]) < 0.3) continue;
            V o(target);
            o[axis] = Real(center[axis] + (n[axis] > 0 ? 10.0 : -10.0));
            V d(0);
            d[axis] = n[axis] > 0 ? Real(-1) : Real(1);
            shoot(Ray<Real>(o, d), Real(20));
        }
    }
    EXPECT_GT(rays, 30000);
    EXPECT_EQ(misses, 0) << "of " << rays;
    // The same rays slip through a non-watertight test: they do probe the edges.
    EXPECT_GT(naiveMisses, 100);
}

}  // namespace
}  // namespace shadowlab::raytrace
