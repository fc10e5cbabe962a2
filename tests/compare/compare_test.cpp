// tests/compare/compare_test.cpp: the classification rule, the diff colors and every metric on
// hand-built frames whose answers are counted by hand in the comments.
#include "compare/compare.h"

#include <cmath>
#include <filesystem>
#include <limits>

#include <gtest/gtest.h>

#include "scene/error.h"
#include "scene/frame_identity.h"
#include "scene/frame_io.h"
#include "tests/compare/synthetic.h"

namespace shadowlab::compare {
namespace {

using scene::Frame;

// One pixel of a hand-built pair of frames.
struct Px {
    float idM, idR;  // object ids
    float nM, nR;    // N·L
    float vM, vR;    // visibility
    float blockerM = 0;
};

// A width×1 pair (method, reference) from a list of pixels; reference beauty is mid gray.
std::pair<Frame, Frame> framesFrom(const std::vector<Px>& px, bool withBlocker = true) {
    const int w = static_cast<int>(px.size());
    Frame m = Frame::allocate(w, 1, withBlocker), r = Frame::allocate(w, 1, false);
    for (int i = 0; i < w; ++i) {
        m.objectId[i] = px[i].idM;
        r.objectId[i] = px[i].idR;
        m.ndotl[i] = px[i].nM;
        r.ndotl[i] = px[i].nR;
        m.visibility[i] = px[i].vM;
        r.visibility[i] = px[i].vR;
        if (withBlocker) m.blockerId[i] = px[i].blockerM;
        for (int c = 0; c < 3; ++c) r.beauty[3 * i + c] = 0.2f;
    }
    return {m, r};
}

// sRGB encoding written out here, independent of scene::linearToSrgb.
float srgb(float c) { return c <= 0.0031308f ? 12.92f * c : 1.055f * std::pow(c, 1.0f / 2.4f) - 0.055f; }

TEST(ClassifyCounted, FollowsTheTableOnBothSidesOfTau) {
    // τ = 0.5; all values are binary fractions, so the differences are exact.
    EXPECT_EQ(classifyCounted(1.0f, 1.0f), PixelClass::AgreeLit);
    EXPECT_EQ(classifyCounted(0.25f, 0.75f), PixelClass::AgreeLit);          // V_R − V_M = τ: agree
    EXPECT_EQ(classifyCounted(0.2421875f, 0.75f), PixelClass::FalseShadow);  // τ + 1/128
    EXPECT_EQ(classifyCounted(0.0f, 1.0f), PixelClass::FalseShadow);
    EXPECT_EQ(classifyCounted(0.0f, 0.0f), PixelClass::AgreeShadow);
    EXPECT_EQ(classifyCounted(0.75f, 0.25f), PixelClass::AgreeShadow);        // V_M − V_R = τ: agree
    EXPECT_EQ(classifyCounted(0.7578125f, 0.25f), PixelClass::MissedShadow);  // τ + 1/128
    EXPECT_EQ(classifyCounted(1.0f, 0.0f), PixelClass::MissedShadow);
    // V_R = τ exactly is shadowed (V ≤ τ), V_R just above τ is lit.
    EXPECT_EQ(classifyCounted(0.5f, 0.5f), PixelClass::AgreeShadow);
    EXPECT_EQ(classifyCounted(0.5078125f, 0.5078125f), PixelClass::AgreeLit);
}

TEST(CompareFrames, CountsOnlySameObjectFacingTheLightInBothFrames) {
    const auto [m, r] = framesFrom({
        {1, 1, 0.5f, 0.5f, 1, 1},        // 0 counted
        {1, 2, 0.5f, 0.5f, 1, 1},        // 1 ids differ: silhouette
        {0, 0, 0, 0, 1, 1},              // 2 background in both
        {0, 3, 0, 0.5f, 1, 1},           // 3 method sees background: silhouette
        {1, 1, 0.0f, 0.5f, 0, 1},        // 4 method N·L = 0: not counted, sign differs
        {1, 1, 0.5f, -0.2f, 0, 1},       // 5 reference faces away: not counted, sign differs
        {1, 1, -0.1f, -0.2f, 0, 1},      // 6 both face away: not counted, signs agree
        {2.4f, 2.0f, 0.5f, 0.5f, 1, 1},  // 7 ids round to 2 and 2: counted
        {2.6f, 2.0f, 0.5f, 0.5f, 1, 1},  // 8 ids round to 3 and 2: silhouette
    });
    const Comparison c = compareFrames(m, r);
    const std::vector<PixelClass> expected = {PixelClass::AgreeLit,   PixelClass::NotCounted, PixelClass::NotCounted,
                                              PixelClass::NotCounted, PixelClass::NotCounted, PixelClass::NotCounted,
                                              PixelClass::NotCounted, PixelClass::AgreeLit,   PixelClass::NotCounted};
    EXPECT_EQ(c.classes, expected);
    EXPECT_EQ(c.metrics.counted, 2u);
    EXPECT_EQ(c.metrics.notCounted, 7u);
    EXPECT_EQ(c.metrics.silhouetteMismatch, 3u);  // pixels 1, 3, 8
    EXPECT_DOUBLE_EQ(c.metrics.silhouetteMismatchRate, 3.0 / 9.0);
    EXPECT_EQ(c.metrics.ndotlSignMismatch, 2u);  // pixels 4, 5
}

TEST(CompareFrames, NonFiniteValuesAreInvalidAndCountedPerChannel) {
    const float nan = std::numeric_limits<float>::quiet_NaN();
    const float inf = std::numeric_limits<float>::infinity();
    auto [m, r] = framesFrom({
        {1, 1, 0.5f, 0.5f, nan, 1},  // method visibility NaN
        {1, 1, 0.5f, inf, 1, 1},     // reference N·L Inf
        {1, 1, 0.5f, 0.5f, 0, 1},    // an ordinary false shadow
    });
    m.beauty[0] = nan;
    m.beauty[1] = -inf;
    m.depth[2] = inf;
    const Comparison c = compareFrames(m, r);
    EXPECT_EQ(c.classes[0], PixelClass::Invalid);
    EXPECT_EQ(c.classes[1], PixelClass::Invalid);
    EXPECT_EQ(c.classes[2], PixelClass::FalseShadow);
    EXPECT_EQ(c.metrics.invalid, 2u);
    EXPECT_EQ(c.metrics.counted, 1u);
    EXPECT_EQ(c.metrics.methodHealth.visibility.nan, 1u);
    EXPECT_EQ(c.metrics.methodHealth.beauty.nan, 1u);
    EXPECT_EQ(c.metrics.methodHealth.beauty.inf, 1u);
    EXPECT_EQ(c.metrics.methodHealth.depth.inf, 1u);
    EXPECT_EQ(c.metrics.methodHealth.total(), 4u);
    EXPECT_EQ(c.metrics.referenceHealth.ndotl.inf, 1u);
    EXPECT_EQ(c.metrics.referenceHealth.total(), 1u);
    EXPECT_NE(summaryLine(c.metrics).find("NON-FINITE"), std::string::npos);
}

TEST(CompareFrames, MetricsOfAHandBuiltRowEqualHandCounts) {
    const auto [m, r] = framesFrom({
        {1, 1, 0.5f, 0.5f, 1, 1},      // p0 agree lit
        {1, 1, 0.5f, 0.5f, 0, 0},      // p1 agree shadow
        {1, 1, 0.5f, 0.5f, 0, 1, 1},   // p2 false shadow, blocked by itself: acne
        {1, 1, 0.5f, 0.5f, 0, 1, 2},   // p3 false shadow, blocked by object 2
        {2, 2, 0.5f, 0.5f, 1, 0},      // p4 missed shadow
        {2, 2, 0.5f, 0.5f, 0.25f, 0},  // p5 agree shadow, |ΔV| = 0.25
        {1, 2, 0.5f, 0.5f, 1, 1},      // p6 silhouette
        {0, 0, 0, 0, 1, 1},            // p7 background
        {0, 1, 0, 0.5f, 1, 1},         // p8 silhouette
        {2, 2, -0.1f, 0.3f, 0, 1},     // p9 N·L sign differs
    });
    const Metrics k = compareFrames(m, r).metrics;
    EXPECT_EQ(k.totalPixels, 10u);
    EXPECT_EQ(k.counted, 6u);  // p0..p5
    EXPECT_EQ(k.agreeLit, 1u);
    EXPECT_EQ(k.agreeShadow, 2u);
    EXPECT_EQ(k.falseShadow, 2u);
    EXPECT_EQ(k.missedShadow, 1u);
    EXPECT_EQ(k.notCounted, 4u);
    EXPECT_DOUBLE_EQ(k.falseShadowRate, 2.0 / 6.0);
    EXPECT_DOUBLE_EQ(k.missedShadowRate, 1.0 / 6.0);
    EXPECT_DOUBLE_EQ(k.mismatchRate, 3.0 / 6.0);
    // |ΔV| over p0..p5: 0 + 0 + 1 + 1 + 1 + 0.25.
    EXPECT_DOUBLE_EQ(k.meanAbsVisibilityError, 3.25 / 6.0);
    // Shadowed (V ≤ τ): method {p1,p2,p3,p5}, reference {p1,p4,p5}; ∩ = {p1,p5}, ∪ = 5 pixels.
    EXPECT_EQ(k.shadowedMethod, 4u);
    EXPECT_EQ(k.shadowedReference, 3u);
    EXPECT_EQ(k.shadowedIntersection, 2u);
    EXPECT_EQ(k.shadowedUnion, 5u);
    EXPECT_DOUBLE_EQ(k.shadowIoU, 0.4);
    EXPECT_EQ(k.silhouetteMismatch, 2u);
    EXPECT_DOUBLE_EQ(k.silhouetteMismatchRate, 0.2);
    EXPECT_EQ(k.ndotlSignMismatch, 1u);
    EXPECT_TRUE(k.hasBlockerIds);
    EXPECT_EQ(k.selfShadowAcne, 1u);  // p2 only: p3's blocker is another object
    EXPECT_DOUBLE_EQ(k.selfShadowAcneRate, 1.0 / 6.0);
    ASSERT_EQ(k.perObject.size(), 2u);
    EXPECT_EQ(k.perObject[0].objectId, 1);
    EXPECT_EQ(k.perObject[0].counted, 4u);
    EXPECT_EQ(k.perObject[0].falseShadow, 2u);
    EXPECT_EQ(k.perObject[0].selfShadowAcne, 1u);
    EXPECT_EQ(k.perObject[0].missedShadow, 0u);
    EXPECT_EQ(k.perObject[1].objectId, 2);
    EXPECT_EQ(k.perObject[1].counted, 2u);
    EXPECT_EQ(k.perObject[1].missedShadow, 1u);
}

TEST(CompareFrames, SelfAcneLitNearGrazingIsCountedApart) {
    // Four false-shadow pixels, each blocked by its own object in the method:
    //   0: N·L 0.1 in the reference   -> grazing
    //   1: N·L 0.19                    -> grazing
    //   2: N·L 0.5                     -> not
    //   3: N·L 0.1, blocked by object 2 -> not acne at all
    const auto [m, r] = framesFrom({{1, 1, 0.1f, 0.1f, 0, 1, 1},
                                    {1, 1, 0.19f, 0.19f, 0, 1, 1},
                                    {1, 1, 0.5f, 0.5f, 0, 1, 1},
                                    {1, 1, 0.1f, 0.1f, 0, 1, 2}});
    const Metrics k = compareFrames(m, r).metrics;
    EXPECT_EQ(k.falseShadow, 4u);
    EXPECT_EQ(k.selfShadowAcne, 3u);
    EXPECT_EQ(k.selfShadowAcneGrazing, 2u);
    EXPECT_EQ(toJson(k).at("self_shadow_acne_grazing"), 2);
    const auto [m2, r2] = framesFrom({{1, 1, 0.1f, 0.1f, 0, 1}}, /*withBlocker=*/false);
    EXPECT_TRUE(toJson(compareFrames(m2, r2).metrics).at("self_shadow_acne_grazing").is_null());
}

TEST(CompareFrames, WithoutMethodBlockerIdsSelfAcneIsUnknownNotZero) {
    const auto [m, r] = framesFrom({{1, 1, 0.5f, 0.5f, 0, 1}}, /*withBlocker=*/false);
    const Metrics k = compareFrames(m, r).metrics;
    EXPECT_FALSE(k.hasBlockerIds);
    EXPECT_EQ(k.falseShadow, 1u);
    const auto j = toJson(k);
    EXPECT_TRUE(j.at("self_shadow_acne").is_null());
    EXPECT_EQ(summaryLine(k).find("self acne"), std::string::npos);
}

TEST(CompareFrames, MissedShadowWhereTheReceiverBlocksItselfAtGrazingLightIsTheTerminator) {
    // Every pixel on object 1 and lit in the method; the reference's blocker and N·L decide:
    //   0: missed, blocked by itself at N·L 0.1        -> terminator
    //   1: missed, blocked by itself at N·L 0.5        -> not (too far from grazing)
    //   2: missed, blocked by object 2 at N·L 0.1      -> not (another caster)
    //   3: both shadowed, blocked by itself at 0.1     -> not (no error)
    //   4: missed, blocked by itself just under 0.2    -> terminator
    const std::vector<Px> px = {{1, 1, 0.1f, 0.1f, 1, 0},
                                {1, 1, 0.5f, 0.5f, 1, 0},
                                {1, 1, 0.1f, 0.1f, 1, 0},
                                {1, 1, 0.1f, 0.1f, 0, 0, 1},
                                {1, 1, 0.19f, 0.19f, 1, 0}};
    auto [m, r] = framesFrom(px);
    r.blockerId = {1, 1, 2, 1, 1};
    const Metrics k = compareFrames(m, r).metrics;
    EXPECT_TRUE(k.hasReferenceBlockerIds);
    EXPECT_EQ(k.missedShadow, 4u);
    EXPECT_EQ(k.terminatorMissed, 2u);
    EXPECT_DOUBLE_EQ(k.terminatorMissedRate, 2.0 / 5.0);
    ASSERT_EQ(k.perObject.size(), 1u);
    EXPECT_EQ(k.perObject[0].terminatorMissed, 2u);
    const auto j = toJson(k);
    EXPECT_EQ(j.at("terminator_missed"), 2);
    EXPECT_EQ(j.at("per_object").at(0).at("terminator_missed"), 2);

    // A reference without blocker ids (an older frame, or an engine's): unknown, not zero.
    r.blockerId.clear();
    const Metrics u = compareFrames(m, r).metrics;
    EXPECT_FALSE(u.hasReferenceBlockerIds);
    EXPECT_EQ(u.terminatorMissed, 0u);
    EXPECT_TRUE(toJson(u).at("terminator_missed").is_null());
    EXPECT_TRUE(toJson(u).at("terminator_missed_rate").is_null());
}

TEST(CompareFrames, NothingCountedGivesZeroRatesAndUnitIoU) {
    const auto [m, r] = framesFrom({{0, 0, 0, 0, 1, 1}, {1, 2, 0.5f, 0.5f, 1, 1}});
    const Metrics k = compareFrames(m, r).metrics;
    EXPECT_EQ(k.counted, 0u);
    EXPECT_EQ(k.mismatchRate, 0.0);
    EXPECT_EQ(k.meanAbsVisibilityError, 0.0);
    EXPECT_EQ(k.shadowIoU, 1.0);  // both shadowed sets empty: they agree
}

TEST(DiffColors, EachClassHasItsDocumentedColor) {
    const auto [m, r] = framesFrom({
        {1, 1, 0.5f, 0.5f, 1, 1},                                        // agree lit
        {1, 1, 0.5f, 0.5f, 0, 0},                                        // agree shadow
        {1, 1, 0.5f, 0.5f, 0, 1},                                        // false
        {1, 1, 0.5f, 0.5f, 1, 0},                                        // missed
        {0, 0, 0, 0, 1, 1},                                              // not counted
        {1, 1, 0.5f, 0.5f, std::numeric_limits<float>::quiet_NaN(), 1},  // invalid
    });
    const Comparison c = compareFrames(m, r);
    auto px = [&](int i) { return std::array<float, 3>{c.diffRgb[3 * i], c.diffRgb[3 * i + 1], c.diffRgb[3 * i + 2]}; };
    // Reference beauty is linear gray 0.2: luminance 0.2 (709 weights sum to 1), sRGB ≈ 0.484.
    const float y = srgb(0.2f);
    EXPECT_NEAR(px(0)[0], DiffColors::kLitBase + DiffColors::kLitScale * y, 1e-5);
    EXPECT_EQ(px(0)[0], px(0)[1]);  // gray: the scene's colors never look like an error class
    EXPECT_NEAR(px(1)[0], DiffColors::kShadowBase + DiffColors::kShadowScale * y, 1e-5);
    EXPECT_EQ(px(2), (std::array<float, 3>{1.0f, 0.08f, 0.05f}));   // red
    EXPECT_EQ(px(3), (std::array<float, 3>{0.10f, 0.40f, 1.0f}));   // blue
    EXPECT_EQ(px(4), (std::array<float, 3>{0.42f, 0.42f, 0.42f}));  // neutral gray
    EXPECT_EQ(px(5), (std::array<float, 3>{1.0f, 0.0f, 1.0f}));     // magenta
}

TEST(DiffColors, AgreementBandsNeverOverlapNotCountedGray) {
    // Whatever the reference brightness, lit agreement is brighter than the not-counted gray
    // and shadowed agreement darker, so a viewer can tell the three apart.
    for (const float lin : {0.0f, 0.01f, 0.2f, 1.0f, 50.0f}) {
        const auto lit = diffColor(PixelClass::AgreeLit, lin, lin, lin);
        const auto dark = diffColor(PixelClass::AgreeShadow, lin, lin, lin);
        EXPECT_GT(lit[0], DiffColors::kNotCounted[0] + 0.1f) << lin;
        EXPECT_LT(dark[0], DiffColors::kNotCounted[0] - 0.1f) << lin;
        EXPECT_LE(lit[0], 1.0f);
        EXPECT_GE(dark[0], 0.0f);
    }
}

TEST(CompareFrames, SizeMismatchThrowsNamingBothSizes) {
    const Frame a = test::uniformFrame(4, 4, 1, 0.5f, 1), b = test::uniformFrame(4, 5, 1, 0.5f, 1);
    try {
        compareFrames(a, b);
        FAIL() << "expected InputError";
    } catch (const scene::InputError& e) {
        const std::string what = e.what();
        EXPECT_NE(what.find("method is 4x4"), std::string::npos) << what;
        EXPECT_NE(what.find("reference is 4x5"), std::string::npos) << what;
    }
}

TEST(CompareFrames, MissingChannelThrowsNamingFrameAndChannel) {
    const Frame good = test::uniformFrame(3, 2, 1, 0.5f, 1);
    auto expectThrow = [&](const Frame& m, const Frame& r, const std::string& which, const std::string& channel) {
        try {
            compareFrames(m, r);
            ADD_FAILURE() << "expected InputError for " << which << " " << channel;
        } catch (const scene::InputError& e) {
            const std::string what = e.what();
            EXPECT_NE(what.find(which), std::string::npos) << what;
            EXPECT_NE(what.find("'" + channel + "'"), std::string::npos) << what;
        }
    };
    Frame noVis = good;
    noVis.visibility.clear();
    expectThrow(noVis, good, "method", "visibility");
    Frame noId = good;
    noId.objectId.clear();
    expectThrow(good, noId, "reference", "object_id");
    Frame shortNdotl = good;
    shortNdotl.ndotl.pop_back();
    expectThrow(shortNdotl, good, "method", "ndotl");
    Frame noBeauty = good;
    noBeauty.beauty.clear();
    expectThrow(good, noBeauty, "reference", "beauty");  // the diff image needs it
    Frame badBlocker = good;
    badBlocker.blockerId.assign(2, 0.0f);
    expectThrow(badBlocker, good, "method", "blocker_id");
    EXPECT_NO_THROW(compareFrames(noBeauty, good));  // the method's beauty is not needed
    EXPECT_THROW(compareFrames(Frame{}, Frame{}), scene::InputError);
}

TEST(CompareFrames, IdenticalFramesAgreeEverywhere) {
    test::SyntheticOptions o;
    o.width = 96;
    o.height = 54;
    o.acne = o.jaggies = true;  // faults in both: still identical
    const Frame f = test::syntheticFrame(o);
    const Metrics k = compareFrames(f, f).metrics;
    std::size_t expectedCounted = 0;
    for (std::size_t i = 0; i < f.pixelCount(); ++i) expectedCounted += f.objectId[i] > 0 && f.ndotl[i] > 0;
    EXPECT_EQ(k.counted, expectedCounted);
    EXPECT_GT(k.counted, 0u);
    EXPECT_EQ(k.falseShadow + k.missedShadow, 0u);
    EXPECT_EQ(k.silhouetteMismatch, 0u);
    EXPECT_EQ(k.meanAbsVisibilityError, 0.0);
    EXPECT_EQ(k.shadowIoU, 1.0);
    EXPECT_EQ(k.hotspot.wrongPixels, 0u);
}

// A 20×20 floor (object 1), reference shadowed for x < 10.
std::pair<Frame, Frame> halfShadow(int methodShadowColumns) {
    Frame r = test::uniformFrame(20, 20, 1, 0.5f, 1), m = r;
    for (int y = 0; y < 20; ++y)
        for (int x = 0; x < 20; ++x) {
            r.visibility[y * 20 + x] = x < 10 ? 0.0f : 1.0f;
            m.visibility[y * 20 + x] = x < methodShadowColumns ? 0.0f : 1.0f;
        }
    return {m, r};
}

TEST(EdgeAwareError, WrongPixelsNextToAReferenceShadowEdgeAreAliasing) {
    auto [m, r] = halfShadow(12);      // columns 10 and 11 falsely shadowed
    m.visibility[5 * 20 + 18] = 0.0f;  // a false speckle 8 columns from the edge
    m.visibility[0] = 1.0f;            // a missed pixel 9 columns from the edge
    // Reference edge pixels: columns 9 and 10 (neighbours differ), 20 rows each.
    CompareOptions radius0;
    radius0.edgeRadius = 0;
    const Metrics k0 = compareFrames(m, r, radius0).metrics;
    EXPECT_EQ(k0.referenceShadowEdgePixels, 40u);
    EXPECT_EQ(k0.falseShadow, 41u);
    EXPECT_EQ(k0.falseShadowNearEdge, 20u);  // only column 10 is itself an edge pixel
    EXPECT_EQ(k0.aliasingPixels, 20u);
    EXPECT_EQ(k0.biasErrorPixels, 22u);  // column 11 + speckle + missed pixel
    CompareOptions radius1;
    radius1.edgeRadius = 1;
    const Metrics k1 = compareFrames(m, r, radius1).metrics;
    EXPECT_EQ(k1.falseShadowNearEdge, 40u);  // column 11 is 1 from column 10
    EXPECT_EQ(k1.missedShadowNearEdge, 0u);
    EXPECT_EQ(k1.aliasingPixels, 40u);
    EXPECT_EQ(k1.biasErrorPixels, 2u);
    EXPECT_DOUBLE_EQ(k1.aliasingRate, 40.0 / 400.0);
    EXPECT_DOUBLE_EQ(k1.biasErrorRate, 2.0 / 400.0);
}

TEST(EdgeAwareError, APointSampledMethodHasNoAliasing) {
    // The same wrong pixels as above (columns 10 and 11, a speckle, a missed pixel), from a ray
    // tracer: its frame records a ray bias and no shadow-map texel, so it tests each pixel's own
    // point as the reference does and no wrong pixel is a sampling grid's. Near-edge counts stay
    // as measured; none of them is aliasing.
    auto [m, r] = halfShadow(12);
    m.visibility[5 * 20 + 18] = 0.0f;
    m.visibility[0] = 1.0f;
    m.attributes["ray_bias"] = "0.001";
    const Metrics k = compareFrames(m, r).metrics;
    EXPECT_TRUE(k.pointSampled);
    EXPECT_EQ(k.falseShadowNearEdge, 40u);  // columns 10 and 11 (radius 2 from the edge at 9|10)
    EXPECT_EQ(k.aliasingPixels, 0u);
    EXPECT_EQ(k.biasErrorPixels, 42u);
    // A frame that also records a shadow-map texel looks its shadows up on a grid: aliasing again.
    m.attributes["texel_world_size"] = "0.01";
    const Metrics map = compareFrames(m, r).metrics;
    EXPECT_FALSE(map.pointSampled);
    EXPECT_EQ(map.aliasingPixels, 40u);
    EXPECT_EQ(map.biasErrorPixels, 2u);
}

TEST(EdgeAwareError, AThinShadowLostWholeToTheBiasIsABiasLeakNotAliasing) {
    // Reference: a shadow two columns wide (x = 10, 11) on a lit floor, its blocker 0.01 away
    // along the ray; the method (a shadow map: texel 0.01, bias 0.005, slope 1) misses all of it.
    // Contact distance D = b + (s + 4)·t·max(1, tanθ) with N·L = 0.5 (tanθ = √3) is
    // 0.005 + 5·0.01·√3 = 0.092 > 0.01, so every missed pixel is a bias leak; all of them lie
    // within 2 px of the strip's edges (columns 9|10 and 11|12), so by distance alone they would
    // all be aliasing. A missed pixel x = 15 whose blocker is 1 away (beyond D) in a second strip
    // (x = 15, rows 0..19) stays aliasing: it is a far blocker's shadow, near its edge.
    Frame r = test::uniformFrame(20, 20, 1, 0.5f, 1), m = r;
    r.blockerId.assign(r.pixelCount(), 0.0f);
    r.blockerDistance.assign(r.pixelCount(), 0.0f);
    for (int y = 0; y < 20; ++y)
        for (const int x : {10, 11, 15}) {
            const std::size_t i = std::size_t(y) * 20 + x;
            r.visibility[i] = 0.0f;
            r.blockerId[i] = 2.0f;
            r.blockerDistance[i] = x == 15 ? 1.0f : 0.01f;
        }
    m.attributes = {{"texel_world_size", "0.01"}, {"depth_bias", "0.005"}, {"slope_bias", "1"}};
    const Metrics k = compareFrames(m, r).metrics;
    ASSERT_TRUE(k.hasBlockerDistance);
    EXPECT_FALSE(k.pointSampled);
    EXPECT_NEAR(k.contactDistance, 0.005 + 5 * 0.01, 1e-9);  // at tanθ ≤ 1
    EXPECT_EQ(k.missedShadow, 60u);
    EXPECT_EQ(k.missedShadowNearEdge, 60u);
    EXPECT_EQ(k.biasLeak, 40u);
    EXPECT_EQ(k.biasLeakNearEdge, 40u);
    EXPECT_EQ(k.aliasingPixels, 20u);   // the far blocker's column only
    EXPECT_EQ(k.biasErrorPixels, 40u);  // the thin strip, lost to the bias
    EXPECT_EQ(toJson(k)["bias_leak_near_edge"], 40);
    // A far blocker's missed shadow away from every edge is a filter's light bleeding: one pixel
    // (5, 10) inside a wide shadow (x = 0..14, its edge at 14|15, 9 columns away) whose blocker
    // is 1 away. A ray tracer missing it (its frame records a ray bias and no texel) has no
    // filter: no bleeding, and bias error rather than aliasing.
    Frame wide = test::uniformFrame(20, 20, 1, 0.5f, 1), miss = wide;
    wide.blockerId.assign(wide.pixelCount(), 0.0f);
    wide.blockerDistance.assign(wide.pixelCount(), 0.0f);
    for (int y = 0; y < 20; ++y)
        for (int x = 0; x < 15; ++x) {
            const std::size_t i = std::size_t(y) * 20 + x;
            wide.visibility[i] = miss.visibility[i] = 0.0f;
            wide.blockerId[i] = 2.0f;
            wide.blockerDistance[i] = 1.0f;
        }
    miss.visibility[10 * 20 + 5] = 1.0f;
    miss.attributes = m.attributes;  // the shadow map's
    EXPECT_EQ(compareFrames(miss, wide).metrics.bleeding, 1u);
    // The same pixel at the receiver's own terminator (blocked by itself, N·L 0.1 in the
    // reference) is the faceted shadow counted apart, not bleeding, however far its blocker.
    Frame own = wide;
    own.blockerId[10 * 20 + 5] = 1.0f;
    own.ndotl[10 * 20 + 5] = 0.1f;
    const Metrics terminator = compareFrames(miss, own).metrics;
    EXPECT_EQ(terminator.terminatorMissed, 1u);
    EXPECT_EQ(terminator.bleeding, 0u);
    miss.attributes = {{"ray_bias", "0.001"}};
    const Metrics ray = compareFrames(miss, wide).metrics;
    EXPECT_TRUE(ray.pointSampled);
    EXPECT_EQ(ray.missedShadow, 1u);
    EXPECT_EQ(ray.bleeding, 0u);
    EXPECT_EQ(ray.biasErrorPixels, 1u);
    EXPECT_EQ(ray.aliasingPixels, 0u);
}

TEST(EdgeAwareError, ABoundaryBetweenTwoObjectsIsNotAShadowEdge) {
    // Left half object 1 shadowed, right half object 2 lit: a contact, not a shadow edge, so a
    // missing contact shadow stays bias error (peter-panning).
    auto [m, r] = halfShadow(9);  // column 9 missed
    for (int y = 0; y < 20; ++y)
        for (int x = 10; x < 20; ++x) m.objectId[y * 20 + x] = r.objectId[y * 20 + x] = 2;
    const Metrics k = compareFrames(m, r).metrics;
    EXPECT_EQ(k.referenceShadowEdgePixels, 0u);
    EXPECT_EQ(k.missedShadow, 20u);
    EXPECT_EQ(k.aliasingPixels, 0u);
    EXPECT_EQ(k.biasErrorPixels, 20u);
}

TEST(CompareFrames, HotspotIsTheWindowHoldingTheErrorCluster) {
    Frame r = test::uniformFrame(40, 40, 1, 0.5f, 1), m = r;
    for (int y = 5; y < 9; ++y)
        for (int x = 30; x < 34; ++x) m.visibility[y * 40 + x] = 0.0f;  // 16 false shadow
    m.visibility[35 * 40 + 2] = 0.0f;                                   // a lone one elsewhere
    CompareOptions o;
    o.hotspotSize = 8;
    const ErrorHotspot h = compareFrames(m, r, o).metrics.hotspot;
    EXPECT_EQ(h.size, 8);
    EXPECT_EQ(h.wrongPixels, 16u);
    EXPECT_LE(h.x, 30);
    EXPECT_GE(h.x + 8, 34);
    EXPECT_LE(h.y, 5);
    EXPECT_GE(h.y + 8, 9);
}

TEST(CompareFrames, CarriesBothFramesTimingsAndBackends) {
    Frame m = test::uniformFrame(2, 2, 1, 0.5f, 1), r = m;
    m.timingsMs = {{"setup", 1.5}, {"render", 2.5}};
    m.attributes["backend"] = "raster";
    r.timingsMs = {{"render", 100.0}};
    r.attributes["backend"] = "reference";
    const Metrics k = compareFrames(m, r).metrics;
    EXPECT_DOUBLE_EQ(k.methodTiming.totalMs, 4.0);
    EXPECT_EQ(k.methodTiming.stagesMs, m.timingsMs);
    EXPECT_DOUBLE_EQ(k.referenceTiming.totalMs, 100.0);
    EXPECT_EQ(k.methodBackend, "raster");
    EXPECT_EQ(k.referenceBackend, "reference");
    const auto j = toJson(k);
    EXPECT_DOUBLE_EQ(j.at("method_timing").at("total_ms").get<double>(), 4.0);
    EXPECT_EQ(j.at("method_timing").at("stages")[1].at("stage"), "render");
}

TEST(ToJson, HoldsTheMetricValues) {
    const auto [m, r] = framesFrom({{1, 1, 0.5f, 0.5f, 0, 1, 1}, {1, 1, 0.5f, 0.5f, 1, 1}});
    const Metrics k = compareFrames(m, r).metrics;
    const auto j = toJson(k);
    EXPECT_EQ(j.at("counted").get<std::size_t>(), 2u);
    EXPECT_EQ(j.at("false_shadow").get<std::size_t>(), 1u);
    EXPECT_DOUBLE_EQ(j.at("false_shadow_rate").get<double>(), 0.5);
    EXPECT_DOUBLE_EQ(j.at("mismatch_rate").get<double>(), 0.5);
    EXPECT_EQ(j.at("self_shadow_acne").get<std::size_t>(), 1u);
    EXPECT_DOUBLE_EQ(j.at("shadow_iou").get<double>(), 0.0);  // method {p0}, reference {}
    EXPECT_EQ(j.at("method_non_finite").at("total").get<std::size_t>(), 0u);
    // The summary line carries the same numbers, formatted.
    const std::string line = summaryLine(k);
    EXPECT_NE(line.find("counted 2 px"), std::string::npos) << line;
    EXPECT_NE(line.find("false shadow 50.0%"), std::string::npos) << line;
}

TEST(CompareFrames, GivesTheSameAnswerOnFramesReadBackFromExr) {
    // `shadowlab compare` reads EXRs: every channel compare uses must survive the round trip.
    test::SyntheticOptions o;
    o.width = 64;
    o.height = 36;
    const Frame ref = test::syntheticFrame(o);
    o.acne = o.shiftShadow = o.jaggies = true;
    const Frame method = test::syntheticFrame(o);
    const auto dir = std::filesystem::path(::testing::TempDir()) / "compare_exr_roundtrip";
    std::filesystem::create_directories(dir);
    scene::writeFrame(method, dir / "m.exr");
    scene::writeFrame(ref, dir / "r.exr");
    const Metrics direct = compareFrames(method, ref).metrics;
    const Metrics read = compareFrames(scene::readFrame(dir / "m.exr"), scene::readFrame(dir / "r.exr")).metrics;
    std::filesystem::remove_all(dir);
    EXPECT_GT(direct.falseShadow, 0u);
    EXPECT_GT(direct.missedShadow, 0u);
    EXPECT_EQ(toJson(read).dump(), toJson(direct).dump());
}

// A 40×40 floor (id 1, N·L 1) whose left half the reference shadows by object 2: columns 0..9 with
// the blocker 0.05 from the receiver, columns 10..19 with it 2.0 away; the method lights all of it.
// Its attributes give the contact distance D = 0.02 + (0 + 4)·0.01·1 = 0.06 (N·L 1: tanθ 0).
std::pair<Frame, Frame> bleedingPair(bool withDistance) {
    Frame m = test::uniformFrame(40, 40, 1.0f, 1.0f, 1.0f, true);
    Frame r = test::uniformFrame(40, 40, 1.0f, 1.0f, 1.0f, true);
    if (withDistance) r.blockerDistance.assign(r.pixelCount(), 0.0f);
    for (int y = 0; y < 40; ++y)
        for (int x = 0; x < 20; ++x) {
            const std::size_t i = std::size_t(y) * 40 + std::size_t(x);
            r.visibility[i] = 0.0f;
            r.blockerId[i] = 2.0f;
            if (withDistance) r.blockerDistance[i] = x < 10 ? 0.05f : 2.0f;
        }
    m.attributes = {{"backend", "raster"}, {"depth_bias", "0.02"}, {"slope_bias", "0"}, {"texel_world_size", "0.01"}};
    return {m, r};
}

TEST(Bleeding, MissedShadowFarFromItsBlockerIsBleedingAndNearItABiasLeak) {
    const auto [m, r] = bleedingPair(true);
    const Metrics x = compareFrames(m, r).metrics;
    ASSERT_TRUE(x.hasBlockerDistance);
    EXPECT_DOUBLE_EQ(x.contactDistance, 0.02 + 4 * 0.01);
    EXPECT_EQ(x.missedShadow, 800u);
    EXPECT_EQ(x.biasLeak, 400u);  // columns 0..9: 0.05 <= D
    // Columns 10..19 are 2.0 away: bleeding, except those within the edge radius of the
    // reference's shadow edge at x = 20, which are that edge's aliasing (all of them in this band).
    EXPECT_GT(x.missedShadowNearEdge, 0u);
    EXPECT_EQ(x.bleeding, 400u - x.missedShadowNearEdge);
    EXPECT_DOUBLE_EQ(x.bleedingRate, double(x.bleeding) / 1600.0);
    EXPECT_DOUBLE_EQ(x.biasLeakRate, 400.0 / 1600.0);
    const nlohmann::json j = toJson(x);
    EXPECT_EQ(j["bias_leak"], 400);
    EXPECT_EQ(j["bleeding"], x.bleeding);
    // A steeper receiver widens D by tanθ: at N·L = 0.6 (tanθ = 4/3), D = 0.02 + 4·0.01·4/3 = 0.0733.
    auto [m2, r2] = bleedingPair(true);
    for (std::size_t i = 0; i < r2.pixelCount(); ++i) {
        r2.ndotl[i] = m2.ndotl[i] = 0.6f;
        if (r2.blockerDistance[i] == 0.05f) r2.blockerDistance[i] = 0.07f;
    }
    EXPECT_EQ(compareFrames(m2, r2).metrics.biasLeak, 400u);
    // A ray tracer's offset: D = 2 × 0.03 = 0.06.
    Frame ray = m;
    ray.attributes = {{"backend", "raytrace"}, {"ray_bias", "0.03"}};
    const Metrics rx = compareFrames(ray, r).metrics;
    EXPECT_DOUBLE_EQ(rx.contactDistance, 0.06);
    EXPECT_EQ(rx.biasLeak, 400u);
}

// A perspective map's texel grows with the distance d along its axis (texel_world_size "X*d"),
// so the contact distance is taken at each pixel's d: its position from the frame's view depth
// and camera (the worldToCamera and worldToNDC attributes), the map's apex and axis from
// texel_axis. A 40×40 camera 10 above a floor (id 1, N·L 1), looking straight down (+x to the
// right, 40° field of view): pixel column c sees world x = 10·(2(c + 0.5)/40 − 1)·tan 20°. A spot
// at (−10, 0.5, 0) looking along +x with X = 0.01: d = x + 10, from 6.45 (column 0) to 13.55, and
// D = 0.02 + 4·0.01·d. The reference shadows every pixel with its blocker 0.4 away, and the method
// lights them all: a bias leak where D >= 0.4, d >= 9.5, x >= −0.5, i.e. 2(c + 0.5)/40 − 1 >=
// −0.05/tan 20° = −0.137, c >= 16.75: columns 17..39 (23 × 40 = 920 pixels); bleeding in columns
// 0..16 (680; no shadow edge in the image). A point light's six faces at the same place give the
// same: the floor lies in its +X face (|x + 10| >= 6.4 > |z|, 0.5), where d is the same.
TEST(Bleeding, APerspectiveMapsContactDistanceGrowsWithTheDistanceFromTheLight) {
    scene::Scene s;
    s.camera.position = scene::Vec3(0, 10, 0);
    s.camera.lookAt = scene::Vec3(0, 0, 0);
    s.camera.up = scene::Vec3(0, 0, -1);
    s.camera.fovYDegrees = 40.0;
    s.camera.width = 40;
    s.camera.height = 40;
    Frame m = test::uniformFrame(40, 40, 1.0f, 1.0f, 1.0f, true);
    Frame r = test::uniformFrame(40, 40, 1.0f, 1.0f, 0.0f, true);
    m.depth.assign(m.pixelCount(), 10.0f);
    r.blockerId.assign(r.pixelCount(), 2.0f);
    r.blockerDistance.assign(r.pixelCount(), 0.4f);
    scene::recordIdentity(m, s);
    scene::recordIdentity(r, s);
    m.attributes["backend"] = "raster";
    m.attributes["depth_bias"] = "0.02";
    m.attributes["slope_bias"] = "0";
    const std::string spotAxis = "-10,0.5,0,1,0,0";
    const std::string faces[] = {"-10,0.5,0,1,0,0",  "-10,0.5,0,-1,0,0", "-10,0.5,0,0,1,0",
                                 "-10,0.5,0,0,-1,0", "-10,0.5,0,0,0,1",  "-10,0.5,0,0,0,-1"};
    std::string pointAxes, pointSizes;
    for (int k = 0; k < 6; ++k) {
        pointAxes += (k ? ";" : "") + faces[k];
        pointSizes += k ? ";0.01*d" : "0.01*d";
    }
    for (const bool point : {false, true}) {
        m.attributes["texel_world_size"] = point ? pointSizes : "0.01*d";
        m.attributes["texel_axis"] = point ? pointAxes : spotAxis;
        const Metrics x = compareFrames(m, r).metrics;
        ASSERT_TRUE(x.hasBlockerDistance);
        EXPECT_EQ(x.missedShadow, 1600u);
        EXPECT_EQ(x.biasLeak, 920u) << (point ? "point" : "spot");
        EXPECT_EQ(x.bleeding, 680u) << (point ? "point" : "spot");
        // contact_distance: the smallest D over the counted pixels, at column 0's d = 10 − 10·0.975·tan 20°.
        EXPECT_NEAR(x.contactDistance, 0.02 + 0.04 * (10.0 - 9.75 * std::tan(20.0 * M_PI / 180.0)), 1e-5);
    }
    // Without the camera the pixels' distances are unknown: X·d counts as X (D = 0.06), all bleeding.
    m.typedAttributes.clear();
    r.typedAttributes.clear();
    const Metrics unknown = compareFrames(m, r).metrics;
    EXPECT_DOUBLE_EQ(unknown.contactDistance, 0.02 + 4 * 0.01);
    EXPECT_EQ(unknown.bleeding, 1600u);
    // An orthographic map beside it keeps its constant texel: the larger of the two counts.
    scene::recordIdentity(m, s);
    m.attributes["texel_world_size"] = "0.2;0.01*d";
    m.attributes["texel_axis"] = "-;" + spotAxis;
    EXPECT_EQ(compareFrames(m, r).metrics.biasLeak, 1600u);  // D >= 0.02 + 4·0.2 = 0.82 everywhere
}

TEST(Bleeding, WithoutTheReferencesBlockerDistancesItIsUnknownNotZero) {
    const auto [m, r] = bleedingPair(false);  // a reference written before the channel
    const Metrics x = compareFrames(m, r).metrics;
    EXPECT_FALSE(x.hasBlockerDistance);
    EXPECT_EQ(x.bleeding, 0u);
    const nlohmann::json j = toJson(x);
    EXPECT_TRUE(j["bleeding"].is_null());
    EXPECT_TRUE(j["bias_leak_rate"].is_null());
    // Nor without a contact distance: a method frame with no bias or texel attributes.
    auto [m2, r2] = bleedingPair(true);
    m2.attributes.clear();
    EXPECT_FALSE(compareFrames(m2, r2).metrics.hasBlockerDistance);
    CompareOptions o;
    o.contactBias = 0.1;  // given by the caller instead
    const Metrics given = compareFrames(m2, r2, o).metrics;
    EXPECT_TRUE(given.hasBlockerDistance);
    EXPECT_EQ(given.biasLeak, 400u);
}

TEST(Bleeding, TheBlockerDistanceSurvivesTheExrAndAnOlderFrameReadsWithout) {
    auto [m, r] = bleedingPair(true);
    const auto dir = std::filesystem::path(::testing::TempDir()) / "compare_bleeding_exr";
    std::filesystem::create_directories(dir);
    scene::writeFrame(r, dir / "r.exr");
    scene::writeFrame(m, dir / "m.exr");  // no blocker_distance channel
    const Frame rr = scene::readFrame(dir / "r.exr"), mr = scene::readFrame(dir / "m.exr");
    std::filesystem::remove_all(dir);
    EXPECT_EQ(rr.blockerDistance, r.blockerDistance);
    EXPECT_TRUE(mr.blockerDistance.empty());
    EXPECT_EQ(toJson(compareFrames(mr, rr).metrics).dump(), toJson(compareFrames(m, r).metrics).dump());
}

}  // namespace
}  // namespace shadowlab::compare
