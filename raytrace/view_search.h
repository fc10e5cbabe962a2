// raytrace/view_search.h: a view and a sun that show shadows, for a model whose file has no
// camera or no light. Candidate views (around the model, or inside it when it encloses its
// space, as Sponza does) and candidate suns are scored with the float ray tracer at thumbnail
// size, the best few again at 3 × that size, and the best pair is kept (docs/decisions.md,
// "Views and suns for a model").
#pragma once

#include <string>

#include "scene/scene.h"

namespace shadowlab::raytrace {

struct ViewSearchOptions {
    bool chooseView = true;  // else the scene's camera stays
    bool chooseSun = true;   // else the scene's lights stay (their shadows are what is scored)
    int width = 64;          // thumbnail width; the height follows the camera's aspect (at least 16)
    int threads = 0;         // 0 = all
    // The best pairs scored again at 3 × the thumbnail's width, where the holes of cut-outs and
    // thin casters that the thumbnail loses decide between them; 0 keeps the thumbnail's best.
    int refine = 8;
};

// How one thumbnail (one view under one sun) scores. Shares are of the thumbnail's pixels; the
// shadowed share, the edges and the holes count a pixel whose surface is seen more than 60° from
// head-on as |cos| / 0.5 of one (its shadows are squeezed), and edges only between pixels on one
// surface.
struct ViewScore {
    double coverage = 0;       // pixels that see geometry
    double facing = 0;         // of those, the share whose surface faces the light (N·L > 0)
    double modelFacing = 0;    // the same on the model alone (an added ground left out)
    double shadowedShare = 0;  // of the facing ones, the share in cast shadow (transmittance < 0.5)
    double edgeLength = 0;     // lit–shadowed neighbour pairs (4-neighbours), per (width + height)
    double sunSide = 0;        // cosine between the view direction and the way light travels
    // Effective number of casters whose shadow outlines are seen: (Σ o)² / Σ o² over the casters'
    // outline lengths o (the lit–shadowed pairs each one's shadow makes).
    double casters = 0;
    // Of edgeLength, the pairs whose lit side is lit through a cut-out or a transparent caster:
    // the outlines of the holes in its shadow.
    double holeEdgeLength = 0;
    // The product of the factors (docs/decisions.md); in a search, times the light through
    // cut-outs relative to the candidate that shows most of it, where some candidate shows it.
    double score = 0;
};

struct ViewSearchResult {
    bool interior = false;               // the model encloses its space: views from inside
    int enclosedPoints = 0;              // probe points with walls around them (see interior)
    int probePoints = 0;                 // probe points not inside a solid
    int views = 0, suns = 0;             // candidates scored (views × suns pairs)
    int width = 0, height = 0;           // thumbnail size
    int refined = 0;                     // the best pairs scored again (ViewSearchOptions::refine) ...
    int fineWidth = 0, fineHeight = 0;   // ... at this size
    bool holes = false;                  // some candidate shows light through cut-outs: scores are weighed by it
    double seconds = 0;                  // the whole search, tracer build included
    scene::Camera camera;                // the chosen view (the scene's image size)
    scene::Vec3 sunDirection{0, -1, 0};  // the chosen sun (when chosen)
    ViewScore best;
    std::string viewText, sunText;  // what was chosen and why, in words
};

// Scores the candidates; deterministic (fixed candidates, no random numbers, per-pixel work
// independent of thread count).
ViewSearchResult searchViewAndSun(const scene::Scene& scene, const ViewSearchOptions& options);

// Scores the scene as it is (its camera, its lights) at thumbnail size: what the search
// maximizes, for --explain and tests.
ViewScore scoreScene(const scene::Scene& scene, int width, int threads = 0);

// Runs the search where scene.origin asks for one (chooseView / chooseSun), puts the result in
// the scene and records it in scene.origin.choices. Does nothing otherwise.
void chooseViewAndSun(scene::Scene& scene, int threads = 0);

}  // namespace shadowlab::raytrace
