// tests/studies/shard_test.cpp: the shard split (every row in exactly one shard), shards run
// with a fake renderer and merged (equal to the unsharded run, reruns merged once, shards of
// another sweep refused, missing and unfinished shards named, damaged journals refused), and the
// reference shared by the shards of one folder (rendered once; a dead holder's lock taken over).
#include "studies/merge.h"

#include <algorithm>
#include <filesystem>
#include <fstream>
#include <map>
#include <set>
#include <sstream>
#include <thread>

#include <gtest/gtest.h>

#include "scene/error.h"
#include "scene/frame_io.h"
#include "scene/loader.h"
#include "studies/auto_bias.h"
#include "studies/machine.h"
#include "studies/shard.h"
#include "studies/sweep_report.h"
#include "tests/compare/synthetic.h"

namespace shadowlab::studies {
namespace {

namespace fs = std::filesystem;
using Json = nlohmann::json;

// A fresh folder per test under the system's temporary folder.
struct Folder {
    fs::path path;
    Folder() {
        path = fs::temp_directory_path() / ("shadowlab-shard-" + std::to_string(::getpid()) + "-" +
                                            ::testing::UnitTest::GetInstance()->current_test_info()->name());
        fs::remove_all(path);
        fs::create_directories(path);
    }
    ~Folder() {
        std::error_code ec;
        fs::remove_all(path, ec);
    }
};

// Scripted, deterministic frames: a raster map of 512 shadows everything (all false shadow
// against a lit reference), other configurations are right; every timed frame of a
// configuration gets the same times in every run, so two runs of one grid write equal rows.
struct FakeRenderer {
    int referenceCalls = 0;
    std::map<std::string, int> calls;
    RenderFn fn() {
        return [this](const scene::Scene& sc, const scene::RenderSettings& s, scene::Backend backend) {
            if (backend == scene::Backend::Reference) ++referenceCalls;
            const std::string what = scene::toString(backend) + std::to_string(s.raster.shadowMapSize) +
                                     std::to_string(s.raster.depthBias) + std::to_string(s.raytrace.rayBias);
            const int n = calls[what]++;
            const float v = backend == scene::Backend::Raster && s.raster.shadowMapSize == 512 ? 0.0f : 1.0f;
            scene::Frame f = compare::test::uniformFrame(sc.camera.width, sc.camera.height, 1.0f, 0.6f, v);
            f.timingsMs = {{"setup", 2.0}, {"render", n == 0 ? 50.0 : 10.0 + n}};
            return f;
        };
    }
};

fs::path writeScene(const fs::path& dir, double radius = 1.0) {
    fs::create_directories(dir);
    const Json scene = {
        {"camera",
         {{"position", {0, 2, 6}},
          {"look_at", {0, 0.7, 0}},
          {"up", {0, 1, 0}},
          {"fov_y", 40},
          {"resolution", {24, 16}},
          {"near", 0.1},
          {"far", 100}}},
        {"materials", {{"matte", {{"albedo", {0.8, 0.8, 0.8}}}}}},
        {"lights", {{{"type", "directional"}, {"direction", {-1, -2, -1}}, {"color", {1, 1, 1}}, {"intensity", 3}}}},
        {"objects",
         {{{"type", "sphere"}, {"center", {0, 1, 0}}, {"radius", radius}, {"material", "matte"}},
          {{"type", "quad"},
           {"center", {0, 0, 0}},
           {"normal", {0, 1, 0}},
           {"size", {20, 20}},
           {"material", "matte"}}}}};
    std::ofstream(dir / "scene.json") << scene.dump(2);
    return dir / "scene.json";
}

// A grid of `n` distinct raster rows (map sizes 512.. with depth-bias samples) plus two ray rows.
SweepGrid grid(int n) {
    SweepGrid g;
    g.repetitions = 2;
    g.resolution = "24x16";
    for (int i = 0; i < n; ++i) {
        SweepConfig c;
        c.backend = scene::Backend::Raster;
        c.overrides.shadowMapSize = i % 2 ? 1024 : 512;
        c.overrides.filter = "none";
        c.overrides.depthBias = 0.001 * (i + 1);
        c.overrides.slopeBias = 0.0;
        c.biasKind = "depth";
        c.biasValue = *c.overrides.depthBias;
        g.configs.push_back(c);
    }
    for (const char* bias : {"0.001", "robust"}) {
        SweepConfig c;
        c.backend = scene::Backend::Raytrace;
        c.overrides.rayBias = bias;
        c.overrides.precision = "float";
        g.configs.push_back(c);
    }
    return g;
}

std::string readText(const fs::path& file) {
    std::ifstream in(file, std::ios::binary);
    std::ostringstream s;
    s << in.rdbuf();
    return s.str();
}

SweepOptions options(const fs::path& dir, FakeRenderer& fake) {
    SweepOptions o;
    o.outputDir = dir;
    o.render = fake.fn();
    o.writeImages = true;
    return o;
}

void runAllShards(const scene::Scene& scene, const SweepGrid& g, int n, const fs::path& dir, FakeRenderer& fake) {
    for (int k = 0; k < n; ++k) runShard(scene, g, {k, n}, options(dir, fake));
}

std::string errorOf(const std::function<void()>& f) {
    try {
        f();
    } catch (const scene::InputError& e) {
        return e.what();
    }
    return "";
}

TEST(ShardSplit, EveryRowIsInExactlyOneShardForOneToEightShards) {
    // 13 rows, and grids smaller than N (1, 2 and 3 rows for N up to 8): the shards must be
    // disjoint, cover every key, and differ in size by at most one row (round-robin dealing).
    for (const int rows : {1, 2, 3, 13}) {
        SweepGrid g = grid(std::max(rows - 2, 0));
        g.configs.resize(std::size_t(rows));
        const std::vector<std::string> keys = gridKeys(g);
        ASSERT_EQ(keys.size(), std::size_t(rows));
        for (int n = 1; n <= 8; ++n) {
            std::map<std::string, int> seen;
            std::size_t smallest = keys.size(), largest = 0;
            for (int k = 0; k < n; ++k) {
                const SweepGrid part = shardGrid(g, {k, n});
                for (const SweepConfig& c : part.configs) ++seen[c.key()];
                smallest = std::min(smallest, part.configs.size());
                largest = std::max(largest, part.configs.size());
            }
            EXPECT_EQ(seen.size(), keys.size()) << rows << " rows, " << n << " shards";
            for (const auto& [key, count] : seen) EXPECT_EQ(count, 1) << key << " with " << n << " shards";
            EXPECT_LE(largest - smallest, 1u) << rows << " rows, " << n << " shards";
            // More shards than rows: exactly `rows` shards hold one row, the rest none.
            if (n > rows) {
                EXPECT_EQ(largest, 1u);
            }
        }
    }
}

TEST(ShardSplit, DependsOnTheKeysNotOnTheirOrderInTheGrid) {
    const SweepGrid g = grid(9);
    SweepGrid reversed = g;
    std::reverse(reversed.configs.begin(), reversed.configs.end());
    // A configuration named twice is one row, in the shard of its key.
    reversed.configs.push_back(g.configs[3]);
    for (int k = 0; k < 4; ++k) {
        std::set<std::string> a, b;
        for (const auto& c : shardGrid(g, {k, 4}).configs) a.insert(c.key());
        for (const auto& c : shardGrid(reversed, {k, 4}).configs) b.insert(c.key());
        EXPECT_EQ(a, b) << "shard " << k;
    }
}

TEST(ShardSplit, ParsesKOfNAndRejectsWhatIsNot) {
    EXPECT_EQ(parseShard("0/1").index, 0);
    EXPECT_EQ(parseShard("3/4").count, 4);
    for (const char* bad : {"4/4", "-1/4", "1/0", "1", "a/b", "1/2x", "1/200000", ""})
        EXPECT_THROW(parseShard(bad), scene::InputError) << bad;
    EXPECT_EQ(shardFolderName({2, 4}), "shard-2-of-4");
}

TEST(ShardCommand, ReplacesTheShardKeepsEveryOtherArgumentAndQuotesForAShell) {
    const std::vector<std::string> cmd = {
        "/opt/bin/shadowlab", "sweep", "my scene.gltf", "--grid", "g.json", "--shard", "0/4", "-o", "out", "--resume"};
    EXPECT_EQ(shardCommandText(cmd, {3, 4}, false), "shadowlab sweep 'my scene.gltf' --grid g.json --shard 3/4 -o out");
    EXPECT_EQ(shardCommandText(cmd, {1, 4}, true),
              "shadowlab sweep 'my scene.gltf' --grid g.json --shard 1/4 -o out --resume");
    EXPECT_EQ(shardCommandText({"shadowlab", "path", "s.json", "--shard=2/3", "-o", "p"}, {0, 3}, false),
              "shadowlab path s.json --shard=0/3 -o p");
    // Nothing to go on: no command, or one without --shard.
    EXPECT_EQ(shardCommandText({}, {0, 2}, false), "");
    EXPECT_EQ(shardCommandText({"shadowlab", "sweep", "s.json", "-o", "x"}, {0, 2}, false), "");
    // What a POSIX shell reads specially is quoted; a quote inside is closed, escaped, reopened.
    EXPECT_EQ(quoteArg("plain/path-1.json"), "plain/path-1.json");
    EXPECT_EQ(quoteArg(""), "''");
    EXPECT_EQ(quoteArg("a$b"), "'a$b'");
    EXPECT_EQ(quoteArg("it's"), "'it'\\''s'");
    EXPECT_EQ(quoteArg("x;rm"), "'x;rm'");
    for (const char* special : {"a{1,2}", "a[0]", "hey!", "two\nlines"})
        EXPECT_EQ(quoteArg(special), "'" + std::string(special) + "'");
    // Run in another folder: its relative paths hold there, so the command goes there first.
    EXPECT_EQ(
        shardCommandText({"shadowlab", "path", "s.json", "--shard", "0/2", "-o", "p"}, {1, 2}, false, "/no/such/place"),
        "cd /no/such/place && shadowlab path s.json --shard 1/2 -o p");
    EXPECT_EQ(shardCommandText({"shadowlab", "path", "s.json", "--shard", "0/2", "-o", "p"}, {1, 2}, false,
                               fs::current_path().string()),
              "shadowlab path s.json --shard 1/2 -o p");
}

TEST(ShardMerge, EqualsTheUnshardedRunAndRendersTheReferenceOnce) {
    Folder f;
    const scene::Scene scene = scene::loadScene(writeScene(f.path / "scene"));
    const SweepGrid g = grid(7);
    FakeRenderer whole, parts;
    const SweepResult unsharded = runSweep(scene, g, options(f.path / "whole", whole));
    runAllShards(scene, g, 3, f.path / "sharded", parts);
    EXPECT_EQ(parts.referenceCalls, 1) << "every shard but the first reuses the shared reference";

    const MergedSweep merged = readShards({f.path / "sharded"});
    EXPECT_EQ(merged.shardCount, 3);
    EXPECT_EQ(merged.duplicates, 0u);
    writeMerged(merged, f.path / "sharded");
    EXPECT_EQ(rowDifferences(unsharded.rows, merged.rows), std::vector<std::string>{});
    EXPECT_EQ(verdictDifferences(unsharded.rows, merged.rows), std::vector<std::string>{});
    // The fake's times are the same in both runs and both ran here: the CSVs are equal byte for byte.
    EXPECT_EQ(readText(f.path / "whole" / "results.csv"), readText(f.path / "sharded" / "results.csv"));
    EXPECT_EQ(rowDifferences(readResults(f.path / "whole"), readResults(f.path / "sharded")),
              std::vector<std::string>{});
    // Every row's images are in the merged folder under the names the unsharded run gives them.
    for (const SweepRow& r : merged.rows) {
        EXPECT_TRUE(fs::exists(f.path / "sharded" / r.image)) << r.image;
        EXPECT_TRUE(fs::exists(f.path / "sharded" / r.diffImage)) << r.diffImage;
    }
    EXPECT_TRUE(fs::exists(f.path / "sharded" / "reference.png"));
}

TEST(ShardMerge, MoreShardsThanRowsGivesEmptyShardsThatNeedNoReferenceAndMergeCleanly) {
    Folder f;
    const scene::Scene scene = scene::loadScene(writeScene(f.path / "scene"));
    const SweepGrid g = grid(1);  // 3 rows
    FakeRenderer whole, parts;
    const SweepResult unsharded = runSweep(scene, g, options(f.path / "whole", whole));
    // Shards 3..7 of 8 are empty: they finish without a reference.
    for (int k = 7; k >= 3; --k) runShard(scene, g, {k, 8}, options(f.path / "s", parts));
    EXPECT_EQ(parts.referenceCalls, 0);
    EXPECT_FALSE(fs::exists(f.path / "s" / "reference.exr"));
    for (int k = 2; k >= 0; --k) runShard(scene, g, {k, 8}, options(f.path / "s", parts));
    EXPECT_EQ(parts.referenceCalls, 1);
    const MergedSweep m = readShards({f.path / "s"});
    EXPECT_EQ(m.shardDirs.size(), 8u);
    EXPECT_EQ(rowDifferences(unsharded.rows, m.rows), std::vector<std::string>{});
}

TEST(ShardMerge, TheComparisonSeesAChangedMetric) {
    // The check above must be able to fail: one metric changed is one difference.
    Folder f;
    const scene::Scene scene = scene::loadScene(writeScene(f.path / "scene"));
    FakeRenderer fake;
    const SweepResult r = runSweep(scene, grid(3), options(f.path / "a", fake));
    std::vector<SweepRow> changed = r.rows;
    changed[1].metrics["false_shadow"] = changed[1].metrics["false_shadow"].get<double>() + 1;
    EXPECT_EQ(rowDifferences(r.rows, changed).size(), 1u);
    std::vector<SweepRow> swapped = r.rows;
    std::swap(swapped[0], swapped[1]);
    EXPECT_EQ(rowDifferences(r.rows, swapped).size(), 2u);
}

TEST(ShardMerge, ARerunShardIsMergedOnce) {
    Folder f;
    const scene::Scene scene = scene::loadScene(writeScene(f.path / "scene"));
    const SweepGrid g = grid(6);
    FakeRenderer fake;
    runAllShards(scene, g, 2, f.path / "a", fake);
    runShard(scene, g, {1, 2}, options(f.path / "b", fake));  // shard 1 again, elsewhere
    const MergedSweep m = readShards({f.path / "a", f.path / "b"});
    EXPECT_EQ(m.rows.size(), gridKeys(g).size());
    EXPECT_EQ(m.duplicates, shardGrid(g, {1, 2}).configs.size());
    std::set<std::string> keys;
    for (const SweepRow& r : m.rows) EXPECT_TRUE(keys.insert(r.key).second) << r.key;
}

TEST(ShardMerge, RefusesShardsOfAnotherSceneGridOrSplit) {
    Folder f;
    const scene::Scene scene = scene::loadScene(writeScene(f.path / "scene"));
    const scene::Scene other = scene::loadScene(writeScene(f.path / "other", 0.5));
    const SweepGrid g = grid(6);
    FakeRenderer fake;
    runShard(scene, g, {0, 2}, options(f.path / "mine", fake));
    runShard(other, g, {1, 2}, options(f.path / "theirs", fake));
    std::string e = errorOf([&] { readShards({f.path / "mine", f.path / "theirs"}); });
    EXPECT_NE(e.find("different sweeps"), std::string::npos) << e;
    EXPECT_NE(e.find("scene hash"), std::string::npos) << e;

    SweepGrid more = g;
    more.repetitions = 3;
    runShard(scene, more, {1, 2}, options(f.path / "reps", fake));
    e = errorOf([&] { readShards({f.path / "mine", f.path / "reps"}); });
    EXPECT_NE(e.find("repetitions 2 vs 3"), std::string::npos) << e;

    runShard(scene, g, {1, 3}, options(f.path / "thirds", fake));
    e = errorOf([&] { readShards({f.path / "mine", f.path / "thirds"}); });
    EXPECT_NE(e.find("different splits"), std::string::npos) << e;

    // A shard folder of another sweep is refused when the shard runs again into it, too.
    e = errorOf([&] {
        SweepOptions o = options(f.path / "mine", fake);
        o.resume = true;
        runShard(other, g, {0, 2}, o);
    });
    EXPECT_NE(e.find("another sweep"), std::string::npos) << e;
}

TEST(ShardMerge, NamesAMissingShardAndAnUnfinishedOneWithTheCommandsThatCompleteThem) {
    Folder f;
    const scene::Scene scene = scene::loadScene(writeScene(f.path / "scene"));
    const SweepGrid g = grid(7);  // 9 rows: 3 per shard
    FakeRenderer fake;
    runShard(scene, g, {0, 3}, options(f.path / "s", fake));
    runShard(scene, g, {2, 3}, options(f.path / "s", fake));
    // Shard 2 was stopped after its first row: the journal keeps one line.
    const fs::path journal = f.path / "s" / "shard-2-of-3" / "results.jsonl";
    const std::string first = readText(journal).substr(0, readText(journal).find('\n') + 1);
    std::ofstream(journal, std::ios::binary) << first;
    const std::string e = errorOf([&] { readShards({f.path / "s"}); });
    EXPECT_NE(e.find("shard 1/3 is missing"), std::string::npos) << e;
    EXPECT_NE(e.find("--shard 1/3` and the same grid options"), std::string::npos) << e;
    EXPECT_NE(e.find("shard 2/3 is unfinished (2 of 3 rows missing)"), std::string::npos) << e;
    EXPECT_NE(e.find("--shard 2/3 --resume"), std::string::npos) << e;

    // A shard that recorded its command line: the message repeats it, grid options and all.
    setCommandLine({"shadowlab", "sweep", "scene.json", "--grid", "my grid.json", "--shard", "2/3", "-o", "s"});
    runShard(scene, g, {2, 3}, [&] {
        SweepOptions r = options(f.path / "s", fake);
        r.resume = true;
        return r;
    }());
    std::ofstream(journal, std::ios::binary) << first;  // stopped after its first row again
    setCommandLine({});
    const std::string named = errorOf([&] { readShards({f.path / "s"}); });
    EXPECT_NE(named.find("render it with `shadowlab sweep scene.json --grid 'my grid.json' --shard 1/3 -o s`"),
              std::string::npos)
        << named;
    EXPECT_NE(named.find("finish it with `shadowlab sweep scene.json --grid 'my grid.json' --shard 2/3 -o s --resume`"),
              std::string::npos)
        << named;

    // The unfinished shard resumed renders only its two missing rows; then the merge is whole.
    SweepOptions o = options(f.path / "s", fake);
    o.resume = true;
    std::size_t rendered = 0;
    o.progress = [&](const SweepProgress& p) { rendered = p.done - p.skipped; };
    runShard(scene, g, {2, 3}, o);
    EXPECT_EQ(rendered, 2u);
    runShard(scene, g, {1, 3}, options(f.path / "s", fake));
    EXPECT_EQ(readShards({f.path / "s"}).rows.size(), 9u);
}

TEST(ShardMerge, ADamagedJournalLineIsOneErrorNamingTheFileAndLine) {
    Folder f;
    const scene::Scene scene = scene::loadScene(writeScene(f.path / "scene"));
    FakeRenderer fake;
    runAllShards(scene, grid(6), 2, f.path / "s", fake);
    const fs::path journal = f.path / "s" / "shard-0-of-2" / "results.jsonl";
    std::string text = readText(journal);
    const std::size_t second = text.find('\n') + 1;
    text.replace(second, 10, "#garbage#!");  // the second line is no longer JSON
    std::ofstream(journal, std::ios::binary) << text;
    const std::string e = errorOf([&] { readShards({f.path / "s"}); });
    EXPECT_NE(e.find(journal.string() + ":2: damaged journal line"), std::string::npos) << e;

    // A torn last line (what a kill leaves: no newline) is an unfinished row, not damage.
    std::ofstream(journal, std::ios::binary) << readText(journal).substr(0, second) << "{\"key\": \"backend=ras";
    const std::string torn = errorOf([&] { readShards({f.path / "s"}); });
    EXPECT_NE(torn.find("shard 0/2 is unfinished"), std::string::npos) << torn;
}

TEST(ShardMerge, WillNotWriteIntoAShardFolderOrAnUnshardedSweep) {
    Folder f;
    const scene::Scene scene = scene::loadScene(writeScene(f.path / "scene"));
    FakeRenderer fake;
    runAllShards(scene, grid(4), 2, f.path / "s", fake);
    runSweep(scene, grid(4), options(f.path / "whole", fake));
    const MergedSweep m = readShards({f.path / "s"});
    const fs::path shard = f.path / "s" / "shard-0-of-2";
    const std::string journal = readText(shard / "results.jsonl");
    EXPECT_NE(errorOf([&] { writeMerged(m, shard); }).find("is a shard folder"), std::string::npos);
    EXPECT_EQ(readText(shard / "results.jsonl"), journal);
    const std::string csv = readText(f.path / "whole" / "results.csv");
    EXPECT_NE(errorOf([&] { writeMerged(m, f.path / "whole"); }).find("holds an unsharded sweep"), std::string::npos);
    EXPECT_EQ(readText(f.path / "whole" / "results.csv"), csv);
}

TEST(ShardMerge, AMissingFolderOrAFolderWithoutShardsIsRefused) {
    Folder f;
    EXPECT_NE(errorOf([&] { readShards({f.path / "nowhere"}); }).find("nowhere: no such folder"), std::string::npos);
    EXPECT_NE(errorOf([&] { readShards({f.path}); }).find("holds no shard"), std::string::npos);
}

TEST(SharedReference, ASecondShardWaitsForTheFirstAndReusesItsReference) {
    Folder f;
    const scene::Scene scene = scene::loadScene(writeScene(f.path / "scene"));
    std::atomic<int> renders{0};
    auto slowRender = [&] {
        ++renders;
        std::this_thread::sleep_for(std::chrono::milliseconds(300));
        scene::Frame fr = compare::test::uniformFrame(scene.camera.width, scene.camera.height, 1.0f, 0.6f, 1.0f);
        fr.timingsMs = {{"render", 7.0}};
        return fr;
    };
    SharedReferenceOptions o;
    o.pollSeconds = 0.02;
    scene::Frame a, b;
    std::thread first([&] { a = sharedReference(f.path / "out", scene, slowRender, o); });
    std::this_thread::sleep_for(std::chrono::milliseconds(50));
    std::thread second([&] { b = sharedReference(f.path / "out", scene, slowRender, o); });
    first.join();
    second.join();
    EXPECT_EQ(renders.load(), 1);
    EXPECT_EQ(a.visibility, b.visibility);
    EXPECT_FALSE(fs::exists(f.path / "out" / "reference.exr.lock"));

    // Another scene's reference in the same folder is refused, not used.
    const scene::Scene other = scene::loadScene(writeScene(f.path / "other", 0.5));
    EXPECT_THROW(sharedReference(f.path / "out", other, slowRender, o), scene::InputError);
}

TEST(SharedReference, TheLockOfAStoppedShardIsTakenOver) {
    Folder f;
    const scene::Scene scene = scene::loadScene(writeScene(f.path / "scene"));
    auto render = [&] {
        return compare::test::uniformFrame(scene.camera.width, scene.camera.height, 1.0f, 0.6f, 1.0f);
    };
    SharedReferenceOptions o;
    o.pollSeconds = 0.02;
    o.staleSeconds = 0.3;
    // A holder on another host that stopped refreshing its lock: stale after staleSeconds.
    fs::create_directories(f.path / "a");
    std::ofstream(f.path / "a" / "reference.exr.lock") << "some-other-host 12345\n";
    const auto start = std::chrono::steady_clock::now();
    sharedReference(f.path / "a", scene, render, o);
    EXPECT_GE(std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count(), 0.3);
    EXPECT_TRUE(fs::exists(f.path / "a" / "reference.exr"));
    // A holder on this host whose process is gone: taken over at once.
    fs::create_directories(f.path / "b");
    pid_t dead = ::fork();
    if (dead == 0) ::_exit(0);
    ::waitpid(dead, nullptr, 0);
    std::ofstream(f.path / "b" / "reference.exr.lock") << currentMachine().host << " " << dead << "\n";
    o.staleSeconds = 30.0;
    const auto start2 = std::chrono::steady_clock::now();
    sharedReference(f.path / "b", scene, render, o);
    EXPECT_LT(std::chrono::duration<double>(std::chrono::steady_clock::now() - start2).count(), 10.0);
}

TEST(ShardReport, SaysWhenRowsWereTimedOnDifferentMachinesAndMarksEachMachine) {
    Folder f;
    const scene::Scene scene = scene::loadScene(writeScene(f.path / "scene"));
    FakeRenderer fake;
    SweepReportInput in;
    in.rows = runSweep(scene, grid(4), options(f.path / "a", fake)).rows;
    const AutoBias bias = recommendBias(in.rows);
    auto mentions = [&](const std::string& what) {
        for (const std::string& line : describeSweep(in, bias))
            if (line.find(what) != std::string::npos) return true;
        return false;
    };
    EXPECT_FALSE(mentions("different machines"));
    auto paths = [](const std::string& svg) {  // non-circle markers (and the off-axis triangles)
        std::size_t n = 0;
        for (std::size_t p = svg.find("<path d=\"M"); p != std::string::npos; p = svg.find("<path d=\"M", p + 1)) ++n;
        return n;
    };
    const std::size_t onOneMachine = paths(sweepErrorTimeSvg(in));
    EXPECT_EQ(sweepErrorTimeSvg(in).find(" · "), std::string::npos) << "one machine: no machine in the legend";
    // Two rows timed elsewhere: the summary names both machines, and those rows get another shape.
    for (std::size_t i : {0u, 2u}) {
        in.rows[i].machine["host"] = "node-b";
        in.rows[i].machine["cpu"] = "Other CPU";
    }
    EXPECT_TRUE(mentions("timed on 2 different machines"));
    EXPECT_TRUE(mentions("node-b (Other CPU"));
    const std::string svg = sweepErrorTimeSvg(in);
    EXPECT_NE(svg.find("raster · node-b"), std::string::npos);
    EXPECT_GT(paths(svg), onOneMachine) << "the second machine's rows are squares, not circles";
    EXPECT_NE(renderSweepReportHtml(in).find("<th>timed on</th>"), std::string::npos);
}

TEST(Machine, DescribesThisMachineAndSurvivesJson) {
    const MachineInfo m = currentMachine();
    EXPECT_FALSE(m.cpu.empty());
    EXPECT_GE(m.cores, 1);
    EXPECT_LE(m.cores, m.onlineCores);
    const MachineInfo back = machineFromJson(toJson(m));
    EXPECT_EQ(back.id(), m.id());
    EXPECT_EQ(machineFromJson(nullptr).id(), MachineInfo{}.id());
}

}  // namespace
}  // namespace shadowlab::studies
