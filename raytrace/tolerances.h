// raytrace/tolerances.h: every constant of the ray tracer that is not derived from the scene
// or from rounding-error bounds, each with the reason for its value. Biases are not here: they
// are settings (scene/settings.h), and the robust offsets are derived, not chosen.
#pragma once

namespace shadowlab::raytrace {

// Tiles of 16x16 pixels: 256 rays per task make TBB's per-task overhead (a few µs at most)
// negligible, and a 160x90 test image still splits into 60 tasks for load balance.
inline constexpr int kTileSize = 16;

// BVH build. Binned SAH (Wald, "On fast Construction of SAH-based Bounding Volume
// Hierarchies", RT'07) with 16 bins per axis: between pbrt-v4's 12 buckets and the 32 some
// builders use; more bins buy little tree quality for a linear increase in build time.
inline constexpr int kBvhBins = 16;
// Leaves are intersected in SSE packets of this many triangles (triangle4.h): the SAH counts a
// leaf's cost in packets, so leaves fill whole packets when that is cheaper.
inline constexpr unsigned kBvhLeafBlock = 4;
// A node with this many primitives or fewer is always a leaf: they fit one packet, tested at
// the cost of one, so a split cannot save a test.
inline constexpr unsigned kBvhMinSplitCount = 4;
// Leaves never hold more than this (two packets), even when SAH prefers a leaf: bounds the
// worst case of a ray that hits a big leaf of coincident triangles.
inline constexpr unsigned kBvhMaxLeafCount = 8;
// Cost of visiting a (binary) node relative to one packet test, in the SAH. A binary node
// becomes half of a 4-wide node's box test after the collapse; pbrt-v4 uses 1/2 relative to
// one triangle for its binary tree. 1.0 (a packet costs about two scalar triangles, a 4-wide
// box test about one) measured best on Sponza (docs/performance.md).
inline constexpr double kBvhTraversalCost = 1.0;
// Below this depth splits use SAH; deeper, the build halves by count. Keeps any tree within
// 48 + log2(2^32) = 80 levels, below the traversal stack of 128.
inline constexpr int kBvhSahMaxDepth = 48;

// Parallel build (TBB): ranges of at least this many primitives bin and bound in parallel
// chunks and build their two halves as two tasks; smaller ones run sequentially, where a task
// (a few µs) would cost more than the work. The tree does not depend on it (bvh.cpp).
inline constexpr unsigned kBvhParallelCount = 4096;
inline constexpr unsigned kBvhParallelGrain = 1024;

// An instance's world box (the top-level tree over a mesh object's instances) is its object-
// space box's eight corners transformed, widened by this fraction of (largest |coordinate| +
// diagonal). The ray is transformed into object space with rounding, so the box test in world
// space and the triangle tests in object space see slightly different rays; the pad (2^-16,
// over 100x the float rounding of a transform, ~3·2^-24 relative) keeps the world test from
// culling a hit the object-space test finds. The object-space trees decide every hit.
inline constexpr double kInstanceBoxPad = 0x1.0p-16;

// The float walk's closest-hit tie rule (docs/raytrace.md, "Ties") needs every triangle hit at
// the best t tested, but a box's entry distance and a triangle's t are computed differently
// and may round apart (a box entered at exactly the hit's t measures a float or two beyond
// it). So the walk culls boxes beyond tMax·(1 + 2^-16): over 100 floats of slack, far more
// than the few roundings either side carries for any but the most grazing hits.
inline constexpr float kTieCullSlack = 1.0f + 0x1.0p-16f;

// Pre-splitting of the float build (bvh.cpp, Presplitter): extra references, as a fraction of
// the triangle count, and the most pieces one triangle is cut into.
inline constexpr double kPresplitBudget = 0.1;
inline constexpr int kPresplitMaxPieces = 64;
// A piece's box is widened by this much of the mesh's scale (largest coordinate plus diagonal),
// within its triangle's whole box: far above the float triangle test's rounding (a few 2^-24
// of that scale), so every hit the test can accept lies in some piece's box.
inline constexpr double kPresplitPad = 0x1.0p-16;

// Seed of the per-pixel random streams for area-light samples, so renders are reproducible.
inline constexpr unsigned long long kSampleSeed = 0x5eed5eedULL;

}  // namespace shadowlab::raytrace
