// tests/scene/model_view_test.cpp: picking a glTF file's camera (--camera, a mesh object's
// "camera" key), the ground under a model, the sun's direction from azimuth and elevation.
#include "scene/model_view.h"

#include <cmath>

#include <gtest/gtest.h>

#include "scene/camera.h"
#include "scene/error.h"
#include "scene/loader.h"
#include "tests/scene/camera_gltf.h"
#include "tests/scene/test_files.h"

namespace shadowlab::scene {
namespace {

constexpr double kPi = 3.14159265358979323846;

void expectNear(const Vec3& a, const Vec3& b, double tol = 1e-9) {
    EXPECT_NEAR(a.x, b.x, tol);
    EXPECT_NEAR(a.y, b.y, tol);
    EXPECT_NEAR(a.z, b.z, tol);
}

TEST(ModelView, AModelSceneListsItsCamerasAndUsesTheFirst) {
    test::TempDir dir;
    const Scene s = loadScene(dir.write("box.gltf", test::cameraBoxGltf()));
    ASSERT_EQ(s.origin.cameras.size(), 2u);
    EXPECT_EQ(s.origin.cameras[0].name, "Front");
    EXPECT_EQ(s.origin.cameras[1].name, "Side");
    EXPECT_FALSE(s.origin.chooseView);
    expectNear(s.camera.position, {0.5, 0.25, 3});
    EXPECT_NEAR(s.camera.fovYDegrees, 0.7 * 180 / kPi, 1e-9);
}

TEST(ModelView, ANamedCameraIsPlacedWhereItsGltfNodeIs) {
    test::TempDir dir;
    for (const char* spec : {"Side", "1"}) {
        Scene s = loadScene(dir.write("box.gltf", test::cameraBoxGltf()));
        applyCameraOption(s, spec);
        // The node's translation, and its 90° turn about Y takes the camera's −Z to −X.
        expectNear(s.camera.position, {4, 0.25, 0.125});
        expectNear(glm::normalize(s.camera.lookAt - s.camera.position), {-1, 0, 0}, 1e-9);
        EXPECT_NEAR(s.camera.fovYDegrees, 0.5 * 180 / kPi, 1e-9);
        EXPECT_DOUBLE_EQ(s.camera.near, 0.02);
        EXPECT_DOUBLE_EQ(s.camera.far, 40);
        EXPECT_EQ(s.camera.width, 1280);  // the image size stays the scene's
    }
}

TEST(ModelView, AnUnknownCameraIsBadInputThatListsTheCameras) {
    test::TempDir dir;
    Scene s = loadScene(dir.write("box.gltf", test::cameraBoxGltf()));
    for (const char* spec : {"Top", "2", "-1"}) {
        try {
            applyCameraOption(s, spec);
            ADD_FAILURE() << spec << " was accepted";
        } catch (const InputError& e) {
            const std::string what = e.what();
            EXPECT_NE(what.find("'Front'"), std::string::npos) << what;
            EXPECT_NE(what.find("'Side'"), std::string::npos) << what;
        }
    }
    applyCameraOption(s, "auto");
    EXPECT_TRUE(s.origin.chooseView);
}

TEST(ModelView, AModelWithoutCameraOrLightAsksForASearch) {
    test::TempDir dir;
    const Scene s = loadScene(dir.write("box.gltf", test::cameraBoxGltf(false)));
    EXPECT_TRUE(s.origin.cameras.empty());
    EXPECT_TRUE(s.origin.chooseView);
    EXPECT_TRUE(s.origin.chooseSun);
    EXPECT_TRUE(s.origin.modelScene);
}

std::string jsonWithModel(const std::string& objectExtra, const std::string& camera) {
    return R"({"camera": )" + camera + R"(, "materials": {"m": {}},
        "lights": [{"type": "directional", "direction": [0, -1, 0]}],
        "objects": [{"type": "mesh", "file": "box.gltf", "translate": [10, 0, 0], "material": "m")" +
           objectExtra + "}]}";
}

TEST(ModelView, AMeshObjectsCameraKeyTakesTheViewFromItsFileMovedWithTheObject) {
    test::TempDir dir;
    dir.write("box.gltf", test::cameraBoxGltf());
    const Scene s =
        loadScene(dir.write("a.json", jsonWithModel(R"(, "camera": "Side")", R"({"resolution": [320, 180]})")));
    expectNear(s.camera.position, {14, 0.25, 0.125});  // the node's position, translated with the object
    expectNear(glm::normalize(s.camera.lookAt - s.camera.position), {-1, 0, 0}, 1e-9);
    EXPECT_EQ(s.camera.width, 320);
    ASSERT_EQ(s.origin.cameras.size(), 2u);
    // Without a "camera" block at all, by index.
    const Scene t = loadScene(dir.write("b.json", R"({"materials": {"m": {}},
        "lights": [{"type": "directional", "direction": [0, -1, 0]}],
        "objects": [{"type": "mesh", "file": "box.gltf", "material": "m", "camera": 0}]})"));
    expectNear(t.camera.position, {0.5, 0.25, 3});
}

TEST(ModelView, TwoObjectsNamingOneFileEachListItsCamerasAndEitherMayNameTheView) {
    // The file is read once (the mesh cache), but each object places its cameras by its own transform.
    test::TempDir dir;
    dir.write("box.gltf", test::cameraBoxGltf());
    const Scene s = loadScene(dir.write("two.json", R"({"camera": {}, "materials": {"m": {}},
        "lights": [{"type": "directional", "direction": [0, -1, 0]}],
        "objects": [{"type": "mesh", "file": "box.gltf", "material": "m"},
                    {"type": "mesh", "file": "box.gltf", "translate": [0, 0, -20], "material": "m", "camera": "Front"}]})"));
    ASSERT_EQ(s.origin.cameras.size(), 4u);
    expectNear(s.origin.cameras[0].camera.position, {0.5, 0.25, 3});
    expectNear(s.origin.cameras[2].camera.position, {0.5, 0.25, -17});
    expectNear(s.camera.position, {0.5, 0.25, -17});
}

TEST(ModelView, AMeshObjectsCameraKeyRefusesAViewGivenTwiceOrACameraTheFileLacks) {
    test::TempDir dir;
    dir.write("box.gltf", test::cameraBoxGltf());
    const auto expectError = [&](const std::string& text, const std::string& part) {
        try {
            loadScene(dir.write("bad.json", text));
            ADD_FAILURE() << "accepted: " << text;
        } catch (const SceneError& e) {
            EXPECT_NE(std::string(e.what()).find(part), std::string::npos) << e.what();
        }
    };
    expectError(jsonWithModel(R"(, "camera": "Side")", R"({"position": [0, 1, 5], "look_at": [0, 0, 0]})"),
                "camera.position");
    expectError(jsonWithModel(R"(, "camera": 7)", "{}"), "objects[0].camera");
    expectError(jsonWithModel(R"(, "camera": "Top")", "{}"), "'Side'");
}

TEST(ModelView, AModelWithoutAFloorGetsAGroundJustBelowIt) {
    test::TempDir dir;
    Scene s = loadScene(dir.write("box.gltf", test::cameraBoxGltf(false)));
    EXPECT_FALSE(hasOwnGround(s));
    applyGround(s, std::nullopt);
    ASSERT_EQ(s.objects.size(), 2u);
    const Quad& q = std::get<Quad>(s.objects.back().shape);
    // The box spans [0,1] x [0,0.5] x [0,0.25]: side max(1, 0.25) + 3 x 0.5, centered under it.
    EXPECT_DOUBLE_EQ(q.size.x, 2.5);
    EXPECT_DOUBLE_EQ(q.size.y, 2.5);
    EXPECT_NEAR(q.center.x, 0.5, 1e-12);
    EXPECT_NEAR(q.center.z, 0.125, 1e-12);
    EXPECT_LT(q.center.y, 0.0);
    EXPECT_GT(q.center.y, -1e-3);
    expectNear(q.normal, {0, 1, 0});
    EXPECT_EQ(s.materials[std::size_t(s.objects.back().material)].name, "ground");
}

TEST(ModelView, ALowSunGrowsTheAddedGroundToHoldTheModelsShadow) {
    test::TempDir dir;
    const Scene loaded = loadScene(dir.write("box.gltf", test::cameraBoxGltf(false)));
    auto groundSide = [](const Scene& s) { return std::get<Quad>(s.objects.back().shape).size.x; };
    // The box spans [0,1] x [0,0.5] x [0,0.25]; its ground's side is 2.5 (above).
    Scene high = loaded;
    applyGround(high, std::nullopt);
    applySunOption(high, "0,50");
    fitGroundToSun(high);
    EXPECT_DOUBLE_EQ(groundSide(high), 2.5);  // 0.5 / tan 50° = 0.42 fits the default
    // 20° up: the shadow reaches 0.5 / tan 20° = 1.3737 from the base, on every side.
    Scene low = loaded;
    applyGround(low, std::nullopt);
    applySunOption(low, "0,20");
    fitGroundToSun(low);
    EXPECT_NEAR(groundSide(low), 1.0 + 2.0 * 0.5 / std::tan(20.0 * kPi / 180.0), 1e-9);
    EXPECT_TRUE(low.origin.notes.empty());
    bool said = false;
    for (const auto& [key, text] : low.origin.choices)
        said |= key == "ground" &&
                text.find("grown from 2.5 to hold the shadow of a sun 20 degrees up") != std::string::npos;
    EXPECT_TRUE(said);
    // 4° up: grown only to what a 10° sun needs (1 + 2 · 0.5 / tan 10° = 6.671), with a note that the
    // shadow, 0.5 / tan 4° = 7.15 long, runs past it.
    Scene grazing = loaded;
    applyGround(grazing, std::nullopt);
    applySunOption(grazing, "0,4");
    fitGroundToSun(grazing);
    EXPECT_NEAR(groundSide(grazing), 1.0 + 2.0 * 0.5 / std::tan(10.0 * kPi / 180.0), 1e-9);
    ASSERT_EQ(grazing.origin.notes.size(), 1u);
    EXPECT_NE(grazing.origin.notes[0].find("shadow 7.15 from its base"), std::string::npos) << grazing.origin.notes[0];
    EXPECT_NE(grazing.origin.notes[0].find("runs off the ground's edge"), std::string::npos);
    // No added ground, or a sun still to be searched (it is searched at 35° or more): nothing.
    Scene none = loaded;
    applyGround(none, false);
    applySunOption(none, "0,4");
    const std::size_t objects = none.objects.size();
    fitGroundToSun(none);
    EXPECT_EQ(none.objects.size(), objects);
    EXPECT_TRUE(none.origin.notes.empty());
    Scene searched = loaded;
    applyGround(searched, std::nullopt);
    searched.lights[0].direction = sunDirection(0, 4);
    ASSERT_TRUE(searched.origin.chooseSun);
    fitGroundToSun(searched);
    EXPECT_DOUBLE_EQ(groundSide(searched), 2.5);
}

TEST(ModelView, NoGroundWhenAskedOrWhenTheModelHasAFloor) {
    test::TempDir dir;
    Scene s = loadScene(dir.write("box.gltf", test::cameraBoxGltf(false)));
    applyGround(s, false);
    EXPECT_EQ(s.objects.size(), 1u);
    // A wide floor at the bottom of the bounds: a floor of its own.
    Scene withFloor = s;
    Quad floor;
    floor.center = {0.5, 0, 0.125};
    floor.size = {4, 4};
    quadAxes(floor.normal, floor.uAxis, floor.vAxis);
    withFloor.objects.push_back({"floor", floor, 0});
    withFloor.origin.modelBounds = {};
    EXPECT_TRUE(hasOwnGround(withFloor));
    applyGround(withFloor, std::nullopt);
    EXPECT_EQ(withFloor.objects.size(), 2u);
}

TEST(ModelView, AJsonScenesGroundKeyAddsOne) {
    test::TempDir dir;
    const std::string scene = R"({"camera": {"position": [0, 2, 6], "look_at": [0, 0, 0]}, "ground": true,
        "materials": {"m": {}}, "lights": [{"type": "directional", "direction": [0, -1, 0]}],
        "objects": [{"type": "sphere", "center": [0, 1, 0], "radius": 1, "material": "m"}]})";
    Scene s = loadScene(dir.write("g.json", scene));
    applyGround(s, std::nullopt);
    ASSERT_EQ(s.objects.size(), 2u);
    EXPECT_NEAR(std::get<Quad>(s.objects.back().shape).center.y, -1e-4 * std::sqrt(12.0), 1e-12);
    Scene off = loadScene(dir.write("g.json", scene));
    applyGround(off, false);  // --no-ground wins over the key
    EXPECT_EQ(off.objects.size(), 1u);
}

TEST(ModelView, AJsonCameraWithoutFarSeesTheWholeSceneEvenAnAddedGround) {
    // Camera at (30, 12, 40) over a 400 x 400 ground at y = 0: the farthest corner is
    // (−200, 0, −200), √(230² + 12² + 240²) away; far is a hundredth beyond it. A given far stays.
    test::TempDir dir;
    const auto scene = [&](const std::string& cameraExtra, const std::string& ground) {
        return R"({"camera": {"position": [30, 12, 40], "look_at": [0, 0, 0])" + cameraExtra + R"(}, )" + ground +
               R"("materials": {"m": {}}, "lights": [{"type": "directional", "direction": [0, -1, 0]}],
                  "objects": [{"type": "quad", "center": [0, 0, 0], "normal": [0, 1, 0], "size": [400, 400], "material": "m"},
                              {"type": "sphere", "center": [0, 1, 0], "radius": 1, "material": "m"}]})";
    };
    const Scene fitted = loadScene(dir.write("a.json", scene("", "")));
    EXPECT_NEAR(fitted.camera.far, 1.01 * std::sqrt(230.0 * 230 + 12 * 12 + 240.0 * 240), 1e-9);
    const Scene given = loadScene(dir.write("b.json", scene(R"(, "far": 100)", "")));
    EXPECT_EQ(given.camera.far, 100.0);
    // A near beyond the old constant far is not an error when far is left to the scene.
    const Scene nearOnly = loadScene(dir.write("c.json", scene(R"(, "near": 150)", "")));
    EXPECT_GT(nearOnly.camera.far, 150.0);
    // An added ground (sized from the bounds, larger than them) is refitted: every corner of
    // it lies within far.
    Scene grounded = loadScene(dir.write("d.json", scene("", R"("ground": true, )")));
    applyGround(grounded, std::nullopt);
    const Quad& q = std::get<Quad>(grounded.objects.back().shape);
    for (const double u : {-0.5, 0.5})
        for (const double v : {-0.5, 0.5}) {
            const Vec3 corner = q.center + u * q.size.x * q.uAxis + v * q.size.y * q.vAxis;
            EXPECT_LT(glm::length(corner - grounded.camera.position), grounded.camera.far);
        }
}

TEST(ModelView, SunAzimuthRunsFromZTowardXAndElevationUpFromTheHorizon) {
    // Azimuth 0: the sun toward +Z, its light travelling toward −Z; azimuth 90: toward +X.
    expectNear(sunDirection(0, 0), {0, 0, -1});
    expectNear(sunDirection(90, 0), {-1, 0, 0});
    expectNear(sunDirection(0, 90), {0, -1, 0});
    expectNear(sunDirection(90, 30), {-std::sqrt(3.0) / 2, -0.5, 0});
    const glm::dvec2 a = sunAngles(sunDirection(225, 40));
    EXPECT_NEAR(a.x, 225, 1e-9);
    EXPECT_NEAR(a.y, 40, 1e-9);
}

TEST(ModelView, SunAtAQuarterTurnTravelsExactlyInAnAxisPlane) {
    // sin(180° in radians) is 1.2e-16 in double, not 0: a sun at azimuth 180 computed that way
    // gives a face whose normal is exactly +X an N·L of 1e-16 instead of 0, so a face edge-on to
    // the light would count as lit-facing. At every quarter turn the off-plane component is 0.
    for (const double el : {0.0, 35.0, 55.0, 75.0, -20.0}) {
        EXPECT_EQ(sunDirection(0, el).x, 0.0) << el;
        EXPECT_EQ(sunDirection(180, el).x, 0.0) << el;
        EXPECT_EQ(sunDirection(-180, el).x, 0.0) << el;
        EXPECT_EQ(sunDirection(360, el).x, 0.0) << el;
        EXPECT_EQ(sunDirection(90, el).z, 0.0) << el;
        EXPECT_EQ(sunDirection(270, el).z, 0.0) << el;
        EXPECT_EQ(sunDirection(-90, el).z, 0.0) << el;
        EXPECT_EQ(glm::dot(Vec3(1, 0, 0), -sunDirection(180, el)), 0.0) << el;
    }
    for (const double az : {0.0, 45.0, 135.0, 180.0, 300.0}) {
        EXPECT_EQ(sunDirection(az, 90).x, 0.0) << az;
        EXPECT_EQ(sunDirection(az, 90).z, 0.0) << az;
        EXPECT_EQ(sunDirection(az, 90).y, -1.0) << az;
    }
    // Between quarter turns the formula is the usual one: at 45° both components are cos e·√½,
    // at 225° both negated, the direction stays a unit vector.
    const double h = std::cos(35 * kPi / 180) * std::sqrt(0.5);
    expectNear(sunDirection(45, 35), {-h, -std::sin(35 * kPi / 180), -h});
    expectNear(sunDirection(225, 35), {h, -std::sin(35 * kPi / 180), h});
    for (const double az : {10.0, 100.0, 190.0, 280.0, 359.0})
        EXPECT_NEAR(glm::length(sunDirection(az, 35)), 1.0, 1e-15) << az;
}

// The unit cube [−0.5, 0.5]³ and the view search's framing of it from azimuth 30, 20° up, 16:9.
Bounds unitCube() {
    Bounds b;
    b.extend(Vec3(-0.5, -0.5, -0.5));
    b.extend(Vec3(0.5, 0.5, 0.5));
    return b;
}
Camera framedUnitCube() {
    Camera base;
    base.width = 1280;
    base.height = 720;
    const double a = 30 * kPi / 180, e = 20 * kPi / 180;
    return framedCamera(unitCube(), {std::cos(e) * std::sin(a), std::sin(e), std::cos(e) * std::cos(a)}, 40.0, base);
}
// Where a point lies in a view: the larger of |x| and |y| over the image's half-extent at its depth.
double reach(const CameraBasis& v, const Vec3& p) {
    const Vec3 q = p - v.position;
    const double z = glm::dot(q, v.forward);
    return std::max(std::abs(glm::dot(q, v.right)) / (z * v.tanHalfFovY * v.aspect),
                    std::abs(glm::dot(q, v.up)) / (z * v.tanHalfFovY));
}

TEST(ModelView, AFramedViewMovesBackJustEnoughToHoldTheModelsShadow) {
    // A unit cube [−0.5, 0.5]³ seen from azimuth 30, 20° up (the view search's framing, 16:9).
    // A sun 25° up at azimuth 300 sends its light along h = (−sin 300°, 0, −cos 300°) =
    // (0.866, 0, −0.5) and down: a corner Δ above the base y = −0.5 casts its shadow on that
    // plane Δ/tan 25° along h, up to 2.14 beyond the cube, off to the side of this view. Straight
    // overhead the cube casts under itself, and the framing stays as it was.
    const Bounds b = unitCube();
    const Camera framed = framedUnitCube();
    const Camera overhead = framedWithShadow(framed, b, sunDirection(300, 90));
    EXPECT_EQ(overhead.position, framed.position);
    EXPECT_EQ(overhead.lookAt, framed.lookAt);

    const Camera low = framedWithShadow(framed, b, sunDirection(300, 25));
    const CameraBasis f = cameraBasis(framed), c = cameraBasis(low);
    EXPECT_NEAR(glm::dot(f.forward, c.forward), 1.0, 1e-12) << "the same view direction";
    EXPECT_GE(glm::length(low.lookAt - low.position), glm::length(framed.lookAt - framed.position));
    // Every corner and every corner's shadow within 1/1.1 of the half-extents, the tightest of
    // them on that margin (no farther back than needed); in the framed view some shadow corner
    // lay outside the image.
    const Vec3 h(std::sqrt(3.0) / 2, 0, -0.5);
    double tightest = 0, framedReach = 0;
    for (int k = 0; k < 8; ++k) {
        const Vec3 corner((k & 1) ? 0.5 : -0.5, (k & 2) ? 0.5 : -0.5, (k & 4) ? 0.5 : -0.5);
        const double above = corner.y + 0.5;
        const Vec3 shadow = corner + (above / std::tan(25 * kPi / 180)) * h - Vec3(0, above, 0);
        for (const Vec3& p : {corner, shadow}) {
            EXPECT_LE(reach(c, p), 1 / 1.1 + 1e-9) << p.x << " " << p.y << " " << p.z;
            tightest = std::max(tightest, reach(c, p));
            framedReach = std::max(framedReach, reach(f, p));
        }
    }
    EXPECT_NEAR(tightest, 1 / 1.1, 1e-9);
    EXPECT_GT(framedReach, 1.0);
}

// The same cube on the ground addGround gives it (side 1 + 3·1 = 4, x and z in [−2, 2]) under a
// sun 5° up at azimuth 300: the shadow runs 0.5 + 1/tan 5° ≈ 11.9 along h, far past the ground.
// Only what lands on the ground counts: the shadow's rectangle on the base plane, x from −0.5 to
// 0.5 + 11.43·0.866 and z from 0.5 − 11.43·0.5 to 0.5, cut to [−2, 2]², is [−0.5, 2] x [−2, 0.5];
// the view holds its corners and the cube's on the margin, and stays far closer than the one that
// holds the whole shadow.
TEST(ModelView, AFramedViewHoldsOnlyTheShadowThatLandsOnTheGround) {
    const Bounds b = unitCube();
    Bounds ground = b;
    ground.extend(Vec3(-2, -0.5, -2));
    ground.extend(Vec3(2, -0.5, 2));
    const Camera framed = framedUnitCube();
    const Camera whole = framedWithShadow(framed, b, sunDirection(300, 5));
    const Camera cut = framedWithShadow(framed, b, sunDirection(300, 5), ground);
    const CameraBasis c = cameraBasis(cut);
    double tightest = 0;
    std::vector<Vec3> must;
    for (int k = 0; k < 8; ++k) must.push_back({(k & 1) ? 0.5 : -0.5, (k & 2) ? 0.5 : -0.5, (k & 4) ? 0.5 : -0.5});
    for (const double x : {-0.5, 2.0})
        for (const double z : {-2.0, 0.5}) must.push_back({x, -0.5, z});
    for (const Vec3& p : must) {
        EXPECT_LE(reach(c, p), 1 / 1.1 + 1e-9) << p.x << " " << p.y << " " << p.z;
        tightest = std::max(tightest, reach(c, p));
    }
    EXPECT_NEAR(tightest, 1 / 1.1, 1e-9);
    EXPECT_LT(2.0 * glm::length(cut.lookAt - cut.position), glm::length(whole.lookAt - whole.position));
    // A shadow that stays on the ground is framed exactly as without the receivers.
    const Camera high = framedWithShadow(framed, b, sunDirection(300, 45), ground);
    EXPECT_EQ(high.position, framedWithShadow(framed, b, sunDirection(300, 45)).position);
}

TEST(ModelView, SunOptionPointsTheDirectionalLightAndRefusesBadText) {
    test::TempDir dir;
    Scene s = loadScene(dir.write("box.gltf", test::cameraBoxGltf(false)));
    applySunOption(s, "90,30");
    expectNear(s.lights[0].direction, {-std::sqrt(3.0) / 2, -0.5, 0});
    EXPECT_FALSE(s.origin.chooseSun);
    EXPECT_TRUE(s.origin.notes.empty());
    // A sun below the horizon is allowed, with a note that says what it gives.
    Scene below = s;
    applySunOption(below, "0,-30");
    expectNear(below.lights[0].direction, {0, 0.5, -std::sqrt(3.0) / 2});
    ASSERT_EQ(below.origin.notes.size(), 1u);
    EXPECT_NE(below.origin.notes[0].find("below the horizon"), std::string::npos) << below.origin.notes[0];
    EXPECT_NE(below.origin.notes[0].find("elevation 30"), std::string::npos) << below.origin.notes[0];
    for (const char* bad : {"90", "90;30", "a,b", "0,95", "0,-91", "1,2,3"})
        EXPECT_THROW(applySunOption(s, bad), InputError) << bad;
    Scene point = s;
    point.lights[0].type = LightType::Point;
    EXPECT_THROW(applySunOption(point, "0,45"), InputError);
}

}  // namespace
}  // namespace shadowlab::scene
