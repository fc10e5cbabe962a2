// tests/raytrace/parallel_build_test.cpp: the TBB-parallel BVH build makes the same tree, byte
// for byte, whatever the number of threads, and that tree is a valid BVH over every primitive.
#include <cstring>
#include <random>

#include <gtest/gtest.h>
#include <tbb/task_arena.h>

#include "raytrace/bvh.h"
#include "raytrace/tolerances.h"
#include "raytrace/wide_bvh.h"
#include "tests/kit/test_scenes.h"

namespace shadowlab::raytrace {
namespace {

using scene::Vec3;

using test::randomBoxes;

Bvh buildWith(int threads, const std::vector<scene::Bounds>& boxes) {
    tbb::task_arena arena(threads);
    Bvh bvh;
    arena.execute([&] { bvh = Bvh::build(boxes); });
    return bvh;
}

bool sameTree(const Bvh& a, const Bvh& b) {
    return a.nodes().size() == b.nodes().size() && a.primitives() == b.primitives() && a.depth() == b.depth() &&
           std::memcmp(a.nodes().data(), b.nodes().data(), a.nodes().size() * sizeof(BvhNode)) == 0;
}

TEST(ParallelBuild, TheTreeDoesNotDependOnTheThreadCount) {
    // 60,000 primitives: far above kBvhParallelCount, so the top levels split into tasks.
    const auto boxes = randomBoxes(60000, 99);
    ASSERT_GT(boxes.size(), 8 * std::size_t(kBvhParallelCount));
    const Bvh one = buildWith(1, boxes);
    for (int threads : {2, 4, 8}) {
        for (int run = 0; run < 2; ++run) {  // twice: a race would rarely repeat exactly
            SCOPED_TRACE(threads);
            EXPECT_TRUE(sameTree(one, buildWith(threads, boxes)));
        }
    }
    // And the collapsed 8-wide tree built from it, including its slot order.
    tbb::task_arena a1(1), a4(4);
    Bvh8 w1, w4;
    a1.execute([&] { w1 = Bvh8::build(boxes); });
    a4.execute([&] { w4 = Bvh8::build(boxes); });
    ASSERT_EQ(w1.nodes().size(), w4.nodes().size());
    EXPECT_EQ(w1.primitives(), w4.primitives());
    EXPECT_EQ(std::memcmp(w1.nodes().data(), w4.nodes().data(), w1.nodes().size() * sizeof(Bvh8Node)), 0);
}

TEST(ParallelBuild, TheParallelTreeHoldsEveryPrimitiveOnceInsideItsNodesBoxes) {
    const auto boxes = randomBoxes(60000, 7);
    const Bvh bvh = buildWith(4, boxes);
    std::vector<int> seen(boxes.size(), 0);
    // Depth-first walk: node i's first child is i + 1, its second `offset` (> i + 1).
    std::vector<std::pair<std::uint32_t, int>> stack = {{0u, 0}};
    int deepest = 0;
    while (!stack.empty()) {
        const auto [i, depth] = stack.back();
        stack.pop_back();
        ASSERT_LT(i, bvh.nodes().size());
        const BvhNode& n = bvh.nodes()[i];
        deepest = std::max(deepest, depth);
        auto inside = [&](const scene::Bounds& b) {
            for (int k = 0; k < 3; ++k)
                if (!(n.lo[k] <= b.min[k] && b.max[k] <= n.hi[k])) return false;
            return true;
        };
        if (n.count > 0) {
            for (std::uint32_t s = n.offset; s < n.offset + n.count; ++s) {
                const std::uint32_t p = bvh.primitives().at(s);
                ++seen.at(p);
                EXPECT_TRUE(inside(boxes[p])) << p;
            }
            continue;
        }
        ASSERT_GT(n.offset, i + 1);
        stack.push_back({n.offset, depth + 1});
        stack.push_back({i + 1, depth + 1});
    }
    for (std::size_t p = 0; p < seen.size(); ++p) ASSERT_EQ(seen[p], 1) << p;
    EXPECT_EQ(deepest, bvh.depth());
}

}  // namespace
}  // namespace shadowlab::raytrace
