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

// What writing that Frame to EXR adds while it runs: an interleaved copy for OpenImageIO and
// OpenEXR's own line buffers, measured at about 1.75 Frames (docs/reliability.md); counted as 2.
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

// What a job may use: SHADOWLAB_MEMORY_LIMIT_MB when set (for containers whose limit the kernel
// does not show in /proc/meminfo), else MemAvailable from /proc/meminfo; 0 when unknown.
std::uint64_t availableMemoryBytes();

// Throws InputError when `needed` exceeds availableMemoryBytes(): "WHAT needs about N MiB, but
// only M MiB are available ...", with what to lower.
void checkMemory(std::uint64_t needed, const std::string& what);

}  // namespace shadowlab::scene
