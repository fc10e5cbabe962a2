// tests/compare/pareto_test.cpp: the Pareto front of a hand-made point set, and agreement with
// the O(n²) definition on a pseudo-random set.
#include "compare/pareto.h"

#include <cmath>

#include <gtest/gtest.h>

#include "tests/compare/synthetic.h"

namespace shadowlab::compare {
namespace {

TEST(ParetoFront, KeepsExactlyTheNonDominatedPointsInTimeOrder) {
    const std::vector<TimeErrorPoint> p = {
        {10, 0.5},   // 0 front
        {20, 0.2},   // 1 front
        {15, 0.6},   // 2 dominated by 0 (faster and more accurate)
        {40, 0.2},   // 3 dominated by 1 (same error, slower)
        {50, 0.05},  // 4 front
        {20, 0.2},   // 5 duplicate of 1: kept, neither dominates
        {5, 0.9},    // 6 front: the fastest
        {NAN, 0.0},  // 7 failed row: never on the front
        {60, 0.05},  // 8 dominated by 4
        {30, 0.1},   // 9 front
    };
    EXPECT_EQ(paretoFront(p), (std::vector<std::size_t>{6, 0, 1, 5, 9, 4}));
    EXPECT_TRUE(paretoFront({}).empty());
    EXPECT_EQ(paretoFront({{3, 0.1}}), (std::vector<std::size_t>{0}));
}

TEST(ParetoFront, MatchesTheDefinitionOnManyPoints) {
    std::vector<TimeErrorPoint> p;
    for (int i = 0; i < 300; ++i)  // coarse values so that ties happen
        p.push_back({std::round(100 * test::hashNoise(i, 1)), std::round(50 * test::hashNoise(i, 2)) / 50});
    auto dominated = [&](std::size_t i) {
        for (std::size_t j = 0; j < p.size(); ++j)
            if (p[j].timeMs <= p[i].timeMs && p[j].error <= p[i].error &&
                (p[j].timeMs < p[i].timeMs || p[j].error < p[i].error))
                return true;
        return false;
    };
    const auto front = paretoFront(p);
    std::vector<bool> onFront(p.size(), false);
    for (const auto i : front) onFront[i] = true;
    for (std::size_t i = 0; i < p.size(); ++i) EXPECT_EQ(onFront[i], !dominated(i)) << i;
    for (std::size_t k = 1; k < front.size(); ++k) {
        EXPECT_LE(p[front[k - 1]].timeMs, p[front[k]].timeMs);
        EXPECT_GE(p[front[k - 1]].error, p[front[k]].error);
    }
}

}  // namespace
}  // namespace shadowlab::compare
