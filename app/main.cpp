// app/main.cpp: the `shadowlab` program: parses the command line (CLI11), calls the
// subcommand, and turns every failure into one message and a non-zero exit code:
//   1  a render or device failure, 2  bad input (scene, frame, command line),
//   3  a method broke an error budget (compare, run, check).
#include <csignal>
#include <cstdio>
#include <iostream>
#include <string>
#include <vector>

#include <CLI/CLI.hpp>

#include "app/commands.h"
#include "app/guards.h"
#include "raster/vulkan_error.h"
#include "scene/backend.h"
#include "scene/error.h"
#include "scene/interrupt.h"
#include "studies/shard.h"

namespace {

using shadowlab::app::SceneOptions;

// The scene and what decides the view: the image size, the camera, the ground, the sun.
void addViewOptions(CLI::App& cmd, SceneOptions& o) {
    cmd.add_option("SCENE", o.scene, "Scene file, or the name of a shipped scene (e.g. seed)")->required();
    cmd.add_option("--resolution", o.resolution, "Image size WxH, overriding the scene's camera (e.g. 640x360)");
    cmd.add_option("--camera", o.camera,
                   "View: a camera of the scene's glTF file by index (0, 1, ...) or name, or 'auto' to search a view "
                   "that shows shadows (default: the file's first camera; a search where it has none)");
    cmd.add_flag_function(
        "--ground", [&o](std::int64_t) { o.ground = true; },
        "Put a ground under the model, sized from its bounds (default for a glTF scene without a floor of its own)");
    cmd.add_flag_function(
        "--no-ground", [&o](std::int64_t) { o.ground = false; }, "No added ground");
    cmd.add_option("--sun", o.sun,
                   "AZIMUTH,ELEVATION in degrees: the directional light's direction (azimuth in the ground plane from "
                   "+Z toward +X, elevation above the horizon; default: the scene's, or a search)");
    cmd.add_flag("--explain", o.explain, "Print what this scene needs (the render plan) before rendering");
}

void addSceneOptions(CLI::App& cmd, SceneOptions& o) {
    addViewOptions(cmd, o);
    auto& s = o.settings;
    cmd.add_option("--shadow-map-size", s.shadowMapSize,
                   "raster: shadow-map texels per side (default: chosen per view, the power of two in 256..2048 whose "
                   "texel is no larger than a pixel on the visible receivers and gives the smallest caster 4 "
                   "texels; 2048 with cascades; --explain says why)");
    cmd.add_option("--depth-bias", s.depthBias,
                   "raster: constant depth bias in world units (default: half a texel of each map as fitted or "
                   "cascaded)");
    cmd.add_option("--slope-bias", s.slopeBias,
                   "raster: slope-scaled bias in texels, times tan(angle to light) up to tan 10; past that the rest "
                   "lifts the lookup along the normal, so a grazing plane keeps its margin (default 1)");
    cmd.add_option("--filter", s.filter,
                   "raster: shadow-map filter none|pcf2x2|pcf|poisson|pcss|vsm|evsm2|evsm4|esm|msm (default pcf2x2: "
                   "bilinear 2x2 PCF; pcss: soft shadows sized by a spot/point light's radius; vsm..msm: filterable "
                   "moment maps, docs/raster.md)");
    cmd.add_option("--pcf-size", s.pcfSize,
                   "raster: pcf taps per side, or poisson kernel diameter in texels (default 3)");
    cmd.add_option("--min-variance", s.minVariance,
                   "raster: vsm/evsm variance floor, normalized depth² (default 1e-6)");
    cmd.add_option("--bleeding-reduction", s.bleedReduction,
                   "raster: vsm/evsm light-bleeding reduction, 0..0.99 of the visibility tail cut (default 0.2)");
    cmd.add_option("--evsm-positive", s.evsmPositive, "raster: evsm positive warp exponent, 0..42 (default 40)");
    cmd.add_option("--evsm-negative", s.evsmNegative, "raster: evsm4 negative warp exponent, 0..42 (default 5)");
    cmd.add_option("--esm-exponent", s.esmExponent, "raster: esm exponent, 0..85 (default 80)");
    cmd.add_option("--moment-bias", s.momentBias, "raster: msm moment bias (default 3e-5)");
    cmd.add_option("--blur-width", s.blurWidth, "raster: vsm..msm box blur width in texels, odd, 1..63 (default 5)");
    cmd.add_option("--normal-offset", s.normalOffset,
                   "raster: move receivers along their normal by this many texels, on top of the slope bias's lift "
                   "past tan 10 (default 0)");
    cmd.add_flag("--receiver-plane-bias", s.receiverPlaneBias,
                 "raster: compare each filter tap against the receiver's plane (from screen-space derivatives) "
                 "instead of the slope bias");
    cmd.add_flag("--hardware-bias", s.hardwareBias,
                 "raster: apply the constant and slope bias with the rasterizer's depth-bias state in the depth "
                 "pass of directional maps (converted from world units and texels; recorded in the Frame) "
                 "instead of in the lit shader");
    // Unset (the default: fitted) unless given. --fit-light-frustum[=on|off] goes through a string
    // so a bad value is a parse error (exit 2), and --no-fit-light-frustum is its short form of off.
    static std::string fitText;
    cmd.add_flag("--fit-light-frustum{on}", fitText,
                 "raster: fit each light's map to the casters of visible receivers (default on; "
                 "--fit-light-frustum=off or --no-fit-light-frustum: the scene's bounding sphere)")
        ->each([&s](const std::string& v) {
            if (v == "on" || v == "true" || v == "1")
                s.fitLightFrustum = true;
            else if (v == "off" || v == "false" || v == "0")
                s.fitLightFrustum = false;
            else
                throw CLI::ValidationError("--fit-light-frustum: expected on or off, got '" + v + "'");
        });
    cmd.add_flag_callback(
        "--no-fit-light-frustum", [&s] { s.fitLightFrustum = false; },
        "raster: the scene's bounding-sphere map (and the whole spot cone and cube), not fitted");
    cmd.add_flag_callback(
        "--no-snap", [&s] { s.snapLightFrustum = false; },
        "raster: leave fitted directional maps and cascades unsnapped (they then swim as the camera moves; for "
        "measuring what snapping buys, docs/temporal.md)");
    cmd.add_option("--cascades", s.cascades,
                   "raster: cascaded shadow maps per directional light, 1..4 (default: chosen per view, 1 unless "
                   "one map's texel exceeds 2 pixels at the nearest receiver; --explain says why)");
    cmd.add_option("--cascade-blend", s.cascadeBlend,
                   "raster: blend each cascade into the next over this fraction of its slice before the split, "
                   "0..0.5 (default 0: switch abruptly)");
    cmd.add_option("--device", s.device, "raster: Vulkan device index or name part (default: lavapipe)");
    cmd.add_option(
        "--ray-bias", s.rayBias,
        "raytrace: shadow-ray offset along the normal in world units, or 'robust' "
        "(default: half a pixel's footprint at each point, at most 1e-4 of the scene's size and at least 16 float "
        "steps of its largest coordinate)");
    cmd.add_option("--precision", s.precision, "raytrace: float|double (default float)");
    cmd.add_option("--samples", s.samples, "raytrace: shadow samples per pixel for area lights (default 16)");
    cmd.add_option("--threads", s.threads, "raytrace: worker threads, 0 = all cores (default 0)");
    cmd.add_flag("--validate", s.validate,
                 "raster: enable VK_LAYER_KHRONOS_validation; any message makes the command fail");
    cmd.add_flag("--json", o.json, "Print machine-readable results on stdout");
}

void addBudgetOptions(CLI::App& cmd, shadowlab::app::BudgetOptions& o) {
    using shadowlab::scene::budgetInfo;
    using shadowlab::scene::BudgetKind;
    const char* help[shadowlab::scene::kBudgetKindCount] = {
        "Budget: false + missed shadow pixels, as a rate of the counted pixels (0.005 or 0.5%) or a count (120px)",
        "Budget: false-shadow (acne) pixels, a rate (0.5%) or a count (120px)",
        "Budget: missed-shadow (leak) pixels, a rate (0.5%) or a count (120px)",
        "Budget: self-shadow acne pixels (needs the method's blocker ids), a rate (0.5%) or a count (120px)",
        "Budget: mean |V_method - V_reference| over the counted pixels, 0..1 or a percentage",
        "Budget: least IoU of the shadowed sets, 0..1 or a percentage",
        "Budget: light-bleeding pixels (missed shadow far from its blocker; needs the reference's blocker "
        "distances), a rate (0.5%) or a count (120px)",
    };
    for (int k = 0; k < shadowlab::scene::kBudgetKindCount; ++k)
        cmd.add_option(budgetInfo(BudgetKind(k)).option, o.text[k], std::string(help[k]) + "; a broken budget exits 3");
}

}  // namespace

int main(int argc, char** argv) {
    // The files are the product, the terminal lines are not: a log piped into a reader that quits
    // early (`| head`) must not kill a render before its output is renamed into place, so a write
    // to a closed pipe fails quietly instead of raising SIGPIPE.
    std::signal(SIGPIPE, SIG_IGN);
    // Ctrl-C in the middle of a run leaves no hidden staging folder behind.
    shadowlab::scene::removeTemporariesOnInterrupt();
    CLI::App app{
        "shadowlab: renders a scene with a Vulkan shadow map and a CPU ray tracer and shows,\n"
        "with difference images and numbers, how each gets its shadows wrong against a\n"
        "double-precision ray-traced reference."};
    app.require_subcommand(1);
    app.set_version_flag("--version", std::string("shadowlab ") + SHADOWLAB_VERSION);

    shadowlab::app::RunOptions runOptions;
    auto* runCmd = app.add_subcommand("run",
                                      "The main job: reference, both backends, difference images, "
                                      "metrics.json and report.html in one folder");
    addSceneOptions(*runCmd, runOptions.common);
    runCmd->add_option("-o,--output", runOptions.outputDir, "Output folder (created)")->required();
    runCmd->add_flag("--no-raster", runOptions.skipRaster, "Skip the Vulkan backend (no Vulkan on this machine)");
    runCmd->add_flag("--no-sweep", runOptions.skipSweep,
                     "Skip the small settings sweep (error against run time, bias windows)");
    addBudgetOptions(*runCmd, runOptions.budgets);

    shadowlab::app::RenderOptions renderOptions;
    std::string backendName = shadowlab::scene::toString(renderOptions.backend);
    std::vector<std::string> backendNames;
    for (const shadowlab::scene::Backend b : shadowlab::scene::kBackends)
        backendNames.push_back(shadowlab::scene::toString(b));
    auto* renderCmd = app.add_subcommand("render",
                                         "Render one backend into a Frame (.exr: every AOV and "
                                         "metadata) or a beauty image (.png)");
    addSceneOptions(*renderCmd, renderOptions.common);
    auto* backendOption =
        renderCmd
            ->add_option("--backend", backendName, "raster|raytrace|reference (default raytrace; raster with --view)")
            ->check(CLI::IsMember(backendNames));
    renderCmd->add_option("-o,--output", renderOptions.output, "Output file, .exr or .png")->required();
    renderCmd
        ->add_option("--view", renderOptions.view,
                     "raster debug view instead of the beauty image (.png only): shadow-map (every map "
                     "layer as depth), cascades (beauty tinted by cascade), texel-density (shadow texel vs "
                     "screen pixel size), light-frustum (each map's frustum drawn over the scene; what it "
                     "covers tinted, lit points outside it striped magenta)")
        ->check(CLI::IsMember({"shadow-map", "cascades", "texel-density", "light-frustum"}));

    shadowlab::app::SweepOptions sweepOptions;
    auto* sweepCmd = app.add_subcommand("sweep",
                                        "Render a grid of settings for both backends, time each and "
                                        "measure each against the reference: results.csv, results.json, "
                                        "plots and report.html");
    addSceneOptions(*sweepCmd, sweepOptions.common);
    sweepCmd->add_option("-o,--output", sweepOptions.outputDir, "Output folder (created)")->required();
    sweepCmd->add_option("--grid", sweepOptions.grid,
                         "Grid file (JSON, see docs/sweep.md); default: the built-in grid");
    sweepCmd->add_flag("--resume", sweepOptions.resume, "Continue a stopped sweep in the same folder");
    sweepCmd->add_flag("--quick", sweepOptions.quick, "The small built-in grid (what `run` includes)");
    sweepCmd->add_option("--repetitions", sweepOptions.repetitions, "Timed frames per configuration (default 3)")
        ->check(CLI::Range(1, 100));
    sweepCmd->add_option(
        "--shard", sweepOptions.shard,
        "K/N: render only shard K (from 0) of N into OUTPUT/shard-K-of-N, sharing OUTPUT/reference.exr; "
        "join the shards with `shadowlab merge` (docs/sweep.md)");
    sweepCmd
        ->add_option("--flicker", sweepOptions.flicker,
                     "The flicker axis: also render every row along a short path (KIND, default subtexel: "
                     "sub-texel camera steps) and record flicker, error variation and swim (docs/sweep.md)")
        ->expected(0, 1);
    sweepCmd->add_option("--flicker-frames", sweepOptions.flickerFrames, "Frames of the flicker path (default 4)")
        ->check(CLI::Range(2, 64));

    shadowlab::app::MergeOptions mergeOptions;
    auto* mergeCmd =
        app.add_subcommand("merge",
                           "Join the shards of a sweep (`sweep --shard K/N`) into the results.csv, "
                           "results.json, plots and report.html of the whole sweep, those of a "
                           "check (`check --shard K/N`) into its junit.xml, summary.md, summary.html and cases/, "
                           "or those of a path (`path --shard K/N`) into its metrics and report");
    mergeCmd
        ->add_option(
            "DIRS", mergeOptions.inputs,
            "Shard folders, or folders holding shard-K-of-N folders (the -o of `sweep`, `check` or `path --shard`)")
        ->required();
    mergeCmd->add_option("-o,--output", mergeOptions.outputDir, "Merged folder (default: the one input folder)");
    mergeCmd->add_flag("--json", mergeOptions.json, "Print the merged rows as JSON on stdout");

    shadowlab::app::PathCommandOptions pathOptions;
    auto* pathCmd = app.add_subcommand("path",
                                       "Render frames along a camera or light path with the reference and "
                                       "both backends and measure flicker and swimming (docs/temporal.md)");
    addSceneOptions(*pathCmd, pathOptions.common);
    pathCmd->add_option("-o,--output", pathOptions.outputDir, "Output folder (created)")->required();
    pathCmd->add_option("--kind", pathOptions.kind,
                        "orbit|dolly|pan|subtexel|sun-azimuth|sun-elevation|light-move|gltf-animation (default: the "
                        "scene's \"path\" block, else orbit)");
    pathCmd
        ->add_option("--camera-animation", pathOptions.cameraAnimation,
                     "Follow a glTF camera animation of a .gltf/.glb scene (NAME or INDEX; empty: the first); "
                     "the same as --kind gltf-animation")
        ->expected(0, 1);
    pathCmd->add_option("--frames", pathOptions.frames, "Frames along the path (default 12)");
    pathCmd->add_option("--amount", pathOptions.amount,
                        "The path's extent: degrees (orbit 20, sun-azimuth 20, sun-elevation 10), fraction of the "
                        "distance to the look-at point (dolly 0.3, pan 0.1), per-frame step in min(texel, pixel) "
                        "(subtexel 0.1), fraction of the scene's size (light-move 0.1)");
    pathCmd->add_option("--light", pathOptions.light, "The light a light path moves (default 0)");
    pathCmd->add_flag("--resume", pathOptions.resume, "Continue a stopped path in the same folder");
    pathCmd->add_option("--shard", pathOptions.shard,
                        "K/N: render only the frames t with t mod N = K into OUTPUT/shard-K-of-N; `shadowlab merge "
                        "OUTPUT` measures the merged frames (docs/temporal.md)");
    pathCmd->add_flag("--no-raster", pathOptions.skipRaster, "Skip the Vulkan backend");
    pathCmd->add_flag("--no-raytrace", pathOptions.skipRaytrace, "Skip the ray-traced method");
    pathCmd->add_flag("--no-held-view", pathOptions.noHeldView,
                      "Camera paths: skip the raster frames drawn from frame 0's camera");

    shadowlab::app::StabilityCommandOptions stabilityOptions;
    auto* stabilityCmd =
        app.add_subcommand("stability",
                           "Run stiff and extreme cases through the reference and both backends (defaults and best "
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
    auto* compareCmd = app.add_subcommand("compare",
                                          "Classify a method's shadows against a reference Frame "
                                          "and write the difference image");
    compareCmd
        ->add_option("METHOD", compareOptions.method,
                     "Method Frame (.exr from `render`), or a shadow mask (.png, or with --mask-*)")
        ->required();
    compareCmd->add_option("REFERENCE", compareOptions.reference, "Reference Frame (.exr)")->required();
    compareCmd->add_option("-o,--output", compareOptions.output, "Difference image (.png)")->required();
    compareCmd->add_flag("--json", compareOptions.json, "Print the metrics as JSON on stdout");
    compareCmd->add_option(
        "--heat", compareOptions.heat,
        "Also write the |V_method - V_reference| heat map (.png; docs/compare.md has its color scale)");
    addBudgetOptions(*compareCmd, compareOptions.budgets);
    compareCmd->add_flag("--allow-different-scene", compareOptions.allowDifferentScene,
                         "Compare frames that record different scenes, cameras (a warning instead of exit 2)");
    compareCmd->add_option("--mask-channel", compareOptions.maskChannel,
                           "METHOD is a shadow mask: read this channel of it (1 = lit); ids, N.L and which pixels "
                           "count come from REFERENCE");
    compareCmd->add_flag("--mask-invert", compareOptions.maskInvert, "METHOD is a shadow mask storing 1 = shadowed");
    compareCmd->add_flag("--mask-srgb", compareOptions.maskSrgb,
                         "METHOD is a shadow mask with sRGB-encoded values (default: linear)");

    shadowlab::app::ExportOptions exportOptions;
    auto* exportCmd = app.add_subcommand("export",
                                         "Write the scene run renders (its view, sun and ground) as glTF "
                                         "2.0 with KHR_lights_punctual (.glb or .gltf) for another engine "
                                         "(docs/export.md)");
    addViewOptions(*exportCmd, exportOptions.common);
    exportCmd->add_option("-o,--output", exportOptions.output, "The glTF file (.glb or .gltf)")->required();
    exportCmd->add_option("--tolerance", exportOptions.tolerance,
                          "Largest sagitta of a tessellated sphere, as a fraction of its radius (default 1e-3)");

    shadowlab::app::CheckOptions checkOptions;
    auto* checkCmd = app.add_subcommand(
        "check",
        "CI gate: run a suite of cases (scene, backend, settings, budgets) against the reference, their "
        "budgets and a stored baseline; writes junit.xml, summary.md, summary.html and one JSON per case; exits 3 "
        "when a case fails, 1 when one cannot render");
    checkCmd->add_option("SUITE", checkOptions.suite, "Suite file (JSON, see docs/ci.md)")->required();
    checkCmd->add_option("-o,--output", checkOptions.outputDir, "Output folder (replaced as a whole)")->required();
    checkCmd->add_option("--baseline", checkOptions.baseline, "Baseline file instead of the suite's \"baseline\"");
    checkCmd->add_flag("--update-baseline", checkOptions.updateBaseline,
                       "Write this run's metrics as the baseline (budgets still apply; no regression check)");
    checkCmd->add_option("--shard", checkOptions.shard,
                         "K/N: run only shard K (from 0) of N of the cases into OUTPUT/shard-K-of-N; join the shards "
                         "with `shadowlab merge OUTPUT` (docs/ci.md)");

    bool infoValidate = false;
    auto* infoCmd = app.add_subcommand("info", "Vulkan devices, driver and API versions, lavapipe or not");
    infoCmd->add_flag("--validate", infoValidate, "Also check that the validation layer loads");

    shadowlab::studies::setCommandLine(std::vector<std::string>(argv, argv + argc));
    try {
        app.parse(argc, argv);
    } catch (const CLI::CallForHelp& e) {
        return app.exit(e);
    } catch (const CLI::CallForAllHelp& e) {
        return app.exit(e);
    } catch (const CLI::CallForVersion& e) {
        return app.exit(e);
    } catch (const CLI::ParseError& e) {
        // The parser's words with the program's prefix, as every other error has it.
        std::cerr << "shadowlab: error: " << e.what() << "\nRun with --help for more information.\n";
        return 2;
    }

    try {
        // Every command's results on stdout (--json) must reach it: a failed write is an error.
        using shadowlab::app::finishStandardOutput;
        if (*runCmd) return finishStandardOutput(shadowlab::app::run(runOptions));
        if (*renderCmd) {
            // The debug views are views of the shadow maps: --view alone means the raster backend.
            // IsMember above has checked the name.
            renderOptions.backend = *shadowlab::scene::parseBackend(backendName);
            if (renderOptions.view && backendOption->count() == 0)
                renderOptions.backend = shadowlab::scene::Backend::Raster;
            return finishStandardOutput(shadowlab::app::render(renderOptions));
        }
        if (*compareCmd) return finishStandardOutput(shadowlab::app::compareFiles(compareOptions));
        if (*infoCmd) return finishStandardOutput(shadowlab::app::info(infoValidate));
        if (*sweepCmd) return finishStandardOutput(shadowlab::app::sweep(sweepOptions));
        if (*mergeCmd) return finishStandardOutput(shadowlab::app::merge(mergeOptions));
        if (*stabilityCmd) return finishStandardOutput(shadowlab::app::stability(stabilityOptions));
        if (*checkCmd) return finishStandardOutput(shadowlab::app::check(checkOptions));
        if (*pathCmd) return finishStandardOutput(shadowlab::app::path(pathOptions));
        if (*exportCmd) return finishStandardOutput(shadowlab::app::exportScene(exportOptions));
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
