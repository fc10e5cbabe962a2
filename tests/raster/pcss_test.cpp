// tests/raster/pcss_test.cpp: percentage-closer soft shadows (--filter pcss) for a spot light with
// a radius: the penumbra of a straight blocker edge widens with the receiver–blocker distance as
// Fernando's formula says, on lavapipe with the validation layer.
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <vector>

#include <gtest/gtest.h>

#include "raster/renderer.h"
#include "tests/raster/test_scenes.h"

namespace shadowlab::raster {
namespace {

using test::Vec3;

// A spot light of diameter `size` at height H straight above the origin, pointing down; a square
// blocker at height hb covering x in [-6, 0] (edge along z at x = 0); the floor y = 0. The camera
// looks at the edge's shadow from the lit side, where the blocker cannot hide it.
constexpr double kH = 10.0, kSize = 1.0;

scene::Scene edgeScene(double hb) {
    scene::Scene s;
    s.camera.position = Vec3(2.5, 3.0, 0.0);
    s.camera.lookAt = Vec3(0.0, 0.0, 0.0);
    s.camera.up = Vec3(0, 1, 0);
    s.camera.fovYDegrees = 40.0;
    s.camera.width = 320;
    s.camera.height = 180;
    s.camera.near = 0.1;
    s.camera.far = 100.0;
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
    auto quad = [](const Vec3& c, double side) {
        scene::Quad q;
        q.center = c;
        q.normal = Vec3(0, 1, 0);
        q.size = scene::Vec2(side, side);
        scene::quadAxes(q.normal, q.uAxis, q.vAxis);
        return q;
    };
    s.objects.push_back({"floor", quad(Vec3(0, 0, 0), 20.0), 0});
    s.objects.push_back({"blocker", quad(Vec3(-3, hb, 0), 6.0), 0});
    return s;
}

// The 10%–90% width of the visibility ramp across the edge, on the floor near z = 0: floor pixels
// (found by the test's own ray–plane intersection) are binned by x, each bin's mean visibility
// taken, and the 0.1 and 0.9 crossings interpolated.
double rampWidth(const scene::Scene& s, const scene::Frame& f) {
    const scene::CameraBasis cam = scene::cameraBasis(s.camera);
    constexpr double lo = -1.2, hi = 1.2, bin = 0.02;
    const int bins = int((hi - lo) / bin);
    std::vector<double> sum(std::size_t(bins), 0.0);
    std::vector<int> count(std::size_t(bins), 0);
    for (int y = 0; y < f.height; ++y)
        for (int x = 0; x < f.width; ++x) {
            const std::size_t i = std::size_t(y) * std::size_t(f.width) + std::size_t(x);
            if (f.objectId[i] != 1.0f) continue;  // the floor
            const Vec3 d = test::pixelRay(cam, x, y);
            const Vec3 q = cam.position + (-cam.position.y / d.y) * d;
            if (std::abs(q.z) > 0.4 || q.x < lo || q.x >= hi) continue;
            const int b = int((q.x - lo) / bin);
            sum[std::size_t(b)] += f.visibility[i];
            ++count[std::size_t(b)];
        }
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
    return crossing(0.9) - crossing(0.1);
}

scene::Frame renderPcss(const scene::Scene& s) {
    scene::RasterSettings r = test::validatedSettings(512, 0.01, 1.0, scene::ShadowFilter::Pcss);
    scene::Frame f = render(s, test::planFor(s, r), r);
    EXPECT_EQ(f.attributes["validation_messages"], "0") << "validation messages were printed above";
    EXPECT_EQ(f.attributes["filter"], "pcss");
    return f;
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
    ASSERT_TRUE(std::isfinite(widths[0]) && std::isfinite(widths[1])) << widths[0] << " " << widths[1];
    // The visibility under a disk kernel of diameter W across a straight edge is the disk's area
    // beyond a line; it passes 10% and 90% at ±0.687·W/2, so the 10–90 width is 0.687·W.
    for (std::size_t i = 0; i < 2; ++i)
        EXPECT_NEAR(widths[i], 0.687 * formula[i], 0.3 * 0.687 * formula[i] + 0.04)
            << "blocker " << (i ? 4 : 2) << " above the floor";
    // The ratio does not depend on the kernel's shape: (4/6)/(2/8) = 2.67.
    EXPECT_NEAR(widths[1] / widths[0], formula[1] / formula[0], 0.2 * formula[1] / formula[0]);
}

TEST(RasterPcss, APointSizedLightKeepsTheHardShadowOfPoisson) {
    // Without a light size pcss has nothing to size a penumbra with: it is `poisson` with pcfSize.
    scene::Scene s = edgeScene(3.0);
    s.lights[0].radius = 0.0;
    scene::RasterSettings pcss = test::validatedSettings(512, 0.01, 1.0, scene::ShadowFilter::Pcss);
    scene::RasterSettings poisson = pcss;
    poisson.filter = scene::ShadowFilter::Poisson;
    const scene::Frame a = render(s, test::planFor(s, pcss), pcss);
    const scene::Frame b = render(s, test::planFor(s, poisson), poisson);
    EXPECT_EQ(a.visibility, b.visibility);
    EXPECT_EQ(a.attributes.at("validation_messages"), "0");
}

}  // namespace
}  // namespace shadowlab::raster
