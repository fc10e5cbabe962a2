// tests/scene/camera_animation_test.cpp: glTF camera animations written by the test (JSON + a
// binary buffer) with an analytic motion, loaded as the scene and sampled: LINEAR translation and
// slerped rotation under a moved parent, STEP, CUBICSPLINE; and the scene's "path" block with its
// errors at their JSON paths.
#include "scene/camera_animation.h"

#include <cmath>
#include <cstring>
#include <fstream>
#include <vector>

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include "scene/error.h"
#include "scene/loader.h"
#include "tests/scene/animated_gltf.h"
#include "tests/scene/test_files.h"

namespace shadowlab::scene {
namespace {

using Json = nlohmann::json;
using test::TempDir;
using test::writeAnimatedGltf;
constexpr double kPi = 3.14159265358979323846;

TEST(CameraAnimation, LinearTranslationAndSlerpedRotationUnderAMovedParentFollowTheKeys) {
    TempDir dir;
    const Scene scene = loadScene(writeAnimatedGltf(dir));
    ASSERT_EQ(scene.origin.cameraAnimations.size(), 3u);
    const CameraAnimation& fly = findCameraAnimation(scene, "Fly");
    EXPECT_EQ(fly.start, 0.0);
    EXPECT_EQ(fly.end, 2.0);
    for (double t : {0.0, 0.25, 0.5, 1.0, 1.5, 2.0}) {
        const Camera c = animatedCamera(scene, fly, t);
        // Position: the rig's +10 in X, plus x = t from the keys (linear between 0, 1 and 2).
        EXPECT_NEAR(c.position.x, 10.0 + t, 1e-6) << t;
        EXPECT_NEAR(c.position.y, 1.0, 1e-6);
        EXPECT_NEAR(c.position.z, 5.0, 1e-6);
        // Rotation: 45t degrees about +Y turns the view −Z to (−sin θ, 0, −cos θ); up stays +Y.
        const double theta = 45.0 * t * kPi / 180.0;
        const Vec3 forward = c.lookAt - c.position;
        EXPECT_NEAR(forward.x, -std::sin(theta), 1e-6) << t;
        EXPECT_NEAR(forward.z, -std::cos(theta), 1e-6) << t;
        EXPECT_NEAR(forward.y, 0.0, 1e-6);
        EXPECT_NEAR(c.up.y, 1.0, 1e-6);
        EXPECT_NEAR(c.fovYDegrees, 0.7 * 180.0 / kPi, 1e-9);  // the animated camera's own field of view
    }
    // By index as well as by name; empty picks the first.
    EXPECT_EQ(findCameraAnimation(scene, "1").name, "Hop");
    EXPECT_EQ(findCameraAnimation(scene, "").name, "Fly");
    EXPECT_THROW(findCameraAnimation(scene, "Nope"), InputError);
}

TEST(CameraAnimation, StepHoldsEachKeyAndCubicSplineFollowsItsHermiteCurve) {
    TempDir dir;
    const Scene scene = loadScene(writeAnimatedGltf(dir));
    const CameraAnimation& hop = findCameraAnimation(scene, "Hop");
    EXPECT_NEAR(animatedCamera(scene, hop, 0.0).position.y, 1.0, 1e-6);
    EXPECT_NEAR(animatedCamera(scene, hop, 0.999).position.y, 1.0, 1e-6);  // STEP holds key 0 until key 1
    EXPECT_NEAR(animatedCamera(scene, hop, 1.0).position.y, 3.0, 1e-6);
    const CameraAnimation& smooth = findCameraAnimation(scene, "Smooth");
    for (double s : {0.0, 0.25, 0.5, 0.75, 1.0}) {
        // Zero tangents: p(s) = p0 + (3s² − 2s³)(p1 − p0), z from 5 to 3.
        const double z = 5.0 + (3 * s * s - 2 * s * s * s) * (3.0 - 5.0);
        EXPECT_NEAR(animatedCamera(scene, smooth, s).position.z, z, 1e-6) << s;
    }
}

TEST(CameraAnimation, AnUnknownInterpolationIsAnErrorNamingTheSampler) {
    TempDir dir;
    try {
        loadScene(writeAnimatedGltf(dir, "BEZIER"));
        FAIL() << "loaded an unknown interpolation";
    } catch (const SceneError& e) {
        EXPECT_NE(std::string(e.what()).find("animations[0].samplers[0].interpolation"), std::string::npos) << e.what();
    }
}

const char* kSceneHead =
    R"({"camera": {"position": [0, 2, 6], "look_at": [0, 0.7, 0], "fov_y": 40, "resolution": [64, 36]},
  "materials": {"matte": {"albedo": [0.8, 0.8, 0.8]}},
  "lights": [{"type": "directional", "direction": [-1, -2, -1]}],
  "objects": [{"type": "sphere", "center": [0, 1, 0], "radius": 1, "material": "matte"}])";

TEST(ScenePathBlock, IsReadWithEveryValue) {
    TempDir dir;
    const Scene s = loadScene(dir.write(
        "p.json",
        std::string(kSceneHead) + R"(, "path": {"kind": "sun-azimuth", "frames": 6, "amount": 15, "light": 0}})"));
    ASSERT_TRUE(s.path.has_value());
    EXPECT_EQ(s.path->kind, "sun-azimuth");
    EXPECT_EQ(s.path->frames, std::optional<int>(6));
    EXPECT_EQ(s.path->amount, std::optional<double>(15.0));
    EXPECT_EQ(s.path->light, std::optional<int>(0));
    EXPECT_FALSE(loadScene(dir.write("none.json", std::string(kSceneHead) + "}")).path.has_value());
}

TEST(ScenePathBlock, BadValuesAreErrorsAtTheirJsonPath) {
    const struct {
        const char* block;
        const char* path;
    } cases[] = {
        {R"({"kind": "zigzag"})", "path.kind"},
        {R"({"frames": 4})", "path.kind"},  // kind is required
        {R"({"kind": "orbit", "frames": 1})", "path.frames"},
        {R"({"kind": "orbit", "frames": 2.5})", "path.frames"},
        {R"({"kind": "orbit", "amount": "lots"})", "path.amount"},
        {R"({"kind": "dolly", "amount": 1.5})", "path.amount"},
        {R"({"kind": "orbit", "speed": 2})", "path.speed"},
        {R"({"kind": "orbit", "light": 0})", "path.light"},
        {R"({"kind": "sun-azimuth", "light": 1})", "path.light"},
        {R"({"kind": "light-move"})", "path.kind"},  // the only light is directional
        {R"({"kind": "orbit", "animation": "Fly"})", "path.animation"},
        {R"({"kind": "gltf-animation"})", "path.kind"},  // a JSON scene holds no animation
        {R"("orbit")", "path"},
    };
    TempDir dir;
    for (const auto& c : cases) {
        const auto file = dir.write("bad.json", std::string(kSceneHead) + ", \"path\": " + c.block + "}");
        try {
            loadScene(file);
            ADD_FAILURE() << "loaded " << c.block;
        } catch (const SceneError& e) {
            EXPECT_EQ(e.jsonPath(), c.path) << c.block << ": " << e.what();
        }
    }
}

}  // namespace
}  // namespace shadowlab::scene
