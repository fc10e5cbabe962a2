// tests/compare/continuous_error_test.cpp: the continuous error beside the classes: |V_M − V_R|
// over counted pixels and over the reference's penumbra, the soft-error count τ hides, the
// heat map's documented color scale, per-light channels, and the words the report uses.
#include <cmath>

#include <gtest/gtest.h>

#include "compare/compare.h"
#include "compare/report.h"

namespace shadowlab::compare {
namespace {

using scene::Frame;

// A w×h pair on one object facing the light (id 1, N·L 0.5): the reference holds a penumbra
// ramp on the left half and hard values on the right; the method is `offset` lighter inside
// the penumbra only (clamped to 1), exact elsewhere.
std::pair<Frame, Frame> penumbraPair(int w, int h, float offset) {
    Frame m = Frame::allocate(w, h, false), r = Frame::allocate(w, h, false);
    for (int y = 0; y < h; ++y)
        for (int x = 0; x < w; ++x) {
            const std::size_t i = std::size_t(y) * w + x;
            m.objectId[i] = r.objectId[i] = 1.0f;
            m.ndotl[i] = r.ndotl[i] = 0.5f;
            // Penumbra: x < w/2 holds V_R = 0.25 (a quarter lit); right half: 0 on even rows, 1 on odd.
            const bool pen = x < w / 2;
            const float vr = pen ? 0.25f : float(y % 2);
            r.visibility[i] = vr;
            m.visibility[i] = pen ? std::min(1.0f, vr + offset) : vr;
            for (int c = 0; c < 3; ++c) r.beauty[3 * i + c] = m.beauty[3 * i + c] = 0.3f;
        }
    return {m, r};
}

TEST(ContinuousError, APenumbraWrongByLessThanTauIsAgreementInClassButNotInError) {
    // 8×4: 16 penumbra pixels (x < 4) off by 0.375, 16 hard pixels exact. τ = 0.5 sees no
    // wrong pixel; the mean over 32 counted pixels is 16·0.375/32 = 0.1875, over the penumbra
    // it is 0.375, and all 16 penumbra pixels are off by more than 0.25: soft error.
    const auto [m, r] = penumbraPair(8, 4, 0.375f);
    const Metrics k = compareFrames(m, r).metrics;
    EXPECT_EQ(k.counted, 32u);
    EXPECT_EQ(k.falseShadow + k.missedShadow, 0u);
    EXPECT_EQ(k.mismatchRate, 0.0);
    EXPECT_DOUBLE_EQ(k.meanAbsVisibilityError, 0.1875);
    EXPECT_EQ(k.penumbraPixels, 16u);
    EXPECT_DOUBLE_EQ(k.meanAbsVisibilityErrorPenumbra, 0.375);
    EXPECT_DOUBLE_EQ(k.maxAbsVisibilityError, 0.375);
    EXPECT_EQ(k.softErrorPixels, 16u);
    EXPECT_DOUBLE_EQ(k.softErrorRate, 0.5);
}

TEST(ContinuousError, ErrorsAtOrBelowAQuarterAreNotSoftErrorsAndBeyondTauAreWrongPixels) {
    // Offset 0.25 exactly (binary fractions, exact): |ΔV| = 0.25 is not > 0.25.
    const auto [m1, r1] = penumbraPair(8, 4, 0.25f);
    EXPECT_EQ(compareFrames(m1, r1).metrics.softErrorPixels, 0u);
    EXPECT_DOUBLE_EQ(compareFrames(m1, r1).metrics.meanAbsVisibilityErrorPenumbra, 0.25);
    // Offset 0.75: 0.25 + 0.75 = 1, |ΔV| = 0.75 > τ: missed shadow, not soft error.
    const auto [m2, r2] = penumbraPair(8, 4, 0.75f);
    const Metrics k = compareFrames(m2, r2).metrics;
    EXPECT_EQ(k.missedShadow, 16u);
    EXPECT_EQ(k.softErrorPixels, 0u);
    EXPECT_DOUBLE_EQ(k.meanAbsVisibilityErrorPenumbra, 0.75);
}

TEST(ContinuousError, HardShadowsHaveNoPenumbraAndJsonCarriesTheNames) {
    // Offset 0: the reference's values are 0.25 (penumbra), 0 and 1; with no penumbra column
    // (w = 1 → w/2 = 0) every value is 0 or 1.
    const auto [m, r] = penumbraPair(1, 4, 0.0f);
    const Metrics k = compareFrames(m, r).metrics;
    EXPECT_EQ(k.penumbraPixels, 0u);
    EXPECT_EQ(k.meanAbsVisibilityErrorPenumbra, 0.0);
    const auto j = toJson(k);
    for (const char* key : {"mean_abs_visibility_error", "mean_abs_visibility_error_penumbra", "penumbra_pixels",
                            "soft_error_pixels", "soft_error_rate", "max_abs_visibility_error", "per_light"})
        EXPECT_TRUE(j.contains(key)) << key;
    const auto [m2, r2] = penumbraPair(8, 4, 0.375f);
    const auto j2 = toJson(compareFrames(m2, r2).metrics);
    EXPECT_DOUBLE_EQ(j2["mean_abs_visibility_error_penumbra"].get<double>(), 0.375);
    EXPECT_EQ(j2["soft_error_pixels"].get<int>(), 16);
}

TEST(HeatScale, ColorsFollowTheDocumentedStopsAndInterpolateLinearly) {
    for (std::size_t k = 0; k < HeatScale::kStops.size(); ++k) {
        const auto c = heatColor(float(k) / 4.0f);
        for (int ch = 0; ch < 3; ++ch) EXPECT_FLOAT_EQ(c[ch], HeatScale::kStops[k][ch]) << k;
    }
    // 0.125 is halfway between the stops at 0 and 0.25.
    const auto mid = heatColor(0.125f);
    for (int ch = 0; ch < 3; ++ch)
        EXPECT_NEAR(mid[ch], 0.5f * (HeatScale::kStops[0][ch] + HeatScale::kStops[1][ch]), 1e-6f);
    // Clamped outside 0..1; NaN is the invalid magenta.
    EXPECT_EQ(heatColor(2.0f), heatColor(1.0f));
    EXPECT_EQ(heatColor(-1.0f), heatColor(0.0f));
    EXPECT_EQ(heatColor(NAN), DiffColors::kInvalid);
    // Luminance rises along the scale, so a larger error is always brighter.
    double last = -1.0;
    for (int i = 0; i <= 40; ++i) {
        const auto c = heatColor(float(i) / 40.0f);
        const double y = 0.2126 * c[0] + 0.7152 * c[1] + 0.0722 * c[2];
        EXPECT_GT(y, last) << i;
        last = y;
    }
}

TEST(HeatMap, PixelsHoldTheScaleColorOfTheirErrorAndNotCountedIsGray) {
    auto [m, r] = penumbraPair(8, 4, 0.375f);
    r.objectId[7] = 0.0f;  // (7, 0): background in the reference: not counted
    const Comparison c = compareFrames(m, r);
    ASSERT_EQ(c.heatRgb.size(), 3u * 32u);
    const auto pen = heatColor(0.375f), exact = heatColor(0.0f);
    for (int ch = 0; ch < 3; ++ch) {
        EXPECT_FLOAT_EQ(c.heatRgb[3 * 0 + ch], pen[ch]);    // (0, 0): penumbra
        EXPECT_FLOAT_EQ(c.heatRgb[3 * 5 + ch], exact[ch]);  // (5, 0): hard, exact
        EXPECT_FLOAT_EQ(c.heatRgb[3 * 7 + ch], DiffColors::kNotCounted[ch]);
    }
}

TEST(ContinuousError, PerLightChannelsGiveEachLightsOwnError) {
    // Two lights on 4×1: light 0 exact and hard; light 1's reference is 0.5 everywhere (its
    // penumbra) and the method reads 0.875: |ΔV| = 0.375 on 4 pixels, all soft errors.
    Frame m = Frame::allocate(4, 1, false), r = Frame::allocate(4, 1, false);
    m.lightVisibility.assign(2, std::vector<float>(4));
    r.lightVisibility.assign(2, std::vector<float>(4));
    for (int i = 0; i < 4; ++i) {
        m.objectId[i] = r.objectId[i] = 1.0f;
        m.ndotl[i] = r.ndotl[i] = 1.0f;
        m.lightVisibility[0][i] = r.lightVisibility[0][i] = 1.0f;
        r.lightVisibility[1][i] = 0.5f;
        m.lightVisibility[1][i] = 0.875f;
        r.visibility[i] = 0.75f;  // the mean of both
        m.visibility[i] = 0.9375f;
        for (int ch = 0; ch < 3; ++ch) r.beauty[3 * i + ch] = 0.3f;
    }
    const Comparison c = compareFrames(m, r);
    ASSERT_EQ(c.metrics.perLight.size(), 2u);
    EXPECT_EQ(c.metrics.perLight[0].meanAbsVisibilityError, 0.0);
    EXPECT_EQ(c.metrics.perLight[0].penumbraPixels, 0u);
    EXPECT_DOUBLE_EQ(c.metrics.perLight[1].meanAbsVisibilityError, 0.375);
    EXPECT_DOUBLE_EQ(c.metrics.perLight[1].meanAbsVisibilityErrorPenumbra, 0.375);
    EXPECT_EQ(c.metrics.perLight[1].softErrorPixels, 4u);
    ASSERT_EQ(c.lightHeatRgb.size(), 2u);
    EXPECT_FLOAT_EQ(c.lightHeatRgb[1][0], heatColor(0.375f)[0]);
    EXPECT_EQ(toJson(c.metrics)["per_light"].size(), 2u);
}

// A w×1 pair on one object lit by two hard lights of equal weight: the method lit everywhere; the
// reference has light 0 blocked on the first `lost` pixels (combined V 0.5 there), so the method
// lost that shadow. |ΔV| = 0.5 is not beyond τ: the combined mask counts no wrong pixel there,
// light 0's own channel misses each of them, and neither light has a penumbra.
std::pair<Frame, Frame> lostShadowOfOneLight(int w, int lost) {
    Frame m = Frame::allocate(w, 1, false), r = Frame::allocate(w, 1, false);
    m.lightVisibility.assign(2, std::vector<float>(std::size_t(w), 1.0f));
    r.lightVisibility.assign(2, std::vector<float>(std::size_t(w), 1.0f));
    for (int i = 0; i < w; ++i) {
        m.objectId[i] = r.objectId[i] = 1.0f;
        m.ndotl[i] = r.ndotl[i] = 1.0f;
        m.visibility[i] = r.visibility[i] = 1.0f;
        if (i < lost) {
            r.lightVisibility[0][i] = 0.0f;
            r.visibility[i] = 0.5f;
        }
    }
    return {m, r};
}

TEST(ContinuousError, OneLightsLostShadowWhereAnotherLightStillReachesIsNamedPerLight) {
    const auto [m, r] = lostShadowOfOneLight(4, 4);
    const Metrics mt = compareFrames(m, r).metrics;
    EXPECT_EQ(mt.missedShadow, 0u);
    EXPECT_EQ(mt.penumbraPixels, 0u);
    ASSERT_EQ(mt.perLight.size(), 2u);
    EXPECT_EQ(mt.perLight[0].missedShadow, 4u);
    EXPECT_EQ(mt.perLight[0].falseShadow, 0u);
    EXPECT_EQ(mt.perLight[1].missedShadow + mt.perLight[1].falseShadow, 0u);
    EXPECT_EQ(mt.perLightWrongPixels, 4u);
    EXPECT_EQ(toJson(mt)["per_light"][0]["missed_shadow"], 4);
    ReportInput in;
    in.methods.push_back({"raster", "raster.png", "diff-raster.png", m, mt});
    const std::string text = describeFindings(in);
    EXPECT_EQ(text.find("matches the reference"), std::string::npos) << text;
    EXPECT_NE(text.find("Per light, 4 px are wrong outright, more than the 0 the combined visibility counts"),
              std::string::npos)
        << text;
    EXPECT_NE(text.find("0 px false shadow and 4 px missed in its own channel"), std::string::npos) << text;
    EXPECT_NE(text.find("one light's shadow is wrong outright where another light still reaches the point"),
              std::string::npos)
        << text;
    EXPECT_NE(summaryLine(mt).find("PER LIGHT 4 px wrong outright"), std::string::npos) << summaryLine(mt);

    // One such pixel of 2000 (0.05%, under the 0.1% that is notable) is edge noise: still a match.
    const auto [m2, r2] = lostShadowOfOneLight(2000, 1);
    const Metrics one = compareFrames(m2, r2).metrics;
    EXPECT_EQ(one.perLightWrongPixels, 1u);
    EXPECT_FALSE(lightsHideWrongPixels(one));
    ReportInput quiet;
    quiet.methods.push_back({"raytrace", "raytrace.png", "diff-raytrace.png", m2, one});
    const std::string q = describeFindings(quiet);
    EXPECT_NE(q.find("matches the reference"), std::string::npos) << q;
    EXPECT_EQ(q.find("Per light,"), std::string::npos) << q;
    EXPECT_EQ(summaryLine(one).find("PER LIGHT"), std::string::npos) << summaryLine(one);
}

TEST(ContinuousError, AFiltersBlurOfAHardEdgeIsNotSoftErrorThatDominates) {
    // 40×20 on one lit object: the reference is 0 left of x = 20 and 1 from it (a hard edge); the
    // method blurs the two columns beside the edge to 0.3 and 0.7, as a 2×2 PCF does: 40 soft-error
    // pixels (5%), all at the edge.
    const int w = 40, h = 20;
    Frame r = Frame::allocate(w, h, false);
    for (int y = 0; y < h; ++y)
        for (int x = 0; x < w; ++x) {
            const std::size_t i = std::size_t(y) * w + x;
            r.objectId[i] = 1.0f;
            r.ndotl[i] = 0.5f;
            r.visibility[i] = x < 20 ? 0.0f : 1.0f;
            for (int ch = 0; ch < 3; ++ch) r.beauty[3 * i + ch] = 0.3f;
        }
    Frame blurred = r, banded = r;
    for (int y = 0; y < h; ++y) {
        blurred.visibility[std::size_t(y) * w + 19] = 0.3f;
        blurred.visibility[std::size_t(y) * w + 20] = 0.7f;
        banded.visibility[std::size_t(y) * w + 30] = 0.7f;  // ten pixels into the light: not the edge's
        banded.visibility[std::size_t(y) * w + 31] = 0.7f;
    }
    const Metrics mb = compareFrames(blurred, r).metrics;
    EXPECT_EQ(mb.softErrorPixels, 40u);
    EXPECT_EQ(mb.softErrorNearEdge, 40u);
    EXPECT_FALSE(softErrorDominates(mb));
    EXPECT_EQ(summaryLine(mb).find("SOFT ERROR"), std::string::npos) << summaryLine(mb);
    ReportInput in;
    in.methods.push_back({"raster", "raster.png", "diff-raster.png", blurred, mb});
    const std::string text = describeFindings(in);
    EXPECT_NE(text.find("matches the reference on all 800 counted pixels"), std::string::npos) << text;
    EXPECT_NE(text.find("but for its filter's blur along the shadow edges (40 px"), std::string::npos) << text;
    // The same count of soft error away from the edge dominates.
    const Metrics ma = compareFrames(banded, r).metrics;
    EXPECT_EQ(ma.softErrorPixels, 40u);
    EXPECT_EQ(ma.softErrorNearEdge, 0u);
    EXPECT_TRUE(softErrorDominates(ma));
    EXPECT_NE(summaryLine(ma).find("SOFT ERROR dominates: 5.00%"), std::string::npos) << summaryLine(ma);
}

TEST(ContinuousError, FindingsNameSoftShadowErrorWhenItDominatesAndDoNotSayAgree) {
    const auto [m, r] = penumbraPair(8, 4, 0.375f);
    ReportInput in;
    in.methods.push_back({"raster", "raster.png", "diff-raster.png", m, compareFrames(m, r).metrics});
    const std::string text = describeFindings(in);
    EXPECT_EQ(text.find("matches the reference"), std::string::npos) << text;
    EXPECT_NE(text.find("soft-shadow error dominates"), std::string::npos) << text;
    EXPECT_NE(text.find("0.375 over the reference's penumbra"), std::string::npos) << text;
    // Exact frames still match.
    const auto [m0, r0] = penumbraPair(8, 4, 0.0f);
    ReportInput exact;
    exact.methods.push_back({"raster", "raster.png", "diff-raster.png", m0, compareFrames(m0, r0).metrics});
    EXPECT_NE(describeFindings(exact).find("matches the reference"), std::string::npos);
    // A few soft-error pixels (sampling noise: 1 of 2000 = 0.05% ≤ 0.1%) are counted, not judged.
    const auto [m1, r1] = penumbraPair(2000, 1, 0.0f);
    Frame noisy = m1;
    noisy.visibility[0] = 0.625f;  // V_R = 0.25 there: off by 0.375
    ReportInput few;
    few.methods.push_back({"raytrace", "raytrace.png", "diff-raytrace.png", noisy, compareFrames(noisy, r1).metrics});
    const std::string t = describeFindings(few);
    EXPECT_NE(t.find("matches the reference"), std::string::npos) << t;
    EXPECT_NE(t.find("1 px (0.05%) are off by more than 0.25"), std::string::npos) << t;
    EXPECT_EQ(t.find("dominates"), std::string::npos) << t;
}

TEST(ContinuousError, ReportShowsHeatMapsTheScaleAndWarnings) {
    const auto [m, r] = penumbraPair(8, 4, 0.375f);
    ReportInput in;
    in.reference = {"reference", "reference.png", r};
    ReportMethod rm{"raster", "raster.png", "diff-raster.png", m, compareFrames(m, r).metrics};
    rm.heatPng = "heat-raster.png";
    in.methods.push_back(rm);
    in.warnings.push_back("light 0 has a radius");
    const std::string html = renderReportHtml(in);
    EXPECT_NE(html.find("heat-raster.png"), std::string::npos);
    EXPECT_NE(html.find("heatbar"), std::string::npos);
    EXPECT_NE(html.find("over the reference's penumbra"), std::string::npos);
    EXPECT_NE(html.find("light 0 has a radius"), std::string::npos);
    EXPECT_NE(describeFindings(in).find("Warning: light 0 has a radius"), std::string::npos);
}

}  // namespace
}  // namespace shadowlab::compare
