// bench/view_search_bench.cpp: what the view search costs on models given as the scene, and
// what its second pass (the best pairs scored again at 3 × the thumbnail, ViewSearchOptions::
// refine) adds: the search with refine = 0 and with 8 (the default), interleaved in one process,
// process CPU time and wall time, medians with min–max.
// Usage: view_search_bench [--repeats N] [MODEL.gltf ...] (default: Sponza, SciFiHelmet,
// IntelSponzaCurtains and AlphaBlendModeTest from SHADOWLAB_SHARED_SCENES).
#include <algorithm>
#include <chrono>
#include <cstdio>
#include <ctime>
#include <exception>
#include <filesystem>
#include <string>
#include <vector>

#include "raytrace/view_search.h"
#include "scene/loader.h"
#include "scene/model_view.h"

namespace {

using namespace shadowlab;
namespace fs = std::filesystem;

double cpuSeconds() {
    timespec t{};
    clock_gettime(CLOCK_PROCESS_CPUTIME_ID, &t);
    return double(t.tv_sec) + double(t.tv_nsec) * 1e-9;
}

struct Series {
    std::vector<double> cpu, wall;
    static double median(std::vector<double> v) {
        std::sort(v.begin(), v.end());
        const std::size_t n = v.size();
        return n % 2 ? v[n / 2] : 0.5 * (v[n / 2 - 1] + v[n / 2]);
    }
    std::string text(const std::vector<double>& v) const {
        char buf[96];
        std::snprintf(buf, sizeof buf, "%.2f (%.2f-%.2f)", median(v), *std::min_element(v.begin(), v.end()),
                      *std::max_element(v.begin(), v.end()));
        return buf;
    }
};

}  // namespace

int main(int argc, char** argv) try {
    int repeats = 5;
    std::vector<fs::path> models;
    for (int i = 1; i < argc; ++i) {
        const std::string a = argv[i];
        if (a == "--repeats" && i + 1 < argc)
            repeats = std::max(1, std::stoi(argv[++i]));
        else
            models.emplace_back(a);
    }
    if (models.empty())
        for (const char* m : {"Sponza/Sponza.gltf", "SciFiHelmet/SciFiHelmet.gltf",
                              "IntelSponzaCurtains/sponza_curtains.gltf", "AlphaBlendModeTest/AlphaBlendModeTest.gltf"})
            models.push_back(fs::path(SHADOWLAB_SHARED_SCENES) / m);
    std::printf("view search, %d interleaved runs each; seconds, median (min-max)\n", repeats);
    std::printf("%-44s %-22s %-22s %-22s %-22s %s\n", "model", "cpu refine=0", "cpu refine=8", "wall refine=0",
                "wall refine=8", "cpu ratio");
    for (const fs::path& file : models) {
        scene::Scene s;
        try {
            s = scene::loadScene(file);
        } catch (const std::exception& e) {
            std::printf("%-44s skipped: %s\n", file.filename().string().c_str(), e.what());
            continue;
        }
        scene::applyGround(s, std::nullopt);
        Series plain, refined;
        for (int r = 0; r < repeats; ++r)
            for (const int refine : {0, 8}) {
                raytrace::ViewSearchOptions o;
                o.refine = refine;
                const double c0 = cpuSeconds();
                const auto w0 = std::chrono::steady_clock::now();
                const raytrace::ViewSearchResult result = raytrace::searchViewAndSun(s, o);
                Series& into = refine ? refined : plain;
                into.cpu.push_back(cpuSeconds() - c0);
                into.wall.push_back(std::chrono::duration<double>(std::chrono::steady_clock::now() - w0).count());
                if (result.best.score < 0) throw std::runtime_error("no candidate scored");
            }
        std::printf("%-44s %-22s %-22s %-22s %-22s %.2f\n", file.filename().string().c_str(),
                    plain.text(plain.cpu).c_str(), refined.text(refined.cpu).c_str(), plain.text(plain.wall).c_str(),
                    refined.text(refined.wall).c_str(), Series::median(refined.cpu) / Series::median(plain.cpu));
    }
    return 0;
} catch (const std::exception& e) {
    std::fprintf(stderr, "view_search_bench: %s\n", e.what());
    return 1;
}
