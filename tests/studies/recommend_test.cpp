// tests/studies/recommend_test.cpp: the recommended "shadow" block never loses to the user's
// defaults. With a fake renderer whose error is a known function of the biases: the search finds
// an optimum off the coarse grid by refinement, keeps the defaults when they are best, and keeps
// them when the candidate loses at the requested resolution. With lavapipe (validation on) and
// the reference: on the seed and on a stiff extreme case, the block pasted into the scene file
// renders with no more mismatch than the defaults.
#include "studies/recommend.h"

#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>

#include <gtest/gtest.h>

#include "compare/compare.h"
#include "scene/loader.h"
#include "tests/kit/render_checked.h"
#include "tests/kit/test_scenes.h"

namespace shadowlab::studies {
namespace {

namespace fs = std::filesystem;
using Json = nlohmann::json;

// A one-row scene-less "scene": the fake renderer only reads the camera size and the settings.
scene::Scene fakeScene(int width) {
    scene::Scene s = scene::loadScene(scene::findScene("seed"));
    s.camera.width = width;
    s.camera.height = 1;
    return s;
}

// Every pixel is object 1 facing the light, lit in the reference; the fake method darkens the
// first `wrong` pixels (false shadow), so its mismatch rate is wrong / width.
scene::Frame row(int width, int wrong) {
    scene::Frame f = scene::Frame::allocate(width, 1, false);
    for (int i = 0; i < width; ++i) {
        f.objectId[i] = 1.0f;
        f.ndotl[i] = 1.0f;
        f.visibility[i] = i < wrong ? 0.0f : 1.0f;
        for (int c = 0; c < 3; ++c) f.beauty[3 * i + c] = 0.5f;
    }
    return f;
}

// The fake's error: 10 pixels per octave away from (depth*, slope*), 200 when a bias is 0.
int octaves(double v, double target) {
    return v > 0.0 ? int(std::lround(10.0 * std::fabs(std::log2(v / target)))) : 200;
}

struct Fake {
    double depthTarget = 0.0, slopeTarget = 2.0;
    // Used at this width only: the candidate loses there (for the "never loses" case).
    int loseAtWidth = 0;
    // The map-size cap: a frame at the default size reports this many texels needed (0: none),
    // and a map of at most 2048 texels adds smallMapFloor wrong pixels (aliasing a larger one fixes).
    double neededMap = 0.0;
    bool neededEvenWhenSet = false;  // report it at a size the user set too (the guard is the caller's)
    int smallMapFloor = 0;
    // A curved receiver's terminator band: this many wrong pixels at every bias unless the lookup
    // moves at least bandClearedAt texels along the normal; each texel of offset beyond that
    // loses offsetCost pixels of contact shadow.
    int grazingBand = 0;
    double bandClearedAt = 0.5;
    int offsetCost = 10;
    int renders = 0;
    scene::Frame operator()(const scene::Scene& s, const scene::RenderSettings& settings, scene::Backend backend) {
        ++renders;
        const int w = s.camera.width;
        if (backend == scene::Backend::Reference) return row(w, 0);
        int wrong = 0;
        if (backend == scene::Backend::Raster) {
            wrong = octaves(settings.raster.depthBias, depthTarget) + octaves(settings.raster.slopeBias, slopeTarget);
            if (w == loseAtWidth && !settings.raster.depthBiasIsDefault) wrong = w;
            if (settings.raster.shadowMapSize <= 2048) wrong += smallMapFloor;
            const double offset = settings.raster.normalOffset;
            wrong += offset >= bandClearedAt ? int(std::lround(offsetCost * (offset - bandClearedAt) / bandClearedAt))
                                             : grazingBand;
        } else {
            wrong = settings.raytrace.robustOffset ? 0 : 3;
        }
        scene::Frame f = row(w, std::min(wrong, w));
        char buf[40];
        std::snprintf(buf, sizeof buf, "%.9g", settings.raster.depthBias);
        f.attributes["depth_bias"] = buf;
        f.attributes["filter"] = "pcf2x2";
        f.attributes["shadow_map_size"] = std::to_string(settings.raster.shadowMapSize);
        if (neededMap > 0.0 && (settings.raster.shadowMapSizeIsDefault || neededEvenWhenSet))
            f.attributes["shadow_map_size_needed"] = std::to_string(int(neededMap));
        return f;
    }
};

// Options whose renderer is `fake` (shared, so a test can read its render count afterwards).
RecommendOptions fakeOptions(const std::shared_ptr<Fake>& fake) {
    RecommendOptions o;
    o.render = [fake](const scene::Scene& sc, const scene::RenderSettings& st, scene::Backend b) {
        return (*fake)(sc, st, b);
    };
    return o;
}

TEST(Recommend, RefinementFindsTheOptimumBetweenCoarsePointsAndTheBlockHoldsIt) {
    const scene::Scene s = fakeScene(1000);
    const double b0 = scene::resolveSettings(s, {}).raster.depthBias;  // the default half texel
    auto fake = std::make_shared<Fake>();
    // Optimum at depth 2·b0, slope 2: off the coarse grid (b0 × {0,1,4,16}, slope {0,1,4}); the
    // coarse best is (b0, 1) or (4b0, 4) at 20 px; its geometric midpoints reach (2b0, 2): 0 px.
    fake->depthTarget = 2.0 * b0;
    RecommendOptions o = fakeOptions(fake);
    const scene::Frame ref = row(1000, 0);
    const Recommendation r = recommendShadow(s, ref, s, ref, nullptr, nullptr, Json{{"ray_bias", "robust"}}, o);
    ASSERT_GE(r.best, 0);
    const BiasPoint& best = r.points[r.best];
    EXPECT_TRUE(best.refined);
    // Values are rounded to 3 significant digits: within half a unit of the third, 0.5% of the value.
    EXPECT_NEAR(best.depthBias, 2.0 * b0, 5e-3 * 2.0 * b0);
    EXPECT_EQ(best.slopeBias, 2.0);
    EXPECT_TRUE(r.raster.beatsDefaults);
    // Defaults: (b0, 1) is one octave off on each axis: 20 px of 1000.
    EXPECT_DOUBLE_EQ(r.raster.defaults.mismatchRate, 0.02);
    EXPECT_LE(r.raster.recommended.mismatchRate, 0.001);
    EXPECT_NEAR(r.shadowBlock.at("depth_bias").get<double>(), 2.0 * b0, 5e-3 * 2.0 * b0);
    EXPECT_EQ(r.shadowBlock.at("slope_bias").get<double>(), 2.0);
    // The ray tracer's robust candidate (0 px against 3) wins too.
    EXPECT_EQ(r.shadowBlock.at("ray_bias"), "robust");
    // Bounded cost: 12 coarse points (one of them the defaults) + at most 8 refined, + 2 checks.
    EXPECT_LE(r.points.size(), 20u);
    const Json file = r.toJson();
    EXPECT_DOUBLE_EQ(file["measured"]["raster"]["mismatch_rate_gain"].get<double>(),
                     0.02 - r.raster.recommended.mismatchRate);
    EXPECT_EQ(file["shadow"], r.shadowBlock);
    // The block is a valid scene-file "shadow" block.
    Json doc;
    std::ifstream(scene::findScene("seed")) >> doc;
    doc["shadow"] = r.shadowBlock;
    const fs::path tmp = fs::temp_directory_path() / "shadowlab-recommend-block.json";
    std::ofstream(tmp) << doc.dump();
    EXPECT_NO_THROW(scene::loadScene(tmp));
    fs::remove(tmp);
}

TEST(Recommend, KeepsTheDefaultsWhenNothingSearchedBeatsThem) {
    const scene::Scene s = fakeScene(1000);
    const double b0 = scene::resolveSettings(s, {}).raster.depthBias;
    auto fake = std::make_shared<Fake>();
    fake->depthTarget = b0;  // the defaults (b0, 1) are the optimum: 0 px
    fake->slopeTarget = 1.0;
    RecommendOptions o = fakeOptions(fake);
    o.raytrace = false;
    const scene::Frame ref = row(1000, 0);
    const Recommendation r = recommendShadow(s, ref, s, ref, nullptr, nullptr, Json::object(), o);
    EXPECT_TRUE(r.points[r.best].defaults);
    EXPECT_FALSE(r.raster.beatsDefaults);
    EXPECT_FALSE(r.shadowBlock.contains("depth_bias"));
    EXPECT_FALSE(r.shadowBlock.contains("slope_bias"));
    EXPECT_EQ(r.raster.recommended.mismatchRate, 0.0);
}

TEST(Recommend, ACandidateThatLosesAtTheRequestedResolutionIsNotRecommended) {
    const scene::Scene search = fakeScene(1000), full = fakeScene(2000);
    const double b0 = scene::resolveSettings(search, {}).raster.depthBias;
    auto fake = std::make_shared<Fake>();
    fake->depthTarget = 2.0 * b0;
    fake->loseAtWidth = 2000;  // at 2000 px every explicit bias darkens everything
    RecommendOptions o = fakeOptions(fake);
    o.raytrace = false;
    const Recommendation r =
        recommendShadow(search, row(1000, 0), full, row(2000, 0), nullptr, nullptr, Json::object(), o);
    EXPECT_TRUE(r.raster.searched);
    EXPECT_DOUBLE_EQ(r.raster.tried.mismatchRate, 1.0);
    EXPECT_DOUBLE_EQ(r.raster.defaults.mismatchRate, 0.01);  // 20 px of 2000
    EXPECT_FALSE(r.raster.beatsDefaults);
    EXPECT_FALSE(r.shadowBlock.contains("depth_bias"));
    EXPECT_DOUBLE_EQ(r.raster.recommended.mismatchRate, r.raster.defaults.mismatchRate);
}

// The defaults' biases are the fake's optimum (no bias beats them), but every map of at most 2048
// texels loses 30 px to aliasing, and the receivers ask for 5000 texels: a 4096 map (the largest
// tried) at the default biases, whose depth bias is half a 4096 texel, is rendered and wins.
TEST(Recommend, ALargerMapIsRecommendedWhereTheDefaultSizeCapsWhatTheReceiversAskFor) {
    const scene::Scene s = fakeScene(1000);
    const double b0 = scene::resolveSettings(s, {}).raster.depthBias;
    scene::SettingsOverrides at4096;
    at4096.shadowMapSize = 4096;
    const double b4096 = scene::resolveSettings(s, at4096).raster.depthBias;
    auto fake = std::make_shared<Fake>();
    fake->depthTarget = b0;
    fake->slopeTarget = 1.0;
    fake->neededMap = 5000;
    fake->smallMapFloor = 30;
    RecommendOptions o = fakeOptions(fake);
    o.raytrace = false;
    const scene::Frame ref = row(1000, 0);
    const Recommendation r = recommendShadow(s, ref, s, ref, nullptr, nullptr, Json::object(), o);
    EXPECT_DOUBLE_EQ(r.raster.defaults.mismatchRate, 0.03);
    ASSERT_EQ(r.raster.largerMapSize, 4096);
    // The fake's own error at the 4096 map's default bias, slope 1 on target: no floor.
    const double expected = octaves(b4096, b0) / 1000.0;
    ASSERT_LT(expected, 0.03);
    EXPECT_DOUBLE_EQ(r.raster.largerMap.mismatchRate, expected);
    EXPECT_TRUE(r.raster.largerMapRecommended);
    EXPECT_TRUE(r.raster.beatsDefaults);
    EXPECT_DOUBLE_EQ(r.raster.recommended.mismatchRate, expected);
    EXPECT_EQ(r.shadowBlock.at("shadow_map_size"), 4096);
    EXPECT_FALSE(r.shadowBlock.contains("depth_bias"));
    EXPECT_EQ(r.toJson()["measured"]["raster"]["larger_map"]["shadow_map_size"], 4096);
    // A normal offset of the user's own (which costs the fake nothing) stays in the block beside
    // the larger map, which was rendered with it.
    o.user.normalOffset = 0.5;
    const Recommendation own = recommendShadow(s, ref, s, ref, nullptr, nullptr, Json::object(), o);
    EXPECT_TRUE(own.raster.largerMapRecommended);
    EXPECT_EQ(own.shadowBlock.at("shadow_map_size"), 4096);
    EXPECT_EQ(own.shadowBlock.at("normal_offset"), 0.5);
}

TEST(Recommend, ALargerMapIsNotTriedWhereNothingIsCappedOrTheUserSetTheSize) {
    const scene::Scene s = fakeScene(1000);
    const double b0 = scene::resolveSettings(s, {}).raster.depthBias;
    for (const bool userSize : {false, true}) {
        auto fake = std::make_shared<Fake>();
        fake->depthTarget = b0;
        fake->slopeTarget = 1.0;
        fake->smallMapFloor = 30;
        // With the user's size the frame still says the receivers ask for more: the size is theirs.
        fake->neededMap = userSize ? 5000 : 0;
        fake->neededEvenWhenSet = true;
        RecommendOptions o = fakeOptions(fake);
        o.raytrace = false;
        if (userSize) o.user.shadowMapSize = 2048;
        const Recommendation r = recommendShadow(s, row(1000, 0), s, row(1000, 0), nullptr, nullptr, Json::object(), o);
        EXPECT_EQ(r.raster.largerMapSize, 0) << "user size " << userSize;
        EXPECT_EQ(r.shadowBlock.value("shadow_map_size", 0), userSize ? 2048 : 0);
    }
}

// The biases are at the fake's optimum, but 15 px of terminator band stay at every bias: half a
// texel of normal offset clears them (0 px), one texel clears them and costs 10 px of contact
// shadow. The block adds normal_offset 0.5 and nothing else; with the user's own offset, or
// without the band, no offset is recommended.
TEST(Recommend, ANormalOffsetIsRecommendedWhereItClearsWhatNoBiasDoes) {
    const scene::Scene s = fakeScene(1000);
    const double b0 = scene::resolveSettings(s, {}).raster.depthBias;
    auto make = [&](int band) {
        auto fake = std::make_shared<Fake>();
        fake->depthTarget = b0;
        fake->slopeTarget = 1.0;
        fake->grazingBand = band;
        return fake;
    };
    RecommendOptions o = fakeOptions(make(15));
    o.raytrace = false;
    const scene::Frame ref = row(1000, 0);
    const Recommendation r = recommendShadow(s, ref, s, ref, nullptr, nullptr, Json::object(), o);
    EXPECT_FALSE(r.raster.searched);  // no bias beats the defaults: the band is at every bias
    EXPECT_DOUBLE_EQ(r.raster.defaults.mismatchRate, 0.015);
    ASSERT_EQ(r.raster.normalOffsets.size(), 2u);
    EXPECT_DOUBLE_EQ(r.raster.normalOffsets[0].second.mismatchRate, 0.0);   // 0.5 texel
    EXPECT_DOUBLE_EQ(r.raster.normalOffsets[1].second.mismatchRate, 0.01);  // 1 texel: 10 px lost
    EXPECT_EQ(r.raster.normalOffsetRecommended, 0.5);
    EXPECT_TRUE(r.raster.beatsDefaults);
    EXPECT_DOUBLE_EQ(r.raster.recommended.mismatchRate, 0.0);
    EXPECT_EQ(r.shadowBlock.at("normal_offset"), 0.5);
    EXPECT_FALSE(r.shadowBlock.contains("depth_bias"));
    const Json file = r.toJson();
    EXPECT_EQ(file["measured"]["raster"]["normal_offset_recommended"], 0.5);
    EXPECT_EQ(file["measured"]["raster"]["normal_offsets"].size(), 2u);
    bool said = false;
    for (const std::string& n : r.notes) said = said || n.find("normal offset of 0.5 texels") != std::string::npos;
    EXPECT_TRUE(said);

    RecommendOptions own = fakeOptions(make(15));
    own.raytrace = false;
    own.user.normalOffset = 0.25;  // below what clears the band: the user's, not replaced
    const Recommendation u = recommendShadow(s, ref, s, ref, nullptr, nullptr, Json::object(), own);
    EXPECT_TRUE(u.raster.normalOffsets.empty());
    EXPECT_EQ(u.shadowBlock.at("normal_offset"), 0.25);

    RecommendOptions clean = fakeOptions(make(0));
    clean.raytrace = false;
    const Recommendation c = recommendShadow(s, ref, s, ref, nullptr, nullptr, Json::object(), clean);
    EXPECT_EQ(c.raster.normalOffsets.size(), 2u);
    EXPECT_EQ(c.raster.normalOffsetRecommended, 0.0);
    EXPECT_FALSE(c.shadowBlock.contains("normal_offset"));
}

// A larger map whose default bias is off the optimum (10 px) loses to defaults at 0 px: kept out.
TEST(Recommend, ALargerMapThatDoesNotHelpIsNotRecommended) {
    const scene::Scene s = fakeScene(1000);
    const double b0 = scene::resolveSettings(s, {}).raster.depthBias;
    auto fake = std::make_shared<Fake>();
    fake->depthTarget = b0;
    fake->slopeTarget = 1.0;
    fake->neededMap = 3000;
    RecommendOptions o = fakeOptions(fake);
    o.raytrace = false;
    const Recommendation r = recommendShadow(s, row(1000, 0), s, row(1000, 0), nullptr, nullptr, Json::object(), o);
    EXPECT_EQ(r.raster.largerMapSize, 4096);
    EXPECT_GT(r.raster.largerMap.mismatchRate, 0.0);
    EXPECT_FALSE(r.raster.largerMapRecommended);
    EXPECT_FALSE(r.shadowBlock.contains("shadow_map_size"));
    EXPECT_EQ(r.raster.recommended.mismatchRate, 0.0);
}

TEST(Recommend, KeepsTheUsersOwnSettingsInTheBlock) {
    const scene::Scene s = fakeScene(500);
    auto fake = std::make_shared<Fake>();
    fake->depthTarget = 1e-3;
    RecommendOptions o = fakeOptions(fake);
    o.user.filter = "pcf";
    o.user.shadowMapSize = 1024;
    o.user.fitLightFrustum = false;  // a flag not given: not the user's choice
    o.raytrace = false;
    const scene::Frame ref = row(500, 0);
    const Recommendation r = recommendShadow(s, ref, s, ref, nullptr, nullptr, Json::object(), o);
    EXPECT_EQ(r.shadowBlock.at("filter"), "pcf");
    EXPECT_EQ(r.shadowBlock.at("shadow_map_size"), 1024);
    EXPECT_FALSE(r.shadowBlock.contains("fit_light_frustum"));
}

// The real thing: lavapipe with validation, against the double-precision reference. The block is
// pasted into the scene file (its "shadow" merged over the scene's) and rendered anew, so the
// check does not trust the recommendation's own numbers.
Measured pasted(const fs::path& sceneFile, const Json& block, int w, int h, const scene::Frame& reference) {
    Json doc;
    std::ifstream(sceneFile) >> doc;
    if (!doc.contains("shadow")) doc["shadow"] = Json::object();
    doc["shadow"].update(block);
    const fs::path tmp = fs::temp_directory_path() / ("shadowlab-pasted-" + sceneFile.filename().string());
    std::ofstream(tmp) << doc.dump();
    scene::Scene s = scene::loadScene(tmp);
    fs::remove(tmp);
    s.camera.width = w;
    s.camera.height = h;
    scene::SettingsOverrides v;
    v.validate = true;
    return measure(shadowlab::test::renderChecked(s, scene::resolveSettings(s, v).raster), reference);
}

void checkNeverLoses(const std::string& name) {
    const fs::path file = scene::findScene(name);
    scene::Scene full = scene::loadScene(file), search = full;
    full.camera.width = 160;
    full.camera.height = 90;
    search.camera.width = 80;
    search.camera.height = 45;
    const scene::Frame ref = renderWithBackend(full, scene::resolveSettings(full, {}), scene::Backend::Reference);
    const scene::Frame searchRef =
        renderWithBackend(search, scene::resolveSettings(search, {}), scene::Backend::Reference);
    RecommendOptions o;
    o.user.validate = true;
    o.raytrace = false;
    const Recommendation r = recommendShadow(search, searchRef, full, ref, nullptr, nullptr, Json::object(), o);
    ASSERT_TRUE(r.raster.defaults.ok) << r.raster.defaults.error;
    scene::SettingsOverrides v;
    v.validate = true;
    const Measured defaults =
        measure(shadowlab::test::renderChecked(full, scene::resolveSettings(full, v).raster), ref);
    const Measured block = pasted(file, r.shadowBlock, 160, 90, ref);
    std::printf("%s: %zu points, defaults %.4f%% (IoU %.3f), block %.4f%% (IoU %.3f), block %s\n", name.c_str(),
                r.points.size(), 100 * defaults.mismatchRate, defaults.shadowIoU, 100 * block.mismatchRate,
                block.shadowIoU, r.shadowBlock.dump().c_str());
    EXPECT_LE(block.mismatchRate, defaults.mismatchRate) << r.shadowBlock.dump();
    EXPECT_LE(block.meanAbsVisibilityError, defaults.meanAbsVisibilityError) << r.shadowBlock.dump();
    EXPECT_DOUBLE_EQ(r.raster.recommended.mismatchRate, block.mismatchRate);
}

TEST(RecommendOnLavapipe, OneRendererForEveryPointMeasuresWhatARendererPerPointMeasures) {
    // With the default render function the search draws its points with one raster renderer,
    // changing its biases between them; a wrapper around the same function (not recognised as
    // the default) makes a renderer per point. Every point must measure the same.
    const fs::path file = scene::findScene("extreme/grazing-1deg");
    scene::Scene search = scene::loadScene(file);
    search.camera.width = 80;
    search.camera.height = 45;
    const scene::Frame ref = renderWithBackend(search, scene::resolveSettings(search, {}), scene::Backend::Reference);
    RecommendOptions reused;
    reused.user.validate = true;
    reused.raytrace = false;
    RecommendOptions perPoint = reused;
    perPoint.render = [](const scene::Scene& sc, const scene::RenderSettings& st, scene::Backend b) {
        return renderWithBackend(sc, st, b);
    };
    const Recommendation a = recommendShadow(search, ref, search, ref, nullptr, nullptr, Json::object(), reused);
    const Recommendation b = recommendShadow(search, ref, search, ref, nullptr, nullptr, Json::object(), perPoint);
    ASSERT_EQ(a.points.size(), b.points.size());
    ASSERT_GT(a.points.size(), 10u);
    std::set<double> rates;
    for (std::size_t i = 0; i < a.points.size(); ++i) {
        ASSERT_TRUE(a.points[i].at.ok) << i << ": " << a.points[i].at.error;
        EXPECT_EQ(a.points[i].depthBias, b.points[i].depthBias) << i;
        EXPECT_EQ(a.points[i].slopeBias, b.points[i].slopeBias) << i;
        EXPECT_EQ(a.points[i].at.mismatchRate, b.points[i].at.mismatchRate) << i;
        EXPECT_EQ(a.points[i].at.meanAbsVisibilityError, b.points[i].at.meanAbsVisibilityError) << i;
        rates.insert(a.points[i].at.mismatchRate);
    }
    EXPECT_GT(rates.size(), 3u);  // the biases change what the points measure
    EXPECT_EQ(a.shadowBlock, b.shadowBlock);
}

TEST(RecommendOnLavapipe, TheSeedsBlockIsNoWorseThanItsDefaults) { checkNeverLoses("seed"); }

TEST(RecommendOnLavapipe, AStiffCasesBlockIsNoWorseThanItsDefaults) { checkNeverLoses("extreme/grazing-1deg"); }

}  // namespace
}  // namespace shadowlab::studies
