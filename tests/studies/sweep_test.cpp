// tests/studies/sweep_test.cpp: the sweep runner with a fake renderer (no Vulkan, no ray
// tracing): result files in grid order, refusal to overwrite, resume after a torn journal line,
// refusal of another scene's folder, grid files, and timings as medians without the warm-up.
#include "studies/sweep.h"

#include <sys/stat.h>
#include <algorithm>
#include <chrono>
#include <filesystem>
#include <fstream>
#include <map>
#include <set>
#include <sstream>
#include <stdexcept>

#include <gtest/gtest.h>

#include "scene/error.h"
#include "scene/loader.h"
#include "scene/memory.h"
#include "scene/render_plan.h"
#include "tests/compare/synthetic.h"

namespace shadowlab::studies {
namespace {

namespace fs = std::filesystem;
using Json = nlohmann::json;

// The timed runs of every configuration get these stage times in turn; the untimed warm-up
// gets an outlier that would move any median or minimum/maximum it leaked into.
constexpr double kSetupMs[] = {5.0, 7.0, 6.0, 100.0};
constexpr double kFrameMs[] = {10.0, 30.0, 20.0, 40.0};
constexpr double kWarmUpSetupMs = 1000.0, kWarmUpFrameMs = 9000.0;

// What a render was asked for, as text: one entry per distinct configuration.
std::string describe(const scene::RenderSettings& s, scene::Backend backend) {
    std::ostringstream o;
    o << scene::toString(backend) << " map=" << s.raster.shadowMapSize << " filter=" << scene::toString(s.raster.filter)
      << " depth=" << s.raster.depthBias << " slope=" << s.raster.slopeBias << " ray=" << s.raytrace.rayBias
      << " robust=" << s.raytrace.robustOffset << " precision=" << scene::toString(s.raytrace.precision);
    return o.str();
}

// Counts calls per configuration, returns uniform synthetic frames with scripted timings, and
// fails (like a lost device) on configurations it is told to.
struct FakeRenderer {
    std::map<std::string, int> calls;  // by describe(); the reference included
    int referenceCalls = 0, methodCalls = 0;
    double failDepthBias = -1.0;  // a raster render with this depth bias throws

    RenderFn fn() {
        return [this](const scene::Scene& sc, const scene::RenderSettings& s, scene::Backend backend) {
            const int n = calls[describe(s, backend)]++;
            if (backend == scene::Backend::Reference) {
                ++referenceCalls;
            } else {
                ++methodCalls;
            }
            if (backend == scene::Backend::Raster && s.raster.depthBias == failDepthBias)
                throw std::runtime_error("VK_ERROR_DEVICE_LOST (fake)");
            scene::Frame f = compare::test::uniformFrame(sc.camera.width, sc.camera.height, 1.0f, 0.6f, 1.0f);
            f.attributes["backend"] = scene::toString(backend);
            if (backend == scene::Backend::Reference || n == 0) {
                f.timingsMs = {{"setup", kWarmUpSetupMs}, {"render", kWarmUpFrameMs}};
            } else {
                f.timingsMs = {{"setup", kSetupMs[(n - 1) % 4]}, {"render", kFrameMs[(n - 1) % 4]}};
            }
            return f;
        };
    }
};

fs::path writeSceneFile(const fs::path& dir, const std::string& name) {
    fs::create_directories(dir);
    const Json scene = {
        {"camera",
         {{"position", {0, 2, 6}},
          {"look_at", {0, 0.7, 0}},
          {"up", {0, 1, 0}},
          {"fov_y", 40},
          {"resolution", {48, 32}},
          {"near", 0.1},
          {"far", 100}}},
        {"materials", {{"matte", {{"albedo", {0.8, 0.8, 0.8}}}}}},
        {"lights", {{{"type", "directional"}, {"direction", {-1, -2, -1}}, {"color", {1, 1, 1}}, {"intensity", 3}}}},
        {"objects",
         {{{"type", "sphere"}, {"center", {0, 1, 0}}, {"radius", 1}, {"material", "matte"}},
          {{"type", "quad"},
           {"center", {0, 0, 0}},
           {"normal", {0, 1, 0}},
           {"size", {20, 20}},
           {"material", "matte"}}}}};
    std::ofstream(dir / name) << scene.dump(2);
    return dir / name;
}

SweepConfig rasterConfig(int size, const std::string& filter) {
    SweepConfig c;
    c.backend = scene::Backend::Raster;
    c.overrides.shadowMapSize = size;
    c.overrides.filter = filter;
    return c;
}

// Five configurations of both backends, two of them bias samples.
SweepGrid smallGrid() {
    SweepGrid g;
    g.repetitions = 3;
    g.resolution = "24x16";
    g.configs.push_back(rasterConfig(512, "none"));
    g.configs.push_back(rasterConfig(1024, "pcf2x2"));
    SweepConfig depth = rasterConfig(1024, "none");
    depth.overrides.depthBias = 0.01;
    depth.overrides.slopeBias = 0.0;
    depth.biasKind = "depth";
    depth.biasValue = 0.01;
    g.configs.push_back(depth);
    SweepConfig ray;
    ray.backend = scene::Backend::Raytrace;
    ray.overrides.rayBias = "0.001";
    ray.overrides.precision = "float";
    ray.biasKind = "ray";
    ray.biasValue = 0.001;
    g.configs.push_back(ray);
    SweepConfig robust;
    robust.backend = scene::Backend::Raytrace;
    robust.overrides.rayBias = "robust";
    robust.overrides.precision = "double";
    g.configs.push_back(robust);
    return g;
}

std::vector<std::string> keysOf(const SweepGrid& g) {
    std::vector<std::string> k;
    for (const auto& c : g.configs) k.push_back(c.key());
    return k;
}

std::vector<std::string> readLines(const fs::path& file) {
    std::ifstream in(file);
    std::vector<std::string> lines;
    for (std::string line; std::getline(in, line);) lines.push_back(line);
    return lines;
}

std::string readText(const fs::path& file) {
    std::ifstream in(file, std::ios::binary);
    std::ostringstream s;
    s << in.rdbuf();
    return s.str();
}

// Every file under dir with its content, to prove a refused run touched nothing.
std::map<std::string, std::string> snapshot(const fs::path& dir) {
    std::map<std::string, std::string> files;
    for (const auto& e : fs::recursive_directory_iterator(dir))
        if (e.is_regular_file()) files[fs::relative(e.path(), dir).string()] = readText(e.path());
    return files;
}

class Sweep : public ::testing::Test {
protected:
    void SetUp() override {
        root = fs::path(::testing::TempDir()) /
               ("shadowlab_sweep_" + std::string(::testing::UnitTest::GetInstance()->current_test_info()->name()));
        fs::remove_all(root);
        scene = scene::loadScene(writeSceneFile(root / "scenes", "a.json"));
        dir = root / "out";
    }
    void TearDown() override { fs::remove_all(root); }

    SweepResult run(FakeRenderer& fake, const SweepGrid& grid, bool resume, const scene::Scene* other = nullptr) {
        SweepOptions o;
        o.outputDir = dir;
        o.resume = resume;
        o.render = fake.fn();
        return runSweep(other ? *other : scene, grid, o);
    }

    fs::path root, dir;
    scene::Scene scene;
};

TEST_F(Sweep, WritesEveryResultFileWithOneRowPerConfigurationInGridOrder) {
    FakeRenderer fake;
    const SweepGrid grid = smallGrid();
    const SweepResult result = run(fake, grid, false);
    const std::vector<std::string> keys = keysOf(grid);

    ASSERT_EQ(result.rows.size(), keys.size());
    for (std::size_t i = 0; i < keys.size(); ++i) EXPECT_EQ(result.rows[i].key, keys[i]);

    const auto journal = readLines(dir / "results.jsonl");
    ASSERT_EQ(journal.size(), keys.size());
    for (std::size_t i = 0; i < keys.size(); ++i) EXPECT_EQ(Json::parse(journal[i]).at("key"), keys[i]);

    const Json json = Json::parse(readText(dir / "results.json"));
    ASSERT_EQ(json.size(), keys.size());
    for (std::size_t i = 0; i < keys.size(); ++i) EXPECT_EQ(json[i].at("key"), keys[i]);

    const auto csv = readLines(dir / "results.csv");
    ASSERT_EQ(csv.size(), keys.size() + 1);  // header + rows
    EXPECT_EQ(csv[0].rfind("key,backend,", 0), 0u);
    for (std::size_t i = 0; i < keys.size(); ++i) EXPECT_EQ(csv[i + 1].substr(0, csv[i + 1].find(',')), keys[i]);

    for (const auto& r : result.rows) {
        EXPECT_TRUE(r.error.empty()) << r.error;
        EXPECT_TRUE(fs::exists(dir / r.image)) << r.image;
        EXPECT_TRUE(fs::exists(dir / r.diffImage)) << r.diffImage;
        EXPECT_EQ(r.rate("mismatch_rate"), 0.0);  // the fake renders every method exactly like the reference
    }
    EXPECT_TRUE(fs::exists(dir / "reference.exr"));
    EXPECT_TRUE(fs::exists(dir / "reference.png"));
    // Each configuration: one warm-up and `repetitions` timed frames; the reference once.
    EXPECT_EQ(fake.methodCalls, int(keys.size()) * (1 + grid.repetitions));
    EXPECT_EQ(fake.referenceCalls, 1);
    EXPECT_EQ(result.reference.width, 24);  // the grid's resolution, not the scene's 48x32
}

TEST_F(Sweep, ASecondRunWithoutResumeIsRefusedAndWritesNothing) {
    FakeRenderer first;
    run(first, smallGrid(), false);
    const auto before = snapshot(dir);
    FakeRenderer second;
    EXPECT_THROW(run(second, smallGrid(), false), scene::InputError);
    EXPECT_EQ(second.referenceCalls + second.methodCalls, 0);
    EXPECT_EQ(snapshot(dir), before);
}

TEST_F(Sweep, ResumeAfterATornLastLineRendersExactlyTheMissingConfigurations) {
    const SweepGrid grid = smallGrid();
    FakeRenderer first;
    run(first, grid, false);
    // Simulate a kill in the middle of the third row's write: two whole lines and half a line.
    const auto lines = readLines(dir / "results.jsonl");
    ASSERT_EQ(lines.size(), 5u);
    {
        std::ofstream out(dir / "results.jsonl", std::ios::binary | std::ios::trunc);
        out << lines[0] << "\n" << lines[1] << "\n" << lines[2].substr(0, lines[2].size() / 2);
    }
    FakeRenderer resumed;
    const SweepResult result = run(resumed, grid, true);

    // Configurations 3, 4 and 5 render (warm-up + 3 timed frames each); 1 and 2 do not; the
    // cached reference is reused.
    EXPECT_EQ(resumed.referenceCalls, 0);
    EXPECT_EQ(resumed.methodCalls, 3 * (1 + grid.repetitions));
    EXPECT_EQ(resumed.calls.size(), 3u);
    // Which configurations those were: the grid's last three.
    for (std::size_t i = 2; i < grid.configs.size(); ++i) {
        const auto settings = scene::resolveSettings(scene, grid.configs[i].overrides);
        EXPECT_EQ(resumed.calls.count(describe(settings, grid.configs[i].backend)), 1u) << grid.configs[i].label();
    }

    // Every key exactly once, in the journal and in the results, and in grid order.
    const auto journal = readLines(dir / "results.jsonl");
    std::multiset<std::string> seen;
    for (const auto& line : journal) seen.insert(Json::parse(line).at("key").get<std::string>());
    const auto keys = keysOf(grid);
    EXPECT_EQ(seen, std::multiset<std::string>(keys.begin(), keys.end()));
    ASSERT_EQ(result.rows.size(), keys.size());
    for (std::size_t i = 0; i < keys.size(); ++i) EXPECT_EQ(result.rows[i].key, keys[i]);
    const Json json = Json::parse(readText(dir / "results.json"));
    ASSERT_EQ(json.size(), keys.size());
    for (std::size_t i = 0; i < keys.size(); ++i) EXPECT_EQ(json[i].at("key"), keys[i]);
}

TEST_F(Sweep, ResumesAJournalWrittenInTheJournalFormatAndRewritesItsLinesUnchanged) {
    // A journal as docs/sweep.md describes it, written by hand rather than by this build: one JSON
    // object per line, keys sorted, the backend and the key naming the backend by its name. The
    // keys are SweepConfig::key() of smallGrid()'s first and fourth rows: "backend=" + the name,
    // then map, filter, ..., ray_bias, precision, each only when set.
    const SweepGrid grid = smallGrid();
    const std::string rasterLine =
        R"({"backend":"raster","bias_kind":"","bias_value":null,"diff_image":"images/raster-a-diff.png",)"
        R"("error":"","frame_ms":2.5,"frame_ms_max":3.0,"frame_ms_min":2.0,"image":"images/raster-a.png",)"
        R"("key":"backend=raster;map=512;filter=none","label":"raster: map 512, none",)"
        R"("machine":{"cores":8,"cpu":"test cpu","host":"journal-host","load":0.5,"online_cores":8},)"
        R"("metrics":{"false_shadow_rate":0.125,"mismatch_rate":0.25,"missed_shadow_rate":0.125},)"
        R"("overrides":{"filter":"none","shadow_map_size":512},"repetitions":3,"settings":{},"setup_ms":1.5})";
    const std::string rayLine =
        R"({"backend":"raytrace","bias_kind":"ray","bias_value":0.001,"diff_image":"images/raytrace-b-diff.png",)"
        R"("error":"","frame_ms":4.0,"frame_ms_max":5.0,"frame_ms_min":3.0,"image":"images/raytrace-b.png",)"
        R"("key":"backend=raytrace;ray_bias=0.001;precision=float","label":"raytrace: ray bias 0.001, float",)"
        R"("machine":{"cores":8,"cpu":"test cpu","host":"journal-host","load":0.5,"online_cores":8},)"
        R"("metrics":{"false_shadow_rate":0.5,"mismatch_rate":0.5,"missed_shadow_rate":0.0},)"
        R"("overrides":{"precision":"float","ray_bias":"0.001"},"repetitions":3,"settings":{},"setup_ms":0.5})";
    ASSERT_EQ(grid.configs[0].key(), "backend=raster;map=512;filter=none");
    ASSERT_EQ(grid.configs[3].key(), "backend=raytrace;ray_bias=0.001;precision=float");
    fs::create_directories(dir);
    // The folder's identity: the scene file and the grid's resolution (24x16).
    std::ofstream(dir / "sweep.json") << Json{{"scene", scene.file.string()}, {"resolution", {24, 16}}}.dump(2) << "\n";
    std::ofstream(dir / "results.jsonl") << rasterLine << "\n" << rayLine << "\n";

    FakeRenderer resumed;
    const SweepResult result = run(resumed, grid, true);

    // Only the three rows the journal lacks render (a warm-up and three timed frames each).
    EXPECT_EQ(resumed.methodCalls, 3 * (1 + grid.repetitions));
    for (const std::size_t i : {std::size_t(0), std::size_t(3)}) {
        const auto settings = scene::resolveSettings(scene, grid.configs[i].overrides);
        EXPECT_EQ(resumed.calls.count(describe(settings, grid.configs[i].backend)), 0u) << grid.configs[i].label();
    }
    // The journal's rows come back as written: their backends, timings and metrics (the fake
    // renders every method like the reference, so a re-rendered row would have no mismatch).
    ASSERT_EQ(result.rows.size(), grid.configs.size());
    EXPECT_EQ(result.rows[0].config.backend, scene::Backend::Raster);
    EXPECT_EQ(result.rows[0].frameMs, 2.5);
    EXPECT_EQ(result.rows[0].rate("mismatch_rate"), 0.25);
    EXPECT_EQ(result.rows[3].config.backend, scene::Backend::Raytrace);
    EXPECT_EQ(result.rows[3].config.biasKind, "ray");
    EXPECT_EQ(result.rows[3].rate("mismatch_rate"), 0.5);
    EXPECT_EQ(result.rows[1].rate("mismatch_rate"), 0.0);
    // The resume rewrites the journal before appending: the two lines come out byte for byte.
    const auto journal = readLines(dir / "results.jsonl");
    ASSERT_EQ(journal.size(), grid.configs.size());
    EXPECT_EQ(journal[0], rasterLine);
    EXPECT_EQ(journal[1], rayLine);
    // And the results files name each backend as the journal does.
    const auto csv = readLines(dir / "results.csv");
    ASSERT_EQ(csv.size(), grid.configs.size() + 1);
    EXPECT_EQ(csv[1].rfind("backend=raster;map=512;filter=none,raster,", 0), 0u) << csv[1];
    EXPECT_EQ(csv[4].rfind("backend=raytrace;ray_bias=0.001;precision=float,raytrace,", 0), 0u) << csv[4];
    EXPECT_EQ(Json::parse(readText(dir / "results.json"))[3].at("backend"), "raytrace");
}

TEST_F(Sweep, AJournalLineNamingAnUnknownBackendIsNotARow) {
    // readJournal skips what is not a row (as a torn line); merge reads journals strictly and
    // names the line (ShardMerge tests). Both go through rowFromJournal.
    Json line = {{"backend", "pathtracer"}, {"key", "backend=pathtracer"}, {"overrides", Json::object()}};
    EXPECT_THROW(rowFromJournal(line), std::invalid_argument);
    line["backend"] = "raster";
    EXPECT_EQ(rowFromJournal(line).config.backend, scene::Backend::Raster);
}

TEST_F(Sweep, ResumeRefusesAFolderHoldingAnotherScenesSweep) {
    FakeRenderer first;
    run(first, smallGrid(), false);
    const auto before = snapshot(dir);

    scene::Scene other = scene::loadScene(writeSceneFile(root / "scenes", "b.json"));
    FakeRenderer second;
    EXPECT_THROW(run(second, smallGrid(), true, &other), scene::InputError);
    // The same scene at another resolution is another sweep too.
    SweepGrid bigger = smallGrid();
    bigger.resolution = "32x20";
    EXPECT_THROW(run(second, bigger, true), scene::InputError);
    EXPECT_EQ(second.referenceCalls + second.methodCalls, 0);
    EXPECT_EQ(snapshot(dir), before);
}

TEST_F(Sweep, TimingsAreMediansOfTheTimedRunsWithTheWarmUpLeftOut) {
    SweepGrid grid = smallGrid();
    grid.configs.resize(1);
    FakeRenderer fake;
    const SweepRow three = run(fake, grid, false).rows.at(0);
    // Timed runs: setup 5, 7, 6 -> median 6; per-frame 10, 30, 20 -> median 20, min 10, max 30.
    // The warm-up (1000 + 9000 ms) would raise the max and shift both medians if counted.
    EXPECT_EQ(three.repetitions, 3);
    EXPECT_DOUBLE_EQ(three.setupMs, 6.0);
    EXPECT_DOUBLE_EQ(three.frameMs, 20.0);
    EXPECT_DOUBLE_EQ(three.frameMsMin, 10.0);
    EXPECT_DOUBLE_EQ(three.frameMsMax, 30.0);

    // Four runs: setup 5, 7, 6, 100 -> (6 + 7) / 2; per-frame 10, 30, 20, 40 -> (20 + 30) / 2.
    fs::remove_all(dir);
    grid.repetitions = 4;
    FakeRenderer fake4;
    const SweepRow four = run(fake4, grid, false).rows.at(0);
    EXPECT_DOUBLE_EQ(four.setupMs, 6.5);
    EXPECT_DOUBLE_EQ(four.frameMs, 25.0);
    EXPECT_DOUBLE_EQ(four.frameMsMin, 10.0);
    EXPECT_DOUBLE_EQ(four.frameMsMax, 40.0);
}

TEST_F(Sweep, AFailingConfigurationIsRecordedAndTheSweepGoesOn) {
    FakeRenderer fake;
    fake.failDepthBias = 0.01;  // the third configuration
    const SweepResult result = run(fake, smallGrid(), false);
    ASSERT_EQ(result.rows.size(), 5u);
    EXPECT_NE(result.rows[2].error.find("DEVICE_LOST"), std::string::npos);
    EXPECT_TRUE(result.rows[2].metrics.is_null());
    for (std::size_t i : {0u, 1u, 3u, 4u}) EXPECT_TRUE(result.rows[i].error.empty()) << i;
    EXPECT_NE(readText(dir / "results.csv").find("DEVICE_LOST"), std::string::npos);
    // Resuming retries the failed configuration alone (warm-up + timed runs) and keeps one row
    // per key: the failure may have been the machine's, not the configuration's.
    FakeRenderer again;
    const SweepResult resumed = run(again, smallGrid(), true);
    EXPECT_EQ(again.methodCalls, 1 + smallGrid().repetitions);
    ASSERT_EQ(resumed.rows.size(), 5u);
    EXPECT_TRUE(resumed.rows[2].error.empty());
    EXPECT_EQ(readLines(dir / "results.jsonl").size(), 5u);
}

TEST_F(Sweep, AConfigurationNamedTwiceRendersOnceAndHasOneRow) {
    SweepGrid grid = smallGrid();
    grid.configs.push_back(grid.configs[1]);  // e.g. include_default plus an overlapping axis
    FakeRenderer fake;
    const SweepResult result = run(fake, grid, false);
    EXPECT_EQ(result.rows.size(), 5u);
    EXPECT_EQ(readLines(dir / "results.jsonl").size(), 5u);
    EXPECT_EQ(fake.methodCalls, 5 * (1 + grid.repetitions));
}

TEST_F(Sweep, ReadJournalSkipsATornLastLine) {
    FakeRenderer fake;
    run(fake, smallGrid(), false);
    const auto lines = readLines(dir / "results.jsonl");
    std::ofstream(dir / "torn.jsonl") << lines[0] << "\n" << lines[1] << "\n" << lines[2].substr(0, 40);
    const auto rows = readJournal(dir / "torn.jsonl");
    ASSERT_EQ(rows.size(), 2u);
    EXPECT_EQ(rows[1].key, Json::parse(lines[1]).at("key"));
}

// ---- Grid files -----------------------------------------------------------------------

class GridFile : public Sweep {
protected:
    fs::path write(const std::string& text) {
        fs::create_directories(root);
        std::ofstream(root / "grid.json") << text;
        return root / "grid.json";
    }
};

TEST_F(GridFile, AxesBecomeTheirCartesianProduct) {
    const SweepGrid g = loadGrid(write(R"({
        "repetitions": 5, "resolution": "64x36",
        "raster": { "shadow_map_size": [512, 1024], "filter": ["none", "pcf2x2"], "depth_bias": [0, 0.01] },
        "raytrace": { "ray_bias": [0.001, "robust"], "precision": ["float", "double"] } })"),
                                 scene);
    EXPECT_EQ(g.repetitions, 5);
    EXPECT_EQ(g.resolution, std::optional<std::string>("64x36"));
    // 2 × 2 × 2 raster and 2 × 2 raytrace configurations, each exactly once.
    std::set<std::string> expected;
    for (int size : {512, 1024})
        for (const char* filter : {"none", "pcf2x2"})
            for (double bias : {0.0, 0.01}) {
                SweepConfig c = rasterConfig(size, filter);
                c.overrides.depthBias = bias;
                expected.insert(c.key());
            }
    for (const char* ray : {"0.001", "robust"})
        for (const char* precision : {"float", "double"}) {
            SweepConfig c;
            c.backend = scene::Backend::Raytrace;
            c.overrides.rayBias = ray;
            c.overrides.precision = precision;
            expected.insert(c.key());
        }
    std::set<std::string> got;
    for (const auto& c : g.configs) got.insert(c.key());
    EXPECT_EQ(g.configs.size(), 12u);
    EXPECT_EQ(got, expected);
    for (const auto& c : g.configs) {
        if (c.backend == scene::Backend::Raster) {
            EXPECT_EQ(c.biasKind, "depth");
            EXPECT_EQ(c.biasValue, *c.overrides.depthBias);
        } else if (c.overrides.rayBias == std::optional<std::string>("robust")) {
            EXPECT_EQ(c.biasKind, "");  // robust offsets have no bias to plot
        } else {
            EXPECT_EQ(c.biasKind, "ray");
            EXPECT_DOUBLE_EQ(c.biasValue, 0.001);
        }
    }
}

TEST_F(GridFile, ASingleValuedDepthAxisIsHeldFixedInASlopeSeries) {
    // defaultGrid's slope series written as a file: constant bias 0, slope swept.
    const SweepGrid g = loadGrid(write(R"({ "raster": { "depth_bias": [0], "slope_bias": [0, 0.5, 2, 8] } })"), scene);
    ASSERT_EQ(g.configs.size(), 4u);
    for (const auto& c : g.configs) {
        EXPECT_EQ(c.biasKind, "slope") << c.label();
        EXPECT_EQ(c.biasValue, *c.overrides.slopeBias);
    }
    // Both swept: depth series, one per slope value.
    const SweepGrid both = loadGrid(write(R"({ "raster": { "depth_bias": [0, 1], "slope_bias": [0, 2] } })"), scene);
    for (const auto& c : both.configs) EXPECT_EQ(c.biasKind, "depth") << c.label();
}

TEST_F(GridFile, CascadesAxisVariesTheRasterRowsAndIsRecorded) {
    const SweepGrid g = loadGrid(write(R"({ "raster": { "shadow_map_size": [512], "cascades": [1, 3] } })"), scene);
    ASSERT_EQ(g.configs.size(), 2u);
    EXPECT_EQ(g.configs[0].overrides.cascades, std::optional<int>(1));
    EXPECT_EQ(g.configs[1].overrides.cascades, std::optional<int>(3));
    EXPECT_NE(g.configs[0].key(), g.configs[1].key());
    EXPECT_NE(g.configs[1].label().find("3 cascades"), std::string::npos) << g.configs[1].label();
    // The CSV has a cascades column, and the JSON rows carry the override.
    std::vector<SweepRow> rows(2);
    for (std::size_t i = 0; i < 2; ++i) {
        rows[i].config = g.configs[i];
        rows[i].key = g.configs[i].key();
    }
    const std::string csv = rowsToCsv(rows);
    const std::string header = csv.substr(0, csv.find('\n'));
    EXPECT_NE(header.find(",filter,cascades,depth_bias,"), std::string::npos) << header;
    const std::string row3 = csv.substr(csv.rfind(rows[1].key));
    EXPECT_NE(row3.find(",512,,3,"), std::string::npos) << row3;  // map, filter (none given), cascades
    const nlohmann::json j = rowsToJson(rows);
    EXPECT_EQ(j[1]["overrides"]["cascades"], 3);
}

TEST_F(GridFile, ReceiverPlaneBiasAxisVariesTheRasterRowsAndIsRecorded) {
    const SweepGrid g =
        loadGrid(write(R"({ "raster": { "receiver_plane_bias": [false, true], "slope_bias": [0, 2] } })"), scene);
    ASSERT_EQ(g.configs.size(), 4u);
    EXPECT_EQ(g.configs[0].overrides.receiverPlaneBias, std::optional<bool>(false));
    EXPECT_EQ(g.configs[2].overrides.receiverPlaneBias, std::optional<bool>(true));
    EXPECT_NE(g.configs[0].key(), g.configs[2].key());
    EXPECT_NE(g.configs[2].label().find("receiver-plane bias"), std::string::npos) << g.configs[2].label();
    EXPECT_EQ(g.configs[2].biasKind, "slope");  // the series is still the slope bias
    EXPECT_THROW(loadGrid(write(R"({ "raster": { "receiver_plane_bias": [1] } })"), scene), scene::SceneError);
}

TEST_F(GridFile, HardwareBiasAxisVariesTheRasterRowsAndRoundTrips) {
    const SweepGrid g =
        loadGrid(write(R"({ "raster": { "hardware_bias": [false, true], "depth_bias": [0, 0.01] } })"), scene);
    ASSERT_EQ(g.configs.size(), 4u);
    EXPECT_EQ(g.configs[0].overrides.hardwareBias, std::optional<bool>(false));
    EXPECT_EQ(g.configs[2].overrides.hardwareBias, std::optional<bool>(true));
    EXPECT_NE(g.configs[0].key(), g.configs[2].key());
    EXPECT_NE(g.configs[2].label().find("hardware bias"), std::string::npos) << g.configs[2].label();
    EXPECT_EQ(g.configs[2].biasKind, "depth");
    SweepRow row;
    row.key = g.configs[2].key();
    row.config = g.configs[2];
    EXPECT_EQ(rowsToJson({row})[0]["overrides"]["hardware_bias"], true);
    EXPECT_THROW(loadGrid(write(R"({ "raster": { "hardware_bias": ["on"] } })"), scene), scene::SceneError);
}

TEST_F(GridFile, DefaultGridComparesCascadesOnlyWithADirectionalLight) {
    auto cascaded = [](const SweepGrid& g) {
        std::size_t n = 0;
        for (const auto& c : g.configs) n += c.overrides.cascades.value_or(1) > 1 ? 1 : 0;
        return n;
    };
    EXPECT_EQ(cascaded(defaultGrid(scene, true)), 1u);
    EXPECT_EQ(cascaded(defaultGrid(scene, false)), 2u);
    scene::Scene spotOnly = scene;
    for (auto& l : spotOnly.lights) {
        l.type = scene::LightType::Spot;
        l.coneAngleDegrees = 30.0;
    }
    EXPECT_EQ(cascaded(defaultGrid(spotOnly, false)), 0u);
}

TEST_F(GridFile, DefaultGridComparesTheHardwareBiasOnceWithADirectionalLight) {
    auto hardware = [](const SweepGrid& g) {
        std::vector<SweepConfig> rows;
        for (const auto& c : g.configs)
            if (c.overrides.hardwareBias.value_or(false)) rows.push_back(c);
        return rows;
    };
    for (const bool quick : {true, false}) {
        const std::vector<SweepConfig> rows = hardware(defaultGrid(scene, quick));
        ASSERT_EQ(rows.size(), 1u);
        EXPECT_EQ(rows[0].overrides.shadowMapSize, std::optional<int>(quick ? 2048 : 4096));
        EXPECT_EQ(rows[0].overrides.filter, std::optional<std::string>("pcf2x2"));
        EXPECT_NE(rows[0].label().find("hardware bias"), std::string::npos) << rows[0].label();
    }
    scene::Scene spotOnly = scene;
    for (auto& l : spotOnly.lights) {
        l.type = scene::LightType::Spot;
        l.coneAngleDegrees = 30.0;
    }
    EXPECT_TRUE(hardware(defaultGrid(spotOnly, false)).empty());
}

TEST_F(GridFile, DefaultGridComparesAFittedMapAtEverySize) {
    // One pcf2x2 row per map size with the fitted frustum, beside the bounding-sphere rows.
    for (const bool quick : {true, false}) {
        std::set<int> fittedSizes, sizes;
        for (const auto& c : defaultGrid(scene, quick).configs) {
            if (c.backend != scene::Backend::Raster || !c.overrides.shadowMapSize) continue;
            sizes.insert(*c.overrides.shadowMapSize);
            if (c.overrides.fitLightFrustum.value_or(false)) {
                fittedSizes.insert(*c.overrides.shadowMapSize);
                EXPECT_EQ(c.overrides.filter.value_or(""), "pcf2x2");
                EXPECT_NE(c.label().find("fitted frustum"), std::string::npos) << c.label();
            }
        }
        EXPECT_EQ(fittedSizes.size(), quick ? 2u : 4u);
        for (int size : fittedSizes) EXPECT_TRUE(sizes.count(size)) << size;
    }
}

TEST_F(GridFile, KeysOfRowsWithoutMomentParametersAreUnchanged) {
    // The resume key as journals written before the filterable maps hold it, spelled out from
    // key()'s fields: a moment parameter appears only when a row sets it.
    SweepConfig c = rasterConfig(1024, "pcf2x2");
    c.overrides.depthBias = 0.01;
    c.overrides.slopeBias = 0.0;
    c.overrides.fitLightFrustum = false;
    c.overrides.cascades = 1;
    EXPECT_EQ(c.key(),
              "backend=raster;map=1024;filter=pcf2x2;depth_bias=0.01;slope_bias=0;fit_light_frustum=0;cascades=1");
    EXPECT_EQ(c.label(), "raster: map 1024, pcf2x2, depth bias 0.01, slope bias 0, bounds frustum, 1 cascade");
    c.overrides.filter = "vsm";
    c.overrides.minVariance = 1e-5;
    c.overrides.blurWidth = 7;
    EXPECT_EQ(c.key(),
              "backend=raster;map=1024;filter=vsm;depth_bias=0.01;slope_bias=0;fit_light_frustum=0;cascades=1;"
              "min_variance=1e-05;blur_width=7");
    EXPECT_NE(c.label().find("min variance 1e-05, blur 7"), std::string::npos) << c.label();
}

TEST_F(GridFile, MomentParameterAxesAreSeriesAndRoundTrip) {
    const SweepGrid g = loadGrid(write(R"({ "raster": { "filter": ["vsm", "evsm4"], "min_variance": [1e-6, 1e-4, 1e-2],
        "bleeding_reduction": [0.3], "evsm_positive": [20], "evsm_negative": [4], "esm_exponent": [60],
        "moment_bias": [1e-4], "blur_width": [3] } })"),
                                 scene);
    ASSERT_EQ(g.configs.size(), 6u);  // 2 filters × 3 floors; the one-valued axes held fixed
    std::set<std::string> keys;
    for (const SweepConfig& c : g.configs) {
        keys.insert(c.key());
        EXPECT_EQ(c.biasKind, "min_variance") << c.label();  // the only axis of several values
        EXPECT_EQ(c.biasValue, *c.overrides.minVariance);
        EXPECT_EQ(c.overrides.bleedReduction, std::optional<double>(0.3));
        EXPECT_EQ(c.overrides.evsmPositive, std::optional<double>(20));
        EXPECT_EQ(c.overrides.evsmNegative, std::optional<double>(4));
        EXPECT_EQ(c.overrides.esmExponent, std::optional<double>(60));
        EXPECT_EQ(c.overrides.momentBias, std::optional<double>(1e-4));
        EXPECT_EQ(c.overrides.blurWidth, std::optional<int>(3));
        // The journal line gives back the same configuration, hence the same key.
        SweepRow row;
        row.config = c;
        row.key = c.key();
        const SweepRow back = rowFromJournal(journalRow(row));
        EXPECT_EQ(back.config.key(), c.key());
        EXPECT_EQ(back.config.biasKind, "min_variance");
    }
    EXPECT_EQ(keys.size(), 6u);
    // Each filterable filter is a grid value; a one-valued parameter axis is no series.
    const SweepGrid filters = loadGrid(write(R"({ "raster": { "filter": ["vsm", "evsm2", "evsm4", "esm", "msm"],
        "esm_exponent": [40] } })"),
                                       scene);
    ASSERT_EQ(filters.configs.size(), 5u);
    for (const SweepConfig& c : filters.configs) EXPECT_EQ(c.biasKind, "") << c.label();
    // With a depth series beside it, a swept parameter of a filterable filter is the series;
    // a non-filterable one keeps the depth series (the parameter does nothing there).
    const SweepGrid both = loadGrid(write(R"({ "raster": { "filter": ["pcf2x2", "vsm"], "depth_bias": [0, 0.01],
        "bleeding_reduction": [0.1, 0.5] } })"),
                                    scene);
    for (const SweepConfig& c : both.configs)
        EXPECT_EQ(c.biasKind, *c.overrides.filter == "vsm" ? "bleeding_reduction" : "depth") << c.label();
}

TEST_F(GridFile, DefaultGridHasOneRowPerFilterableMapAtDefaultParameters) {
    for (const bool quick : {true, false}) {
        std::multiset<std::string> filters;
        int largest = 0;
        for (const auto& c : defaultGrid(scene, quick).configs)
            if (c.backend == scene::Backend::Raster) largest = std::max(largest, c.overrides.shadowMapSize.value_or(0));
        for (const auto& c : defaultGrid(scene, quick).configs) {
            const std::string f = c.overrides.filter.value_or("");
            if (!isFilterableName(f)) continue;
            filters.insert(f);
            EXPECT_EQ(c.overrides.shadowMapSize, std::optional<int>(largest));
            EXPECT_EQ(c.overrides.cascades, std::optional<int>(1));
            EXPECT_FALSE(c.overrides.minVariance || c.overrides.bleedReduction || c.overrides.evsmPositive ||
                         c.overrides.evsmNegative || c.overrides.esmExponent || c.overrides.momentBias ||
                         c.overrides.blurWidth);
            EXPECT_EQ(c.biasKind, "");
        }
        EXPECT_EQ(filters, (std::multiset<std::string>{"esm", "evsm2", "evsm4", "msm", "vsm"}));
    }
}

TEST_F(GridFile, BadValuesAreRejectedWithTheirJsonPath) {
    const std::vector<std::pair<std::string, std::string>> cases = {
        {R"({ "raster": { "depth_bias": [0, 0.1, -1] } })", "raster.depth_bias[2]"},
        {R"({ "raster": { "slope_bias": [0, "a"] } })", "raster.slope_bias[1]"},
        {R"({ "raster": { "filter": ["none", "bilinear"] } })", "raster.filter[1]"},
        {R"({ "raster": { "shadow_map_size": [8] } })", "raster.shadow_map_size[0]"},
        {R"({ "raster": { "shadow_map_size": [] } })", "raster.shadow_map_size"},
        {R"({ "raster": { "colour": [1] } })", "raster.colour"},
        {R"({ "raytrace": { "ray_bias": [1e-3, "fast"] } })", "raytrace.ray_bias[1]"},
        {R"({ "raytrace": { "precision": ["half"] } })", "raytrace.precision[0]"},
        {R"({ "raytrace": { "samples": [4, 0] } })", "raytrace.samples[1]"},
        {R"({ "repetitions": 0, "raster": { "filter": ["none"] } })", "repetitions"},
        {R"({ "resolution": "wide", "raster": { "filter": ["none"] } })", "resolution"},
        {R"({ "resolution": "0x10", "raster": { "filter": ["none"] } })", "resolution"},
        {R"({ "include_default": "yes" })", "include_default"},
        {R"({ "rasterr": {} })", "rasterr"},
        {R"({ "raster": { "cascades": [1, 0] } })", "raster.cascades[1]"},
        {R"({ "raster": { "cascades": [5] } })", "raster.cascades[0]"},
        {R"({ "raster": { "cascades": [2.5] } })", "raster.cascades[0]"},
        {R"({ "raster": { "cascades": ["3"] } })", "raster.cascades[0]"},
        {R"({ "raytrace": { "cascades": [3] } })", "raytrace.cascades"},
        {R"({ "raster": { "min_variance": [1e-6, -1] } })", "raster.min_variance[1]"},
        {R"({ "raster": { "bleeding_reduction": [1] } })", "raster.bleeding_reduction[0]"},
        {R"({ "raster": { "evsm_positive": [43] } })", "raster.evsm_positive[0]"},
        {R"({ "raster": { "evsm_negative": ["5"] } })", "raster.evsm_negative[0]"},
        {R"({ "raster": { "esm_exponent": [86] } })", "raster.esm_exponent[0]"},
        {R"({ "raster": { "moment_bias": [2] } })", "raster.moment_bias[0]"},
        {R"({ "raster": { "blur_width": [4] } })", "raster.blur_width[0]"},
        {R"({ "raster": { "blur_width": [65] } })", "raster.blur_width[0]"},
        {R"({ "raytrace": { "min_variance": [1e-6] } })", "raytrace.min_variance"},
        {R"({ "raster": { "filter": ["vsm", "vsm8"] } })", "raster.filter[1]"},
    };
    for (const auto& [text, path] : cases) {
        const fs::path file = write(text);
        try {
            loadGrid(file, scene);
            ADD_FAILURE() << "accepted: " << text;
        } catch (const scene::SceneError& e) {
            EXPECT_EQ(e.jsonPath(), path) << text << " -> " << e.what();
            EXPECT_EQ(e.file(), file);
        } catch (const std::exception& e) {
            ADD_FAILURE() << "not a SceneError for " << text << ": " << e.what();
        }
    }
}

TEST_F(GridFile, HostileFilesAreRefusedBeforeTheyAreReadOrExpanded) {
    fs::create_directories(root);
    // A FIFO would block a reader forever, a folder or /dev/zero never end.
    ASSERT_EQ(::mkfifo((root / "pipe.json").c_str(), 0600), 0);
    fs::create_symlink("/dev/zero", root / "zero.json");
    for (const char* name : {"pipe.json", "zero.json"}) {
        try {
            loadGrid(root / name, scene);
            ADD_FAILURE() << name << " was read";
        } catch (const scene::SceneError& e) {
            EXPECT_NE(std::string(e.what()).find("not a regular file"), std::string::npos) << e.what();
        }
    }
    // Deep nesting is refused before the parser or a message printer recurses on it.
    const std::string deep = std::string(100000, '[') + std::string(100000, ']');
    try {
        loadGrid(write(R"({ "raster": { "depth_bias": )" + deep + " } }"), scene);
        ADD_FAILURE() << "a deep grid was read";
    } catch (const scene::SceneError& e) {
        EXPECT_NE(std::string(e.what()).find("nested deeper than 64 levels"), std::string::npos) << e.what();
    }
    // Axes of 1000 values multiply to 10^9 configurations: refused before they are built (the
    // loop that built them first exhausted memory).
    std::string values = "[";
    for (int i = 0; i < 1000; ++i) {
        if (i) values += ',';
        values += std::to_string(i);
    }
    values += "]";
    const auto start = std::chrono::steady_clock::now();
    try {
        loadGrid(write(R"({ "raster": { "shadow_map_size": [16, 32, 64], "depth_bias": )" + values +
                       R"(, "slope_bias": )" + values + R"(, "cascades": [1, 2, 3, 4] } })"),
                 scene);
        ADD_FAILURE() << "a grid of 10^9 configurations was built";
    } catch (const scene::SceneError& e) {
        EXPECT_NE(std::string(e.what()).find("configurations, more than 100000"), std::string::npos) << e.what();
    }
    EXPECT_LT(std::chrono::steady_clock::now() - start, std::chrono::seconds(5));
}

TEST_F(Sweep, EachRowRendersWithOneRendererAndMeasuresWhatARendererPerFrameMeasures) {
    // With the default render function a raster or ray-traced row renders its warm-up and timed
    // frames with one renderer; its setup (the device and upload, or the trees) is the warm-up's.
    // A wrapper around the same function renders each frame anew: the same metrics on every row.
    const SweepGrid grid = smallGrid();
    SweepOptions reused;
    reused.outputDir = dir;
    reused.writeImages = false;
    const SweepResult a = runSweep(scene, grid, reused);
    SweepOptions perFrame = reused;
    perFrame.outputDir = root / "per-frame";
    perFrame.render = [](const scene::Scene& s, const scene::RenderSettings& st, scene::Backend b) {
        return renderWithBackend(s, st, b);
    };
    const SweepResult b = runSweep(scene, grid, perFrame);
    ASSERT_EQ(a.rows.size(), grid.configs.size());
    ASSERT_EQ(b.rows.size(), grid.configs.size());
    for (std::size_t i = 0; i < a.rows.size(); ++i) {
        EXPECT_TRUE(a.rows[i].error.empty()) << a.rows[i].error;
        for (const auto& [key, value] : a.rows[i].metrics.items())
            if (key != "method_timing" && key != "reference_timing")  // times of their own
                EXPECT_EQ(value, b.rows[i].metrics.value(key, Json())) << a.rows[i].config.label() << ": " << key;
        EXPECT_GT(a.rows[i].setupMs, 0.0) << a.rows[i].config.label();  // the constructor's
        EXPECT_GT(a.rows[i].frameMs, 0.0) << a.rows[i].config.label();
    }
}

// A sweep holds one renderer at a time: its estimate counts the largest, whichever row it is, and
// the Frames a flicker path keeps (its references, a row's frames and the held view's).
TEST(SweepMemory, CountsTheLargestRowsRendererOnceAndTheFlickerPathsFrames) {
    const scene::Scene scene = scene::loadScene(scene::findScene("seed"));
    SweepGrid grid;
    grid.resolution = "64x36";
    grid.configs.push_back(SweepConfig{.backend = scene::Backend::Raytrace});
    const scene::Scene at = sweepScene(scene, grid);
    auto bytesOf = [&](scene::Backend backend, const scene::SettingsOverrides& overrides) {
        const scene::RenderSettings s = scene::resolveSettings(at, overrides);
        return estimateMemoryBytes(backend, at, scene::makeRenderPlan(at, s), s);
    };
    const JobMemory traced = estimateSweepMemory(scene, grid, {});
    EXPECT_EQ(traced.largestRenderer, bytesOf(scene::Backend::Raytrace, {}));

    // A filterable 2048² map (its moment arrays and compute pipeline) outweighs the tracer and the
    // user's pcf2x2 raster renderer, and replaces the tracer in the total.
    scene::SettingsOverrides vsm;
    vsm.filter = "vsm";
    vsm.shadowMapSize = 2048;
    grid.configs.push_back(SweepConfig{.backend = scene::Backend::Raster, .overrides = vsm});
    const JobMemory withVsm = estimateSweepMemory(scene, grid, {});
    const std::uint64_t vsmBytes = bytesOf(scene::Backend::Raster, vsm);
    ASSERT_GT(vsmBytes, bytesOf(scene::Backend::Raster, {}));
    EXPECT_EQ(withVsm.largestRenderer, vsmBytes);
    EXPECT_EQ(withVsm.total - traced.total, vsmBytes - traced.largestRenderer);

    grid.flicker = defaultFlickerPath();
    grid.flicker->frames = 8;
    EXPECT_EQ(estimateSweepMemory(scene, grid, {}).total - withVsm.total, 3 * 8 * scene::frameBytes(at));
}

}  // namespace
}  // namespace shadowlab::studies
