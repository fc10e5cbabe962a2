// tests/studies/check_test.cpp: reading a check suite (studies/check.cpp).
#include <gtest/gtest.h>

#include <algorithm>
#include <filesystem>
#include <fstream>

#include "studies/check.h"
#include "studies/check_report.h"

using namespace shadowlab;
namespace fs = std::filesystem;

// A case's "settings" reach its scene, every key of them: the filterable maps' parameters
// included, which a case sets to grade a filter away from its defaults.
TEST(CheckSuite, ACasesSettingsReachItsScene) {
    const fs::path dir = fs::path(testing::TempDir()) / "check_suite_settings";
    fs::create_directories(dir);
    const fs::path suiteFile = dir / "suite.json";
    {
        std::ofstream out(suiteFile);
        out << R"({"cases": [{"name": "seed.vsm", "scene": ")" << SHADOWLAB_SOURCE_DIR << R"(/scenes/seed.json",
            "settings": {"filter": "vsm", "blur_width": 9, "min_variance": 0.01, "light_bleeding_reduction": 0.3,
                         "shadow_map_size": 512}}]})";
    }
    const studies::CheckSuite suite = studies::loadSuite(suiteFile);
    ASSERT_EQ(suite.cases.size(), 1u);
    const scene::ShadowDefaults& s = suite.cases[0].scene.shadow;
    EXPECT_EQ(s.filter, "vsm");
    EXPECT_EQ(s.blurWidth, 9);
    EXPECT_EQ(s.minVariance, 0.01);
    EXPECT_EQ(s.bleedReduction, 0.3);
    EXPECT_EQ(s.shadowMapSize, 512);
    fs::remove_all(dir);
}

// An error's row keeps the table's columns and cuts a long message at a word, pointing to "Why",
// which holds it whole.
TEST(CheckSummary, ALongErrorIsCutAtAWordInItsRowAndWholeUnderWhy) {
    const fs::path dir = fs::path(testing::TempDir()) / "check_summary_error";
    fs::create_directories(dir);
    const fs::path suiteFile = dir / "suite.json";
    {
        std::ofstream out(suiteFile);
        out << R"({"cases": [{"name": "a", "scene": ")" << SHADOWLAB_SOURCE_DIR << R"(/scenes/seed.json"}]})";
    }
    const studies::CheckSuite suite = studies::loadSuite(suiteFile);
    studies::CaseResult r;
    r.name = "a";
    r.verdict = studies::CaseVerdict::Error;
    std::string error;
    for (int i = 0; i < 30; ++i) error += "word" + std::to_string(i) + " ";  // 203 characters
    error += "END";
    r.error = error;
    const std::string md = studies::markdownSummary(suite, {r}, false);
    const auto rowStart = md.find("| a |");
    ASSERT_NE(rowStart, std::string::npos) << md;
    const std::string row = md.substr(rowStart, md.find('\n', rowStart) - rowStart);
    EXPECT_EQ(std::count(row.begin(), row.end(), '|'), 13) << row;  // 12 cells
    EXPECT_NE(row.find(" … (see Why)"), std::string::npos) << row;
    EXPECT_EQ(row.find("END"), std::string::npos) << row;
    // The cut falls between words: the text before the ellipsis ends with a whole word.
    const std::size_t cut = row.find(" … (see Why)");
    EXPECT_NE(row.substr(0, cut).find("word16"), std::string::npos) << row;  // the last space within 110
    EXPECT_EQ(row.find("word17"), std::string::npos) << row;
    EXPECT_NE(md.find("- `a`: error: " + error.substr(0, 20)), std::string::npos) << md;
    EXPECT_NE(md.find("END\n"), std::string::npos) << md;
    // No space to cut at (a long path of two-byte characters): cut between characters, never
    // inside one, so the summary stays valid UTF-8.
    r.error = "x";  // then 'é' = C3 A9 from byte 1: byte 110 is the second byte of one
    for (int i = 0; i < 80; ++i) r.error += "é";
    const std::string md2 = studies::markdownSummary(suite, {r}, false);
    const auto at = md2.find("| a |");
    const std::string row2 = md2.substr(at, md2.find('\n', at) - at);
    const std::size_t ellipsis = row2.find(" … (see Why)");
    ASSERT_NE(ellipsis, std::string::npos) << row2;
    const std::string kept = row2.substr(0, ellipsis);
    EXPECT_EQ(kept.substr(kept.size() - 2), "é") << kept;
    fs::remove_all(dir);
}
