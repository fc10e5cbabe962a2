// studies/sweep.h: renders a grid of settings for both backends, times each (setup separated
// from per-frame time, median of several runs after a warm-up), measures each against a cached
// reference and appends one row per configuration as it finishes. A stopped sweep resumes
// where it left off: finished rows are never lost or duplicated (see docs/sweep.md).
#pragma once

#include <filesystem>
#include <functional>
#include <limits>
#include <optional>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "scene/backend.h"
#include "scene/frame.h"
#include "scene/scene.h"
#include "scene/settings.h"
#include "studies/backend.h"
#include "studies/path.h"

namespace shadowlab::studies {

// One point of the grid: a backend and the settings that differ from the scene's defaults.
struct SweepConfig {
    scene::Backend backend = scene::Backend::Raster;  // Raster or Raytrace
    scene::SettingsOverrides overrides;
    // The bias parameter this configuration samples, for bias-window plots: "depth" (world
    // units), "slope" (texels), "ray" (world units); empty when it samples none.
    std::string biasKind;
    double biasValue = std::numeric_limits<double>::quiet_NaN();

    // Canonical text of backend + overrides, identical across runs: the resume key.
    std::string key() const;
    // Short text for tables and plot tooltips, e.g. "map 1024, none, depth 0.01, slope 0".
    std::string label() const;
    // label() without the backend: the settings it overrides, numbers to 4 significant digits
    // (the key keeps every digit); empty for the defaults.
    std::string settingsText() const;
};

// The filterable maps' parameters as sweep axes and grid-file keys (docs/sweep.md):
// "min_variance", "bleeding_reduction", "evsm_positive", "evsm_negative", "esm_exponent",
// "moment_bias", "blur_width".
bool isMomentAxis(const std::string& name);
// The override a real-valued moment axis sets (every one but "blur_width"); throws
// std::logic_error for another name.
std::optional<double>& momentOverride(scene::SettingsOverrides& o, const std::string& name);
std::optional<double> momentOverride(const scene::SettingsOverrides& o, const std::string& name);
// True for "vsm", "evsm2", "evsm4", "esm", "msm": filters that read no depth or slope bias.
bool isFilterableName(const std::string& filter);

// The most configurations a grid file may multiply to, checked before they are built: far
// beyond a sweep anyone would wait for (a configuration is at least one render), and small
// enough that the grid and its rows fit in memory.
inline constexpr std::size_t kMaxGridConfigurations = 100000;

struct SweepGrid {
    std::vector<SweepConfig> configs;
    int repetitions = 3;                    // timed frames per configuration (after one warm-up)
    std::optional<std::string> resolution;  // "WxH" for every render of the sweep
    // The flicker axis (docs/sweep.md): every row is also rendered along this path (one path for
    // the whole sweep, made with the scene's own settings) and measured with compare/temporal.h;
    // unset, a sweep renders and writes exactly what it does without it.
    std::optional<PathSpec> flicker;
};

// The flicker axis's path when a grid or the command line names none: four frames of sub-texel
// camera steps of a tenth of min(texel, pixel), where a snapped map must hold still.
PathSpec defaultFlickerPath();
// The path's frames as the sweep renders them: pathScenes of `scene` (at the sweep's resolution)
// with the scene's own settings, so every row moves along the same path. Throws scene::InputError.
std::vector<scene::Scene> flickerScenes(const scene::Scene& scene, const PathSpec& path);
// Canonical text of the path, in the sweep's identity (sweep.json, a shard's grid hash).
std::string flickerKey(const PathSpec& path);

// The grid `sweep` runs without --grid: shadow-map size × filter at default bias, a constant
// and a slope depth-bias series, and a ray-bias series in float plus robust offsets in float and
// double. `quick` is the smaller grid `run` includes in its report.
SweepGrid defaultGrid(const scene::Scene& scene, bool quick);
// A grid file (JSON, see docs/sweep.md). Throws scene::SceneError naming the file and the JSON
// path of a bad value.
SweepGrid loadGrid(const std::filesystem::path& file, const scene::Scene& scene);

struct SweepRow {
    SweepConfig config;
    std::string key;
    int repetitions = 0;
    double setupMs = 0.0;  // median over the runs
    double frameMs = 0.0;  // median per-frame time (total − setup)
    double frameMsMin = 0.0, frameMsMax = 0.0;
    nlohmann::json metrics;        // compare::toJson of the last run, or null on error
    nlohmann::json settings;       // the settings applied (Frame attributes)
    std::string error;             // non-empty when the configuration failed
    std::string image, diffImage;  // file names under DIR/images/
    nlohmann::json machine;        // toJson(MachineInfo) it was timed on; null in old journals
    // With a flicker axis: the row along the path (flicker_rate, flicker_px, error_variation,
    // swim_px, edge_offset_px, pairs; "held": the same for the raster held view on camera paths).
    // Null without one.
    nlohmann::json temporal;

    double rate(const char* name) const;  // a metrics rate, NaN when absent
    // Missed shadow but at smooth meshes' terminators (compare.h terminatorMissed; NaN without a
    // missed-shadow rate):
    // the faceted shadow a renderer's offset or bias hides on purpose at every setting, which
    // neither the bias windows nor the sweep's summary count as a leak.
    double missedBesideTerminatorRate() const;
    // A temporal figure (`held`: of the raster held view), NaN when absent.
    double temporalValue(const char* name, bool held = false) const;
};

// Renders one configuration (or the reference); tests pass fakes. The default renders through
// the backend seam (studies/backend.h) and records the scene's identity in the Frame.
using RenderFn = std::function<scene::Frame(const scene::Scene&, const scene::RenderSettings&, scene::Backend backend)>;
scene::Frame renderWithBackend(const scene::Scene& scene, const scene::RenderSettings& settings,
                               scene::Backend backend);
// Whether `render` is renderWithBackend itself (not a wrapper or a test's fake): then a study may
// keep one renderer across frames that differ only in what the renderer can change (a sweep row's
// frames, the recommendation's bias points) and get the same frames.
bool isRenderWithBackend(const RenderFn& render);

struct SweepProgress {
    std::size_t done = 0, total = 0, skipped = 0;  // skipped: already in the journal (resume)
    const SweepRow* row = nullptr;                 // the row just finished
    double elapsedSeconds = 0.0, etaSeconds = 0.0;
};

struct SweepOptions {
    std::filesystem::path outputDir;
    bool resume = false;
    bool writeImages = true;
    RenderFn render = renderWithBackend;
    std::function<void(const SweepProgress&)> progress;
    // Where the reference comes from, given the scene at the sweep's resolution; unset: rendered
    // once and cached as DIR/reference.exr. Shards share one (studies/shard.h).
    std::function<scene::Frame(const scene::Scene&)> reference;
};

struct SweepResult {
    std::vector<SweepRow> rows;  // in grid order
    scene::Frame reference;
    double referenceMs = 0.0;
};

// Writes DIR/reference.exr (cached: reused when it matches the scene and resolution),
// DIR/results.jsonl (the journal, one line per finished row, fsync'ed), and regenerates
// DIR/results.csv and DIR/results.json after every row. Throws scene::InputError when DIR
// already holds a sweep and `resume` is false, or holds one of another scene.
SweepResult runSweep(const scene::Scene& scene, const SweepGrid& grid, const SweepOptions& options);

// The scene a sweep renders: `scene` at the grid's resolution, when it sets one. Throws
// scene::InputError on a bad resolution.
scene::Scene sweepScene(const scene::Scene& scene, const SweepGrid& grid);

// The memory a sweep holds at its peak (docs/reliability.md, "Memory"): the program, the scene, the
// reference and a row's Frames at the sweep's resolution (and the recommendation's), writing the
// reference, the flicker path's references and frames, and the largest renderer among its rows' and
// the recommendation's (the rows' backends in the settings `user` gives).
JobMemory estimateSweepMemory(const scene::Scene& scene, const SweepGrid& grid, const scene::SettingsOverrides& user);

// One journal line's JSON and back (merge reads journals strictly with these); the backend is
// written as its name (scene::toString). rowFromJournal throws nlohmann::json::exception on a line
// that is JSON but not a row, and std::invalid_argument on a backend name no build has.
nlohmann::json journalRow(const SweepRow& row);
SweepRow rowFromJournal(const nlohmann::json& line);

// Reads the rows of a journal; a torn last line (a kill in the middle of a write) is ignored.
std::vector<SweepRow> readJournal(const std::filesystem::path& file);
std::string rowsToCsv(const std::vector<SweepRow>& rows);
nlohmann::json rowsToJson(const std::vector<SweepRow>& rows);

}  // namespace shadowlab::studies
