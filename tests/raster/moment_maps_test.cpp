// tests/raster/moment_maps_test.cpp: the filterable shadow maps (--filter vsm, evsm2, evsm4, esm,
// msm) on lavapipe with the validation layer, against closed forms: a lone plane is fully lit,
// the Chebyshev bound of two planes follows from the blur's weights over the captured depths,
// ESM behind a plane is exp(−cΔ), MSM lights its plane and darkens what lies behind it.
#include <algorithm>
#include <cmath>
#include <cstdint>
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

TEST(MomentMaps, MsmLightsItsPlaneAndShadowsWhatLiesBehind) {
    // A single depth: the moments are (z, z², z³, z⁴) of one point, biased by α = 3e-5 toward
    // (0.5, ...). The Hamburger bound then shadows a receiver in front of z by at most ~α-sized
    // amounts and one well behind z (Δ ≈ 1/range) almost fully.
    {
        const scene::Scene s = floorScene({}, Vec3(1.5, 5.0, 4.0), Vec3(0.0));
        const scene::Frame f = test::renderChecked(s, filterable(scene::ShadowFilter::Msm, 256, 0.02));
        double least = 1.0;
        test::forEachFloorPixel(s, f, [&](const Vec3&, double v) { least = std::min(least, v); });
        EXPECT_GT(least, 0.98);
    }
    {
        const scene::Scene s = underACaster();
        const scene::Frame f = test::renderChecked(s, filterable(scene::ShadowFilter::Msm, 256, 0.01));
        double most = 0.0;
        int pixels = 0;
        test::forEachFloorPixel(s, f, [&](const Vec3& q, double v) {
            if (std::abs(q.x) > 2.5 || std::abs(q.z) > 2.5) return;
            ++pixels;
            most = std::max(most, v);
        });
        EXPECT_GT(pixels, 1000);
        EXPECT_LT(most, 0.02);
    }
}

}  // namespace
}  // namespace shadowlab::raster
