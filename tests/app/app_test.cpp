// tests/app/app_test.cpp: runs the `shadowlab` program as a user would: the main job on the
// seed scene writes every output with sane metrics; bad input gets one clear error, a non-zero
// exit and writes nothing.
#include <sys/wait.h>
#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <fstream>
#include <sstream>

#include <OpenImageIO/imageio.h>
#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include "scene/frame_io.h"
#include "tests/app/cli.h"
#include "tests/scene/test_files.h"

namespace shadowlab {
namespace {

using test::TempDir;

using Result = test::CliResult;
using test::slurpFile;

std::string slurp(const std::filesystem::path& p) { return slurpFile(p); }
Result shadowlab(const std::vector<std::string>& args) { return test::runShadowlab(args); }

// Width and height from a PNG's IHDR chunk (big-endian at bytes 16..23).
std::pair<int, int> pngSize(const std::filesystem::path& file) {
    const std::string bytes = slurp(file);
    if (bytes.size() < 24 || bytes.compare(1, 3, "PNG") != 0) return {-1, -1};
    auto be32 = [&](std::size_t at) {
        return (int((unsigned char)bytes[at]) << 24) | (int((unsigned char)bytes[at + 1]) << 16) |
               (int((unsigned char)bytes[at + 2]) << 8) | int((unsigned char)bytes[at + 3]);
    };
    return {be32(16), be32(20)};
}

TEST(App, RunOnTheSeedSceneWritesEveryOutputWithSaneMetrics) {
    TempDir dir;
    const auto out = dir.path() / "seed";
    const Result r = shadowlab(
        {"run", "seed", "-o", out.string(), "--resolution", "192x108", "--shadow-map-size", "1024", "--validate"});
    ASSERT_EQ(r.exitCode, 0) << r.err;
    for (const char* f : {"raster.exr", "raytrace.exr", "reference.exr", "raster.png", "raytrace.png", "reference.png",
                          "diff-raster.png", "diff-raytrace.png", "metrics.json", "report.html"})
        EXPECT_TRUE(std::filesystem::is_regular_file(out / f)) << f;

    const auto metrics = nlohmann::json::parse(slurp(out / "metrics.json"));
    for (const char* method : {"raster", "raytrace"}) {
        SCOPED_TRACE(method);
        const auto& m = metrics.at("methods").at(method).at("metrics");
        // The seed scene is mostly lit plane and sphere: most pixels count, and a method at its
        // default settings agrees with the reference almost everywhere.
        EXPECT_GT(m.at("counted").get<double>(), 0.5 * 192 * 108);
        EXPECT_LT(m.at("mismatch_rate").get<double>(), 0.05);
        EXPECT_GT(m.at("shadow_iou").get<double>(), 0.8);
        EXPECT_GT(metrics.at("methods").at(method).at("timings_ms").at("total").get<double>(), 0.0);
    }
    const std::string html = slurp(out / "report.html");
    for (const char* f : {"reference.png", "diff-raster.png", "diff-raytrace.png"})
        EXPECT_NE(html.find(f), std::string::npos) << f;
    // The raster backend's debug views, in the report: one 1024² map shown as a 512² tile, the
    // others at the image's size; no cascades view without cascades.
    const std::vector<std::pair<std::string, std::pair<int, int>>> views = {{"raster-shadow-map.png", {512, 512}},
                                                                            {"raster-light-frustum.png", {192, 108}},
                                                                            {"raster-texel-density.png", {192, 108}}};
    for (const auto& [file, size] : views) {
        EXPECT_EQ(pngSize(out / file), size) << file;
        EXPECT_NE(html.find("src=\"" + file + "\""), std::string::npos) << file;
    }
    EXPECT_FALSE(std::filesystem::exists(out / "raster-cascades.png"));
    EXPECT_NE(html.find("Inside the shadow maps"), std::string::npos);
    // The continuous error: a heat map per method, and its numbers in metrics.json.
    for (const char* method : {"raster", "raytrace"}) {
        EXPECT_EQ(pngSize(out / (std::string("heat-") + method + ".png")), std::make_pair(192, 108)) << method;
        EXPECT_NE(html.find(std::string("src=\"heat-") + method + ".png\""), std::string::npos) << method;
        const auto& m = metrics.at("methods").at(method).at("metrics");
        for (const char* key : {"mean_abs_visibility_error_penumbra", "penumbra_pixels", "soft_error_pixels"})
            EXPECT_TRUE(m.contains(key)) << key;
    }
    // The recommendation was checked against this run's own defaults and never loses to them.
    const auto rec = nlohmann::json::parse(slurp(out / "sweep" / "recommended-shadow.json"));
    ASSERT_TRUE(rec.at("shadow").is_object());
    const auto& measured = rec.at("measured").at("raster");
    const double defaults = metrics.at("methods").at("raster").at("metrics").at("mismatch_rate").get<double>();
    EXPECT_DOUBLE_EQ(measured.at("defaults").at("mismatch_rate").get<double>(), defaults);
    EXPECT_LE(measured.at("recommended").at("mismatch_rate").get<double>(), defaults);
    EXPECT_EQ(rec.at("shadow").at("shadow_map_size"), 1024);  // the user's own setting is kept
    EXPECT_EQ(metrics.at("sweep").at("recommended"), rec);
#ifndef __SANITIZE_ADDRESS__  // AddressSanitizer's shadow memory and quarantine are not in the estimate
    // The sweep's and the search's renderers keep the heap they free for the next one only while a
    // whole renderer still fits beside it within the estimate.
    EXPECT_LE(metrics.at("memory").at("peak_mib").get<double>(), metrics.at("memory").at("estimate_mib").get<double>());
#endif
}

TEST(App, RunWarnsWhenALightWithARadiusGetsAHardFilter) {
    TempDir dir;
    const auto out = dir.path() / "soft";
    const Result r = shadowlab({"run", "lesson/spherical-light", "-o", out.string(), "--resolution", "64x36",
                                "--no-sweep", "--filter", "pcf2x2"});
    ASSERT_EQ(r.exitCode, 0) << r.err;
    EXPECT_NE(r.err.find("warning: light 0 has a radius"), std::string::npos) << r.err;
    EXPECT_NE(slurp(out / "report.html").find("light 0 has a radius"), std::string::npos);
    const Result pcss = shadowlab({"run", "lesson/spherical-light", "-o", (dir.path() / "pcss").string(),
                                   "--resolution", "64x36", "--no-sweep", "--filter", "pcss"});
    ASSERT_EQ(pcss.exitCode, 0) << pcss.err;
    EXPECT_EQ(pcss.err.find("warning: light"), std::string::npos) << pcss.err;
}

// Two slips a new scene file makes: the camera turned away from everything, and a sun given as
// the way to the light rather than the way the light travels. Each renders (the scene is valid)
// and each gets a note naming what is wrong.
TEST(App, ACameraThatSeesNothingAndASunBelowTheHorizonGetANote) {
    TempDir dir;
    const std::string rest = R"("materials": {"m": {}},
        "objects": [{"type": "sphere", "center": [0, 1, 0], "radius": 1, "material": "m"},
                    {"type": "quad", "center": [0, 0, 0], "normal": [0, 1, 0], "size": [20, 20], "material": "m"}]})";
    // The notes a scene with this look-at and light direction gets from `render`.
    const auto notes = [&](const std::string& name, const std::string& lookAt, const std::string& direction) {
        const auto file = dir.write(name + ".json", R"({"camera": {"position": [0, 2, 6], "look_at": )" + lookAt +
                                                        R"(}, "lights": [{"type": "directional", "direction": )" +
                                                        direction + "}], " + rest);
        const Result r = shadowlab({"render", file.string(), "--backend", "raytrace", "--resolution", "32x18", "-o",
                                    (dir.path() / (name + ".png")).string()});
        EXPECT_EQ(r.exitCode, 0) << r.err;
        return r.err;
    };
    const std::string away = notes("away", "[0, 2, 20]", "[-1, -2, -1]");
    EXPECT_NE(away.find("frames none of the objects"), std::string::npos) << away;
    EXPECT_EQ(away.find("points up"), std::string::npos) << away;
    const std::string below = notes("below", "[0, 0.7, 0]", "[1, 2, 1]");
    EXPECT_NE(below.find("lights[0].direction [1,2,1] points up"), std::string::npos) << below;
    EXPECT_EQ(below.find("frames none"), std::string::npos) << below;
}

TEST(App, RenderWritesTheRequestedFrame) {
    TempDir dir;
    const auto exr = dir.path() / "rt.exr";
    const Result r =
        shadowlab({"render", "seed", "--backend", "raytrace", "--resolution", "32x18", "-o", exr.string()});
    ASSERT_EQ(r.exitCode, 0) << r.err;
    EXPECT_TRUE(std::filesystem::is_regular_file(exr));
    const Result c =
        shadowlab({"compare", exr.string(), exr.string(), "-o", (dir.path() / "d.png").string(), "--json"});
    ASSERT_EQ(c.exitCode, 0) << c.err;
    const auto j = nlohmann::json::parse(c.out);
    EXPECT_EQ(j.at("false_shadow").get<double>(), 0.0);  // a frame agrees with itself
    EXPECT_EQ(j.at("missed_shadow").get<double>(), 0.0);
    EXPECT_EQ(j.at("mean_abs_visibility_error_penumbra").get<double>(), 0.0);
    const Result h = shadowlab({"compare", exr.string(), exr.string(), "-o", (dir.path() / "d.png").string(), "--heat",
                                (dir.path() / "h.png").string()});
    ASSERT_EQ(h.exitCode, 0) << h.err;
    EXPECT_EQ(pngSize(dir.path() / "h.png"), std::make_pair(32, 18));
}

// A PNG's 8-bit RGB codes, row by row (empty when it cannot be read).
std::vector<unsigned char> pngCodes(const std::filesystem::path& file) {
    auto in = OIIO::ImageInput::open(file.string());
    if (!in || in->spec().nchannels < 3) return {};
    const OIIO::ImageSpec spec = in->spec();
    std::vector<unsigned char> codes(std::size_t(spec.width) * spec.height * 3);
    if (!in->read_image(0, 0, 0, 3, OIIO::TypeDesc::UINT8, codes.data())) return {};
    return codes;
}

// A light forty times the seed's: `render -o x.png` is for looking at, so the PNG is scaled as
// run's report images are (by 1 / the 99th percentile of the scene's luminance) instead of
// clipping every lit pixel to white; the EXR keeps the values. Expected codes are computed here
// from the EXR's beauty and ids.
TEST(App, APngOfABrightSceneIsScaledForDisplay) {
    TempDir dir;
    const auto file = dir.write("bright.json", R"({"camera": {"position": [0, 2, 6], "look_at": [0, 0.7, 0]},
        "lights": [{"type": "directional", "direction": [-1, -2, -1], "intensity": 56}],
        "materials": {"m": {"albedo": [0.8, 0.7, 0.6]}},
        "objects": [{"type": "sphere", "center": [0, 1, 0], "radius": 1, "material": "m"},
                    {"type": "quad", "center": [0, 0, 0], "normal": [0, 1, 0], "size": [20, 20], "material": "m"}]})");
    const auto exr = dir.path() / "bright.exr";
    const Result e =
        shadowlab({"render", file.string(), "--backend", "raytrace", "--resolution", "64x36", "-o", exr.string()});
    ASSERT_EQ(e.exitCode, 0) << e.err;
    const scene::Frame frame = scene::readFrame(exr);
    std::vector<float> luminance;
    for (std::size_t i = 0; i < frame.pixelCount(); ++i)
        if (frame.objectId[i] > 0)
            luminance.push_back(0.2126f * frame.beauty[3 * i] + 0.7152f * frame.beauty[3 * i + 1] +
                                0.0722f * frame.beauty[3 * i + 2]);
    ASSERT_GT(luminance.size(), 1000u);
    std::sort(luminance.begin(), luminance.end());
    const float p99 = luminance[std::size_t(0.99 * double(luminance.size() - 1))];
    ASSERT_GT(p99, 5.0f);  // unscaled, most lit pixels would be white

    const auto png = dir.path() / "bright.png";
    const Result r = shadowlab(
        {"render", file.string(), "--backend", "raytrace", "--resolution", "64x36", "-o", png.string(), "--json"});
    ASSERT_EQ(r.exitCode, 0) << r.err;
    EXPECT_NE(r.err.find("for display"), std::string::npos) << r.err;
    EXPECT_NEAR(nlohmann::json::parse(r.out).at("display_exposure").get<double>(), 1.0 / p99, 1e-6 / p99);
    const std::vector<unsigned char> codes = pngCodes(png);
    ASSERT_EQ(codes.size(), 3 * frame.pixelCount());
    int differ = 0;
    for (std::size_t i = 0; i < codes.size(); ++i)
        differ += std::abs(int(codes[i]) - int(scene::linearToSrgbCode(frame.beauty[i] / p99))) > 1;
    EXPECT_EQ(differ, 0);

    // The raster backend's PNG is scaled alike: about 1% of the scene's pixels reach white, not all.
    const auto rasterPng = dir.path() / "bright-raster.png";
    const Result g = shadowlab({"render", file.string(), "--backend", "raster", "--resolution", "64x36", "--validate",
                                "-o", rasterPng.string()});
    ASSERT_EQ(g.exitCode, 0) << g.err;
    const std::vector<unsigned char> rasterCodes = pngCodes(rasterPng);
    ASSERT_EQ(rasterCodes.size(), 3 * frame.pixelCount());
    int white = 0, scene = 0;
    for (std::size_t i = 0; i < frame.pixelCount(); ++i)
        if (frame.objectId[i] > 0) {
            ++scene;
            white += rasterCodes[3 * i] == 255 && rasterCodes[3 * i + 1] == 255 && rasterCodes[3 * i + 2] == 255;
        }
    EXPECT_LT(white, scene / 20) << white << " of " << scene;
}

TEST(App, MemoryIsEstimatedBeforeRenderingAndBoundsThePeak) {
    TempDir dir;
    // The estimate is an upper bound of the measured peak (both reported with --json).
    const Result ok = shadowlab({"render", "seed", "--backend", "raytrace", "--resolution", "960x540", "-o",
                                 (dir.path() / "ok.exr").string(), "--json"});
    ASSERT_EQ(ok.exitCode, 0) << ok.err;
    const auto memory = nlohmann::json::parse(ok.out).at("memory");
    EXPECT_GT(memory.at("peak_mib").get<double>(), 0.0);
#ifndef __SANITIZE_ADDRESS__  // AddressSanitizer's shadow memory and quarantine are not in the estimate
    EXPECT_LE(memory.at("peak_mib").get<double>(), memory.at("estimate_mib").get<double>());
#endif

    // A job larger than the memory the machine offers is refused before anything is written.
    ::setenv("SHADOWLAB_MEMORY_LIMIT_MB", "200", 1);
    const std::size_t before = dir.fileCount();
    for (const std::vector<std::string>& args :
         {std::vector<std::string>{"render", "seed", "--backend", "raytrace", "--resolution", "1920x1080", "-o",
                                   (dir.path() / "out" / "big.exr").string()},
          std::vector<std::string>{"run", "seed", "--resolution", "1920x1080", "-o", (dir.path() / "out").string()}}) {
        const Result r = shadowlab(args);
        EXPECT_EQ(r.exitCode, 2) << r.err;
        EXPECT_NE(r.err.find("needs about"), std::string::npos) << r.err;
        EXPECT_NE(r.err.find("only 200 MiB are available (SHADOWLAB_MEMORY_LIMIT_MB)"), std::string::npos) << r.err;
    }
    EXPECT_EQ(dir.fileCount(), before) << "something was written";
    ::setenv("SHADOWLAB_MEMORY_LIMIT_MB", "lots", 1);
    const Result bad = shadowlab({"render", "seed", "--resolution", "16x9", "-o", (dir.path() / "x.exr").string()});
    EXPECT_EQ(bad.exitCode, 2);
    EXPECT_NE(bad.err.find("SHADOWLAB_MEMORY_LIMIT_MB: expected a positive whole number"), std::string::npos)
        << bad.err;
    ::unsetenv("SHADOWLAB_MEMORY_LIMIT_MB");
}

struct BadRun {
    const char* name;
    std::vector<std::string> args;  // "OUT" ("OUTPNG") is replaced by a .exr (.png) path in a fresh folder
    std::string mentions;
};

class BadInput : public ::testing::TestWithParam<BadRun> {};

TEST_P(BadInput, OneClearErrorNonZeroExitNothingWritten) {
    TempDir dir;
    const auto scene = dir.write("bad.json", R"({"camera": {"position": [0,2,6], "look_at": [0,0,0]},
        "materials": {"m": {}}, "lights": [{"type": "directional", "direction": [0,0,0]}],
        "objects": [{"type": "sphere", "center": [0,1,0], "radius": 1, "material": "m"}]})");
    std::vector<std::string> args;  // OUTDIRPARENT: the test's folder; UNDERBAD: a path under the BAD file
    for (const auto& a : GetParam().args)
        args.push_back(a == "OUT"            ? (dir.path() / "out" / "x.exr").string()
                       : a == "OUTPNG"       ? (dir.path() / "out" / "x.png").string()
                       : a == "OUTDIR"       ? (dir.path() / "out").string()
                       : a == "BAD"          ? scene.string()
                       : a == "OUTDIRPARENT" ? dir.path().string()
                       : a == "UNDERBAD"     ? (scene / "d.png").string()
                                             : a);
    const std::size_t before = dir.fileCount();
    const Result r = shadowlab(args);
    EXPECT_NE(r.exitCode, 0);
    EXPECT_NE(r.err.find(GetParam().mentions), std::string::npos) << r.err;
    EXPECT_EQ(r.err.find("terminate"), std::string::npos) << r.err;  // no crash, no abort
    EXPECT_EQ(dir.fileCount(), before) << "something was written";
}

INSTANTIATE_TEST_SUITE_P(
    Cases, BadInput,
    ::testing::Values(
        BadRun{"bad_scene_run", {"run", "BAD", "-o", "OUTDIR"}, "lights[0].direction: must be a non-zero direction"},
        BadRun{"bad_scene_render", {"render", "BAD", "-o", "OUT"}, "lights[0].direction"},
        BadRun{"unknown_scene", {"run", "no-such-scene", "-o", "OUTDIR"}, "no shipped scene of that name"},
        BadRun{"zero_resolution", {"run", "seed", "--resolution", "0x10", "-o", "OUTDIR"}, "--resolution"},
        BadRun{"huge_resolution", {"run", "seed", "--resolution", "100000x100000", "-o", "OUTDIR"}, "--resolution"},
        BadRun{"negative_map", {"run", "seed", "--shadow-map-size", "-5", "-o", "OUTDIR"}, "--shadow-map-size"},
        BadRun{"bad_ray_bias", {"run", "seed", "--ray-bias", "lots", "-o", "OUTDIR"}, "--ray-bias"},
        BadRun{"bad_backend", {"render", "seed", "--backend", "magic", "-o", "OUT"}, "--backend"},
        BadRun{"unknown_device_run",
               {"run", "seed", "--resolution", "32x18", "--no-sweep", "--device", "no-such-gpu", "-o", "OUTDIR"},
               "--device 'no-such-gpu' matches no Vulkan device"},
        BadRun{"unknown_device_render",
               {"render", "seed", "--backend", "raster", "--device", "99", "-o", "OUT"},
               "--device '99' matches no"},
        BadRun{"bad_extension", {"render", "seed", "-o", "frame.tiff"}, "unknown output type"},
        BadRun{"view_needs_raster",
               {"render", "seed", "--backend", "raytrace", "--view", "cascades", "-o", "OUTPNG"},
               "needs --backend raster and a .png output"},
        BadRun{"view_needs_png",
               {"render", "seed", "--backend", "raster", "--view", "shadow-map", "-o", "OUT"},
               "needs --backend raster and a .png output"},
        BadRun{"unknown_view",
               {"render", "seed", "--backend", "raster", "--view", "normals", "-o", "OUTPNG"},
               "--view: normals not in {shadow-map,cascades,texel-density,light-frustum}"},
        BadRun{"bad_cascades", {"render", "seed", "--backend", "raster", "--cascades", "9", "-o", "OUT"}, "--cascades"},
        BadRun{"bad_cascade_blend",
               {"render", "seed", "--backend", "raster", "--cascades", "3", "--cascade-blend", "0.7", "-o", "OUT"},
               "--cascade-blend: must be in 0..0.5"},
        BadRun{"missing_frames", {"compare", "a.exr", "b.exr", "-o", "OUT.png"}, "no such file"},
        BadRun{"bad_path_kind", {"path", "seed", "--kind", "spiral", "-o", "OUTDIR"}, "--kind: expected orbit|"},
        BadRun{"path_one_frame", {"path", "seed", "--frames", "1", "-o", "OUTDIR"}, "--frames: must be in 2.."},
        BadRun{"path_no_such_light",
               {"path", "seed", "--kind", "sun-azimuth", "--light", "2", "-o", "OUTDIR"},
               "--light: the scene has 1 light(s)"},
        BadRun{"path_bad_scene", {"path", "BAD", "-o", "OUTDIR"}, "lights[0].direction"},
        BadRun{"path_no_camera_animation",
               {"path", "seed", "--camera-animation", "-o", "OUTDIR"},
               "has no animation that moves a camera"},
        BadRun{"path_bad_shard", {"path", "seed", "--shard", "2/2", "-o", "OUTDIR"}, "--shard"},
        BadRun{"cli_parse_error",
               {"render", "seed", "--shadow-map-size", "1e9", "-o", "OUT"},
               "shadowlab: error: Could not convert"},
        BadRun{"no_subcommand", {"bogus"}, "shadowlab: error: "},
        BadRun{"scene_is_a_folder", {"render", "OUTDIRPARENT", "-o", "OUT"}, ": is a folder, not a file"},
        BadRun{"heat_is_the_diff",
               {"compare", "BAD", "BAD", "-o", "OUTPNG", "--heat", "OUTPNG"},
               "names the same file as -o"},
        BadRun{"compare_under_a_file", {"compare", "BAD", "BAD", "-o", "UNDERBAD"}, "is a file, not a folder"},
        BadRun{"sweep_bad_flicker_kind",
               {"sweep", "seed", "--quick", "--flicker", "spiral", "-o", "OUTDIR"},
               "--kind: expected orbit|"}),
    [](const ::testing::TestParamInfo<BadRun>& testParam) { return std::string(testParam.param.name); });

TEST(App, RenderViewsWriteImagesOfTheDocumentedSizes) {
    TempDir dir;
    // 4 cascades at map 128: 2 x 2 tiles of 128 pixels, 4 apart; the other views: the image size.
    const std::vector<std::pair<std::string, std::pair<int, int>>> views = {{"shadow-map", {2 * 128 + 4, 2 * 128 + 4}},
                                                                            {"cascades", {96, 54}},
                                                                            {"texel-density", {96, 54}},
                                                                            {"light-frustum", {96, 54}}};
    for (const auto& [view, size] : views) {
        const auto out = dir.path() / (view + ".png");
        const Result r =
            shadowlab({"render", "seed", "--backend", "raster", "--view", view, "--cascades", "4", "--shadow-map-size",
                       "128", "--resolution", "96x54", "--validate", "-o", out.string()});
        ASSERT_EQ(r.exitCode, 0) << view << ": " << r.err;
        EXPECT_EQ(pngSize(out), size) << view;
    }
    // --view without --backend: the views are of the shadow maps, so it renders with raster.
    const auto out = dir.path() / "implied.png";
    const Result r = shadowlab(
        {"render", "seed", "--view", "light-frustum", "--resolution", "96x54", "--validate", "-o", out.string()});
    ASSERT_EQ(r.exitCode, 0) << r.err;
    EXPECT_EQ(pngSize(out), std::make_pair(96, 54));
}

// The seed scene under a spot or point light at (0, 8, 0), with a sphere behind the camera that can
// shadow nothing the camera sees (tests/raster/caster_culling_test.cpp derives which maps leave it
// out) and one above the view whose shadow falls into it.
std::string culledScene(const std::string& light, const std::string& far, const std::string& kept) {
    return R"({"camera": {"position": [0, 2, 6], "look_at": [0, 0.7, 0], "up": [0, 1, 0], "fov_y": 40,
                          "resolution": [96, 54], "near": 0.1, "far": 100},
               "materials": {"m": {"albedo": [0.8, 0.8, 0.8]}},
               "lights": [)" +
           light + R"(],
               "objects": [
                 {"type": "sphere", "center": [0, 1, 0], "radius": 1, "material": "m"},
                 {"type": "quad", "center": [0, 0, 0], "normal": [0, 1, 0], "size": [20, 20], "material": "m"},
                 )" +
           far + ",\n" + kept + "]}";
}

TEST(App, ExplainSaysHowManyCastersEachMapLeavesOut) {
    TempDir dir;
    // Spot straight down, cone 60°: the sphere at (0, 1, 12) lies in its cone but can shadow no
    // visible receiver: 1 of 4 objects left out.
    const auto spot = dir.write(
        "spot.json",
        culledScene(
            R"({"type": "spot", "position": [0, 8, 0], "direction": [0, -1, 0], "cone_angle": 60, "intensity": 800})",
            R"({"type": "sphere", "center": [0, 1, 12], "radius": 1, "material": "m"})",
            R"({"type": "sphere", "center": [2, 6, -2], "radius": 0.5, "material": "m"})"));
    Result r = shadowlab({"render", spot.string(), "--backend", "raster", "--explain", "--validate", "-o",
                          (dir.path() / "spot.png").string()});
    ASSERT_EQ(r.exitCode, 0) << r.err;
    EXPECT_NE(r.err.find("raster light 0: 1 of 4 objects left out of the depth pass"), std::string::npos) << r.err;
    // Point light: per face; every receiver lies below the light, so +Y draws none of the 4.
    const auto point = dir.write(
        "point.json", culledScene(R"({"type": "point", "position": [0, 8, 0], "intensity": 800})",
                                  R"({"type": "sphere", "center": [3, 1, 40], "radius": 1, "material": "m"})",
                                  R"({"type": "sphere", "center": [1.5, 6, -1.5], "radius": 0.4, "material": "m"})"));
    r = shadowlab({"render", point.string(), "--backend", "raster", "--explain", "--validate", "-o",
                   (dir.path() / "point.png").string()});
    ASSERT_EQ(r.exitCode, 0) << r.err;
    EXPECT_NE(r.err.find("left out of 6 depth passes (+X "), std::string::npos) << r.err;
    EXPECT_NE(r.err.find("+Y 4 of 4"), std::string::npos) << r.err;
}

TEST(App, ExplainSaysWhereTheBiasIsApplied) {
    TempDir dir;
    const std::string out = (dir.path() / "seed.png").string();
    Result r = shadowlab({"render", "seed", "--backend", "raster", "--explain", "--resolution", "96x54", "--depth-bias",
                          "0.02", "--slope-bias", "1.5", "-o", out});
    ASSERT_EQ(r.exitCode, 0) << r.err;
    EXPECT_NE(r.err.find("raster bias: constant 0.02 world units, slope 1.5 texels x tan(angle to light), in the "
                         "lit shader; past tan 10 (84.3 deg between normal and light) the slope term goes on as a "
                         "lift along the normal"),
              std::string::npos)
        << r.err;
    EXPECT_EQ(r.err.find("normal offset"), std::string::npos) << r.err;  // none given
    r = shadowlab({"render", "seed", "--backend", "raster", "--explain", "--resolution", "96x54", "--hardware-bias",
                   "--normal-offset", "0.5", "-o", out});
    ASSERT_EQ(r.exitCode, 0) << r.err;
    EXPECT_NE(r.err.find("half a texel of each map as fitted or cascaded (the default; each map's value is on its L"),
              std::string::npos)
        << r.err;
    EXPECT_NE(r.err.find("through the rasterizer's depth-bias state"), std::string::npos) << r.err;
    EXPECT_NE(r.err.find("spot and point maps only: the rasterizer's slope term is not capped"), std::string::npos)
        << r.err;
    EXPECT_NE(r.err.find("; normal offset 0.5 texels\n"), std::string::npos) << r.err;
    // Without a slope bias there is nothing to continue past the cap.
    r = shadowlab({"render", "seed", "--backend", "raster", "--explain", "--resolution", "96x54", "--slope-bias", "0",
                   "-o", out});
    ASSERT_EQ(r.exitCode, 0) << r.err;
    EXPECT_EQ(r.err.find("lift along the normal"), std::string::npos) << r.err;
}

TEST(App, ExplainGivesEveryAutomaticRasterChoiceAndEachCanBeForced) {
    TempDir dir;
    const std::string out = (dir.path() / "seed.png").string();
    Result r = shadowlab({"render", "seed", "--backend", "raster", "--explain", "--resolution", "96x54", "-o", out});
    ASSERT_EQ(r.exitCode, 0) << r.err;
    EXPECT_NE(r.err.find("raster light frustum: fitted to what the camera sees"), std::string::npos) << r.err;
    EXPECT_NE(r.err.find("(default; --no-fit-light-frustum for the bounding sphere)"), std::string::npos) << r.err;
    EXPECT_NE(r.err.find("raster cascades: 1 (default: one map keeps its texel within 2 pixels"), std::string::npos)
        << r.err;
    EXPECT_NE(r.err.find("raster shadow-map size: "), std::string::npos) << r.err;
    EXPECT_NE(r.err.find("casters: 4 texels across the smallest feature"), std::string::npos) << r.err;
    for (const char* off : {"--no-fit-light-frustum", "--fit-light-frustum=off"}) {
        r = shadowlab({"render", "seed", "--backend", "raster", "--explain", "--resolution", "96x54", off, "--cascades",
                       "2", "--shadow-map-size", "1024", "-o", out});
        ASSERT_EQ(r.exitCode, 0) << r.err;
        EXPECT_NE(r.err.find("raster light frustum: the scene's bounding sphere (set by"), std::string::npos) << r.err;
        EXPECT_NE(r.err.find("raster cascades: 2 (set by --cascades or the scene)"), std::string::npos) << r.err;
        EXPECT_NE(r.err.find("raster shadow-map size: 1024 (set by"), std::string::npos) << r.err;
    }
    r = shadowlab({"render", "seed", "--backend", "raster", "--fit-light-frustum=maybe", "-o", out});
    EXPECT_EQ(r.exitCode, 2) << r.err;
    EXPECT_NE(r.err.find("--fit-light-frustum: expected on or off, got 'maybe'"), std::string::npos) << r.err;
}

TEST(App, StabilityRunsTheNamedCasesAndWritesItsReport) {
    TempDir dir;
    const auto out = dir.path() / "stability";
    const Result r = shadowlab({"stability", "extreme/straight-down", "extreme/far-1e5", "-o", out.string(),
                                "--resolution", "48x27", "--no-search", "--json"});
    ASSERT_EQ(r.exitCode, 0) << r.err;
    for (const char* f : {"stability.html", "stability.csv", "stability.json"})
        EXPECT_TRUE(std::filesystem::is_regular_file(out / f)) << f;
    EXPECT_EQ(nlohmann::json::parse(r.out).size(), 2u);
    // A bad case name is refused before anything is written.
    const auto bad = dir.path() / "bad";
    EXPECT_EQ(shadowlab({"stability", "extreme/no-such-case", "-o", bad.string()}).exitCode, 2);
    EXPECT_FALSE(std::filesystem::exists(bad));
}

TEST(App, HelpOnEverySubcommandNamesItsOptions) {
    for (const auto& [cmd, option] : std::vector<std::pair<std::string, std::string>>{{"run", "--output"},
                                                                                      {"render", "--backend"},
                                                                                      {"compare", "--json"},
                                                                                      {"info", "--validate"},
                                                                                      {"sweep", "--resume"},
                                                                                      {"stability", "--no-search"}}) {
        const Result r = shadowlab({cmd, "--help"});
        EXPECT_EQ(r.exitCode, 0) << cmd;
        EXPECT_NE(r.out.find(option), std::string::npos) << cmd << ": " << r.out;
    }
}

}  // namespace
}  // namespace shadowlab
