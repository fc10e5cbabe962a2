// tests/raytrace/view_search_test.cpp: the view and sun search on a model outside, a room with
// an opening in its roof, and Sponza: the sun is above the horizon, the camera is outside or
// inside as the model asks, and the chosen view shows shadow by the reference's own count.
#include "raytrace/view_search.h"

#include <filesystem>

#include <gtest/gtest.h>

#include "raytrace/renderer.h"
#include "scene/camera.h"
#include "scene/loader.h"
#include "scene/model_view.h"
#include "scene/render_plan.h"
#include "scene/settings.h"
#include "tests/scene/camera_gltf.h"
#include "tests/scene/gltf_files.h"
#include "tests/scene/test_files.h"

namespace shadowlab::raytrace {
namespace {

using scene::Vec3;

// Of the pixels the reference sees lit-facing (N·L > 0), the share in cast shadow (V < 0.5):
// counted by the double-precision reference, not by the search's float thumbnails.
double referenceShadowedShare(scene::Scene s, int width, int height, double* groundShadowShare = nullptr) {
    s.camera.width = width;
    s.camera.height = height;
    const scene::RenderSettings settings = scene::resolveSettings(s, {});
    const scene::Frame f = renderReference(s, scene::makeRenderPlan(s, settings), settings.raytrace);
    std::size_t facing = 0, shadowed = 0, groundShadow = 0;
    const float groundId = float(s.objects.size());  // the added ground is the last object
    for (std::size_t i = 0; i < f.pixelCount(); ++i) {
        if (f.objectId[i] == 0 || !(f.ndotl[i] > 0)) continue;
        ++facing;
        if (f.visibility[i] < 0.5f) {
            ++shadowed;
            groundShadow += f.objectId[i] == groundId;
        }
    }
    if (groundShadowShare) *groundShadowShare = double(groundShadow) / double(f.pixelCount());
    return facing ? double(shadowed) / double(facing) : 0.0;
}

bool inside(const scene::Bounds& b, const Vec3& p) {
    return p.x > b.min.x && p.y > b.min.y && p.z > b.min.z && p.x < b.max.x && p.y < b.max.y && p.z < b.max.z;
}

TEST(ViewSearch, AModelOutsideIsSeenFromOutsideUnderASunAboveTheHorizonWithItsShadowInView) {
    test::TempDir dir;
    scene::Scene s = scene::loadScene(dir.write("box.gltf", test::boxGltf(R"([{"mesh": 0}])", "[0]")));
    scene::applyGround(s, std::nullopt);
    ASSERT_EQ(s.objects.size(), 2u);
    const ViewSearchResult r = searchViewAndSun(s, {});
    EXPECT_FALSE(r.interior);
    EXPECT_EQ(r.views, 24);
    EXPECT_EQ(r.suns, 24);
    // The sun is one of the candidates: 35° or more above the horizon.
    EXPECT_GE(scene::sunAngles(r.sunDirection).y, 35.0 - 1e-9);
    EXPECT_FALSE(inside(s.origin.modelBounds, r.camera.position));
    EXPECT_GT(r.camera.position.y, 0.0);
    // Not from the sun's side: the view does not look the way the light travels.
    EXPECT_LT(glm::dot(scene::cameraBasis(r.camera).forward, r.sunDirection), 0.5);

    chooseViewAndSun(s);
    EXPECT_EQ(s.camera.position, r.camera.position);  // deterministic: the same search, the same answer
    EXPECT_EQ(s.lights[0].direction, r.sunDirection);
    double groundShadow = 0;
    const double share = referenceShadowedShare(s, 160, 90, &groundShadow);
    EXPECT_GT(share, 0.08);
    EXPECT_LT(share, 0.9);
    EXPECT_GT(groundShadow, 0.02);  // the box's shadow on the ground fills 2% of the image or more
    bool recorded = false;
    for (const auto& [key, text] : s.origin.choices) recorded = recorded || (key == "view" && text.find("searched") == 0);
    EXPECT_TRUE(recorded);
}

TEST(ViewSearch, CameraAutoLetsTheFilesCamerasCompeteWithTheSearchedViews) {
    test::TempDir dir;
    scene::Scene s = scene::loadScene(dir.write("box.gltf", test::cameraBoxGltf()));
    EXPECT_FALSE(s.origin.chooseView);  // the file's first camera, by default
    scene::applyCameraOption(s, "auto");
    scene::applyGround(s, std::nullopt);
    ViewSearchOptions o;
    o.chooseSun = false;
    const ViewSearchResult r = searchViewAndSun(s, o);
    EXPECT_EQ(r.views, 24 + 2);
    EXPECT_EQ(r.suns, 1);
}

TEST(ViewSearch, TheSearchIsBetterThanTheFramedPlaceholder) {
    // The loader's placeholder view and sun (from above-front, the sun behind the camera) show
    // less shadow than the search's choice, scored the same way.
    test::TempDir dir;
    scene::Scene s = scene::loadScene(dir.write("box.gltf", test::boxGltf(R"([{"mesh": 0}])", "[0]")));
    scene::applyGround(s, std::nullopt);
    const double before = scoreScene(s, 64).score;
    chooseViewAndSun(s);
    EXPECT_GT(scoreScene(s, 64).score, before);
}

// A 10 x 4 x 10 room of quads, its roof open over the strip |x| < 1, with a pillar box under the
// opening and one standing in a corner.
scene::Scene room() {
    scene::Scene s;
    s.materials.push_back({"m", {0.8, 0.8, 0.8}, 1.0});
    auto quad = [&](Vec3 c, Vec3 n, scene::Vec2 size) {
        scene::Quad q;
        q.center = c;
        q.normal = n;
        q.size = size;
        scene::quadAxes(q.normal, q.uAxis, q.vAxis);
        s.objects.push_back({"quad", q, 0});
    };
    quad({0, 0, 0}, {0, 1, 0}, {10, 10});
    quad({5, 2, 0}, {1, 0, 0}, {10, 4});  // u along Z, v along Y
    quad({-5, 2, 0}, {1, 0, 0}, {10, 4});
    quad({0, 2, 5}, {0, 0, 1}, {10, 4});  // u along X
    quad({0, 2, -5}, {0, 0, 1}, {10, 4});
    quad({-3, 4, 0}, {0, 1, 0}, {4, 10});
    quad({3, 4, 0}, {0, 1, 0}, {4, 10});
    s.objects.push_back({"pillar", scene::Box{{-0.3, 0, -0.3}, {0.3, 3.5, 0.3}}, 0});
    s.objects.push_back({"corner", scene::Box{{3.5, 0, 3.5}, {4.5, 2, 4.5}}, 0});
    s.lights.push_back({});
    s.origin.chooseView = s.origin.chooseSun = true;
    s.origin.modelBounds = s.bounds();
    return s;
}

TEST(ViewSearch, ARoomIsSeenFromInsideWithTheSunComingInThroughItsOpening) {
    scene::Scene s = room();
    const ViewSearchResult r = searchViewAndSun(s, {});
    EXPECT_TRUE(r.interior);
    // 50 probes (x, z in -4, -2, 0, 2, 4; y = 0.8 and 1.6): the two in the pillar (x = z = 0) and
    // the two in the corner box (x = z = 4) meet back faces only and are left out.
    EXPECT_EQ(r.probePoints, 46);
    EXPECT_GE(r.enclosedPoints, 12);
    EXPECT_TRUE(inside(s.bounds(), r.camera.position));
    EXPECT_GE(scene::sunAngles(r.sunDirection).y, 35.0 - 1e-9);
    chooseViewAndSun(s);
    const double share = referenceShadowedShare(s, 160, 90);
    // Sun through a 2-wide opening of a 10-wide roof: most of the room is in shadow, not all.
    EXPECT_GT(share, 0.1);
    EXPECT_LT(share, 0.97);
}

TEST(ViewSearch, SponzaIsSeenFromInsideInSeconds) {
    const std::filesystem::path file = std::filesystem::path(SHADOWLAB_SHARED_SCENES) / "Sponza" / "Sponza.gltf";
    if (!std::filesystem::exists(file)) GTEST_SKIP() << file << " is not here";
    scene::Scene s = scene::loadScene(file);
    EXPECT_TRUE(scene::hasOwnGround(s));
    const std::size_t objects = s.objects.size();  // one per glTF material
    scene::applyGround(s, std::nullopt);
    EXPECT_EQ(s.objects.size(), objects);  // its own floor: no ground added
    const ViewSearchResult r = searchViewAndSun(s, {});
    EXPECT_TRUE(r.interior);
    EXPECT_TRUE(inside(s.bounds(), r.camera.position));
    EXPECT_LT(r.seconds, 30.0);  // about 1 s on 2 cores; generous for a loaded machine
    chooseViewAndSun(s);
    const double share = referenceShadowedShare(s, 128, 72);
    EXPECT_GT(share, 0.1);
    EXPECT_LT(share, 0.9);
}

}  // namespace
}  // namespace shadowlab::raytrace
