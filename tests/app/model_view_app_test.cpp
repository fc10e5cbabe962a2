// tests/app/model_view_app_test.cpp: --camera, --sun, --ground and the view search as a user
// meets them: listed by --explain, recorded in the Frame, bad values are one clear error (exit 2).
#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include "tests/app/cli.h"
#include "tests/scene/camera_gltf.h"

namespace shadowlab {
namespace {

using test::runShadowlab;
using test::TempDir;

nlohmann::json attributes(const test::CliResult& r) { return nlohmann::json::parse(r.out).at("attributes"); }

TEST(ModelViewApp, ExplainListsTheFilesCamerasAndCameraPicksOneByName) {
    TempDir dir;
    const auto model = dir.write("box.gltf", test::cameraBoxGltf());
    const auto out = dir.path() / "x.exr";
    const auto r = runShadowlab({"render", model.string(), "--camera", "Side", "--explain", "--json", "--resolution",
                                 "64x36", "-o", out.string()});
    ASSERT_EQ(r.exitCode, 0) << r.err;
    EXPECT_NE(r.err.find("0 'Front'"), std::string::npos) << r.err;
    EXPECT_NE(r.err.find("1 'Side'"), std::string::npos) << r.err;
    EXPECT_NE(attributes(r).at("choice.view").get<std::string>().find("'Side'"), std::string::npos) << r.out;
}

TEST(ModelViewApp, AnUnknownCameraExitsTwoNamingTheCamerasAndWritesNothing) {
    TempDir dir;
    const auto model = dir.write("box.gltf", test::cameraBoxGltf());
    const auto out = dir.path() / "x.png";
    const auto r = runShadowlab({"render", model.string(), "--camera", "Top", "-o", out.string()});
    EXPECT_EQ(r.exitCode, 2);
    EXPECT_NE(r.err.find("--camera Top"), std::string::npos) << r.err;
    EXPECT_NE(r.err.find("'Front'"), std::string::npos) << r.err;
    EXPECT_FALSE(std::filesystem::exists(out));
}

TEST(ModelViewApp, AModelWithoutCameraOrLightGetsASearchedViewSunAndGroundRecordedInTheFrame) {
    TempDir dir;
    const auto model = dir.write("box.gltf", test::cameraBoxGltf(false));
    const auto r = runShadowlab({"render", model.string(), "--json", "--explain", "--resolution", "64x36", "-o",
                                 (dir.path() / "x.exr").string()});
    ASSERT_EQ(r.exitCode, 0) << r.err;
    const auto a = attributes(r);
    EXPECT_EQ(a.at("choice.view").get<std::string>().rfind("searched", 0), 0u) << a.dump();
    EXPECT_EQ(a.at("choice.sun").get<std::string>().rfind("searched", 0), 0u) << a.dump();
    EXPECT_NE(a.at("choice.ground").get<std::string>().find("quad"), std::string::npos) << a.dump();
    EXPECT_NE(r.err.find("view: searched"), std::string::npos) << r.err;
}

TEST(ModelViewApp, SunAndNoGroundOverrideTheDefaults) {
    TempDir dir;
    const auto model = dir.write("box.gltf", test::cameraBoxGltf(false));
    const auto r = runShadowlab({"render", model.string(), "--sun", "90,30", "--no-ground", "--json", "--resolution",
                                 "64x36", "-o", (dir.path() / "x.exr").string()});
    ASSERT_EQ(r.exitCode, 0) << r.err;
    const auto a = attributes(r);
    EXPECT_EQ(a.at("choice.sun").get<std::string>(), "azimuth 90, elevation 30 degrees (--sun)");
    EXPECT_EQ(a.at("choice.ground").get<std::string>(), "none (--no-ground)");
    for (const char* bad : {"90", "north,30", "0,120"}) {
        const auto b = runShadowlab({"render", model.string(), "--sun", bad, "-o", (dir.path() / "y.png").string()});
        EXPECT_EQ(b.exitCode, 2) << bad;
        EXPECT_NE(b.err.find("--sun"), std::string::npos) << b.err;
        EXPECT_FALSE(std::filesystem::exists(dir.path() / "y.png"));
    }
}

TEST(ModelViewApp, HelpNamesTheViewOptions) {
    for (const char* cmd : {"render", "run", "sweep"}) {
        const auto r = runShadowlab({cmd, "--help"});
        EXPECT_EQ(r.exitCode, 0);
        for (const char* option : {"--camera", "--sun", "--ground", "--no-ground"})
            EXPECT_NE(r.out.find(option), std::string::npos) << cmd << " " << option;
    }
}

TEST(ModelViewApp, GroundOnAJsonSceneAddsOne) {
    TempDir dir;
    const auto s = runShadowlab(
        {"render", "seed", "--ground", "--explain", "--resolution", "32x18", "-o", (dir.path() / "x.png").string()});
    ASSERT_EQ(s.exitCode, 0) << s.err;
    EXPECT_NE(s.err.find("ground: a "), std::string::npos) << s.err;
}

}  // namespace
}  // namespace shadowlab
