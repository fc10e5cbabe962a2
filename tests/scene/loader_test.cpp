// tests/scene/loader_test.cpp: the JSON loader accepts the shipped scenes and gives one clear
// error, with the JSON path, for each kind of bad input.
#include "scene/loader.h"

#include <cmath>
#include <fstream>
#include <iterator>

#include <gtest/gtest.h>

#include "scene/error.h"
#include "tests/scene/test_files.h"

namespace shadowlab::scene {
namespace {

using test::TempDir;

// A valid scene; each bad case below replaces one piece of it.
const std::string kCamera =
    R"("camera": {"position": [0, 2, 6], "look_at": [0, 0.7, 0], "fov_y": 40, "resolution": [64, 36]})";
const std::string kMaterials = R"("materials": {"matte": {"albedo": [0.8, 0.8, 0.8]}})";
const std::string kLights = R"("lights": [{"type": "directional", "direction": [-1, -2, -1]}])";
const std::string kObjects =
    R"("objects": [{"type": "sphere", "center": [0, 1, 0], "radius": 1, "material": "matte"},
                   {"type": "quad", "center": [0, 0, 0], "normal": [0, 1, 0], "size": [20, 20], "material": "matte"}])";

std::string sceneText(const std::string& camera = kCamera, const std::string& materials = kMaterials,
                      const std::string& lights = kLights, const std::string& objects = kObjects,
                      const std::string& extra = "") {
    return "{" + camera + ",\n" + materials + ",\n" + lights + ",\n" + objects + extra + "}";
}

TEST(SceneLoader, LoadsAValidSceneWithEveryValueInPlace) {
    TempDir dir;
    const Scene s = loadScene(dir.write("ok.json", sceneText()));
    EXPECT_EQ(s.camera.width, 64);
    EXPECT_EQ(s.camera.height, 36);
    ASSERT_EQ(s.lights.size(), 1u);
    // Directions are normalized on load: (-1,-2,-1)/sqrt(6).
    EXPECT_NEAR(s.lights[0].direction.y, -2.0 / std::sqrt(6.0), 1e-15);
    ASSERT_EQ(s.objects.size(), 2u);
    EXPECT_DOUBLE_EQ(std::get<Sphere>(s.objects[0].shape).radius, 1.0);
    const Bounds b = s.bounds();
    EXPECT_DOUBLE_EQ(b.min.x, -10.0);
    EXPECT_DOUBLE_EQ(b.max.y, 2.0);
    EXPECT_TRUE(s.allOpaque());
}

TEST(SceneLoader, LoadsEveryShippedScene) {
    std::size_t count = 0;
    const bool haveShared = std::filesystem::is_directory(SHADOWLAB_SHARED_SCENES);
    for (const auto& e : std::filesystem::recursive_directory_iterator(scenesDirectory())) {
        if (e.path().extension() != ".json") continue;
        if (e.path().filename() == "scene.schema.json") continue;  // the schema, not a scene
        SCOPED_TRACE(e.path().string());
        // Scenes built on the large models read them from ../shared/scenes beside the checkout.
        std::ifstream in(e.path());
        const std::string text((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
        if (!haveShared && text.find("shared/scenes/") != std::string::npos) continue;
        EXPECT_NO_THROW(loadScene(e.path()));
        ++count;
    }
    EXPECT_GE(count, 1u);
}

TEST(SceneLoader, FindsShippedScenesByNameAndListsThemWhenNoneMatches) {
    EXPECT_EQ(findScene("seed").filename(), "seed.json");
    try {
        findScene("no-such-scene");
        FAIL() << "expected an error";
    } catch (const InputError& e) {
        EXPECT_NE(std::string(e.what()).find("seed"), std::string::npos) << e.what();
    }
}

struct BadCase {
    const char* name;
    std::string text;
    std::string path;      // expected JSON path in the error ("" when none)
    std::string mentions;  // a phrase the message must contain
};

class BadScene : public ::testing::TestWithParam<BadCase> {};

TEST(SceneLoader, ShadowBlockReadsTheCascadeBlendAndTheHardwareBias) {
    TempDir dir;
    const auto file = dir.write(
        "blend.json", sceneText(kCamera, kMaterials, kLights, kObjects,
                                R"(, "shadow": {"cascades": 3, "cascade_blend": 0.2, "hardware_bias": true})"));
    const Scene s = loadScene(file);
    ASSERT_TRUE(s.shadow.cascadeBlend.has_value());
    EXPECT_EQ(*s.shadow.cascadeBlend, 0.2);
    EXPECT_EQ(s.shadow.hardwareBias, std::optional<bool>(true));
}

TEST_P(BadScene, GivesOneErrorNamingFileAndPath) {
    const BadCase& c = GetParam();
    TempDir dir;
    const auto file = dir.write(std::string(c.name) + ".json", c.text);
    try {
        loadScene(file);
        FAIL() << "loaded a bad scene: " << c.name;
    } catch (const SceneError& e) {
        const std::string what = e.what();
        EXPECT_EQ(e.jsonPath(), c.path) << what;
        EXPECT_NE(what.find(file.string()), std::string::npos) << what;
        EXPECT_NE(what.find(c.mentions), std::string::npos) << what;
    }
}

std::string withObjects(const std::string& objects) {
    return sceneText(kCamera, kMaterials, kLights, "\"objects\": " + objects);
}
std::string withLights(const std::string& lights) { return sceneText(kCamera, kMaterials, lights, kObjects); }
std::string withCamera(const std::string& camera) { return sceneText(camera, kMaterials, kLights, kObjects); }

INSTANTIATE_TEST_SUITE_P(
    Cases, BadScene,
    ::testing::Values(
        BadCase{"syntax", R"({"camera": {"position": [0, 2, 6],, }})", "", "invalid JSON near line 1"},
        BadCase{"truncated", sceneText().substr(0, 80), "", "invalid JSON"},
        BadCase{"not_an_object", "[1, 2, 3]", "", "expected an object"},
        BadCase{"unknown_top_key", sceneText(kCamera, kMaterials, kLights, kObjects, R"(, "lightz": [])"), "lightz",
                "unknown key"},
        BadCase{"unknown_key_suggests",
                withObjects(R"([{"type": "sphere", "center": [0,1,0], "radus": 1, "material": "matte"}])"),
                "objects[0].radus", "did you mean 'radius'"},
        BadCase{"wrong_type",
                withObjects(R"([{"type": "sphere", "center": [0,1,0], "radius": "one", "material": "matte"}])"),
                "objects[0].radius", "expected a number, got a string"},
        BadCase{"infinite",
                withObjects(R"([{"type": "sphere", "center": [0,1e999,0], "radius": 1, "material": "matte"}])"), "",
                "number overflow parsing '1e999'"},
        BadCase{"nan_token",
                withObjects(R"([{"type": "sphere", "center": [0,NaN,0], "radius": 1, "material": "matte"}])"), "",
                "invalid JSON"},
        BadCase{"zero_direction", withLights(R"("lights": [{"type": "directional", "direction": [0, 0, 0]}])"),
                "lights[0].direction", "non-zero direction"},
        BadCase{"negative_radius",
                withObjects(R"([{"type": "sphere", "center": [0,1,0], "radius": -1, "material": "matte"}])"),
                "objects[0].radius", "must be > 0"},
        BadCase{
            "zero_quad_size",
            withObjects(
                R"([{"type": "quad", "center": [0,0,0], "normal": [0,1,0], "size": [20, 0], "material": "matte"}])"),
            "objects[0].size[1]", "must be > 0"},
        BadCase{"inverted_box",
                withObjects(R"([{"type": "box", "min": [0,0,0], "max": [1,-1,1], "material": "matte"}])"),
                "objects[0].max", "greater than min"},
        BadCase{"missing_material",
                withObjects(R"([{"type": "sphere", "center": [0,1,0], "radius": 1, "material": "gold"}])"),
                "objects[0].material", "no material named 'gold'"},
        BadCase{"absurd_resolution",
                withCamera(R"("camera": {"position": [0,2,6], "look_at": [0,0,0], "resolution": [100000, 100000]})"),
                "camera.resolution[0]", "must be in 1..16384"},
        BadCase{"zero_resolution",
                withCamera(R"("camera": {"position": [0,2,6], "look_at": [0,0,0], "resolution": [0, 10]})"),
                "camera.resolution[0]", "must be in 1..16384"},
        BadCase{"missing_mesh_file", withObjects(R"([{"type": "mesh", "file": "nowhere.obj", "material": "matte"}])"),
                "objects[0].file", "no such file"},
        BadCase{"unknown_object_type", withObjects(R"([{"type": "torus", "material": "matte"}])"), "objects[0].type",
                "unknown object type 'torus'"},
        BadCase{"unknown_light_type", withLights(R"("lights": [{"type": "laser", "direction": [0, -1, 0]}])"),
                "lights[0].type", "unknown light type"},
        BadCase{"no_lights", withLights(R"("lights": [])"), "lights", "at least one light"},
        BadCase{"missing_camera", "{" + kMaterials + "," + kLights + "," + kObjects + "}", "camera", "is required"},
        BadCase{"camera_at_target", withCamera(R"("camera": {"position": [1,1,1], "look_at": [1,1,1]})"),
                "camera.look_at", "must differ"},
        BadCase{"fov_out_of_range", withCamera(R"("camera": {"position": [0,2,6], "look_at": [0,0,0], "fov_y": 180})"),
                "camera.fov_y", "(0, 180)"},
        BadCase{"far_before_near",
                withCamera(R"("camera": {"position": [0,2,6], "look_at": [0,0,0], "near": 5, "far": 1})"), "camera.far",
                "greater than near"},
        BadCase{"opacity_out_of_range", sceneText(kCamera, R"("materials": {"matte": {"opacity": 1.5}})"),
                "materials.matte.opacity", "must be in 0..1"},
        BadCase{"spot_without_cone",
                withLights(R"("lights": [{"type": "spot", "position": [0,5,0], "direction": [0,-1,0]}])"),
                "lights[0].cone_angle", "is required"},
        BadCase{"bad_shadow_filter",
                sceneText(kCamera, kMaterials, kLights, kObjects, R"(, "shadow": {"filter": "blur"})"), "shadow.filter",
                "expected none, pcf2x2, pcf, poisson, pcss, vsm, evsm2, evsm4, esm or msm"},
        BadCase{"evsm_exponent_overflows_float",
                sceneText(kCamera, kMaterials, kLights, kObjects, R"(, "shadow": {"evsm_positive_exponent": 43})"),
                "shadow.evsm_positive_exponent", "must be in 0..42"},
        BadCase{"esm_exponent_overflows_float",
                sceneText(kCamera, kMaterials, kLights, kObjects, R"(, "shadow": {"esm_exponent": 90})"),
                "shadow.esm_exponent", "must be in 0..85"},
        BadCase{"negative_min_variance",
                sceneText(kCamera, kMaterials, kLights, kObjects, R"(, "shadow": {"min_variance": -1e-6})"),
                "shadow.min_variance", "must be in 0..1"},
        BadCase{"bleeding_reduction_of_one",
                sceneText(kCamera, kMaterials, kLights, kObjects, R"(, "shadow": {"light_bleeding_reduction": 1})"),
                "shadow.light_bleeding_reduction", "must be in 0..0.99"},
        BadCase{"even_blur_width",
                sceneText(kCamera, kMaterials, kLights, kObjects, R"(, "shadow": {"blur_width": 4})"),
                "shadow.blur_width", "must be odd"},
        BadCase{"moment_bias_not_a_number",
                sceneText(kCamera, kMaterials, kLights, kObjects, R"(, "shadow": {"moment_bias": "small"})"),
                "shadow.moment_bias", "expected"},
        BadCase{"too_many_cascades",
                sceneText(kCamera, kMaterials, kLights, kObjects, R"(, "shadow": {"cascades": 5})"), "shadow.cascades",
                "must be in 1..4"},
        BadCase{"cascade_blend_too_wide",
                sceneText(kCamera, kMaterials, kLights, kObjects, R"(, "shadow": {"cascade_blend": 0.6})"),
                "shadow.cascade_blend", "must be in 0..0.5"},
        BadCase{"cascade_blend_negative",
                sceneText(kCamera, kMaterials, kLights, kObjects, R"(, "shadow": {"cascade_blend": -0.1})"),
                "shadow.cascade_blend", "must be in 0..0.5"},
        BadCase{"hardware_bias_not_bool",
                sceneText(kCamera, kMaterials, kLights, kObjects, R"(, "shadow": {"hardware_bias": "yes"})"),
                "shadow.hardware_bias", "expected"},
        BadCase{"receiver_plane_bias_not_bool",
                sceneText(kCamera, kMaterials, kLights, kObjects, R"(, "shadow": {"receiver_plane_bias": 1})"),
                "shadow.receiver_plane_bias", "expected"},
        BadCase{"fractional_cascades",
                sceneText(kCamera, kMaterials, kLights, kObjects, R"(, "shadow": {"cascades": 2.5})"),
                "shadow.cascades", "expected an integer"}),
    [](const ::testing::TestParamInfo<BadCase>& testParam) { return std::string(testParam.param.name); });

// A sphere 2 cm across seen from 5 cm: the default near plane 0.1 would clip all of it. Without
// near and far, far is the farthest corner plus 1% and near a thousandth of it; with far alone,
// near is a thousandth of that far; with near given it stays as written.
TEST(SceneLoader, ACentimetreSceneWithoutANearPlaneIsNotClippedAway) {
    TempDir dir;
    const std::string objects =
        R"("objects": [{"type": "sphere", "center": [0, 0.01, 0], "radius": 0.01, "material": "matte"}])";
    const std::string view = R"("position": [0, 0.01, 0.05], "look_at": [0, 0.01, 0])";
    // Farthest corner of [−0.01, 0.01] x [0, 0.02] x [−0.01, 0.01] from (0, 0.01, 0.05):
    // √(0.01² + 0.01² + 0.06²).
    const double far = 1.01 * std::sqrt(0.0001 + 0.0001 + 0.0036);
    const Scene fitted =
        loadScene(dir.write("a.json", sceneText(R"("camera": {)" + view + "}", kMaterials, kLights, objects)));
    EXPECT_NEAR(fitted.camera.far, far, 1e-12);
    EXPECT_NEAR(fitted.camera.near, 1e-3 * far, 1e-15);
    EXPECT_LT(fitted.camera.near, 0.04);  // the sphere's nearest point
    const Scene farOnly = loadScene(
        dir.write("b.json", sceneText(R"("camera": {)" + view + R"(, "far": 0.5})", kMaterials, kLights, objects)));
    EXPECT_DOUBLE_EQ(farOnly.camera.near, 5e-4);
    const Scene given = loadScene(
        dir.write("c.json", sceneText(R"("camera": {)" + view + R"(, "near": 0.02})", kMaterials, kLights, objects)));
    EXPECT_DOUBLE_EQ(given.camera.near, 0.02);
    // A scene whose far plane is beyond 100 keeps the default: a 200 x 200 ground reaches about
    // 140 from the camera.
    const std::string large = R"("objects": [{"type": "quad", "center": [0, 0, 0], "normal": [0, 1, 0],
                                              "size": [200, 200], "material": "matte"}])";
    const Scene big = loadScene(dir.write("d.json", sceneText(kCamera, kMaterials, kLights, large)));
    EXPECT_GT(big.camera.far, 100.0);
    EXPECT_DOUBLE_EQ(big.camera.near, 0.1);
}

TEST(SceneLoader, AGltfFileIsASceneWithAFramedCameraAndADefaultSun) {
    // The Khronos Box has no camera and no light: the loader frames its bounding sphere
    // (a unit cube: radius sqrt(3)/2) and adds one directional light.
    const Scene s = loadScene(scenesDirectory() / "models" / "Box" / "Box.gltf");
    ASSERT_EQ(s.objects.size(), 1u);
    EXPECT_EQ(std::get<Mesh>(s.objects[0].shape).triangleCount(), 12u);
    ASSERT_EQ(s.lights.size(), 1u);
    EXPECT_EQ(s.lights[0].type, LightType::Directional);
    EXPECT_LT(s.lights[0].direction.y, 0.0);  // the sun shines down
    const Vec3 toCenter = s.bounds().center() - s.camera.position;
    const double distance = glm::length(toCenter);
    // The whole bounding sphere is inside the vertical field of view, and not tiny in it.
    const double halfAngle = std::asin((std::sqrt(3.0) / 2.0) / distance) * 180.0 / 3.14159265358979;
    EXPECT_LT(halfAngle, s.camera.fovYDegrees / 2.0);
    EXPECT_GT(halfAngle, s.camera.fovYDegrees / 4.0);
    EXPECT_LT(s.camera.near, distance - std::sqrt(3.0) / 2.0);
    EXPECT_GT(s.camera.far, distance + std::sqrt(3.0) / 2.0);
}

TEST(SceneLoader, GltfCamerasAndPunctualLightsAreUsed) {
    TempDir dir;
    // One triangle, a camera node at (0,0,5) looking down −Z, and a spot light node at (0,3,0)
    // rotated −90° about X so its −Z axis points down (quaternion (−sin45°, 0, 0, cos45°)).
    const std::string buffer = "AAAAAAAAAAAAAAAAAACAPwAAAAAAAAAAAAAAAAAAgD8AAAAA";  // 3 vec3: 0,0,0 1,0,0 0,1,0
    dir.write("t.gltf", R"({"asset": {"version": "2.0"}, "scene": 0, "scenes": [{"nodes": [0, 1, 2]}],
      "nodes": [{"mesh": 0}, {"camera": 0, "translation": [0, 0, 5]},
                {"rotation": [-0.70710678, 0, 0, 0.70710678], "translation": [0, 3, 0],
                 "extensions": {"KHR_lights_punctual": {"light": 0}}}],
      "cameras": [{"type": "perspective", "perspective": {"yfov": 0.5, "znear": 0.1, "zfar": 50}}],
      "extensionsUsed": ["KHR_lights_punctual"],
      "extensions": {"KHR_lights_punctual": {"lights": [{"type": "spot", "intensity": 10,
                     "spot": {"outerConeAngle": 0.5}}]}},
      "meshes": [{"primitives": [{"attributes": {"POSITION": 0}}]}],
      "accessors": [{"bufferView": 0, "componentType": 5126, "count": 3, "type": "VEC3",
                     "min": [0, 0, 0], "max": [1, 1, 0]}],
      "bufferViews": [{"buffer": 0, "byteLength": 36}],
      "buffers": [{"byteLength": 36, "uri": "data:application/octet-stream;base64,)" +
                            buffer + R"("}]})");
    const Scene s = loadScene(dir.path() / "t.gltf");
    EXPECT_NEAR(s.camera.position.z, 5.0, 1e-12);
    EXPECT_NEAR(glm::normalize(s.camera.lookAt - s.camera.position).z, -1.0, 1e-12);
    EXPECT_NEAR(s.camera.fovYDegrees, 0.5 * 180.0 / 3.14159265358979, 1e-9);
    ASSERT_EQ(s.lights.size(), 1u);
    EXPECT_EQ(s.lights[0].type, LightType::Spot);
    EXPECT_NEAR(s.lights[0].position.y, 3.0, 1e-9);
    EXPECT_NEAR(s.lights[0].direction.y, -1.0, 1e-6);
    // Candela to our convention: irradiance I/d² = ours/(4π d²).
    EXPECT_NEAR(s.lights[0].intensity, 4.0 * 3.14159265358979 * 10.0, 1e-9);
    EXPECT_NEAR(s.lights[0].coneAngleDegrees, 0.5 * 180.0 / 3.14159265358979, 1e-9);
    // No innerConeAngle: the specification's default 0, a falloff from the axis.
    EXPECT_EQ(s.lights[0].innerConeAngleDegrees, 0.0);
    // A given one is used, one past the outer angle is an error at its path.
    std::ifstream original(dir.path() / "t.gltf");
    std::string withInner((std::istreambuf_iterator<char>(original)), std::istreambuf_iterator<char>());
    withInner.replace(withInner.find(R"("outerConeAngle": 0.5)"), 21,
                      R"("outerConeAngle": 0.5, "innerConeAngle": 0.25)");
    dir.write("inner.gltf", withInner);
    EXPECT_NEAR(loadScene(dir.path() / "inner.gltf").lights[0].innerConeAngleDegrees, 0.25 * 180.0 / 3.14159265358979,
                1e-9);
    std::string pastOuter = withInner;
    pastOuter.replace(pastOuter.find("0.25"), 4, "0.75");
    dir.write("past.gltf", pastOuter);
    try {
        loadScene(dir.path() / "past.gltf");
        ADD_FAILURE() << "an innerConeAngle past the outer one loaded";
    } catch (const SceneError& e) {
        EXPECT_NE(std::string(e.what()).find("extensions.KHR_lights_punctual.lights[0].spot.innerConeAngle"),
                  std::string::npos)
            << e.what();
    }
}

TEST(SceneLoader, ASpotsInnerConeAngleIsReadAndChecked) {
    TempDir dir;
    auto scene = [&](const std::string& light) {
        return R"({"camera": {"position": [0, 2, 6], "look_at": [0, 0, 0]}, "materials": {"m": {}},
                   "objects": [{"type": "sphere", "center": [0, 1, 0], "radius": 1, "material": "m"}],
                   "lights": [)" +
               light + "]}";
    };
    const std::string spot = R"({"type": "spot", "position": [0, 4, 0], "direction": [0, -1, 0], "cone_angle": 30)";
    EXPECT_EQ(loadScene(dir.write("hard.json", scene(spot + "}"))).lights[0].innerConeAngleDegrees, 90.0);
    EXPECT_EQ(
        loadScene(dir.write("soft.json", scene(spot + R"(, "inner_cone_angle": 12})"))).lights[0].innerConeAngleDegrees,
        12.0);
    for (const auto& [light, what] : std::vector<std::pair<std::string, std::string>>{
             {spot + R"(, "inner_cone_angle": 31})", "lights[0].inner_cone_angle: must be in [0, cone_angle]"},
             {spot + R"(, "inner_cone_angle": -1})", "lights[0].inner_cone_angle: must be in [0, cone_angle]"},
             {R"({"type": "point", "position": [0, 4, 0], "inner_cone_angle": 10})",
              "lights[0].inner_cone_angle: does not apply to a point light"}}) {
        try {
            loadScene(dir.write("bad.json", scene(light)));
            ADD_FAILURE() << light;
        } catch (const SceneError& e) {
            EXPECT_NE(std::string(e.what()).find(what), std::string::npos) << e.what();
        }
    }
}

TEST(SceneLoader, RejectsAMissingFileAndAFolder) {
    TempDir dir;
    EXPECT_THROW(loadScene(dir.path() / "absent.json"), SceneError);
    EXPECT_THROW(loadScene(dir.path()), SceneError);
}

}  // namespace
}  // namespace shadowlab::scene
