// tests/raster/cascades_test.cpp: cascaded shadow maps: the practical split formula, each cascade's
// frustum against its slice of the view (corners computed here from the camera's basis), texel
// snapping under camera motion, the texel gain on a large scene (closed-form bound), and, on
// lavapipe with validation, that one cascade is the single map, that cascades are ignored without
// a directional light, the debug views (sizes, exactly N tints, the density ramp), and cascades
// through the reusable Renderer (channel masks, later frames, two lights); and the blend bands
// before the splits (--cascade-blend): off is bit for bit the unblended frame, on is the linear mix.
#include "raster/cascades.h"

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <set>
#include <sstream>

#include <gtest/gtest.h>

#include "raster/debug_views.h"
#include "raster/renderer.h"
#include "raster/tolerances.h"
#include "scene/frame_io.h"
#include "tests/kit/render_checked.h"
#include "tests/kit/test_scenes.h"

namespace shadowlab::raster {
namespace {

using test::Vec3;

std::vector<std::string> labels(const RenderDebug& debug) {
    std::vector<std::string> out;
    for (const ShadowLayer& l : debug.layers) out.push_back(l.label);
    return out;
}

// The practical split scheme (Zhang et al. 2006), written out here: C_i = λ n (f/n)^(i/N) +
// (1 − λ)(n + (f − n) i/N).
double zhangSplit(double n, double f, int i, int count, double lambda) {
    return lambda * n * std::pow(f / n, double(i) / count) + (1.0 - lambda) * (n + (f - n) * double(i) / count);
}

// Corner (sx, sy) = (±1, ±1) of the view frustum at view depth d, from the camera's basis:
// eye + d·(forward + sx·tan(fov/2)·aspect·right + sy·tan(fov/2)·up).
Vec3 frustumCorner(const scene::CameraBasis& c, double d, double sx, double sy) {
    return c.position + d * (c.forward + sx * c.tanHalfFovY * c.aspect * c.right + sy * c.tanHalfFovY * c.up);
}

// Whether world point p lies inside f's box (clip x, y in -1..1, depth in 0..1), with a relative slack.
bool insideFrustum(const LightFrustum& f, const Vec3& p, double slack = 1e-9) {
    const glm::dvec4 c = f.toClip(Vec3(0.0)) * glm::dvec4(p, 1.0);
    return std::abs(c.x) <= 1.0 + slack && std::abs(c.y) <= 1.0 + slack && c.z >= -slack && c.z <= 1.0 + slack;
}

// Distance of x from the nearest integer.
double offGrid(double x) { return std::abs(x - std::round(x)); }

TEST(CascadeSplits, PracticalSchemeMatchesTheFormula) {
    for (const double lambda : {0.0, 0.5, kCascadeSplitLambda, 1.0})
        for (const int count : {1, 2, 3, 4}) {
            const std::vector<double> s = practicalSplits(0.5, 200.0, count, lambda);
            ASSERT_EQ(s.size(), std::size_t(count) + 1);
            for (int i = 0; i <= count; ++i)
                EXPECT_NEAR(s[std::size_t(i)], zhangSplit(0.5, 200.0, i, count, lambda), 1e-12 * 200.0)
                    << "lambda " << lambda << " count " << count << " i " << i;
        }
    // λ = 1 is the logarithmic split: n, n·(f/n)^(1/2), f = 0.5, 10, 200.
    const std::vector<double> log = practicalSplits(0.5, 200.0, 2, 1.0);
    EXPECT_NEAR(log[1], 10.0, 1e-12);
    // λ = 0 the uniform one: 0.5, 100.25, 200.
    EXPECT_NEAR(practicalSplits(0.5, 200.0, 2, 0.0)[1], 100.25, 1e-12);
}

TEST(CascadeSplits, DepthRangeHoldsEveryVisiblePlanePointAndNotTheEmptyNearSpace) {
    const scene::Scene s = test::makeLongPlane(64, 36);
    const auto range = visibleDepthRange(s);
    ASSERT_TRUE(range.has_value());
    const scene::CameraBasis cam = scene::cameraBasis(s.camera);
    double nearest = INFINITY;
    for (int y = 0; y < cam.height; ++y)
        for (int x = 0; x < cam.width; ++x) {
            const Vec3 d = test::pixelRay(cam, x, y);
            if (!(d.y < 0.0)) continue;
            const double t = -cam.position.y / d.y;  // the plane y = 0; forward·d = 1, so t is the view depth
            const Vec3 q = cam.position + t * d;
            if (std::abs(q.x) > 100.0 || q.z < -200.0 || q.z > 0.0) continue;
            EXPECT_GE(t, (*range)[0] * (1.0 - 1e-9));
            EXPECT_LE(t, (*range)[1] * (1.0 + 1e-9));
            nearest = std::min(nearest, t);
        }
    ASSERT_TRUE(std::isfinite(nearest));
    // The first visible receiver is several units away (the plane under the bottom of the view, a
    // sphere's box); the scene's box, which holds the camera, would have started at near = 0.1.
    EXPECT_GT((*range)[0], 0.5 * nearest);
    EXPECT_GE((*range)[0], s.camera.near);
}

TEST(Cascades, EveryCascadeFrustumContainsItsSliceCornersAndTheCastersTowardTheLight) {
    scene::Scene s = test::makeLongPlane();
    const Vec3 dir = s.lights[0].direction;
    const scene::CameraBasis cam = scene::cameraBasis(s.camera);
    // A caster far up toward the light, out of the view, above a plane point of the first slice.
    const CascadeSet probe = fitCascades(s, dir, 3, 1024);
    ASSERT_EQ(probe.frusta.size(), 3u);
    const double mid0 = 0.5 * (probe.splits[0] + probe.splits[1]);
    const Vec3 ground = cam.position + mid0 * cam.forward - Vec3(0, 2.5 + mid0 * cam.forward.y, 0);
    const Vec3 high = ground - 60.0 * dir;
    scene::Object caster;
    caster.name = "high";
    caster.shape = scene::Sphere{high, 0.5};
    s.objects.push_back(caster);

    for (const int count : {2, 3, 4}) {
        const CascadeSet set = fitCascades(s, dir, count, 1024);
        ASSERT_EQ(set.frusta.size(), std::size_t(count));
        ASSERT_EQ(set.splits.size(), std::size_t(count) + 1);
        const LightFrustum whole = fitDirectionalLight(s.bounds(), dir, 1024);
        for (int i = 0; i < count; ++i) {
            const LightFrustum& f = set.frusta[std::size_t(i)];
            EXPECT_FALSE(f.perspective);
            if (f.halfWidth == whole.halfWidth && f.center == whole.center) {
                // A slice wider than the scene uses the scene's map, which holds every receiver:
                // the corners of the scene's bounds.
                const scene::Bounds b = s.bounds();
                for (int k = 0; k < 8; ++k)
                    EXPECT_TRUE(insideFrustum(f, Vec3((k & 1) ? b.max.x : b.min.x, (k & 2) ? b.max.y : b.min.y,
                                                      (k & 4) ? b.max.z : b.min.z)));
                EXPECT_GT(i, 0) << "the first slice is never wider than this scene";
                continue;
            }
            for (const double d : {set.splits[std::size_t(i)], set.splits[std::size_t(i) + 1]})
                for (const double sx : {-1.0, 1.0})
                    for (const double sy : {-1.0, 1.0})
                        EXPECT_TRUE(insideFrustum(f, frustumCorner(cam, d, sx, sy)))
                            << "cascade " << i << " of " << count << ", corner at depth " << d;
        }
        // The high sphere is over the first slice, so the first map must reach up to it.
        const LightFrustum& f0 = set.frusta[0];
        const Vec3 top = high - 0.5 * dir;  // its point nearest the light
        const Vec3 rel = top - f0.center;
        if (std::abs(glm::dot(rel, f0.right)) < f0.halfWidth && std::abs(glm::dot(rel, f0.up)) < f0.halfWidth)
            EXPECT_TRUE(insideFrustum(f0, top)) << "a caster toward the light is cut off by the near plane";
        else
            ADD_FAILURE() << "the test's caster is not over the first cascade's map";
    }
}

TEST(Cascades, WithABlendBandEachCascadeAlsoHoldsTheBandOfTheSliceBeforeIt) {
    // lit.frag mixes cascade i into the last `blend` of slice i − 1, so cascade i's map must hold
    // that band's corners too. A narrow view (fov 20°, 16:9: the slice's sphere is centered between
    // its ends, (d0 + d1)(1 + k²)/2, k² = tan²(10°)(1 + (16/9)²) ≈ 0.13) and the widest band (0.5):
    // the band's near corners lie well outside the sphere of slice i alone.
    scene::Scene s = test::makeLongPlane();
    s.camera.fovYDegrees = 20.0;
    const Vec3 dir = s.lights[0].direction;
    const scene::CameraBasis cam = scene::cameraBasis(s.camera);
    const double blend = 0.5;
    const CascadeSet plain = fitCascades(s, dir, 3, 1024);
    const CascadeSet blended = fitCascades(s, dir, 3, 1024, blend);
    ASSERT_EQ(blended.frusta.size(), 3u);
    ASSERT_EQ(blended.splits, plain.splits);  // the splits stay; only the maps grow
    const LightFrustum whole = fitDirectionalLight(s.bounds(), dir, 1024);
    int outsideWithoutBand = 0;
    for (std::size_t i = 1; i < 3; ++i) {
        const double bandStart = blended.splits[i] - blend * (blended.splits[i] - blended.splits[i - 1]);
        for (const double sx : {-1.0, 1.0})
            for (const double sy : {-1.0, 1.0}) {
                const Vec3 corner = frustumCorner(cam, bandStart, sx, sy);
                if (blended.frusta[i].halfWidth == whole.halfWidth && blended.frusta[i].center == whole.center)
                    continue;  // the scene's own map: it holds every receiver (previous test)
                EXPECT_TRUE(insideFrustum(blended.frusta[i], corner)) << "cascade " << i << ", band corner";
                if (!insideFrustum(plain.frusta[i], corner)) ++outsideWithoutBand;
            }
    }
    EXPECT_GT(outsideWithoutBand, 0) << "the scene does not tell a band-aware fit from a plain one";
}

TEST(Cascades, SnappedCenterStaysOnTheTexelGridWhenTheCameraMovesByAFractionOfATexel) {
    scene::Scene s = test::makeLongPlane();
    const Vec3 dir = s.lights[0].direction;
    const CascadeSet a = fitCascades(s, dir, 3, 1024);
    ASSERT_EQ(a.frusta.size(), 3u);
    // A slice wider than the scene uses the scene's map, fixed in the world: not snapped, and it
    // must not move at all.
    const LightFrustum whole = fitDirectionalLight(s.bounds(), dir, 1024);
    auto isWhole = [&](const LightFrustum& f) { return f.halfWidth == whole.halfWidth && f.center == whole.center; };
    auto checkOnGrid = [&](const LightFrustum& f) {
        if (isWhole(f)) return;
        const double t = f.texelWorldSize();
        EXPECT_LT(offGrid(glm::dot(f.center, f.right) / t), 1e-6);
        EXPECT_LT(offGrid(glm::dot(f.center, f.up) / t), 1e-6);
    };
    for (const LightFrustum& f : a.frusta) checkOnGrid(f);
    ASSERT_FALSE(isWhole(a.frusta[0]) || isWhole(a.frusta[1])) << "the test wants snapped cascades";

    // Move the camera (and what it looks at) sideways by 0.37 of the first cascade's texel.
    const scene::CameraBasis cam = scene::cameraBasis(s.camera);
    const Vec3 step = 0.37 * a.frusta[0].texelWorldSize() * cam.right;
    s.camera.position += step;
    s.camera.lookAt += step;
    const CascadeSet b = fitCascades(s, dir, 3, 1024);
    ASSERT_EQ(b.frusta.size(), 3u);
    for (std::size_t i = 0; i < 3; ++i) {
        const LightFrustum& fa = a.frusta[i];
        const LightFrustum& fb = b.frusta[i];
        checkOnGrid(fb);
        EXPECT_EQ(isWhole(fa), isWhole(fb)) << "cascade " << i;
        // Same texel size (the half-width is quantized), and the map moved by whole texels.
        EXPECT_EQ(fa.texelWorldSize(), fb.texelWorldSize()) << "cascade " << i;
        const double t = fa.texelWorldSize();
        EXPECT_LT(offGrid(glm::dot(fb.center - fa.center, fa.right) / t), 1e-6);
        EXPECT_LT(offGrid(glm::dot(fb.center - fa.center, fa.up) / t), 1e-6);
    }

    // Turning the camera leaves the slice's bounding sphere the same size.
    scene::Scene turned = s;
    turned.camera.lookAt = Vec3(-7, 0.2, -18);
    const BoundingSphere s0 = sliceBoundingSphere(scene::cameraBasis(s.camera), 3.0, 11.0);
    const BoundingSphere s1 = sliceBoundingSphere(scene::cameraBasis(turned.camera), 3.0, 11.0);
    EXPECT_NEAR(s0.radius, s1.radius, 1e-12 * s0.radius);
}

TEST(Cascades, NearCascadeTexelIsAFractionOfTheSingleMapTexelOnALargeScene) {
    const scene::Scene s = test::makeLongPlane();
    const int size = 1024;
    const LightFrustum single = fitDirectionalLight(s.bounds(), s.lights[0].direction, size);
    const CascadeSet set = fitCascades(s, s.lights[0].direction, 3, size);
    ASSERT_EQ(set.frusta.size(), 3u);
    // Bound: the first slice [n, C1] has a bounding sphere of radius R0 (corners at depth d lie d·k
    // off the axis, k² = tx² + ty²; the sphere through both rings is centered at depth
    // z = min((n + C1)(1 + k²)/2, C1)); its map is R0 · 1.01, widened by 8 texels a side and
    // quantized up by at most 1/16: texel ≤ 2 · R0 · 1.01 · size/(size − 16) · 17/16 / size. The
    // single map spans the scene's bounding sphere: texel = 1.01 · diagonal / size.
    const scene::CameraBasis cam = scene::cameraBasis(s.camera);
    const double n = set.splits[0], c1 = zhangSplit(set.splits[0], set.splits[3], 1, 3, kCascadeSplitLambda);
    const double tx = cam.tanHalfFovY * cam.aspect, ty = cam.tanHalfFovY, k2 = tx * tx + ty * ty;
    const double z = std::min(0.5 * (n + c1) * (1.0 + k2), c1);
    const double r0 = std::sqrt(std::max((z - n) * (z - n) + n * n * k2, (c1 - z) * (c1 - z) + c1 * c1 * k2));
    const double bound = 2.0 * r0 * 1.01 * size / (size - 16.0) * (17.0 / 16.0) / size;
    EXPECT_LE(set.frusta[0].texelWorldSize(), bound * (1.0 + 1e-12));
    EXPECT_NEAR(single.texelWorldSize(), 1.01 * s.bounds().diagonal() / size, 1e-12);
    const double ratio = set.frusta[0].texelWorldSize() / single.texelWorldSize();
    EXPECT_LE(ratio, bound / single.texelWorldSize() * (1.0 + 1e-12));
    // Here n ≈ 4, f ≈ 280, C1 ≈ 36, R0 ≈ 27 against the scene's radius ≈ 142: about 0.2.
    EXPECT_LT(ratio, 0.25) << "the near cascade should be > 4x finer than one map over 200 units";
    // No cascade is coarser than the single map (a far slice wider than the scene uses the scene's map).
    for (const LightFrustum& f : set.frusta) EXPECT_LE(f.texelWorldSize(), single.texelWorldSize());
    // Texels grow from cascade to cascade (longer, wider slices).
    EXPECT_LT(set.frusta[0].texelWorldSize(), set.frusta[1].texelWorldSize());
    EXPECT_LT(set.frusta[1].texelWorldSize(), set.frusta[2].texelWorldSize());
}

TEST(Cascades, NoneWhenTheCameraSeesNothing) {
    scene::Scene s = test::makeLongPlane();
    s.camera.lookAt = s.camera.position + Vec3(0, 1, 0.001);  // straight up, at an empty sky
    EXPECT_FALSE(visibleDepthRange(s).has_value());
    EXPECT_TRUE(fitCascades(s, s.lights[0].direction, 3, 512).frusta.empty());
}

// --- renders on lavapipe ---

scene::RasterSettings cascadeSettings(int cascades, int mapSize = 512) {
    scene::RasterSettings r = test::validatedSettings(mapSize, 0.0, 1.0, scene::ShadowFilter::Pcf2x2);
    r.depthBias = scene::defaultDepthBias(test::makeLongPlane(), mapSize);
    r.depthBiasIsDefault = true;
    r.cascades = cascades;
    return r;
}

using test::renderChecked;

std::vector<double> parseList(const std::string& text) {
    std::vector<double> v;
    std::stringstream in(text);
    std::string item;
    while (std::getline(in, item, ';')) v.push_back(std::stod(item));
    return v;
}

TEST(RasterCascades, OneCascadeIsTheSingleMapPixelForPixel) {
    const scene::Scene s = test::makeLongPlane();
    const scene::Frame one = renderChecked(s, cascadeSettings(1));
    // The single map is the bounding-sphere map fitDirectionalLight() makes (as before cascades).
    const LightFrustum expected = fitDirectionalLight(s.bounds(), s.lights[0].direction, 512);
    EXPECT_EQ(one.attributes.at("light_frustum"), expected.describe());
    EXPECT_EQ(one.attributes.at("cascades"), "1");
    EXPECT_EQ(one.attributes.count("cascade_splits"), 0u);
    // A fitted single map likewise.
    scene::RasterSettings fitted = cascadeSettings(1);
    fitted.fitLightFrustum = true;
    const scene::Frame fit = renderChecked(s, fitted);
    EXPECT_EQ(fit.attributes.at("light_frustum"),
              fitDirectionalLightToReceivers(s, s.lights[0].direction, 512).describe());
    // And two cascades differ from it (the test can fail).
    const scene::Frame two = renderChecked(s, cascadeSettings(2));
    EXPECT_NE(two.visibility, one.visibility);
}

TEST(RasterCascades, CascadesAreIgnoredWithoutADirectionalLightWithTheReasonInThePlan) {
    scene::Scene s = test::makeLongPlane();
    s.lights[0].type = scene::LightType::Spot;
    s.lights[0].position = Vec3(10, 20, -10);
    s.lights[0].direction = glm::normalize(Vec3(-10, -20, -5));
    s.lights[0].coneAngleDegrees = 50.0;
    s.lights[0].intensity = 5000.0;
    scene::RenderSettings settings;
    settings.raster = cascadeSettings(3);
    const scene::RenderPlan plan = scene::makeRenderPlan(s, settings);
    EXPECT_EQ(plan.cascades, 1);
    EXPECT_NE(plan.explain().find("ignored: no shadowed directional light"), std::string::npos) << plan.explain();
    const scene::Frame three = renderChecked(s, cascadeSettings(3));
    const scene::Frame one = renderChecked(s, cascadeSettings(1));
    EXPECT_EQ(three.visibility, one.visibility);
    EXPECT_EQ(three.beauty, one.beauty);
    EXPECT_EQ(three.attributes.at("cascades"), "1");
}

TEST(RasterCascades, AttributesRecordTheSplitsAndEachCascadesTexel) {
    const scene::Scene s = test::makeLongPlane();
    const scene::Frame f = renderChecked(s, cascadeSettings(3));
    EXPECT_EQ(f.attributes.at("cascades"), "3");
    EXPECT_EQ(f.attributes.at("shadow_maps"), "3");
    const std::vector<double> splits = parseList(f.attributes.at("cascade_splits"));
    ASSERT_EQ(splits.size(), 4u);
    for (int i = 1; i < 3; ++i)
        EXPECT_NEAR(splits[std::size_t(i)], zhangSplit(splits[0], splits[3], i, 3, kCascadeSplitLambda),
                    1e-7 * splits[3]);
    const std::vector<double> texels = parseList(f.attributes.at("cascade_texel_world_size"));
    const CascadeSet set = fitCascades(s, s.lights[0].direction, 3, 512);
    ASSERT_EQ(texels.size(), 3u);
    for (std::size_t i = 0; i < 3; ++i) EXPECT_NEAR(texels[i], set.frusta[i].texelWorldSize(), 1e-8 * texels[i]);
    // The default constant bias is half of each cascade's texel.
    const std::vector<double> bias = parseList(f.attributes.at("depth_bias"));
    ASSERT_EQ(bias.size(), 3u);
    for (std::size_t i = 0; i < 3; ++i) EXPECT_NEAR(bias[i], 0.5 * texels[i], 1e-8 * texels[i]);
}

// The tint whose direction (normalized color) is nearest to the pixel's: the view multiplies the
// tint by a gray shade, which keeps its direction.
int nearestTint(const float* rgb) {
    const glm::dvec3 c = glm::normalize(glm::dvec3(rgb[0], rgb[1], rgb[2]));
    int best = -1;
    double bestDot = -1.0;
    for (int k = 0; k < 4; ++k) {
        const std::array<float, 3> t = cascadeTint(k);
        const double d = glm::dot(c, glm::normalize(glm::dvec3(t[0], t[1], t[2])));
        if (d > bestDot) {
            bestDot = d;
            best = k;
        }
    }
    return bestDot > 0.999 ? best : -1;
}

TEST(RasterCascades, CascadeViewShowsExactlyNTintsWhereEveryCascadeIsVisible) {
    const scene::Scene s = test::makeLongPlane();
    for (const int count : {3, 4}) {
        RenderDebug debug;
        const scene::Frame f = renderChecked(s, cascadeSettings(count), &debug);
        const DisplayImage img = cascadeView(f, debug);
        ASSERT_EQ(img.width, f.width);
        ASSERT_EQ(img.height, f.height);
        const std::vector<double> splits = parseList(f.attributes.at("cascade_splits"));
        std::set<int> tints;
        std::size_t wrong = 0;
        for (std::size_t i = 0; i < f.pixelCount(); ++i) {
            if (!(f.objectId[i] > 0.0f)) continue;
            // Expected: the number of inner split depths the pixel's view depth exceeds.
            int expected = 0;
            for (int k = 1; k < count; ++k) expected += f.depth[i] > float(splits[std::size_t(k)]) ? 1 : 0;
            const int tint = nearestTint(&img.rgb[3 * i]);
            tints.insert(tint);
            wrong += tint != expected ? 1 : 0;
        }
        EXPECT_EQ(tints.size(), std::size_t(count)) << count << " cascades";
        EXPECT_EQ(tints.count(-1), 0u) << "a receiver pixel is no tint";
        EXPECT_EQ(wrong, 0u);
    }
}

TEST(RasterCascades, ShadowMapAndTexelDensityViewsHaveTheDocumentedSizes) {
    const scene::Scene s = test::makeLongPlane();
    RenderDebug debug;
    debug.captureShadowMaps = true;
    const scene::Frame f = renderChecked(s, cascadeSettings(3, 256), &debug);
    ASSERT_EQ(debug.layerDepths.size(), 3u);
    ASSERT_EQ(labels(debug), (std::vector<std::string>{"L0 C0", "L0 C1", "L0 C2"}));
    // Three layers: 2 columns x 2 rows of 256-pixel tiles, 4 pixels apart.
    const DisplayImage map = shadowMapView(debug);
    EXPECT_EQ(map.width, 2 * 256 + kShadowMapViewGap);
    EXPECT_EQ(map.height, 2 * 256 + kShadowMapViewGap);
    const DisplayImage density = texelDensityView(f, s, debug);
    EXPECT_EQ(density.width, f.width);
    EXPECT_EQ(density.height, f.height);
    // Each receiver's ratio is its cascade's texel over 2·z·tan(fov/2)/height.
    const std::vector<double> ratio = texelToPixelRatios(f, s, debug);
    const std::vector<int> cascade = cascadeIndices(f, debug);
    const scene::CameraBasis cam = scene::cameraBasis(s.camera);
    for (std::size_t i = 0; i < f.pixelCount(); i += 37) {
        if (!(f.objectId[i] > 0.0f)) {
            EXPECT_TRUE(std::isnan(ratio[i]));
            continue;
        }
        const double pixel = 2.0 * f.depth[i] * cam.tanHalfFovY / s.camera.height;
        EXPECT_NEAR(ratio[i], cascadeTexels(debug.layers)[std::size_t(cascade[i])] / pixel, 1e-9 * ratio[i]);
    }
}

// The reusable Renderer (and its lit.frag variants: all targets, beauty only) with cascades: every
// frame and channel mask sees the same cascades, and RenderDebug comes through Renderer::render.
TEST(RasterCascades, RendererFramesOfEveryChannelMaskUseTheCascades) {
    const scene::Scene s = test::makeLongPlane();
    const scene::RasterSettings settings = cascadeSettings(3, 256);
    Renderer renderer(s, test::planFor(s, settings), settings);
    RenderDebug debug;
    debug.captureShadowMaps = true;
    const scene::Frame all = renderer.render(scene::kAllChannels, &debug);
    EXPECT_EQ(all.attributes.at("cascades"), "3");
    ASSERT_EQ(labels(debug), (std::vector<std::string>{"L0 C0", "L0 C1", "L0 C2"}));
    ASSERT_EQ(debug.layerDepths.size(), 3u);
    EXPECT_EQ(cascadeSplits(debug.layers).size(), 4u);
    // The beauty-only variant (what `render -o x.png` uses) shades with the same cascades.
    const scene::Frame beautyOnly = renderer.render(scene::kChannelBeauty | scene::kChannelVisibility);
    EXPECT_TRUE(beautyOnly.objectId.empty());
    EXPECT_EQ(beautyOnly.visibility, all.visibility);
    EXPECT_EQ(beautyOnly.beauty, all.beauty);
    // A later frame re-renders the same maps.
    RenderDebug again;
    again.captureShadowMaps = true;
    const scene::Frame second = renderer.render(scene::kAllChannels, &again);
    EXPECT_EQ(second.visibility, all.visibility);
    EXPECT_EQ(again.layerDepths, debug.layerDepths);
    // And one map gives another picture (the comparisons above can fail).
    const scene::Frame one = renderChecked(s, cascadeSettings(1, 256));
    EXPECT_NE(one.visibility, all.visibility);
    EXPECT_EQ(renderer.validationMessages(), 0) << "validation messages were printed above";
}

// With two cascaded directional lights (the per-light visibility variant of lit.frag), each light
// uses its own cascades (uniform slots light * SHADOWLAB_MAX_CASCADES + c): its per-light
// visibility is the visibility of the same scene lit by that light alone.
TEST(RasterCascades, EachOfTwoLightsUsesItsOwnCascades) {
    scene::Scene both = test::makeLongPlane();
    scene::Light second = both.lights[0];
    second.direction = glm::normalize(Vec3(1.2, -1.0, 0.4));
    both.lights.push_back(second);
    const scene::Frame f = renderChecked(both, cascadeSettings(3, 256));
    EXPECT_EQ(f.attributes.at("shadow_maps"), "6");
    ASSERT_EQ(f.lightVisibility.size(), 2u);
    for (std::size_t light = 0; light < 2; ++light) {
        scene::Scene alone = test::makeLongPlane();
        alone.lights = {both.lights[light]};
        const scene::Frame a = renderChecked(alone, cascadeSettings(3, 256));
        ASSERT_EQ(a.visibility.size(), f.lightVisibility[light].size());
        std::size_t differ = 0, shadowed = 0;
        for (std::size_t i = 0; i < a.visibility.size(); ++i) {
            differ += std::abs(a.visibility[i] - f.lightVisibility[light][i]) > 1e-5f ? 1 : 0;
            shadowed += a.objectId[i] > 0.0f && a.visibility[i] < 0.5f ? 1 : 0;
        }
        EXPECT_EQ(differ, 0u) << "light " << light;
        EXPECT_GT(shadowed, 20u) << "light " << light << " casts no shadow: the comparison proves nothing";
    }
    EXPECT_NE(f.lightVisibility[0], f.lightVisibility[1]);
}

// --- blend bands before the splits (--cascade-blend) ---

// Where pixel i lies with respect to the blend band F of its cascade's slice, from its view depth
// (the Frame's Z, the expression lit.frag selects by) and the splits, in float as lit.frag: the band
// is z > end − F·(end − start) of slice [start, end] for every cascade but the last; t is the
// position in it, 0 at its start to 1 at the split. Pixels within a relative 1e-4 of the band's
// start are "unsure" (float rounding of the two computations may differ there).
struct BandPosition {
    enum Kind { Outside, Inside, Unsure } kind = Outside;
    int cascade = 0;
    double t = 0.0;
};
BandPosition bandPosition(const scene::Frame& f, const std::vector<double>& splits, double blend, std::size_t i) {
    BandPosition b;
    const float z = f.depth[i];
    const std::size_t count = splits.size() - 1;
    for (std::size_t k = 0; k + 1 < count; ++k)
        if (z > float(splits[k + 1])) b.cascade = int(k) + 1;
    if (std::size_t(b.cascade) + 1 >= count) return b;  // the last cascade has no band
    const double start = float(splits[std::size_t(b.cascade)]), end = float(splits[std::size_t(b.cascade) + 1]);
    const double bandStart = end - blend * (end - start);
    const double margin = 1e-4 * end;
    if (z < bandStart - margin) return b;
    b.kind = z > bandStart + margin ? BandPosition::Inside : BandPosition::Unsure;
    b.t = std::clamp((z - bandStart) / (end - bandStart), 0.0, 1.0);
    return b;
}

// The long plane with two larger spheres whose shadows lie in the blend bands of both inner splits
// (view depths ~24 and ~68; the splits are near 29 and 76), seen at 480x270 so that the far band
// is more than a few rows tall, so that their edges, where the two
// cascades' texels give different filtered visibilities, cross the bands. The plane shades itself
// (a mesh), so the cascades split all of its visible depths, not only those under the spheres.
scene::Scene blendScene() {
    scene::Scene s = test::makeLongPlane(480, 270);
    test::makeGroundShadeItself(s, 0);
    const std::pair<Vec3, double> extra[] = {{Vec3(4.0, 1.6, -22.0), 1.5}, {Vec3(-5.0, 3.2, -66.0), 3.0}};
    for (const auto& [center, radius] : extra) {
        scene::Object o;
        o.name = "objects[" + std::to_string(s.objects.size()) + "]";
        o.shape = scene::Sphere{center, radius};
        s.objects.push_back(o);
    }
    return s;
}

scene::RasterSettings blendSettings(double blend) {
    scene::RasterSettings r = cascadeSettings(3);
    r.cascadeBlend = blend;
    return r;
}

TEST(RasterCascadeBlend, ZeroIsTheFrameWithoutTheSettingBitForBit) {
    scene::Scene s = test::makeLongPlane();
    s.shadow.cascades = 3;
    scene::SettingsOverrides absent, zero;
    zero.cascadeBlend = 0.0;
    const scene::RenderSettings withoutSetting = scene::resolveSettings(s, absent);
    const scene::RenderSettings withZero = scene::resolveSettings(s, zero);
    ASSERT_EQ(withoutSetting.raster.cascades, 3);
    EXPECT_EQ(withZero.raster.cascadeBlend, 0.0);
    scene::RasterSettings a = blendSettings(0.0), b = blendSettings(0.0);
    a.cascadeBlend = withoutSetting.raster.cascadeBlend;
    b.cascadeBlend = withZero.raster.cascadeBlend;
    const scene::Frame fa = renderChecked(s, a), fb = renderChecked(s, b);
    EXPECT_EQ(fa.beauty, fb.beauty);
    EXPECT_EQ(fa.visibility, fb.visibility);
    EXPECT_EQ(fa.blockerId, fb.blockerId);
    EXPECT_EQ(fb.attributes.at("cascade_blend"), "0");
    // And a band changes the picture (the comparisons here and below can fail).
    EXPECT_NE(renderChecked(s, blendSettings(0.5)).visibility, fb.visibility);
}

// On the long plane (3 cascades, with blendScene()'s shadows crossing both inner bands): with F = 0.25 and
// 0.5, every pixel outside the bands is the unblended frame's (same maps), bit for bit; inside, the visibility
// is the linear mix v = v_c + t·(v_{c+1} − v_c) of cascade c's own value v_c (the unblended frame's
// there, as the band lies inside slice c) and cascade c + 1's. v_{c+1} is unknown, so it is solved
// from the F = 0.5 frame, where t is largest; it must be a visibility (0..1), and it must predict
// the F = 0.25 frame at the same pixel with that band's t (the mix is linear in t, and both
// frames use the same two cascades' taps). Where v_c is 0 or 1 and both frames agree with it (fully
// shadowed or lit by both cascades) the mix is exactly that value.
TEST(RasterCascadeBlend, OutsideTheBandsUnchangedInsideTheLinearMixOfTheTwoCascades) {
    const scene::Scene s = blendScene();
    RenderDebug debug;
    // With blending on, every cascade's map covers the widest band (cascadeBandCover), whatever F:
    // the unblended reference is a frame with a vanishing band (1e-9 of a slice: no pixel in it)
    // and the same maps as F = 0.25 and 0.5.
    const scene::Frame plain = renderChecked(s, blendSettings(1e-9), &debug);
    const scene::Frame half = renderChecked(s, blendSettings(0.5));
    const scene::Frame quarter = renderChecked(s, blendSettings(0.25));
    ASSERT_EQ(cascadeSplits(debug.layers).size(), 4u);
    EXPECT_EQ(half.attributes.at("cascade_blend"), "0.5");
    EXPECT_EQ(quarter.attributes.at("cascade_blend"), "0.25");
    std::size_t outside = 0, checked = 0, mixed[2] = {0, 0}, exact = 0, notHeld = 0;
    const CascadeSet set = fitCascades(s, s.lights[0].direction, 3, 512, scene::kMaxCascadeBlend);
    ASSERT_EQ(set.splits, cascadeSplits(debug.layers));
    const scene::CameraBasis cam = scene::cameraBasis(s.camera);
    for (std::size_t i = 0; i < plain.pixelCount(); ++i) {
        if (!(plain.objectId[i] > 0.0f)) continue;
        const BandPosition bh = bandPosition(plain, cascadeSplits(debug.layers), 0.5, i);
        const BandPosition bq = bandPosition(plain, cascadeSplits(debug.layers), 0.25, i);
        const float vc = plain.visibility[i];
        if (bq.kind == BandPosition::Outside) {
            ASSERT_EQ(quarter.visibility[i], vc) << "pixel " << i;
            ASSERT_EQ(quarter.beauty[3 * i], plain.beauty[3 * i]) << "pixel " << i;
        }
        if (bh.kind == BandPosition::Outside) {
            ++outside;
            ASSERT_EQ(half.visibility[i], vc) << "pixel " << i;
            for (std::size_t k = 0; k < 3; ++k)
                ASSERT_EQ(half.beauty[3 * i + k], plain.beauty[3 * i + k]) << "pixel " << i;
            continue;
        }
        const int x = int(i % std::size_t(plain.width)), y = int(i / std::size_t(plain.width));
        const Vec3 point = cam.position + double(plain.depth[i]) * test::pixelRay(cam, x, y);
        if (!insideFrustum(set.frusta[std::size_t(bh.cascade) + 1], point, 1e-6)) ++notHeld;
        if (bh.kind != BandPosition::Inside || bh.t < 0.2) continue;
        const double next = vc + (double(half.visibility[i]) - vc) / bh.t;  // v_{c+1}
        EXPECT_GE(next, -1e-4) << "pixel " << i;
        EXPECT_LE(next, 1.0 + 1e-4) << "pixel " << i;
        if (std::abs(half.visibility[i] - vc) > 0.02f) ++mixed[bh.cascade];
        if (bq.kind == BandPosition::Inside) {
            ++checked;
            EXPECT_NEAR(quarter.visibility[i], vc + bq.t * (next - vc), 2e-4) << "pixel " << i << " t " << bq.t;
            if ((vc == 0.0f || vc == 1.0f) && half.visibility[i] == vc) {
                EXPECT_EQ(quarter.visibility[i], vc) << "pixel " << i;
                ++exact;
            }
        } else if (bq.kind == BandPosition::Outside) {
            EXPECT_EQ(quarter.visibility[i], vc) << "pixel " << i;
        }
    }
    // The band lies in the nearer slice: the next cascade's map must hold it, or its taps read the
    // border (lit). Every band pixel's point (the camera ray to its view depth) is inside that map.
    // Enough of each kind that the checks mean something: most of the image outside the bands,
    // band pixels of both inner splits where the two cascades disagree (a shadow edge crosses).
    EXPECT_EQ(notHeld, 0u);
    EXPECT_GT(outside, plain.pixelCount() / 4);
    EXPECT_GT(checked, 200u);
    EXPECT_GT(exact, 100u);
    EXPECT_GE(mixed[0], 20u);
    EXPECT_GE(mixed[1], 3u);
}

TEST(RasterCascadeBlend, IgnoredWithoutCascadesWithTheReasonInThePlan) {
    const scene::Scene s = test::makeLongPlane();
    scene::RasterSettings one = cascadeSettings(1);
    one.cascadeBlend = 0.5;
    scene::RenderSettings settings;
    settings.raster = one;
    const scene::RenderPlan plan = scene::makeRenderPlan(s, settings);
    EXPECT_EQ(plan.cascadeBlend, 0.0);
    EXPECT_NE(plan.explain().find("cascade blend: 0 (cascade_blend = 0.5 ignored: no cascades)"), std::string::npos)
        << plan.explain();
    EXPECT_EQ(renderChecked(s, one).visibility, renderChecked(s, cascadeSettings(1)).visibility);
    settings.raster = blendSettings(0.25);
    EXPECT_NE(scene::makeRenderPlan(s, settings).explain().find("cascade blend: 0.25 (the last 0.25 of each slice"),
              std::string::npos);
}

TEST(DebugViews, DensityRampIsGreenAtOneToOneRedWhenUndersampledBlueWhenOversampled) {
    const auto g = densityColor(1.0), r = densityColor(8.0), b = densityColor(1.0 / 8.0);
    EXPECT_GT(g[1], 2.0f * std::max(g[0], g[2]));
    EXPECT_GT(r[0], 2.0f * std::max(r[1], r[2]));
    EXPECT_GT(b[2], 2.0f * std::max(b[0], b[1]));
    // Clamped beyond 8x.
    EXPECT_EQ(densityColor(100.0), r);
    EXPECT_EQ(densityColor(0.001), b);
}

}  // namespace
}  // namespace shadowlab::raster
