// tests/raster/debug_views_test.cpp: the light-frustum view: frustum corners and edges projected
// into the camera (against the pinhole formula written out here), clipping at the camera's near
// plane, insideLightMap on each face of orthographic and perspective frusta, and, on lavapipe with
// validation, the coverage of a spot map (the pyramid's footprint on the plane, computed here),
// a forced narrow map whose lit points outside it are striped, and cascades that hold every slice.
// (The other views are tested in cascades_test.cpp.)
#include "raster/debug_views.h"

#include <cmath>
#include <cstdlib>
#include <set>

#include <gtest/gtest.h>

#include "raster/cascades.h"
#include "raster/renderer.h"
#include "raster/tolerances.h"
#include "scene/frame_io.h"
#include "tests/kit/render_checked.h"
#include "tests/kit/test_scenes.h"

namespace shadowlab::raster {
namespace {

using test::kPi;
using test::Vec3;

// A camera at (0, 0, 5) looking down −z (right = +x, up = +y), 60° vertical field of view,
// 200 x 100 pixels (aspect 2).
scene::CameraBasis testCamera() {
    scene::Camera c;
    c.position = Vec3(0, 0, 5);
    c.lookAt = Vec3(0, 0, 0);
    c.up = Vec3(0, 1, 0);
    c.fovYDegrees = 60.0;
    c.width = 200;
    c.height = 100;
    c.near = 0.1;
    c.far = 100.0;
    return scene::cameraBasis(c);
}

// The pinhole projection for testCamera(), written out: a point (X, Y, Z) is at view depth
// z = 5 − Z, and lands at column W/2·(1 + X/(z·tan 30°·2)), row H/2·(1 − Y/(z·tan 30°)).
glm::dvec3 pinhole(const Vec3& p) {
    const double t = std::tan(30.0 * kPi / 180.0), z = 5.0 - p.z;
    return {100.0 * (1.0 + p.x / (z * t * 2.0)), 50.0 * (1.0 - p.y / (z * t)), z};
}

TEST(FrustumView, BoxCornersAndEdgesProjectWhereThePinholeFormulaPutsThem) {
    // A box along −z: setBasis gives right = dir × Y = +x, up = right × dir = +y. Center
    // (0.5, −0.25, 0), half-width 1, depth −1..2 along −z: corners x in {−0.5, 1.5}, y in
    // {−1.25, 0.75}, z in {1 (near), −2 (far)}.
    LightFrustum f;
    setBasis(f, Vec3(0, 0, -1));
    f.center = Vec3(0.5, -0.25, 0.0);
    f.halfWidth = 1.0;
    f.nearDepth = -1.0;
    f.farDepth = 2.0;
    const std::array<Vec3, 8> corners = frustumCorners(f);
    for (int k = 0; k < 8; ++k) {
        const Vec3 expected((k & 1) ? 1.5 : -0.5, (k & 2) ? 0.75 : -1.25, (k & 4) ? -2.0 : 1.0);
        EXPECT_NEAR(glm::distance(corners[std::size_t(k)], expected), 0.0, 1e-12) << "corner " << k;
    }
    const scene::CameraBasis cam = testCamera();
    std::set<std::pair<int, int>> edges;
    for (const auto& e : kFrustumEdges) {
        const Vec3 a = corners[std::size_t(e[0])], b = corners[std::size_t(e[1])];
        // A box edge joins corners that differ along exactly one axis.
        const Vec3 d = glm::abs(a - b);
        EXPECT_EQ((d.x > 1e-9) + (d.y > 1e-9) + (d.z > 1e-9), 1) << e[0] << "-" << e[1];
        edges.insert({std::min(e[0], e[1]), std::max(e[0], e[1])});
        const auto s = projectSegment(cam, 0.1, a, b);
        ASSERT_TRUE(s.has_value());
        const glm::dvec3 pa = pinhole(a), pb = pinhole(b);
        EXPECT_NEAR(s->a.x, pa.x, 1e-9);
        EXPECT_NEAR(s->a.y, pa.y, 1e-9);
        EXPECT_NEAR(s->a.z, pa.z, 1e-12);
        EXPECT_NEAR(s->b.x, pb.x, 1e-9);
        EXPECT_NEAR(s->b.y, pb.y, 1e-9);
        EXPECT_NEAR(s->b.z, pb.z, 1e-12);
    }
    EXPECT_EQ(edges.size(), 12u) << "an edge is listed twice";
    // A numeric spot check of the formula: corner 0 = (−0.5, −1.25, 1) at z = 4:
    // x = 100·(1 − 0.5/(4·0.57735·2)) = 89.175, y = 50·(1 + 1.25/(4·0.57735)) = 77.063.
    EXPECT_NEAR(projectPoint(cam, corners[0]).x, 89.1747, 1e-3);
    EXPECT_NEAR(projectPoint(cam, corners[0]).y, 77.0633, 1e-3);
}

TEST(FrustumView, PerspectiveCornersLieOnThePyramidAtNearAndFar) {
    // A spot at (0, 4, 0) looking down, tan(half fov) = 0.5, near 1, far 3. The light is vertical,
    // so setBasis's reference axis is X: right = (0, −1, 0) × (1, 0, 0) = (0, 0, 1), up = right ×
    // direction = (1, 0, 0). Each corner is then 0.5·d along x and z at depth d below the light.
    LightFrustum f;
    f.perspective = true;
    setBasis(f, Vec3(0, -1, 0));
    f.position = Vec3(0, 4, 0);
    f.tanHalfFov = 0.5;
    f.near = 1.0;
    f.far = 3.0;
    const std::array<Vec3, 8> corners = frustumCorners(f);
    for (int k = 0; k < 8; ++k) {
        const double d = (k & 4) ? 3.0 : 1.0;
        const Vec3 c = corners[std::size_t(k)];
        EXPECT_NEAR(c.y, 4.0 - d, 1e-12) << k;
        // Across the axis (the xz plane), both coordinates are ±0.5·d (the basis is x/z-aligned).
        EXPECT_NEAR(std::abs(c.x), 0.5 * d, 1e-12) << k;
        EXPECT_NEAR(std::abs(c.z), 0.5 * d, 1e-12) << k;
        EXPECT_TRUE(insideLightMap(f, c)) << "a corner is on the boundary, which is inside";
    }
}

TEST(FrustumView, PixelCentersProjectToThemselves) {
    // The point a pixel's center ray hits (scene::pixelDirection) projects to (x + 0.5, y + 0.5).
    const scene::CameraBasis cam = testCamera();
    for (const auto& [x, y] : {std::pair{0, 0}, std::pair{199, 99}, std::pair{37, 81}}) {
        const ScreenPoint p = projectPoint(cam, cam.position + 3.7 * scene::pixelDirection(cam, x, y));
        EXPECT_NEAR(p.x, x + 0.5, 1e-9);
        EXPECT_NEAR(p.y, y + 0.5, 1e-9);
        EXPECT_NEAR(p.z, 3.7, 1e-12);
    }
}

TEST(FrustumView, SegmentCrossingTheCameraPlaneIsClippedNotWrapped) {
    const scene::CameraBasis cam = testCamera();
    // a = (1, 0.5, 0) at view depth 5, b = (1, 0.5, 10) at −5 (behind the camera). Clipped at
    // depth 0.1: the world point (1, 0.5, 4.9), at x = 100·(1 + 1/(0.1·0.57735·2)) = 966.03,
    // y = 50·(1 − 0.5/(0.1·0.57735)) = −383.01: far right and above, continuing the direction
    // the segment leaves a in. Projecting b itself would put it left of the center (X/z < 0).
    const Vec3 a(1, 0.5, 0), b(1, 0.5, 10);
    const auto s = projectSegment(cam, 0.1, a, b);
    ASSERT_TRUE(s.has_value());
    const glm::dvec3 pa = pinhole(a), clipped = pinhole(Vec3(1, 0.5, 4.9));
    EXPECT_NEAR(s->a.x, pa.x, 1e-9);
    EXPECT_NEAR(s->b.x, clipped.x, 1e-6);
    EXPECT_NEAR(s->b.y, clipped.y, 1e-6);
    EXPECT_NEAR(s->b.z, 0.1, 1e-12);
    EXPECT_NEAR(s->b.x, 966.03, 0.01);
    EXPECT_GT(s->b.x, s->a.x) << "wrapped around through infinity";
    EXPECT_LT(pinhole(b).x, 100.0) << "the unclipped end would have wrapped (the test can fail)";
    // The same segment the other way round clips the same way.
    const auto r = projectSegment(cam, 0.1, b, a);
    ASSERT_TRUE(r.has_value());
    EXPECT_NEAR(r->a.x, clipped.x, 1e-6);
    EXPECT_NEAR(r->b.x, pa.x, 1e-9);
    // Wholly behind the near plane (depths 0.05 and −5): nothing.
    EXPECT_FALSE(projectSegment(cam, 0.1, Vec3(1, 0.5, 4.95), b).has_value());
}

TEST(FrustumView, InsideLightMapOnEachFaceOfAnOrthographicBox) {
    LightFrustum f;
    setBasis(f, Vec3(-1, -2, -1));
    f.center = Vec3(1, 2, 3);
    f.halfWidth = 2.0;
    f.nearDepth = -3.0;
    f.farDepth = 4.0;
    const double e = 1e-6;
    const Vec3 mid = f.center + 0.5 * (f.nearDepth + f.farDepth) * f.direction;  // depth 0.5
    EXPECT_TRUE(insideLightMap(f, mid));
    for (const Vec3 axis : {f.right, -f.right, f.up, -f.up}) {
        EXPECT_TRUE(insideLightMap(f, mid + (2.0 - e) * axis));
        EXPECT_FALSE(insideLightMap(f, mid + (2.0 + e) * axis));
    }
    EXPECT_TRUE(insideLightMap(f, f.center + (-3.0 + e) * f.direction));
    EXPECT_FALSE(insideLightMap(f, f.center + (-3.0 - e) * f.direction));
    EXPECT_TRUE(insideLightMap(f, f.center + (4.0 - e) * f.direction));
    EXPECT_FALSE(insideLightMap(f, f.center + (4.0 + e) * f.direction));
    // A corner region: inside across one axis, outside across the other.
    EXPECT_FALSE(insideLightMap(f, mid + 1.9 * f.right + 2.1 * f.up));
}

TEST(FrustumView, InsideLightMapOnEachFaceOfASpotPyramidAndAPointFace) {
    LightFrustum f;
    f.perspective = true;
    setBasis(f, Vec3(1, -2, 0.5));
    f.position = Vec3(-1, 5, 2);
    f.tanHalfFov = std::tan(30.0 * kPi / 180.0);
    f.near = 1.0;
    f.far = 5.0;
    const double e = 1e-6;
    // At depth 3 along the axis the pyramid reaches 3·tan 30° = 1.7321 across.
    const Vec3 axisPoint = f.position + 3.0 * f.direction;
    const double across = 3.0 * f.tanHalfFov;
    for (const Vec3 axis : {f.right, -f.right, f.up, -f.up}) {
        EXPECT_TRUE(insideLightMap(f, axisPoint + (across - e) * axis));
        EXPECT_FALSE(insideLightMap(f, axisPoint + (across + e) * axis));
    }
    EXPECT_TRUE(insideLightMap(f, f.position + (1.0 + e) * f.direction));
    EXPECT_FALSE(insideLightMap(f, f.position + (1.0 - e) * f.direction));
    EXPECT_TRUE(insideLightMap(f, f.position + (5.0 - e) * f.direction));
    EXPECT_FALSE(insideLightMap(f, f.position + (5.0 + e) * f.direction));
    // Behind the light: the mirror image of an inside point is outside.
    EXPECT_FALSE(insideLightMap(f, f.position - 3.0 * f.direction));
    // A point light's face (tan > 1): any point whose major axis is the face's is across-inside,
    // so only near/far along the axis decide. The +X face, point (d, 0.99d, −0.99d).
    LightFrustum face;
    face.perspective = true;
    setBasis(face, Vec3(1, 0, 0));
    face.position = Vec3(0, 0, 0);
    face.tanHalfFov = 1.05;
    face.near = 0.5;
    face.far = 10.0;
    for (const double d : {0.5 + e, 3.0, 10.0 - e})
        EXPECT_TRUE(insideLightMap(face, Vec3(d, 0.99 * d, -0.99 * d))) << d;
    for (const double d : {0.5 - e, 10.0 + e}) EXPECT_FALSE(insideLightMap(face, Vec3(d, 0.99 * d, -0.99 * d))) << d;
}

// --- On lavapipe, with validation ---

using test::renderChecked;

void maybeWritePng(const DisplayImage& img, const std::string& name) {
    if (const char* dir = std::getenv("SHADOWLAB_TEST_PNG_DIR"))
        scene::writePngDisplay(std::filesystem::path(dir) / (name + ".png"), img.width, img.height, img.rgb);
}

// The spot test's scene: the sphere over the plane, lit by an orange spot 4 above the plane
// at (0.3, 4, 0.2), pointing straight down with a 30° cone.
struct SpotCase {
    test::SphereOverPlane p;
    scene::Scene s;
    SpotCase() {
        p.width = 160;
        p.height = 90;
        s = test::makeScene(p);
        s.lights[0].type = scene::LightType::Spot;
        s.lights[0].position = Vec3(0.3, 4.0, 0.2);
        s.lights[0].direction = Vec3(0, -1, 0);
        s.lights[0].coneAngleDegrees = 30.0;
        s.lights[0].color = Vec3(1.0, 0.5, 0.25);
        s.lights[0].intensity = 200.0;
    }
    // Plane point q (y = 0) lies 4 below the light; inside a downward pyramid of tan t when both
    // its offsets across the axis are within 4·t. The basis of a vertical light is x/z-aligned
    // (setBasis uses world X as reference), so the offsets are |q.x − 0.3| and |q.z − 0.2|.
    double pyramidReach(const Vec3& q) const { return std::max(std::abs(q.x - 0.3), std::abs(q.z - 0.2)) / 4.0; }
    // tan of the angle between q and the axis, seen from the light.
    double coneReach(const Vec3& q) const { return std::hypot(q.x - 0.3, q.z - 0.2) / 4.0; }
};

bool isTint(const float* rgb, const std::array<float, 3>& tint) {
    const glm::dvec3 c(rgb[0], rgb[1], rgb[2]), t(tint[0], tint[1], tint[2]);
    return glm::length(c) > 0.0 && glm::dot(glm::normalize(c), glm::normalize(t)) > 0.9999;
}

TEST(FrustumView, SpotMapHoldsItsPyramidAndAForcedNarrowMapStripesLitPointsOutsideIt) {
    SpotCase c;
    const scene::RasterSettings settings = test::validatedSettings(256, 0.01, 1.0, scene::ShadowFilter::Pcf2x2);
    RenderDebug debug;
    const scene::Frame f = renderChecked(c.s, settings, &debug);
    ASSERT_EQ(debug.layers.size(), 1u);
    ASSERT_TRUE(debug.layers[0].frustum.perspective);
    // The map's field of view is the cone widened by kSpotFovMargin (2%): tan(30.6°).
    const double tMap = std::tan(30.0 * kSpotFovMargin * kPi / 180.0);
    const double tCone = std::tan(30.0 * kPi / 180.0);
    const std::array<float, 3> tint{1.0f, 0.5f, 0.25f};  // the light's colour over its largest component
    const scene::CameraBasis cam = scene::cameraBasis(c.s.camera);

    // The real map: the plane inside the pyramid is Covered (tinted), outside it Outside (the
    // spot does not reach there, so no stripes: the dimmed beauty).
    {
        const std::vector<Coverage> cov = lightMapCoverage(f, c.s, debug);
        const DisplayImage img = lightFrustumView(f, c.s, debug);
        maybeWritePng(img, "frustum_spot");
        ASSERT_EQ(img.width, f.width);
        ASSERT_EQ(img.height, f.height);
        int inside = 0, outside = 0, backdrop = 0;
        for (int y = 0; y < f.height; ++y)
            for (int x = 0; x < f.width; ++x) {
                const std::size_t i = std::size_t(y) * std::size_t(f.width) + std::size_t(x);
                const test::PrimaryHit h = test::primaryHit(c.p, cam, x, y);
                if (h.id != 2 || f.objectId[i] != 2.0f) continue;
                const double r = c.pyramidReach(h.p);
                EXPECT_NE(cov[i], Coverage::Uncovered) << x << "," << y;
                if (r < 0.98 * tMap) {
                    ++inside;
                    EXPECT_EQ(cov[i], Coverage::Covered) << x << "," << y;
                } else if (r > 1.02 * tMap) {
                    ++outside;
                    EXPECT_EQ(cov[i], Coverage::Outside) << x << "," << y;
                    // The backdrop, sRGB beauty × kFrustumViewDim, unless an outline passes here.
                    const float b = kFrustumViewDim * scene::linearToSrgb(std::clamp(f.beauty[3 * i], 0.0f, 1.0f));
                    backdrop += img.rgb[3 * i] == b;
                }
            }
        EXPECT_GT(backdrop, 0.9 * outside);
        EXPECT_GT(inside, 2000);
        EXPECT_GT(outside, 2000);
        // Counted over the whole image: covered pixels carry the light's tint, except under an
        // outline, the legend or a marker (well under a tenth of them).
        int tinted = 0, covered = 0;
        for (std::size_t i = 0; i < cov.size(); ++i)
            if (cov[i] == Coverage::Covered) {
                ++covered;
                tinted += isTint(&img.rgb[3 * i], tint);
            }
        EXPECT_GT(tinted, 0.9 * covered);
    }

    // Forced: the map narrowed to tan 15°, the cone still 30°. Plane points the spot lights
    // (within the cone) but the map does not hold are Uncovered, and striped magenta.
    {
        RenderDebug narrow = debug;
        const double tNarrow = std::tan(15.0 * kPi / 180.0);
        narrow.layers[0].frustum.tanHalfFov = tNarrow;
        const std::vector<Coverage> cov = lightMapCoverage(f, c.s, narrow);
        const DisplayImage img = lightFrustumView(f, c.s, narrow);
        maybeWritePng(img, "frustum_spot_forced");
        int covered = 0, leak = 0, stripe = 0, magenta = 0, outside = 0;
        for (int y = 0; y < f.height; ++y)
            for (int x = 0; x < f.width; ++x) {
                const std::size_t i = std::size_t(y) * std::size_t(f.width) + std::size_t(x);
                const test::PrimaryHit h = test::primaryHit(c.p, cam, x, y);
                if (h.id != 2 || f.objectId[i] != 2.0f) continue;
                const double r = c.pyramidReach(h.p), cone = c.coneReach(h.p);
                if (r < 0.98 * tNarrow) {
                    ++covered;
                    EXPECT_EQ(cov[i], Coverage::Covered) << x << "," << y;
                } else if (r > 1.02 * tNarrow && cone < 0.98 * tCone) {
                    ++leak;
                    EXPECT_EQ(cov[i], Coverage::Uncovered) << x << "," << y;
                    if (((x + y) / kLeakStripeWidth) % 2 == 0) {
                        ++stripe;
                        const std::array<float, 3> v{img.rgb[3 * i], img.rgb[3 * i + 1], img.rgb[3 * i + 2]};
                        magenta += v == kLeakColor;  // unless an outline is drawn over it
                    }
                } else if (r > 1.02 * tNarrow && cone > 1.02 * tCone) {
                    ++outside;
                    EXPECT_EQ(cov[i], Coverage::Outside) << x << "," << y;
                }
            }
        EXPECT_GT(covered, 300);
        EXPECT_GT(leak, 1000);
        EXPECT_GT(stripe, 400);
        // The narrow pyramid's edges (3 px with their halos) cross the striped ring of this small
        // image and cover about a tenth of it.
        EXPECT_GT(magenta, 0.8 * stripe);
        EXPECT_GT(outside, 1000);
    }
}

TEST(FrustumView, CascadesHoldEverySliceAndEachReceiverCarriesItsCascadesTint) {
    // The long plane with 3 cascades: each cascade's map is fitted to its slice, so every visible
    // receiver lies in the map of the cascade its view depth picks (no stripes anywhere). The plane
    // shades itself (a mesh), so all of it is a receiver the cascades must hold.
    scene::Scene s = test::makeLongPlane();
    test::makeGroundShadeItself(s, 0);
    scene::RasterSettings settings = test::validatedSettings(256, 0.0, 1.0, scene::ShadowFilter::Pcf2x2);
    settings.depthBias = scene::defaultDepthBias(s, 256);
    settings.depthBiasIsDefault = true;
    settings.cascades = 3;
    RenderDebug debug;
    const scene::Frame f = renderChecked(s, settings, &debug);
    ASSERT_EQ(debug.layers.size(), 3u);
    const std::vector<Coverage> cov = lightMapCoverage(f, s, debug);
    const std::vector<int> cascade = cascadeIndices(f, debug);
    const DisplayImage img = lightFrustumView(f, s, debug);
    maybeWritePng(img, "frustum_cascades");
    std::set<int> seen;
    int tinted = 0, receivers = 0;
    for (std::size_t i = 0; i < cov.size(); ++i) {
        if (!(f.objectId[i] > 0.0f)) {
            EXPECT_EQ(cov[i], Coverage::Background);
            continue;
        }
        ++receivers;
        EXPECT_EQ(cov[i], Coverage::Covered) << "pixel " << i;
        seen.insert(cascade[i]);
        tinted += isTint(&img.rgb[3 * i], cascadeTint(cascade[i]));
    }
    EXPECT_EQ(seen.size(), 3u);
    EXPECT_GT(tinted, 0.9 * receivers);
    // Shrinking cascade 1's map to a tenth of its width leaves most of its slice of the plane (id 1)
    // uncovered. (The spheres are convex: the parts of them no other object can shade stay Outside.)
    RenderDebug shrunk = debug;
    shrunk.layers[1].frustum.halfWidth *= 0.1;
    const std::vector<Coverage> after = lightMapCoverage(f, s, shrunk);
    int slice = 0, uncovered = 0;
    for (std::size_t i = 0; i < after.size(); ++i)
        if (f.objectId[i] == 1.0f && cascade[i] == 1 && f.ndotl[i] > 0.0f) {
            ++slice;
            uncovered += after[i] == Coverage::Uncovered;
            // The light reaches every facing point of the plane, and the plane shades itself.
            EXPECT_NE(after[i], Coverage::Outside);
        }
    EXPECT_GT(uncovered, slice / 2);
}

TEST(FrustumView, PointLightGetsAMarkerAtItsPositionAndNoOutline) {
    // A point light at (1, 2.5, 1): its marker (ring and cross, the light's tint) is centered on
    // the pixel the pinhole formula gives (test::projectToPixel); every receiver is Covered.
    test::SphereOverPlane p;
    scene::Scene s = test::makeScene(p);
    s.lights[0].type = scene::LightType::Point;
    s.lights[0].position = Vec3(1.0, 2.5, 1.0);
    s.lights[0].color = Vec3(0.25, 0.5, 1.0);
    s.lights[0].intensity = 60.0;
    RenderDebug debug;
    const scene::Frame f =
        renderChecked(s, test::validatedSettings(128, 0.01, 1.0, scene::ShadowFilter::Pcf2x2), &debug);
    ASSERT_EQ(debug.layers.size(), 6u);
    const std::vector<Coverage> cov = lightMapCoverage(f, s, debug);
    for (std::size_t i = 0; i < cov.size(); ++i)
        EXPECT_EQ(cov[i], f.objectId[i] > 0.0f ? Coverage::Covered : Coverage::Background) << i;
    const DisplayImage img = lightFrustumView(f, s, debug);
    maybeWritePng(img, "frustum_point");
    const auto [mx, my] = test::projectToPixel(scene::cameraBasis(s.camera), s.lights[0].position);
    ASSERT_TRUE(mx > 10 && my > 10 && mx < f.width - 10 && my < f.height - 10);
    // The cross's center and a ring pixel r = 4 to the right carry the full tint (the light is in
    // front of every surface behind it).
    const std::array<float, 3> tint{0.25f, 0.5f, 1.0f};
    const std::size_t center = std::size_t(my) * std::size_t(f.width) + std::size_t(mx);
    EXPECT_TRUE(isTint(&img.rgb[3 * center], tint));
    EXPECT_FLOAT_EQ(img.rgb[3 * center + 2], 1.0f);
    EXPECT_FLOAT_EQ(img.rgb[3 * (center + 4) + 2], 1.0f);
}

}  // namespace
}  // namespace shadowlab::raster
