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
constexpr double kDegreesToRadians = 3.14159265358979323846 / 180.0;

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
    // The whole shadow is in view: no pixel on the image's border is the ground in shadow.
    {
        scene::Scene v = s;
        v.camera.width = 160;
        v.camera.height = 90;
        const scene::RenderSettings settings = scene::resolveSettings(v, {});
        const scene::Frame f = renderReference(v, scene::makeRenderPlan(v, settings), settings.raytrace);
        const float groundId = float(v.objects.size());
        std::size_t cut = 0;
        for (int y = 0; y < 90; ++y)
            for (int x = 0; x < 160; ++x) {
                if (x > 0 && x < 159 && y > 0 && y < 89) continue;
                const std::size_t i = std::size_t(y) * 160 + x;
                cut += f.objectId[i] == groundId && f.ndotl[i] > 0 && f.visibility[i] < 0.5f;
            }
        EXPECT_EQ(cut, 0u) << "the box's shadow runs off the image";
    }
    bool recorded = false;
    for (const auto& [key, text] : s.origin.choices)
        recorded = recorded || (key == "view" && text.find("searched") == 0);
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

// An N × N checkerboard alpha texture of 1 and 0: with MASK, half of a caster is holes.
std::shared_ptr<scene::AlphaTexture> checkerHoles(int n) {
    auto t = std::make_shared<scene::AlphaTexture>();
    t->file = "checker";
    t->width = t->height = n;
    for (int y = 0; y < n; ++y)
        for (int x = 0; x < n; ++x) t->alpha.push_back((x + y) % 2 == 0 ? 1.0f : 0.0f);
    return t;
}

scene::Quad uprightQuad(const Vec3& center, const scene::Vec2& size) {
    scene::Quad q;
    q.center = center;
    q.normal = {0, 0, 1};
    q.size = size;
    scene::quadAxes(q.normal, q.uAxis, q.vAxis);
    return q;
}

// A row of four upright cards (centers x = -3.3, -1.1, 1.1, 3.3; 1.6 wide, 2.4 tall, 0.8 above
// the ground; facing ±Z) 1 in front of a wall (x = ±5, 4 tall, its face at z = -1), over a
// ground. `holes`: the cards are BLEND with a 4 × 4 checkerboard of alpha 1 and 0, which casts as
// MASK would and makes every shadow ray name its nearest blocker (closest hits, no any-hit).
scene::Scene cardsBeforeAWall(bool holes) {
    scene::Scene s;
    s.materials.push_back({"plain", {0.8, 0.8, 0.8}, 1.0});
    scene::Material cards{"cards", {0.8, 0.8, 0.8}, 1.0};
    if (holes) {
        cards.alphaMode = scene::AlphaMode::Blend;
        cards.alphaTexture = checkerHoles(4);
    }
    s.materials.push_back(cards);
    s.objects.push_back({"wall", scene::Box{{-5, 0, -1.2}, {5, 4, -1}}, 0});
    for (int k = 0; k < 4; ++k) s.objects.push_back({"card", uprightQuad({-3.3 + 2.2 * k, 2.0, 0}, {1.6, 2.4}), 1});
    s.lights.push_back({});
    s.origin.modelBounds = s.bounds();
    scene::Quad ground;
    ground.size = {24, 24};
    scene::quadAxes(ground.normal, ground.uAxis, ground.vAxis);
    s.objects.push_back({"ground", ground, 0});  // last and so named: the view search's ground
    return s;
}

TEST(ViewSearch, CasterVarietyCountsTheShadowsWhoseOutlinesShowNotThoseSwallowedByAnothers) {
    // Seen from the front (azimuth 330, 20° up) under a sun from the front (azimuth 45, 35° up)
    // each card casts its own shadow onto the wall's face, the four of equal size: an effective
    // number of casters of 4, a little more where the wall's own shadow shows at its ends. Under
    // a sun from behind (azimuth 180, 35° up) the wall's shadow on the ground reaches z =
    // -1 + 4 / tan 35° = 4.7 and x = ±5: the cards (at most 3.2 tall, |x| <= 4.1) and their
    // shadows lie inside it, so only the wall's outline shows: 1. (Counted by shadowed area, the
    // ground in front of each card, whose nearest blocker is the card, would count for it.)
    scene::Scene s = cardsBeforeAWall(true);
    const double a = 330.0 * kDegreesToRadians, e = 20.0 * kDegreesToRadians;
    s.camera = scene::framedCamera(s.origin.modelBounds,
                                   {std::cos(e) * std::sin(a), std::sin(e), std::cos(e) * std::cos(a)}, 40.0, s.camera);
    s.lights[0].direction = scene::sunDirection(45.0, 35.0);
    const ViewScore front = scoreScene(s, 192);
    s.lights[0].direction = scene::sunDirection(180.0, 35.0);
    const ViewScore behind = scoreScene(s, 192);
    EXPECT_GE(front.casters, 3.5);
    EXPECT_LE(front.casters, 5.0);
    EXPECT_NEAR(behind.casters, 1.0, 0.05);
    // The holes of the cards' shadows show under the front sun; under the sun from behind there
    // is no light through them.
    EXPECT_GT(front.holeEdgeLength, 0.1);
    EXPECT_EQ(behind.holeEdgeLength, 0.0);
    // Opaque cards have no holes: the same view counts none.
    scene::Scene opaque = cardsBeforeAWall(false);
    opaque.camera = s.camera;
    opaque.lights[0].direction = scene::sunDirection(45.0, 35.0);
    EXPECT_EQ(scoreScene(opaque, 192).holeEdgeLength, 0.0);
}

TEST(ViewSearch, ShadowEdgesSeenNearEdgeOnCountByTheirLegibility) {
    // A wall (the plane z = 0, facing +Z) and, 3 in front of it, a 4 × 4 MASK screen of eight
    // vertical stripes (alternately solid and holes); light travelling along (-1, 0, -1) lays the
    // stripes on the wall at x = -5 .. -1. Narrow (4°) views of the point (-3, 0, 0) from 30° and
    // 75° off the wall's normal (toward -X) see only the wall; from 20° toward +X the screen
    // stands in front of part of it. The score counts each lit–shadowed pair on the wall by
    // min(1, |cos| / 0.5) of the view ray against its normal: 1 at 20° and 30°, about cos 75° /
    // 0.5 = 0.52 at 75°; a lit screen texel beside the shadowed wall is a silhouette and does not
    // count. The expected value sums those weights over the wall's pairs in the double-precision
    // reference at the same size.
    scene::Scene s;
    s.materials.push_back({"plain", {0.8, 0.8, 0.8}, 1.0});
    scene::Material screen{"screen", {0.8, 0.8, 0.8}, 1.0};
    screen.alphaMode = scene::AlphaMode::Mask;
    auto stripes = std::make_shared<scene::AlphaTexture>();
    stripes->file = "stripes";
    stripes->width = 8;
    stripes->height = 1;
    for (int x = 0; x < 8; ++x) stripes->alpha.push_back(x % 2 == 0 ? 1.0f : 0.0f);
    screen.alphaTexture = stripes;
    s.materials.push_back(screen);
    s.objects.push_back({"wall", uprightQuad({0, 0, 0}, {40, 40}), 0});
    s.objects.push_back({"screen", uprightQuad({0, 0, 3}, {4, 4}), 1});
    s.lights.push_back({});
    s.lights[0].direction = glm::normalize(Vec3(-1, 0, -1));
    const Vec3 target(-3, 0, 0), normal(0, 0, 1);
    for (const double offNormal : {-20.0, 30.0, 75.0}) {
        const double t = offNormal * kDegreesToRadians;
        s.camera.position = target + 20.0 * Vec3(-std::sin(t), 0, std::cos(t));
        s.camera.lookAt = target;
        s.camera.up = {0, 1, 0};
        s.camera.fovYDegrees = 4.0;
        s.camera.near = 0.1;
        s.camera.far = 100.0;
        s.camera.width = 192;
        s.camera.height = 108;
        const ViewScore v = scoreScene(s, 192);

        const scene::RenderSettings settings = scene::resolveSettings(s, {});
        const scene::Frame f = renderReference(s, scene::makeRenderPlan(s, settings), settings.raytrace);
        const scene::CameraBasis basis = scene::cameraBasis(s.camera);
        auto legibility = [&](int x, int y) {
            return std::min(1.0, std::abs(glm::dot(normal, glm::normalize(scene::pixelDirection(basis, x, y)))) / 0.5);
        };
        auto onWall = [&](std::size_t i) { return f.objectId[i] == 1.0f && f.ndotl[i] > 0; };
        double weighted = 0, pairs = 0;
        for (int y = 0; y < 108; ++y)
            for (int x = 0; x < 192; ++x) {
                const std::size_t i = std::size_t(y) * 192 + x;
                for (const auto& [dx, dy] : {std::pair{1, 0}, std::pair{0, 1}}) {
                    if (x + dx >= 192 || y + dy >= 108) continue;
                    const std::size_t j = std::size_t(y + dy) * 192 + x + dx;
                    if (!onWall(i) || !onWall(j) || (f.visibility[i] < 0.5f) == (f.visibility[j] < 0.5f)) continue;
                    ++pairs;
                    weighted += std::min(legibility(x, y), legibility(x + dx, y + dy));
                }
            }
        ASSERT_GT(pairs, 100.0) << offNormal << "°: the stripes' edges are in view";
        EXPECT_NEAR(v.edgeLength, weighted / 300.0, 0.05 * weighted / 300.0) << offNormal << "° off the normal";
        if (offNormal < 60.0)
            EXPECT_DOUBLE_EQ(weighted, pairs);  // within 60°: every pair counts whole
        else
            EXPECT_LT(weighted, 0.6 * pairs);  // squeezed: about half
        if (offNormal < 0.0) {
            std::size_t screenPixels = 0;
            for (std::size_t i = 0; i < f.pixelCount(); ++i) screenPixels += f.objectId[i] == 2.0f;
            EXPECT_GT(screenPixels, 1000u) << "the screen is in view";
        }
    }
}

TEST(ViewSearch, AlphaBlendModeTestShowsItsBoardsCutOutShadowsFromTheFront) {
    // The glTF sample's test boards stand in the plane z = 0 (facing ±Z), 0.47 in front of the
    // face of a wall (z = -0.47, facing +Z, 2.3 tall, taller than the boards). Their cut-outs'
    // shadows can only land on that face, under a sun from the front (light travelling -Z), and
    // be seen from the front; seen along the row (±X) the face is edge-on, and under a sun from
    // behind the wall's shadow covers the boards'. The chosen view is on the front side within
    // 60° of the face's normal (azimuths 300..60), and shows holes in the shadows.
    const std::filesystem::path file =
        std::filesystem::path(SHADOWLAB_SHARED_SCENES) / "AlphaBlendModeTest" / "AlphaBlendModeTest.gltf";
    if (!std::filesystem::exists(file)) GTEST_SKIP() << file << " is not here";
    scene::Scene s = scene::loadScene(file);
    scene::applyGround(s, std::nullopt);
    const ViewSearchResult r = searchViewAndSun(s, {});
    EXPECT_LT(r.sunDirection.z, 0.0) << "a sun from the front";
    const Vec3 forward = scene::cameraBasis(r.camera).forward;
    const double horizontal = std::hypot(forward.x, forward.z);
    ASSERT_GT(horizontal, 0.0);
    EXPECT_GE(-forward.z / horizontal, 0.5 - 1e-9) << "within 60° of the wall's normal, from the front";
    EXPECT_TRUE(r.holes);
    EXPECT_GT(r.best.holeEdgeLength, 0.0);
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
