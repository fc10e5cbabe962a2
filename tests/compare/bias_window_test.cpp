// tests/compare/bias_window_test.cpp: the bias window of synthetic acne/leak curves whose
// crossings are solved by hand, a stiff case, and the edge rules.
#include "compare/bias_window.h"

#include <algorithm>
#include <cmath>

#include <gtest/gtest.h>

#include "scene/error.h"

namespace shadowlab::compare {
namespace {

// Acne falls off exponentially with bias, leaks grow quadratically:
//   false(b) = 0.1·exp(−b/0.001)          ≤ T=0.001  ⇔  b ≥ 0.001·ln(100) ≈ 0.004605
//   missed(b) = 0.02·(b/leakScale)²       ≤ T        ⇔  b ≤ leakScale·√0.05
std::vector<BiasSample> curves(double leakScale) {
    std::vector<BiasSample> s;
    for (int k = 1; k <= 40; ++k) {  // b = 0.0005 .. 0.02
        const double b = 0.0005 * k;
        s.push_back({b, 0.1 * std::exp(-b / 0.001), 0.02 * (b / leakScale) * (b / leakScale)});
    }
    return s;
}

TEST(BiasWindow, IsTheSampledRangeBetweenTheTwoCrossings) {
    // leakScale 0.05: missed ≤ T for b ≤ 0.05·√0.05 ≈ 0.01118. Samples are multiples of
    // 0.0005, so the window is [0.005, 0.011] with 13 samples and failing neighbours 0.0045, 0.0115.
    const BiasWindow w = findBiasWindow(curves(0.05), 0.001);
    ASSERT_FALSE(w.stiff);
    EXPECT_NEAR(w.lo, 0.005, 1e-12);
    EXPECT_NEAR(w.hi, 0.011, 1e-12);
    EXPECT_EQ(w.acceptableSamples, 13u);
    EXPECT_NEAR(w.outerLo, 0.0045, 1e-12);
    EXPECT_NEAR(w.outerHi, 0.0115, 1e-12);
    EXPECT_NE(w.describe().find("bias window 0.005 .. 0.011"), std::string::npos) << w.describe();
}

TEST(BiasWindow, SampleOrderDoesNotMatter) {
    auto s = curves(0.05);
    std::reverse(s.begin(), s.end());
    std::rotate(s.begin(), s.begin() + 17, s.end());
    const BiasWindow w = findBiasWindow(s, 0.001);
    EXPECT_NEAR(w.lo, 0.005, 1e-12);
    EXPECT_NEAR(w.hi, 0.011, 1e-12);
}

TEST(BiasWindow, StiffWhenLeaksStartBeforeAcneEnds) {
    // leakScale 0.01: missed ≤ T only for b ≤ 0.01·√0.05 ≈ 0.00224, but acne needs
    // b ≥ 0.0046: no bias is good for both.
    const auto s = curves(0.01);
    const BiasWindow w = findBiasWindow(s, 0.001);
    EXPECT_TRUE(w.stiff);
    EXPECT_NE(w.describe().find("stiff"), std::string::npos);
    // The best compromise minimises max(false, missed): check it against every sample.
    const double bestWorst = std::max(w.bestFalseShadowRate, w.bestMissedShadowRate);
    for (const auto& x : s) EXPECT_LE(bestWorst, std::max(x.falseShadowRate, x.missedShadowRate));
    // The curves cross between 0.0025 and 0.0045 (false falls, missed rises through there).
    EXPECT_GE(w.bestBias, 0.0025);
    EXPECT_LE(w.bestBias, 0.0045);
}

TEST(BiasWindow, EdgeRules) {
    // A rate equal to the threshold is acceptable; NaN is not; the longest run wins.
    const std::vector<BiasSample> s = {
        {1, 0.001, 0.0},   // ok (run of 1)
        {2, 0.5, 0.0},     // acne
        {3, 0.0, 0.0005},  // ok
        {4, 0.0, 0.001},   // ok: exactly at the threshold
        {5, NAN, 0.0},     // failed row
        {6, 0.0, 0.0},     // ok (run of 1)
    };
    const BiasWindow w = findBiasWindow(s, 0.001);
    ASSERT_FALSE(w.stiff);
    EXPECT_EQ(w.lo, 3);
    EXPECT_EQ(w.hi, 4);
    EXPECT_EQ(w.outerLo, 2);
    EXPECT_EQ(w.outerHi, 5);
    // A run reaching the end of the sampled range has no outer limit there.
    const BiasWindow end = findBiasWindow({{1, 0.5, 0}, {2, 0, 0}}, 0.001);
    EXPECT_EQ(end.lo, 2);
    EXPECT_TRUE(std::isinf(end.outerHi));
    EXPECT_THROW(findBiasWindow({}, 0.001), scene::InputError);
    EXPECT_THROW(findBiasWindow(s, -1.0), scene::InputError);
    EXPECT_THROW(findBiasWindow(s, NAN), scene::InputError);
}

}  // namespace
}  // namespace shadowlab::compare
