// bench/terrain_scene.h: the generated terrain both benchmarks scale with (raytrace_bench against
// Embree, raster_bench against the bare lavapipe baseline): the same mesh, camera and sun.
#pragma once

#include "scene/scene.h"

namespace shadowlab::bench {

// 708² cells, two triangles each: 1,002,528 triangles, the benches' default size.
constexpr int kTerrainCells = 708;

// A height field of cells² quads (two triangles each) over [−50, 50]², with smooth hills and
// sharp ridges so that shadow rays cross much of the terrain before they leave it, with
// area-weighted vertex normals, seen from a corner under a sun about 14° above the horizon (long
// shadows). The camera's image size is left to the bench.
scene::Scene terrainScene(int cells = kTerrainCells);

// The cells for about `triangles` triangles (two per cell, rounded; at least one cell).
int terrainCellsFor(long long triangles);

}  // namespace shadowlab::bench
