// tests/app/threejs_grade_test.cpp: tools/threejs-grade.sh end to end on the seed: three.js (the
// pinned npm package, headless Chromium, SwiftShader) renders its shadow masks, `compare` grades
// them, and the script writes report.html, which must pass tools/browser-check.sh. Registered as
// the ctests threejs_grade_seed and threejs_grade_seed_bias (label browser, docs/ci.md), not
// discovered: each is one run of the script.
//
// The seed's light: direction (-0.408, -0.816, -0.408), so θ = 35.3° from the ground's normal
// (tan θ = 0.707). Its shadow camera (tools/browser/threejs-grade.html) is a box fitted to the
// meshes' bounding sphere, radius R = 14.18 (the 20 x 20 ground), with a 2048² map: a texel is
// 2R / 2048 = 0.01384 wide and the depth range far - near is 2R = 28.35.
#include <sys/wait.h>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <string>

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include "tests/app/cli.h"

namespace fs = std::filesystem;
using Json = nlohmann::json;

namespace shadowlab {
namespace {

const fs::path kSource = SHADOWLAB_SOURCE_DIR;
const fs::path kBuild = SHADOWLAB_BINARY_DIR;

using test::shellQuote;

struct ScriptRun {
    int exitCode = -1;
    std::string out, err;
};

ScriptRun runScript(const fs::path& script, const std::string& args) {
    test::TempDir io;
    const std::string cmd = "SHADOWLAB_BUILD_DIR=" + shellQuote(kBuild.string()) +
                            " SHADOWLAB_EXE=" + shellQuote(SHADOWLAB_EXE) + " SHADOWLAB_BROWSER_SCREENSHOTS=" +
                            shellQuote((kBuild / "browser-check" / "screenshots" / "threejs-grade").string()) + " " +
                            shellQuote(script.string()) + " " + args + " >" + shellQuote((io.path() / "out").string()) +
                            " 2>" + shellQuote((io.path() / "err").string());
    const int status = std::system(cmd.c_str());
    return {WIFEXITED(status) ? WEXITSTATUS(status) : -1, test::slurpFile(io.path() / "out"),
            test::slurpFile(io.path() / "err")};
}

ScriptRun grade(const fs::path& out, const std::string& options) {
    return runScript(kSource / "tools" / "threejs-grade.sh", "seed " + shellQuote(out.string()) + " " + options);
}

Json readJson(const fs::path& p) {
    std::ifstream in(p);
    EXPECT_TRUE(in) << p;
    return Json::parse(in, nullptr, false);
}

// The page passes the browser check: no console error, every image loads, nothing overflows.
void expectPageChecksOut(const fs::path& page) {
    const ScriptRun r = runScript(kSource / "tools" / "browser-check.sh", shellQuote(page.string()));
    EXPECT_EQ(r.exitCode, 0) << r.out << r.err;
    EXPECT_EQ(r.out, "") << r.err;
}

// The section of the page about one method, from its id to the end of its card.
std::string sectionOf(const std::string& page, const std::string& method) {
    const std::size_t at = page.find("<section class=\"card\" id=\"" + method + "\">");
    if (at == std::string::npos) return "";
    return page.substr(at, page.find("</section>", at) - at);
}

TEST(ThreejsGrade, SeedAtThreesDefaultsShowsAcneOnItsPage) {
    const fs::path out = kBuild / "threejs-grade" / "seed";
    const ScriptRun r = grade(out, "--resolution 320x180");
    ASSERT_EQ(r.exitCode, 0) << r.out << r.err;

    const Json three = readJson(out / "threejs.json");
    EXPECT_EQ(three["width"], 320);
    EXPECT_EQ(three["bias"], 0.0);
    EXPECT_EQ(three["normalBias"], 0.0);
    const Json sil = readJson(out / "silhouette.json");
    EXPECT_LE(sil["differ"].get<double>(), 0.005 * sil["total"].get<double>());

    // At bias 0 a lit receiver is tested against the map's depth at the centres of the texels
    // around it, which differ from its own by tan θ times the offset to the centre, as often
    // above as below: about half of PCF's 17 taps fail, the mask sits near 0.5, and about half
    // the lit pixels (nearly all counted pixels here) come out as false shadow. 25% is far below
    // that and far above the few edge pixels a biased map gets wrong.
    for (const char* m : {"PCFShadowMap", "PCFSoftShadowMap"}) {
        const Json j = readJson(out / (std::string(m) + ".json"));
        EXPECT_GT(j["false_shadow_rate"].get<double>(), 0.25) << m;
    }
    // shadowlab's own raster of the same .glb, at its defaults, has no acne.
    EXPECT_LT(readJson(out / "raster.json")["mismatch_rate"].get<double>(), 0.01);

    const std::string page = test::slurpFile(out / "report.html");
    EXPECT_NE(page.find("bias 0, normalBias 0 (three’s defaults)"), std::string::npos);
    for (const char* m : {"PCFShadowMap", "PCFSoftShadowMap", "VSMShadowMap", "raster"}) {
        const std::string s = sectionOf(page, m);
        ASSERT_NE(s, "") << m;
        for (const std::string& img : {std::string("diff-") + m + ".png", std::string("heat-") + m + ".png"})
            EXPECT_NE(s.find(img), std::string::npos) << m << " " << img;
    }
    EXPECT_NE(sectionOf(page, "PCFShadowMap").find("Self-shadow acne"), std::string::npos);
    EXPECT_EQ(sectionOf(page, "raster").find("acne"), std::string::npos);
    expectPageChecksOut(out / "report.html");
}

TEST(ThreejsGrade, SeedWithAUsersBiasLosesTheAcne) {
    const fs::path out = kBuild / "threejs-grade" / "seed-bias";
    const ScriptRun r = grade(out, "--resolution 160x90 --bias -0.0005 --normal-bias 0.02");
    ASSERT_EQ(r.exitCode, 0) << r.out << r.err;

    const Json three = readJson(out / "threejs.json");
    EXPECT_EQ(three["bias"], -0.0005);
    EXPECT_EQ(three["normalBias"], 0.02);
    ASSERT_EQ(three["lights"].size(), 1u);
    EXPECT_EQ(three["lights"][0]["bias"], -0.0005);
    EXPECT_EQ(three["lights"][0]["normalBias"], 0.02);

    // The farthest PCF tap's texel centre is 1.5 texels from the receiver: a depth step of
    // 0.707 * 1.5 * 0.01384 = 0.0147, 5.2e-4 of the depth range. The bias gives 5e-4 of it; the
    // normal offset lifts the lookup 0.02 off the ground, which leaves the ground behind it
    // 0.02 / cos θ = 0.0245 (8.6e-4) farther along the light: 1.4e-3 in all, and no tap fails on
    // the flat ground. The price is light through gaps under 0.0142 + 0.0245 = 0.039 between
    // blocker and receiver: around the sphere's contact, ground within sqrt(2 * 1 * 0.039) = 0.28
    // of it, a few pixels at 160x90, most behind the sphere. 1% (92 of the 9190 counted pixels)
    // bounds both.
    for (const char* m : {"PCFShadowMap", "PCFSoftShadowMap", "VSMShadowMap"}) {
        const Json j = readJson(out / (std::string(m) + ".json"));
        EXPECT_LT(j["false_shadow_rate"].get<double>(), 0.01) << m;
        EXPECT_LT(j["missed_shadow_rate"].get<double>(), 0.01) << m;
    }
    const std::string page = test::slurpFile(out / "report.html");
    EXPECT_NE(page.find("bias -0.0005, normalBias 0.02"), std::string::npos);
    EXPECT_EQ(page.find("Self-shadow acne"), std::string::npos);
    expectPageChecksOut(out / "report.html");
}

// The page's words and numbers from hand-made grades (no browser): tools/browser/threejs-report.mjs
// on an exported spot-light scene (objects sphere, box, ground: ids 1, 2, 3) with metrics chosen
// so that each method has one thing wrong.
Json grades(double falseShadow, double falseNearEdge, double missed, double missedNearEdge, const Json& perObject) {
    const double n = 10000;
    return {{"counted", n},
            {"mismatch_rate", (falseShadow + missed) / n},
            {"false_shadow", falseShadow},
            {"false_shadow_rate", falseShadow / n},
            {"false_shadow_near_edge", falseNearEdge},
            {"missed_shadow", missed},
            {"missed_shadow_rate", missed / n},
            {"missed_shadow_near_edge", missedNearEdge},
            {"per_object", perObject},
            {"edge_radius", 2},
            {"penumbra_pixels", 0},
            {"mean_abs_visibility_error", (falseShadow + missed) / n},
            {"mean_abs_visibility_error_penumbra", 0.0},
            {"soft_error_pixels", 0},
            {"soft_error_rate", 0.0},
            {"shadow_iou", 0.5},
            {"hotspot", {{"x", 0}, {"y", 0}, {"size", 16}, {"wrong_pixels", 0}}}};
}

TEST(ThreejsGrade, ThePageSaysWhatWentWrongAndWhatTheBiasIsInWorldUnits) {
    test::TempDir dir;
    const fs::path out = dir.path();
    ASSERT_EQ(std::system((shellQuote(SHADOWLAB_EXE) + " export lesson/spot-light -o " +
                           shellQuote((out / "scene.glb").string()) + " >/dev/null 2>&1")
                              .c_str()),
              0);
    // A spot's map holds perspective depth far (d - near) / (d (far - near)): at distance d a
    // bias b spans b (far - near) d^2 / (far near) in world units, 0.001 * 16 * 64 / 80 = 0.0128.
    const Json three = {{"width", 64},
                        {"height", 36},
                        {"three", "181"},
                        {"webgl", "test"},
                        {"mapSize", 1024},
                        {"bias", -0.001},
                        {"normalBias", 0},
                        {"lights", Json::array({{{"type", "SpotLight"},
                                                 {"near", 4},
                                                 {"far", 20},
                                                 {"fov", 64},
                                                 {"distance", 8},
                                                 {"bias", -0.001},
                                                 {"normalBias", 0}}})}};
    std::ofstream(out / "threejs.json") << three.dump();
    std::ofstream(out / "silhouette.json") << R"({"differ": 0, "total": 2304})";
    const Json acne =
        grades(3000, 0, 0, 0, Json::array({{{"object_id", 3}, {"false_shadow", 3000}, {"missed_shadow", 0}}}));
    std::ofstream(out / "PCFShadowMap.json") << acne.dump();
    std::ofstream(out / "PCFSoftShadowMap.json") << acne.dump();
    std::ofstream(out / "VSMShadowMap.json")
        << grades(0, 0, 500, 100,
                  Json::array({{{"object_id", 1}, {"false_shadow", 0}, {"missed_shadow", 400}},
                               {{"object_id", 3}, {"false_shadow", 0}, {"missed_shadow", 100}}}))
               .dump();
    std::ofstream(out / "raster.json") << grades(10, 10, 10, 10,
                                                 Json::array(
                                                     {{{"object_id", 3}, {"false_shadow", 10}, {"missed_shadow", 10}}}))
                                              .dump();

    const ScriptRun r = runScript("node", shellQuote((kSource / "tools" / "browser" / "threejs-report.mjs").string()) +
                                              " " + shellQuote(out.string()) + " --scene spot");
    ASSERT_EQ(r.exitCode, 0) << r.err;
    const std::string page = test::slurpFile(out / "report.html");
    EXPECT_NE(page.find("bias -0.001, normalBias 0"), std::string::npos);
    EXPECT_NE(page.find("<td>0.0128 (at the scene's centre, 8 from the light)</td>"), std::string::npos);
    // 3000 of 10000 false, none near an edge, all on the ground, at a non-zero bias: acne left.
    EXPECT_NE(sectionOf(page, "PCFShadowMap").find("Acne remains over 30.00% of the counted pixels (all on “ground”)"),
              std::string::npos);
    // 400 of the 500 missed pixels away from the edges (4%), 400 of 500 on the sphere: VSM's bleeding.
    const std::string vsm = sectionOf(page, "VSMShadowMap");
    EXPECT_NE(vsm.find("Missed shadow away from the edges (4.00%, 80% of it on “sphere”): light bleeding"),
              std::string::npos);
    EXPECT_EQ(vsm.find("acne"), std::string::npos);
    EXPECT_NE(sectionOf(page, "raster").find("Close to the reference: 0.20%"), std::string::npos);
}

TEST(ThreejsGrade, ABadBiasIsRefusedBeforeAnythingIsWritten) {
    test::TempDir dir;
    const fs::path out = dir.path() / "out";
    for (const char* bad : {"--bias abc", "--normal-bias 1e", "--map-size 0", "--bias"}) {
        const ScriptRun r = grade(out, std::string(bad));
        EXPECT_EQ(r.exitCode, 2) << bad << r.err;
        EXPECT_NE(r.err.find("threejs-grade: "), std::string::npos) << bad << r.err;
        EXPECT_FALSE(fs::exists(out)) << bad;
    }
}

}  // namespace
}  // namespace shadowlab
