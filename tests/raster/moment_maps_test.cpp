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
#include "tests/raster/test_scenes.h"

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
    for (std::size_t i = 0; i < casters.size(); ++i)
        s.objects.push_back({"caster" + std::to_string(i), casters[i], 0});
    return s;
}

scene::RasterSettings filterable(scene::ShadowFilter filter, int mapSize, double depthBias) {
    scene::RasterSettings r = test::validatedSettings(mapSize, depthBias, 0.0, filter);
    return r;
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
            const scene::Frame f = test::renderChecked(s, filterable(filter, 256, 0.02));
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
        return (1 - fy) * ((1 - fx) * c(i0, j0) + fx * c(i0 + 1, j0)) + fy * ((1 - fx) * c(i0, j0 + 1) + fx * c(i0 + 1, j0 + 1));
    }
};

TEST(MomentMaps, VsmOfTwoParallelPlanesIsTheChebyshevBoundOfTheBlurredMoments) {
    // A caster over x < 0 at height 1 above the floor, light straight down. Near the caster's edge
    // the blur window holds a fraction α of caster texels (depth z_c) and 1 − α of floor texels
    // (z_f): μ = α z_c + (1 − α) z_f, σ² = α(1 − α)(z_f − z_c)², and the receiver at t = z_f − b
    // gets p = σ²/(σ² + (t − μ)²) — here from the blur weights over the captured depths, with no
    // bleeding reduction and no variance floor. (With b → 0 that is 1 − α: the bound is tight
    // for two depths, so VSM equals box-filtered PCF there.)
    const scene::Scene s = floorScene({horizontalQuad(Vec3(-2.0, 1.0, 0.0), 4.0, 8.0)}, Vec3(2.0, 3.0, 2.5),
                                      Vec3(0.0, 0.0, 0.0));
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
        const double tp = t + ((corner >> 4) & 1 ? 1.0 : -1.0) * kUlps * std::abs(t) * std::numeric_limits<float>::epsilon();
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
        {"caster edge", floorScene({horizontalQuad(Vec3(-2.0, 1.0, 0.0), 4.0, 8.0)}, Vec3(2.0, 3.0, 2.5), Vec3(0.0)), 128,
         0.01, 0.0},
    };
    for (const Case& c : cases) {
        scene::RasterSettings r = filterable(scene::ShadowFilter::Msm, c.mapSize, c.bias);
        r.moments.blurWidth = 5;
        RenderDebug debug;
        debug.captureShadowMaps = true;
        const scene::Frame f = test::renderChecked(c.scene, r, &debug);
        ASSERT_EQ(debug.layerDepths.size(), 1u);
        const LightFrustum& frustum = debug.layers[0].frustum;
        const glm::dmat4 toTexture = frustum.toTexture(Vec3(0.0));
        const CpuMoments cpu{debug.layerDepths[0], int(debug.mapSize), r.moments.blurWidth};
        int pixels = 0, outside = 0;
        double least = 1.0, most = 0.0, worstExcess = 0.0;
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
            least = std::min(least, expected);
            most = std::max(most, expected);
            const double excess = std::abs(v - expected) - tolerance;
            if (excess > 0) {
                ++outside;
                worstExcess = std::max(worstExcess, excess);
            }
        });
        std::printf("%s: %d pixels, expected %.4f..%.4f, %d outside the tolerance (worst by %.4g)\n", c.name, pixels,
                    least, most, outside, worstExcess);
        EXPECT_GT(pixels, 1000) << c.name;
        // A handful of pixels at the floor's own silhouette sample texels the camera ray misses.
        EXPECT_LE(outside, pixels / 1000) << c.name;
    }
}

TEST(MomentMaps, SpotAndPointMapsLightTheirPlaneAndShadowBehindACaster) {
    // A spot's and a point light's faces are perspective maps: the stored depth is affine in
    // 1/distance along the face's axis, and 1/distance is affine in the map's (u, v) over a plane,
    // so a plane's depth is linear across the map there too and the argument of the directional
    // case holds: the lone floor is fully lit (MSM up to its moment bias). Under a caster 1 above
    // the floor the gap in stored depth is small (perspective depth is compressed away from the
    // light) but the variance of one depth is the floor's, so every filter still shadows.
    scene::Light spot;
    spot.type = scene::LightType::Spot;
    spot.position = Vec3(0.5, 5.0, -0.3);
    spot.direction = glm::normalize(Vec3(-0.5, -5.0, 0.3));
    spot.coneAngleDegrees = 50.0;
    spot.intensity = 300.0;
    scene::Light point = spot;
    point.type = scene::LightType::Point;
    point.coneAngleDegrees = 0.0;
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
            {
                const scene::Frame f = test::renderChecked(lone, filterable(filter, 256, 0.02));
                int pixels = 0, dark = 0;
                test::forEachFloorPixel(lone, f, [&](const Vec3& q, double v) {
                    // Inside the spot's cone by a blur width; the point light reaches all.
                    const Vec3 d = glm::normalize(q - light.position);
                    if (light.type == scene::LightType::Spot &&
                        glm::dot(d, light.direction) < std::cos((light.coneAngleDegrees - 4.0) * test::kPi / 180.0))
                        return;
                    ++pixels;
                    if (v < (msm ? 0.98 : 1.0)) ++dark;
                });
                EXPECT_GT(pixels, 10000) << kind;
                EXPECT_EQ(dark, 0) << kind << " " << scene::toString(filter) << ": the lone plane";
            }
            {
                const scene::Frame f = test::renderChecked(covered, filterable(filter, 256, 0.01));
                int pixels = 0;
                double most = 0.0;
                test::forEachFloorPixel(covered, f, [&](const Vec3& q, double v) {
                    if (std::abs(q.x) > 1.5 || std::abs(q.z) > 1.5) return;  // the caster's shadow, by 1.5 clear of its edge
                    ++pixels;
                    most = std::max(most, v);
                });
                EXPECT_GT(pixels, 1000) << kind;
                EXPECT_LT(most, 0.05) << kind << " " << scene::toString(filter) << ": under the caster";
            }
        }
    }
}

}  // namespace
}  // namespace shadowlab::raster
