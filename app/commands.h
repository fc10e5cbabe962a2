// app/commands.h: the subcommands of `shadowlab`, each taking its parsed options. They call the
// libraries and throw on failure; main.cpp maps exceptions to messages and exit codes.
#pragma once

#include <filesystem>
#include <optional>
#include <string>
#include <vector>

#include "scene/settings.h"

namespace shadowlab::app {

// Options every rendering command shares.
struct SceneOptions {
    std::string scene;                    // path or shipped name
    std::optional<std::string> resolution;  // "WxH" overrides the scene's camera
    scene::SettingsOverrides settings;
    bool explain = false;                 // print the RenderPlan before rendering
    bool json = false;                    // machine-readable results on stdout
};

struct RenderOptions {
    SceneOptions common;
    std::string backend = "raytrace";
    std::filesystem::path output;
    std::optional<std::string> view;  // raster debug view: shadow-map | cascades | texel-density | light-frustum
};

struct RunOptions {
    SceneOptions common;
    std::filesystem::path outputDir;
    bool skipRaster = false;
    bool skipSweep = false;
};

struct SweepOptions {
    SceneOptions common;
    std::filesystem::path outputDir;
    std::optional<std::filesystem::path> grid;  // JSON grid file; default grid otherwise
    bool resume = false;
    bool quick = false;
    std::optional<int> repetitions;
};

struct StabilityCommandOptions {
    std::vector<std::string> scenes;  // paths or shipped names; empty: every scenes/extreme case
    std::filesystem::path outputDir;
    std::string resolution = "160x90";
    std::optional<int> shadowMapSize;
    bool noSearch = false;  // skip the bias search and best-settings renders
    bool fullGrid = false;  // the full default grid for the bias search (slower)
    bool validate = false;
    bool json = false;
};

struct CompareOptions {
    std::filesystem::path method;
    std::filesystem::path reference;
    std::filesystem::path output;
    bool json = false;
};

struct PathCommandOptions {
    SceneOptions common;
    std::filesystem::path outputDir;
    std::string kind = "orbit";  // compare::PathKind
    int frames = 12;
    std::optional<double> amount;
    int light = 0;
    bool resume = false;
    bool skipRaster = false;
    bool skipRaytrace = false;
    bool noHeldView = false;
};

int render(const RenderOptions& options);
int path(const PathCommandOptions& options);
int run(const RunOptions& options);
int compareFiles(const CompareOptions& options);
int info(bool validate);
int sweep(const SweepOptions& options);
int stability(const StabilityCommandOptions& options);

}  // namespace shadowlab::app
