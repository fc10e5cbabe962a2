// tests/studies/check_test.cpp: reading a check suite (studies/check.cpp).
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>

#include "studies/check.h"

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
