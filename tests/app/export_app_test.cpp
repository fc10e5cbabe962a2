// tests/app/export_app_test.cpp: `shadowlab export`: bad input is one clear error with exit 2 and
// nothing written; an export loaded back as the scene keeps its camera, image size and lights and
// renders the reference's shadows within what the tessellation allows.
#include <algorithm>
#include <fstream>

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include "scene/gltf_export.h"
#include "scene/loader.h"
#include "tests/app/cli.h"

namespace shadowlab {
namespace {

namespace fs = std::filesystem;
using test::runShadowlab;
using test::TempDir;

TEST(ExportApp, AnUnknownExtensionIsBadInputAndWritesNothing) {
    TempDir dir;
    const auto r = runShadowlab({"export", "seed", "-o", (dir.path() / "seed.obj").string()});
    EXPECT_EQ(r.exitCode, 2) << r.err;
    EXPECT_NE(r.err.find("unknown export type '.obj'"), std::string::npos) << r.err;
    EXPECT_TRUE(fs::is_empty(dir.path()));
}

TEST(ExportApp, AnOutputUnderAFileIsBadInputAndWritesNothing) {
    TempDir dir;
    std::ofstream(dir.path() / "file") << "x";
    const auto r = runShadowlab({"export", "seed", "-o", (dir.path() / "file" / "seed.glb").string()});
    EXPECT_EQ(r.exitCode, 2) << r.err;
    EXPECT_NE(r.err.find("is a file, not a folder"), std::string::npos) << r.err;
}

TEST(ExportApp, ABadSceneNamesFileAndPathAndWritesNothing) {
    TempDir dir;
    std::ofstream(dir.path() / "bad.json")
        << R"({"camera": {"position": [0, 2, 6], "look_at": [0, 0, 0]}, "materials": {"m": {}},
              "lights": [{"type": "directional", "direction": [0, -1, 0]}],
              "objects": [{"type": "sphere", "center": [0, 1, 0], "radius": -1, "material": "m"}]})";
    const auto r = runShadowlab({"export", (dir.path() / "bad.json").string(), "-o", (dir.path() / "x.glb").string()});
    EXPECT_EQ(r.exitCode, 2) << r.err;
    EXPECT_NE(r.err.find("objects[0].radius"), std::string::npos) << r.err;
    EXPECT_FALSE(fs::exists(dir.path() / "x.glb"));
    // Out of range, and finer than any view resolves (it would grow without bound): refused at once.
    for (const char* tol : {"0", "0.5", "1e-300", "9e-6"}) {
        const auto t = runShadowlab({"export", "seed", "--tolerance", tol, "-o", (dir.path() / "y.glb").string()});
        EXPECT_EQ(t.exitCode, 2) << tol << ": " << t.err;
        EXPECT_NE(t.err.find("--tolerance: must be in [1e-05, 0.5)"), std::string::npos) << t.err;
        EXPECT_FALSE(fs::exists(dir.path() / "y.glb"));
    }
}

TEST(ExportApp, UvSphereSagittaMatchesTheChordFormulaAtTheEquator) {
    // With 4 rings the equator is a ring of vertices; its cells' flat middles are the deepest
    // points. A cell spanning Δφ = 2π/s and Δθ = π/4 whose vertices lie on the unit sphere: the
    // sagitta is at least the single-chord value 1 − cos(Δφ/2) and below the cell's corner
    // distance bound 1 − cos(half the cell's diagonal angle).
    const double pi = 3.14159265358979323846;
    const double s = scene::uvSphereSagitta(64, 4);
    EXPECT_GE(s, 1.0 - std::cos(pi / 64));
    EXPECT_LE(s, 1.0 - std::cos(0.5 * std::hypot(2 * pi / 64, pi / 4)));
}

TEST(ExportApp, AnExportLoadsBackWithTheSceneCameraSizeAndLights) {
    TempDir dir;
    // A spot that falls off from 12° to its 30° cone: its inner angle goes out as innerConeAngle.
    const std::string soft = dir.write("soft-spot.json", R"({"camera": {"position": [0, 2, 6], "look_at": [0, 0.5, 0]},
            "lights": [{"type": "spot", "position": [1, 5, 1], "direction": [-1, -5, -1], "cone_angle": 30,
                        "inner_cone_angle": 12, "intensity": 500}],
            "materials": {"m": {}},
            "objects": [{"type": "sphere", "center": [0, 1, 0], "radius": 1, "material": "m"},
                        {"type": "quad", "center": [0, 0, 0], "normal": [0, 1, 0], "size": [8, 8], "material": "m"}]})")
                                 .string();
    for (const std::string& name :
         {std::string("seed"), std::string("lesson/spot-light"), std::string("lesson/spherical-light"), soft}) {
        const fs::path out = dir.path() / (fs::path(name).stem().string() + ".glb");
        const auto r = runShadowlab({"export", name, "-o", out.string()});
        ASSERT_EQ(r.exitCode, 0) << r.err;
        const scene::Scene a = scene::loadScene(scene::findScene(name));
        const scene::Scene b = scene::loadScene(out);
        EXPECT_EQ(b.camera.width, a.camera.width) << name;
        EXPECT_EQ(b.camera.height, a.camera.height) << name;
        EXPECT_NEAR(b.camera.fovYDegrees, a.camera.fovYDegrees, 1e-9) << name;
        EXPECT_NEAR(glm::length(b.camera.position - a.camera.position), 0.0, 1e-9) << name;
        const scene::Vec3 fa = glm::normalize(a.camera.lookAt - a.camera.position);
        const scene::Vec3 fb = glm::normalize(b.camera.lookAt - b.camera.position);
        EXPECT_NEAR(glm::length(fa - fb), 0.0, 1e-9) << name;
        EXPECT_EQ(b.objects.size(), a.objects.size()) << name;  // one glTF material per object
        ASSERT_EQ(b.lights.size(), a.lights.size()) << name;
        for (std::size_t i = 0; i < a.lights.size(); ++i) {
            EXPECT_EQ(int(b.lights[i].type), int(a.lights[i].type)) << name;
            EXPECT_NEAR(b.lights[i].intensity, a.lights[i].intensity, 1e-9 * a.lights[i].intensity) << name;
            EXPECT_NEAR(b.lights[i].coneAngleDegrees, a.lights[i].coneAngleDegrees, 1e-9) << name;
            if (a.lights[i].type == scene::LightType::Spot) {  // a hard cone comes back hard, and the same
                EXPECT_NEAR(b.lights[i].innerConeAngleDegrees, a.lights[i].innerConeAngleDegrees, 1e-9) << name;
            }
            EXPECT_NEAR(b.lights[i].radius, a.lights[i].radius, 1e-12) << name;
            if (a.lights[i].type != scene::LightType::Point) {
                EXPECT_NEAR(glm::length(b.lights[i].direction - a.lights[i].direction), 0.0, 1e-9) << name;
            }
            if (a.lights[i].type != scene::LightType::Directional) {
                EXPECT_NEAR(glm::length(b.lights[i].position - a.lights[i].position), 0.0, 1e-9) << name;
            }
        }
    }
}

TEST(ExportApp, AnAlphaTextureThatIsNoFileIsEmbeddedAsThePngOfItsAlpha) {
    // The foliage's leaf as if it had come from inside a glTF (a name, not a file): the export
    // embeds the decoded alpha as a PNG, which loads back texel for texel (to 1/255).
    scene::Scene s = scene::loadScene(scene::findScene("foliage"));
    const scene::AlphaTexture* original = nullptr;
    for (scene::Material& m : s.materials)
        if (m.alphaTexture) {
            auto inside = std::make_shared<scene::AlphaTexture>(*m.alphaTexture);
            inside->file = "model.gltf#images[0]";
            m.alphaTexture = inside;
            original = inside.get();
        }
    ASSERT_TRUE(original);
    TempDir dir;
    const fs::path out = dir.path() / "leaf.glb";
    scene::exportGltf(s, out);
    const scene::Scene back = scene::loadScene(out);
    int textured = 0;
    for (const scene::Material& m : back.materials) {
        if (!m.alphaTexture) continue;
        ++textured;
        EXPECT_EQ(m.alphaMode, scene::AlphaMode::Mask);
        ASSERT_EQ(m.alphaTexture->width, original->width);
        ASSERT_EQ(m.alphaTexture->height, original->height);
        for (std::size_t i = 0; i < original->alpha.size(); ++i)
            ASSERT_NEAR(m.alphaTexture->alpha[i], original->alpha[i], 0.5 / 255.0 + 1e-6) << "texel " << i;
    }
    EXPECT_GT(textured, 0);
}

TEST(ExportApp, TheReferenceOfAnExportAgreesWithTheSceneWithinTheTessellation) {
    // The seed: sphere r = 1 on a plane; at 320x180 the sphere covers about 40 px of radius R. The
    // tessellation (sagitta ≤ 1e-3 r, vertices on the sphere) changes two things:
    //  - the shadow outline moves by at most the sagitta, 1e-3 r ≈ 0.04 px, so only pixels the
    //    reference's outline passes through may flip: at most its length, under 2π · 3R ≈ 750 px;
    //  - near the terminator a flat facet may shadow its neighbour where the smooth N·L is below
    //    the facet's tilt, about sin(cell diagonal) ≈ 0.1: a band of about 0.1 · πR · R ≈ 500 px.
    // So fewer than 1250 of the counted pixels may differ, and the silhouettes agree except on the
    // sphere's outline (under 2πR ≈ 250 px), again through the 0.04 px sagitta.
    TempDir dir;
    const fs::path glb = dir.path() / "seed.glb", a = dir.path() / "a.exr", b = dir.path() / "b.exr";
    ASSERT_EQ(runShadowlab({"export", "seed", "-o", glb.string()}).exitCode, 0);
    ASSERT_EQ(runShadowlab({"render", "seed", "--backend", "reference", "--resolution", "320x180", "-o", a.string()})
                  .exitCode,
              0);
    ASSERT_EQ(
        runShadowlab({"render", glb.string(), "--backend", "reference", "--resolution", "320x180", "-o", b.string()})
            .exitCode,
        0);
    const auto r = runShadowlab({"compare", b.string(), a.string(), "-o", (dir.path() / "d.png").string(), "--json",
                                 "--allow-different-scene"});
    ASSERT_EQ(r.exitCode, 0) << r.err;
    const auto m = nlohmann::json::parse(r.out);
    EXPECT_LT(m["false_shadow"].get<long>() + m["missed_shadow"].get<long>(), 1250) << r.out;
    EXPECT_GT(m["counted"].get<long>(), 30000) << r.out;
}

// A model with no camera, no light and no floor (the Khronos Box): run and render search a view
// and a sun and add a ground, and the export holds that scene, so that another engine's render
// of it is graded against the same reference. The geometry is the same up to the export's float
// vertices (relative rounding about 6e-8 of the model's size, far under a pixel's 1/50), so no
// pixel's verdict may change; the box and ground together give the one extra object and a light.
TEST(ExportApp, AModelsExportHoldsTheViewSunAndGroundThatRunRenders) {
    TempDir dir;
    const std::string model = (scene::scenesDirectory() / "models" / "Box" / "Box.gltf").string();
    const fs::path glb = dir.path() / "box.glb", a = dir.path() / "a.exr", b = dir.path() / "b.exr";
    const auto e = runShadowlab({"export", model, "--resolution", "96x54", "-o", glb.string()});
    ASSERT_EQ(e.exitCode, 0) << e.err;
    const scene::Scene exported = scene::loadScene(glb);
    EXPECT_EQ(exported.objects.size(), 2u);  // the box and the added ground
    EXPECT_EQ(exported.camera.width, 96);
    ASSERT_EQ(exported.lights.size(), 1u);
    ASSERT_EQ(
        runShadowlab({"render", model, "--backend", "reference", "--resolution", "96x54", "-o", a.string()}).exitCode,
        0);
    ASSERT_EQ(runShadowlab({"render", glb.string(), "--backend", "reference", "-o", b.string()}).exitCode, 0);
    const auto r = runShadowlab({"compare", b.string(), a.string(), "-o", (dir.path() / "d.png").string(), "--json",
                                 "--allow-different-scene"});
    ASSERT_EQ(r.exitCode, 0) << r.err;
    const auto m = nlohmann::json::parse(r.out);
    EXPECT_EQ(m["false_shadow"].get<long>() + m["missed_shadow"].get<long>(), 0) << r.out;
    EXPECT_GT(m["counted"].get<long>(), 96 * 54 / 4) << r.out;
    EXPECT_GT(m["shadowed_reference"].get<long>(), 20) << r.out;  // a view where a shadow shows
}

}  // namespace
}  // namespace shadowlab
