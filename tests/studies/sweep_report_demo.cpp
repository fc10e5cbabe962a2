// tests/studies/sweep_report_demo.cpp: runs the real sweep runner (studies::runSweep) on the
// default grid with a fake renderer that draws synthetic frames whose artifacts follow the
// settings the way real ones do (acne falls and peter-panning grows with bias, coarse maps are
// jagged, robust offsets are clean, one configuration fails), then writes the sweep report and
// a `run`-style report that includes the sweep summary, to look at in a browser.
// Usage: compare_sweep_report_demo OUTDIR   (writes OUTDIR/report.html and OUTDIR/sweep/)
//        compare_sweep_report_demo --from SWEEPDIR   (the report of a real `shadowlab sweep`
//        folder, from its journal and cached reference, until the app writes it itself)
#include <cmath>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <stdexcept>
#include <string>

#include "compare/compare.h"
#include "compare/report.h"
#include "scene/frame_io.h"
#include "scene/loader.h"
#include "scene/settings.h"
#include "studies/sweep.h"
#include "studies/sweep_report.h"
#include "tests/compare/synthetic.h"

namespace studies = shadowlab::studies;
namespace compare = shadowlab::compare;
namespace scene = shadowlab::scene;
namespace fs = std::filesystem;

namespace {

// A scene file the sizes and biases are scaled to: a sphere on a 20×20 floor, like `seed`.
const char* kScene = R"({
  "camera": { "position": [0, 2, 6], "look_at": [0, 0.7, 0], "up": [0, 1, 0],
              "fov_y": 40, "resolution": [640, 360], "near": 0.1, "far": 100 },
  "materials": { "matte": { "albedo": [0.8, 0.8, 0.8] } },
  "lights": [ { "type": "directional", "direction": [-1, -2, -1], "color": [1, 1, 1], "intensity": 3 } ],
  "objects": [
    { "name": "sphere", "type": "sphere", "center": [0, 1, 0], "radius": 1, "material": "matte" },
    { "name": "ground", "type": "quad", "center": [0, 0, 0], "normal": [0, 1, 0], "size": [20, 20], "material": "matte" }
  ]
})";

// Deterministic jitter of a few percent, so repeated frames do not time identically.
double jitter(int call) { return 1.0 + 0.06 * (compare::test::hashNoise(call, 7) - 0.5); }

scene::Frame fakeRender(const scene::Scene& s, const scene::RenderSettings& settings, scene::Backend backend) {
    static int call = 0;
    ++call;
    compare::test::SyntheticOptions o;
    o.width = s.camera.width;
    o.height = s.camera.height;
    scene::Frame f;
    if (backend == scene::Backend::Reference) {
        f = compare::test::syntheticFrame(o);
        f.timingsMs = {{"setup", 3.1}, {"primary", 210.0}, {"shadow", 690.0}};
    } else if (backend == scene::Backend::Raster) {
        const auto& r = settings.raster;
        if (r.shadowMapSize >= 4096 && r.filter == scene::ShadowFilter::Pcf2x2)
            throw std::runtime_error("VK_ERROR_OUT_OF_DEVICE_MEMORY: vkAllocateMemory for the 4096² shadow map (fake)");
        const double texel = 2.0 * scene::defaultDepthBias(s, r.shadowMapSize);  // world size of a texel
        const double k = r.depthBias / texel;                                    // constant bias in texels
        const double bias = k + 0.5 * r.slopeBias;  // what reaches the lit floor, in texels
        const double acne = 0.35 * std::exp(-bias / 0.3);
        o.acne = acne > 1e-5;
        o.acneProbability = acne;
        // The shadow detaches as the bias grows; slope bias pushes harder on the grazing caster.
        const int shift = int(k / 8.0 + r.slopeBias / 1.0);
        o.shiftShadow = shift > 0;
        o.shadowShiftPx = shift;
        o.jaggies = r.shadowMapSize < 1024;
        o.texelPx = std::max(1, 1024 / r.shadowMapSize) * (r.filter == scene::ShadowFilter::Pcf2x2 ? 1 : 2);
        f = compare::test::syntheticFrame(o);
        const double size = r.shadowMapSize;
        const double shadow = 0.4 + size * size * 1.1e-6 * (r.filter == scene::ShadowFilter::Pcf2x2 ? 1.5 : 1.0);
        f.timingsMs = {{"setup", 38.0 * jitter(call)},
                       {"shadow_pass", shadow * jitter(call + 1)},
                       {"lit_pass", 2.6 * jitter(call + 2)},
                       {"readback", 0.9}};
    } else {
        const auto& t = settings.raytrace;
        const double extent = s.bounds().diagonal();
        const double rel = t.rayBias / extent;
        if (!t.robustOffset) {
            if (rel < 1e-7) {
                o.acne = true;  // float rounding puts half the hit points under the floor
                o.acneProbability = 0.25;
            } else if (rel < 1e-5) {
                o.rayAcne = true;  // only the grazing terminator still self-shadows
            }
            const int shift = int(std::round(rel * 100.0));
            o.shiftShadow = shift > 0;
            o.shadowShiftPx = shift;
        }
        f = compare::test::syntheticFrame(o);
        const double scale = t.precision == scene::Precision::Double ? 1.7 : 1.0;
        f.timingsMs = {{"setup", 2.8 * jitter(call)},
                       {"primary", 30.0 * scale * jitter(call + 1)},
                       {"shadow", (t.robustOffset ? 68.0 : 62.0) * scale * jitter(call + 2)}};
    }
    f.attributes["backend"] = scene::toString(backend);
    return f;
}

}  // namespace

int main(int argc, char** argv) {
    if (argc < 2 || (std::string(argv[1]) == "--from" && argc < 3)) {
        std::cerr << "usage: compare_sweep_report_demo OUTDIR | --from SWEEPDIR\n";
        return 2;
    }
    try {
        if (std::string(argv[1]) == "--from") {
            const fs::path dir = argv[2];
            studies::SweepResult result;
            result.rows = studies::readJournal(dir / "results.jsonl");
            result.reference = scene::readFrame(dir / "reference.exr");
            result.referenceMs = result.reference.totalTimeMs();
            const auto scenePath =
                result.reference.attributes.count("scene") ? result.reference.attributes.at("scene") : "";
            const studies::SweepReportInput input =
                studies::makeSweepReportInput(fs::path(scenePath).stem().string(), scenePath, result);
            studies::writeSweepReport(dir, input);
            for (const auto& line : studies::describeSweep(input, studies::recommendBias(input.rows)))
                std::cout << line << "\n";
            std::cout << "wrote " << (dir / "report.html").string() << "\n";
            return 0;
        }
        const fs::path dir = argv[1];
        fs::create_directories(dir);
        std::ofstream(dir / "scene.json") << kScene;
        const scene::Scene s = scene::loadScene(dir / "scene.json");

        // The sweep, as `run` does it: the default grid at half resolution into DIR/sweep/.
        studies::SweepGrid grid = studies::defaultGrid(s, false);
        grid.resolution = "320x180";
        studies::SweepOptions options;
        options.outputDir = dir / "sweep";
        options.resume = true;  // a second run of the demo reuses the rows
        options.render = fakeRender;
        const studies::SweepResult result = studies::runSweep(s, grid, options);
        const studies::SweepReportInput input =
            studies::makeSweepReportInput("demo", (dir / "scene.json").string(), result);
        studies::writeSweepReport(dir / "sweep", input);
        for (const auto& line : studies::describeSweep(input, studies::recommendBias(input.rows)))
            std::cout << line << "\n";

        // The run report at full resolution, with the sweep's summary.
        compare::ReportInput report;
        report.sceneName = "demo";
        report.scenePath = (dir / "scene.json").string();
        report.objectNames = {"sphere", "ground"};
        const scene::RenderSettings defaults = scene::resolveSettings(s, {});
        const scene::Frame reference = fakeRender(s, defaults, scene::Backend::Reference);
        scene::writePngLinear(dir / "reference.png", reference.width, reference.height, reference.beauty);
        report.reference = {"reference", "reference.png", reference};
        for (const scene::Backend b : {scene::Backend::Raytrace, scene::Backend::Raster}) {
            const std::string backend = scene::toString(b);
            const scene::Frame frame = fakeRender(s, defaults, b);
            scene::writePngLinear(dir / (backend + ".png"), frame.width, frame.height, frame.beauty);
            const compare::Comparison c = compare::compareFrames(frame, reference);
            scene::writePngDisplay(dir / ("diff-" + backend + ".png"), c.width, c.height, c.diffRgb);
            report.methods.push_back({backend, backend + ".png", "diff-" + backend + ".png", frame, c.metrics});
        }
        report.sweep = studies::summarizeSweep(input, "sweep/report.html");
        compare::writeReport(dir, report);
        std::cout << "wrote " << (dir / "report.html").string() << " and " << (dir / "sweep" / "report.html").string()
                  << "\n";
    } catch (const std::exception& e) {
        std::cerr << "compare_sweep_report_demo: " << e.what() << "\n";
        return 1;
    }
    return 0;
}
