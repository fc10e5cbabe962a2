// tests/scene/frame_identity_test.cpp: the camera as OpenEXR's worldToCamera/worldToNDC (row
// vectors in the file, the documented axes and pixel centres), the scene hash (what changes it
// and what does not), the identity check, and budgets, external masks.
#include "scene/frame_identity.h"

#include <cmath>
#include <fstream>

#include <OpenImageIO/imageio.h>
#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include "scene/budgets.h"
#include "scene/camera.h"
#include "scene/error.h"
#include "scene/frame_io.h"
#include "scene/mask_io.h"
#include "tests/scene/test_files.h"

namespace shadowlab::scene {
namespace {

using test::TempDir;

Scene sphereScene() {
    Scene s;
    s.camera.position = {1, 2, 6};
    s.camera.lookAt = {0, 0.5, 0};
    s.camera.width = 64;
    s.camera.height = 32;
    s.materials.push_back({"m", {0.8, 0.8, 0.8}, 1.0});
    s.lights.push_back({});
    s.objects.push_back({"ball", Sphere{{0, 1, 0}, 1.0}, 0});
    return s;
}

// p·M with M the row-vector matrix as the EXR file stores it (Imath's convention), then / w.
glm::dvec4 rowTimes(const glm::dvec3& p, const float m[16]) {
    const double v[4] = {p.x, p.y, p.z, 1.0};
    glm::dvec4 out(0.0);
    for (int j = 0; j < 4; ++j)
        for (int i = 0; i < 4; ++i) out[j] += v[i] * double(m[4 * i + j]);
    return out;
}

TEST(FrameIdentity, ExrCameraMatricesAreRowVectorM44fThatProjectAPixelCentreToItsNdc) {
    const Scene s = sphereScene();
    Frame f = Frame::allocate(s.camera.width, s.camera.height, false);
    recordIdentity(f, s);
    TempDir dir;
    const auto file = dir.path() / "f.exr";
    writeFrame(f, file);

    // Read the header with OpenImageIO directly: typed m44f, not strings.
    auto in = OIIO::ImageInput::open(file.string());
    ASSERT_TRUE(in);
    const OIIO::ParamValue* w2c = in->spec().find_attribute("worldtocamera");
    const OIIO::ParamValue* w2n = in->spec().find_attribute("worldtoNDC");
    ASSERT_TRUE(w2c && w2n);
    EXPECT_EQ(w2c->type(), OIIO::TypeMatrix44);
    EXPECT_EQ(w2n->type(), OIIO::TypeMatrix44);
    const auto* c = static_cast<const float*>(w2c->data());
    const auto* n = static_cast<const float*>(w2n->data());

    // A point 3 units along the ray through the centre of pixel (10, 5): in OpenEXR's camera
    // space it lies in front (z > 0), left of and above the image centre (pixel 10 < 32, row
    // 5 < 16: x < 0, y > 0), at camera distance 3·|dir|·cos = 3 along forward (dir·forward = 1).
    const CameraBasis b = cameraBasis(s.camera);
    const glm::dvec3 p = b.position + 3.0 * pixelDirection(b, 10, 5);
    const glm::dvec4 pc = rowTimes(p, c);
    EXPECT_NEAR(pc.z, 3.0, 1e-5);
    EXPECT_LT(pc.x, 0.0);
    EXPECT_GT(pc.y, 0.0);
    EXPECT_NEAR(pc.w, 1.0, 1e-6);
    // NDC: (0,0) top-left, (1,1) bottom-right corner; pixel centres at ((x+0.5)/W, (y+0.5)/H).
    const glm::dvec4 pn = rowTimes(p, n);
    EXPECT_NEAR(pn.x / pn.w, 10.5 / 64.0, 1e-5);
    EXPECT_NEAR(pn.y / pn.w, 5.5 / 32.0, 1e-5);
    // The look-at point is the image centre.
    const glm::dvec4 centre = rowTimes(s.camera.lookAt, n);
    EXPECT_NEAR(centre.x / centre.w, 0.5, 1e-5);
    EXPECT_NEAR(centre.y / centre.w, 0.5, 1e-5);

    // The file's standard names are OpenEXR's, found in the raw header bytes.
    std::ifstream raw(file, std::ios::binary);
    const std::string bytes((std::istreambuf_iterator<char>(raw)), {});
    EXPECT_NE(bytes.find(std::string("worldToCamera\0m44f\0", 19)), std::string::npos);
    EXPECT_NE(bytes.find(std::string("worldToNDC\0m44f\0", 16)), std::string::npos);
    EXPECT_NE(bytes.find(std::string("shadowlab:light.0.intensity\0float\0", 34)), std::string::npos);
    EXPECT_NE(bytes.find(std::string("shadowlab:light_count\0int\0", 26)), std::string::npos);

    // And readFrame gives them back typed.
    const Frame back = readFrame(file);
    EXPECT_TRUE(describeIdentityDifference(back, f).empty());
    ASSERT_TRUE(std::holds_alternative<glm::mat4>(back.typedAttributes.at("worldToNDC")));
    EXPECT_EQ(std::get<int>(back.typedAttributes.at("light_count")), 1);
    EXPECT_EQ(std::get<float>(back.typedAttributes.at("light.0.intensity")), 1.0f);
    EXPECT_EQ(std::get<glm::vec3>(back.typedAttributes.at("light.0.direction")), glm::vec3(0, -1, 0));
}

TEST(FrameIdentity, SceneHashFollowsTheContentNotTheCameraOrNames) {
    const Scene a = sphereScene();
    Scene b = a;
    b.camera.width = 640;
    b.camera.position = {5, 5, 5};
    b.objects[0].name = "renamed";
    b.shadow.depthBias = 0.5;
    EXPECT_EQ(sceneHash(a), sceneHash(b));
    EXPECT_EQ(sceneHash(a).size(), 16u);
    Scene c = a;
    std::get<Sphere>(c.objects[0].shape).radius = 1.0 + 1e-12;
    EXPECT_NE(sceneHash(a), sceneHash(c));
    Scene d = a;
    d.lights[0].intensity = 2.0;
    EXPECT_NE(sceneHash(a), sceneHash(d));
    // One vertex of a mesh moved by one ulp changes it.
    auto mesh = std::make_shared<TriangleMesh>();
    mesh->positions = {{0, 0, 0}, {1, 0, 0}, {0, 1, 0}};
    mesh->normals = {{0, 0, 1}, {0, 0, 1}, {0, 0, 1}};
    mesh->indices = {0, 1, 2};
    Scene e = a, e2 = a;
    e.objects.push_back({"tri", Mesh::single("t.obj", mesh), 0});
    auto moved = std::make_shared<TriangleMesh>(*mesh);
    moved->positions[1].x = std::nextafter(1.0, 2.0);
    e2.objects.push_back({"tri", Mesh::single("t.obj", moved), 0});
    EXPECT_NE(sceneHash(e), sceneHash(e2));
}

TEST(FrameIdentity, TheHashOfAMeshSceneIsTheSameWhetherRecomputedOrRemembered) {
    // sceneHash remembers the last scenes by everything but their meshes' and alpha textures'
    // bulk and by which (shared, never changed) geometry they hold: a scene whose geometry is new
    // objects with the same content hashes the same, other content or other lights differently,
    // and asking again gives what the first call computed.
    auto triangle = [](float x) {
        auto mesh = std::make_shared<TriangleMesh>();
        mesh->positions = {{0, 0, 0}, {x, 0, 0}, {0, 1, 0}};
        mesh->normals = {{0, 0, 1}, {0, 0, 1}, {0, 0, 1}};
        mesh->indices = {0, 1, 2};
        return mesh;
    };
    Scene a = sphereScene();
    a.objects.push_back({"tri", Mesh::single("t.obj", triangle(1.0f)), 0});
    const std::string first = sceneHash(a);
    EXPECT_EQ(sceneHash(a), first);
    Scene copy = sphereScene();  // the same content in new objects
    copy.objects.push_back({"tri", Mesh::single("t.obj", triangle(1.0f)), 0});
    EXPECT_EQ(sceneHash(copy), first);
    Scene other = sphereScene();
    other.objects.push_back({"tri", Mesh::single("t.obj", triangle(2.0f)), 0});
    EXPECT_NE(sceneHash(other), first);
    EXPECT_EQ(sceneHash(a), first);  // still, after another scene
    Scene lit = a;                   // the same geometry, another light
    lit.lights[0].intensity = 2.0;
    EXPECT_NE(sceneHash(lit), first);
    // An alpha texture's texels count as a mesh's vertices do.
    auto texture = [](float alpha) {
        auto t = std::make_shared<AlphaTexture>();
        t->width = t->height = 2;
        t->alpha = {1, alpha, 1, 1};
        return t;
    };
    Scene masked = a, masked2 = a;
    masked.materials[0].alphaMode = masked2.materials[0].alphaMode = AlphaMode::Mask;
    masked.materials[0].alphaTexture = texture(0.0f);
    masked2.materials[0].alphaTexture = texture(0.5f);
    const std::string m = sceneHash(masked);
    EXPECT_NE(sceneHash(masked2), m);
    EXPECT_EQ(sceneHash(masked), m);
}

TEST(FrameIdentity, DifferenceNamesSizeSceneOrCamera) {
    const Scene s = sphereScene();
    Frame a = Frame::allocate(64, 32, false);
    recordIdentity(a, s);
    Frame b = a;
    EXPECT_EQ(describeIdentityDifference(a, b), "");
    Scene moved = s;
    moved.camera.position.x += 0.01;
    recordIdentity(b, moved);
    EXPECT_NE(describeIdentityDifference(a, b).find("different cameras (worldTo"), std::string::npos);
    Scene other = s;
    other.ambient = 0.2;
    Frame c = a;
    recordIdentity(c, other);
    EXPECT_NE(describeIdentityDifference(a, c).find("different scenes"), std::string::npos);
    Frame d = Frame::allocate(32, 32, false);
    EXPECT_NE(describeIdentityDifference(a, d).find("different image sizes (method 64x32, reference 32x32)"),
              std::string::npos);
    // A frame that records nothing (another engine's) is held to the size only.
    Frame bare = Frame::allocate(64, 32, false);
    EXPECT_EQ(describeIdentityDifference(bare, a), "");
}

TEST(Budgets, RatesPercentagesAndPixelCounts) {
    EXPECT_DOUBLE_EQ(parseBudgetLimit("0.5%", BudgetKind::MaxMismatch, "--max-mismatch").value, 0.005);
    EXPECT_DOUBLE_EQ(parseBudgetLimit("0.005", BudgetKind::MaxMismatch, "--max-mismatch").value, 0.005);
    const BudgetLimit px = parseBudgetLimit("120px", BudgetKind::MaxFalseShadow, "--max-false-shadow");
    EXPECT_EQ(px.unit, BudgetLimit::Unit::Pixels);
    EXPECT_EQ(px.value, 120.0);
    EXPECT_DOUBLE_EQ(parseBudgetLimit("99%", BudgetKind::MinIoU, "--min-iou").value, 0.99);
    for (const char* bad : {"", "1.5", "-0.1", "101%", "12.5px", "px", "nan", "inf", "0x1p-3", "5 %", "1e400"})
        EXPECT_THROW(parseBudgetLimit(bad, BudgetKind::MaxMismatch, "--max-mismatch"), InputError) << bad;
    // A mean and an IoU are not pixel counts.
    EXPECT_THROW(parseBudgetLimit("3px", BudgetKind::MinIoU, "--min-iou"), InputError);
    EXPECT_THROW(parseBudgetLimit("3px", BudgetKind::MaxMeanAbsDiff, "--max-mean-abs-diff"), InputError);
}

TEST(Budgets, JsonBlockErrorsNameTheFileAndPath) {
    const nlohmann::json good = {{"max_mismatch", "0.5%"}, {"min_iou", 0.9}, {"max_false_shadow", "40px"}};
    const Budgets b = readBudgets("s.json", good, JsonPath() / "budgets");
    EXPECT_DOUBLE_EQ(b[BudgetKind::MaxMismatch]->value, 0.005);
    EXPECT_DOUBLE_EQ(b[BudgetKind::MinIoU]->value, 0.9);
    EXPECT_FALSE(b[BudgetKind::MaxSelfAcne]);
    try {
        readBudgets("s.json", {{"max_mismatch", "2px%"}}, JsonPath() / "budgets");
        FAIL();
    } catch (const SceneError& e) {
        EXPECT_EQ(e.jsonPath(), "budgets.max_mismatch");
        EXPECT_NE(std::string(e.what()).find("s.json: budgets.max_mismatch: "), std::string::npos) << e.what();
    }
    EXPECT_THROW(readBudgets("s.json", {{"max_mismatsh", 0.1}}, JsonPath() / "budgets"), SceneError);
    EXPECT_THROW(readBudgets("s.json", {{"max_mismatch", true}}, JsonPath() / "budgets"), SceneError);
    EXPECT_THROW(readBudgets("s.json", nlohmann::json::array(), JsonPath() / "budgets"), SceneError);
    // The command line overrides the file, key by key.
    Budgets cli;
    cli[BudgetKind::MinIoU] = parseBudgetLimit("0.5", BudgetKind::MinIoU, "--min-iou");
    const Budgets merged = b.overriddenBy(cli);
    EXPECT_DOUBLE_EQ(merged[BudgetKind::MinIoU]->value, 0.5);
    EXPECT_DOUBLE_EQ(merged[BudgetKind::MaxMismatch]->value, 0.005);
}

// A one-channel 8-bit PNG with the given codes, written with OpenImageIO.
void writeGrayPng(const std::filesystem::path& file, int w, int h, const std::vector<unsigned char>& codes,
                  int channels = 1) {
    auto out = OIIO::ImageOutput::create(file.string());
    ASSERT_TRUE(out);
    ASSERT_TRUE(out->open(file.string(), OIIO::ImageSpec(w, h, channels, OIIO::TypeDesc::UINT8)));
    ASSERT_TRUE(out->write_image(OIIO::TypeDesc::UINT8, codes.data()));
    out->close();
}

TEST(ShadowMask, PngLinearSrgbAndInvertedDecodeToVisibility) {
    TempDir dir;
    const auto png = dir.path() / "m.png";
    writeGrayPng(png, 2, 1, {0, 128});
    const ShadowMask lin = readShadowMask(png, {});
    EXPECT_EQ(lin.visibility[0], 0.0f);
    EXPECT_NEAR(lin.visibility[1], 128.0 / 255.0, 1e-6);
    // sRGB code 128 is linear ((128/255 + 0.055) / 1.055)^2.4 = 0.21586 (IEC 61966-2-1).
    const ShadowMask srgb = readShadowMask(png, {std::nullopt, false, true});
    EXPECT_NEAR(srgb.visibility[1], 0.21586, 1e-4);
    const ShadowMask inv = readShadowMask(png, {std::nullopt, true, false});
    EXPECT_EQ(inv.visibility[0], 1.0f);
    // Several channels need a choice; a wrong name lists what is there.
    const auto rgb = dir.path() / "rgb.png";
    writeGrayPng(rgb, 1, 1, {10, 20, 255}, 3);
    EXPECT_THROW(readShadowMask(rgb, {}), InputError);
    EXPECT_EQ(readShadowMask(rgb, {std::string("B"), false, false}).visibility[0], 1.0f);
    try {
        readShadowMask(rgb, {std::string("shadow"), false, false});
        FAIL();
    } catch (const InputError& e) {
        EXPECT_NE(std::string(e.what()).find("no channel 'shadow' (it has R, G, B)"), std::string::npos) << e.what();
    }
    // The mask takes ids and N·L from the reference; sizes must agree.
    Frame ref = Frame::allocate(2, 1, true);
    ref.objectId = {1, 2};
    ref.ndotl = {0.5f, 0.25f};
    const Frame f = frameFromMask(lin, ref, png);
    EXPECT_EQ(f.objectId, ref.objectId);
    EXPECT_EQ(f.ndotl, ref.ndotl);
    EXPECT_TRUE(f.blockerId.empty());
    EXPECT_EQ(f.visibility, lin.visibility);
    EXPECT_THROW(frameFromMask(lin, Frame::allocate(3, 1, false), png), InputError);
}

// A one-row EXR of one float channel `name` holding `values`, as another engine might write it.
bool writeOneChannelExr(const std::filesystem::path& file, const std::string& name, const std::vector<float>& values) {
    auto out = OIIO::ImageOutput::create(file.string());
    if (!out) return false;
    OIIO::ImageSpec spec(int(values.size()), 1, 1, OIIO::TypeDesc::FLOAT);
    spec.channelnames = {name};
    return out->open(file.string(), spec) && out->write_image(OIIO::TypeDesc::FLOAT, values.data()) && out->close();
}

TEST(ShadowMask, ASingleChannelExrIsAMaskAndAFrameIsNot) {
    TempDir dir;
    const auto exr = dir.path() / "mask.exr";
    ASSERT_TRUE(writeOneChannelExr(exr, "shadow", {0.25f, 1.0f}));
    EXPECT_TRUE(looksLikeMask(exr));
    const ShadowMask m = readShadowMask(exr, {});
    EXPECT_EQ(m.channel, "shadow");
    EXPECT_EQ(m.visibility, (std::vector<float>{0.25f, 1.0f}));
    const auto frame = dir.path() / "frame.exr";
    writeFrame(Frame::allocate(2, 1, false), frame);
    EXPECT_FALSE(looksLikeMask(frame));
    EXPECT_FALSE(looksLikeMask(dir.path() / "missing.exr"));
}

TEST(ShadowMask, AnEnginesOneChannelNamedVisibilityIsAMaskAndItsSizeIsCheckedBeforeItsValues) {
    TempDir dir;
    const auto exr = dir.path() / "engine.exr";
    ASSERT_TRUE(writeOneChannelExr(exr, "visibility", {1.0f, -0.00005f, 0.0f}));  // a resampled mask's undershoot
    EXPECT_TRUE(looksLikeMask(exr));
    // Against a 2x1 reference the size is what is wrong, not the value at pixel (1, 0).
    MaskOptions o;
    o.expectedWidth = 2;
    o.expectedHeight = 1;
    try {
        readShadowMask(exr, o);
        ADD_FAILURE() << "a 3x1 mask read against a 2x1 reference";
    } catch (const InputError& e) {
        EXPECT_NE(std::string(e.what()).find("the mask is 3x1, the reference 2x1"), std::string::npos) << e.what();
    }
    o.expectedWidth = 3;
    try {
        readShadowMask(exr, o);
        ADD_FAILURE() << "a value below 0 read";
    } catch (const InputError& e) {
        EXPECT_NE(std::string(e.what()).find("pixel (1, 0)"), std::string::npos) << e.what();
    }
    // Only PNG and EXR: a JPEG is refused by its name, with the reason.
    const auto jpg = dir.path() / "mask.jpg";
    std::ofstream(jpg) << "not read";
    try {
        readShadowMask(jpg, {});
        ADD_FAILURE() << "a JPEG mask read";
    } catch (const InputError& e) {
        EXPECT_NE(std::string(e.what()).find("mask.jpg: a shadow mask is read from a .png or an .exr (JPEG"),
                  std::string::npos)
            << e.what();
    }
}

}  // namespace
}  // namespace shadowlab::scene
