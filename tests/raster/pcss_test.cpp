// tests/raster/pcss_test.cpp: percentage-closer soft shadows (--filter pcss) for a spot light with
// a radius: the penumbra of a straight blocker edge widens with the receiver–blocker distance as
// Fernando's formula says, on lavapipe with the validation layer.
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <string>
#include <variant>
#include <vector>

#include <gtest/gtest.h>

#include "raster/renderer.h"
#include "tests/kit/render_checked.h"
#include "tests/kit/test_scenes.h"

namespace shadowlab::raster {
namespace {

using test::Vec3;

// A spot light of diameter `size` at height H straight above the origin, pointing down; a square
// blocker at height hb covering x in [-6, 0] (edge along z at x = 0); the floor y = 0. The camera
// looks at the edge's shadow from the lit side, where the blocker cannot hide it.
constexpr double kH = 10.0, kSize = 1.0;

scene::Scene edgeScene(double hb) {
    scene::Scene s;
    s.camera = {
        .position = Vec3(2.5, 3.0, 0.0), .lookAt = Vec3(0.0), .width = 320, .height = 180};  // fov 40°, near 0.1
    scene::Material m;
    m.name = "matte";
    s.materials.push_back(m);
    scene::Light l;
    l.type = scene::LightType::Spot;
    l.position = Vec3(0, kH, 0);
    l.direction = Vec3(0, -1, 0);
    l.coneAngleDegrees = 45.0;
    l.radius = 0.5 * kSize;
    l.intensity = 2000.0;
    s.lights.push_back(l);
    s.objects.push_back(test::horizontalQuad("floor", Vec3(0, 0, 0), 20.0, 20.0));
    s.objects.push_back(test::horizontalQuad("blocker", Vec3(-3, hb, 0), 6.0, 6.0));
    return s;
}

// The 10%–90% width of the visibility ramp across the edge, on the floor near z = 0: floor pixels
// (found by the test's own ray–plane intersection) are binned by x, each bin's mean visibility
// taken, and the 0.1 and 0.9 crossings interpolated. `umbra`: the visibility in the full shadow
// (0 behind an opaque blocker, 1 − opacity behind a semi-transparent one); the levels are taken
// between it and 1.
double rampWidth(const scene::Scene& s, const scene::Frame& f, double umbra = 0.0) {
    constexpr double lo = -1.2, hi = 1.2, bin = 0.02;
    const int bins = int((hi - lo) / bin);
    std::vector<double> sum(std::size_t(bins), 0.0);
    std::vector<int> count(std::size_t(bins), 0);
    test::forEachFloorPixel(s, f, [&](const Vec3& q, double v) {
        if (std::abs(q.z) > 0.4 || q.x < lo || q.x >= hi) return;
        const int b = int((q.x - lo) / bin);
        sum[std::size_t(b)] += v;
        ++count[std::size_t(b)];
    });
    auto crossing = [&](double level) {
        double prevV = -1.0, prevX = 0.0;
        for (int b = 0; b < bins; ++b) {
            if (!count[std::size_t(b)]) continue;
            const double v = sum[std::size_t(b)] / count[std::size_t(b)], x = lo + (b + 0.5) * bin;
            if (prevV >= 0.0 && prevV < level && v >= level) return prevX + (level - prevV) / (v - prevV) * (x - prevX);
            prevV = v;
            prevX = x;
        }
        return std::nan("");
    };
    return crossing(umbra + 0.9 * (1.0 - umbra)) - crossing(umbra + 0.1 * (1.0 - umbra));
}

scene::Frame renderPcss(const scene::Scene& s) {
    scene::Frame f = test::renderChecked(s, test::validatedSettings(512, 0.01, 1.0, scene::ShadowFilter::Pcss));
    EXPECT_EQ(f.attributes["filter"], "pcss");
    return f;
}

// The measured 10–90 widths of blockers at heights 2 and 4 against Fernando's formula for them.
void expectPenumbraWidths(const std::vector<double>& widths, const std::vector<double>& formula) {
    ASSERT_TRUE(std::isfinite(widths[0]) && std::isfinite(widths[1])) << widths[0] << " " << widths[1];
    // The visibility under a disk kernel of diameter W across a straight edge is the disk's area
    // beyond a line; it passes 10% and 90% at ±0.687·W/2, so the 10–90 width is 0.687·W.
    for (std::size_t i = 0; i < 2; ++i)
        EXPECT_NEAR(widths[i], 0.687 * formula[i], 0.3 * 0.687 * formula[i] + 0.04)
            << "blocker " << (i ? 4 : 2) << " above the floor";
    // The ratio does not depend on the kernel's shape: (4/6)/(2/8) = 2.67.
    EXPECT_NEAR(widths[1] / widths[0], formula[1] / formula[0], 0.2 * formula[1] / formula[0]);
}

TEST(RasterPcss, PenumbraWidensWithTheReceiverBlockerDistanceAsTheFormulaSays) {
    // Light points at x_L in [-w/2, w/2] at height H; the line through the edge (0, hb) meets the
    // floor at x = -x_L·hb/(H − hb): the penumbra is w·hb/(H − hb) wide, which is Fernando's
    // (d_r − d_b)·w/d_b with d_r = H and d_b = H − hb.
    std::vector<double> widths, formula;
    for (const double hb : {2.0, 4.0}) {
        const scene::Scene s = edgeScene(hb);
        const scene::Frame f = renderPcss(s);
        widths.push_back(rampWidth(s, f));
        formula.push_back(kSize * hb / (kH - hb));
    }
    expectPenumbraWidths(widths, formula);
}

TEST(RasterPcss, ASemiTransparentBlockerGetsTheSamePenumbraAtItsOwnDepth) {
    // The blocker of opacity 0.5: its umbra lets half the light through (visibility 0.5) and its
    // penumbra ramps from 0.5 to 1 over the same width as an opaque blocker's at that height. The
    // blocker search sees it through the transmittance map's nearest depths (before, it found no
    // opaque blocker and returned "lit": no shadow at all).
    std::vector<double> widths, formula;
    for (const double hb : {2.0, 4.0}) {
        scene::Scene s = edgeScene(hb);
        scene::Material glass;
        glass.name = "glass";
        glass.opacity = 0.5;
        s.materials.push_back(glass);
        s.objects[1].material = 1;
        const scene::Frame f = renderPcss(s);
        EXPECT_EQ(f.attributes.at("transmittance_map"), "made");
        // In the umbra (x in [-1.2, -0.6], z near 0) and in the light (x in [0.6, 1.2]): the
        // penumbra is at most 1·4/6 = 0.67 wide, centered on x = 0.
        double umbra = 0.0, lit = 0.0;
        int nu = 0, nl = 0;
        test::forEachFloorPixel(s, f, [&](const Vec3& q, double v) {
            if (std::abs(q.z) > 0.4) return;
            if (q.x > -1.2 && q.x < -0.6) umbra += v, ++nu;
            if (q.x > 0.6 && q.x < 1.2) lit += v, ++nl;
        });
        ASSERT_GT(nu, 20);
        ASSERT_GT(nl, 20);
        EXPECT_NEAR(umbra / nu, 0.5, 0.01) << "blocker at " << hb;
        EXPECT_NEAR(lit / nl, 1.0, 0.01) << "blocker at " << hb;
        widths.push_back(rampWidth(s, f, 0.5));
        formula.push_back(kSize * hb / (kH - hb));
    }
    expectPenumbraWidths(widths, formula);
}

TEST(RasterPcss, APointSizedLightKeepsTheHardShadowOfPoisson) {
    // Without a light size pcss has nothing to size a penumbra with: it is `poisson` with pcfSize.
    scene::Scene s = edgeScene(3.0);
    s.lights[0].radius = 0.0;
    scene::RasterSettings pcss = test::validatedSettings(512, 0.01, 1.0, scene::ShadowFilter::Pcss);
    scene::RasterSettings poisson = pcss;
    poisson.filter = scene::ShadowFilter::Poisson;
    const scene::Frame a = test::renderChecked(s, pcss);
    const scene::Frame b = test::renderChecked(s, poisson);
    EXPECT_EQ(a.visibility, b.visibility);
}

// A point light of diameter 1 at height 4 above the origin, a blocker quad at height 2 covering
// x in [0, 8], z in [-6, 0]: its straight edge (z = 0) casts a penumbra 1 unit wide on the floor
// along z = 0, which crosses the seam between the cube's -Y and +X faces at x = 4 (there the
// direction from the light is 45° down). The PCSS search (up to 1/16 of the map) and filter (1/8)
// reach far past a face's 12-texel margin there.
constexpr double kSeamH = 4.0, kSeamHb = 2.0, kSeamDiameter = 1.0;

scene::Scene seamScene() {
    scene::Scene s = edgeScene(kSeamHb);
    s.camera.position = Vec3(kSeamH, 2.5, 3.0);
    s.camera.lookAt = Vec3(kSeamH, 0.0, 0.0);
    s.lights[0].type = scene::LightType::Point;
    s.lights[0].position = Vec3(0, kSeamH, 0);
    s.lights[0].radius = 0.5 * kSeamDiameter;
    s.lights[0].intensity = 500.0;
    scene::Quad& blocker = std::get<scene::Quad>(s.objects[1].shape);
    blocker.center = Vec3(kSeamH, kSeamHb, -3.0);
    blocker.size = scene::Vec2(2.0 * kSeamH, 6.0);
    scene::quadAxes(blocker.normal, blocker.uAxis, blocker.vAxis);
    return s;
}

// The fraction of the light's disk (radius R, facing q) seen from the floor point q past the
// blocker: a 64×64 grid over the disk, each segment to the light's point tested against the
// blocker's rectangle at y = hb. Independent of the renderer.
double diskVisibility(const Vec3& q) {
    const Vec3 c(0, kSeamH, 0);
    const Vec3 w = glm::normalize(c - q);
    const Vec3 a = std::abs(w.y) < 0.9 ? Vec3(0, 1, 0) : Vec3(1, 0, 0);
    const Vec3 u = glm::normalize(glm::cross(w, a));
    const Vec3 v = glm::cross(w, u);
    constexpr int n = 64;
    const double r = 0.5 * kSeamDiameter;
    int inside = 0, seen = 0;
    for (int j = 0; j < n; ++j)
        for (int i = 0; i < n; ++i) {
            const double x = (2.0 * (i + 0.5) / n - 1.0) * r, y = (2.0 * (j + 0.5) / n - 1.0) * r;
            if (x * x + y * y > r * r) continue;
            ++inside;
            const Vec3 l = c + x * u + y * v;
            const double t = (kSeamHb - q.y) / (l.y - q.y);
            const Vec3 h = q + t * (l - q);
            const bool blocked = h.x >= 0.0 && h.x <= 2.0 * kSeamH && h.z >= -6.0 && h.z <= 0.0;
            if (!blocked) ++seen;
        }
    return double(seen) / inside;
}

TEST(RasterPcss, APointLightPenumbraCrossesACubeFaceSeamWithoutACut) {
    const scene::Scene s = seamScene();
    const scene::Frame f = renderPcss(s);
    // Floor pixels within 0.3 of the seam (x = 4), from the lit side (z = 0.8) through the
    // penumbra into the umbra (z = -2.5): each side's mean error of the visibility against the
    // disk integral. PCSS is an estimate (a mean
    // blocker depth, 16 rotated taps), so single pixels differ; a cut would leave a whole side
    // wrong (before the fix: a streak of light along the seam in the umbra, and a narrower penumbra).
    double err[2] = {0, 0};
    int count[2] = {0, 0};
    test::forEachFloorPixel(s, f, [&](const Vec3& q, double v) {
        if (std::abs(q.x - kSeamH) > 0.3 || std::abs(q.x - kSeamH) < 0.02 || q.z < -2.5 || q.z > 0.8) return;
        const int side = q.x > kSeamH ? 1 : 0;
        err[side] += std::abs(v - diskVisibility(q));
        ++count[side];
    });
    ASSERT_GT(count[0], 500);
    ASSERT_GT(count[1], 500);
    for (int side = 0; side < 2; ++side) {
        const double mean = err[side] / count[side];
        std::printf("side %d (%s the seam): %d pixels, mean |V - V_disk| = %.4f\n", side,
                    side ? "+X face," : "-Y face,", count[side], mean);
        EXPECT_LT(mean, 0.04) << (side ? "+X" : "-Y") << " side of the seam";
    }
    EXPECT_LT(std::abs(err[0] / count[0] - err[1] / count[1]), 0.03);
    test::writePngToLookAt(f, "pcss_point_seam");
}

}  // namespace
}  // namespace shadowlab::raster
