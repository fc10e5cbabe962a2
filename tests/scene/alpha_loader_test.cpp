// tests/scene/alpha_loader_test.cpp: alpha-tested and blended casters as loaded: the JSON
// material keys, the alpha textures (read with OpenImageIO), bad input, and a glTF model given
// as the scene kept per material (AlphaBlendModeTest from ../shared/scenes).
#include <filesystem>
#include <set>

#include <OpenImageIO/imageio.h>
#include <gtest/gtest.h>

#include "scene/loader.h"
#include "scene/memory.h"
#include "tests/scene/gltf_files.h"
#include "tests/scene/test_files.h"

namespace shadowlab::scene {
namespace {

using test::TempDir;

// A 2×2 RGBA PNG whose alpha codes are (0, 255 / 128, 255), row by row from the top.
std::filesystem::path writeAlphaPng(const TempDir& dir, const std::string& name) {
    const std::filesystem::path file = dir.path() / name;
    const unsigned char pixels[16] = {9, 9, 9, 0, 9, 9, 9, 255, 9, 9, 9, 128, 9, 9, 9, 255};
    auto out = OIIO::ImageOutput::create(file.string());
    EXPECT_TRUE(out);
    EXPECT_TRUE(out->open(file.string(), OIIO::ImageSpec(2, 2, 4, OIIO::TypeDesc::UINT8)));
    EXPECT_TRUE(out->write_image(OIIO::TypeDesc::UINT8, pixels));
    out->close();
    return file;
}

std::string sceneWith(const std::string& material, const std::string& object) {
    return R"({"camera": {"position": [0, 5, 5], "look_at": [0, 0, 0]},
               "materials": {"ground": {}, "leaf": )" +
           material + R"(},
               "lights": [{"type": "directional", "direction": [0, -1, 0]}],
               "objects": [{"type": "quad", "center": [0, 0, 0], "normal": [0, 1, 0], "size": [4, 4], "material": "ground"},
                           )" +
           object + "]}";
}

const std::string kLeafQuad =
    R"({"type": "quad", "center": [0, 1, 0], "normal": [0, 1, 0], "size": [1, 1], "material": "leaf", "uv_min": [-1, 0], "uv_max": [2, 3]})";

template <typename F>
std::string errorOf(F&& f) {
    try {
        f();
    } catch (const std::exception& e) {  // SceneError and InputError
        return e.what();
    }
    return "";
}

TEST(AlphaLoader, AJsonMaterialCarriesItsModeCutoffFactorTextureAndWraps) {
    TempDir dir;
    writeAlphaPng(dir, "leaf.png");
    const Scene s = loadScene(dir.write("s.json", sceneWith(R"({"alpha_mode": "mask", "alpha_cutoff": 0.3, "alpha": 0.9,
        "texture": "leaf.png", "wrap_s": "clamp_to_edge", "wrap_t": "mirrored_repeat"})",
                                                            kLeafQuad)));
    const Material& m = s.materials[1];
    EXPECT_EQ(m.alphaMode, AlphaMode::Mask);
    EXPECT_DOUBLE_EQ(m.alphaCutoff, 0.3);
    EXPECT_DOUBLE_EQ(m.alphaFactor, 0.9);
    ASSERT_TRUE(m.alphaTexture);
    EXPECT_EQ(m.alphaTexture->width, 2);
    EXPECT_EQ(m.alphaTexture->height, 2);
    // 8-bit codes read as code / 255.
    EXPECT_EQ(m.alphaTexture->alpha, (std::vector<float>{0.0f, 1.0f, 128.0f / 255.0f, 1.0f}));
    EXPECT_EQ(m.alphaTexture->wrapS, TextureWrap::ClampToEdge);
    EXPECT_EQ(m.alphaTexture->wrapT, TextureWrap::MirroredRepeat);
    EXPECT_TRUE(m.alphaTextured());
    EXPECT_TRUE(m.opaque());  // MASK is not semi-transparent: the any-hit path stays
    const auto& q = std::get<Quad>(s.objects[1].shape);
    EXPECT_EQ(q.uvMin, Vec2(-1, 0));
    EXPECT_EQ(q.uvMax, Vec2(2, 3));
    EXPECT_TRUE(m.alphaCanFallBelow(m.alphaCutoff));  // texel 0 · 0.9 is under 0.3
    // The texture is counted in the scene's memory (4 texels).
    EXPECT_GE(alphaTextureBytes(s), 16u);
}

TEST(AlphaLoader, DefaultsAreTheGltfOnesAndBlendIsSemiTransparent) {
    TempDir dir;
    const Scene s = loadScene(dir.write("s.json", sceneWith(R"({"alpha_mode": "blend", "alpha": 0.25})", kLeafQuad)));
    const Material& m = s.materials[1];
    EXPECT_EQ(m.alphaMode, AlphaMode::Blend);
    EXPECT_DOUBLE_EQ(m.alphaCutoff, 0.5);
    EXPECT_FALSE(m.opaque());
    EXPECT_DOUBLE_EQ(m.transmittance(1.0), 0.75);
    EXPECT_FALSE(m.alphaTextured());  // a constant BLEND is the opacity path alone
    EXPECT_EQ(s.materials[0].alphaMode, AlphaMode::Opaque);
}

TEST(AlphaLoader, BadAlphaInputNamesTheFileTheJsonPathAndTheProblem) {
    TempDir dir;
    writeAlphaPng(dir, "leaf.png");
    dir.write("not-an-image.png", "this is text");
    struct Case {
        std::string material, object, path, what;
    };
    const Case cases[] = {
        {R"({"alpha_mode": "mask", "texture": "missing.png"})", kLeafQuad, "materials.leaf.texture", "missing.png"},
        {R"({"alpha_mode": "mask", "texture": "not-an-image.png"})", kLeafQuad, "materials.leaf.texture",
         "not a readable image"},
        {R"({"alpha_mode": "mask", "alpha_cutoff": 1.5})", kLeafQuad, "materials.leaf.alpha_cutoff", "0..1"},
        {R"({"alpha_mode": "mask", "alpha_cutoff": -0.1})", kLeafQuad, "materials.leaf.alpha_cutoff", "0..1"},
        {R"({"alpha_mode": "cutout"})", kLeafQuad, "materials.leaf.alpha_mode", "unknown alpha mode 'cutout'"},
        {R"({"alpha_mode": "mask", "texture": "leaf.png", "wrap_s": "clamp"})", kLeafQuad, "materials.leaf.wrap_s",
         "unknown wrap mode"},
        {R"({"alpha_cutoff": 0.5})", kLeafQuad, "materials.leaf.alpha_cutoff", "only with"},
        {R"({"alpha_mode": "mask", "texture": "leaf.png"})",
         R"({"type": "sphere", "center": [0, 1, 0], "radius": 0.5, "material": "leaf"})", "objects[1].material",
         "texture coordinates"},
    };
    for (const Case& c : cases) {
        const std::filesystem::path file = dir.write("bad.json", sceneWith(c.material, c.object));
        const std::string e = errorOf([&] { loadScene(file); });
        SCOPED_TRACE(c.material);
        EXPECT_NE(e.find(file.string()), std::string::npos) << e;
        EXPECT_NE(e.find(c.what), std::string::npos) << e;
        EXPECT_NE(e.find(": " + c.path + ": "), std::string::npos) << e;
    }
}

TEST(AlphaLoader, AGltfModelSceneKeepsEachMaterialAsItsOwnObject) {
    const std::filesystem::path file =
        std::filesystem::path(SHADOWLAB_SHARED_SCENES) / "AlphaBlendModeTest" / "AlphaBlendModeTest.gltf";
    if (!std::filesystem::exists(file)) GTEST_SKIP() << file << " is not here";
    const Scene s = loadScene(file);
    // Six materials, each used: MatBed, MatBlend, MatCutoff25, MatCutoff75, MatCutoffDefault, MatOpaque.
    ASSERT_EQ(s.objects.size(), 6u);
    std::set<std::string> names;
    const AlphaTexture* labels = nullptr;
    for (const Object& o : s.objects) {
        const Material& m = s.materialOf(o);
        names.insert(m.name);
        const auto& mesh = std::get<Mesh>(o.shape);
        for (const MeshInstance& inst : mesh.instances)
            EXPECT_EQ(inst.geometry->uvs.empty(), !m.alphaTextured()) << m.name << ": UVs only where alpha is read";
        if (m.name == "MatCutoff25") {
            EXPECT_DOUBLE_EQ(m.alphaCutoff, 0.25);
        }
        if (m.name == "MatCutoff75") {
            EXPECT_DOUBLE_EQ(m.alphaCutoff, 0.75);
        }
        if (m.name == "MatCutoffDefault") {
            EXPECT_DOUBLE_EQ(m.alphaCutoff, 0.5);
        }
        if (m.name.rfind("MatCutoff", 0) == 0) {
            EXPECT_EQ(m.alphaMode, AlphaMode::Mask);
            ASSERT_TRUE(m.alphaTexture);
            // One image and sampler: one texture in memory for every material that reads it.
            if (!labels) labels = m.alphaTexture.get();
            EXPECT_EQ(m.alphaTexture.get(), labels);
            EXPECT_EQ(m.alphaTexture->width, 1024);
        }
        if (m.name == "MatBlend") {
            EXPECT_EQ(m.alphaMode, AlphaMode::Blend);
        }
        if (m.name == "MatOpaque" || m.name == "MatBed") {
            EXPECT_EQ(m.alphaMode, AlphaMode::Opaque);
            EXPECT_FALSE(m.alphaTexture) << "OPAQUE reads no texture";
        }
        EXPECT_EQ(o.name, "AlphaBlendModeTest/" + m.name);
    }
    EXPECT_EQ(names.size(), 6u);
}

// The test box as a glTF model whose one material is BLEND with alpha factor 0.6 and a
// baseColorTexture read from `imageUri`.
std::string blendBoxGltf(const std::string& imageUri) {
    std::string g = test::boxGltf(R"([{"mesh": 0}])", "[0]");
    const std::string prim = R"("primitives": [{"attributes": {"POSITION": 0}, "indices": 1}])";
    g.replace(g.find(prim), prim.size(),
              R"("primitives": [{"attributes": {"POSITION": 0}, "indices": 1, "material": 0}])");
    const std::string asset = R"({"asset": {"version": "2.0"},)";
    g.replace(g.find(asset), asset.size(),
              asset + R"( "materials": [{"name": "Lens", "alphaMode": "BLEND",
        "pbrMetallicRoughness": {"baseColorFactor": [1, 1, 1, 0.6], "baseColorTexture": {"index": 0}}}],
        "textures": [{"source": 0}], "images": [{"uri": ")" +
                  imageUri + R"("}],)");
    return g;
}

TEST(AlphaLoader, AGltfModelWhoseImageFileIsMissingCastsWithItsFactorAndSaysSo) {
    // Models are often passed on without their image files; the rest of the model's shadow is
    // still worth grading, so the material keeps its factor's alpha and the scene carries a note.
    TempDir dir;
    const Scene s = loadScene(dir.write("lens.gltf", blendBoxGltf("gone.png")));
    ASSERT_EQ(s.objects.size(), 1u);
    const Material& m = s.materialOf(s.objects[0]);
    EXPECT_EQ(m.alphaMode, AlphaMode::Blend);
    EXPECT_DOUBLE_EQ(m.alphaFactor, 0.6);
    EXPECT_FALSE(m.alphaTexture);
    EXPECT_DOUBLE_EQ(m.transmittance(1.0), 0.4);  // the factor alone: 1 − 0.6
    ASSERT_EQ(s.origin.notes.size(), 1u);
    const std::string& note = s.origin.notes[0];
    EXPECT_NE(note.find("gone.png"), std::string::npos) << note;
    EXPECT_NE(note.find("Lens"), std::string::npos) << note;
    EXPECT_NE(note.find("missing"), std::string::npos) << note;
}

TEST(AlphaLoader, AGltfModelWhoseImageIsThereButBrokenIsBadInput) {
    TempDir dir;
    dir.write("broken.png", "this is text");
    const std::filesystem::path file = dir.write("lens.gltf", blendBoxGltf("broken.png"));
    const std::string e = errorOf([&] { loadScene(file); });
    EXPECT_NE(e.find(file.string()), std::string::npos) << e;
    EXPECT_NE(e.find("images[0] (broken.png)"), std::string::npos) << e;
}

}  // namespace
}  // namespace shadowlab::scene
