// tests/studies/run_test.cpp: the `run` study called as a library: the folder it writes as one set,
// the names it owns, and what it tells as it goes. The reference and the ray tracer only (no
// device, no sweep), on the seed scene at 48x27, so a run takes about a second.
#include "studies/run.h"

#include <filesystem>
#include <fstream>
#include <set>
#include <sstream>

#include <gtest/gtest.h>

#include "raster/memory.h"
#include "scene/loader.h"

namespace shadowlab::studies {
namespace {

namespace fs = std::filesystem;
using Json = nlohmann::json;

// Records what a run tells, in order.
struct Recorder final : RunProgress {
    std::vector<std::string> events;
    int open = 0;  // stages begun and not ended
    int deepest = 0;
    void begin(const std::string& stage) override {
        events.push_back("begin " + stage);
        deepest = std::max(deepest, ++open);
    }
    void end(const std::string& note) override {
        events.push_back("end " + note);
        --open;
    }
    void backendFailed(scene::Backend backend, const std::string&) override {
        events.push_back(std::string("failed ") + scene::toString(backend));
        --open;
    }
    void budgets(const std::string& method, const std::vector<compare::BudgetCheck>& checks) override {
        events.push_back("budgets " + method + " " + std::to_string(checks.size()));
    }
};

class RunStudy : public ::testing::Test {
protected:
    void SetUp() override {
        dir = fs::path(::testing::TempDir()) /
              ("shadowlab_run_" + std::string(::testing::UnitTest::GetInstance()->current_test_info()->name()));
        fs::remove_all(dir);
        fs::create_directories(dir);
        scene = scene::loadScene(scene::findScene("seed"));
        scene.camera.width = 48;
        scene.camera.height = 27;
        settings = scene::resolveSettings(scene, {});
        plan = scene::makeRenderPlan(scene, settings);
    }
    void TearDown() override { fs::remove_all(dir); }

    RunStudyResult run(RunProgress* progress, const scene::Budgets& budgets = {}) {
        RunStudyOptions o;
        o.outputDir = dir;
        o.raster = false;
        o.sweep = false;
        o.budgets = budgets;
        o.progress = progress;
        return runStudy(scene, settings, plan, o);
    }

    std::set<std::string> filesInFolder() const {
        std::set<std::string> names;
        for (const auto& e : fs::directory_iterator(dir)) names.insert(e.path().filename().string());
        return names;
    }

    fs::path dir;
    scene::Scene scene;
    scene::RenderSettings settings;
    scene::RenderPlan plan;
};

TEST_F(RunStudy, WritesTheReferenceAndTheRayTracerAsOneSetListedInItsManifestAndKeepsTheUsersFiles) {
    std::ofstream(dir / "notes.txt") << "mine\n";
    Recorder recorder;
    scene::Budgets budgets;
    budgets[scene::BudgetKind::MaxMismatch] = scene::parseBudgetLimit("100%", scene::BudgetKind::MaxMismatch, "test");
    const RunStudyResult r = run(&recorder, budgets);

    EXPECT_FALSE(r.backendFailed);
    EXPECT_FALSE(r.budgetBroken);  // no method can mismatch more than every pixel
    EXPECT_GT(r.memoryEstimate, 0u);
    // The run's files (README.md, "What `run` writes"), by the backends' names; no raster file.
    const std::set<std::string> files = filesInFolder();
    for (const char* name : {"reference.exr", "reference.png", "raytrace.exr", "raytrace.png", "diff-raytrace.png",
                             "heat-raytrace.png", "metrics.json", "report.html", ".shadowlab-run.json", "notes.txt"})
        EXPECT_EQ(files.count(name), 1u) << name;
    for (const std::string& name : files) EXPECT_EQ(name.rfind("raster", 0), std::string::npos) << name;
    // The manifest lists exactly what the run wrote: every file but the user's and itself.
    std::ifstream in(dir / ".shadowlab-run.json");
    const Json manifest = Json::parse(in);
    std::set<std::string> listed;
    for (const Json& n : manifest.at("files")) listed.insert(n.get<std::string>());
    std::set<std::string> expected = files;
    expected.erase("notes.txt");
    expected.erase(".shadowlab-run.json");
    EXPECT_EQ(listed, expected);
    for (const std::string& name : listed) EXPECT_TRUE(isRunOutput(name)) << name;

    // metrics.json is what the result holds: the reference's record and the ray tracer's method,
    // keyed by the backends' names, with the budget checked; no sweep was asked for.
    std::ifstream m(dir / "metrics.json");
    const Json written = Json::parse(m);
    EXPECT_EQ(written, r.metrics);
    EXPECT_TRUE(written.at("reference").contains("timings_ms"));
    EXPECT_TRUE(written.at("methods").at("raytrace").at("metrics").contains("mismatch_rate"));
    EXPECT_EQ(written.at("methods").at("raytrace").at("budgets").size(), 1u);
    EXPECT_FALSE(written.at("methods").contains("raster"));
    EXPECT_FALSE(written.contains("sweep"));
    EXPECT_TRUE(written.contains("memory"));

    // Two stages, each ended, the budgets told right after the ray tracer's.
    ASSERT_EQ(recorder.events.size(), 5u);
    EXPECT_EQ(recorder.events[0], "begin reference (double precision, robust offsets)");
    EXPECT_EQ(recorder.events[1], "end ");
    EXPECT_EQ(recorder.events[2], "begin raytrace (shadow rays)");
    EXPECT_EQ(recorder.events[3].rfind("end ", 0), 0u);
    EXPECT_EQ(recorder.events[4], "budgets raytrace 1");
    EXPECT_EQ(recorder.open, 0);
    EXPECT_EQ(recorder.deepest, 1);
}

TEST_F(RunStudy, ASecondRunRemovesWhatTheEarlierManifestListedAndNeedsNoProgressReporter) {
    run(nullptr);
    // A name the earlier run's manifest lists that this run does not write (run names its own
    // files; the manifest is what proves an earlier run wrote this one), and a file of the user's.
    std::ofstream(dir / "earlier-extra.txt") << "earlier\n";
    std::ofstream(dir / "notes.txt") << "mine\n";
    Json manifest = Json::parse(std::ifstream(dir / ".shadowlab-run.json"));
    manifest["files"].push_back("earlier-extra.txt");
    std::ofstream(dir / ".shadowlab-run.json") << manifest.dump();
    const RunStudyResult r = run(nullptr);
    EXPECT_FALSE(r.backendFailed);
    const std::set<std::string> files = filesInFolder();
    EXPECT_EQ(files.count("earlier-extra.txt"), 0u);
    EXPECT_EQ(files.count("notes.txt"), 1u);
    EXPECT_EQ(files.count("raytrace.exr"), 1u);
}

TEST(RunOutputNames, AreTheBackendsFramesAndImagesAndTheRunsOwnFiles) {
    // README.md, "What `run` writes": each backend's Frame and image, the difference and heat
    // images, the raster debug views, metrics.json, report.html, sweep/ and the manifest.
    for (const char* name :
         {"reference.exr", "reference.png", "raytrace.exr", "raytrace.png", "raster.exr", "raster.png",
          "diff-raster.png", "heat-raytrace.png", "heat-raster-light1.png", "raster-shadow-map.png",
          "raster-cascades.png", "metrics.json", "report.html", "sweep", ".shadowlab-run.json"})
        EXPECT_TRUE(isRunOutput(name)) << name;
    // A user's files, and names that only look like the run's.
    for (const char* name : {"notes.txt", "raster.txt", "raytrace.exr.bak", "diff-.png", "raster-.png",
                             "heat-raster.jpg", "sweep2", "mask.png", ".shadowlab.lock"})
        EXPECT_FALSE(isRunOutput(name)) << name;
}

// The estimate counts one renderer at a time, the largest: with the quick sweep, its rows' at half
// size, among them a filterable map of 2048² (its moment arrays and compute pipeline), which the
// run's own pcf2x2 frame does not have.
TEST_F(RunStudy, TheMemoryEstimateCountsTheLargestOfTheSweepsRenderers) {
    RunStudyOptions o;
    o.sweep = false;
    const JobMemory alone = estimateRunMemory(scene, settings, plan, o);
    const std::uint64_t ownRaster = raster::estimateMemoryBytes(scene, plan, settings.raster);
    EXPECT_EQ(alone.largestRenderer, ownRaster);  // the 48x27 frame's raster renderer outweighs its tracer

    o.sweep = true;
    const JobMemory swept = estimateRunMemory(scene, settings, plan, o);
    scene::Scene half = scene;
    half.camera.width = 24;  // half of 48x27, at least 16 a side
    half.camera.height = 16;
    scene::SettingsOverrides vsm;
    vsm.filter = "vsm";
    vsm.shadowMapSize = 2048;
    const scene::RenderSettings vsmSettings = scene::resolveSettings(half, vsm);
    const std::uint64_t vsmRaster =
        raster::estimateMemoryBytes(half, scene::makeRenderPlan(half, vsmSettings), vsmSettings.raster);
    ASSERT_GT(vsmRaster, ownRaster);
    EXPECT_GE(swept.largestRenderer, vsmRaster);
    EXPECT_EQ(swept.total - alone.total, swept.largestRenderer - ownRaster);

    // Without the raster backend the sweep's rows are ray-traced at half size: nothing larger
    o.raster = false;
    o.sweep = false;
    const JobMemory tracerOnly = estimateRunMemory(scene, settings, plan, o);
    o.sweep = true;
    EXPECT_EQ(estimateRunMemory(scene, settings, plan, o).total, tracerOnly.total);
    // (and no raster renderer or debug views in the run itself)
    EXPECT_EQ(tracerOnly.total,
              alone.total - ownRaster - raster::debugViewBytes(scene, plan, settings.raster, "shadow-map"));
}

}  // namespace
}  // namespace shadowlab::studies
