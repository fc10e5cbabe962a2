// compare/temporal.h: how still a method's shadows hold along a path of frames (docs/temporal.md):
// flicker (counted pixels whose lit/shadow state changes between consecutive frames while the
// reference's does not), the temporal variation of the visibility error, and swimming (how far
// the method's shadow edges move against the reference's between frames, apart from a stable offset).
#pragma once

#include <cstddef>
#include <vector>

#include <nlohmann/json.hpp>

#include "compare/compare.h"
#include "scene/frame.h"

namespace shadowlab::compare {

// A reference edge crossing is matched with the method's nearest crossing of the same direction on
// the same image row or column when that lies within this many pixels: farther, the method has no
// edge there (a missing or extra shadow is error, not an offset of this edge).
inline constexpr double kEdgeMatchPixels = 8.0;
// Between frames a reference crossing is the same edge when it moved by at most this many pixels
// along its row or column (a path's steps move edges by less; a larger jump is another edge).
inline constexpr double kEdgeTrackPixels = 1.5;

// One consecutive pair of frames (t, t + 1), compared at the same image position.
struct PairStability {
    int first = 0;                     // t
    std::size_t comparable = 0;        // pixels counted (compare's rule) in both frames
    std::size_t methodChanges = 0;     // comparable pixels whose method state (V ≤ τ: shadow) changes
    std::size_t referenceChanges = 0;  // ... whose reference state changes
    std::size_t flicker = 0;           // method changes while the reference does not
    std::size_t missedChanges = 0;     // the reference changes while the method does not
    double flickerRate = 0.0;          // flicker / comparable (0 when nothing is comparable)
    // Mean and largest over comparable pixels of | |V_M − V_R|(t+1) − |V_M − V_R|(t) |.
    double errorVariation = 0.0;
    double maxErrorVariation = 0.0;
    // Reference edge crossings matched in both frames and tracked from t to t + 1, and the mean
    // change of the method's offset against them (pixels): 0 for an edge that keeps its offset.
    std::size_t trackedEdges = 0;
    double swimPixels = 0.0;
};

// The method's shadow edges against the reference's in one frame.
struct FrameEdges {
    std::size_t referenceCrossings = 0;  // reference edge crossings along rows and columns
    std::size_t matched = 0;             // ... with a method crossing within kEdgeMatchPixels
    // Signed mean offset of the matched method crossings (pixels along the row or column):
    // positive where the method's shadow is smaller (peter-panning, leaks), negative larger.
    double meanOffset = 0.0;
    double meanAbsOffset = 0.0;
};

struct TemporalSummary {
    int frames = 0;
    std::vector<PairStability> pairs;  // frames − 1 of them
    std::vector<FrameEdges> edges;     // one per frame
    std::size_t totalFlicker = 0;
    double meanFlickerRate = 0.0, maxFlickerRate = 0.0;
    int worstPair = -1;  // the pair with the most flicker pixels (-1 without pairs)
    double meanErrorVariation = 0.0, maxErrorVariation = 0.0;
    // Swimming over the pairs with tracked edges (0 when there are none), and the stable part:
    // the mean of the frames' signed offsets.
    double meanSwimPixels = 0.0, maxSwimPixels = 0.0;
    double meanEdgeOffset = 0.0;
};

// method[t] and reference[t] share a camera (the same image positions); `classes[t]` is
// compareFrames(method[t], reference[t]).classes (what counts). Throws scene::InputError when the
// counts or the sizes differ.
TemporalSummary measureTemporal(const std::vector<const scene::Frame*>& method,
                                const std::vector<const scene::Frame*>& reference,
                                const std::vector<const std::vector<PixelClass>*>& classes);
// The same, classifying each pair of frames itself (tests, small paths).
TemporalSummary measureTemporal(const std::vector<const scene::Frame*>& method,
                                const std::vector<const scene::Frame*>& reference);

// Per pixel, 1 where pair (t, t + 1) flickers (counted in both, the method's state changes, the
// reference's does not), else 0: what PairStability::flicker counts.
std::vector<unsigned char> flickerMask(const scene::Frame& method0, const scene::Frame& method1,
                                       const scene::Frame& reference0, const scene::Frame& reference1,
                                       const std::vector<PixelClass>& classes0,
                                       const std::vector<PixelClass>& classes1);

nlohmann::json toJson(const TemporalSummary& summary);
nlohmann::json toJson(const PairStability& pair);

}  // namespace shadowlab::compare
