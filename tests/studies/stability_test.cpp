// tests/studies/stability_test.cpp: every scenes/extreme case through the stability suite at
// small resolution (reference, analytic oracle, lavapipe raster with validation, ray tracer,
// a small bias search), asserting each case's expected outcome; plus the runner's failure
// handling with a fake renderer.
#include "studies/stability.h"

#include <algorithm>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <set>
#include <stdexcept>

#include <gtest/gtest.h>

#include "scene/loader.h"

namespace shadowlab::studies {
namespace {
namespace fs = std::filesystem;

StabilityOptions smallOptions() {
    StabilityOptions o;
    o.width = 96;
    o.height = 54;
    o.shadowMapSize = 512;
    o.searchMapSize = 512;
    o.biasSeriesOnly = true;
    o.validate = true;
    return o;
}

// Expected bias-search verdicts, from each case's physics (measured to agree at 96x54, map 512;
// docs/stability.md has the numbers). Cases in neither set sit within a few pixels of the 0.1%
// threshold at this resolution (contact-box, coplanar-quads, grazing-0.1deg, slivers,
// thin-occluder) and are reported, not asserted.
// Stiff for the raster:
// - grazing-1deg: the plane's depth slope toward the light is tan 89° = 57 texels per texel;
//   the constant or slope bias that removes acne there exceeds the sphere's depth extent along
//   the light near the contact, so the shadow detaches (leaks dominate).
// - tiny-and-huge: the map is fitted to the bounding sphere of the whole scene, which the
//   radius-1000 sphere makes ~100x larger: the seed sphere covers a few texels of a 512 map and
//   its shadow is lost in them whatever the bias (leaks dominate).
const std::set<std::string> kRasterStiff = {"grazing-1deg", "tiny-and-huge"};
// A bias window for the raster: moderate slopes at sensible scale, or scale-invariant defaults
// (far-*, scale-*, near-far only move or scale the seed scene; the raster is camera-relative).
const std::set<std::string> kRasterWindow = {"far-1e5",    "far-1e7",   "grazing-0deg", "near-far-1e-5",
                                             "scale-1e-3", "scale-1e4", "straight-down"};
// Stiff for the float ray tracer with the lesson's constant ray bias: at 1e7 the float spacing
// (1.0) is the sphere's radius, so primary and shadow hit points are off by whole units and no
// bias can separate acne from leaks; robust offsets in float cannot fix that either (only double).
const std::set<std::string> kRaytraceStiff = {"far-1e7"};
const std::set<std::string> kRaytraceWindow = {"contact-box",   "coplanar-quads", "grazing-0deg",  "near-far-1e-5",
                                               "scale-1e-3",    "scale-1e4",      "straight-down", "slivers",
                                               "thin-occluder", "tiny-and-huge"};

std::vector<std::string> extremeCases() {
    std::vector<std::string> names;
    for (const auto& e : fs::directory_iterator(scene::scenesDirectory() / "extreme"))
        if (e.path().extension() == ".json") names.push_back(e.path().stem().string());
    std::sort(names.begin(), names.end());
    return names;
}

class ExtremeCase : public ::testing::TestWithParam<std::string> {};

TEST_P(ExtremeCase, MeetsItsExpectedOutcome) {
    const fs::path file = scene::scenesDirectory() / "extreme" / (GetParam() + ".json");
    const scene::Scene s = scene::loadScene(file);
    const StabilityCase c = runStabilityCase(s, smallOptions(), GetParam(), readDescription(file));

    for (const std::string& f : c.failures) ADD_FAILURE() << GetParam() << ": " << f;
    ASSERT_TRUE(c.referenceOk) << c.referenceError;
    EXPECT_EQ(c.referenceHealth.total(), 0u);
    // Reference exact where analytic: every case but the mesh one is analytic.
    if (GetParam() == "slivers") {
        EXPECT_FALSE(c.analytic.has_value());
    } else {
        ASSERT_TRUE(c.analytic.has_value()) << c.notAnalytic;
        EXPECT_TRUE(c.analytic->passed()) << c.analytic->summary();
    }
    for (const scene::Backend backend : {scene::Backend::Raster, scene::Backend::Raytrace})
        for (const char* variant : {"defaults", "best"}) {
            const BackendRun* r = c.run(backend, variant);
            const std::string what = std::string(scene::toString(backend)) + " " + variant;
            ASSERT_NE(r, nullptr) << what;
            EXPECT_TRUE(r->ok) << what << ": " << r->error;
            EXPECT_EQ(r->health.total(), 0u) << what;
            EXPECT_FALSE(r->blackFrame) << what;
            if (backend == scene::Backend::Raster) {
                EXPECT_EQ(r->validationMessages, 0) << variant;
            }
        }
    // The best settings never lose to the defaults (they are searched and then checked against them).
    for (const scene::Backend backend : {scene::Backend::Raster, scene::Backend::Raytrace}) {
        const BackendRun* d = c.run(backend, "defaults");
        const BackendRun* b = c.run(backend, "best");
        if (d && b) {
            EXPECT_LE(b->mismatchRate, d->mismatchRate) << scene::toString(backend) << " " << c.bestShadowBlock.dump();
        }
    }
    const MethodBias* raster = c.biasOf(scene::Backend::Raster);
    ASSERT_NE(raster, nullptr);
    if (kRasterStiff.count(GetParam())) {
        EXPECT_TRUE(raster->stiff) << raster->text;
    }
    if (kRasterWindow.count(GetParam())) {
        EXPECT_FALSE(raster->stiff) << raster->text;
    }
    const MethodBias* ray = c.biasOf(scene::Backend::Raytrace);
    ASSERT_NE(ray, nullptr);
    if (kRaytraceStiff.count(GetParam())) {
        EXPECT_TRUE(ray->stiff) << ray->text;
        EXPECT_NE(ray->text.find("Robust offsets (float): false"), std::string::npos);
        EXPECT_NE(ray->text.find("(fail)"), std::string::npos) << ray->text;
    }
    if (kRaytraceWindow.count(GetParam())) {
        EXPECT_FALSE(ray->stiff) << ray->text;
    }
    EXPECT_FALSE(c.failed());
    std::cout << GetParam() << ": raster " << raster->text << "\n  raytrace "
              << (c.biasOf(scene::Backend::Raytrace) ? c.biasOf(scene::Backend::Raytrace)->text : "") << "\n";
}

std::string paramName(const ::testing::TestParamInfo<std::string>& info) {
    std::string n = info.param;
    for (char& ch : n)
        if (!std::isalnum(static_cast<unsigned char>(ch))) ch = '_';
    return n;
}

INSTANTIATE_TEST_SUITE_P(Extreme, ExtremeCase, ::testing::ValuesIn(extremeCases()), paramName);

// Not run by ctest: writes the full suite's report at 320x180 for docs/stability.md, e.g.
// SHADOWLAB_STABILITY_OUT=/tmp/st stability_tests --gtest_also_run_disabled_tests
//   --gtest_filter='*DISABLED_WriteReport*'
TEST(StabilityTest, DISABLED_WriteReport) {
    const char* out = std::getenv("SHADOWLAB_STABILITY_OUT");
    ASSERT_NE(out, nullptr);
    StabilityOptions o;
    o.width = 320;
    o.height = 180;
    o.validate = true;
    std::vector<StabilityCase> cases;
    for (const std::string& name : extremeCases()) {
        const fs::path file = scene::scenesDirectory() / "extreme" / (name + ".json");
        cases.push_back(runStabilityCase(scene::loadScene(file), o, name, readDescription(file)));
        const StabilityCase& c = cases.back();
        std::cout << name << ": reference " << c.referenceVerdict() << "; raster "
                  << stateOf(c.run(scene::Backend::Raster, "defaults"), false).text << " / "
                  << stateOf(c.run(scene::Backend::Raster, "best"), true).text << "; raytrace "
                  << stateOf(c.run(scene::Backend::Raytrace, "defaults"), false).text << " / "
                  << stateOf(c.run(scene::Backend::Raytrace, "best"), true).text
                  << (c.failed() ? "; FAILED to run cleanly" : "") << std::endl;
    }
    writeStabilityReport(out, cases);
}

TEST(StabilityTest, EveryShippedCaseIsCovered) {
    // The suite must not silently shrink: the lead shipped 14 cases.
    EXPECT_GE(extremeCases().size(), 14u);
    EXPECT_EQ(extremeSceneFiles().size(), extremeCases().size());
}

TEST(StabilityTest, SuiteRecordsAnUnloadableSceneAsAFailedCase) {
    const fs::path bad = fs::temp_directory_path() / "shadowlab_stability_bad.json";
    std::ofstream(bad) << "{ \"description\": \"broken\", \"objects\": 3 }";
    StabilityOptions o;
    o.search = false;
    int calls = 0;
    const auto cases = runStabilitySuite({bad}, o, [&](const StabilityCase&) { ++calls; });
    fs::remove(bad);
    ASSERT_EQ(cases.size(), 1u);
    EXPECT_EQ(calls, 1);
    EXPECT_TRUE(cases[0].failed());
    EXPECT_EQ(cases[0].description, "broken");
    EXPECT_NE(cases[0].failures[0].find("failed to load"), std::string::npos);
    EXPECT_FALSE(suitePassed(cases));
}

scene::Scene tinyScene() {
    scene::Scene s;
    s.materials.push_back({});
    // A point light makes the scene non-analytic, so the fake frames are judged on health only.
    scene::Light l;
    l.type = scene::LightType::Point;
    l.position = {0, 5, 0};
    s.lights.push_back(l);
    scene::Quad q;
    q.size = {20, 20};
    s.objects.push_back({"ground", q, 0});
    s.objects.push_back({"sphere", scene::Sphere{{0, 1, 0}, 1.0}, 0});
    return s;
}

// A fake backend: a flat lit frame for the reference, and per-backend breakage.
scene::Frame fakeFrame(int w, int h, float value) {
    scene::Frame f = scene::Frame::allocate(w, h, true);
    std::fill(f.beauty.begin(), f.beauty.end(), value);
    std::fill(f.visibility.begin(), f.visibility.end(), 1.0f);
    std::fill(f.objectId.begin(), f.objectId.end(), 1.0f);
    std::fill(f.ndotl.begin(), f.ndotl.end(), 1.0f);
    std::fill(f.depth.begin(), f.depth.end(), 1.0f);
    return f;
}

TEST(StabilityTest, CrashNanAndBlackFramesFailTheCase) {
    StabilityOptions o;
    o.width = 8;
    o.height = 4;
    o.search = false;
    o.render = [](const scene::Scene& s, const scene::RenderSettings&, scene::Backend backend) {
        if (backend == scene::Backend::Raster) throw std::runtime_error("device lost");
        scene::Frame f = fakeFrame(s.camera.width, s.camera.height, backend == scene::Backend::Reference ? 0.5f : 0.0f);
        return f;
    };
    StabilityCase c = runStabilityCase(tinyScene(), o, "fake");
    ASSERT_NE(c.run(scene::Backend::Raster, "defaults"), nullptr);
    EXPECT_FALSE(c.run(scene::Backend::Raster, "defaults")->ok);
    EXPECT_EQ(c.run(scene::Backend::Raster, "defaults")->error, "device lost");
    EXPECT_TRUE(c.run(scene::Backend::Raytrace, "defaults")->blackFrame);
    EXPECT_TRUE(c.failed());
    EXPECT_FALSE(suitePassed({c}));

    o.render = [](const scene::Scene& s, const scene::RenderSettings&, scene::Backend backend) {
        scene::Frame f = fakeFrame(s.camera.width, s.camera.height, 0.5f);
        if (backend == scene::Backend::Raytrace) f.ndotl[3] = std::numeric_limits<float>::quiet_NaN();
        return f;
    };
    c = runStabilityCase(tinyScene(), o, "fake");
    EXPECT_EQ(c.run(scene::Backend::Raytrace, "defaults")->health.total(), 1u);
    EXPECT_FALSE(c.run(scene::Backend::Raster, "defaults")->failed());
    ASSERT_EQ(c.failures.size(), 1u);
    EXPECT_NE(c.failures[0].find("NaN"), std::string::npos);
}

TEST(StabilityTest, ReportFilesAreWritten) {
    StabilityOptions o;
    o.width = 8;
    o.height = 4;
    o.search = false;
    o.render = [](const scene::Scene& s, const scene::RenderSettings&, scene::Backend) {
        return fakeFrame(s.camera.width, s.camera.height, 0.5f);
    };
    const StabilityCase c = runStabilityCase(tinyScene(), o, "fake");
    EXPECT_FALSE(c.failed());
    const fs::path dir = fs::temp_directory_path() / "shadowlab_stability_test";
    fs::remove_all(dir);
    writeStabilityReport(dir, {c});
    for (const char* f : {"stability.html", "stability.csv", "stability.json", "stability/fake-reference.png",
                          "stability/fake-raster-diff.png"})
        EXPECT_TRUE(fs::exists(dir / f)) << f;
    std::ifstream in(dir / "stability.json");
    const nlohmann::json j = nlohmann::json::parse(in);
    EXPECT_TRUE(j["passed"].get<bool>());
    EXPECT_EQ(j["cases"][0]["health"], "ok");
    EXPECT_EQ(j["cases"][0]["reference_verdict"], "unchecked");
    fs::remove_all(dir);
}

// A fake raster whose defaults darken the first 26 of 200 lit pixels (13% acne) while a constant
// bias of at least `cleanFrom` is clean; the reference and the ray tracer are exact.
StabilityOptions acneOptions(double cleanFrom) {
    StabilityOptions o;
    o.width = 20;
    o.height = 10;
    o.render = [cleanFrom](const scene::Scene& s, const scene::RenderSettings& settings, scene::Backend backend) {
        scene::Frame f = fakeFrame(s.camera.width, s.camera.height, 0.5f);
        if (backend == scene::Backend::Raster && settings.raster.depthBias < cleanFrom)
            for (int i = 0; i < 26; ++i) f.visibility[i] = 0.0f;
        f.attributes["validation_messages"] = "0";
        return f;
    };
    return o;
}

TEST(StabilityVerdicts, InjectedAcneAtDefaultsShowsTheAcneStateNotAPass) {
    StabilityOptions o = acneOptions(1e30);  // never clean
    o.search = false;
    const StabilityCase c = runStabilityCase(tinyScene(), o, "acne");
    EXPECT_FALSE(c.failed());                      // nothing crashed: the run is healthy, the shadows are not
    EXPECT_EQ(c.referenceVerdict(), "unchecked");  // a point light: no analytic answer
    const BackendState raster = stateOf(c.run(scene::Backend::Raster, "defaults"), false);
    EXPECT_EQ(raster.state, "acne");
    EXPECT_EQ(raster.text, "acne 13.0%");  // 26 / 200
    EXPECT_EQ(stateOf(c.run(scene::Backend::Raytrace, "defaults"), false).state, "clean");
    const nlohmann::json j = toJson(c);
    EXPECT_EQ(j["states"]["raster"]["defaults"]["state"], "acne");
    EXPECT_EQ(j["states"]["raytrace"]["defaults"]["state"], "clean");
    EXPECT_FALSE(j.contains("verdict"));
    const fs::path dir = fs::temp_directory_path() / "shadowlab_stability_acne";
    fs::remove_all(dir);
    writeStabilityReport(dir, {c});
    std::ifstream in(dir / "stability.html");
    const std::string html((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
    EXPECT_NE(html.find("<td class=\"st-acne\">acne 13.0%</td>"), std::string::npos);
    EXPECT_NE(html.find("<td class=\"ref-unchecked\">unchecked</td>"), std::string::npos);
    EXPECT_EQ(html.find("PASS"), std::string::npos);
    fs::remove_all(dir);
}

TEST(StabilityVerdicts, TheBestBiasIsCleanWhenTheSearchFindsOneAndStiffWhenNot) {
    // Clean from 3 default half-texels: the search's 4 × b0 points are clean.
    scene::Scene s = tinyScene();
    s.camera.width = 20;
    s.camera.height = 10;
    const double b0 = scene::resolveSettings(s, {}).raster.depthBias;
    StabilityCase c = runStabilityCase(tinyScene(), acneOptions(3.0 * b0), "fixable");
    EXPECT_EQ(stateOf(c.run(scene::Backend::Raster, "defaults"), false).state, "acne");
    EXPECT_EQ(stateOf(c.run(scene::Backend::Raster, "best"), true).state, "clean") << c.bestShadowBlock.dump();
    EXPECT_GE(c.bestShadowBlock.at("depth_bias").get<double>(), 3.0 * b0);
    // Never clean: the best bias is stiff, and says what remains.
    c = runStabilityCase(tinyScene(), acneOptions(1e30), "stiff");
    const BackendState best = stateOf(c.run(scene::Backend::Raster, "best"), true);
    EXPECT_EQ(best.state, "stiff");
    EXPECT_EQ(best.text, "stiff: acne 13.0%");
    EXPECT_FALSE(c.bestShadowBlock.contains("depth_bias"));  // nothing beat the defaults
}

}  // namespace
}  // namespace shadowlab::studies
