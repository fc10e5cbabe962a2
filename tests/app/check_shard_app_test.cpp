// tests/app/check_shard_app_test.cpp: `check --shard K/N` and `merge` of check shards end to end:
// the merged junit.xml, summary.md, summary.html and cases/ equal the unsharded run's (run times aside) with
// its exit code; shards of another suite or split refused; missing shards named; nothing written
// by a refused merge.
#include <filesystem>
#include <fstream>
#include <regex>
#include <set>

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include "tests/app/cli.h"
#include "tests/scene/test_files.h"

namespace shadowlab {
namespace {

namespace fs = std::filesystem;
using test::runShadowlab;
using test::slurpFile;
using test::TempDir;

// seed without ray bias fails its 1% false-shadow budget (acne), a raster case on a device that
// does not exist cannot render, the robust ray tracer passes a 0 px budget.
const char* kSuite = R"({"resolution": "64x36", "cases": [
    {"name": "acne", "scene": "seed", "backend": "raytrace", "settings": {"ray_bias": 0},
     "budgets": {"max_false_shadow": "1%"}},
    {"name": "no-device", "scene": "seed", "backend": "raster", "device": "no-such-vulkan-device"},
    {"name": "robust", "scene": "seed", "backend": "raytrace", "settings": {"ray_bias": "robust"},
     "budgets": {"max_mismatch": "0px"}}]})";

// What timing measures goes: time="..." attributes and durations ("0.377 ms", "2.8 s").
std::string withoutTimes(const std::string& text) {
    static const std::regex time(R"(time="[^"]*")");
    static const std::regex duration(R"([0-9][0-9.]*(e[-+]?[0-9]+)? (ms|s)\b)");
    return std::regex_replace(std::regex_replace(text, time, "time=\"\""), duration, "T");
}

std::set<std::string> filesIn(const fs::path& dir) {
    std::set<std::string> names;
    for (const auto& e : fs::directory_iterator(dir)) names.insert(e.path().filename().string());
    return names;
}

nlohmann::json caseWithoutTimes(const fs::path& file) {
    nlohmann::json j = nlohmann::json::parse(slurpFile(file));
    j.erase("seconds");
    if (j.contains("metrics")) {
        j["metrics"].erase("method_timing");
        j["metrics"].erase("reference_timing");
    }
    return j;
}

void expectMergedEqualsUnsharded(const std::string& suiteJson, int expectedExit, const std::vector<int>& counts) {
    TempDir dir;
    const fs::path suite = dir.write("suite.json", suiteJson);
    const auto full = runShadowlab({"check", suite.string(), "-o", (dir.path() / "full").string()});
    ASSERT_EQ(full.exitCode, expectedExit) << full.err;
    for (int n : counts) {
        const fs::path out = dir.path() / ("sharded-" + std::to_string(n));
        for (int k = 0; k < n; ++k) {
            const auto r = runShadowlab(
                {"check", suite.string(), "--shard", std::to_string(k) + "/" + std::to_string(n), "-o", out.string()});
            ASSERT_TRUE(r.exitCode == 0 || r.exitCode == 1 || r.exitCode == 3) << r.err;
            const std::string name = "shard-" + std::to_string(k) + "-of-" + std::to_string(n);
            ASSERT_TRUE(fs::exists(out / name / "shard.json")) << r.err;
            ASSERT_TRUE(fs::exists(out / name / "junit.xml"));
            ASSERT_TRUE(fs::exists(out / name / "summary.md"));
        }
        EXPECT_FALSE(fs::exists(out / "junit.xml"));  // only merge writes the whole suite's
        const auto m = runShadowlab({"merge", out.string()});
        EXPECT_EQ(m.exitCode, expectedExit) << "N=" << n << ": " << m.err;
        const std::string a = slurpFile(dir.path() / "full" / "junit.xml"), b = slurpFile(out / "junit.xml");
        EXPECT_FALSE(b.empty());
        EXPECT_EQ(withoutTimes(a), withoutTimes(b)) << "N=" << n;
        EXPECT_EQ(withoutTimes(slurpFile(dir.path() / "full" / "summary.md")),
                  withoutTimes(slurpFile(out / "summary.md")))
            << "N=" << n;
        EXPECT_EQ(withoutTimes(slurpFile(dir.path() / "full" / "summary.html")),
                  withoutTimes(slurpFile(out / "summary.html")))
            << "N=" << n;
        // Every case once, with its difference image when it failed.
        ASSERT_EQ(filesIn(dir.path() / "full" / "cases"), filesIn(out / "cases")) << "N=" << n;
        for (const std::string& f : filesIn(out / "cases")) {
            if (f.size() > 5 && f.substr(f.size() - 5) == ".json") {
                EXPECT_EQ(caseWithoutTimes(dir.path() / "full" / "cases" / f), caseWithoutTimes(out / "cases" / f))
                    << f;
            }
        }
    }
}

TEST(CheckShardApp, MergedJUnitSummaryAndCasesEqualTheUnshardedRunWithItsExitCode) {
    // An error outranks a failure: 1. N = 4 is more shards than cases (one shard is empty).
    expectMergedEqualsUnsharded(kSuite, 1, {1, 2, 4});
    // A failure alone: 3.
    expectMergedEqualsUnsharded(R"({"resolution": "64x36", "cases": [
        {"name": "acne", "scene": "seed", "backend": "raytrace", "settings": {"ray_bias": 0},
         "budgets": {"max_false_shadow": "1%"}},
        {"name": "robust", "scene": "seed", "backend": "raytrace", "settings": {"ray_bias": "robust"}}]})",
                                3, {2});
}

TEST(CheckShardApp, AShardOfAnotherSuiteOrAnotherSplitIsRefusedAndNothingIsWritten) {
    TempDir dir;
    const fs::path a = dir.write("a.json", kSuite);
    // The same case names, another setting: another suite file.
    std::string other = kSuite;
    other.replace(other.find("\"max_mismatch\": \"0px\""), 21, "\"max_mismatch\": \"1px\"");
    const fs::path b = dir.write("b.json", other);
    const fs::path out = dir.path() / "out";
    ASSERT_NE(runShadowlab({"check", a.string(), "--shard", "0/2", "-o", out.string()}).exitCode, 2);
    ASSERT_NE(runShadowlab({"check", b.string(), "--shard", "1/2", "-o", out.string()}).exitCode, 2);
    const auto r = runShadowlab({"merge", out.string()});
    EXPECT_EQ(r.exitCode, 2) << r.err;
    EXPECT_NE(r.err.find("a shard of another check"), std::string::npos) << r.err;
    EXPECT_NE(r.err.find("another suite file"), std::string::npos) << r.err;
    EXPECT_NE(r.err.find("shard-1-of-2"), std::string::npos) << r.err;
    EXPECT_FALSE(fs::exists(out / "junit.xml"));
    EXPECT_FALSE(fs::exists(out / "summary.md"));
    EXPECT_FALSE(fs::exists(out / "cases"));

    // Shards of one suite split two ways.
    const fs::path mixed = dir.path() / "mixed";
    ASSERT_NE(runShadowlab({"check", a.string(), "--shard", "0/2", "-o", mixed.string()}).exitCode, 2);
    ASSERT_NE(runShadowlab({"check", a.string(), "--shard", "1/3", "-o", mixed.string()}).exitCode, 2);
    const auto s = runShadowlab({"merge", mixed.string()});
    EXPECT_EQ(s.exitCode, 2) << s.err;
    EXPECT_NE(s.err.find("split into"), std::string::npos) << s.err;
    EXPECT_FALSE(fs::exists(mixed / "junit.xml"));

    // A sharded check writes no baseline: N shards would race on one file.
    const auto u = runShadowlab({"check", a.string(), "--shard", "0/2", "--update-baseline", "--baseline",
                                 (dir.path() / "base.json").string(), "-o", (dir.path() / "u").string()});
    EXPECT_EQ(u.exitCode, 2) << u.err;
    EXPECT_NE(u.err.find("--update-baseline is not sharded"), std::string::npos) << u.err;
    EXPECT_FALSE(fs::exists(dir.path() / "u"));
}

TEST(CheckShardApp, AMissingShardIsNamedWithTheCommandThatWritesIt) {
    TempDir dir;
    const fs::path suite = dir.write("my suite.json", kSuite);  // the command quotes it for a shell
    const fs::path out = dir.path() / "out";
    ASSERT_NE(runShadowlab({"check", suite.string(), "--shard", "0/3", "-o", out.string()}).exitCode, 2);
    ASSERT_NE(runShadowlab({"check", suite.string(), "--shard", "2/3", "-o", out.string()}).exitCode, 2);
    const auto r = runShadowlab({"merge", out.string()});
    EXPECT_EQ(r.exitCode, 2) << r.err;
    EXPECT_NE(r.err.find("1 of 3 shards"), std::string::npos) << r.err;
    EXPECT_NE(r.err.find((out / "shard-1-of-3").string()), std::string::npos) << r.err;
    EXPECT_NE(r.err.find("): shadowlab check '" + suite.string() + "' --shard 1/3 -o " + out.string()),
              std::string::npos)
        << r.err;
    EXPECT_EQ(r.err.find("shard 0/3 ("), std::string::npos) << r.err;  // only the missing one
    EXPECT_FALSE(fs::exists(out / "junit.xml"));
    EXPECT_FALSE(fs::exists(out / "cases"));
    // Rendered now, the merge goes through; but first a case file of shard 0 cut short (a copy
    // that stopped) is refused by name, with nothing written.
    ASSERT_NE(runShadowlab({"check", suite.string(), "--shard", "1/3", "-o", out.string()}).exitCode, 2);
    fs::path caseFile;
    for (const auto& e : fs::directory_iterator(out / "shard-0-of-3" / "cases"))
        if (e.path().extension() == ".json") caseFile = e.path();
    ASSERT_FALSE(caseFile.empty());
    const std::string whole = slurpFile(caseFile);
    std::ofstream(caseFile, std::ios::binary | std::ios::trunc) << whole.substr(0, whole.size() / 2);
    const auto cut = runShadowlab({"merge", out.string()});
    EXPECT_EQ(cut.exitCode, 2) << cut.err;
    EXPECT_NE(cut.err.find(caseFile.string() + ": invalid JSON"), std::string::npos) << cut.err;
    EXPECT_FALSE(fs::exists(out / "junit.xml"));
    std::ofstream(caseFile, std::ios::binary | std::ios::trunc) << whole;
    const auto m = runShadowlab({"merge", out.string()});
    EXPECT_EQ(m.exitCode, 1) << m.err;
    EXPECT_TRUE(fs::exists(out / "junit.xml"));
}

TEST(CheckShardApp, ShardsInFoldersOfTheirOwnAsACIMatrixDownloadsThemMergeIntoTheGivenFolder) {
    TempDir dir;
    const fs::path suite = dir.write("suite.json", kSuite);
    const fs::path a = dir.path() / "shards" / "job-0", b = dir.path() / "shards" / "job-1";
    ASSERT_NE(runShadowlab({"check", suite.string(), "--shard", "0/2", "-o", a.string()}).exitCode, 2);
    ASSERT_NE(runShadowlab({"check", suite.string(), "--shard", "1/2", "-o", b.string()}).exitCode, 2);
    EXPECT_EQ(runShadowlab({"merge", a.string(), b.string()}).exitCode, 2);  // two inputs: -o is needed
    const fs::path merged = dir.path() / "merged";
    const auto m = runShadowlab({"merge", a.string(), b.string(), "-o", merged.string()});
    EXPECT_EQ(m.exitCode, 1) << m.err;
    EXPECT_EQ(filesIn(merged / "cases"),
              (std::set<std::string>{"acne.json", "acne-diff.png", "no-device.json", "robust.json"}));
    EXPECT_NE(slurpFile(merged / "junit.xml").find("tests=\"3\" failures=\"1\" errors=\"1\""), std::string::npos);
}

}  // namespace
}  // namespace shadowlab
