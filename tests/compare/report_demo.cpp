// tests/compare/report_demo.cpp: writes a complete `shadowlab run`-style output folder from
// synthetic frames (reference, a shadow map with acne and a detached shadow, a ray tracer with
// a little terminator acne), so the difference images and report.html can be looked at before
// the real backends exist. Usage: compare_report_demo OUTDIR [WIDTH HEIGHT]
#include <cmath>
#include <filesystem>
#include <iostream>
#include <string>

#include "compare/bias_window.h"
#include "compare/compare.h"
#include "compare/report.h"
#include "compare/svg_plot.h"
#include "scene/frame_io.h"
#include "tests/compare/synthetic.h"

namespace sc = shadowlab::compare;

int main(int argc, char** argv) {
    if (argc < 2) {
        std::cerr << "usage: compare_report_demo OUTDIR [WIDTH HEIGHT]\n";
        return 2;
    }
    const std::filesystem::path dir = argv[1];
    std::filesystem::create_directories(dir);
    sc::test::SyntheticOptions o;
    if (argc >= 4) {
        o.width = std::stoi(argv[2]);
        o.height = std::stoi(argv[3]);
    }
    auto reference = sc::test::syntheticFrame(o);
    reference.attributes = {
        {"backend", "reference"}, {"precision", "double"}, {"ray_bias", "robust"}, {"version", "0.1.0"}};
    reference.timingsMs = {{"setup", 2.1}, {"render", 912.0}};

    sc::test::SyntheticOptions ro = o;
    ro.acne = ro.shiftShadow = ro.jaggies = true;
    auto raster = sc::test::syntheticFrame(ro);
    raster.attributes = {
        {"backend", "raster"}, {"shadow_map_size", "2048"}, {"depth_bias", "0.002"}, {"filter", "none"}};
    raster.timingsMs = {{"setup", 41.0}, {"shadow_pass", 3.2}, {"lit_pass", 5.1}, {"readback", 1.9}};

    sc::test::SyntheticOptions to = o;
    to.rayAcne = true;
    auto raytrace = sc::test::syntheticFrame(to);
    raytrace.attributes = {{"backend", "raytrace"}, {"precision", "float"}, {"ray_bias", "0.0001"}};
    raytrace.timingsMs = {{"bvh", 0.4}, {"render", 118.0}};

    sc::ReportInput report;
    report.sceneName = "synthetic";
    report.scenePath = "tests/compare/synthetic.h";
    report.planText = "synthetic frames: no render plan\n";
    report.objectNames = {"the plane", "the sphere"};
    shadowlab::scene::writeFrame(reference, dir / "reference.exr");
    shadowlab::scene::writePngLinear(dir / "reference.png", reference.width, reference.height, reference.beauty);
    report.reference = {"reference", "reference.png", reference};
    for (auto* entry : {&raytrace, &raster}) {
        const std::string name = entry->attributes["backend"];
        shadowlab::scene::writeFrame(*entry, dir / (name + ".exr"));
        shadowlab::scene::writePngLinear(dir / (name + ".png"), entry->width, entry->height, entry->beauty);
        const sc::Comparison c = sc::compareFrames(*entry, reference);
        shadowlab::scene::writePngDisplay(dir / ("diff-" + name + ".png"), c.width, c.height, c.diffRgb);
        std::cout << name << ": " << sc::summaryLine(c.metrics) << "\n";
        report.methods.push_back({name, name + ".png", "diff-" + name + ".png", *entry, c.metrics});
    }
    sc::writeReport(dir, report);

    // Sweep plots from made-up curves: acne falls with bias, leaks grow with it.
    std::vector<sc::BiasSample> bias;
    std::vector<sc::SweepPoint> sweep;
    for (int k = 0; k <= 12; ++k) {
        const double b = 0.0002 * std::pow(1.5, k);
        bias.push_back({b, 0.2 * std::exp(-b / 0.0006), 0.03 * std::pow(b / 0.01, 2)});
    }
    for (int size : {256, 512, 1024, 2048, 4096})
        for (int pcf = 0; pcf < 2; ++pcf)
            sweep.push_back({"raster", 8.0 + size * size * 1e-6 * (pcf ? 1.6 : 1.0),
                             0.3 / size * (pcf ? 0.6 : 1.0) + 0.002 * sc::test::hashNoise(size, pcf),
                             std::to_string(size) + (pcf ? " pcf2x2" : " none")});
    for (int spp : {1, 4, 16})
        sweep.push_back({"raytrace", 110.0 * spp, spp == 16 ? 0.0 : 0.001 / spp, std::to_string(spp) + " spp"});
    const sc::BiasWindow window = sc::findBiasWindow(bias);
    shadowlab::scene::writeTextAtomic(dir / "bias.svg",
                                      sc::renderSvg(sc::biasPlot(bias, window, "depth bias (world units)", true)));
    shadowlab::scene::writeTextAtomic(dir / "error-time.svg", sc::renderSvg(sc::errorTimePlot(sweep, 912.0)));
    std::cout << window.describe() << "\n";
    for (auto& b : bias) b.missedShadowRate *= 0.02;  // leaks start later: a window opens
    const sc::BiasWindow open = sc::findBiasWindow(bias);
    shadowlab::scene::writeTextAtomic(dir / "bias-window.svg",
                                      sc::renderSvg(sc::biasPlot(bias, open, "depth bias (world units)", true)));
    std::cout << open.describe() << "\n";
    std::cout << "wrote " << (dir / "report.html").string() << "\n";
    return 0;
}
