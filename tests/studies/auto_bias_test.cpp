// tests/studies/auto_bias_test.cpp: the recommended bias is the middle of each known window
// (geometric for log-spaced samples), stiff series name the artifact that dominates, robust
// offsets win when they pass, and the shadow block is one the scene loader accepts.
#include "studies/auto_bias.h"

#include <cmath>
#include <filesystem>
#include <fstream>

#include <gtest/gtest.h>

#include "scene/error.h"
#include "scene/loader.h"
#include "tests/studies/sweep_rows.h"

namespace shadowlab::studies {
namespace {

namespace fs = std::filesystem;
using test::depthRow;
using test::rayRow;
using test::robustRow;
using test::slopeRow;

constexpr double kTexel = 0.002;  // world size of a texel in these made-up series
constexpr double kOk = 0.0002;    // a rate well under the 0.1% threshold
constexpr double kBad = 0.02;     // a rate well over it

// A sphere over nothing under a sun, with `shadow` as its "shadow" block, written to a scene file
// in the test's temporary folder `name` and loaded by the scene loader.
scene::Scene loadWithShadowBlock(const nlohmann::json& shadow, const std::string& name) {
    const nlohmann::json scene = {
        {"camera",
         {{"position", {0, 2, 6}},
          {"look_at", {0, 0.7, 0}},
          {"up", {0, 1, 0}},
          {"fov_y", 40},
          {"resolution", {64, 36}},
          {"near", 0.1},
          {"far", 100}}},
        {"materials", {{"matte", {{"albedo", {0.8, 0.8, 0.8}}}}}},
        {"lights", {{{"type", "directional"}, {"direction", {-1, -2, -1}}, {"color", {1, 1, 1}}, {"intensity", 3}}}},
        {"objects", {{{"type", "sphere"}, {"center", {0, 1, 0}}, {"radius", 1}, {"material", "matte"}}}},
        {"shadow", shadow}};
    const fs::path dir = fs::path(::testing::TempDir()) / name;
    fs::create_directories(dir);
    std::ofstream(dir / "scene.json") << scene.dump(2);
    return scene::loadScene(dir / "scene.json");
}

// A depth series at 0, ¼, 1, 4, 16, 64 texels (defaultGrid's quick series) where 1..16 texels
// are clean: acne below, leaks above.
std::vector<SweepRow> depthSeriesWithWindow() {
    return {depthRow(0, 0.3, 0),        depthRow(0.25 * kTexel, kBad, 0), depthRow(1 * kTexel, kOk, 0),
            depthRow(4 * kTexel, 0, 0), depthRow(16 * kTexel, 0, kOk),    depthRow(64 * kTexel, 0, kBad)};
}

TEST(IsLogSpaced, TellsGeometricFromArithmeticSeries) {
    EXPECT_TRUE(isLogSpaced({0, 0.25, 1, 4, 16, 64}));  // ratio 4, zero ignored
    EXPECT_TRUE(isLogSpaced({1e-8, 1e-6, 1e-4, 1e-2}));
    EXPECT_FALSE(isLogSpaced({0, 1, 2, 3, 4, 5}));  // step 1
    EXPECT_FALSE(isLogSpaced({0.1, 0.2, 0.3, 0.4}));
    EXPECT_TRUE(isLogSpaced({0.001, 0.01}));  // two values a decade apart
    EXPECT_FALSE(isLogSpaced({0.001, 0.002}));
    EXPECT_FALSE(isLogSpaced({0, 0.5}));  // one positive value
}

TEST(WindowMiddle, GeometricForLogSpacedPositiveWindowsElseArithmetic) {
    EXPECT_DOUBLE_EQ(windowMiddle(1e-4, 1e-2, true), 1e-3);  // sqrt(1e-4 · 1e-2)
    EXPECT_DOUBLE_EQ(windowMiddle(1e-4, 1e-2, false), 0.00505);
    EXPECT_DOUBLE_EQ(windowMiddle(0.0, 1e-2, true), 0.005);  // lo = 0: no geometric middle
}

TEST(AutoBias, RecommendsTheGeometricMiddleOfALogSpacedWindow) {
    const AutoBias a = recommendBias(depthSeriesWithWindow());
    const BiasSeries* d = a.primary("depth");
    ASSERT_NE(d, nullptr);
    EXPECT_FALSE(d->window.stiff);
    EXPECT_DOUBLE_EQ(d->window.lo, 1 * kTexel);
    EXPECT_DOUBLE_EQ(d->window.hi, 16 * kTexel);
    EXPECT_TRUE(d->logSpaced);
    // sqrt(1 · 16) = 4 texels.
    EXPECT_NEAR(d->recommended, 4 * kTexel, 1e-12);
    EXPECT_NEAR(a.shadowBlock.at("depth_bias").get<double>(), 4 * kTexel, 1e-12);
    // The series held slope bias at 0 on a 1024 map with no filter: the block keeps all three.
    EXPECT_EQ(a.shadowBlock.at("slope_bias").get<double>(), 0.0);
    EXPECT_EQ(a.shadowBlock.at("shadow_map_size").get<int>(), 1024);
    EXPECT_EQ(a.shadowBlock.at("filter").get<std::string>(), "none");
    EXPECT_FALSE(a.shadowBlock.contains("ray_bias"));
    EXPECT_EQ(a.primary("slope"), nullptr);
    EXPECT_EQ(a.primary("ray"), nullptr);
}

TEST(AutoBias, RecommendsTheArithmeticMiddleOfAnEvenlySpacedWindow) {
    // Slope bias 0..5 texels in steps of 1; clean from 1 to 4: middle (1 + 4) / 2 = 2.5.
    const AutoBias a = recommendBias({slopeRow(0, kBad, 0), slopeRow(1, kOk, 0), slopeRow(2, 0, 0), slopeRow(3, 0, 0),
                                      slopeRow(4, 0, kOk), slopeRow(5, 0, kBad)});
    const BiasSeries* s = a.primary("slope");
    ASSERT_NE(s, nullptr);
    EXPECT_FALSE(s->logSpaced);
    EXPECT_DOUBLE_EQ(s->recommended, 2.5);
    EXPECT_DOUBLE_EQ(a.shadowBlock.at("slope_bias").get<double>(), 2.5);
    EXPECT_EQ(a.shadowBlock.at("depth_bias").get<double>(), 0.0);
}

TEST(AutoBias, AWindowStartingAtZeroUsesTheArithmeticMiddle) {
    // Ray bias 0, 1e-6 .. 1e-3 (log-spaced), clean from 0 to 1e-4: (0 + 1e-4) / 2.
    const AutoBias a = recommendBias(
        {rayRow(0, 0, 0), rayRow(1e-6, 0, 0), rayRow(1e-5, 0, 0), rayRow(1e-4, 0, kOk), rayRow(1e-3, 0, kBad)});
    const BiasSeries* r = a.primary("ray");
    ASSERT_NE(r, nullptr);
    EXPECT_TRUE(r->logSpaced);
    EXPECT_DOUBLE_EQ(r->window.lo, 0.0);
    EXPECT_DOUBLE_EQ(r->recommended, 5e-5);
    EXPECT_DOUBLE_EQ(a.shadowBlock.at("ray_bias").get<double>(), 5e-5);
    EXPECT_EQ(a.shadowBlock.at("precision").get<std::string>(), "float");
}

TEST(AutoBias, AStiffSeriesNamesAcneWhenFalseShadowDominatesTheBestCompromise) {
    // max(false, missed) per sample: 0.2, 0.05, 0.01, 0.03 -> best compromise at 4 texels,
    // where false shadow (0.01) outweighs missed (0.002): acne dominates.
    const AutoBias a = recommendBias({depthRow(1 * kTexel, 0.2, 0), depthRow(2 * kTexel, 0.05, 0),
                                      depthRow(4 * kTexel, 0.01, 0.002), depthRow(8 * kTexel, 0.004, 0.03)});
    const BiasSeries* d = a.primary("depth");
    ASSERT_NE(d, nullptr);
    EXPECT_TRUE(d->window.stiff);
    EXPECT_EQ(d->dominant, "false");
    EXPECT_DOUBLE_EQ(d->recommended, 4 * kTexel);
    EXPECT_NE(d->describe().find("stiff"), std::string::npos);
    EXPECT_NE(d->describe().find("acne"), std::string::npos);
    EXPECT_DOUBLE_EQ(a.shadowBlock.at("depth_bias").get<double>(), 4 * kTexel);
    bool saysStiff = false;
    for (const auto& n : a.notes) saysStiff = saysStiff || n.find("shadow map is stiff") != std::string::npos;
    EXPECT_TRUE(saysStiff);
}

TEST(AutoBias, AStiffSeriesNamesPeterPanningWhenMissedShadowDominates) {
    // max: 0.02, 0.008, 0.05 -> best at 2 texels, where missed (0.008) > false (0.003).
    const AutoBias a = recommendBias({slopeRow(1, 0.02, 0.001), slopeRow(2, 0.003, 0.008), slopeRow(4, 0, 0.05)});
    const BiasSeries* s = a.primary("slope");
    ASSERT_NE(s, nullptr);
    EXPECT_TRUE(s->window.stiff);
    EXPECT_EQ(s->dominant, "missed");
    EXPECT_NE(s->describe().find("peter-panning"), std::string::npos);
}

TEST(AutoBias, MissedShadowAtTerminatorsBoundsNoWindow) {
    // Of each row's missed shadow 0.008 lies at smooth meshes' terminators (renderers leave it at
    // every bias, and the recommendation does not judge it): without it the 2-texel row is
    // within the window's 0.1% on both sides; counted as leaks, the series would be stiff.
    std::vector<SweepRow> rows = {slopeRow(1, 0.02, 0.009), slopeRow(2, 0.0005, 0.0085), slopeRow(4, 0, 0.05)};
    const AutoBias asLeaks = recommendBias(rows);
    ASSERT_NE(asLeaks.primary("slope"), nullptr);
    EXPECT_TRUE(asLeaks.primary("slope")->window.stiff);
    for (SweepRow& r : rows) r.metrics["terminator_missed_rate"] = 0.008;
    const AutoBias judged = recommendBias(rows);
    ASSERT_NE(judged.primary("slope"), nullptr);
    EXPECT_FALSE(judged.primary("slope")->window.stiff);
}

TEST(AutoBias, RobustOffsetsAreJudgedWithoutTheTerminatorAsTheWindowsAre) {
    // Robust offsets that miss 0.5% of the pixels, all at smooth meshes' terminators (where a
    // float offset along the shading normal and the reference's facets part), pass as the
    // ray-bias window's rows would; the same miss elsewhere fails them.
    std::vector<SweepRow> rows = {rayRow(0, kBad, 0), rayRow(1e-4, 0, 0), rayRow(1e-2, 0, kBad),
                                  robustRow("float", 0, 0.005, 50.0)};
    EXPECT_EQ(recommendBias(rows).robustPick(), nullptr);
    rows[3].metrics["terminator_missed_rate"] = 0.005;
    const AutoBias judged = recommendBias(rows);
    ASSERT_NE(judged.robustPick(), nullptr);
    EXPECT_EQ(judged.shadowBlock.at("ray_bias"), "robust");
    EXPECT_DOUBLE_EQ(judged.robustPick()->missedShadowRate, 0.0);
}

TEST(AutoBias, PrefersTheRasterBiasKindWithTheWiderWindow) {
    // Depth: one clean sample; slope: three. The slope bias wins, the depth bias stays at 0
    // as it was when the slope series was measured.
    std::vector<SweepRow> rows = {depthRow(0, kBad, 0), depthRow(kTexel, 0, 0), depthRow(4 * kTexel, 0, kBad),
                                  slopeRow(0, kBad, 0), slopeRow(0.5, 0, 0),    slopeRow(2, 0, 0),
                                  slopeRow(8, 0, 0),    slopeRow(32, 0, kBad)};
    const AutoBias a = recommendBias(rows);
    EXPECT_DOUBLE_EQ(a.shadowBlock.at("slope_bias").get<double>(), 2.0);  // sqrt(0.5 · 8)
    EXPECT_EQ(a.shadowBlock.at("depth_bias").get<double>(), 0.0);
    // Reversed: depth has the wider window.
    rows = {depthRow(0, kBad, 0), depthRow(kTexel, 0, 0), depthRow(4 * kTexel, 0, 0), depthRow(16 * kTexel, 0, kBad),
            slopeRow(0, kBad, 0), slopeRow(2, 0, 0),      slopeRow(8, 0, kBad)};
    const AutoBias b = recommendBias(rows);
    EXPECT_DOUBLE_EQ(b.shadowBlock.at("depth_bias").get<double>(), 2 * kTexel);  // sqrt(1 · 4) texels
    EXPECT_EQ(b.shadowBlock.at("slope_bias").get<double>(), 0.0);
}

TEST(AutoBias, RecommendsRobustOffsetsWhenTheyPass) {
    std::vector<SweepRow> rows = {rayRow(0, kBad, 0), rayRow(1e-4, 0, 0), rayRow(1e-2, 0, kBad),
                                  robustRow("float", kOk, 0, 50.0), robustRow("double", 0, 0, 80.0)};
    const AutoBias a = recommendBias(rows);
    EXPECT_EQ(a.shadowBlock.at("ray_bias"), "robust");
    EXPECT_EQ(a.shadowBlock.at("precision"), "float");  // both pass: float, the tracer's own
    // Float is chosen by precision, not time: a double row timed faster (noise) does not flip it.
    std::vector<SweepRow> timed = rows;
    timed[4] = robustRow("double", 0, 0, 40.0);
    EXPECT_EQ(recommendBias(timed).shadowBlock.at("precision"), "float");
    timed[3] = robustRow("float", kBad, 0, 50.0);  // float fails: double
    EXPECT_EQ(recommendBias(timed).shadowBlock.at("precision"), "double");
    ASSERT_NE(a.robustPick(), nullptr);
    bool said = false;
    for (const auto& n : a.notes) said = said || n.find("\"ray_bias\": \"robust\"") != std::string::npos;
    EXPECT_TRUE(said);
    // When robust offsets leave acne above the threshold, the ray-bias window is used instead.
    rows[3] = robustRow("float", kBad, 0);
    rows[4] = robustRow("double", 0.002, 0);
    const AutoBias b = recommendBias(rows);
    EXPECT_EQ(b.robustPick(), nullptr);
    EXPECT_DOUBLE_EQ(b.shadowBlock.at("ray_bias").get<double>(), 1e-4);
}

TEST(AutoBias, IgnoresFailedRowsAndRowsWithoutRates) {
    // Without the failed row at 4 texels the series is stiff; a failed row (error set) must
    // never open a window, even if it carries rates.
    std::vector<SweepRow> rows = {depthRow(kTexel, kBad, 0), depthRow(16 * kTexel, 0, kBad)};
    SweepRow failed = depthRow(4 * kTexel, 0, 0);
    failed.error = "VK_ERROR_DEVICE_LOST";
    rows.push_back(failed);
    rows.push_back(test::failedRow(depthRow(2 * kTexel, 0, 0), "out of memory"));
    const AutoBias a = recommendBias(rows);
    ASSERT_NE(a.primary("depth"), nullptr);
    EXPECT_EQ(a.primary("depth")->samples.size(), 2u);
    EXPECT_TRUE(a.primary("depth")->window.stiff);
}

TEST(AutoBias, SplitsSeriesRunAtOtherSettingsAndUsesTheLongest) {
    std::vector<SweepRow> rows = depthSeriesWithWindow();  // 6 samples at 1024
    for (double k : {1.0, 4.0, 16.0}) rows.push_back(depthRow(k * kTexel, kBad, 0, 2048));
    const AutoBias a = recommendBias(rows);
    ASSERT_EQ(a.series.size(), 2u);
    EXPECT_EQ(a.primary("depth")->samples.size(), 6u);
    EXPECT_EQ(a.shadowBlock.at("shadow_map_size").get<int>(), 1024);
    EXPECT_NEAR(a.shadowBlock.at("depth_bias").get<double>(), 4 * kTexel, 1e-12);
}

TEST(AutoBias, TheDepthSeriesZeroRowIsAlsoTheSlopeSeriesZeroSample) {
    // defaultGrid renders depth 0 + slope 0 once, as a depth row; the slope series (depth held
    // at 0, same map and filter) starts there too. A map-size row at default biases (no bias
    // override) belongs to neither.
    const std::vector<SweepRow> rows = {depthRow(0, 0.3, 0), depthRow(kTexel, 0, 0), slopeRow(0.5, 0.01, 0),
                                        slopeRow(2, 0, 0), test::mapRow(1024, "none", 0.0, 0.0, 4.0)};
    const AutoBias a = recommendBias(rows);
    const BiasSeries* s = a.primary("slope");
    ASSERT_NE(s, nullptr);
    ASSERT_EQ(s->samples.size(), 3u);
    EXPECT_EQ(s->samples[0].bias, 0.0);
    EXPECT_EQ(s->samples[0].falseShadowRate, 0.3);
    EXPECT_EQ(a.primary("depth")->samples.size(), 2u);
}

TEST(AutoBias, NoBiasRowsGiveAnEmptyBlockAndABadThresholdThrows) {
    const AutoBias a = recommendBias({test::mapRow(1024, "none", 0.001, 0, 4.0)});
    EXPECT_TRUE(a.series.empty());
    EXPECT_TRUE(a.shadowBlock.empty());
    EXPECT_THROW(recommendBias({}, -0.1), scene::InputError);
    EXPECT_THROW(recommendBias({}, std::nan("")), scene::InputError);
}

TEST(AutoBias, TheShadowBlockIsAcceptedByTheSceneLoader) {
    std::vector<SweepRow> rows = depthSeriesWithWindow();
    for (double s : {0.0, 0.5, 2.0}) rows.push_back(slopeRow(s, s == 0 ? kBad : 0, 0));
    rows.push_back(rayRow(1e-4, 0, 0));
    rows.push_back(robustRow("double", 0, 0));
    const AutoBias a = recommendBias(rows);
    const scene::Scene loaded = loadWithShadowBlock(a.shadowBlock, "auto_bias_scene");
    ASSERT_TRUE(loaded.shadow.depthBias.has_value());
    EXPECT_NEAR(*loaded.shadow.depthBias, 4 * kTexel, 1e-12);
    ASSERT_TRUE(loaded.shadow.robustRayOffset.has_value());
    EXPECT_TRUE(*loaded.shadow.robustRayOffset);
    EXPECT_EQ(loaded.shadow.precision, std::optional<std::string>("double"));
    EXPECT_EQ(loaded.shadow.shadowMapSize, std::optional<int>(1024));
}

// A VSM min-variance series at 1e-7 .. 1e-2 (decades): too small a floor lets the blurred
// receiver's own variance shadow it (false), too large a floor lets light through (missed).
std::vector<SweepRow> minVarianceSeries() {
    using test::momentRow;
    return {momentRow("vsm", "min_variance", 1e-7, kBad, 0), momentRow("vsm", "min_variance", 1e-6, kOk, 0),
            momentRow("vsm", "min_variance", 1e-5, 0, 0),    momentRow("vsm", "min_variance", 1e-4, 0, 0),
            momentRow("vsm", "min_variance", 1e-3, 0, kOk),  momentRow("vsm", "min_variance", 1e-2, 0, kBad)};
}

TEST(AutoBias, AFilterableMapsParameterSeriesHasItsOwnWindow) {
    const AutoBias a = recommendBias(minVarianceSeries());
    const BiasSeries* m = a.primary("min_variance");
    ASSERT_NE(m, nullptr);
    EXPECT_EQ(a.primary("depth"), nullptr);
    EXPECT_FALSE(m->window.stiff);
    EXPECT_DOUBLE_EQ(m->window.lo, 1e-6);
    EXPECT_DOUBLE_EQ(m->window.hi, 1e-3);
    EXPECT_TRUE(m->logSpaced);
    // sqrt(1e-6 · 1e-3) = 3.1623e-5, to 3 digits.
    EXPECT_DOUBLE_EQ(m->recommended, 3.16e-5);
    EXPECT_EQ(m->name(), "min variance");
    const std::string d = m->describe();
    EXPECT_NE(d.find("min variance (normalized depth squared; filter vsm, map 1024): parameter window"),
              std::string::npos)
        << d;
    // No depth or slope series chose the block's filter: the parameter is not put in it, and a
    // sentence says with which filter it goes.
    EXPECT_FALSE(a.shadowBlock.contains("min_variance"));
    bool said = false;
    for (const std::string& n : a.notes)
        said = said || (n.find("\"min_variance\"") != std::string::npos && n.find("vsm") != std::string::npos);
    EXPECT_TRUE(said);
}

TEST(AutoBias, AStiffBleedingReductionSeriesNamesLightBleeding) {
    using test::momentRow;
    const AutoBias a = recommendBias({momentRow("vsm", "bleeding_reduction", 0.0, 0, 0.05),
                                      momentRow("vsm", "bleeding_reduction", 0.2, 0, 0.03),
                                      momentRow("vsm", "bleeding_reduction", 0.4, 0.01, 0.02)});
    const BiasSeries* b = a.primary("bleeding_reduction");
    ASSERT_NE(b, nullptr);
    EXPECT_TRUE(b->window.stiff);
    EXPECT_EQ(b->dominant, "missed");
    EXPECT_DOUBLE_EQ(b->recommended, 0.4);  // the best compromise: worst rate 2%
    EXPECT_NE(b->describe().find("light bleeding and leaks"), std::string::npos) << b->describe();
}

TEST(AutoBias, TheBlockCarriesTheParameterWhenItsSeriesRanWithTheBlocksFilter) {
    // The depth series run with VSM (its receiver depth is biased as for `none`), beside the
    // min-variance series: the block's filter is vsm, so the parameter window's middle joins it.
    std::vector<SweepRow> rows;
    for (SweepRow r : depthSeriesWithWindow()) {
        r.config.overrides.filter = "vsm";
        r.key = r.config.key();
        rows.push_back(r);
    }
    for (const SweepRow& r : minVarianceSeries()) rows.push_back(r);
    const AutoBias a = recommendBias(rows);
    ASSERT_NE(a.primary("depth"), nullptr);
    EXPECT_EQ(a.shadowBlock.at("filter").get<std::string>(), "vsm");
    EXPECT_DOUBLE_EQ(a.shadowBlock.at("min_variance").get<double>(), 3.16e-5);
    const scene::Scene loaded = loadWithShadowBlock(a.shadowBlock, "auto_bias_moment_scene");
    EXPECT_EQ(loaded.shadow.filter, std::optional<std::string>("vsm"));
    ASSERT_TRUE(loaded.shadow.minVariance.has_value());
    EXPECT_DOUBLE_EQ(*loaded.shadow.minVariance, 3.16e-5);
}

}  // namespace
}  // namespace shadowlab::studies
