// studies/recommend.h: the recommended scene-file "shadow" block, searched in the configuration
// the user will run (their filter, map size, cascades and fitting as resolved; only the biases
// change), over depth × slope bias together and refined around the best point, then rendered at
// the requested resolution against the user's defaults. The defaults are recommended whenever
// nothing beats them, so the recommendation never loses (docs/sweep.md "The recommendation").
#pragma once

#include <algorithm>
#include <optional>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "scene/frame.h"
#include "scene/scene.h"
#include "scene/settings.h"
#include "studies/auto_bias.h"
#include "studies/sweep.h"

namespace shadowlab::studies {

// The measurement of one configuration against the reference.
struct Measured {
    bool ok = false;
    std::string error;  // when !ok
    double mismatchRate = 0.0, falseShadowRate = 0.0, missedShadowRate = 0.0;
    double shadowIoU = 1.0, meanAbsVisibilityError = 0.0;
    double softErrorRate = 0.0;  // off by more than 0.25 without crossing τ (compare.h)
    // Missed shadow at a smooth-shaded mesh's terminator (compare.h): the reference's facets
    // shadowing their neighbours, which a renderer's offset or bias is meant to hide. The search
    // and beats() judge the rest (judgedRate), so that no setting is recommended for bringing the
    // faceted terminator back.
    double terminatorMissedRate = 0.0;
    double timeMs = 0.0;  // the render's total time (one render: a rough figure)
    double judgedRate() const { return std::max(0.0, mismatchRate - terminatorMissedRate); }
};
Measured measure(const scene::Frame& method, const scene::Frame& reference);
// The search's order: a is strictly better than b with less mismatch (judgedRate: the terminator's
// left out), or as much and less mean |ΔV|. A failed measurement is never better.
bool better(const Measured& a, const Measured& b);
// A candidate replaces the defaults only when neither its mismatch nor its mean |ΔV| is larger
// (with a filter, a bias can trade a few wrong pixels for a wide band of partial acne the classes
// do not see, which must not count as a gain) AND one of them falls by a tenth and by at least
// kMaterialGain (a rate, or a mean |ΔV|): less is sampling noise, not a reason to change settings.
inline constexpr double kMaterialGain = 1e-4;
bool beats(const Measured& candidate, const Measured& defaults);

// One searched raster point. `defaults` is the user's configuration untouched: its biases are
// whatever resolveSettings gives (a default depth bias is re-derived per fitted map and cascade).
struct BiasPoint {
    bool defaults = false;
    double depthBias = 0.0;  // world units (the defaults point: the applied value, for display)
    double slopeBias = 0.0;  // texels
    bool refined = false;    // added by the refinement round
    Measured at;             // at the search resolution
};

// The verdict of one backend at the requested resolution.
struct Verified {
    bool searched = false;  // a candidate other than the defaults was found and rendered
    bool beatsDefaults = false;
    Measured defaults;      // the user's configuration
    Measured tried;         // the candidate (when searched)
    Measured recommended;   // what the block gives: the best of defaults, tried and largerMap
    std::string candidate;  // "depth bias 0.01 world units, slope bias 2 texels", "ray bias robust (float)"
    // Raster: the map size tried where the default size capped what the receivers ask for (0: not
    // tried), at the user's biases, and what it measured.
    int largerMapSize = 0;
    Measured largerMap;
    bool largerMapRecommended = false;
    // Raster: the normal offsets tried on top of the biases recommended so far (texels; empty where
    // the user set one), what each measured, and the one recommended (0: none).
    std::vector<std::pair<double, Measured>> normalOffsets;
    double normalOffsetRecommended = 0.0;
};

// Twice the default size: four times its texels and memory, about 1.7 times the raster frame's
// time on lavapipe (docs/sweep.md "The recommendation"); larger maps are the user's call.
inline constexpr int kLargestRecommendedMapSize = 2 * scene::kDefaultShadowMapSize;

struct RecommendOptions {
    RenderFn render = renderWithBackend;
    // The user's settings (command line); the scene's own "shadow" block applies below them.
    scene::SettingsOverrides user;
    bool raster = true, raytrace = true;
    // Coarse grid around the user's biases (b0: the applied constant bias, s0: the slope bias,
    // 1 when it is 0): depth b0 × depthSteps, slope s0 × slopeSteps; then one refinement round of
    // the 3×3 geometric midpoints around the best point.
    std::vector<double> depthSteps{0.0, 1.0, 4.0, 16.0};
    std::vector<double> slopeSteps{0.0, 1.0, 4.0};
    bool refine = true;
    // Where the user set no map size and the default capped it below what the receivers ask for
    // (the frame's shadow_map_size_needed), the next power of two up to this size is tried too.
    int largestMapSize = kLargestRecommendedMapSize;
    // Normal offsets (texels) tried at the requested resolution on top of the recommended biases,
    // where the user set none: a grazing receiver on a curved mesh self-shadows past any slope bias
    // that keeps thin casters' shadows (docs/sweep.md "The recommendation"). Empty: not tried.
    std::vector<double> normalOffsetSteps{0.5, 1.0};
};

struct Recommendation {
    std::string searchResolution, resolution;  // "WxH"
    std::vector<BiasPoint> points;             // in search order; points[0] is the defaults
    int best = -1;                             // index into points
    Verified raster, raytrace;
    // The scene-file "shadow" block (scene/loader.cpp readShadow accepts every key): the user's
    // own non-bias settings from the command line, plus the biases that beat the defaults.
    nlohmann::json shadowBlock = nlohmann::json::object();
    std::vector<std::string> notes;  // sentences for reports: what was searched, measured, chosen

    // {"shadow": block, "measured": {...}}: what recommended-shadow.json holds.
    nlohmann::json toJson() const;
};

// `searchScene`/`searchReference`: the resolution the search renders at (the sweep's);
// `scene`/`reference`: the requested resolution. `rasterDefaults`/`raytraceDefaults`: the user's
// configuration already rendered at the requested resolution (run has them); rendered here
// when null. `rayCandidate`: the sweep's ray-tracer choice (AutoBias's "ray_bias" and
// "precision"), tried against the ray tracer's defaults. Render failures are recorded, never
// thrown; a failed candidate is never recommended.
Recommendation recommendShadow(const scene::Scene& searchScene, const scene::Frame& searchReference,
                               const scene::Scene& scene, const scene::Frame& reference,
                               const scene::Frame* rasterDefaults, const scene::Frame* raytraceDefaults,
                               const nlohmann::json& rayCandidate, const RecommendOptions& options);

// The shadow block of an AutoBias limited to the ray tracer's keys (ray_bias, precision).
nlohmann::json rayCandidateOf(const AutoBias& bias);

}  // namespace shadowlab::studies
