// tests/app/sweep_resume_test.cpp: a sweep killed with SIGKILL in the middle resumes with
// --resume and ends with every configuration exactly once, keeping the rows finished before the
// kill as they were.
#include <chrono>
#include <csignal>
#include <fstream>
#include <map>
#include <set>
#include <thread>

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include "tests/app/subprocess.h"
#include "tests/scene/test_files.h"

namespace shadowlab {
namespace {

using test::TempDir;
using Json = nlohmann::json;

std::vector<Json> journalRows(const std::filesystem::path& file) {
    std::vector<Json> rows;
    std::ifstream in(file);
    std::string line;
    while (std::getline(in, line)) {
        try {
            rows.push_back(Json::parse(line));
        } catch (const std::exception&) {
            // a torn line: not a finished row
        }
    }
    return rows;
}

TEST(SweepResume, KilledSweepResumesWithEveryRowExactlyOnce) {
    TempDir dir;
    const auto out = dir.path() / "sweep";
    const std::vector<std::string> args = {
        "sweep", "seed",          "-o", out.string(),        "--quick", "--resolution",
        "48x27", "--repetitions", "1",  "--shadow-map-size", "256"};
    const auto journal = out / "results.jsonl";

    // Kill twice, at different points: once after two rows, once a little later still.
    std::map<std::string, Json> beforeKill;
    for (std::size_t killAfter : {2u, 5u}) {
        std::vector<std::string> a = args;
        if (std::filesystem::exists(journal)) a.push_back("--resume");
        const pid_t pid = test::spawnShadowlab(a);
        ASSERT_GT(pid, 0);
        const auto deadline = std::chrono::steady_clock::now() + std::chrono::minutes(3);
        while (journalRows(journal).size() < killAfter && std::chrono::steady_clock::now() < deadline)
            std::this_thread::sleep_for(std::chrono::milliseconds(5));
        kill(pid, SIGKILL);
        test::waitFor(pid);
        for (const Json& row : journalRows(journal)) beforeKill[row.at("key").get<std::string>()] = row;
        ASSERT_GE(beforeKill.size(), killAfter) << "the sweep did not get far enough before the deadline";
    }

    const pid_t pid = test::spawnShadowlab([&] {
        auto a = args;
        a.push_back("--resume");
        return a;
    }());
    ASSERT_GT(pid, 0);
    ASSERT_EQ(test::waitFor(pid), 0);

    const std::vector<Json> rows = journalRows(journal);
    std::set<std::string> keys;
    for (const Json& row : rows) EXPECT_TRUE(keys.insert(row.at("key").get<std::string>()).second) << row.at("key");
    // Every row finished before a kill is still there, untouched (same measured times).
    for (const auto& [key, row] : beforeKill) {
        ASSERT_TRUE(keys.count(key)) << key;
        for (const Json& r : rows) {
            if (r.at("key") == key) {
                EXPECT_EQ(r.at("frame_ms"), row.at("frame_ms")) << key;
            }
        }
    }
    // results.json holds the same rows, and results.csv one line per row plus the header.
    std::ifstream jsonIn(out / "results.json");
    const Json all = Json::parse(jsonIn);
    EXPECT_EQ(all.size(), rows.size());
    std::ifstream csvIn(out / "results.csv");
    std::size_t lines = 0;
    for (std::string line; std::getline(csvIn, line);) ++lines;
    EXPECT_EQ(lines, rows.size() + 1);
    // No temporary file is left behind by the kills.
    for (const auto& e : std::filesystem::directory_iterator(out))
        EXPECT_EQ(e.path().filename().string().find(".tmp-"), std::string::npos) << e.path();
}

TEST(SweepResume, ASecondSweepIntoTheSameFolderWithoutResumeIsRefused) {
    TempDir dir;
    const auto out = dir.path() / "sweep";
    std::filesystem::create_directories(out);
    std::ofstream(out / "results.jsonl") << "";
    const pid_t pid = test::spawnShadowlab({"sweep", "seed", "-o", out.string(), "--quick", "--resolution", "16x9"});
    ASSERT_GT(pid, 0);
    EXPECT_EQ(test::waitFor(pid), 2);
    EXPECT_FALSE(std::filesystem::exists(out / "results.csv"));
}

}  // namespace
}  // namespace shadowlab
