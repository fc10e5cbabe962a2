// tests/studies/path_shard_test.cpp: `path --shard K/N` and its merge (every frame in exactly one
// shard; the merged path measures exactly what the unsharded one does; a shard of another path
// refused; a missing or unfinished shard named with its command), paths from a glTF camera
// animation written by the test, the scene's "path" block as a spec, and the sweep's flicker axis
// on lavapipe (snapped against unsnapped fitted maps in the held view).
#include <sys/wait.h>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <set>

#include <unistd.h>

#include <gtest/gtest.h>

#include "raster/light_frustum.h"
#include "scene/camera.h"
#include "scene/error.h"
#include "scene/loader.h"
#include "studies/path.h"
#include "studies/shard.h"
#include "studies/sweep.h"
#include "tests/kit/render_checked.h"
#include "tests/kit/test_scenes.h"
#include "tests/scene/animated_gltf.h"

namespace shadowlab::studies {
namespace {

namespace fs = std::filesystem;
using Json = nlohmann::json;
using scene::Vec3;
constexpr double kPi = 3.14159265358979323846;

scene::RenderSettings settingsFor(const scene::Scene& s, int mapSize) {
    scene::RenderSettings settings = scene::resolveSettings(s, {});
    settings.raster.shadowMapSize = mapSize;
    settings.raster.shadowMapSizeIsDefault = false;
    settings.raster.depthBias = scene::defaultDepthBias(s, mapSize);
    settings.raster.depthBiasIsDefault = true;
    settings.raster.validate = true;
    return settings;
}

scene::Scene slantedSphere(int width, int height) {
    shadowlab::test::SphereOverPlane p;
    p.lightDirection = Vec3(-1, -2, -1);
    p.width = width;
    p.height = height;
    scene::Scene s = shadowlab::test::makeScene(p);
    s.file = "test-scene.json";  // no such file: its hash is that of the name, the same in every shard
    return s;
}

// The same with a plane that shades itself (a mesh), so that every visible point of it is a receiver
// the fitted map must hold, and the map follows the camera as it moves (over a quad it would hold
// only the fixed region under the sphere, and not move at all).
scene::Scene slantedSphereOverAShadingPlane(int width, int height) {
    scene::Scene s = slantedSphere(width, height);
    shadowlab::test::makeGroundShadeItself(s, 1);
    return s;
}

struct TempFolder {
    fs::path path;
    explicit TempFolder(const std::string& name)
        : path(fs::temp_directory_path() / ("shadowlab-" + name + "-" + std::to_string(::getpid()))) {
        fs::remove_all(path);
    }
    ~TempFolder() { fs::remove_all(path); }
};

// What the merged path must equal: every figure but run times (per frame: the compare metrics
// without their stage timings; per method: the temporal summary).
Json measured(const PathResult& r) {
    Json methods = Json::array();
    for (const PathMethod& m : r.methods) {
        Json frames = Json::array();
        for (const compare::Metrics& x : m.metrics) {
            Json j = toJson(x);
            j.erase("method_timing");
            j.erase("reference_timing");
            frames.push_back(j);
        }
        methods.push_back({{"name", m.name}, {"temporal", toJson(m.temporal)}, {"frames", frames}});
    }
    return {{"kind", toString(r.spec.kind)},
            {"frames", r.frames},
            {"amount", r.amount},
            {"reference", toJson(r.referenceTemporal)},
            {"methods", methods}};
}

TEST(PathShards, EveryFrameIsInExactlyOneShardForOneToEightShards) {
    for (int frames : {2, 3, 5, 12})
        for (int n = 1; n <= 8; ++n) {
            std::multiset<int> seen;
            for (int k = 0; k < n; ++k)
                for (int t : pathShardFrames(frames, k, n)) {
                    EXPECT_EQ(t % n, k);  // dealt round-robin by frame index
                    seen.insert(t);
                }
            ASSERT_EQ(seen.size(), std::size_t(frames)) << frames << " frames, " << n << " shards";
            for (int t = 0; t < frames; ++t) EXPECT_EQ(seen.count(t), 1u) << "frame " << t << " of " << n << " shards";
        }
    // More shards than frames: the extra shards render nothing.
    EXPECT_TRUE(pathShardFrames(3, 5, 8).empty());
}

PathRunOptions shardOptions(const fs::path& dir, int k, int n) {
    PathRunOptions o;
    o.outputDir = dir;
    o.shardIndex = k;
    o.shardCount = n;
    return o;
}

TEST(PathShards, MergedShardsMeasureExactlyWhatTheUnshardedPathMeasures) {
    // A camera path (raster, raster-held and raytrace), 4 frames over 3 shards: {0, 3}, {1}, {2}.
    const scene::Scene base = slantedSphere(48, 27);
    const scene::RenderSettings settings = settingsFor(base, 128);
    PathSpec spec;
    spec.kind = PathKind::Pan;
    spec.frames = 4;
    const TempFolder whole("path-whole"), sharded("path-sharded");
    PathRunOptions o;
    o.outputDir = whole.path;
    const PathResult unsharded = runPath(base, settings, spec, o);
    ASSERT_EQ(unsharded.methods.size(), 3u);
    for (int k = 0; k < 3; ++k) {
        const PathResult part = runPath(base, settings, spec, shardOptions(sharded.path, k, 3));
        EXPECT_TRUE(part.methods.empty());  // a shard measures nothing
        EXPECT_TRUE(fs::exists(sharded.path / ("shard-" + std::to_string(k) + "-of-3") / "shard.json"));
    }
    EXPECT_TRUE(holdsPathShards({sharded.path}));
    EXPECT_FALSE(holdsPathShards({whole.path}));
    const MergedPath merged = mergePathShards({sharded.path}, sharded.path);
    EXPECT_EQ(merged.shardCount, 3);
    EXPECT_EQ(measured(merged.result).dump(1), measured(unsharded).dump(1));
    for (const char* f : {"report.html", "metrics.json", "flicker.svg", "raster-held.gif", "frames.jsonl",
                          "frames/0003-raster-held.exr", "merge.json"})
        EXPECT_TRUE(fs::exists(sharded.path / f)) << f;
    // A shard rerun in a second folder: its frames are found twice and merged once.
    const TempFolder rerun("path-rerun");
    runPath(base, settings, spec, shardOptions(rerun.path, 1, 3));
    const MergedPath again = mergePathShards({sharded.path, rerun.path / "shard-1-of-3"}, sharded.path);
    EXPECT_EQ(again.duplicates, 1u);
    EXPECT_EQ(measured(again.result).dump(1), measured(unsharded).dump(1));
}

TEST(PathShards, ProgressCountsTheShardsOwnFramesWithTheTimeLeft) {
    EXPECT_EQ(pathProgressLine(4, 12, 5, 0, 65.4), "frame 5/12, ETA 1m05s");
    EXPECT_EQ(pathProgressLine(10, 12, 6, 6, 0.0), "frame 11/12 (6 of 6 in this shard), ETA 0m00s");
    // Shard 1 of 2 of a five-frame path renders frames 1 and 3: its lines count 1 and 2 of 2.
    const scene::Scene base = slantedSphere(24, 16);
    PathSpec spec;
    spec.kind = PathKind::SunAzimuth;
    spec.frames = 5;
    const TempFolder dir("path-progress");
    PathRunOptions o = shardOptions(dir.path, 1, 2);
    o.raster = false;
    std::vector<std::string> lines;
    o.progress = [&](const std::string& line) { lines.push_back(line); };
    runPath(base, settingsFor(base, 64), spec, o);
    ASSERT_EQ(lines.size(), 2u);
    EXPECT_EQ(lines[0].rfind("frame 2/5 (1 of 2 in this shard), ETA ", 0), 0u) << lines[0];
    EXPECT_EQ(lines[1], "frame 4/5 (2 of 2 in this shard), ETA 0m00s");
}

TEST(PathShards, ADamagedFrameFoundWhileMeasuringLeavesTheMergedFolderAsItWasAndAKilledMergesStagingIsCleared) {
    const scene::Scene base = slantedSphere(24, 16);
    PathSpec spec;
    spec.kind = PathKind::SunAzimuth;
    spec.frames = 2;
    const TempFolder dir("path-damaged");
    for (int k = 0; k < 2; ++k) {
        PathRunOptions o = shardOptions(dir.path, k, 2);
        o.raster = false;
        runPath(base, settingsFor(base, 64), spec, o);
    }
    // Shard 1's ray-traced frame cut to its first 2000 bytes (a copy that stopped half-way).
    fs::path damaged;
    for (const auto& e : fs::directory_iterator(dir.path / "shard-1-of-2" / "frames"))
        if (e.path().filename().string().find("raytrace") != std::string::npos) damaged = e.path();
    ASSERT_FALSE(damaged.empty());
    {
        std::ifstream in(damaged, std::ios::binary);
        std::string all((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
        fs::remove(damaged);  // a new file, not the one the merge would link
        std::ofstream(damaged, std::ios::binary) << all.substr(0, 2000);
    }
    // The staging folders of two earlier merges: one whose process is gone (killed), which this
    // merge clears away, and one of a live process (this one stands in for it), which it keeps.
    const pid_t child = ::fork();
    if (child == 0) ::_exit(0);
    ASSERT_GT(child, 0);
    ::waitpid(child, nullptr, 0);
    const std::string killed = ".merge.tmp-" + std::to_string(child) + "-0";
    const std::string live = ".merge.tmp-" + std::to_string(::getpid()) + "-99";
    for (const std::string& stage : {killed, live}) {
        fs::create_directories(dir.path / stage / "frames");
        std::ofstream(dir.path / stage / "merge.json") << "{}";
    }
    EXPECT_ANY_THROW(mergePathShards({dir.path}, dir.path));
    std::set<std::string> left;
    for (const auto& e : fs::directory_iterator(dir.path)) left.insert(e.path().filename().string());
    EXPECT_EQ(left, (std::set<std::string>{"shard-0-of-2", "shard-1-of-2", live}));
}

TEST(PathShards, AShardOfAnotherPathIsRefusedAndAMissingOrUnfinishedShardIsNamed) {
    const scene::Scene base = slantedSphere(32, 18);
    const scene::RenderSettings settings = settingsFor(base, 64);
    PathSpec spec;
    spec.kind = PathKind::SunAzimuth;
    spec.frames = 3;
    const TempFolder dir("path-refuse");
    runPath(base, settings, spec, shardOptions(dir.path, 0, 3));
    // Shard 2 recorded the command line it was run with (main does this): merge repeats it.
    setCommandLine(
        {"shadowlab", "path", "s.json", "--kind", "sun-azimuth", "--frames", "3", "--shard", "2/3", "-o", "d"});
    runPath(base, settings, spec, shardOptions(dir.path, 2, 3));
    setCommandLine({});
    try {
        mergePathShards({dir.path}, dir.path);
        FAIL() << "merged without shard 1";
    } catch (const scene::InputError& e) {
        const std::string what = e.what();
        EXPECT_NE(what.find("shard 1/3 is missing"), std::string::npos) << what;
        EXPECT_NE(what.find("render it with `shadowlab path s.json --kind sun-azimuth --frames 3 --shard 1/3 -o d`"),
                  std::string::npos)
            << what;
    }
    EXPECT_FALSE(fs::exists(dir.path / "metrics.json"));  // nothing written
    // Shard 1 started but its only frame's journal line is torn: unfinished, finished with --resume.
    runPath(base, settings, spec, shardOptions(dir.path, 1, 3));
    const fs::path journal = dir.path / "shard-1-of-3" / "frames.jsonl";
    std::string line;
    std::getline(std::ifstream(journal), line);
    std::ofstream(journal, std::ios::trunc) << line.substr(0, line.size() / 2);
    try {
        mergePathShards({dir.path}, dir.path);
        FAIL() << "merged an unfinished shard";
    } catch (const scene::InputError& e) {
        EXPECT_NE(std::string(e.what()).find("shard 1/3 is unfinished"), std::string::npos) << e.what();
        EXPECT_NE(std::string(e.what()).find("--resume"), std::string::npos) << e.what();
    }
    // A shard of another path (another amount) in the same split.
    PathSpec other = spec;
    other.amount = 5.0;
    const TempFolder foreign("path-foreign");
    runPath(base, settings, other, shardOptions(foreign.path, 1, 3));
    try {
        mergePathShards({dir.path / "shard-0-of-3", dir.path / "shard-2-of-3", foreign.path / "shard-1-of-3"},
                        dir.path);
        FAIL() << "merged a shard of another path";
    } catch (const scene::InputError& e) {
        EXPECT_NE(std::string(e.what()).find("another path"), std::string::npos) << e.what();
        EXPECT_NE(std::string(e.what()).find("amount"), std::string::npos) << e.what();
    }
    EXPECT_FALSE(fs::exists(dir.path / "metrics.json"));
}

TEST(GltfAnimationPath, SamplesTheCameraAnimationAtEvenlySpacedTimesFromItsFirstToItsLastKey) {
    const shadowlab::test::TempDir dir;
    const scene::Scene base = scene::loadScene(shadowlab::test::writeAnimatedGltf(dir));
    const scene::RenderSettings settings = scene::resolveSettings(base, {});
    PathSpec spec;
    spec.kind = PathKind::GltfAnimation;
    spec.frames = 5;
    spec.animation = "Fly";  // x = 10 + t, turned 45t° about +Y, for t in 0..2
    const std::vector<scene::Scene> scenes = pathScenes(base, settings, spec);
    ASSERT_EQ(scenes.size(), 5u);
    for (int k = 0; k < 5; ++k) {
        const double t = 2.0 * k / 4.0, theta = 45.0 * t * kPi / 180.0;
        const scene::Camera& c = scenes[std::size_t(k)].camera;
        EXPECT_NEAR(c.position.x, 10.0 + t, 1e-6) << k;
        EXPECT_NEAR(c.position.z, 5.0, 1e-6) << k;
        const Vec3 f = glm::normalize(c.lookAt - c.position);
        EXPECT_NEAR(f.x, -std::sin(theta), 1e-6) << k;
        EXPECT_NEAR(f.z, -std::cos(theta), 1e-6) << k;
        EXPECT_EQ(c.width, base.camera.width);
    }
    EXPECT_TRUE(isCameraPath(PathKind::GltfAnimation));
    spec.amount = 2.0;  // the keys set the motion
    EXPECT_THROW(pathScenes(base, settings, spec), scene::InputError);
    spec.amount.reset();
    spec.animation = "Nope";
    EXPECT_THROW(pathScenes(base, settings, spec), scene::InputError);
    // A scene without camera animations refuses the kind.
    spec.animation.clear();
    EXPECT_THROW(pathScenes(slantedSphere(32, 18), settings, spec), scene::InputError);
}

TEST(ScenePathBlock, BecomesThePathSpecWithTheKindsDefaultsForWhatItLeavesOut) {
    scene::PathBlock b;
    b.kind = "sun-elevation";
    b.frames = 7;
    const PathSpec s = pathSpecOf(b);
    EXPECT_EQ(s.kind, PathKind::SunElevation);
    EXPECT_EQ(s.frames, 7);
    EXPECT_FALSE(s.amount.has_value());
    EXPECT_EQ(s.light, 0);
    // Every kind the loader accepts is one compare knows (the names are the same list).
    for (const char* k :
         {"orbit", "dolly", "pan", "subtexel", "sun-azimuth", "sun-elevation", "light-move", "gltf-animation"})
        EXPECT_STREQ(toString(parsePathKind(k)), k);
}

// The sweep's flicker axis with the real backends: snapped and unsnapped fitted maps as a grid axis
// under sub-texel camera steps, from a start where the snapped frustum stays one frustum over the
// path (as PathStability.SnappedFittedMapsHoldStillUnderSubTexelMovesWhereUnsnappedOnesFlicker):
// the snapped row's held view must not flicker or vary at all, the unsnapped row's must flicker.
TEST(SweepFlickerAxis, SnappedFittedMapsHoldStillInTheHeldViewWhereUnsnappedOnesFlicker) {
    constexpr int kMap = 128;
    scene::Scene base = slantedSphereOverAShadingPlane(128, 72);
    base.shadow.shadowMapSize = kMap;  // the path's texel is the scene's own map's (flickerScenes)
    base.shadow.fitLightFrustum = true;
    const scene::RenderSettings fitted = scene::resolveSettings(base, {});
    const scene::CameraBasis cam = scene::cameraBasis(base.camera);
    const Vec3 along = glm::normalize(cam.right + cam.up);
    PathSpec spec;
    spec.kind = PathKind::SubTexel;
    spec.frames = 6;
    spec.amount = 0.1;
    const double texel = subTexelStep(base, fitted.raster, 1.0).texel;
    bool found = false;
    for (int k = 0; k < 40 && !found; ++k) {
        scene::Scene s = base;
        s.camera.position += 0.05 * k * texel * along;
        s.camera.lookAt += 0.05 * k * texel * along;
        const std::vector<scene::Scene> frames = flickerScenes(s, spec);
        const raster::LightFrustum f0 =
            raster::fitDirectionalLightToReceivers(frames[0], frames[0].lights[0].direction, kMap, true);
        bool still = true;
        for (const scene::Scene& f : frames) {
            const raster::LightFrustum fi =
                raster::fitDirectionalLightToReceivers(f, f.lights[0].direction, kMap, true);
            still = still && fi.center == f0.center && fi.halfWidth == f0.halfWidth && fi.nearDepth == f0.nearDepth &&
                    fi.farDepth == f0.farDepth;
        }
        if (still) base = s, found = true;
    }
    ASSERT_TRUE(found) << "no start within two texels keeps the snapped frustum over the path";

    SweepGrid grid;
    grid.repetitions = 1;
    grid.flicker = spec;
    for (bool snap : {true, false}) {
        SweepConfig c;
        c.backend = scene::Backend::Raster;
        c.overrides.shadowMapSize = kMap;
        c.overrides.filter = "pcf2x2";
        c.overrides.fitLightFrustum = true;
        c.overrides.cascades = 1;
        c.overrides.snapLightFrustum = snap;
        c.overrides.validate = true;
        grid.configs.push_back(c);
    }
    SweepConfig rt;
    rt.backend = scene::Backend::Raytrace;
    grid.configs.push_back(rt);
    const TempFolder dir("sweep-flicker");
    SweepOptions options;
    options.outputDir = dir.path;
    const SweepResult result = runSweep(base, grid, options);
    ASSERT_EQ(result.rows.size(), 3u);
    for (const SweepRow& r : result.rows) ASSERT_TRUE(r.error.empty()) << r.error;
    const SweepRow& snapped = result.rows[0];
    const SweepRow& unsnapped = result.rows[1];
    std::printf(
        "flicker axis, held view: snapped %g px, unsnapped %g px (swim %g px); moving view %g / %g px; "
        "raytrace %g px\n",
        snapped.temporalValue("flicker_px", true), unsnapped.temporalValue("flicker_px", true),
        unsnapped.temporalValue("swim_px", true), snapped.temporalValue("flicker_px"),
        unsnapped.temporalValue("flicker_px"), result.rows[2].temporalValue("flicker_px"));
    EXPECT_EQ(snapped.temporalValue("flicker_px", true), 0.0);
    EXPECT_EQ(snapped.temporalValue("error_variation", true), 0.0);
    EXPECT_EQ(snapped.temporalValue("swim_px", true), 0.0);
    EXPECT_GT(unsnapped.temporalValue("flicker_px", true), 0.0);
    EXPECT_GT(unsnapped.temporalValue("error_variation", true), 0.0);
    // The ray tracer has no held view; its shadow test does not depend on the camera.
    EXPECT_FALSE(result.rows[2].temporal.contains("held"));
    EXPECT_EQ(result.rows[2].temporal.value("frames", 0), 6);
    // The path's references are cached for a resume; the rows carry the figures through the journal.
    EXPECT_TRUE(fs::exists(dir.path / "flicker" / "reference-0005.exr"));
    const std::vector<SweepRow> journal = readJournal(dir.path / "results.jsonl");
    ASSERT_EQ(journal.size(), 3u);
    EXPECT_EQ(journal[1].temporal, unsnapped.temporal);
}

}  // namespace
}  // namespace shadowlab::studies
