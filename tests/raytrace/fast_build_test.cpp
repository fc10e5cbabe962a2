// tests/raytrace/fast_build_test.cpp: the float build (Bvh::buildFast) the float tracer uses is
// a valid tree over every primitive, independent of the thread count, and the float tracer's
// answers are the same on its tree and on the reference's (double-built) tree, exact ties
// included: a tie goes to the lowest triangle index whatever the tree's order.
#include <algorithm>
#include <cmath>
#include <cstring>
#include <limits>
#include <random>

#include <gtest/gtest.h>
#include <tbb/task_arena.h>

#include "raytrace/bvh.h"
#include "raytrace/tolerances.h"
#include "raytrace/tracer.h"
#include "raytrace/wide_bvh.h"
#include "tests/kit/test_scenes.h"

namespace shadowlab::raytrace {
namespace {

using scene::Vec3;

using test::randomBoxes;

TEST(FastBuild, TheTreeDoesNotDependOnTheThreadCount) {
    const auto boxes = randomBoxes(60000, 5);
    tbb::task_arena a1(1), a4(4);
    Bvh t1, t4;
    a1.execute([&] { t1 = Bvh::buildFast(boxes); });
    a4.execute([&] { t4 = Bvh::buildFast(boxes); });
    ASSERT_EQ(t1.nodes().size(), t4.nodes().size());
    EXPECT_EQ(t1.primitives(), t4.primitives());
    EXPECT_EQ(std::memcmp(t1.nodes().data(), t4.nodes().data(), t1.nodes().size() * sizeof(BvhNode)), 0);
}

TEST(FastBuild, HoldsEveryPrimitiveOnceInsideItsNodesBoxes) {
    const auto boxes = randomBoxes(60000, 8);
    const Bvh bvh = Bvh::buildFast(boxes);
    std::vector<int> seen(boxes.size(), 0);
    std::vector<std::uint32_t> stack = {0u};
    std::size_t leafPrims = 0;
    while (!stack.empty()) {
        const std::uint32_t i = stack.back();
        stack.pop_back();
        ASSERT_LT(i, bvh.nodes().size());
        const BvhNode& n = bvh.nodes()[i];
        if (n.count > 0) {
            EXPECT_LE(n.count, kBvhMaxLeafCount);
            for (std::uint32_t s = n.offset; s < n.offset + n.count; ++s) {
                const std::uint32_t p = bvh.primitives().at(s);
                ++seen.at(p);
                ++leafPrims;
                // The float box contains the double box (outward rounding, exact unions).
                for (int k = 0; k < 3; ++k)
                    EXPECT_TRUE(double(n.lo[k]) <= boxes[p].min[k] && boxes[p].max[k] <= double(n.hi[k])) << p;
            }
            continue;
        }
        ASSERT_GT(n.offset, i + 1);
        // A parent's box contains its children's.
        for (std::uint32_t c : {i + 1, n.offset})
            for (int k = 0; k < 3; ++k) EXPECT_TRUE(n.lo[k] <= bvh.nodes()[c].lo[k] && bvh.nodes()[c].hi[k] <= n.hi[k]);
        stack.push_back(n.offset);
        stack.push_back(i + 1);
    }
    EXPECT_EQ(leafPrims, boxes.size());
    for (std::size_t p = 0; p < seen.size(); ++p) ASSERT_EQ(seen[p], 1) << p;
}

// A node's box is exactly what it holds: a leaf's, the union of its primitives' boxes rounded
// outward to float; an interior node's, the union of its children's. A child's box comes from
// its parent's bins and its centroid bounds from the partition, across the two arrays the
// partitions move the references between: the box must be the tight one, not merely one that
// contains it.
TEST(FastBuild, NodeBoxesAreTheUnionsOfWhatTheyHold) {
    const auto boxes = randomBoxes(60000, 11);
    const Bvh bvh = Bvh::buildFast(boxes);
    auto down = [](double x) {
        const float f = float(x);
        return double(f) > x ? std::nextafter(f, -std::numeric_limits<float>::infinity()) : f;
    };
    auto up = [](double x) {
        const float f = float(x);
        return double(f) < x ? std::nextafter(f, std::numeric_limits<float>::infinity()) : f;
    };
    const auto& nodes = bvh.nodes();
    for (std::size_t i = 0; i < nodes.size(); ++i) {
        const BvhNode& n = nodes[i];
        float lo[3], hi[3];
        for (int k = 0; k < 3; ++k) {
            lo[k] = std::numeric_limits<float>::infinity();
            hi[k] = -std::numeric_limits<float>::infinity();
        }
        if (n.count > 0) {
            for (std::uint32_t s = n.offset; s < n.offset + n.count; ++s) {
                const scene::Bounds& b = boxes[bvh.primitives()[s]];
                for (int k = 0; k < 3; ++k) {
                    lo[k] = std::min(lo[k], down(b.min[k]));
                    hi[k] = std::max(hi[k], up(b.max[k]));
                }
            }
        } else {
            for (const std::size_t c : {i + 1, std::size_t(n.offset)})
                for (int k = 0; k < 3; ++k) {
                    lo[k] = std::min(lo[k], nodes[c].lo[k]);
                    hi[k] = std::max(hi[k], nodes[c].hi[k]);
                }
        }
        for (int k = 0; k < 3; ++k) {
            ASSERT_EQ(n.lo[k], lo[k]) << "node " << i << " axis " << k;
            ASSERT_EQ(n.hi[k], hi[k]) << "node " << i << " axis " << k;
        }
    }
}

// The tree's SAH cost, computed here from its nodes alone: Σ over nodes of the node's surface
// area times its cost (kBvhTraversalCost for an interior node, ⌈n/4⌉ packets for a leaf of n),
// over the root's area.
double sahCost(const Bvh& bvh) {
    auto area = [](const BvhNode& n) {
        const double x = double(n.hi[0]) - n.lo[0], y = double(n.hi[1]) - n.lo[1], z = double(n.hi[2]) - n.lo[2];
        return 2.0 * (x * y + y * z + z * x);
    };
    double cost = 0;
    for (const BvhNode& n : bvh.nodes())
        cost += area(n) * (n.count == 0 ? kBvhTraversalCost : double((n.count + kBvhLeafBlock - 1) / kBvhLeafBlock));
    return cost / area(bvh.nodes().front());
}

// The float build is the double build's SAH on rounded boxes: its tree may differ, its cost barely
// (within 0.01% on these boxes). Each child range's centroid bounds scale its bins; bounds found
// wrongly by the partition still give a valid tree, only a worse one (the two sides' swapped:
// 0.7–0.8% dearer), which only this cost shows.
TEST(FastBuild, ItsTreeCostsAboutWhatTheDoubleBuildsDoes) {
    for (const std::uint64_t seed : {3u, 21u}) {
        const auto boxes = randomBoxes(60000, seed);
        const double fast = sahCost(Bvh::buildFast(boxes)), exact = sahCost(Bvh::build(boxes));
        EXPECT_LT(fast, 1.003 * exact) << "seed " << seed << ": " << fast << " against " << exact;
    }
}

// Appends triangle (a, b, c) with three vertices of its own.
void addTriangle(scene::TriangleMesh& mesh, const Vec3& a, const Vec3& b, const Vec3& c) {
    const std::uint32_t base = std::uint32_t(mesh.positions.size());
    for (const Vec3& p : {a, b, c}) mesh.positions.push_back(p);
    for (std::uint32_t k = 0; k < 3; ++k) mesh.indices.push_back(base + k);
}

// A soup of random triangles plus, scattered through the index list, several exact copies of
// a few triangles (so the trees put copies in different leaves, in different orders) and a grid
// of coplanar squares sharing edges (rays through shared edges and vertices hit two or more
// triangles at one t).
std::shared_ptr<scene::TriangleMesh> soupWithTies(std::mt19937_64& g) {
    auto mesh = std::make_shared<scene::TriangleMesh>();
    std::uniform_real_distribution<double> u(-10, 10), d(-1, 1);
    auto tri = [&](Vec3 a, Vec3 b, Vec3 c) { addTriangle(*mesh, a, b, c); };
    std::vector<std::array<Vec3, 3>> copies;
    for (int i = 0; i < 6; ++i) {
        const Vec3 c(u(g), u(g), u(g));
        copies.push_back({c + Vec3(-3, -3, 0.1 * i), c + Vec3(3, -3, 0), c + Vec3(0, 3, 0.2)});
    }
    for (int i = 0; i < 6000; ++i) {
        if (i % 500 == 17) {
            const auto& t = copies[(i / 500) % copies.size()];
            tri(t[0], t[1], t[2]);
            continue;
        }
        const Vec3 c(u(g), u(g), u(g));
        tri(c + 0.4 * Vec3(d(g), d(g), d(g)), c + 0.4 * Vec3(d(g), d(g), d(g)), c + 0.4 * Vec3(d(g), d(g), d(g)));
    }
    for (int y = 0; y < 20; ++y)
        for (int x = 0; x < 20; ++x) {
            const Vec3 p(-10 + x, -10 + y, 11);
            tri(p, p + Vec3(1, 0, 0), p + Vec3(1, 1, 0));
            tri(p, p + Vec3(1, 1, 0), p + Vec3(0, 1, 0));
        }
    return mesh;
}

// How many of the ray's two answers differ between two tracers of the same mesh (0, 1 or 2): the
// closest hit bit for bit (t, triangle, barycentrics) and whether anything is hit at all.
// `hits` counts the closest hits of `fast`.
template <class T>
int answersDiffer(const T& fast, const T& reference, const Ray<float>& ray, bool conservative, int& hits) {
    constexpr float kFar = std::numeric_limits<float>::infinity();
    Hit<float> a, b;
    const bool fa = fast.closestHit(ray, kFar, conservative, a);
    const bool fb = reference.closestHit(ray, kFar, conservative, b);
    hits += fa;
    const bool closest = fa != fb || (fa && (std::memcmp(&a.t, &b.t, sizeof(float)) != 0 || a.prim != b.prim ||
                                             std::memcmp(&a.b1, &b.b1, sizeof(float)) != 0));
    int x = -1, y = -1;
    const bool any = fast.anyHit(ray, kFar, conservative, x) != reference.anyHit(ray, kFar, conservative, y);
    return int(closest) + int(any);
}

TEST(FastBuild, FloatTracerHitsAreTheSameOnItsTreeAndOnTheReferenceTree) {
    std::mt19937_64 g(41);
    scene::Scene s = test::matteMeshScene(soupWithTies(g));
    const Tracer<float> fast(s);
    detail::setFastFloatBuild(false);
    const Tracer<float> reference(s);
    detail::setFastFloatBuild(true);
    std::uniform_real_distribution<double> u(-12, 12);
    std::vector<Ray<float>> rays;
    for (int r = 0; r < 20000; ++r) {
        const Vec3 from(u(g), u(g), -30), to(u(g), u(g), u(g));
        rays.emplace_back(Vec3T<float>(from), Vec3T<float>(to - from));
    }
    // Rays down the grid's shared edges and through its vertices (integer x or y).
    for (int k = 0; k < 400; ++k)
        rays.emplace_back(Vec3T<float>(float(-10 + k % 20), float(-10 + 0.05 * k), -30.0f), Vec3T<float>(0, 0, 1));
    int differ = 0, hits = 0;
    for (const Ray<float>& ray : rays)
        for (bool conservative : {false, true}) differ += answersDiffer(fast, reference, ray, conservative, hits);
    EXPECT_EQ(differ, 0);
    EXPECT_GT(hits, 10000);
}

// Large triangles across the whole mesh box (slanted, and axis-aligned ones whose edges lie on
// their boxes' faces) among small ones: the pre-split build cuts the large ones into pieces.
std::shared_ptr<scene::TriangleMesh> largeAndSmall(std::mt19937_64& g) {
    auto mesh = std::make_shared<scene::TriangleMesh>();
    std::uniform_real_distribution<double> u(-10, 10), d(-1, 1);
    auto tri = [&](Vec3 a, Vec3 b, Vec3 c) { addTriangle(*mesh, a, b, c); };
    for (int i = 0; i < 60; ++i) tri(Vec3(u(g), u(g), u(g)), Vec3(u(g), u(g), u(g)), Vec3(u(g), u(g), u(g)));
    for (int i = 0; i < 20; ++i) {
        const double z = u(g);
        tri(Vec3(-10, -10, z), Vec3(10, -10 + i, z), Vec3(-10 + i, 10, z));
    }
    for (int i = 0; i < 3000; ++i) {
        const Vec3 c(u(g), u(g), u(g));
        tri(c + 0.3 * Vec3(d(g), d(g), d(g)), c + 0.3 * Vec3(d(g), d(g), d(g)), c + 0.3 * Vec3(d(g), d(g), d(g)));
    }
    return mesh;
}

// Every point of every triangle lies in the box of some leaf that holds the triangle: the pieces'
// boxes cover their triangle, whatever the split planes.
TEST(FastBuild, PresplitPiecesCoverTheirTriangles) {
    std::mt19937_64 g(45);
    const auto mesh = largeAndSmall(g);
    const std::size_t n = mesh->indices.size() / 3;
    std::vector<scene::Bounds> boxes(n);
    std::vector<Vec3T<float>> positions;
    for (const Vec3& p : mesh->positions) positions.emplace_back(p);
    for (std::size_t t = 0; t < n; ++t)
        for (int k = 0; k < 3; ++k) boxes[t].extend(mesh->positions[mesh->indices[3 * t + k]]);
    const Bvh bvh = Bvh::buildFast(boxes, positions, mesh->indices);
    EXPECT_GT(bvh.primitives().size(), n);  // some triangles were split
    std::vector<std::vector<std::uint32_t>> leavesOf(n);
    for (std::uint32_t i = 0; i < bvh.nodes().size(); ++i)
        if (bvh.nodes()[i].count > 0)
            for (std::uint32_t s = 0; s < bvh.nodes()[i].count; ++s)
                leavesOf.at(bvh.primitives()[bvh.nodes()[i].offset + s]).push_back(i);
    std::uniform_real_distribution<double> u(0, 1);
    for (std::size_t t = 0; t < n; ++t) {
        ASSERT_FALSE(leavesOf[t].empty()) << t;
        for (int sample = 0; sample < 200; ++sample) {
            double a = u(g), b = u(g);
            if (a + b > 1) a = 1 - a, b = 1 - b;
            // Vertices and edge points exactly, the rest inside.
            if (sample < 3) a = sample == 1, b = sample == 2;
            Vec3T<double> p(0);
            for (int k = 0; k < 3; ++k) {
                const double w = k == 0 ? 1 - a - b : (k == 1 ? a : b);
                p += w * Vec3T<double>(positions[mesh->indices[3 * t + k]]);
            }
            bool inside = false;
            for (std::uint32_t leaf : leavesOf[t]) {
                const BvhNode& nd = bvh.nodes()[leaf];
                bool in = true;
                // (1e-12: the sample's own rounding in double, far below any float box's step)
                for (int k = 0; k < 3; ++k)
                    in = in && double(nd.lo[k]) - 1e-12 <= p[k] && p[k] <= double(nd.hi[k]) + 1e-12;
                inside = inside || in;
            }
            ASSERT_TRUE(inside) << "triangle " << t << " sample " << sample;
        }
    }
}

TEST(FastBuild, ThePresplitTreeDoesNotDependOnTheThreadCount) {
    std::mt19937_64 g(49);
    const auto mesh = largeAndSmall(g);
    std::vector<scene::Bounds> boxes(mesh->indices.size() / 3);
    std::vector<Vec3T<float>> positions;
    for (const Vec3& p : mesh->positions) positions.emplace_back(p);
    for (std::size_t t = 0; t < boxes.size(); ++t)
        for (int k = 0; k < 3; ++k) boxes[t].extend(mesh->positions[mesh->indices[3 * t + k]]);
    tbb::task_arena a1(1), a4(4);
    Bvh t1, t4;
    a1.execute([&] { t1 = Bvh::buildFast(boxes, positions, mesh->indices); });
    a4.execute([&] { t4 = Bvh::buildFast(boxes, positions, mesh->indices); });
    ASSERT_EQ(t1.nodes().size(), t4.nodes().size());
    EXPECT_EQ(t1.primitives(), t4.primitives());
    EXPECT_EQ(std::memcmp(t1.nodes().data(), t4.nodes().data(), t1.nodes().size() * sizeof(BvhNode)), 0);
}

// The float tracer finds the same hits with pre-split triangles as without: rays at random and
// rays aimed at the large triangles' edges, where a piece's box is tightest.
TEST(FastBuild, PresplitTreeGivesTheSameHitsAsTheReferenceTree) {
    std::mt19937_64 g(47);
    const auto mesh = largeAndSmall(g);
    scene::Scene s = test::matteMeshScene(mesh);
    const Tracer<float> fast(s);
    detail::setFastFloatBuild(false);
    const Tracer<float> reference(s);
    detail::setFastFloatBuild(true);
    std::uniform_real_distribution<double> u(-12, 12), w(0, 1);
    std::vector<Ray<float>> rays;
    for (int r = 0; r < 10000; ++r) {
        const Vec3 from(u(g), u(g), -30), to(u(g), u(g), u(g));
        rays.emplace_back(Vec3T<float>(from), Vec3T<float>(to - from));
    }
    for (int t = 0; t < 80; ++t)  // the large triangles
        for (int r = 0; r < 150; ++r) {
            const int e = r % 3;
            const Vec3 a = mesh->positions[mesh->indices[3 * t + e]];
            const Vec3 b = mesh->positions[mesh->indices[3 * t + (e + 1) % 3]];
            const Vec3 to = a + w(g) * (b - a);
            const Vec3 from(u(g), u(g), r % 2 ? -30 : 30);
            rays.emplace_back(Vec3T<float>(from), Vec3T<float>(to - from));
        }
    int differ = 0, hits = 0;
    for (const Ray<float>& ray : rays) differ += answersDiffer(fast, reference, ray, false, hits);
    EXPECT_EQ(differ, 0);
    EXPECT_GT(hits, 10000);
}

TEST(FastBuild, AnExactTieGoesToTheLowestTriangleIndexOnEitherTree) {
    std::mt19937_64 g(43);
    const auto mesh = soupWithTies(g);
    scene::Scene s = test::matteMeshScene(mesh);
    for (bool fastTree : {true, false}) {
        detail::setFastFloatBuild(fastTree);
        const Tracer<float> tracer(s);
        detail::setFastFloatBuild(true);
        // Along +z through each copy's centroid: both copies of its group are hit at one t.
        int checked = 0;
        for (std::size_t t = 17; t < 6000; t += 500) {
            const std::size_t lowest = 17 + 500 * ((t / 500) % 6);  // the group's first copy
            const Vec3 a = mesh->positions[mesh->indices[3 * t]];
            const Vec3 m =
                (a + mesh->positions[mesh->indices[3 * t + 1]] + mesh->positions[mesh->indices[3 * t + 2]]) / 3.0;
            const Ray<float> ray(Vec3T<float>(m + Vec3(0, 0, -40)), Vec3T<float>(0, 0, 1));
            Hit<float> h;
            ASSERT_TRUE(tracer.closestHit(ray, std::numeric_limits<float>::infinity(), false, h));
            if (!(mesh->positions[mesh->indices[3 * std::size_t(h.prim)]] == a)) continue;  // a soup triangle in front
            EXPECT_EQ(std::size_t(h.prim), lowest)
                << "triangle " << t << (fastTree ? " (fast tree)" : " (reference tree)");
            ++checked;
        }
        EXPECT_GE(checked, 8);  // 10 of the 12 copies are not behind a soup triangle
    }
}

}  // namespace
}  // namespace shadowlab::raytrace
