// tests/app/gates_test.cpp: the CI gates end to end: budgets on compare and run (exit 3, each
// broken budget printed), frames of different scenes or cameras refused, another engine's
// shadow mask graded, and `check` suites (JUnit, Markdown, per-case JSON, baselines, errors).
#include <filesystem>
#include <regex>

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include "scene/frame.h"
#include "scene/frame_io.h"
#include "tests/app/cli.h"
#include "tests/scene/test_files.h"

namespace shadowlab {
namespace {

namespace fs = std::filesystem;
using test::runShadowlab;
using test::slurpFile;
using test::TempDir;

std::size_t occurrences(const std::string& text, const std::string& what) {
    std::size_t n = 0;
    for (std::size_t at = text.find(what); at != std::string::npos; at = text.find(what, at + 1)) ++n;
    return n;
}

// The seed at 160x90: the reference and the ray tracer without bias. The README's lesson: with
// --ray-bias 0 about 5% of the counted pixels are self-shadowed (acne); the reference has none.
struct SeedFrames {
    TempDir dir;
    fs::path reference = dir.path() / "ref.exr", acne = dir.path() / "acne.exr";
    SeedFrames() {
        EXPECT_EQ(runShadowlab(
                      {"render", "seed", "--backend", "reference", "--resolution", "160x90", "-o", reference.string()})
                      .exitCode,
                  0);
        EXPECT_EQ(runShadowlab({"render", "seed", "--backend", "raytrace", "--ray-bias", "0", "--resolution", "160x90",
                                "-o", acne.string()})
                      .exitCode,
                  0);
    }
};

TEST(AppGates, CompareExitsThreeAndPrintsEveryBrokenBudgetWithValueAndLimit) {
    SeedFrames f;
    const auto diff = (f.dir.path() / "d.png").string();
    const auto broken =
        runShadowlab({"compare", f.acne.string(), f.reference.string(), "-o", diff, "--json", "--max-false-shadow",
                      "1%", "--max-self-acne", "10px", "--min-iou", "0.99", "--max-missed-shadow", "0.5%"});
    EXPECT_EQ(broken.exitCode, 3) << broken.err;
    const auto j = nlohmann::json::parse(broken.out);
    const double rate = j["false_shadow_rate"];
    EXPECT_GT(rate, 0.01);  // acne over a few percent of the floor
    EXPECT_NE(broken.err.find("--max-false-shadow: "), std::string::npos) << broken.err;
    EXPECT_NE(broken.err.find("> limit 1%: BROKEN"), std::string::npos) << broken.err;
    EXPECT_NE(broken.err.find("> limit 10px: BROKEN"), std::string::npos) << broken.err;
    EXPECT_NE(broken.err.find("< limit 0.99: BROKEN"), std::string::npos) << broken.err;
    // No missed shadow without a bias: that budget holds.
    EXPECT_NE(broken.err.find("--max-missed-shadow: 0% (0 px) <= limit 0.5%: ok"), std::string::npos) << broken.err;
    ASSERT_EQ(j["budgets"].size(), 4u);
    EXPECT_EQ(j["budgets"][1]["budget"], "max_missed_shadow");
    EXPECT_EQ(j["budgets"][1]["broken"], false);
    // The same frames pass a budget above what they measure; no budget: exit 0 as before.
    EXPECT_EQ(
        runShadowlab({"compare", f.acne.string(), f.reference.string(), "-o", diff, "--max-mismatch", "50%"}).exitCode,
        0);
    EXPECT_EQ(runShadowlab({"compare", f.acne.string(), f.reference.string(), "-o", diff}).exitCode, 0);
    // Bad budgets are bad input and write nothing.
    fs::remove(diff);
    for (const char* bad : {"12", "5px%", "-1%"}) {
        const auto r =
            runShadowlab({"compare", f.acne.string(), f.reference.string(), "-o", diff, "--max-mismatch", bad});
        EXPECT_EQ(r.exitCode, 2) << bad;
        EXPECT_NE(r.err.find("--max-mismatch: "), std::string::npos) << r.err;
        EXPECT_FALSE(fs::exists(diff));
    }
    EXPECT_EQ(runShadowlab({"compare", f.acne.string(), f.reference.string(), "-o", diff, "--min-iou", "3px"}).exitCode,
              2);
}

TEST(AppGates, CompareRefusesFramesOfAnotherSceneCameraOrSize) {
    SeedFrames f;
    TempDir dir;
    const auto diff = (dir.path() / "d.png").string();
    const auto other = (dir.path() / "glass.exr").string();
    ASSERT_EQ(runShadowlab(
                  {"render", "lesson/semi-transparent", "--backend", "raytrace", "--resolution", "160x90", "-o", other})
                  .exitCode,
              0);
    auto r = runShadowlab({"compare", other, f.reference.string(), "-o", diff});
    EXPECT_EQ(r.exitCode, 2);
    EXPECT_NE(r.err.find("different scenes (scene_hash "), std::string::npos) << r.err;
    EXPECT_FALSE(fs::exists(diff));
    r = runShadowlab({"compare", other, f.reference.string(), "-o", diff, "--allow-different-scene"});
    EXPECT_EQ(r.exitCode, 0) << r.err;
    EXPECT_NE(r.err.find("warning: different scenes"), std::string::npos) << r.err;

    // The seed from another camera position: same scene hash, different worldToCamera.
    const std::string seed = slurpFile(fs::path(SHADOWLAB_SOURCE_DIR) / "scenes" / "seed.json");
    const auto moved = std::regex_replace(seed, std::regex("\"position\": \\[[^\\]]*\\]"), "\"position\": [0.5, 2, 6]",
                                          std::regex_constants::format_first_only);
    ASSERT_NE(moved, seed);
    const auto movedScene = dir.write("moved.json", moved);
    const auto movedFrame = (dir.path() / "moved.exr").string();
    ASSERT_EQ(runShadowlab({"render", movedScene.string(), "--resolution", "160x90", "-o", movedFrame}).exitCode, 0);
    r = runShadowlab({"compare", movedFrame, f.reference.string(), "-o", diff});
    EXPECT_EQ(r.exitCode, 2);
    EXPECT_NE(r.err.find("different cameras (worldToCamera"), std::string::npos) << r.err;

    const auto big = (dir.path() / "big.exr").string();
    ASSERT_EQ(runShadowlab({"render", "seed", "--resolution", "320x180", "-o", big}).exitCode, 0);
    r = runShadowlab({"compare", big, f.reference.string(), "-o", diff});
    EXPECT_EQ(r.exitCode, 2);
    EXPECT_NE(r.err.find("different image sizes (method 320x180, reference 160x90)"), std::string::npos) << r.err;
}

TEST(AppGates, AnotherEnginesMaskIsGradedWithTheReferencesIdsAndNdotL) {
    SeedFrames f;
    TempDir dir;
    const scene::Frame ref = scene::readFrame(f.reference);
    const scene::Frame acne = scene::readFrame(f.acne);
    // The acne frame's visibility as an 8-bit gray mask (hard shadows: exactly 0 or 1), and
    // inverted (1 = shadow) in the G channel of an RGB PNG.
    std::vector<float> rgb, inverted;
    for (float v : acne.visibility) {
        rgb.insert(rgb.end(), {v, 1.0f - v, v});
    }
    const auto png = dir.path() / "mask.png";
    scene::writePngDisplay(png, acne.width, acne.height, rgb);
    const auto full = runShadowlab(
        {"compare", f.acne.string(), f.reference.string(), "-o", (dir.path() / "a.png").string(), "--json"});
    ASSERT_EQ(full.exitCode, 0) << full.err;
    const auto fromMask = runShadowlab({"compare", png.string(), f.reference.string(), "-o",
                                        (dir.path() / "b.png").string(), "--json", "--mask-channel", "R"});
    ASSERT_EQ(fromMask.exitCode, 0) << fromMask.err;
    const auto a = nlohmann::json::parse(full.out), b = nlohmann::json::parse(fromMask.out);
    // The mask's pixels count where the reference's do: all of the reference's counted pixels,
    // and the same false shadows as the full frame on the pixels both count.
    std::size_t refCounted = 0;
    for (std::size_t i = 0; i < ref.pixelCount(); ++i) refCounted += ref.objectId[i] > 0.5f && ref.ndotl[i] > 0.0f;
    EXPECT_EQ(b["counted"], refCounted);
    EXPECT_EQ(b["silhouette_mismatch"], 0);
    EXPECT_EQ(b["false_shadow"], a["false_shadow"]);
    EXPECT_EQ(b["method_backend"], "mask");
    const auto inv = runShadowlab({"compare", png.string(), f.reference.string(), "-o", (dir.path() / "c.png").string(),
                                   "--json", "--mask-channel", "G", "--mask-invert"});
    ASSERT_EQ(inv.exitCode, 0) << inv.err;
    EXPECT_EQ(nlohmann::json::parse(inv.out)["false_shadow"], a["false_shadow"]);
    // A mask records no run time: the summary says so rather than "0 ms".
    const auto said = runShadowlab(
        {"compare", png.string(), f.reference.string(), "-o", (dir.path() / "e.png").string(), "--mask-channel", "R"});
    ASSERT_EQ(said.exitCode, 0) << said.err;
    EXPECT_NE((said.out + said.err).find("run time not recorded (reference "), std::string::npos)
        << said.out << said.err;
    EXPECT_TRUE(b["method_timing"]["total_ms"].is_null()) << b["method_timing"];
    EXPECT_FALSE(a["method_timing"]["total_ms"].is_null());
    // A mask records no bias or texel size: a bleeding budget is refused for that reason.
    const auto bleeding =
        runShadowlab({"compare", png.string(), f.reference.string(), "-o", (dir.path() / "d.png").string(),
                      "--mask-channel", "R", "--max-bleeding", "1%"});
    EXPECT_EQ(bleeding.exitCode, 2);
    EXPECT_NE(bleeding.err.find("--max-bleeding: a shadow mask records no bias or texel size"), std::string::npos)
        << bleeding.err;
    // Read upside down (as glReadPixels returns rows) or inverted, the mask is wrong nearly everywhere:
    // a hint says which reading agrees. A mask read as it was written gets none.
    std::vector<float> flipped(acne.visibility.size() * 3), invertedGray;
    for (int y = 0; y < acne.height; ++y)
        for (int x = 0; x < acne.width; ++x)
            for (int c = 0; c < 3; ++c)
                flipped[3 * (std::size_t(acne.height - 1 - y) * acne.width + x) + c] =
                    acne.visibility[std::size_t(y) * acne.width + x];
    for (float v : acne.visibility) invertedGray.insert(invertedGray.end(), {1.0f - v, 1.0f - v, 1.0f - v});
    const auto flippedPng = dir.path() / "flipped.png", invertedPng = dir.path() / "inverted.png";
    scene::writePngDisplay(flippedPng, acne.width, acne.height, flipped);
    scene::writePngDisplay(invertedPng, acne.width, acne.height, invertedGray);
    const auto up = runShadowlab({"compare", flippedPng.string(), f.reference.string(), "-o",
                                  (dir.path() / "f.png").string(), "--mask-channel", "R"});
    EXPECT_EQ(up.exitCode, 0) << up.err;
    EXPECT_NE(up.err.find("hint: " + flippedPng.string() + ": read flipped vertically"), std::string::npos)
        << up.out << up.err;
    const auto inverse = runShadowlab({"compare", invertedPng.string(), f.reference.string(), "-o",
                                       (dir.path() / "g.png").string(), "--mask-channel", "R", "--json"});
    EXPECT_EQ(inverse.exitCode, 0) << inverse.err;
    EXPECT_NE(inverse.err.find("read inverted (1 = shadowed: --mask-invert)"), std::string::npos) << inverse.err;
    EXPECT_NE(nlohmann::json::parse(inverse.out)["mask_hint"].get<std::string>().find("read inverted"),
              std::string::npos);
    EXPECT_TRUE(b["mask_hint"].is_null()) << b["mask_hint"];
    // --mask-invert on a mask that was 1 = lit: the hint is to drop the flag, not to add it.
    const auto twice = runShadowlab({"compare", png.string(), f.reference.string(), "-o",
                                     (dir.path() / "h.png").string(), "--mask-channel", "R", "--mask-invert"});
    EXPECT_NE(twice.err.find("read without --mask-invert (1 = lit)"), std::string::npos) << twice.err;
    EXPECT_EQ(said.err.find("hint:"), std::string::npos) << said.err;
    // A mask of several channels needs one chosen; a wrong name lists the channels.
    auto r = runShadowlab({"compare", png.string(), f.reference.string(), "-o", (dir.path() / "d.png").string()});
    EXPECT_EQ(r.exitCode, 2);
    EXPECT_NE(r.err.find("3 channels (R, G, B)"), std::string::npos) << r.err;
    r = runShadowlab({"compare", png.string(), f.reference.string(), "-o", (dir.path() / "d.png").string(),
                      "--mask-channel", "shadow"});
    EXPECT_EQ(r.exitCode, 2);
    EXPECT_NE(r.err.find("no channel 'shadow' (it has R, G, B)"), std::string::npos) << r.err;
    EXPECT_FALSE(fs::exists(dir.path() / "d.png"));
}

TEST(AppGates, RunHoldsEveryMethodToTheBudgetsAndRecordsThem) {
    TempDir dir;
    const auto out = dir.path() / "run";
    const auto r = runShadowlab({"run", "seed", "-o", out.string(), "--resolution", "96x54", "--no-sweep", "--ray-bias",
                                 "0", "--max-false-shadow", "1%"});
    EXPECT_EQ(r.exitCode, 3) << r.err;
    EXPECT_NE(r.err.find("budget: raytrace: --max-false-shadow: "), std::string::npos) << r.err;
    const auto metrics = nlohmann::json::parse(slurpFile(out / "metrics.json"));
    EXPECT_EQ(metrics["methods"]["raytrace"]["budgets"][0]["broken"], true);
    EXPECT_TRUE(fs::exists(out / "report.html"));  // a broken budget still writes everything
}

TEST(AppGates, ASceneCarriesItsBudgetsAndTheCommandLineOverridesThem) {
    TempDir dir;
    const std::string seed = slurpFile(fs::path(SHADOWLAB_SOURCE_DIR) / "scenes" / "seed.json");
    const auto withBudgets = [&](const std::string& block) {
        const auto at = seed.rfind('}');
        return dir.write("s.json", seed.substr(0, at) + ", \"budgets\": " + block + "}");
    };
    const auto scene = withBudgets(R"({"max_false_shadow": "1%"})");
    const auto out = dir.path() / "run";
    auto r = runShadowlab({"run", scene.string(), "-o", out.string(), "--resolution", "96x54", "--no-sweep",
                           "--no-raster", "--ray-bias", "0"});
    EXPECT_EQ(r.exitCode, 3) << r.err;
    EXPECT_NE(r.err.find("--max-false-shadow: "), std::string::npos) << r.err;
    r = runShadowlab({"run", scene.string(), "-o", out.string(), "--resolution", "96x54", "--no-sweep", "--no-raster",
                      "--ray-bias", "0", "--max-false-shadow", "50%"});
    EXPECT_EQ(r.exitCode, 0) << r.err;
    const auto bad = withBudgets(R"({"max_mismatch": "lots"})");
    const auto badOut = dir.path() / "bad";
    r = runShadowlab({"run", bad.string(), "-o", badOut.string(), "--no-sweep"});
    EXPECT_EQ(r.exitCode, 2);
    EXPECT_NE(r.err.find("s.json: budgets.max_mismatch: expected a rate in 0..1"), std::string::npos) << r.err;
    EXPECT_FALSE(fs::exists(badOut));
}

// ---- check ----

struct Suite {
    TempDir dir;
    fs::path write(const std::string& json) const { return dir.write("suite.json", json); }
    fs::path out() const { return dir.path() / "out"; }
};

TEST(Check, TheShippedSuitePassesAgainstItsBaselineAndWritesJUnitAndMarkdown) {
    TempDir dir;
    const fs::path suite = fs::path(SHADOWLAB_SOURCE_DIR) / "suites" / "shipped.json";
    const auto cases = nlohmann::json::parse(slurpFile(suite))["cases"];
    const auto r = runShadowlab({"check", suite.string(), "-o", (dir.path() / "out").string()});
    ASSERT_EQ(r.exitCode, 0) << r.err;
    EXPECT_NE(r.err.find("[1/" + std::to_string(cases.size()) + "]"), std::string::npos);  // progress
    const std::string xml = slurpFile(dir.path() / "out" / "junit.xml");
    EXPECT_EQ(xml.rfind("<?xml version=\"1.0\" encoding=\"UTF-8\"?>\n<testsuites ", 0), 0u) << xml.substr(0, 200);
    EXPECT_EQ(occurrences(xml, "<testsuite "), 1u);
    EXPECT_EQ(occurrences(xml, "<testcase "), cases.size());
    EXPECT_EQ(occurrences(xml, "<failure"), 0u);
    EXPECT_EQ(occurrences(xml, "<error"), 0u);
    const std::string md = slurpFile(dir.path() / "out" / "summary.md");
    EXPECT_NE(md.find("All " + std::to_string(cases.size()) + " cases passed."), std::string::npos) << md;
    for (const auto& c : cases) {
        const std::string name = c["name"];
        EXPECT_TRUE(fs::exists(dir.path() / "out" / "cases" / (name + ".json"))) << name;
        EXPECT_FALSE(fs::exists(dir.path() / "out" / "cases" / (name + "-diff.png"))) << name;  // passing
        EXPECT_NE(md.find("| " + name + " |"), std::string::npos) << name;
        const auto j = nlohmann::json::parse(slurpFile(dir.path() / "out" / "cases" / (name + ".json")));
        EXPECT_EQ(j["has_baseline"], true) << name;
    }
}

TEST(Check, FailingCasesFailErroringCasesAreErrorsAndTheOthersGoOn) {
    Suite s;
    // seed without ray bias: ~5% acne (the README's lesson), over its 1% budget; a raster case on
    // a device that does not exist cannot render; the robust ray tracer passes a 0 px budget.
    const auto file = s.write(R"({"resolution": "96x54", "cases": [
        {"name": "acne", "scene": "seed", "backend": "raytrace", "settings": {"ray_bias": 0},
         "budgets": {"max_false_shadow": "1%"}},
        {"name": "no-device", "scene": "seed", "backend": "raster", "device": "no-such-vulkan-device"},
        {"name": "robust", "scene": "seed", "backend": "raytrace", "settings": {"ray_bias": "robust"},
         "budgets": {"max_mismatch": "0px"}}]})");
    const auto r = runShadowlab({"check", file.string(), "-o", s.out().string()});
    EXPECT_EQ(r.exitCode, 1) << r.err;  // an error outranks a failure
    const std::string xml = slurpFile(s.out() / "junit.xml");
    EXPECT_NE(xml.find("tests=\"3\" failures=\"1\" errors=\"1\""), std::string::npos) << xml;
    EXPECT_NE(xml.find("<failure message=\"budget --max-false-shadow: "), std::string::npos) << xml;
    EXPECT_EQ(occurrences(xml, "<error message="), 1u);
    EXPECT_TRUE(fs::exists(s.out() / "cases" / "acne-diff.png"));
    EXPECT_FALSE(fs::exists(s.out() / "cases" / "robust-diff.png"));
    EXPECT_FALSE(fs::exists(s.out() / "cases" / "no-device-diff.png"));
    EXPECT_EQ(nlohmann::json::parse(slurpFile(s.out() / "cases" / "robust.json"))["verdict"], "passed");
    EXPECT_EQ(nlohmann::json::parse(slurpFile(s.out() / "cases" / "no-device.json"))["verdict"], "error");
    const std::string md = slurpFile(s.out() / "summary.md");
    EXPECT_NE(md.find("1 passed, 1 failed, 1 errors."), std::string::npos) << md;

    // Without the error: a failure alone exits 3.
    const auto two = s.write(R"({"resolution": "96x54", "cases": [
        {"name": "acne", "scene": "seed", "backend": "raytrace", "settings": {"ray_bias": 0},
         "budgets": {"max_false_shadow": "1%"}}]})");
    EXPECT_EQ(runShadowlab({"check", two.string(), "-o", s.out().string()}).exitCode, 3);
    // The output folder is replaced as a whole: the earlier run's files are gone.
    EXPECT_FALSE(fs::exists(s.out() / "cases" / "robust.json"));
}

TEST(Check, BaselineUpdateThenSameVerdictsThenARegressionFails) {
    Suite s;
    const auto file = s.write(R"({"resolution": "96x54", "baseline": "base.json", "cases": [
        {"name": "acne", "scene": "seed", "backend": "raytrace", "settings": {"ray_bias": 0}},
        {"name": "raster", "scene": "seed", "backend": "raster"}]})");
    ASSERT_EQ(runShadowlab({"check", file.string(), "-o", s.out().string()}).exitCode, 2);  // no baseline yet
    const auto up = runShadowlab({"check", file.string(), "-o", s.out().string(), "--update-baseline"});
    ASSERT_EQ(up.exitCode, 0) << up.err;
    const auto base = nlohmann::json::parse(slurpFile(s.dir.path() / "base.json"));
    EXPECT_EQ(base["shadowlab_check_baseline"], 1);
    const double acneRate = base["cases"]["acne"]["false_shadow_rate"];
    EXPECT_GT(acneRate, 0.01);
    // Twice more: the same metrics, so every case is within the tolerance, every time.
    for (int run = 0; run < 2; ++run) {
        const auto again = runShadowlab({"check", file.string(), "-o", s.out().string()});
        ASSERT_EQ(again.exitCode, 0) << again.err;
        const auto j = nlohmann::json::parse(slurpFile(s.out() / "cases" / "acne.json"));
        EXPECT_EQ(j["metrics"]["false_shadow_rate"], acneRate);
    }
    // A baseline that says the acne case had no false shadows: its rate is a regression.
    auto edited = base;
    edited["cases"]["acne"]["false_shadow_rate"] = 0.0;
    edited["cases"]["acne"]["mismatch_rate"] = 0.0;
    s.dir.write("base.json", edited.dump());
    const auto reg = runShadowlab({"check", file.string(), "-o", s.out().string()});
    EXPECT_EQ(reg.exitCode, 3) << reg.err;
    const std::string xml = slurpFile(s.out() / "junit.xml");
    EXPECT_NE(xml.find("type=\"regression\""), std::string::npos) << xml;
    EXPECT_NE(xml.find("regression: false_shadow_rate "), std::string::npos) << xml;
    EXPECT_TRUE(fs::exists(s.out() / "cases" / "acne-diff.png"));
    EXPECT_FALSE(fs::exists(s.out() / "cases" / "raster-diff.png"));
}

TEST(Check, ABaselineGivenOnTheCommandLineAndAnImprovementPasses) {
    Suite s;
    const auto file = s.write(R"({"resolution": "96x54", "cases": [
        {"name": "robust", "scene": "seed", "backend": "raytrace", "settings": {"ray_bias": "robust"}}]})");
    // Robust offsets have no acne on the seed; a baseline that recorded 30% mismatch and an IoU
    // of 0.5 is far worse: better beyond the tolerance, which passes and says so.
    const auto base = s.dir.write("elsewhere.json", R"({"shadowlab_check_baseline": 1, "cases": {"robust":
        {"mismatch_rate": 0.3, "shadow_iou": 0.5}}})");
    const auto r = runShadowlab({"check", file.string(), "-o", s.out().string(), "--baseline", base.string()});
    ASSERT_EQ(r.exitCode, 0) << r.err;
    const auto j = nlohmann::json::parse(slurpFile(s.out() / "cases" / "robust.json"));
    EXPECT_EQ(j["has_baseline"], true);
    ASSERT_EQ(j["baseline_drift"].size(), 2u);  // only the metrics the baseline holds
    for (const auto& d : j["baseline_drift"]) EXPECT_EQ(d["improved"], true) << d;
    EXPECT_NE(slurpFile(s.out() / "summary.md").find("mismatch_rate better, shadow_iou better"), std::string::npos);
}

struct BadSuite {
    const char* name;
    std::string suite;     // written as suite.json
    std::string baseline;  // written as base.json when not empty
    std::string mentions;
};

class CheckBadInput : public ::testing::TestWithParam<BadSuite> {};

TEST_P(CheckBadInput, OneClearErrorExitTwoNothingWritten) {
    TempDir dir;
    const auto file = dir.write("suite.json", GetParam().suite);
    if (!GetParam().baseline.empty()) dir.write("base.json", GetParam().baseline);
    const std::size_t before = dir.fileCount();
    const auto r = runShadowlab({"check", file.string(), "-o", (dir.path() / "out").string()});
    EXPECT_EQ(r.exitCode, 2) << r.err;
    EXPECT_NE(r.err.find(GetParam().mentions), std::string::npos) << r.err;
    EXPECT_EQ(occurrences(r.err, "error:"), 1u) << r.err;
    EXPECT_EQ(dir.fileCount(), before) << "something was written";
}

const char* kCase = R"({"name": "a", "scene": "seed", "backend": "raytrace"})";

INSTANTIATE_TEST_SUITE_P(
    Cases, CheckBadInput,
    ::testing::Values(
        BadSuite{"not_json", "{", "", "suite.json: invalid JSON"},
        BadSuite{"no_cases", "{}", "", "suite.json: cases: is required"},
        BadSuite{"scene_is_a_folder", R"({"cases": [{"name": "a", "scene": ".", "backend": "raytrace"}]})", "",
                 "suite.json: cases[0].scene: .: is a folder, not a file"},
        BadSuite{"unknown_key", std::string(R"({"casez": [], "cases": [)") + kCase + "]}", "",
                 "suite.json: casez: unknown key"},
        BadSuite{"duplicate_name", std::string(R"({"cases": [)") + kCase + "," + kCase + "]}", "",
                 "suite.json: cases[1].name: 'a' names an earlier case too"},
        BadSuite{"bad_name", R"({"cases": [{"name": "a/b", "scene": "seed"}]})", "", "cases[0].name: 'a/b'"},
        BadSuite{"bad_backend", R"({"cases": [{"name": "a", "scene": "seed", "backend": "gpu"}]})", "",
                 "cases[0].backend: expected raster or raytrace"},
        BadSuite{"device_on_raytrace",
                 R"({"cases": [{"name": "a", "scene": "seed", "backend": "raytrace", "device": "llvmpipe"}]})", "",
                 "suite.json: cases[0].device: a Vulkan device applies to a raster case"},
        BadSuite{"no_scene", R"({"cases": [{"name": "a", "scene": "nowhere"}]})", "",
                 "cases[0].scene: nowhere: no such scene file"},
        BadSuite{"bad_budget", R"({"cases": [{"name": "a", "scene": "seed", "budgets": {"max_mismatch": "2 %"}}]})", "",
                 "suite.json: cases[0].budgets.max_mismatch: expected a percentage"},
        BadSuite{"bad_setting", R"({"cases": [{"name": "a", "scene": "seed", "settings": {"filter": "blur"}}]})", "",
                 "suite.json: cases[0].settings.filter: expected none, pcf2x2"},
        BadSuite{"bad_resolution", std::string(R"({"resolution": "big", "cases": [)") + kCase + "]}", "",
                 "suite.json: resolution: expected \"WxH\""},
        BadSuite{"bad_tolerance", std::string(R"({"tolerance": {"rate": -1}, "cases": [)") + kCase + "]}", "",
                 "suite.json: tolerance.rate: expected a number >= 0"},
        BadSuite{"missing_baseline", std::string(R"({"baseline": "none.json", "cases": [)") + kCase + "]}", "",
                 "none.json: no such baseline (write one with --update-baseline)"},
        BadSuite{"bad_baseline_metric", std::string(R"({"baseline": "base.json", "cases": [)") + kCase + "]}",
                 R"({"shadowlab_check_baseline": 1, "cases": {"a": {"mismatch_rate": "low"}}})",
                 "base.json: cases.a.mismatch_rate: expected a number in 0..1"},
        BadSuite{"bad_baseline_version", std::string(R"({"baseline": "base.json", "cases": [)") + kCase + "]}",
                 R"({"shadowlab_check_baseline": 7, "cases": {}})", "base.json: shadowlab_check_baseline: expected 1"}),
    [](const ::testing::TestParamInfo<BadSuite>& testParam) { return std::string(testParam.param.name); });

}  // namespace
}  // namespace shadowlab
