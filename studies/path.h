// studies/path.h: the temporal study: a camera or light path through a scene, rendered frame by
// frame by the reference and both backends (each backend's setup made once and reused), measured
// with compare/temporal.h and written as a resumable folder with a report (docs/temporal.md).
#pragma once

#include <filesystem>
#include <functional>
#include <optional>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "compare/compare.h"
#include "compare/temporal.h"
#include "scene/scene.h"
#include "scene/settings.h"

namespace shadowlab::studies {

// orbit: the camera turns about the world's Y axis through its look-at point; dolly: it moves
// toward the look-at point; pan: camera and look-at move along the view's right axis; subtexel:
// camera and look-at move diagonally (right + up) by a fraction of the smaller of a shadow texel
// and a pixel's footprint per frame; sun-azimuth / sun-elevation: a directional light turns about
// world Y / about its horizontal axis; light-move: a spot or point light moves along world X;
// gltf-animation: the camera follows a glTF animation of a camera's node (scene/camera_animation.h),
// sampled at N evenly spaced times from its first key to its last.
enum class PathKind { Orbit, Dolly, Pan, SubTexel, SunAzimuth, SunElevation, LightMove, GltfAnimation };
const char* toString(PathKind kind);
// Throws scene::InputError naming the option and the kinds.
PathKind parsePathKind(const std::string& text);
bool isCameraPath(PathKind kind);

struct PathSpec {
    PathKind kind = PathKind::Orbit;
    int frames = 12;
    // The path's extent: orbit, sun-azimuth, sun-elevation: degrees over the whole path (20, 20,
    // 10); dolly: the fraction of the distance to the look-at point covered (0.3); pan: the
    // fraction of that distance moved (0.1); subtexel: the step per frame as a fraction of
    // min(texel, pixel footprint) (0.1); light-move: the fraction of the scene's diagonal (0.1).
    std::optional<double> amount;
    int light = 0;          // the light a light path moves
    std::string animation;  // gltf-animation: its name or index; empty: the first camera animation
};
// The scene's "path" block as a PathSpec (the loader has checked its values).
PathSpec pathSpecOf(const scene::PathBlock& block);
double defaultAmount(PathKind kind);

// The per-frame step of a subtexel path in world units (amount × min(texel, pixel footprint at
// the look-at point)), with the texel and footprint it came from.
struct SubTexelStep {
    double step = 0.0, texel = 0.0, pixel = 0.0;
};
SubTexelStep subTexelStep(const scene::Scene& scene, const scene::RasterSettings& settings, double amount);

// The scene of every frame (frame 0 is `base` itself, except for gltf-animation, whose frame 0 is
// the animation's first key). Throws scene::InputError for a path the scene cannot have (a light
// path without that light, a sun path on a point light, < 2 frames, no such camera animation).
std::vector<scene::Scene> pathScenes(const scene::Scene& base, const scene::RenderSettings& settings,
                                     const PathSpec& spec);

struct PathRunOptions {
    std::filesystem::path outputDir;
    bool resume = false;
    bool raster = true;
    bool raytrace = true;
    // Camera paths: also draw each frame's raster maps from frame 0's camera ("raster-held"),
    // which removes the image's own motion (docs/temporal.md).
    bool heldView = true;
    std::function<void(const std::string&)> progress;  // one line per finished frame
    // Sharded (`path --shard K/N`, shardCount > 0): render only the frames t with t mod N = K into
    // outputDir/shard-K-of-N, with its shard.json, and measure nothing; mergePathShards measures
    // the merged frames (docs/temporal.md).
    int shardIndex = 0, shardCount = 0;
};

// One method along the path.
struct PathMethod {
    std::string name;                       // raster | raster-held | raytrace
    double setupMs = 0.0;                   // the one-time setup (Renderer, acceleration structure)
    std::vector<double> frameMs;            // per frame, setup excluded (update included)
    std::vector<compare::Metrics> metrics;  // per frame, against that frame's reference
    compare::TemporalSummary temporal;
};

struct PathResult {
    PathSpec spec;
    double amount = 0.0;  // the amount used (spec's or the default)
    int frames = 0;
    int resumedFrames = 0;  // frames taken from the journal
    double referenceSetupMs = 0.0;
    std::vector<double> referenceFrameMs;
    compare::TemporalSummary referenceTemporal;  // zero by definition; computed as a check
    std::vector<PathMethod> methods;
};

// Renders the path into options.outputDir (frames/NNNN-NAME.exr, the journal frames.jsonl, one
// line per finished frame), then measures every method and writes metrics.json, flicker.svg, the
// animations (NAME.gif), the worst pair's zoom and report.html. Refuses a folder holding a path
// without options.resume, and one holding another path even with it.
PathResult runPath(const scene::Scene& base, const scene::RenderSettings& settings, const PathSpec& spec,
                   const PathRunOptions& options);

nlohmann::json toJson(const PathResult& result);

// The frames shard K of N renders: t with t mod N = K, in order (none when K ≥ frames).
std::vector<int> pathShardFrames(int frames, int index, int count);

// A path's progress line after `frame` (0-based) of `frames`: "frame 5/12, ETA 1m05s", and for a
// shard (shardFrames > 0) "frame 11/12 (6 of 6 in this shard), ETA 0m00s".
std::string pathProgressLine(int frame, int frames, std::size_t shardDone, std::size_t shardFrames, double secondsLeft);

// True when the inputs hold shards of a path (a shard.json naming a path study).
bool holdsPathShards(const std::vector<std::filesystem::path>& inputs);

struct MergedPath {
    PathResult result;
    int shardCount = 0;
    std::vector<std::filesystem::path> shardDirs;
    std::size_t duplicates = 0;  // frames found in more than one shard folder (a rerun), merged once
};
// Reads the path shards under `inputs` (shard folders, or folders holding shard-K-of-N folders),
// checks that they are of one path (program version, scene hash, kind, frames, amount, settings,
// methods) and one split, and that every frame is there, then writes `out` as the unsharded path
// writes its folder (frames/, frames.jsonl, path.json, metrics.json, the report; plus merge.json)
// and measures it from the merged frames. Throws scene::InputError naming the folder when a shard
// is of another path, a frame is in the wrong shard or a journal line is damaged, and, with the
// command that renders them, every missing or unfinished shard; nothing is written then.
MergedPath mergePathShards(const std::vector<std::filesystem::path>& inputs, const std::filesystem::path& out);

// What differs between two path folders' metrics.json, leaving out what timing measures (setup and
// frame times, compare's stage timings) and how many frames were resumed: one line per difference
// (a JSON pointer and both values), empty when they hold the same figures. Throws scene::InputError.
std::vector<std::string> pathDifferences(const std::filesystem::path& a, const std::filesystem::path& b);

}  // namespace shadowlab::studies
