// raytrace/memory.h: an upper estimate of the memory a ray-traced render takes, checked against
// what the machine has before rendering.
#pragma once

#include <cstdint>

#include "scene/render_plan.h"
#include "scene/scene.h"

namespace shadowlab::raytrace {

// The Frame plus the acceleration structure (at most 100 bytes a triangle over the scene's own
// mesh data: the figure bench/raytrace_bench checks, docs/performance.md, for meshes of up to half
// a vertex a triangle; 72 bytes for each vertex beyond that: its float position and normal, and
// their double copy while the tree is built) and a small allowance
// for per-thread state. The program itself and writing the Frame are the caller's part.
std::uint64_t estimateMemoryBytes(const scene::Scene& scene, const scene::RenderPlan& plan);

}  // namespace shadowlab::raytrace
