// app/main.cpp: the `shadowlab` program: parses the command line (CLI11), calls the
// subcommand, and turns every failure into one message and a non-zero exit code:
//   1  a render or device failure, 2  bad input (scene, frame, command line).
#include <cstdio>
#include <iostream>

#include <CLI/CLI.hpp>

#include "app/commands.h"
#include "app/guards.h"
#include "raster/vulkan_error.h"
#include "scene/error.h"

namespace {

using shadowlab::app::SceneOptions;

void addSceneOptions(CLI::App& cmd, SceneOptions& o) {
    cmd.add_option("SCENE", o.scene, "Scene file, or the name of a shipped scene (e.g. seed)")->required();
    cmd.add_option("--resolution", o.resolution, "Image size WxH, overriding the scene's camera (e.g. 640x360)");
    auto& s = o.settings;
    cmd.add_option("--shadow-map-size", s.shadowMapSize, "raster: shadow-map texels per side (default 2048)");
    cmd.add_option("--depth-bias", s.depthBias,
                   "raster: constant depth bias in world units (default: half a shadow-map texel)");
    cmd.add_option("--slope-bias", s.slopeBias,
                   "raster: slope-scaled bias in texels, times tan(angle to light) (default 1)");
    cmd.add_option("--filter", s.filter,
                   "raster: shadow-map filter none|pcf2x2|pcf|poisson|pcss (default pcf2x2: bilinear 2x2 PCF; pcss: "
                   "soft shadows sized by a spot/point light's radius)");
    cmd.add_option("--pcf-size", s.pcfSize, "raster: pcf taps per side, or poisson kernel diameter in texels (default 3)");
    cmd.add_option("--normal-offset", s.normalOffset,
                   "raster: move receivers along their normal by this many texels (default 0)");
    cmd.add_flag("--receiver-plane-bias", s.receiverPlaneBias,
                 "raster: compare each filter tap against the receiver's plane (from screen-space derivatives) "
                 "instead of the slope bias");
    cmd.add_flag("--hardware-bias", s.hardwareBias,
                 "raster: apply the constant and slope bias with the rasterizer's depth-bias state in the depth "
                 "pass of directional maps (converted from world units and texels; recorded in the Frame) "
                 "instead of in the lit shader");
    cmd.add_flag("--fit-light-frustum", s.fitLightFrustum,
                 "raster: fit each light's map to the casters of visible receivers, not the scene's bounds");
    cmd.add_option("--cascades", s.cascades,
                   "raster: cascaded shadow maps per directional light, 1..4 (default 1: one map)");
    cmd.add_option("--cascade-blend", s.cascadeBlend,
                   "raster: blend each cascade into the next over this fraction of its slice before the split, "
                   "0..0.5 (default 0: switch abruptly)");
    cmd.add_option("--device", s.device, "raster: Vulkan device index or name part (default: lavapipe)");
    cmd.add_option("--ray-bias", s.rayBias,
                   "raytrace: shadow-ray offset along the normal in world units, or 'robust' "
                   "(default: 1e-4 of the scene's size)");
    cmd.add_option("--precision", s.precision, "raytrace: float|double (default float)");
    cmd.add_option("--samples", s.samples, "raytrace: shadow samples per pixel for area lights (default 16)");
    cmd.add_option("--threads", s.threads, "raytrace: worker threads, 0 = all cores (default 0)");
    cmd.add_flag("--validate", s.validate,
                 "raster: enable VK_LAYER_KHRONOS_validation; any message makes the command fail");
    cmd.add_flag("--explain", o.explain, "Print what this scene needs (the render plan) before rendering");
    cmd.add_flag("--json", o.json, "Print machine-readable results on stdout");
}

}  // namespace

int main(int argc, char** argv) {
    CLI::App app{"shadowlab: renders a scene with a Vulkan shadow map and a CPU ray tracer and shows,\n"
                 "with difference images and numbers, how each gets its shadows wrong against a\n"
                 "double-precision ray-traced reference."};
    app.require_subcommand(1);
    app.set_version_flag("--version", std::string("shadowlab ") + SHADOWLAB_VERSION);

    shadowlab::app::RunOptions runOptions;
    auto* runCmd = app.add_subcommand("run", "The main job: reference, both backends, difference images, "
                                             "metrics.json and report.html in one folder");
    addSceneOptions(*runCmd, runOptions.common);
    runCmd->add_option("-o,--output", runOptions.outputDir, "Output folder (created)")->required();
    runCmd->add_flag("--no-raster", runOptions.skipRaster, "Skip the Vulkan backend (no Vulkan on this machine)");
    runCmd->add_flag("--no-sweep", runOptions.skipSweep, "Skip the small settings sweep (error against run time, bias windows)");

    shadowlab::app::RenderOptions renderOptions;
    auto* renderCmd = app.add_subcommand("render", "Render one backend into a Frame (.exr: every AOV and "
                                                   "metadata) or a beauty image (.png)");
    addSceneOptions(*renderCmd, renderOptions.common);
    auto* backendOption =
        renderCmd->add_option("--backend", renderOptions.backend,
                              "raster|raytrace|reference (default raytrace; raster with --view)")
            ->check(CLI::IsMember({"raster", "raytrace", "reference"}));
    renderCmd->add_option("-o,--output", renderOptions.output, "Output file, .exr or .png")->required();
    renderCmd->add_option("--view", renderOptions.view,
                          "raster debug view instead of the beauty image (.png only): shadow-map (every map "
                          "layer as depth), cascades (beauty tinted by cascade), texel-density (shadow texel vs "
                          "screen pixel size), light-frustum (each map's frustum drawn over the scene; what it "
                          "covers tinted, lit points outside it striped magenta)")
        ->check(CLI::IsMember({"shadow-map", "cascades", "texel-density", "light-frustum"}));

    shadowlab::app::SweepOptions sweepOptions;
    auto* sweepCmd = app.add_subcommand("sweep", "Render a grid of settings for both backends, time each and "
                                                 "measure each against the reference: results.csv, results.json, "
                                                 "plots and report.html");
    addSceneOptions(*sweepCmd, sweepOptions.common);
    sweepCmd->add_option("-o,--output", sweepOptions.outputDir, "Output folder (created)")->required();
    sweepCmd->add_option("--grid", sweepOptions.grid, "Grid file (JSON, see docs/sweep.md); default: the built-in grid");
    sweepCmd->add_flag("--resume", sweepOptions.resume, "Continue a stopped sweep in the same folder");
    sweepCmd->add_flag("--quick", sweepOptions.quick, "The small built-in grid (what `run` includes)");
    sweepCmd->add_option("--repetitions", sweepOptions.repetitions, "Timed frames per configuration (default 3)")
        ->check(CLI::Range(1, 100));

    shadowlab::app::StabilityCommandOptions stabilityOptions;
    auto* stabilityCmd = app.add_subcommand(
        "stability", "Run stiff and extreme cases through the reference and both backends (defaults and best "
                     "bias): acne and leak rates, bias windows or 'stiff', NaN/Inf, analytic check; exits 1 "
                     "when the reference misses an analytic answer or a backend gives NaN/Inf or fails");
    stabilityCmd->add_option("SCENES", stabilityOptions.scenes,
                             "Scene files or shipped names (default: every scenes/extreme case)");
    stabilityCmd->add_option("-o,--output", stabilityOptions.outputDir, "Output folder (created)")->required();
    stabilityCmd->add_option("--resolution", stabilityOptions.resolution, "Render size WxH (default 160x90)");
    stabilityCmd->add_option("--shadow-map-size", stabilityOptions.shadowMapSize, "raster: map size for every case");
    stabilityCmd->add_flag("--no-search", stabilityOptions.noSearch, "Skip the bias search (defaults only)");
    stabilityCmd->add_flag("--full", stabilityOptions.fullGrid, "Search biases over the full default grid");
    stabilityCmd->add_flag("--validate", stabilityOptions.validate, "Vulkan validation on every raster render");
    stabilityCmd->add_flag("--json", stabilityOptions.json, "Print the cases as JSON on stdout");

    shadowlab::app::CompareOptions compareOptions;
    auto* compareCmd = app.add_subcommand("compare", "Classify a method's shadows against a reference Frame "
                                                     "and write the difference image");
    compareCmd->add_option("METHOD", compareOptions.method, "Method Frame (.exr from `render`)")->required();
    compareCmd->add_option("REFERENCE", compareOptions.reference, "Reference Frame (.exr)")->required();
    compareCmd->add_option("-o,--output", compareOptions.output, "Difference image (.png)")->required();
    compareCmd->add_flag("--json", compareOptions.json, "Print the metrics as JSON on stdout");

    bool infoValidate = false;
    auto* infoCmd = app.add_subcommand("info", "Vulkan devices, driver and API versions, lavapipe or not");
    infoCmd->add_flag("--validate", infoValidate, "Also check that the validation layer loads");

    try {
        app.parse(argc, argv);
    } catch (const CLI::ParseError& e) {
        return app.exit(e) == 0 ? 0 : 2;
    }

    try {
        // Every command's results on stdout (--json) must reach it: a failed write is an error.
        using shadowlab::app::finishStandardOutput;
        if (*runCmd) return finishStandardOutput(shadowlab::app::run(runOptions));
        if (*renderCmd) {
            // The debug views are views of the shadow maps: --view alone means the raster backend.
            if (renderOptions.view && backendOption->count() == 0) renderOptions.backend = "raster";
            return finishStandardOutput(shadowlab::app::render(renderOptions));
        }
        if (*compareCmd) return finishStandardOutput(shadowlab::app::compareFiles(compareOptions));
        if (*infoCmd) return finishStandardOutput(shadowlab::app::info(infoValidate));
        if (*sweepCmd) return finishStandardOutput(shadowlab::app::sweep(sweepOptions));
        if (*stabilityCmd) return finishStandardOutput(shadowlab::app::stability(stabilityOptions));
    } catch (const shadowlab::scene::SceneError& e) {
        std::cerr << "shadowlab: error: " << e.what() << "\n";
        return 2;
    } catch (const shadowlab::scene::InputError& e) {
        std::cerr << "shadowlab: error: " << e.what() << "\n";
        return 2;
    } catch (const std::exception& e) {
        std::cerr << "shadowlab: error: " << e.what() << "\n";
        return 1;
    }
    return 2;
}
