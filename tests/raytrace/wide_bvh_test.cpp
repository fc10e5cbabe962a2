// tests/raytrace/wide_bvh_test.cpp: the 4- and 8-wide BVHs' structure, their traversal against
// the binary tree and brute force, the SSE box test against the scalar one, memory per triangle.
#include "raytrace/wide_bvh.h"

#include <algorithm>
#include <cmath>
#include <cstring>
#include <limits>
#include <random>

#include <gtest/gtest.h>

#include "raytrace/memory.h"
#include "raytrace/tracer.h"
#include "tests/kit/test_scenes.h"

namespace shadowlab::raytrace {
namespace {

using test::Vec3;

struct Soup {
    std::vector<Vec3> p;  // three per triangle
    std::vector<scene::Bounds> bounds;
};

Soup triangleSoup(int count, std::mt19937_64& g) {
    std::uniform_real_distribution<double> pos(-10, 10), edge(-1.5, 1.5);
    Soup s;
    for (int i = 0; i < count; ++i) {
        const Vec3 a(pos(g), pos(g), pos(g));
        scene::Bounds b;
        for (int k = 0; k < 3; ++k) {
            s.p.push_back(k == 0 ? a : a + Vec3(edge(g), edge(g), edge(g)));
            b.extend(s.p.back());
        }
        s.bounds.push_back(b);
    }
    return s;
}

// A scene of one matte mesh holding the soup's triangles in order.
scene::Scene soupScene(const Soup& soup) {
    auto mesh = std::make_shared<scene::TriangleMesh>();
    for (const Vec3& p : soup.p) mesh->positions.push_back(p);
    for (std::uint32_t i = 0; i < soup.p.size(); ++i) mesh->indices.push_back(i);
    return test::matteMeshScene(mesh);
}

// Rays through the soup: `segments` random segments (from anywhere in it toward its middle) and a
// grid × grid of parallel rays `step` apart from below it (the coherent shadow-ray case).
std::vector<Ray<float>> soupRays(std::mt19937_64& g, int segments, int grid, float step) {
    std::uniform_real_distribution<double> u(-14, 14);
    std::vector<Ray<float>> rays;
    for (int r = 0; r < segments; ++r) {
        const Vec3 from(u(g), u(g), u(g)), to(u(g) / 2, u(g) / 2, u(g) / 2);
        rays.emplace_back(Vec3T<float>(from), Vec3T<float>(to - from));
    }
    for (int y = 0; y < grid; ++y)
        for (int x = 0; x < grid; ++x)
            rays.emplace_back(Vec3T<float>(-12.0f + step * x, -12.0f + step * y, -14.0f),
                              Vec3T<float>(0.3f, 0.4f, 1.0f));
    return rays;
}

template <typename Node>
bool boxContains(const Node& n, int c, const scene::Bounds& b) {
    for (int k = 0; k < 3; ++k)
        if (!(n.bounds[k][c] <= b.min[k] && b.max[k] <= n.bounds[3 + k][c])) return false;
    return true;
}

template <typename B>
class WideBvhTest : public ::testing::Test {};
using Widths = ::testing::Types<Bvh4, Bvh8>;
TYPED_TEST_SUITE(WideBvhTest, Widths);

TYPED_TEST(WideBvhTest, ChildBoxesBoundTheirSubtreesAndEveryPrimitiveIsInOneAlignedLeaf) {
    using W = TypeParam;  // the width under test
    constexpr int N = TypeParam::kWidth;
    std::mt19937_64 g(3);
    const Soup soup = triangleSoup(5000, g);
    const Bvh binary = Bvh::build(soup.bounds);
    const TypeParam bvh = TypeParam::collapse(binary);
    ASSERT_FALSE(bvh.empty());
    ASSERT_FALSE(W::isLeaf(bvh.root()));
    std::vector<int> seen(soup.bounds.size(), 0);
    std::size_t children = 0, interior = 0, partialWithInteriorChild = 0;
    std::vector<std::uint32_t> stack = {bvh.root()};
    while (!stack.empty()) {
        const std::uint32_t ref = stack.back();
        stack.pop_back();
        if (W::isLeaf(ref)) {
            const std::uint32_t first = W::leafFirst(ref), count = W::leafCount(ref);
            EXPECT_EQ(first % W::kLeafAlign, 0u);
            EXPECT_LE(count, 8u);
            for (std::uint32_t s = first; s < first + count; ++s) {
                const std::uint32_t p = bvh.primitives()[s];
                ASSERT_LT(p, seen.size());
                ++seen[p];
            }
            // Padding up to the next packet boundary holds no primitive.
            for (std::uint32_t s = first + count; s % W::kLeafAlign != 0; ++s)
                EXPECT_EQ(bvh.primitives()[s], W::kEmpty);
            continue;
        }
        ++interior;
        const auto& n = bvh.nodes()[ref];
        int used = 0, interiorKids = 0;
        for (std::uint32_t r : n.ref) {
            used += r != W::kEmpty;
            interiorKids += r != W::kEmpty && !W::isLeaf(r);
        }
        partialWithInteriorChild += used < N && interiorKids > 0;
        for (int c = 0; c < N; ++c) {
            if (n.ref[c] == W::kEmpty) {
                // An unused child's box is empty: lo > hi on every axis.
                for (int k = 0; k < 3; ++k) EXPECT_GT(n.bounds[k][c], n.bounds[3 + k][c]);
                continue;
            }
            ++children;
            // The child's box contains every primitive below it: check via its subtree's
            // primitives, gathered here independently.
            std::vector<std::uint32_t> sub = {n.ref[c]};
            while (!sub.empty()) {
                const std::uint32_t r = sub.back();
                sub.pop_back();
                if (W::isLeaf(r)) {
                    for (std::uint32_t s = W::leafFirst(r); s < W::leafFirst(r) + W::leafCount(r); ++s)
                        ASSERT_TRUE(boxContains(n, c, soup.bounds[bvh.primitives()[s]]));
                } else {
                    for (std::uint32_t rr : bvh.nodes()[r].ref)
                        if (rr != W::kEmpty) sub.push_back(rr);
                }
            }
            stack.push_back(n.ref[c]);
        }
    }
    for (int s : seen) ASSERT_EQ(s, 1);
    // The collapse really is N-wide: a node with fewer than N children has only leaves below it
    // (otherwise an interior child could have been opened), and the node count is well below
    // the binary tree's L − 1 interior nodes (at best 1/(N − 1) of them).
    EXPECT_EQ(partialWithInteriorChild, 0u);
    std::size_t binaryInterior = 0;
    for (const BvhNode& n : binary.nodes()) binaryInterior += n.count == 0;
    EXPECT_EQ(interior, bvh.nodes().size());
    EXPECT_LT(double(interior), (N == 4 ? 0.5 : 0.45) * double(binaryInterior));
    EXPECT_GE((N - 1) * interior, binaryInterior);
    EXPECT_GT(double(children) / double(interior), N == 4 ? 3.0 : 3.3);
}

TEST(WideBvh, EmptyAndSingleLeafTrees) {
    EXPECT_TRUE(Bvh4::build({}).empty());
    scene::Bounds b;
    b.extend(Vec3(0, 0, 0));
    b.extend(Vec3(1, 1, 0));
    const Bvh4 one = Bvh4::build({b});
    ASSERT_TRUE(Bvh4::isLeaf(one.root()));
    EXPECT_EQ(Bvh4::leafCount(one.root()), 1u);
    float tMax = 5;
    int calls = 0;
    const Ray<float> ray({0.5f, 0.5f, -1}, {0, 0, 1});
    one.traverse(ray, tMax, false, [&](std::uint32_t first, std::uint32_t count, float&) {
        EXPECT_EQ(first, 0u);
        EXPECT_EQ(count, 1u);
        ++calls;
        return false;
    });
    EXPECT_EQ(calls, 1);
}

// The SSE box test returns, bit for bit, the scalar intersectBounds answer for each child,
// including rays parallel to slabs and origins on slab planes (0·inf = NaN slab values).
TYPED_TEST(WideBvhTest, SseChildBoxTestEqualsTheScalarSlabTest) {
    constexpr int N = TypeParam::kWidth;
    std::mt19937_64 g(9);
    std::uniform_real_distribution<float> u(-4, 4);
    std::uniform_int_distribution<int> pick(0, 3);
    WideNode<N> n{};
    int disagreements = 0, entered = 0, tests = 0;
    for (int trial = 0; trial < 20000; ++trial) {
        for (int c = 0; c < N; ++c)
            for (int k = 0; k < 3; ++k) {
                const float a = std::round(u(g)), b = std::round(u(g));  // integers: origins land on planes
                n.bounds[k][c] = std::min(a, b);
                n.bounds[3 + k][c] = std::max(a, b);
            }
        Vec3T<float> o(std::round(u(g)), std::round(u(g)), std::round(u(g))), d(u(g), u(g), u(g));
        for (int k = 0; k < 3; ++k)
            if (pick(g) == 0) d[k] = pick(g) < 2 ? 0.0f : -0.0f;  // parallel to a slab
        const Ray<float> ray(o, d);
        const float tMax = trial % 2 ? std::numeric_limits<float>::infinity() : 3.0f;
        float tn[N];
        const int mask = detail::ChildBoxTest<float, N>(ray)(n, tMax, tn);
        for (int c = 0; c < N; ++c) {
            const float lo[3] = {n.bounds[0][c], n.bounds[1][c], n.bounds[2][c]};
            const float hi[3] = {n.bounds[3][c], n.bounds[4][c], n.bounds[5][c]};
            const bool scalar = intersectBounds(ray, lo, hi, tMax);
            ++tests;
            entered += scalar;
            disagreements += scalar != bool(mask & (1 << c));
        }
    }
    EXPECT_EQ(disagreements, 0) << "of " << tests;
    EXPECT_GT(entered, tests / 10);
    EXPECT_LT(entered, tests * 9 / 10);
}

template <typename Real>
class WideBvhTraversal : public ::testing::Test {};
using Reals = ::testing::Types<float, double>;
// The float build's any-hit order (WideBvh::collapse with smallFirst): a node whose child boxes'
// surface areas differ by more than a factor 2 stores its children by increasing area. Areas are
// recomputed here in double from the stored boxes; nodes within 1% of the factor make no claim.
TEST(WideBvh, FloatBuildStoresChildrenSmallestFirstWhereTheirAreasDiffer) {
    std::mt19937_64 g(4);
    Soup soup = triangleSoup(5000, g);
    // Some large triangles among the small ones, as in real scenes (Sponza's floor and walls).
    std::uniform_real_distribution<double> pos(-10, 10);
    for (int i = 0; i < 200; ++i) {
        scene::Bounds b;
        b.extend(Vec3(pos(g), pos(g), pos(g)));
        b.extend(Vec3(pos(g), pos(g), pos(g)));
        soup.bounds.push_back(b);
    }
    const Bvh8 bvh = Bvh8::buildFast(soup.bounds);
    int ordered = 0, unordered = 0;
    for (const Bvh8Node& n : bvh.nodes()) {
        std::vector<double> area;
        for (int c = 0; c < 8 && n.ref[c] != Bvh8::kEmpty; ++c) {
            const double x = double(n.bounds[3][c]) - n.bounds[0][c], y = double(n.bounds[4][c]) - n.bounds[1][c],
                         z = double(n.bounds[5][c]) - n.bounds[2][c];
            area.push_back(2 * (x * y + y * z + z * x));
        }
        const double lo = *std::min_element(area.begin(), area.end()), hi = *std::max_element(area.begin(), area.end());
        if (hi > 2.02 * lo) {
            ++ordered;
            for (std::size_t c = 1; c < area.size(); ++c) EXPECT_LE(area[c - 1], area[c] * (1 + 1e-6));
        } else if (hi < 1.98 * lo) {
            ++unordered;
        }
    }
    EXPECT_GT(ordered, 100);
    EXPECT_GT(unordered, 10);
}

TYPED_TEST_SUITE(WideBvhTraversal, Reals);

// Closest and any hit through the 8-wide tree (and closest through the 4-wide one) equal the binary tree's and brute force's: same
// t, same triangle, on random rays with and without a finite tMax.
TYPED_TEST(WideBvhTraversal, ClosestAndAnyHitEqualTheBinaryTreeAndBruteForce) {
    using Real = TypeParam;
    using V = Vec3T<Real>;
    std::mt19937_64 g(21);
    const Soup soup = triangleSoup(3000, g);
    const Bvh binary = Bvh::build(soup.bounds);
    const Bvh8 wide = Bvh8::collapse(binary);
    const Bvh4 wide4 = Bvh4::collapse(binary);
    std::vector<V> p(soup.p.begin(), soup.p.end());
    std::uniform_real_distribution<double> u(-14, 14);
    int hits = 0;
    for (int r = 0; r < 2000; ++r) {
        const Vec3 from(u(g), u(g), u(g)), to(u(g) / 2, u(g) / 2, u(g) / 2);
        const Ray<Real> ray(V(from), V(to - from));
        const Real tMax = r % 3 == 0 ? Real(0.6) : std::numeric_limits<Real>::infinity();
        auto test = [&](std::uint32_t tri, Real& tm, int& best) {
            Real t, b0, b1, b2;
            if (!intersectTriangle(ray, p[3 * tri], p[3 * tri + 1], p[3 * tri + 2], tm, false, t, b0, b1, b2))
                return false;
            tm = t;
            best = int(tri);
            return true;
        };
        Real tBrute = tMax;
        int brute = -1;
        for (std::uint32_t t = 0; t < soup.bounds.size(); ++t) test(t, tBrute, brute);
        Real tBin = tMax;
        int bin = -1;
        binary.traverse(ray, tBin, false,
                        [&](std::uint32_t slot, Real& tm) { return test(binary.primitives()[slot], tm, bin); });
        auto walk = [&](const auto& tree, bool anyHit, Real& tm, int& best) {
            return tree.traverse(ray, tm, anyHit, [&](std::uint32_t first, std::uint32_t count, Real& t) {
                bool any = false;
                for (std::uint32_t s = first; s < first + count; ++s) any |= test(tree.primitives()[s], t, best);
                return any;
            });
        };
        auto wideWalk = [&](bool anyHit, Real& tm, int& best) { return walk(wide, anyHit, tm, best); };
        Real t4 = tMax;
        int w4 = -1;
        walk(wide4, false, t4, w4);
        ASSERT_EQ(w4, brute) << "ray " << r;
        ASSERT_EQ(t4, tBrute) << "ray " << r;
        Real tWide = tMax;
        int w = -1;
        const bool found = wideWalk(false, tWide, w);
        ASSERT_EQ(found, brute >= 0) << "ray " << r;
        ASSERT_EQ(bin, brute) << "ray " << r;
        ASSERT_EQ(w, brute) << "ray " << r;
        ASSERT_EQ(tWide, tBrute) << "ray " << r;
        Real tAny = tMax;
        int a = -1;
        ASSERT_EQ(wideWalk(true, tAny, a), found) << "ray " << r;
        hits += found;
    }
    EXPECT_GT(hits, 300);
}

// The memory aim (docs/performance.md, "Setup time and memory per triangle"): vertices, normals,
// indices, BVH and the slot-ordered triangle copies together stay under 100 bytes per triangle on
// a closed mesh with normals (the common case: about half a vertex per triangle).
TEST(WideBvh, FloatTracerHoldsUnder100BytesPerTriangle) {
    scene::Scene s;
    test::addMaterial(s, "matte");
    const auto mesh = test::icosphere(Vec3(0), 1.0, 5);  // 20·4⁵ = 20,480 triangles
    test::addMesh(s, mesh);
    const Tracer<float> tracer(s);
    ASSERT_EQ(tracer.triangleCount(), 20480u);
    // What any tracer must hold at least: float positions and normals, and the indices.
    const double floor = double(mesh->positions.size() * 24 + mesh->indices.size() * 4);
    const double bytes = double(tracer.meshBytes());
    EXPECT_GT(bytes, floor + 36.0 * 20480);  // plus at least one float copy per triangle
    EXPECT_LT(bytes / 20480.0, 100.0) << bytes / 20480.0 << " bytes per triangle";
}

TEST(WideBvh, TheMemoryEstimateCoversAFlatMesh) {
    // A glTF without normals loads flat: three vertices a triangle, six times a shared mesh's
    // share. The estimate's mesh part (what the scene with the mesh adds over the scene without
    // it) must still hold what the tracer allocates.
    scene::Scene empty;
    test::addMaterial(empty, "matte");
    const auto shared = test::icosphere(Vec3(0), 1.0, 4);  // 5,120 triangles
    auto flat = std::make_shared<scene::TriangleMesh>();
    for (const std::uint32_t i : shared->indices) {
        flat->indices.push_back(std::uint32_t(flat->positions.size()));
        flat->positions.push_back(shared->positions[i]);
        flat->normals.push_back(shared->normals[i]);
    }
    scene::Scene s = empty;
    test::addMesh(s, flat);
    const Tracer<float> tracer(s);
    ASSERT_EQ(tracer.triangleCount(), 5120u);
    const std::uint64_t part =
        raytrace::estimateMemoryBytes(s, test::planFor(s)) - raytrace::estimateMemoryBytes(empty, test::planFor(empty));
    EXPECT_GE(part, tracer.meshBytes()) << double(tracer.meshBytes()) / 5120.0 << " bytes per triangle";
}

#if defined(SHADOWLAB_AVX_BOX_TEST)
// Runs the AVX test from a function compiled for AVX (only called when the CPU has it).
__attribute__((target("avx"))) int avxBoxTest(const Ray<float>& ray, const Bvh8Node& n, float tMax, float tn[8]) {
    return detail::ChildBoxTestAvx8(ray)(n, tMax, tn);
}
// The per-octant copy the tracer's walk runs, for the ray's own octant.
template <int kOctant>
__attribute__((target("avx"))) int avxOctantBoxTest(const Ray<float>& ray, const Bvh8Node& n, float tMax, float tn[8]) {
    alignas(32) float t[8];
    const int mask = detail::ChildBoxTestAvx8Octant<kOctant>(ray)(n, tMax, t);
    std::memcpy(tn, t, sizeof t);
    return mask;
}
template <int kOctant>
__attribute__((target("avx2"))) int avx2OctantBoxTest(const Ray<float>& ray, const Bvh8Node& n, float tMax,
                                                      float tn[8]) {
    alignas(32) float t[8];
    const int mask = detail::ChildBoxTestAvx2Octant<kOctant>(ray)(n, tMax, t);
    std::memcpy(tn, t, sizeof t);
    return mask;
}
using OctantBoxTest = int (*)(const Ray<float>&, const Bvh8Node&, float, float[8]);
constexpr OctantBoxTest kAvxOctant[8] = {avxOctantBoxTest<0>, avxOctantBoxTest<1>, avxOctantBoxTest<2>,
                                         avxOctantBoxTest<3>, avxOctantBoxTest<4>, avxOctantBoxTest<5>,
                                         avxOctantBoxTest<6>, avxOctantBoxTest<7>};
constexpr OctantBoxTest kAvx2Octant[8] = {avx2OctantBoxTest<0>, avx2OctantBoxTest<1>, avx2OctantBoxTest<2>,
                                          avx2OctantBoxTest<3>, avx2OctantBoxTest<4>, avx2OctantBoxTest<5>,
                                          avx2OctantBoxTest<6>, avx2OctantBoxTest<7>};
#endif

// What ChildBoxTestAvx2Octant computes for one child, written out in scalar code: slab
// distances (b − o)·inv near and (b − o)·(inv·widen) far, their maximum with +0 and their
// minimum with tMax taken on the bit patterns as signed 32-bit integers, compared as integers.
int avx2Model(const Ray<float>& ray, const Bvh8Node& n, float tMax, float tn[8]) {
    auto bits = [](float x) {
        std::int32_t i;
        std::memcpy(&i, &x, sizeof i);
        return i;
    };
    const float widen = 1 + 2 * gamma<float>(3);
    int mask = 0;
    for (int c = 0; c < 8; ++c) {
        std::int32_t near = 0, far = bits(tMax);
        for (int i = 0; i < 3; ++i) {
            const int nearRow = ray.dirIsNeg[i] ? 3 + i : i, farRow = ray.dirIsNeg[i] ? i : 3 + i;
            near = std::max(near, bits((n.bounds[nearRow][c] - ray.o[i]) * ray.invDir[i]));
            far = std::min(far, bits((n.bounds[farRow][c] - ray.o[i]) * (ray.invDir[i] * widen)));
        }
        std::memcpy(&tn[c], &near, sizeof near);
        if (!(near > far)) mask |= 1 << c;
    }
    return mask;
}

// The AVX 8-wide child-box test, and its per-octant copies, give the SSE test's mask and entry
// distances bit for bit, on the same adversarial boxes as above (integer planes, origins on
// them, axis-parallel rays).
TEST(WideBvh, AvxChildBoxTestEqualsTheSseTestBitForBit) {
#if defined(SHADOWLAB_AVX_BOX_TEST)
    if (!detail::hasAvx()) GTEST_SKIP() << "this CPU has no AVX";
    std::mt19937_64 g(77);
    std::uniform_real_distribution<float> u(-4, 4);
    std::uniform_int_distribution<int> pick(0, 3);
    Bvh8Node n{};
    int differ = 0, entered = 0;
    for (int trial = 0; trial < 40000; ++trial) {
        for (int c = 0; c < 8; ++c)
            for (int k = 0; k < 3; ++k) {
                const float a = std::round(u(g)), b = std::round(u(g));
                n.bounds[k][c] = std::min(a, b);
                n.bounds[3 + k][c] = std::max(a, b);
            }
        if (trial % 5 == 0)  // unused children: empty boxes
            for (int k = 0; k < 3; ++k) {
                n.bounds[k][7] = std::numeric_limits<float>::infinity();
                n.bounds[3 + k][7] = -std::numeric_limits<float>::infinity();
            }
        Vec3T<float> o(std::round(u(g)), std::round(u(g)), std::round(u(g))), d(u(g), u(g), u(g));
        for (int k = 0; k < 3; ++k)
            if (pick(g) == 0) d[k] = pick(g) < 2 ? 0.0f : -0.0f;
        const Ray<float> ray(o, d);
        const float tMax = trial % 2 ? std::numeric_limits<float>::infinity() : 3.0f;
        float tnSse[8], tnAvx[8], tnOct[8];
        const int sse = detail::ChildBoxTest<float, 8>(ray)(n, tMax, tnSse);
        const int avx = avxBoxTest(ray, n, tMax, tnAvx);
        const int oct = kAvxOctant[detail::octantOf(ray)](ray, n, tMax, tnOct);
        differ += (sse != avx) + (sse != oct);
        for (int c = 0; c < 8; ++c)
            if (sse & (1 << c))
                differ += (std::memcmp(&tnSse[c], &tnAvx[c], sizeof(float)) != 0) +
                          (std::memcmp(&tnSse[c], &tnOct[c], sizeof(float)) != 0);
        entered += __builtin_popcount(unsigned(sse));
    }
    EXPECT_EQ(differ, 0);
    EXPECT_GT(entered, 40000);  // the test does enter boxes (about a third of 320,000)
#else
    GTEST_SKIP() << "not an x86-64 GCC build";
#endif
}

#if defined(SHADOWLAB_AVX_BOX_TEST)
__attribute__((target("avx"))) int avxDoubleBoxTest(const Ray<double>& ray, const Bvh8Node& n, double tMax,
                                                    double tn[8]) {
    return detail::ChildBoxTestAvx8Double(ray)(n, tMax, tn);
}
#endif

// The reference's AVX box test (doubles, four children a pass) gives the scalar double test's
// masks and entry distances bit for bit on adversarial boxes (integer planes, origins on them,
// axis-parallel rays, empty children), so the reference walks the same nodes in the same order.
TEST(WideBvh, AvxDoubleChildBoxTestEqualsTheScalarTestBitForBit) {
#if defined(SHADOWLAB_AVX_BOX_TEST)
    if (!detail::hasAvx()) GTEST_SKIP() << "this CPU has no AVX";
    std::mt19937_64 g(79);
    std::uniform_real_distribution<double> u(-4, 4);
    std::uniform_int_distribution<int> pick(0, 3);
    Bvh8Node n{};
    int differ = 0, entered = 0;
    for (int trial = 0; trial < 40000; ++trial) {
        for (int c = 0; c < 8; ++c)
            for (int k = 0; k < 3; ++k) {
                const float a = float(std::round(u(g))), b = float(std::round(u(g)));
                n.bounds[k][c] = std::min(a, b);
                n.bounds[3 + k][c] = std::max(a, b);
            }
        if (trial % 5 == 0)
            for (int k = 0; k < 3; ++k) {
                n.bounds[k][3] = std::numeric_limits<float>::infinity();
                n.bounds[3 + k][3] = -std::numeric_limits<float>::infinity();
            }
        Vec3 o(std::round(u(g)), std::round(u(g)), std::round(u(g))), d(u(g), u(g), u(g));
        for (int k = 0; k < 3; ++k)
            if (pick(g) == 0) d[k] = pick(g) < 2 ? 0.0 : -0.0;
        const Ray<double> ray(o, d);
        const double tMax = trial % 2 ? std::numeric_limits<double>::infinity() : 3.0;
        double tnScalar[8], tnAvx[8];
        const int scalar = detail::ChildBoxTest<double, 8>(ray)(n, tMax, tnScalar);
        const int avx = avxDoubleBoxTest(ray, n, tMax, tnAvx);
        differ += scalar != avx;
        for (int c = 0; c < 8; ++c)
            if (scalar & (1 << c)) differ += std::memcmp(&tnScalar[c], &tnAvx[c], sizeof(double)) != 0;
        entered += __builtin_popcount(unsigned(scalar));
    }
    EXPECT_EQ(differ, 0);
    EXPECT_GT(entered, 40000);
#else
    GTEST_SKIP() << "not an x86-64 GCC build";
#endif
}

// The AVX2 box test (integer min/max, for rays with a finite inverse direction) is its scalar
// model bit for bit on adversarial boxes, and conservative: a box around a point of the ray
// segment is always entered. Points are o + t·d in double with 0 < t < tMax, boxes reach from
// there by 0 to 2 units each way (a third of them flat on some axis), rounded outward to float,
// so the exact segment meets every such box; the test must enter it whatever its rounding.
TEST(WideBvh, Avx2ChildBoxTestIsItsScalarModelAndEntersEveryBoxTheSegmentMeets) {
#if defined(SHADOWLAB_AVX_BOX_TEST)
    if (!detail::hasAvx2()) GTEST_SKIP() << "this CPU has no AVX2";
    std::mt19937_64 g(78);
    std::uniform_real_distribution<float> u(-4, 4);
    std::uniform_real_distribution<double> unit(0, 1);
    std::uniform_int_distribution<int> pick(0, 3);
    Bvh8Node n{};
    int differ = 0, entered = 0, missedContaining = 0, containing = 0;
    for (int trial = 0; trial < 40000; ++trial) {
        Vec3T<float> o(std::round(u(g)), std::round(u(g)), std::round(u(g))), d(u(g), u(g), u(g));
        for (int k = 0; k < 3; ++k)
            if (pick(g) == 0) d[k] = std::round(d[k]) == 0 ? 0.25f : std::round(d[k]);  // exact slabs
        const Ray<float> ray(o, d);
        const float tMax = trial % 2 ? std::numeric_limits<float>::infinity() : 3.0f;
        const bool around = trial % 2 == 0;  // boxes around points of the segment, else adversarial
        int mustEnter = 0;
        for (int c = 0; c < 8; ++c) {
            if (around) {
                const double t = (trial % 4 == 0 ? 3.0 : 6.0) * (0.001 + 0.998 * unit(g));
                for (int k = 0; k < 3; ++k) {
                    const double p = double(o[k]) + t * double(d[k]);
                    const double lo = pick(g) == 0 ? p : p - 2 * unit(g), hi = pick(g) == 0 ? p : p + 2 * unit(g);
                    n.bounds[k][c] = roundDown<float>(lo);
                    n.bounds[3 + k][c] = roundUp<float>(hi);
                }
                if (t < double(tMax)) mustEnter |= 1 << c;
            } else {
                for (int k = 0; k < 3; ++k) {
                    const float a = std::round(u(g)), b = std::round(u(g));
                    n.bounds[k][c] = std::min(a, b);
                    n.bounds[3 + k][c] = std::max(a, b);
                }
            }
        }
        if (trial % 5 == 0)
            for (int k = 0; k < 3; ++k) {
                n.bounds[k][7] = std::numeric_limits<float>::infinity();
                n.bounds[3 + k][7] = -std::numeric_limits<float>::infinity();
                mustEnter &= 0x7F;
            }
        float tnModel[8], tnAvx2[8];
        const int model = avx2Model(ray, n, tMax, tnModel);
        const int avx2 = kAvx2Octant[detail::octantOf(ray)](ray, n, tMax, tnAvx2);
        differ += model != avx2;
        for (int c = 0; c < 8; ++c)
            if (model & (1 << c)) differ += std::memcmp(&tnModel[c], &tnAvx2[c], sizeof(float)) != 0;
        entered += __builtin_popcount(unsigned(avx2));
        containing += __builtin_popcount(unsigned(mustEnter));
        missedContaining += __builtin_popcount(unsigned(mustEnter & ~avx2));
    }
    EXPECT_EQ(differ, 0);
    EXPECT_EQ(missedContaining, 0);
    EXPECT_GT(containing, 100000);
    EXPECT_GT(entered, 120000);
#else
    GTEST_SKIP() << "not an x86-64 GCC build";
#endif
}

// The float tracer gives the same closest hits (t, triangle, bits) and any-hit answers with the
// AVX2, AVX or SSE box test, and with or without the occluder cache: on random rays through a
// triangle soup, on coherent rays (a grid of parallel rays, like a tile's shadow rays), where
// the cache must answer most blocked rays, and on axis-parallel rays.
TEST(WideBvh, TracerAnswersAreTheSameWithAvx2AvxOrSseAndWithOrWithoutTheOccluderCache) {
    std::mt19937_64 g(31);
    const Soup soup = triangleSoup(20000, g);
    const scene::Scene s = soupScene(soup);
    const Tracer<float> tracer(s);
    std::vector<Ray<float>> rays = soupRays(g, 10000, 100, 0.05f);
    std::uniform_real_distribution<double> u(-14, 14);
    // Axis-parallel rays (an infinite inverse direction: the AVX2 walk hands them to the AVX one),
    // and rays with a component so small that its inverse is finite but times the widening
    // factor is not (also the AVX walk's) or just finite (the AVX2 walk's).
    for (int r = 0; r < 3000; ++r) {
        Vec3T<float> d(0.0f);
        d[r % 3] = r % 2 ? 1.0f : -1.0f;
        if (r >= 2000) {
            d[(r + 1) % 3] = 0.4f;
            d[(r + 2) % 3] = r % 4 < 2 ? 1.0f / std::numeric_limits<float>::max() : std::numeric_limits<float>::min();
        }
        rays.emplace_back(Vec3T<float>(Vec3(u(g), u(g), u(g))), d);
    }
    int hits = 0, differ = 0;
    std::uint64_t cacheAnswers = 0;
    for (std::size_t r = 0; r < rays.size(); ++r) {
        const Ray<float>& ray = rays[r];
        const float tMax = r % 3 == 0 ? 0.6f : std::numeric_limits<float>::infinity();
        Hit<float> h[8];
        bool found[8], any[8];
        for (int config = 0; config < 8; ++config) {
            detail::setUseAvx(config & 1);
            setOccluderCache(config & 2);
            detail::setUseAvx2(config & 4);
            found[config] = tracer.closestHit(ray, tMax, r % 2 == 0, h[config]);
            int blocker = -1;
            const std::uint64_t before = occluderCacheHits();
            any[config] = tracer.anyHit(ray, tMax, r % 2 == 0, blocker);
            cacheAnswers += occluderCacheHits() - before;
        }
        hits += found[0];
        for (int config = 1; config < 8; ++config)
            differ +=
                found[0] != found[config] || any[0] != any[config] ||
                (found[0] && (std::memcmp(&h[0].t, &h[config].t, sizeof(float)) != 0 || h[0].prim != h[config].prim));
        differ += any[0] != found[0];  // any hit exactly when a closest hit exists
    }
    detail::setUseAvx(true);
    detail::setUseAvx2(true);
    setOccluderCache(true);
    EXPECT_EQ(differ, 0);
    EXPECT_GT(hits, 3000);
    // The grid's blocked rays: most are answered by the previous ray's triangle packet.
    EXPECT_GT(cacheAnswers, 2000u);
}

// The float tracer's any-hit answer is brute force's: whether some triangle passes the scalar
// watertight test (intersectTriangle) within (0, tMax), in plain and conservative mode, with the
// AVX2, AVX or SSE walk. The any-hit walk takes each node's children in the float build's stored
// order and pushes several at once (the AVX2 walk's vector push); neither may change the answer.
// Rays: random segments and lines through a triangle soup, a grid of parallel rays (the
// coherent shadow-ray case), and rays from just above the soup's triangles (shadow-ray origins).
TEST(WideBvh, FloatTracerAnyHitIsBruteForcesAnswerWithEveryBoxTest) {
    std::mt19937_64 g(33);
    const Soup soup = triangleSoup(20000, g);
    const scene::Scene s = soupScene(soup);
    const Tracer<float> tracer(s);
    const std::vector<Vec3T<float>> p(soup.p.begin(), soup.p.end());  // the tracer's float vertices
    std::uniform_real_distribution<double> unit(0, 1);
    std::vector<Ray<float>> rays = soupRays(g, 3000, 40, 0.6f);
    for (int r = 0; r < 2000; ++r) {
        // A point inside triangle r, lifted a little, towards a fixed "sun".
        const Vec3 a = soup.p[3 * r], b = soup.p[3 * r + 1], c = soup.p[3 * r + 2];
        const double s0 = unit(g), s1 = unit(g) * (1 - s0);
        const Vec3 at = a + s0 * (b - a) + s1 * (c - a) + Vec3(0, 0.01, 0);
        rays.emplace_back(Vec3T<float>(at), Vec3T<float>(0.2f, 1.0f, -0.35f));
    }
    int blocked = 0, differ = 0;
    for (std::size_t r = 0; r < rays.size(); ++r) {
        const Ray<float>& ray = rays[r];
        const float tMax = r % 3 == 0 ? 0.6f : r % 3 == 1 ? 3.0f : std::numeric_limits<float>::infinity();
        const bool conservative = r % 2 == 0;
        bool brute = false;
        for (std::size_t t = 0; t < soup.bounds.size() && !brute; ++t) {
            float th, b0, b1, b2;
            brute = intersectTriangle(ray, p[3 * t], p[3 * t + 1], p[3 * t + 2], tMax, conservative, th, b0, b1, b2);
        }
        blocked += brute;
        for (int config = 0; config < 3; ++config) {
            detail::setUseAvx(config < 2);
            detail::setUseAvx2(config == 0);
            setOccluderCache(false);
            int blocker = -1;
            differ += tracer.anyHit(ray, tMax, conservative, blocker) != brute;
        }
    }
    detail::setUseAvx(true);
    detail::setUseAvx2(true);
    setOccluderCache(true);
    EXPECT_EQ(differ, 0);
    // Both answers are common, so a walk that always or never reports a hit fails.
    EXPECT_GT(blocked, 1000);
    EXPECT_LT(blocked, int(rays.size()) - 1000);
}

// The double tracer (the reference) gives the same closest hits (t, triangle, barycentrics, bit
// for bit) and any-hit answers with the AVX box test or the scalar one, in plain and
// conservative mode, on random and axis-parallel rays through a triangle soup.
TEST(WideBvh, DoubleTracerAnswersAreTheSameWithAvxOrScalarBoxTests) {
    std::mt19937_64 g(32);
    const Soup soup = triangleSoup(20000, g);
    const scene::Scene s = soupScene(soup);
    const Tracer<double> tracer(s);
    std::uniform_real_distribution<double> u(-14, 14);
    int hits = 0, differ = 0;
    for (int r = 0; r < 12000; ++r) {
        const Vec3 from(u(g), u(g), u(g));
        Vec3 d = Vec3(u(g) / 2, u(g) / 2, u(g) / 2) - from;
        if (r % 6 == 0) d = Vec3(0.0), d[r % 3] = r % 4 ? 1.0 : -1.0;
        const Ray<double> ray(from, d);
        const double tMax = r % 3 == 0 ? 0.6 : std::numeric_limits<double>::infinity();
        Hit<double> h[2];
        bool found[2], any[2];
        for (int config = 0; config < 2; ++config) {
            detail::setUseAvx(config == 0);
            found[config] = tracer.closestHit(ray, tMax, r % 2 == 0, h[config]);
            int blocker = -1;
            any[config] = tracer.anyHit(ray, tMax, r % 2 == 0, blocker);
        }
        hits += found[0];
        differ += found[0] != found[1] || any[0] != any[1] ||
                  (found[0] && (std::memcmp(&h[0].t, &h[1].t, sizeof(double)) != 0 || h[0].prim != h[1].prim ||
                                std::memcmp(&h[0].b1, &h[1].b1, sizeof(double)) != 0));
    }
    detail::setUseAvx(true);
    EXPECT_EQ(differ, 0);
    EXPECT_GT(hits, 3000);
}

}  // namespace
}  // namespace shadowlab::raytrace
