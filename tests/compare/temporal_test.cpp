// tests/compare/temporal_test.cpp: flicker, error variation and swimming on hand-made frames of a
// floor with one vertical shadow edge (shadow left of it, lit right), whose answers follow from
// where the edge lies.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <vector>

#include "compare/compare.h"
#include "compare/temporal.h"
#include "scene/error.h"
#include "scene/frame.h"

namespace shadowlab::compare {
namespace {

constexpr int kW = 40, kH = 12;

// Every pixel is floor (id 1, N·L 0.6). hard: V = 1 right of x = edge (pixel centers x + 0.5),
// else 0; soft: the ramp V = 0.5 + (x + 0.5 − edge)/2 clamped to 0..1, whose τ = 0.5 crossing
// interpolated between pixel centers is the edge itself.
scene::Frame edgeFrame(double edge, bool soft) {
    scene::Frame f = scene::Frame::allocate(kW, kH, false);
    for (int y = 0; y < kH; ++y)
        for (int x = 0; x < kW; ++x) {
            const std::size_t i = std::size_t(y) * kW + x;
            const double c = x + 0.5;
            const double v = soft ? std::clamp(0.5 + (c - edge) / 2.0, 0.0, 1.0) : (c > edge ? 1.0 : 0.0);
            f.visibility[i] = float(v);
            f.objectId[i] = 1.0f;
            f.ndotl[i] = 0.6f;
            f.depth[i] = 5.0f;
            f.beauty[3 * i] = f.beauty[3 * i + 1] = f.beauty[3 * i + 2] = float(0.05 + 0.5 * v);
        }
    return f;
}

std::vector<const scene::Frame*> pointers(const std::vector<scene::Frame>& frames) {
    std::vector<const scene::Frame*> p;
    for (const scene::Frame& f : frames) p.push_back(&f);
    return p;
}

TEST(TemporalMetrics, TheReferenceAgainstItselfHasNoFlickerErrorVariationOrSwim) {
    // The reference's edge moves 0.7 px a frame: its pixels change, but flicker only counts
    // changes the reference does not make.
    std::vector<scene::Frame> ref;
    for (int t = 0; t < 6; ++t) ref.push_back(edgeFrame(20.3 + 0.7 * t, false));
    const TemporalSummary s = measureTemporal(pointers(ref), pointers(ref));
    ASSERT_EQ(s.pairs.size(), 5u);
    std::size_t referenceChanges = 0;
    for (const PairStability& p : s.pairs) referenceChanges += p.referenceChanges;
    EXPECT_GT(referenceChanges, 0u);  // not a vacuous check: the frames do change
    EXPECT_EQ(s.totalFlicker, 0u);
    EXPECT_EQ(s.meanErrorVariation, 0.0);
    EXPECT_EQ(s.meanSwimPixels, 0.0);
    EXPECT_EQ(s.meanEdgeOffset, 0.0);
}

TEST(TemporalMetrics, AMethodEqualToTheReferenceInEveryFrameHasZeroFlicker) {
    std::vector<scene::Frame> ref, method;
    for (int t = 0; t < 6; ++t) {
        ref.push_back(edgeFrame(10.2 + 1.3 * t, false));
        method.push_back(edgeFrame(10.2 + 1.3 * t, false));  // a separate copy of the same frame
    }
    const TemporalSummary s = measureTemporal(pointers(method), pointers(ref));
    EXPECT_EQ(s.totalFlicker, 0u);
    EXPECT_EQ(s.maxFlickerRate, 0.0);
    EXPECT_EQ(s.maxErrorVariation, 0.0);
    EXPECT_EQ(s.maxSwimPixels, 0.0);
}

TEST(TemporalMetrics, AFixedWrongOffsetHasZeroFlickerAndNonZeroError) {
    // Still reference edge at 20.3 (its interpolated crossing: the pixel boundary x = 20); the
    // method's soft edge at 17 in every frame: its shadow is 3 px smaller. Columns 17, 18, 19
    // (centers 17.5..19.5, V ≥ 0.75 against 0) are missed shadow in every row; column 16 (V 0.25)
    // agrees.
    std::vector<scene::Frame> ref, method;
    for (int t = 0; t < 5; ++t) {
        ref.push_back(edgeFrame(20.3, false));
        method.push_back(edgeFrame(17.0, true));
    }
    const Metrics m = compareFrames(method[0], ref[0]).metrics;
    EXPECT_EQ(m.missedShadow, std::size_t(3 * kH));
    EXPECT_EQ(m.falseShadow, 0u);
    const TemporalSummary s = measureTemporal(pointers(method), pointers(ref));
    EXPECT_EQ(s.totalFlicker, 0u);
    EXPECT_EQ(s.meanErrorVariation, 0.0);
    EXPECT_EQ(s.meanSwimPixels, 0.0);
    EXPECT_NEAR(s.meanEdgeOffset, 3.0, 1e-6);  // the stable part: 3 px, the method's shadow smaller
    ASSERT_EQ(s.edges.size(), 5u);
    EXPECT_EQ(s.edges[0].referenceCrossings, std::size_t(kH));  // one per row, none along columns
    EXPECT_EQ(s.edges[0].matched, std::size_t(kH));
}

TEST(TemporalMetrics, AnEdgeThatJittersAgainstAStillReferenceFlickersAndSwimsByItsStep) {
    // The method's edge alternates between 17.2 and 17.8: column 17 (center 17.5) is lit, then
    // shadowed, then lit: one flicker pixel per row and pair; the offset alternates 2.8 / 2.2 px,
    // so every pair swims 0.6 px, and the stable part is their mean, 2.5 px.
    std::vector<scene::Frame> ref, method;
    for (int t = 0; t < 6; ++t) {
        ref.push_back(edgeFrame(20.3, false));
        method.push_back(edgeFrame(t % 2 ? 17.8 : 17.2, true));
    }
    const TemporalSummary s = measureTemporal(pointers(method), pointers(ref));
    ASSERT_EQ(s.pairs.size(), 5u);
    for (const PairStability& p : s.pairs) {
        EXPECT_EQ(p.flicker, std::size_t(kH));
        EXPECT_EQ(p.referenceChanges, 0u);
        EXPECT_DOUBLE_EQ(p.flickerRate, 1.0 / kW);
        EXPECT_NEAR(p.swimPixels, 0.6, 1e-6);
        EXPECT_EQ(p.trackedEdges, std::size_t(kH));
        // Column 17 goes between V 0.65 and 0.35 (|error| 0.65 / 0.35), column 18 between 1 and
        // 0.85, column 16 between 0.15 and 0: (0.3 + 0.15 + 0.15)/40 per row.
        EXPECT_NEAR(p.errorVariation, 0.6 / kW, 1e-6);
    }
    EXPECT_NEAR(s.meanEdgeOffset, 2.5, 1e-6);
    EXPECT_EQ(s.worstPair, 0);
}

TEST(TemporalMetrics, AStableOffsetMovingWithTheImageFlickersButDoesNotSwim) {
    // The image moves one pixel a frame (a panning camera): reference edge at 20.3 + t, the
    // method 3 px to its left at every frame. Compared at the same image position, the method's
    // column changes where the reference's does not (one pixel a row: the documented limit of
    // image-position flicker under camera motion); the offset stays 3 px, so swimming is 0.
    std::vector<scene::Frame> ref, method;
    for (int t = 0; t < 5; ++t) {
        ref.push_back(edgeFrame(20.3 + t, false));
        method.push_back(edgeFrame(17.0 + t, true));
    }
    const TemporalSummary s = measureTemporal(pointers(method), pointers(ref));
    for (const PairStability& p : s.pairs) {
        EXPECT_EQ(p.flicker, std::size_t(kH));
        EXPECT_EQ(p.missedChanges, std::size_t(kH));
        EXPECT_EQ(p.trackedEdges, std::size_t(kH));
        EXPECT_NEAR(p.swimPixels, 0.0, 1e-6);
    }
    EXPECT_NEAR(s.meanEdgeOffset, 3.0, 1e-6);
}

TEST(TemporalMetrics, FramesOfDifferentSizesAreRejected) {
    std::vector<scene::Frame> a{edgeFrame(10, false), edgeFrame(10, false)};
    std::vector<scene::Frame> b{edgeFrame(10, false), scene::Frame::allocate(3, 3, false)};
    EXPECT_THROW(measureTemporal(pointers(a), pointers(b)), scene::InputError);
    std::vector<scene::Frame> c{edgeFrame(10, false)};
    EXPECT_THROW(measureTemporal(pointers(a), pointers(c)), scene::InputError);
}

}  // namespace
}  // namespace shadowlab::compare
