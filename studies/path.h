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

namespace shadowlab::compare {

// orbit: the camera turns about the world's Y axis through its look-at point; dolly: it moves
// toward the look-at point; pan: camera and look-at move along the view's right axis; subtexel:
// camera and look-at move diagonally (right + up) by a fraction of the smaller of a shadow texel
// and a pixel's footprint per frame; sun-azimuth / sun-elevation: a directional light turns about
// world Y / about its horizontal axis; light-move: a spot or point light moves along world X.
enum class PathKind { Orbit, Dolly, Pan, SubTexel, SunAzimuth, SunElevation, LightMove };
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
    int light = 0;  // the light a light path moves
};
double defaultAmount(PathKind kind);

// The per-frame step of a subtexel path in world units (amount × min(texel, pixel footprint at
// the look-at point)), with the texel and footprint it came from.
struct SubTexelStep {
    double step = 0.0, texel = 0.0, pixel = 0.0;
};
SubTexelStep subTexelStep(const scene::Scene& scene, const scene::RasterSettings& settings, double amount);

// The scene of every frame (frame 0 is `base` itself). Throws scene::InputError for a path the
// scene cannot have (a light path without that light, a sun path on a point light, < 2 frames).
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
};

// One method along the path.
struct PathMethod {
    std::string name;  // raster | raster-held | raytrace
    double setupMs = 0.0;                // the one-time setup (Renderer, acceleration structure)
    std::vector<double> frameMs;         // per frame, setup excluded (update included)
    std::vector<Metrics> metrics;        // per frame, against that frame's reference
    TemporalSummary temporal;
};

struct PathResult {
    PathSpec spec;
    double amount = 0.0;  // the amount used (spec's or the default)
    int frames = 0;
    int resumedFrames = 0;  // frames taken from the journal
    double referenceSetupMs = 0.0;
    std::vector<double> referenceFrameMs;
    TemporalSummary referenceTemporal;  // zero by definition; computed as a check
    std::vector<PathMethod> methods;
};

// Renders the path into options.outputDir (frames/NNNN-NAME.exr, the journal frames.jsonl, one
// line per finished frame), then measures every method and writes metrics.json, flicker.svg, the
// animations (NAME.gif), the worst pair's zoom and report.html. Refuses a folder holding a path
// without options.resume, and one holding another path even with it.
PathResult runPath(const scene::Scene& base, const scene::RenderSettings& settings, const PathSpec& spec,
                   const PathRunOptions& options);

nlohmann::json toJson(const PathResult& result);

}  // namespace shadowlab::compare
