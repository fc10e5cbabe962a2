// tests/app/shard_app_test.cpp: `sweep --shard K/N` in N processes at once and `merge`, run as a
// user runs them: the merged folder equals the unsharded sweep (rows, metrics, verdicts; not run
// times); a shard killed with SIGKILL makes merge name it and write nothing, and resumed with
// --resume completes the sweep; bad input exits 2 with no merged file written.
#include <chrono>
#include <csignal>
#include <fstream>
#include <set>
#include <thread>

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include "studies/merge.h"
#include "tests/app/subprocess.h"
#include "tests/scene/test_files.h"

namespace shadowlab {
namespace {

namespace fs = std::filesystem;
using test::TempDir;
using Json = nlohmann::json;

// The quick grid of the seed scene, small: 29 rows in a few seconds (24 of shadow-map sizes, filters,
// biases and ray offsets, and one per filterable map: vsm, evsm2, evsm4, esm, msm).
constexpr std::size_t kQuickRows = 29;
std::vector<std::string> sweepArgs(const fs::path& out) {
    return {"sweep", "seed",          "-o", out.string(),        "--quick", "--resolution",
            "48x27", "--repetitions", "1",  "--shadow-map-size", "256"};
}

std::vector<std::string> with(std::vector<std::string> a, const std::vector<std::string>& more) {
    a.insert(a.end(), more.begin(), more.end());
    return a;
}

int runShadowlab(const std::vector<std::string>& args) {
    const pid_t pid = test::spawnShadowlab(args);
    return pid > 0 ? test::waitFor(pid) : -2;
}

std::size_t journalLines(const fs::path& file) {
    std::ifstream in(file);
    std::size_t n = 0;
    for (std::string line; std::getline(in, line);) n += line.empty() ? 0 : 1;
    return n;
}

TEST(ShardedSweep, ThreeProcessesAtOnceMergeToTheUnshardedSweep) {
    TempDir dir;
    ASSERT_EQ(runShadowlab(sweepArgs(dir.path() / "whole")), 0);
    // Three shards at once into one folder, as a job array on a shared file system runs them.
    std::vector<pid_t> pids;
    for (int k = 0; k < 3; ++k)
        pids.push_back(test::spawnShadowlab(with(sweepArgs(dir.path() / "sh"), {"--shard", std::to_string(k) + "/3"})));
    for (pid_t pid : pids) EXPECT_EQ(test::waitFor(pid), 0);
    ASSERT_EQ(runShadowlab({"merge", (dir.path() / "sh").string()}), 0);

    const auto whole = studies::readResults(dir.path() / "whole");
    const auto merged = studies::readResults(dir.path() / "sh");
    EXPECT_EQ(whole.size(), kQuickRows);
    EXPECT_EQ(studies::rowDifferences(whole, merged), std::vector<std::string>{});
    EXPECT_EQ(studies::verdictDifferences(whole, merged), std::vector<std::string>{});
    for (const char* f : {"report.html", "results.csv", "error-time.svg", "recommended-shadow.json", "reference.png"})
        EXPECT_TRUE(fs::exists(dir.path() / "sh" / f)) << f;
    // The one difference: the unsharded sweep searched its block in the user's configuration
    // (measured against the defaults); the merge has the rows only, and its page says so.
    auto read = [](const fs::path& f) {
        std::ifstream in(f);
        return std::string(std::istreambuf_iterator<char>(in), {});
    };
    EXPECT_FALSE(Json::parse(read(dir.path() / "whole" / "recommended-shadow.json"))["measured"].is_null());
    EXPECT_TRUE(Json::parse(read(dir.path() / "sh" / "recommended-shadow.json"))["measured"].is_null());
    EXPECT_NE(read(dir.path() / "sh" / "report.html").find("which a merge of shards does not"), std::string::npos);
    EXPECT_EQ(read(dir.path() / "whole" / "report.html").find("which a merge of shards does not"), std::string::npos);
    // One reference for the three shards, beside them, not one in each.
    for (int k = 0; k < 3; ++k)
        EXPECT_FALSE(fs::exists(dir.path() / "sh" / ("shard-" + std::to_string(k) + "-of-3") / "reference.exr"));
    EXPECT_FALSE(fs::exists(dir.path() / "sh" / "reference.exr.lock"));
}

TEST(ShardedSweep, AKilledShardIsNamedByMergeAndItsResumeCompletesTheSweep) {
    TempDir dir;
    const fs::path out = dir.path() / "sh";
    const fs::path journal = out / "shard-0-of-2" / "results.jsonl";
    const pid_t pid = test::spawnShadowlab(with(sweepArgs(out), {"--shard", "0/2"}));
    ASSERT_GT(pid, 0);
    const auto deadline = std::chrono::steady_clock::now() + std::chrono::minutes(3);
    while (journalLines(journal) < 2 && std::chrono::steady_clock::now() < deadline)
        std::this_thread::sleep_for(std::chrono::milliseconds(5));
    kill(pid, SIGKILL);
    test::waitFor(pid);
    const std::size_t before = journalLines(journal);
    ASSERT_GE(before, 2u);
    ASSERT_LT(before, (kQuickRows + 1) / 2) << "the shard finished before the kill; nothing to resume";
    ASSERT_EQ(runShadowlab(with(sweepArgs(out), {"--shard", "1/2"})), 0);

    // The merge names the unfinished shard, exits 2 and writes no merged file.
    EXPECT_EQ(runShadowlab({"merge", out.string()}), 2);
    for (const char* f : {"results.csv", "results.json", "report.html", "merge.json"})
        EXPECT_FALSE(fs::exists(out / f)) << f;

    ASSERT_EQ(runShadowlab(with(sweepArgs(out), {"--shard", "0/2", "--resume"})), 0);
    ASSERT_EQ(runShadowlab({"merge", out.string()}), 0);
    const auto rows = studies::readResults(out);
    EXPECT_EQ(rows.size(), kQuickRows);
    std::set<std::string> keys;
    for (const auto& r : rows) EXPECT_TRUE(keys.insert(r.key).second) << r.key;
}

TEST(ShardedSweep, BadInputExitsTwoAndWritesNoMergedFile) {
    TempDir dir;
    EXPECT_EQ(runShadowlab({"merge", (dir.path() / "nowhere").string(), "-o", (dir.path() / "m").string()}), 2);
    EXPECT_FALSE(fs::exists(dir.path() / "m" / "results.csv"));
    EXPECT_EQ(runShadowlab(with(sweepArgs(dir.path() / "s"), {"--shard", "2/2"})), 2);
    EXPECT_FALSE(fs::exists(dir.path() / "s"));

    // A shard whose journal has a damaged line in the middle.
    const fs::path out = dir.path() / "sh";
    ASSERT_EQ(runShadowlab(with(sweepArgs(out), {"--shard", "0/1"})), 0);
    const fs::path journal = out / "shard-0-of-1" / "results.jsonl";
    std::ifstream in(journal);
    std::vector<std::string> lines;
    for (std::string line; std::getline(in, line);) lines.push_back(line);
    ASSERT_GE(lines.size(), 3u);
    lines[1] = lines[1].substr(0, lines[1].size() / 2);
    std::ofstream o(journal);
    for (const auto& l : lines) o << l << "\n";
    o.close();
    EXPECT_EQ(runShadowlab({"merge", out.string()}), 2);
    for (const char* f : {"results.csv", "results.json", "report.html", "results.jsonl"})
        EXPECT_FALSE(fs::exists(out / f)) << f;
}

}  // namespace
}  // namespace shadowlab
