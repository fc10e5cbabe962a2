// scene/memory.h: how much memory a render takes, measured and estimated beforehand, so the
// program refuses a job the machine cannot hold with one clear message instead of being killed
// half-way by the kernel. Each backend adds its own part (raster::estimateMemoryBytes,
// raytrace::estimateMemoryBytes); docs/reliability.md has the measured figures.
#pragma once

#include <cstdint>
#include <string>

namespace shadowlab::scene {

struct Scene;

inline constexpr std::uint64_t kMiB = 1024 * 1024;

// The bytes a Frame of the scene's camera resolution takes (every AOV, blocker ids, per-light visibility).
std::uint64_t frameBytes(const Scene& scene);

// What writing that Frame to EXR adds while it runs, and more: the writer interleaves a band of 64
// rows at a time, 12 MiB at 3840x2160 with OpenEXR's line buffers, but a command's peak comes
// while it renders, where a 3840x2160 ray-traced render holds about three Frames and the parts
// above count two; the allowance stays at 2 Frames (docs/reliability.md).
std::uint64_t frameWriteBytes(const Scene& scene);

// The scene itself: its objects, their names, mesh placements and geometry (each shared
// geometry once), and what loading it took at its peak (Scene::loadBytes: the file's text and
// parsed tree, which the process keeps as resident memory once freed).
std::uint64_t sceneBytes(const Scene& scene);

// Alpha-tested and blended casters (docs/scene-format.md): the texels of the scene's alpha
// textures (4 bytes each, each texture once), which the raster backend uploads, and the triangles
// of objects whose material reads one (a triangle carries texture coordinates in both backends).
std::uint64_t alphaTextureBytes(const Scene& scene);
std::uint64_t alphaTexturedTriangles(const Scene& scene);

// What each backend holds per object besides its geometry (its entries in the object and
// instance lists, bounds and acceleration-structure nodes): an allowance, measured at about
// 100 bytes an object for a million spheres and rounded up.
inline constexpr std::uint64_t kBackendBytesPerObject = 256;

// The program and its libraries before any render (measured: 126 MiB resident), rounded up.
inline constexpr std::uint64_t kProgramBytes = 160 * kMiB;

// The most memory this process has held so far (resident set; getrusage's ru_maxrss).
std::uint64_t peakResidentBytes();

// The resident set now (/proc/self/statm); 0 when unknown.
std::uint64_t residentBytes();

// The heap freed between renderers. Studies make renderer after renderer (the sweep's rows, the
// recommendation's checks), and the driver's and the tracers' threads free into their own malloc
// arenas, which keep it. Returned to the system after each renderer (malloc_trim), the next one
// faults every page in again (a quarter of a default run's CPU on a virtual machine); kept, it may
// carry the process past its estimate. While a FreedHeapBudget is alive, releaseFreedHeap()
// returns it only where the resident set plus `headroom` (the largest renderer the job makes, all
// of it fresh memory) would pass `estimate` (or what the machine offers, when less); with none alive
// it always does (docs/reliability.md, "Memory").
// Budgets nest: the innermost one decides while it lives, and the outer one again after it.
class FreedHeapBudget {
public:
    FreedHeapBudget(std::uint64_t estimate, std::uint64_t headroom);
    ~FreedHeapBudget();
    FreedHeapBudget(const FreedHeapBudget&) = delete;
    FreedHeapBudget& operator=(const FreedHeapBudget&) = delete;

private:
    std::uint64_t outerEstimate_ = 0, outerHeadroom_ = 0;
};

// After a renderer is gone (studies/backend.cpp): malloc_trim, unless the budget leaves room.
// Returns whether it trimmed.
bool releaseFreedHeap();

// What a job may use: SHADOWLAB_MEMORY_LIMIT_MB when set (for containers whose limit the kernel
// does not show in /proc/meminfo), else MemAvailable from /proc/meminfo; 0 when unknown.
std::uint64_t availableMemoryBytes();

// Throws InputError when `needed` exceeds availableMemoryBytes(): "WHAT needs about N MiB, but
// only M MiB are available ...", with what to lower.
void checkMemory(std::uint64_t needed, const std::string& what);

}  // namespace shadowlab::scene
