// bench/raster_bench.cpp: our raster frame (raster::Renderer) against a bare two-pass lavapipe
// renderer (bench/bare_renderer.h) on the seed scene and Sponza (or the generated terrain of
// bench/terrain_scene.h at a given size) at 1920x1080 with a 2048² map, in one process:
// per-stage medians of interleaved repetitions, cold (empty Mesa shader cache) and warm first
// frames, and, when LP_NUM_THREADS is not set, the whole run once with LP_NUM_THREADS=2 and once
// with 1 (child processes: lavapipe reads it at device creation).
#include <algorithm>
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <ctime>
#include <exception>
#include <filesystem>
#include <map>
#include <memory>
#include <optional>
#include <stdexcept>
#include <string>
#include <vector>

#include <sys/resource.h>

#include "bare_renderer.h"
#include "raster/renderer.h"
#include "scene/frame_io.h"
#include "scene/loader.h"
#include "scene/render_plan.h"
#include "scene/settings.h"
#include "terrain_scene.h"

namespace {

using namespace shadowlab;
namespace fs = std::filesystem;
using Clock = std::chrono::steady_clock;

// The image: 1920x1080 (full HD, where per-pixel costs dominate), or SHADOWLAB_BENCH_RESOLUTION=WxH.
std::pair<int, int> benchResolution() {
    int w = 1920, h = 1080;
    if (const char* v = std::getenv("SHADOWLAB_BENCH_RESOLUTION"); v && *v)
        if (std::sscanf(v, "%dx%d", &w, &h) != 2 || w <= 0 || h <= 0)
            throw std::runtime_error(std::string("SHADOWLAB_BENCH_RESOLUTION: expected WxH, got ") + v);
    return {w, h};
}
constexpr int kShadowMapSize = 2048;
constexpr const char* kSponzaPath = "/work/shared/scenes/Sponza/Sponza.gltf";

double msSince(Clock::time_point t) { return std::chrono::duration<double, std::milli>(Clock::now() - t).count(); }

// Process CPU time (all threads, lavapipe's included), ms: less disturbed than wall time when
// other work shares the cores.
double cpuMs() {
    timespec t{};
    clock_gettime(CLOCK_PROCESS_CPUTIME_ID, &t);
    return t.tv_sec * 1e3 + t.tv_nsec * 1e-6;
}

// The process's peak resident set so far, MiB (ru_maxrss is in KiB on Linux).
double peakRssMiB() {
    rusage u{};
    getrusage(RUSAGE_SELF, &u);
    return double(u.ru_maxrss) / 1024.0;
}

double median(std::vector<double> v) {
    if (v.empty()) return -1.0;
    std::sort(v.begin(), v.end());
    const std::size_t n = v.size();
    return n % 2 ? v[n / 2] : 0.5 * (v[n / 2 - 1] + v[n / 2]);
}

struct Series {
    std::map<std::string, std::vector<double>> ms;  // stage -> one value per repetition
    void add(const std::string& stage, double v) { ms[stage].push_back(v); }
    double med(const std::string& stage) const {
        const auto it = ms.find(stage);
        return it == ms.end() ? -1.0 : median(it->second);
    }
    std::pair<double, double> range(const std::string& stage) const {
        const auto it = ms.find(stage);
        if (it == ms.end() || it->second.empty()) return {-1, -1};
        const auto [lo, hi] = std::minmax_element(it->second.begin(), it->second.end());
        return {*lo, *hi};
    }
};

void addOurs(Series& s, const scene::Frame& f) {
    for (const char* stage : {"shadow_pass", "lit_pass", "readback"}) s.add(stage, f.timing(stage));
    s.add("per_frame", f.totalTimeMs() - f.timing("setup"));
    for (const char* stage : {"shadow_pass", "lit_pass"})
        if (const auto it = f.attributes.find(std::string("cpu_") + stage + "_ms"); it != f.attributes.end())
            s.add(std::string("cpu_") + stage, std::stod(it->second));
}

void addBare(Series& s, const bench::BareTimings& t) {
    s.add("shadow_pass", t.shadowPass);
    s.add("lit_pass", t.litPass);
    s.add("readback", t.readback);
    s.add("per_frame", t.perFrame());
    s.add("cpu_shadow_pass", t.cpuShadowPass);
    s.add("cpu_lit_pass", t.cpuLitPass);
}

// A fresh, empty Mesa shader cache, so that the next device's pipelines compile from scratch.
void freshShaderCache(std::vector<fs::path>& made) {
    char dirTemplate[] = "/tmp/shadowlab_raster_bench_cache_XXXXXX";
    if (const char* dir = mkdtemp(dirTemplate)) {
        setenv("MESA_SHADER_CACHE_DIR", dir, 1);
        made.emplace_back(dir);
    }
}

// SHADOWLAB_BENCH_SCENE=seed or Sponza: only that scene (while iterating on one);
// SHADOWLAB_BENCH_NO_FRESH=1: leave out the "into a new Frame" series (a quarter of the run).
bool wantScene(const char* label) {
    const char* only = std::getenv("SHADOWLAB_BENCH_SCENE");
    return !only || !*only || std::string(only) == label;
}

// SHADOWLAB_BENCH_LIGHT_CONSTANTS=uniform|vertex|specialization: force where our lit pass reads the light's
// constants (raster::RendererOptions::lightConstants; default: the renderer's own choice).
raster::RendererOptions rendererOptions() {
    raster::RendererOptions o;
    if (const char* v = std::getenv("SHADOWLAB_BENCH_LIGHT_CONSTANTS"); v && *v) {
        const std::string which = v;
        if (which == "uniform")
            o.lightConstants = raster::LightConstants::kUniformBuffer;
        else if (which == "vertex")
            o.lightConstants = raster::LightConstants::kVertexOutputs;
        else if (which == "specialization")
            o.lightConstants = raster::LightConstants::kSpecialization;
        else
            throw std::runtime_error(
                "SHADOWLAB_BENCH_LIGHT_CONSTANTS: expected uniform, vertex or specialization, got " + which);
    }
    // SHADOWLAB_BENCH_ONE_LIGHT_MODULES=0: the general lit shader modules where the size-optimized ones
    // would be used (raster::RendererOptions::oneLightModules), for comparing the pipelines' creation.
    if (const char* v = std::getenv("SHADOWLAB_BENCH_ONE_LIGHT_MODULES"); v && std::string(v) == "0")
        o.oneLightModules = false;
    // SHADOWLAB_BENCH_VIEW_CULL=0: the lit pass draws every triangle (raster::RendererOptions::viewCull).
    if (const char* v = std::getenv("SHADOWLAB_BENCH_VIEW_CULL"); v && std::string(v) == "0") o.viewCull = false;
    return o;
}

// `scaling`: the generated terrain, whose run grows with its size: only the series the scaling
// table reads (ours all channels, ours float beauty, bare), so no png, sRGB or new-Frame series and
// no second bare renderer holding another copy of the triangles.
void benchScene(const std::string& label, scene::Scene s, int repeats, std::vector<fs::path>& caches,
                bool scaling = false) {
    // SHADOWLAB_BENCH_CUTTING_ALPHA=1: every MASK material takes a 2x2 checker of alpha 1 and 0, so
    // that its alpha test can cut and ours draws it with the alpha-tested pipelines (Sponza's MASK
    // materials have no texture and take the plain ones; docs/performance.md, "Latest figures").
    if (const char* v = std::getenv("SHADOWLAB_BENCH_CUTTING_ALPHA"); v && std::string(v) == "1") {
        auto checker = std::make_shared<scene::AlphaTexture>();
        checker->file = "bench-checker";
        checker->width = checker->height = 2;
        checker->alpha = {1.0f, 0.0f, 0.0f, 1.0f};
        for (scene::Material& m : s.materials)
            if (m.alphaMode == scene::AlphaMode::Mask) m.alphaTexture = checker;
    }
    const char* noFresh = std::getenv("SHADOWLAB_BENCH_NO_FRESH");
    const bool skipFresh = scaling || (noFresh && std::string(noFresh) == "1");
    const auto [width, height] = benchResolution();
    s.camera.width = width;
    s.camera.height = height;
    scene::SettingsOverrides overrides;
    overrides.shadowMapSize = kShadowMapSize;
    // One map, as the bare two-pass baseline draws (the defaults would fit it and may cascade it).
    // SHADOWLAB_BENCH_CASCADES=N: N cascades instead (the command line's default for a large view
    // is 4), to compare two builds or light-constant sources of ours on that path; the bare
    // baseline still draws one map, so the ratio to it is not like for like.
    // SHADOWLAB_BENCH_MOVING (below) keeps the maps fitted to the view, as a user's run does, so
    // that a camera move changes them.
    const char* movingName = std::getenv("SHADOWLAB_BENCH_MOVING");
    const bool moving = movingName && *movingName;
    if (!moving) overrides.fitLightFrustum = false;
    overrides.cascades = 1;
    if (const char* v = std::getenv("SHADOWLAB_BENCH_CASCADES"); v && *v) overrides.cascades = std::atoi(v);
    // SHADOWLAB_BENCH_FILTER=name: ours with that shadow filter instead of the scene's (pcf, poisson,
    // pcss and the moment maps take the general lit modules); the bare baseline keeps its own PCF.
    if (const char* v = std::getenv("SHADOWLAB_BENCH_FILTER"); v && *v) overrides.filter = v;
    const scene::RenderSettings settings = scene::resolveSettings(s, overrides);
    const scene::RenderPlan plan = scene::makeRenderPlan(s, settings);

    // Cold first frames: construction + first frame with an empty shader cache. Ours and the
    // bare renderer compile different shaders, so both are cold in the same cache. Wall and
    // process CPU time. SHADOWLAB_BENCH_BARE_FIRST=1 measures the bare one first (to see that the
    // order does not favour either).
    // SHADOWLAB_BENCH_PROFILE=first: the same as cold, with the shader cache as it is (warm after a run).
    const char* profileName = std::getenv("SHADOWLAB_BENCH_PROFILE");
    const bool warmProfile = profileName && std::string(profileName) == "first";
    if (!warmProfile) {
        // The first shader a process compiles also pays LLVM's one-time set-up (25-30 ms of CPU
        // measured): a throwaway 16x9 bare frame in a cache of its own takes it, so that neither
        // cold frame below carries it. Then an empty cache for the two measured.
        freshShaderCache(caches);
        scene::Scene tiny = s;
        tiny.camera.width = 16;
        tiny.camera.height = 9;
        std::vector<std::uint8_t> pixels;
        bench::BareRenderer(tiny, settings.raster).render(pixels);
        freshShaderCache(caches);
    }
    const bool bareFirst =
        std::getenv("SHADOWLAB_BENCH_BARE_FIRST") && std::string(std::getenv("SHADOWLAB_BENCH_BARE_FIRST")) == "1";
    std::vector<std::uint8_t> rgba;
    double bareCold = 0, bareColdCpu = 0;
    auto coldBare = [&] {
        const auto t = Clock::now();
        const double c = cpuMs();
        bench::BareRenderer first(s, settings.raster);
        first.render(rgba);
        bareCold = msSince(t);
        bareColdCpu = cpuMs() - c;
    };
    if (bareFirst) coldBare();
    auto t0 = Clock::now();
    double c0 = cpuMs();
    raster::Renderer ours(s, plan, settings.raster, rendererOptions());
    scene::Frame frame = ours.render();
    const double oursCold = msSince(t0);
    const double oursColdCpu = cpuMs() - c0;
    if (profileName && (std::string(profileName) == "cold" || warmProfile)) {
        // Only our cold (or warm: first) first frame (construction + first frame): a process to run
        // under `perf record`.
        std::printf(
            "first frame %.1f ms, CPU %.1f ms (construction %.1f, setup with the pipelines %.1f; shadow pass "
            "%.1f, CPU %s; lit pass %.1f, CPU %s; readback %.1f)\n",
            oursCold, oursColdCpu, ours.setupMs(), frame.timing("setup"), frame.timing("shadow_pass"),
            frame.attributes["cpu_shadow_pass_ms"].c_str(), frame.timing("lit_pass"),
            frame.attributes["cpu_lit_pass_ms"].c_str(), frame.timing("readback"));
        return;
    }
    if (!bareFirst) coldBare();
    bench::BareRenderer bare(s, settings.raster);
    bare.render(rgba);
    // The same bare passes writing an sRGB target, as ours does for a PNG: what the device's
    // sRGB encoding on store costs (the headline ratios are against the UNORM one above).
    std::optional<bench::BareRenderer> bareSrgb;
    // The bare passes writing every channel of a Frame (bench::BareTarget::Aovs): the floor under
    // the all-channel frame, so that its ratio to the bare one splits into what the AOV contract
    // costs any renderer and what our design adds on top.
    std::optional<bench::BareRenderer> aovFloor;
    // The bare passes writing the float beauty alone (bench::BareTarget::FloatBeauty): the floor
    // under ours' float-beauty frame, which writes 12 bytes a pixel where the bare one writes 4.
    std::optional<bench::BareRenderer> beautyFloor;
    if (!scaling) {
        bareSrgb.emplace(s, settings.raster, bench::BareTarget::Srgb);
        bareSrgb->render(rgba);
        aovFloor.emplace(s, settings.raster, bench::BareTarget::Aovs);
        aovFloor->render(rgba);
        beautyFloor.emplace(s, settings.raster, bench::BareTarget::FloatBeauty);
        beautyFloor->render(rgba);
    }

    std::printf(
        "\n=== %s: %s triangles, %dx%d, shadow map %d, filter %s, light constants: %s, bare PCF: "
        "%s ===\n",
        label.c_str(), frame.attributes["triangles"].c_str(), width, height, kShadowMapSize,
        frame.attributes["filter"].c_str(), frame.attributes["light_constants"].c_str(), bare.pcfKind().c_str());
    if (const char* dir = std::getenv("SHADOWLAB_BENCH_PNG_DIR")) {
        scene::writePngLinear(fs::path(dir) / (label + "-ours.png"), frame.width, frame.height, frame.beauty);
        std::vector<float> rgb(std::size_t(width) * height * 3);
        for (std::size_t i = 0; i < rgb.size() / 3; ++i)
            for (int c = 0; c < 3; ++c) rgb[3 * i + c] = float(rgba[4 * i + c]) / 255.0f;
        scene::writePngDisplay(fs::path(dir) / (label + "-bare.png"), width, height, rgb);
    }

    // SHADOWLAB_BENCH_MOVING=all|beauty: only ours, `repeats` frames with the camera orbiting the
    // look-at point about the vertical by SHADOWLAB_BENCH_MOVING_STEP degrees a frame (default 0.25),
    // each an update() and a frame of those channels: what a camera path costs, where the values
    // baked into the lit pipelines change every frame (docs/performance.md, "A moving camera").
    if (moving) {
        const std::string which = movingName;
        if (which != "all" && which != "beauty")
            throw std::runtime_error("SHADOWLAB_BENCH_MOVING: expected all or beauty, got " + which);
        const char* stepName = std::getenv("SHADOWLAB_BENCH_MOVING_STEP");
        const double step = glm::radians(stepName && *stepName ? std::atof(stepName) : 0.25);
        const scene::Vec3 offset = s.camera.position - s.camera.lookAt;
        Series series;
        scene::Frame into;
        scene::Scene moved = s;
        for (int i = 1; i <= repeats; ++i) {
            const double c = std::cos(step * i), sn = std::sin(step * i);
            moved.camera.position =
                s.camera.lookAt + scene::Vec3(c * offset.x + sn * offset.z, offset.y, -sn * offset.x + c * offset.z);
            const double cpu = cpuMs();
            ours.update(moved);
            ours.render(into, which == "all" ? scene::kAllChannels : scene::kChannelBeauty);
            series.add("cpu_update_and_frame", cpuMs() - cpu);
            addOurs(series, into);
        }
        std::printf("\n=== %s moving (%s): %d frames, light constants after the first update: %s ===\n", label.c_str(),
                    which.c_str(), repeats, into.attributes["light_constants"].c_str());
        for (const char* stage : {"cpu_update_and_frame", "cpu_shadow_pass", "cpu_lit_pass"}) {
            const auto [lo, hi] = series.range(stage);
            std::printf("  %-22s %7.1f (%.1f-%.1f)\n", stage, series.med(stage), lo, hi);
        }
        return;
    }

    // SHADOWLAB_BENCH_PROFILE=all|no-ids|beauty|png|bare|bare-srgb|bare-aovs|bare-beauty: only that series, `repeats` frames,
    // nothing printed: a process to run under `perf record` (docs/performance.md).
    if (const char* profile = std::getenv("SHADOWLAB_BENCH_PROFILE"); profile && *profile) {
        const std::string which = profile;
        scene::Frame into;
        for (int i = 0; i < repeats; ++i) {
            if (which == "all")
                ours.render(into, scene::kAllChannels);
            else if (which == "no-ids")
                ours.render(into, scene::kAllChannels & ~scene::kChannelBlockerId);
            else if (which == "beauty")
                ours.render(into, scene::kChannelBeauty);
            else if (which == "png")
                ours.render(into, scene::kChannelBeauty | scene::kBeautyForDisplay);
            else if (which == "bare")
                bare.render(rgba);
            else if (which == "bare-srgb" && bareSrgb)
                bareSrgb->render(rgba);
            else if (which == "bare-aovs" && aovFloor)
                aovFloor->render(rgba);
            else if (which == "bare-beauty" && beautyFloor)
                beautyFloor->render(rgba);
            else
                throw std::runtime_error(
                    "SHADOWLAB_BENCH_PROFILE: expected all, no-ids, beauty, png, bare, bare-srgb, bare-aovs or "
                    "bare-beauty, got " +
                    which);
        }
        return;
    }

    // Warm frames, interleaved so that both see the same machine: ours with every channel
    // (what compare reads), ours with the float beauty only, ours for a PNG (`render -o x.png`:
    // the beauty into the 8-bit sRGB target), the bare renderer. Each keeps its frame between
    // repetitions, as the bare renderer keeps its image.
    Series all, beauty, png, fresh, base, baseSrgb, baseAovs, baseBeauty;
    scene::Frame allFrame, beautyFrame, pngFrame;
    for (int i = 0; i < repeats; ++i) {
        double c = cpuMs();
        ours.render(allFrame, scene::kAllChannels);
        all.add("cpu_per_frame", cpuMs() - c);
        addOurs(all, allFrame);
        c = cpuMs();
        ours.render(beautyFrame, scene::kChannelBeauty);
        beauty.add("cpu_per_frame", cpuMs() - c);
        addOurs(beauty, beautyFrame);
        if (!scaling) {
            c = cpuMs();
            ours.render(pngFrame, scene::kChannelBeauty | scene::kBeautyForDisplay);
            png.add("cpu_per_frame", cpuMs() - c);
            addOurs(png, pngFrame);
        }
        if (!skipFresh) addOurs(fresh, ours.render(scene::kAllChannels));  // a new Frame every time
        c = cpuMs();
        const bench::BareTimings t = bare.render(rgba);
        base.add("cpu_per_frame", cpuMs() - c);
        addBare(base, t);
        if (bareSrgb) {
            c = cpuMs();
            const bench::BareTimings ts = bareSrgb->render(rgba);
            baseSrgb.add("cpu_per_frame", cpuMs() - c);
            addBare(baseSrgb, ts);
        }
        if (aovFloor) {
            c = cpuMs();
            const bench::BareTimings ta = aovFloor->render(rgba);
            baseAovs.add("cpu_per_frame", cpuMs() - c);
            addBare(baseAovs, ta);
        }
        if (beautyFloor) {
            c = cpuMs();
            const bench::BareTimings tb = beautyFloor->render(rgba);
            baseBeauty.add("cpu_per_frame", cpuMs() - c);
            addBare(baseBeauty, tb);
        }
    }

    // Warm first frames: a new renderer (new device) whose shaders are now in the cache; the
    // construction's CPU time apart (the upload of the triangles: what grows with the scene).
    t0 = Clock::now();
    c0 = cpuMs();
    double oursConstructCpu = 0, bareConstructCpu = 0;
    {
        raster::Renderer again(s, plan, settings.raster, rendererOptions());
        oursConstructCpu = cpuMs() - c0;
        again.render();
    }
    const double oursWarmFirst = msSince(t0);
    const double oursWarmFirstCpu = cpuMs() - c0;
    t0 = Clock::now();
    c0 = cpuMs();
    {
        bench::BareRenderer again(s, settings.raster);
        bareConstructCpu = cpuMs() - c0;
        again.render(rgba);
    }
    const double bareWarmFirst = msSince(t0);
    const double bareWarmFirstCpu = cpuMs() - c0;

    std::printf("median of %d warm frames, ms (min-max)\n", repeats);
    std::printf("  %-12s %22s %22s %22s %22s %9s %9s %9s\n", "stage", "ours (all channels)", "ours (float beauty)",
                "ours (png)", "bare baseline", "all/bare", "bty/bare", "png/bare");
    for (const char* stage :
         {"shadow_pass", "lit_pass", "readback", "per_frame", "cpu_shadow_pass", "cpu_lit_pass", "cpu_per_frame"}) {
        auto cell = [&](const Series& x) {
            if (x.med(stage) < 0) return std::string("-");  // a series not run (the terrain's png)
            char buf[64];
            const auto [lo, hi] = x.range(stage);
            std::snprintf(buf, sizeof buf, "%.1f (%.1f-%.1f)", x.med(stage), lo, hi);
            return std::string(buf);
        };
        std::printf("  %-12s %22s %22s %22s %22s %9.2f %9.2f %9.2f\n", stage, cell(all).c_str(), cell(beauty).c_str(),
                    cell(png).c_str(), cell(base).c_str(), all.med(stage) / base.med(stage),
                    beauty.med(stage) / base.med(stage), scaling ? 0.0 : png.med(stage) / base.med(stage));
    }
    if (!scaling)
        std::printf(
            "  bare with an sRGB target: per_frame %.1f, lit_pass %.1f, cpu_per_frame %.1f; png / bare sRGB: "
            "per_frame %.2f, cpu %.2f\n",
            baseSrgb.med("per_frame"), baseSrgb.med("lit_pass"), baseSrgb.med("cpu_per_frame"),
            png.med("per_frame") / baseSrgb.med("per_frame"), png.med("cpu_per_frame") / baseSrgb.med("cpu_per_frame"));
    if (!scaling) {
        auto range = [](const Series& x, const char* stage) {
            const auto [lo, hi] = x.range(stage);
            char buf[64];
            std::snprintf(buf, sizeof buf, "%.1f (%.1f-%.1f)", x.med(stage), lo, hi);
            return std::string(buf);
        };
        std::printf(
            "  bare writing every AOV (the floor): cpu_shadow_pass %s, cpu_lit_pass %s, cpu_per_frame %s; floor / "
            "bare: cpu %.2f, wall %.2f; all / floor: cpu %.2f, wall %.2f\n",
            range(baseAovs, "cpu_shadow_pass").c_str(), range(baseAovs, "cpu_lit_pass").c_str(),
            range(baseAovs, "cpu_per_frame").c_str(), baseAovs.med("cpu_per_frame") / base.med("cpu_per_frame"),
            baseAovs.med("per_frame") / base.med("per_frame"), all.med("cpu_per_frame") / baseAovs.med("cpu_per_frame"),
            all.med("per_frame") / baseAovs.med("per_frame"));
        std::printf(
            "  bare writing the float beauty (its floor): cpu_shadow_pass %s, cpu_lit_pass %s, cpu_per_frame %s; "
            "floor / bare: cpu %.2f, wall %.2f; float beauty / floor: cpu %.2f, wall %.2f\n",
            range(baseBeauty, "cpu_shadow_pass").c_str(), range(baseBeauty, "cpu_lit_pass").c_str(),
            range(baseBeauty, "cpu_per_frame").c_str(), baseBeauty.med("cpu_per_frame") / base.med("cpu_per_frame"),
            baseBeauty.med("per_frame") / base.med("per_frame"),
            beauty.med("cpu_per_frame") / baseBeauty.med("cpu_per_frame"),
            beauty.med("per_frame") / baseBeauty.med("per_frame"));
    }
    if (!skipFresh)
        std::printf("  ours (all channels) into a new Frame each time: per_frame %.1f, readback %.1f\n",
                    fresh.med("per_frame"), fresh.med("readback"));
    std::printf("  setup (construction): ours %.1f, bare %.1f\n", ours.setupMs(), bare.setupMs());
    std::printf("  first frame incl. setup: cold ours %.1f, bare %.1f; warm ours %.1f, bare %.1f (%s first)\n",
                oursCold, bareCold, oursWarmFirst, bareWarmFirst, bareFirst ? "bare" : "ours");
    std::printf("  first frame, process CPU: cold ours %.1f, bare %.1f (%.2f); warm ours %.1f, bare %.1f (%.2f)\n",
                oursColdCpu, bareColdCpu, oursColdCpu / bareColdCpu, oursWarmFirstCpu, bareWarmFirstCpu,
                oursWarmFirstCpu / bareWarmFirstCpu);
    std::printf("  warm construction alone (the triangles' upload), process CPU: ours %.1f, bare %.1f (%.2f)\n",
                oursConstructCpu, bareConstructCpu, oursConstructCpu / bareConstructCpu);
    std::printf("  gpu timestamps: first frame shadow %s, lit %s; last warm frame (all channels) shadow %s, lit %s\n",
                frame.attributes["gpu_shadow_pass_ms"].c_str(), frame.attributes["gpu_lit_pass_ms"].c_str(),
                allFrame.attributes["gpu_shadow_pass_ms"].c_str(), allFrame.attributes["gpu_lit_pass_ms"].c_str());
    const char* threads = std::getenv("LP_NUM_THREADS");
    // One line per scene for tools/scaling_plot.py: per-frame process CPU medians, the warm first
    // frame's process CPU (construction + first frame, shaders cached), and the peak RSS so far.
    std::printf(
        "RSCALE | %s | %s | frame_cpu ours_all %.1f ours_beauty %.1f bare %.1f | frame_wall ours_all %.1f ours_beauty "
        "%.1f bare %.1f | setup_cpu ours %.1f bare %.1f | construct_cpu ours %.1f bare %.1f | rss_mib %.0f | "
        "lp_threads %s\n",
        label.c_str(), frame.attributes["triangles"].c_str(), all.med("cpu_per_frame"), beauty.med("cpu_per_frame"),
        base.med("cpu_per_frame"), all.med("per_frame"), beauty.med("per_frame"), base.med("per_frame"),
        oursWarmFirstCpu, bareWarmFirstCpu, oursConstructCpu, bareConstructCpu, peakRssMiB(), threads ? threads : "?");
    if (scaling) return;
    std::printf(
        "ROW | %s | %s | %.1f | %.1f | %.1f | %.1f | %.2f | %.2f | %.2f | %.2f | %.2f | %.1f | %.1f | %.1f / %.1f | "
        "%.1f / %.1f |\n",
        label.c_str(), threads ? threads : "?", all.med("per_frame"), beauty.med("per_frame"), png.med("per_frame"),
        base.med("per_frame"), all.med("per_frame") / base.med("per_frame"),
        beauty.med("per_frame") / base.med("per_frame"), png.med("per_frame") / base.med("per_frame"),
        all.med("cpu_per_frame") / base.med("cpu_per_frame"), png.med("cpu_per_frame") / base.med("cpu_per_frame"),
        all.med("lit_pass"), base.med("lit_pass"), oursCold, bareCold, oursWarmFirst, bareWarmFirst);
}

// SHADOWLAB_BENCH_FILTERS=1: instead of the series above, each shadow filter's frame (all
// channels, as compare renders) against pcf2x2 and the bare baseline, repetition by repetition in
// one process (each repetition starts at the next series, so none always runs first): what a
// filterable map's moment and blur passes cost. Wall and process CPU time per frame, medians and
// min-max; the ratios are of the medians.
void benchFilters(const std::string& label, const fs::path& file, int repeats) {
    scene::Scene s = scene::loadScene(file);
    const auto [width, height] = benchResolution();
    s.camera.width = width;
    s.camera.height = height;
    const std::vector<std::string> filters{"pcf2x2", "vsm", "evsm2", "evsm4", "esm", "msm"};
    std::vector<std::unique_ptr<raster::Renderer>> renderers;
    std::vector<scene::Frame> frames(filters.size());
    std::vector<Series> series(filters.size() + 1);  // the last: the bare baseline
    scene::RenderSettings settings;
    for (const std::string& filter : filters) {
        scene::SettingsOverrides overrides;
        overrides.shadowMapSize = kShadowMapSize;
        // One map, as the bare two-pass baseline draws (the defaults would fit it and may cascade it).
        overrides.fitLightFrustum = false;
        overrides.cascades = 1;
        overrides.filter = filter;
        settings = scene::resolveSettings(s, overrides);
        renderers.push_back(std::make_unique<raster::Renderer>(s, scene::makeRenderPlan(s, settings), settings.raster,
                                                               rendererOptions()));
    }
    bench::BareRenderer bare(s, settings.raster);
    std::vector<std::uint8_t> rgba;
    // Warm-up: pipelines are made on the first frame.
    for (std::size_t k = 0; k < filters.size(); ++k) renderers[k]->render(frames[k], scene::kAllChannels);
    bare.render(rgba);
    const std::size_t n = series.size();
    for (int r = 0; r < repeats; ++r) {
        for (std::size_t step = 0; step < n; ++step) {
            const std::size_t k = (std::size_t(r) + step) % n;
            const double c = cpuMs();
            if (k < filters.size()) {
                renderers[k]->render(frames[k], scene::kAllChannels);
                series[k].add("cpu_per_frame", cpuMs() - c);
                addOurs(series[k], frames[k]);
            } else {
                const bench::BareTimings t = bare.render(rgba);
                series[k].add("cpu_per_frame", cpuMs() - c);
                addBare(series[k], t);
            }
        }
    }
    const Series& pcf = series[0];
    const Series& base = series[n - 1];
    std::printf(
        "\n=== filters, %s: %s triangles, %dx%d, shadow map %d, LP_NUM_THREADS=%s, %d repetitions: median "
        "(min-max), ms ===\n",
        label.c_str(), frames[0].attributes["triangles"].c_str(), width, height, kShadowMapSize,
        std::getenv("LP_NUM_THREADS") ? std::getenv("LP_NUM_THREADS") : "?", repeats);
    std::printf("%-7s %-21s %-21s %-21s %-21s %-8s %-8s %-8s %-8s\n", "filter", "per_frame (wall)", "cpu_per_frame",
                "shadow_pass(+moments)", "lit_pass", "wall/pcf", "cpu/pcf", "wall/bare", "cpu/bare");
    auto cell = [](const Series& x, const char* stage) {
        char buf[64];
        const auto [lo, hi] = x.range(stage);
        std::snprintf(buf, sizeof buf, "%.0f (%.0f-%.0f)", x.med(stage), lo, hi);
        return std::string(buf);
    };
    auto row = [&](const std::string& name, const Series& x) {
        std::printf("%-7s %-21s %-21s %-21s %-21s %-8.2f %-8.2f %-8.2f %-8.2f\n", name.c_str(),
                    cell(x, "per_frame").c_str(), cell(x, "cpu_per_frame").c_str(), cell(x, "shadow_pass").c_str(),
                    cell(x, "lit_pass").c_str(), x.med("per_frame") / pcf.med("per_frame"),
                    x.med("cpu_per_frame") / pcf.med("cpu_per_frame"), x.med("per_frame") / base.med("per_frame"),
                    x.med("cpu_per_frame") / base.med("cpu_per_frame"));
    };
    for (std::size_t k = 0; k < filters.size(); ++k) row(filters[k], series[k]);
    row("bare", base);
    // One line per filter for docs/performance.md's table.
    for (std::size_t k = 0; k < filters.size(); ++k) {
        const Series& x = series[k];
        std::printf("FILTER | %s | %s | %s | %s | %s | %.2f / %.2f | %.2f / %.2f |\n", label.c_str(),
                    filters[k].c_str(), cell(x, "per_frame").c_str(), cell(x, "cpu_per_frame").c_str(),
                    cell(x, "shadow_pass").c_str(), x.med("per_frame") / pcf.med("per_frame"),
                    x.med("cpu_per_frame") / pcf.med("cpu_per_frame"), x.med("per_frame") / base.med("per_frame"),
                    x.med("cpu_per_frame") / base.med("cpu_per_frame"));
    }
    std::printf("FILTER | %s | bare | %s | %s | %s | | |\n", label.c_str(), cell(base, "per_frame").c_str(),
                cell(base, "cpu_per_frame").c_str(), cell(base, "shadow_pass").c_str());
}

// SHADOWLAB_BENCH_TRANSMIT=1: the shadow pass with a transmittance map against the same scene
// opaque: a glass sphere (opacity 0.5, radius 1) beside an opaque box on a 20x20 plane under a
// spot and a point light, so 1 + 6 shadow maps of 2048² (the spot's and the point light's cube),
// 640x360, all channels, pcf2x2, unfitted maps; `opaque` makes the sphere opaque (no
// transmittance pass). The two renderers interleaved repetition by repetition in one process.
scene::Scene glassScene(bool opaque) {
    scene::Scene s;
    s.camera.position = {0, 3, 7.5};
    s.camera.lookAt = {0, 0.6, 0};
    s.camera.width = 640;
    s.camera.height = 360;
    s.materials = {{.name = "glass", .albedo = {0.55, 0.75, 0.9}, .opacity = opaque ? 1.0 : 0.5},
                   {.name = "box", .albedo = {0.3, 0.5, 0.8}},
                   {.name = "ground", .albedo = {0.75, 0.75, 0.75}}};
    s.lights = {{.type = scene::LightType::Spot,
                 .direction = glm::normalize(scene::Vec3(3.2, -5.5, -2.6)),
                 .position = {-3, 5.5, 2},
                 .color = {1, 0.95, 0.85},
                 .intensity = 700,
                 .coneAngleDegrees = 32},
                {.type = scene::LightType::Point, .position = {2.5, 4, 1.5}, .color = {0.9, 0.9, 1}, .intensity = 300}};
    s.objects = {{.name = "glass sphere", .shape = scene::Sphere{{0, 1, 0}, 1.0}, .material = 0},
                 {.name = "box", .shape = scene::Box{{-2.4, 0, 0.2}, {-1.6, 1.2, 1.0}}, .material = 1},
                 {.name = "ground",
                  .shape = scene::Quad{.center = {0, 0, 0}, .normal = {0, 1, 0}, .size = {20, 20}},
                  .material = 2}};
    return s;
}

void benchTransmittance(int repeats) {
    struct Case {
        const char* label;
        scene::Scene scene;
        scene::RenderSettings settings;
        std::unique_ptr<raster::Renderer> renderer;
        scene::Frame frame;
        Series series;
        double firstMs = 0.0, firstShadowMs = 0.0;
    };
    Case cases[2] = {{"glass", glassScene(false)}, {"opaque", glassScene(true)}};
    for (Case& c : cases) {
        scene::SettingsOverrides overrides;
        overrides.shadowMapSize = kShadowMapSize;
        overrides.fitLightFrustum = false;
        c.settings = scene::resolveSettings(c.scene, overrides);
        const auto t0 = Clock::now();
        c.renderer = std::make_unique<raster::Renderer>(c.scene, scene::makeRenderPlan(c.scene, c.settings),
                                                        c.settings.raster, rendererOptions());
        c.renderer->render(c.frame, scene::kAllChannels);
        c.firstMs = msSince(t0);
        c.firstShadowMs = c.frame.timing("shadow_pass");
    }
    for (int i = 0; i < repeats; ++i)
        for (Case& c : cases) {
            const double cpu = cpuMs();
            c.renderer->render(c.frame, scene::kAllChannels);
            c.series.add("cpu_per_frame", cpuMs() - cpu);
            addOurs(c.series, c.frame);
            c.series.add("gpu_shadow_pass", std::stod(c.frame.attributes.at("gpu_shadow_pass_ms")));
            if (const auto it = c.frame.attributes.find("cpu_shadow_pass_ms"); it != c.frame.attributes.end())
                c.series.add("cpu_shadow_pass", std::stod(it->second));
        }
    std::printf("\n=== transmittance: %s shadow maps of %d, 640x360, median of %d frames, ms (min-max) ===\n",
                cases[0].frame.attributes.at("shadow_maps").c_str(), kShadowMapSize, repeats);
    std::printf("  %-16s %22s %22s %9s\n", "stage", "glass", "opaque", "ratio");
    for (const char* stage :
         {"shadow_pass", "gpu_shadow_pass", "cpu_shadow_pass", "lit_pass", "per_frame", "cpu_per_frame"}) {
        auto cell = [&](const Series& x) {
            char buf[64];
            const auto [lo, hi] = x.range(stage);
            std::snprintf(buf, sizeof buf, "%.1f (%.1f-%.1f)", x.med(stage), lo, hi);
            return std::string(buf);
        };
        std::printf("  %-16s %22s %22s %9.2f\n", stage, cell(cases[0].series).c_str(), cell(cases[1].series).c_str(),
                    cases[0].series.med(stage) / cases[1].series.med(stage));
    }
    std::printf(
        "  first frame incl. setup (this process's shader cache): glass %.1f (shadow pass %.1f), opaque %.1f "
        "(shadow pass %.1f)\n",
        cases[0].firstMs, cases[0].firstShadowMs, cases[1].firstMs, cases[1].firstShadowMs);
    std::printf("TRANSMIT | %s | %.1f | %.1f | %.2f | %.1f | %.1f | %.2f | %.2f |\n", std::getenv("LP_NUM_THREADS"),
                cases[0].series.med("shadow_pass"), cases[1].series.med("shadow_pass"),
                cases[0].series.med("shadow_pass") / cases[1].series.med("shadow_pass"),
                cases[0].series.med("cpu_shadow_pass"), cases[1].series.med("cpu_shadow_pass"),
                cases[0].series.med("cpu_shadow_pass") / cases[1].series.med("cpu_shadow_pass"),
                cases[0].series.med("cpu_per_frame") / cases[1].series.med("cpu_per_frame"));
}

}  // namespace

int main(int argc, char** argv) {
    int repeats = 5;
    if (argc > 1) repeats = std::max(1, std::atoi(argv[1]));
    if (!std::getenv("LP_NUM_THREADS")) {
        // Both thread counts, each in its own process.
        int rc = 0;
        for (const char* threads : {"2", "1"}) {
            const std::string command =
                std::string("LP_NUM_THREADS=") + threads + " '" + argv[0] + "' " + std::to_string(repeats);
            std::printf("\n##### %s\n", command.c_str());
            std::fflush(stdout);
            rc |= std::system(command.c_str());
        }
        return rc == 0 ? 0 : 1;
    }
    std::printf("raster_bench: LP_NUM_THREADS=%s repeats=%d\n", std::getenv("LP_NUM_THREADS"), repeats);
    if (const char* t = std::getenv("SHADOWLAB_BENCH_TRANSMIT"); t && std::string(t) == "1") {
        try {
            benchTransmittance(repeats);
        } catch (const std::exception& e) {
            std::fprintf(stderr, "transmittance failed: %s\n", e.what());
            return 1;
        }
        return 0;
    }
    if (const char* f = std::getenv("SHADOWLAB_BENCH_FILTERS"); f && std::string(f) == "1") {
        try {
            if (wantScene("seed")) benchFilters("seed", scene::findScene("seed"), repeats);
            if (wantScene("Sponza") && fs::exists(kSponzaPath)) benchFilters("Sponza", kSponzaPath, repeats);
        } catch (const std::exception& e) {
            std::fprintf(stderr, "filters failed: %s\n", e.what());
            return 1;
        }
        return 0;
    }
    // The Vulkan loader and lavapipe (with LLVM) are loaded and relocated once per process, by the
    // first instance: here, so that neither renderer's cold first frame pays it (the first one
    // measured would otherwise carry 80-150 ms that the other does not).
    const auto loadStart = Clock::now();
    raster::enumerateDevices(false);
    std::printf("driver loaded in %.1f ms (before any timing)\n", msSince(loadStart));
    std::vector<fs::path> caches;
    int rc = 0;
    // SHADOWLAB_BENCH_TERRAIN_TRIS=N: only the generated terrain of about N triangles (bench/terrain_scene.h,
    // raytrace_bench's camera and sun), for the scaling table.
    if (const char* t = std::getenv("SHADOWLAB_BENCH_TERRAIN_TRIS"); t && *t) {
        const long long tris = std::atoll(t);
        if (tris <= 0) {
            std::fprintf(stderr, "SHADOWLAB_BENCH_TERRAIN_TRIS: expected a positive count, got %s\n", t);
            return 2;
        }
        try {
            benchScene("terrain", bench::terrainScene(bench::terrainCellsFor(tris)), repeats, caches, true);
        } catch (const std::exception& e) {
            std::fprintf(stderr, "terrain failed: %s\n", e.what());
            rc = 1;
        }
        for (const fs::path& dir : caches) fs::remove_all(dir);
        return rc;
    }
    // SHADOWLAB_BENCH_SCENE_FILE=path: that scene (its own camera) instead of seed and Sponza.
    if (const char* file = std::getenv("SHADOWLAB_BENCH_SCENE_FILE"); file && *file) {
        try {
            benchScene(fs::path(file).stem().string(), scene::loadScene(file), repeats, caches);
        } catch (const std::exception& e) {
            std::fprintf(stderr, "%s failed: %s\n", file, e.what());
            rc = 1;
        }
        for (const fs::path& dir : caches) fs::remove_all(dir);
        return rc;
    }
    if (wantScene("seed")) try {
            benchScene("seed", scene::loadScene(scene::findScene("seed")), repeats, caches);
        } catch (const std::exception& e) {
            std::fprintf(stderr, "seed scene failed: %s\n", e.what());
            rc = 1;
        }
    if (!wantScene("Sponza")) {
    } else if (!fs::exists(kSponzaPath)) {
        std::printf("\n=== Sponza: SKIPPED, file absent: %s ===\n", kSponzaPath);
    } else {
        try {
            benchScene("Sponza", scene::loadScene(kSponzaPath), repeats, caches);
        } catch (const std::exception& e) {
            std::fprintf(stderr, "Sponza failed: %s\n", e.what());
            rc = 1;
        }
    }
    for (const fs::path& dir : caches) fs::remove_all(dir);
    return rc;
}
