// tests/raster/moment_maps_test.cpp: the filterable shadow maps (--filter vsm, evsm2, evsm4, esm,
// msm) on lavapipe with the validation layer, against closed forms: a lone plane is fully lit,
// the Chebyshev bound of two planes follows from the blur's weights over the captured depths,
// ESM behind a plane is exp(−cΔ), MSM is the Hamburger bound of the blurred moments (an oracle in
// double, by another route than the shader's).
#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <limits>
#include <vector>

#include <gtest/gtest.h>

#include "raster/renderer.h"
#include "tests/kit/render_checked.h"
#include "tests/kit/test_scenes.h"

namespace shadowlab::raster {
namespace {

using test::Vec3;

scene::Quad horizontalQuad(const Vec3& center, double sx, double sz) {
    scene::Quad q;
    q.center = center;
    q.normal = Vec3(0, 1, 0);
    q.size = scene::Vec2(sx, sz);
    scene::quadAxes(q.normal, q.uAxis, q.vAxis);  // for +y: u = +x, v = z, so size is (x, z)
    return q;
}

// A floor 8 x 8 at y = 0 (id 1) under a directional light straight down, with `casters` (ids 2...)
// and the camera given.
scene::Scene floorScene(const std::vector<scene::Quad>& casters, const Vec3& eye, const Vec3& at) {
    scene::Scene s;
    s.camera = {.position = eye, .lookAt = at, .width = 320, .height = 180};
    scene::Material m;
    m.name = "matte";
    s.materials.push_back(m);
    scene::Light l;
    l.type = scene::LightType::Directional;
    l.direction = Vec3(0, -1, 0);
    l.intensity = 3.0;
    s.lights.push_back(l);
    s.objects.push_back({"floor", horizontalQuad(Vec3(0), 8.0, 8.0), 0});
    for (std::size_t i = 0; i < casters.size(); ++i) s.objects.push_back({"caster" + std::to_string(i), casters[i], 0});
    return s;
}

scene::RasterSettings filterable(scene::ShadowFilter filter, int mapSize, double depthBias) {
    scene::RasterSettings r = test::validatedSettings(mapSize, depthBias, 0.0, filter);
    return r;
}

// A render whose lights keep their shadow maps, with every object drawn into them: the plan
// leaves out the map of a lone plane (one convex object cannot shadow itself) and caster culling
// the plane from its own map, and then there would be no moments to test.
scene::Frame renderWithMaps(const scene::Scene& s, scene::RasterSettings r, RenderDebug* debug = nullptr) {
    r.cullCasters = false;
    scene::RenderPlan plan = test::planFor(s, r);
    for (scene::LightPlan& lp : plan.lights) lp.needsShadowTest = true;
    scene::Frame f = render(s, plan, r, debug);
    EXPECT_EQ(f.attributes["validation_messages"], "0") << "validation messages were printed above";
    EXPECT_EQ(f.attributes["shadow_maps"], s.lights[0].type == scene::LightType::Point ? "6" : "1");
    return f;
}

TEST(MomentMaps, AloneThePlaneIsFullyLitByEveryFilterableFilter) {
    // One plane, no other caster: every texel holds the plane's own depth z, the blur of a constant
    // is that constant, so μ = z, and the receiver at z − bias lies in front: Chebyshev gives 1
    // (t <= μ), ESM exp(c·(z − t)) >= 1 clamps to 1; MSM's bound for t below the one depth is 0
    // shadow up to the moment bias (checked at 0.98, see MsmLightsItsPlaneAndShadowsWhatLiesBehind).
    // A tilted light makes the depth linear across the map instead: its box mean is still the
    // centre's depth, the same argument holds.
    for (const Vec3 direction : {Vec3(0, -1, 0), glm::normalize(Vec3(0.6, -1.0, 0.3))}) {
        scene::Scene s = floorScene({}, Vec3(1.5, 5.0, 4.0), Vec3(0.0));
        s.lights[0].direction = direction;
        for (const auto filter : {scene::ShadowFilter::Vsm, scene::ShadowFilter::Evsm2, scene::ShadowFilter::Evsm4,
                                  scene::ShadowFilter::Esm}) {
            const scene::Frame f = renderWithMaps(s, filterable(filter, 256, 0.02));
            EXPECT_EQ(f.attributes.at("filter"), scene::toString(filter));
            int pixels = 0, dark = 0;
            test::forEachFloorPixel(s, f, [&](const Vec3&, double v) {
                ++pixels;
                if (v != 1.0) ++dark;
            });
            EXPECT_GT(pixels, 10000);
            EXPECT_EQ(dark, 0) << scene::toString(filter) << " direction " << direction.x;
        }
    }
}

// The blurred moments the lit pass samples, computed here from the captured depths: a box of
// `width` texels in x then y (coordinates clamped to the map, as moments.comp), then the bilinear
// mix of the four texels around (u, v) (the LINEAR, clamp-to-edge sampler).
struct CpuMoments {
    const std::vector<float>& depth;
    int size;
    int width;
    double at(int i, int j, int power) const {
        const int r = (width - 1) / 2;
        double sum = 0.0;
        for (int l = -r; l <= r; ++l)
            for (int k = -r; k <= r; ++k) {
                const int x = std::clamp(i + k, 0, size - 1), y = std::clamp(j + l, 0, size - 1);
                sum += std::pow(double(depth[std::size_t(y) * std::size_t(size) + std::size_t(x)]), power);
            }
        return sum / double(width * width);
    }
    double sample(double u, double v, int power) const {
        const double tx = u * size - 0.5, ty = v * size - 0.5;
        const int i0 = int(std::floor(tx)), j0 = int(std::floor(ty));
        const double fx = tx - i0, fy = ty - j0;
        auto c = [&](int i, int j) { return at(std::clamp(i, 0, size - 1), std::clamp(j, 0, size - 1), power); };
        return (1 - fy) * ((1 - fx) * c(i0, j0) + fx * c(i0 + 1, j0)) +
               fy * ((1 - fx) * c(i0, j0 + 1) + fx * c(i0 + 1, j0 + 1));
    }
};

TEST(MomentMaps, VsmOfTwoParallelPlanesIsTheChebyshevBoundOfTheBlurredMoments) {
    // A caster over x < 0 at height 1 above the floor, light straight down. Near the caster's edge
    // the blur window holds a fraction α of caster texels (depth z_c) and 1 − α of floor texels
    // (z_f): μ = α z_c + (1 − α) z_f, σ² = α(1 − α)(z_f − z_c)², and the receiver at t = z_f − b
    // gets p = σ²/(σ² + (t − μ)²) — here from the blur weights over the captured depths, with no
    // bleeding reduction and no variance floor. (With b → 0 that is 1 − α: the bound is tight
    // for two depths, so VSM equals box-filtered PCF there.)
    const scene::Scene s =
        floorScene({horizontalQuad(Vec3(-2.0, 1.0, 0.0), 4.0, 8.0)}, Vec3(2.0, 3.0, 2.5), Vec3(0.0, 0.0, 0.0));
    scene::RasterSettings r = filterable(scene::ShadowFilter::Vsm, 128, 0.01);
    r.moments.minVariance = 0.0;
    r.moments.bleedReduction = 0.0;
    r.moments.blurWidth = 9;
    RenderDebug debug;
    debug.captureShadowMaps = true;
    const scene::Frame f = test::renderChecked(s, r, &debug);
    ASSERT_EQ(debug.layerDepths.size(), 1u);
    const LightFrustum& frustum = debug.layers[0].frustum;
    const glm::dmat4 toTexture = frustum.toTexture(Vec3(0.0));
    const CpuMoments cpu{debug.layerDepths[0], int(debug.mapSize), 9};
    int penumbra = 0;
    double worst = 0.0;
    test::forEachFloorPixel(s, f, [&](const Vec3& q, double v) {
        const glm::dvec4 t = toTexture * glm::dvec4(q, 1.0);
        const double mu = cpu.sample(t.x, t.y, 1), m2 = cpu.sample(t.x, t.y, 2);
        const double receiver = t.z - r.depthBias / frustum.depthRange();
        const double variance = std::max(m2 - mu * mu, 0.0);
        const double expected = receiver <= mu ? 1.0 : variance / (variance + (receiver - mu) * (receiver - mu));
        if (expected > 0.05 && expected < 0.95) ++penumbra;
        worst = std::max(worst, std::abs(v - expected));
    });
    EXPECT_GT(penumbra, 200) << "the camera must see the penumbra";
    // float moments: E[z²] − μ² loses ~1e-7 of 0.25 absolute, against σ² >= 1e-4 where p is between
    // 0.05 and 0.95 (Δz ≈ 0.1); the pixel's own point vs the rasterized interpolation ≈ 1e-3 texel.
    EXPECT_LT(worst, 0.01);
}

// Under a wide caster plane at height h (seen from a camera below it): every texel the blur
// reaches holds the caster's depth z_c, so ESM gives exp(c·z_c)·exp(−c·t) = exp(−c·(Δ − b)) with
// Δ = h / depth range and b = bias / depth range.
scene::Scene underACaster() {
    return floorScene({horizontalQuad(Vec3(0.0, 1.0, 0.0), 6.0, 6.0)}, Vec3(0.0, 0.6, 2.5), Vec3(0.0, 0.0, -1.0));
}

TEST(MomentMaps, EsmBehindAPlaneIsExpOfMinusTheExponentTimesTheDepthGap) {
    const scene::Scene s = underACaster();
    for (const double c : {2.0, 5.0, 10.0}) {
        scene::RasterSettings r = filterable(scene::ShadowFilter::Esm, 256, 0.01);
        r.moments.esmExponent = c;
        RenderDebug debug;
        const scene::Frame f = test::renderChecked(s, r, &debug);
        ASSERT_EQ(debug.layers.size(), 1u);
        const double range = debug.layers[0].frustum.depthRange();
        const double expected = std::exp(-c * (1.0 - r.depthBias) / range);
        int pixels = 0;
        double worst = 0.0;
        test::forEachFloorPixel(s, f, [&](const Vec3& q, double v) {
            if (std::abs(q.x) > 2.5 || std::abs(q.z) > 2.5) return;  // well inside the caster (blur 5 texels)
            ++pixels;
            worst = std::max(worst, std::abs(v / expected - 1.0));
        });
        EXPECT_GT(pixels, 1000);
        // float: exp(c z) and exp(−c t) each within a few ulp, times c·(rounding of z ≈ 6e-8).
        EXPECT_LT(worst, 1e-4) << "c = " << c << ", expected " << expected;
    }
}

// The Hamburger 4MSM bound (Peters & Klein, "Moment Shadow Mapping", I3D 2015, algorithm 3) in
// double, by another route than the shader's: the moments pulled toward 0.5 by α; the kernel
// polynomial's coefficients c from B c = (1, t, t²) by Cramer's rule; its roots z2 ≤ z3; the
// weights of the three-point distribution {t, z2, z3} with the moments 1, b1, b2 from its
// Vandermonde system, again by Cramer; the shadow is the weight lying strictly in front of t.
double msmVisibility(const std::array<double, 4>& raw, double t, double alpha) {
    std::array<double, 4> b{};
    for (int k = 0; k < 4; ++k) b[k] = (1.0 - alpha) * raw[k] + alpha * 0.5;
    using M3 = std::array<std::array<double, 3>, 3>;
    const auto det = [](const M3& m) {
        return m[0][0] * (m[1][1] * m[2][2] - m[1][2] * m[2][1]) - m[0][1] * (m[1][0] * m[2][2] - m[1][2] * m[2][0]) +
               m[0][2] * (m[1][0] * m[2][1] - m[1][1] * m[2][0]);
    };
    const auto cramer = [&](const M3& m, const std::array<double, 3>& rhs) {
        std::array<double, 3> x{};
        const double d = det(m);
        for (int col = 0; col < 3; ++col) {
            M3 mc = m;
            for (int row = 0; row < 3; ++row) mc[row][col] = rhs[row];
            x[col] = det(mc) / d;
        }
        return x;
    };
    const M3 hankel{{{1.0, b[0], b[1]}, {b[0], b[1], b[2]}, {b[1], b[2], b[3]}}};
    const std::array<double, 3> c = cramer(hankel, {1.0, t, t * t});
    const double disc = std::sqrt(std::max(c[1] * c[1] - 4.0 * c[2] * c[0], 0.0));
    const double r1 = (-c[1] - disc) / (2.0 * c[2]), r2 = (-c[1] + disc) / (2.0 * c[2]);
    const std::array<double, 3> z{t, std::min(r1, r2), std::max(r1, r2)};
    const M3 vandermonde{{{1.0, 1.0, 1.0}, {z[0], z[1], z[2]}, {z[0] * z[0], z[1] * z[1], z[2] * z[2]}}};
    const std::array<double, 3> w = cramer(vandermonde, {1.0, b[0], b[1]});
    double shadow = 0.0;
    for (int k = 1; k < 3; ++k)
        if (z[k] < t) shadow += w[k];
    return std::clamp(1.0 - shadow, 0.0, 1.0);
}

// How far the bound can move when each stored moment is off by the float rounding of the blur
// (a few ulp of float) and the receiver depth by its own: the oracle evaluated at the 32 corners
// of that box. This is the test's tolerance, derived from the shader's precision, not guessed.
double msmSensitivity(const std::array<double, 4>& b, double t, double alpha) {
    constexpr double kUlps = 8.0;  // the blur's sums of up to 9 float terms, then the division
    const double base = msmVisibility(b, t, alpha);
    double worst = 0.0;
    for (int corner = 0; corner < 32; ++corner) {
        std::array<double, 4> p = b;
        for (int k = 0; k < 4; ++k)
            p[k] += ((corner >> k) & 1 ? 1.0 : -1.0) * kUlps * std::abs(b[k]) * std::numeric_limits<float>::epsilon();
        const double tp =
            t + ((corner >> 4) & 1 ? 1.0 : -1.0) * kUlps * std::abs(t) * std::numeric_limits<float>::epsilon();
        worst = std::max(worst, std::abs(msmVisibility(p, tp, alpha) - base));
    }
    return worst;
}

TEST(MomentMaps, MsmOracleGivesTheClosedFormsOfOneAndTwoDepths) {
    // Unbiased (α = 0) moments of one depth z: the bound is a step, lit up to z, shadowed behind.
    const auto one = [](double z) { return std::array<double, 4>{z, z * z, z * z * z, z * z * z * z}; };
    EXPECT_NEAR(msmVisibility(one(0.4), 0.3, 1e-9), 1.0, 1e-6);
    EXPECT_NEAR(msmVisibility(one(0.4), 0.6, 1e-9), 0.0, 1e-6);
    // Two depths 0.2 (weight w) and 0.6: behind both the shadow is everything; between them the
    // sharp lower bound of the Hamburger problem: four moments of two atoms determine them, so
    // the bound is the nearer atom's weight w (up to the tiny α).
    const double w = 0.3;
    std::array<double, 4> two{};
    for (int k = 0; k < 4; ++k) two[k] = w * std::pow(0.2, k + 1) + (1 - w) * std::pow(0.6, k + 1);
    EXPECT_NEAR(msmVisibility(two, 0.9, 1e-7), 0.0, 1e-3);
    EXPECT_NEAR(msmVisibility(two, 0.21, 1e-7), 1.0 - w, 0.02);
    EXPECT_NEAR(msmVisibility(two, 0.1, 1e-7), 1.0, 1e-3);
}

TEST(MomentMaps, MsmIsTheHamburgerBoundOfTheBlurredMoments) {
    // Three scenes: a lone plane (one depth, the receiver just in front of it: lit up to the
    // moment bias), under a wide caster (one depth well in front of the receiver: nearly dark) and
    // the two-plane edge of the VSM test (a mixture across the blur: the penumbra). Each pixel's
    // expected visibility is the oracle above on the blurred, bilinearly sampled moments of the
    // captured depths (CpuMoments), within the oracle's own sensitivity to float rounding.
    struct Case {
        const char* name;
        scene::Scene scene;
        int mapSize;
        double bias;
        double farFromCasterEdge;  // keep |x|, |z| below this (0 = everywhere)
    };
    const std::vector<Case> cases{
        {"lone plane", floorScene({}, Vec3(1.5, 5.0, 4.0), Vec3(0.0)), 256, 0.02, 0.0},
        {"under a caster", underACaster(), 256, 0.01, 2.5},
        {"caster edge", floorScene({horizontalQuad(Vec3(-2.0, 1.0, 0.0), 4.0, 8.0)}, Vec3(2.0, 3.0, 2.5), Vec3(0.0)),
         128, 0.01, 0.0},
    };
    for (const Case& c : cases) {
        scene::RasterSettings r = filterable(scene::ShadowFilter::Msm, c.mapSize, c.bias);
        r.moments.blurWidth = 5;
        RenderDebug debug;
        debug.captureShadowMaps = true;
        const scene::Frame f = renderWithMaps(c.scene, r, &debug);
        ASSERT_EQ(debug.layerDepths.size(), 1u);
        const LightFrustum& frustum = debug.layers[0].frustum;
        const glm::dmat4 toTexture = frustum.toTexture(Vec3(0.0));
        const CpuMoments cpu{debug.layerDepths[0], int(debug.mapSize), r.moments.blurWidth};
        int pixels = 0, outside = 0;
        double least = 1.0, most = 0.0, worstExcess = 0.0, largestError = 0.0;
        test::forEachFloorPixel(c.scene, f, [&](const Vec3& q, double v) {
            if (c.farFromCasterEdge > 0 && (std::abs(q.x) > c.farFromCasterEdge || std::abs(q.z) > c.farFromCasterEdge))
                return;
            const glm::dvec4 tex = toTexture * glm::dvec4(q, 1.0);
            const std::array<double, 4> m{cpu.sample(tex.x, tex.y, 1), cpu.sample(tex.x, tex.y, 2),
                                          cpu.sample(tex.x, tex.y, 3), cpu.sample(tex.x, tex.y, 4)};
            const double t = tex.z - r.depthBias / frustum.depthRange();
            const double expected = msmVisibility(m, t, r.moments.momentBias);
            // The pixel's own point against the rasterized interpolation: ~1e-3 texel, so the
            // bound's slope across a texel times that, plus float's 8-bit-free output rounding.
            const double tolerance = msmSensitivity(m, t, r.moments.momentBias) + 2e-3;
            ++pixels;
            largestError = std::max(largestError, std::abs(v - expected));
            least = std::min(least, expected);
            most = std::max(most, expected);
            const double excess = std::abs(v - expected) - tolerance;
            if (excess > 0) {
                ++outside;
                worstExcess = std::max(worstExcess, excess);
            }
        });
        std::printf(
            "%s: %d pixels, expected %.4f..%.4f, largest |v - expected| %.3g, %d outside the tolerance (worst "
            "by %.4g)\n",
            c.name, pixels, least, most, largestError, outside, worstExcess);
        EXPECT_GT(pixels, 1000) << c.name;
        // A handful of pixels at the floor's own silhouette sample texels the camera ray misses.
        EXPECT_LE(outside, pixels / 1000) << c.name;
    }
}

// A perspective layer's stored depths as the moments pass makes them linear, by another route
// than the shader's: the distance d along the axis from z = far/(far − near)·(1 − near/d), then
// (d − near)/(far − near).
std::vector<float> linearDepths(const std::vector<float>& stored, const LightFrustum& f) {
    std::vector<float> out(stored.size());
    for (std::size_t i = 0; i < stored.size(); ++i) {
        const double d = f.near / (1.0 - double(stored[i]) * (f.far - f.near) / f.far);
        out[i] = float((d - f.near) / (f.far - f.near));
    }
    return out;
}

// Which of the render's layers holds floor point q of a spot (its one map) or a point light (the
// face of q's major axis from the light: +X −X +Y −Y +Z −Z, as lit.frag cubeFace).
std::size_t layerOf(const RenderDebug& debug, const scene::Light& light, const Vec3& q) {
    if (light.type != scene::LightType::Point) return 0;
    const Vec3 d = q - light.position, a = glm::abs(d);
    const int k = a.x >= a.y && a.x >= a.z ? 0 : a.y >= a.z ? 1 : 2;
    const int face = 2 * k + (d[k] < 0.0 ? 1 : 0);
    for (std::size_t l = 0; l < debug.layers.size(); ++l)
        if (debug.layers[l].index == face) return l;
    ADD_FAILURE() << "no layer for face " << face;
    return 0;
}

TEST(MomentMaps, SpotAndPointMapsLightTheirPlaneAndShadowBehindACaster) {
    // Perspective layers (a spot's map, a point light's cube faces) hold moments of the linear depth
    // z = (d − near)/(far − near), d along the layer's axis, and the receiver is compared at
    // (d − b − near)/(far − near). Closed forms:
    // - The lone floor (light 5 above it): the point light's floor lies wholly in its −Y face
    //   (|x − 0.5|, |z + 0.3| < 4.5 < 5), whose axis is the floor's normal, so every texel holds
    //   d = 5: one depth, the receiver b in front of it: vsm, evsm2, evsm4 (t <= μ) and esm
    //   (e^{c(z − t)} >= 1) give exactly 1. The spot's axis is 6° off the normal: there d is
    //   c/(α + β·s) of the map's tangent s, convex, so the blurred and bilinearly sampled mean is
    //   at least the point's own depth (Jensen; the weights are symmetric about the point) and
    //   the receiver b in front of it is lit by the same rules (evsm4's negative warp −e^{−c₋w} is
    //   concave, but its Jensen gap c₋²σ²/2 per unit of |warp| is far below the bias's c₋·2b/(far −
    //   near) for a floor 5 away whose depth moves less than 1e-3 of the range over the footprint).
    // - Under the caster y = 1 with the light at height 3: the ray from floor point q to the light
    //   crosses the caster at 2/3 of q's distance, so along any axis the caster is at 2d/3 and the
    //   normalized gap is g = (d/3 − b)/(far − near), ≈ 0.12 here. The caster's own depth spreads
    //   by s (below) over the footprint (blur radius 2 + bilinear 1 texel): the point light's −Y
    //   face holds the caster and the floor of |x|, |z| <= 1.5 (|q − L| has its major axis on −Y),
    //   both perpendicular to its axis, so s = 0 there. Chebyshev: p <= max(σ², min_variance)/(g −
    //   s)² ≈ 1e-6/0.0144, far below the bleeding reduction 0.2, so vsm, evsm2 and evsm4 (whose
    //   warps only widen the gap against their scaled floors) give exactly 0. ESM: e^{−c·g} within
    //   a factor e^{±c·s}, and the stored depth's float step, d²/(near·far)·2^-24 in z (a few 1e-6
    //   here), times c. MSM: the Hamburger oracle on the captured depths made linear, as in
    //   MsmIsTheHamburgerBoundOfTheBlurredMoments; it also covers the lone floor.
    // (Moments of the stored depth far/(far − near)·(1 − near/d) would see the gap
    // near·far/((far − near)·2d): 1.4e-3 for the bounding-sphere map here, near = far/1000 = 0.008,
    // and esm would give e^{−80·1.4e-3} = 0.9 under the caster.)
    scene::Light spot;
    spot.type = scene::LightType::Spot;
    spot.position = Vec3(0.5, 5.0, -0.3);
    spot.direction = glm::normalize(Vec3(-0.5, -5.0, 0.3));
    spot.coneAngleDegrees = 50.0;
    spot.intensity = 300.0;
    scene::Light point = spot;
    point.type = scene::LightType::Point;
    point.coneAngleDegrees = 0.0;
    const int mapSize = 256, blurWidth = 5;
    for (const scene::Light& light : {spot, point}) {
        const char* kind = light.type == scene::LightType::Spot ? "spot" : "point";
        scene::Scene lone = floorScene({}, Vec3(1.5, 5.0, 4.0), Vec3(0.0));
        scene::Scene covered = underACaster();
        lone.lights[0] = light;
        covered.lights[0] = light;
        covered.lights[0].position = Vec3(0.2, 3.0, -0.1);  // under the caster's middle, 2 above it
        covered.lights[0].direction = glm::normalize(-covered.lights[0].position);
        for (const auto filter : {scene::ShadowFilter::Vsm, scene::ShadowFilter::Evsm2, scene::ShadowFilter::Evsm4,
                                  scene::ShadowFilter::Esm, scene::ShadowFilter::Msm}) {
            const bool msm = filter == scene::ShadowFilter::Msm;
            for (const bool underCaster : {false, true}) {
                const scene::Scene& s = underCaster ? covered : lone;
                const scene::Light& l = s.lights[0];
                scene::RasterSettings r = filterable(filter, mapSize, underCaster ? 0.01 : 0.02);
                r.moments.blurWidth = blurWidth;
                RenderDebug debug;
                debug.captureShadowMaps = msm;
                const scene::Frame f = renderWithMaps(s, r, &debug);
                ASSERT_EQ(debug.layers.size(), light.type == scene::LightType::Point ? 6u : 1u);
                std::vector<std::vector<float>> linear;
                for (std::size_t k = 0; k < debug.layerDepths.size(); ++k)
                    linear.push_back(linearDepths(debug.layerDepths[k], debug.layers[k].frustum));
                int pixels = 0, wrong = 0;
                double worst = 0.0;
                test::forEachFloorPixel(s, f, [&](const Vec3& q, double v) {
                    if (underCaster && (std::abs(q.x) > 1.5 || std::abs(q.z) > 1.5)) return;  // 1.5 clear of its edge
                    // Inside the spot's cone by more than the footprint; the point light reaches all.
                    const Vec3 dir = glm::normalize(q - l.position);
                    if (l.type == scene::LightType::Spot &&
                        glm::dot(dir, l.direction) < std::cos((l.coneAngleDegrees - 4.0) * test::kPi / 180.0))
                        return;
                    const std::size_t layer = layerOf(debug, l, q);
                    const LightFrustum& frustum = debug.layers[layer].frustum;
                    const double range = frustum.far - frustum.near;
                    const glm::dvec4 tex = frustum.toTexture(Vec3(0.0)) * glm::dvec4(q, 1.0);
                    const double d = tex.w;  // distance along the layer's axis
                    const double t = (d - r.depthBias - frustum.near) / range;
                    double expected = underCaster ? 0.0 : 1.0, tolerance = 0.0;
                    if (msm) {
                        const CpuMoments cpu{linear[layer], int(debug.mapSize), blurWidth};
                        const double u = tex.x / tex.w, w = tex.y / tex.w;
                        const std::array<double, 4> m{cpu.sample(u, w, 1), cpu.sample(u, w, 2), cpu.sample(u, w, 3),
                                                      cpu.sample(u, w, 4)};
                        expected = msmVisibility(m, t, r.moments.momentBias);
                        tolerance = msmSensitivity(m, t, r.moments.momentBias) + 2e-3;
                    } else if (underCaster && filter == scene::ShadowFilter::Esm) {
                        // The caster's linear depth at the footprint's corners (3 texels each way):
                        // the ray from the light along axis + s_u·right + s_v·up meets y = 1 at
                        // distance (1 − L.y)/dir.y along the axis.
                        const double texelTan = frustum.texelWorldSize();
                        const double su = (2.0 * tex.x / tex.w - 1.0) * frustum.tanHalfFov + frustum.windowU;
                        const double sv = (2.0 * tex.y / tex.w - 1.0) * frustum.tanHalfFov + frustum.windowV;
                        auto casterDepth = [&](double a, double b) {
                            const Vec3 ray = frustum.direction + a * frustum.right + b * frustum.up;
                            return (1.0 - l.position.y) / ray.y;
                        };
                        const double dc = casterDepth(su, sv);
                        double spread = 0.0;
                        for (const double a : {-3.0, 3.0})
                            for (const double b : {-3.0, 3.0})
                                spread = std::max(
                                    spread, std::abs(casterDepth(su + a * texelTan, sv + b * texelTan) - dc) / range);
                        const double c = r.moments.esmExponent;
                        const double quantum = 2.0 * dc * dc / (frustum.near * frustum.far) * std::ldexp(1.0, -24);
                        expected = std::exp(-c * (t - (dc - frustum.near) / range));
                        tolerance = expected * std::expm1(c * (spread + quantum) + 1e-5);
                    }
                    ++pixels;
                    const double error = std::abs(v - expected);
                    worst = std::max(worst, error);
                    if (error > tolerance) ++wrong;
                });
                std::printf("%s %s %s: %d pixels, largest |v - expected| %.3g, %d beyond the tolerance\n", kind,
                            scene::toString(filter), underCaster ? "under the caster" : "lone floor", pixels, worst,
                            wrong);
                EXPECT_GT(pixels, underCaster ? 1000 : 10000) << kind;
                // MSM: as in MsmIsTheHamburgerBoundOfTheBlurredMoments, a handful at the floor's
                // silhouette may sample texels the camera ray misses.
                EXPECT_LE(wrong, msm ? pixels / 1000 : 0) << kind << " " << scene::toString(filter)
                                                          << (underCaster ? ": under the caster" : ": the lone floor");
            }
        }
    }
}

}  // namespace
}  // namespace shadowlab::raster
