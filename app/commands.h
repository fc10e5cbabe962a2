// app/commands.h: the subcommands of `shadowlab`, each taking its parsed options. They call the
// libraries and throw on failure; main.cpp maps exceptions to messages and exit codes.
#pragma once

#include <filesystem>
#include <optional>
#include <string>
#include <vector>

#include "scene/budgets.h"
#include "scene/settings.h"

namespace shadowlab::app {

// Exit codes besides 0 (success), 1 (a render or device failure) and 2 (bad input): a method's
// shadows broke at least one error budget (docs/ci.md).
inline constexpr int kExitBudgetBroken = 3;

// --max-mismatch and the other budgets as given, by scene::BudgetKind; parsed by the command.
struct BudgetOptions {
    std::optional<std::string> text[scene::kBudgetKindCount];
};

// Options every rendering command shares.
struct SceneOptions {
    std::string scene;                      // path or shipped name
    std::optional<std::string> resolution;  // "WxH" overrides the scene's camera
    scene::SettingsOverrides settings;
    std::optional<std::string> camera;  // --camera N|NAME|auto: a file camera, or search a view
    std::optional<bool> ground;         // --ground / --no-ground
    std::optional<std::string> sun;     // --sun AZIMUTH,ELEVATION (degrees)
    bool explain = false;               // print the RenderPlan before rendering
    bool json = false;                  // machine-readable results on stdout
};

struct RenderOptions {
    SceneOptions common;
    scene::Backend backend = scene::Backend::Raytrace;
    std::filesystem::path output;
    std::optional<std::string> view;  // raster debug view: shadow-map | cascades | texel-density | light-frustum
};

struct RunOptions {
    SceneOptions common;
    std::filesystem::path outputDir;
    bool skipRaster = false;
    bool skipSweep = false;
    BudgetOptions budgets;  // over the scene's "budgets" block, for every method
};

struct SweepOptions {
    SceneOptions common;
    std::filesystem::path outputDir;
    std::optional<std::filesystem::path> grid;  // JSON grid file; default grid otherwise
    bool resume = false;
    bool quick = false;
    std::optional<int> repetitions;
    std::optional<std::string> shard;  // "K/N": render only shard K of N (studies/shard.h)
    // The flicker axis: every row also along this path kind (--flicker [KIND], default subtexel).
    std::optional<std::string> flicker;
    std::optional<int> flickerFrames;
};

struct MergeOptions {
    std::vector<std::filesystem::path> inputs;       // shard folders, or folders holding shard-K-of-N folders
    std::optional<std::filesystem::path> outputDir;  // default: the one input folder
    bool json = false;
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
    std::optional<std::filesystem::path> heat;  // the |ΔV| heat map (.png)
    bool json = false;
    BudgetOptions budgets;
    bool allowDifferentScene = false;
    // The method is another engine's shadow mask (docs/external-masks.md): with any of these, or
    // when it is a .png.
    std::optional<std::string> maskChannel;
    bool maskInvert = false;
    bool maskSrgb = false;
};

struct CheckOptions {
    std::filesystem::path suite;
    std::filesystem::path outputDir;
    std::optional<std::filesystem::path> baseline;  // instead of the suite's "baseline"
    bool updateBaseline = false;
    std::optional<std::string> shard;  // "K/N": run only shard K of N into OUTPUT/shard-K-of-N
};

struct PathCommandOptions {
    SceneOptions common;
    std::filesystem::path outputDir;
    // Unset kind, frames, amount, light: the scene's "path" block, else orbit, 12, the kind's default, 0.
    std::optional<std::string> kind;  // studies::PathKind
    std::optional<int> frames;
    std::optional<double> amount;
    std::optional<int> light;
    std::optional<std::string> cameraAnimation;  // --camera-animation [NAME|INDEX]: kind gltf-animation
    std::optional<std::string> shard;            // "K/N": render only shard K of N (merge measures)
    bool resume = false;
    bool skipRaster = false;
    bool skipRaytrace = false;
    bool noHeldView = false;
};

struct ExportOptions {
    // The scene and the view options run and render take (resolution, camera, ground, sun), so
    // that the file holds the scene they render; render settings do not apply.
    SceneOptions common;
    std::filesystem::path output;  // .glb or .gltf
    double tolerance = 1e-3;       // a sphere's largest sagitta / radius
};

int render(const RenderOptions& options);
int exportScene(const ExportOptions& options);
int check(const CheckOptions& options);
int path(const PathCommandOptions& options);
int run(const RunOptions& options);
int compareFiles(const CompareOptions& options);
int info(bool validate);
int sweep(const SweepOptions& options);
int merge(const MergeOptions& options);
int stability(const StabilityCommandOptions& options);

}  // namespace shadowlab::app
