// scene/memory.cpp: measured and available memory, and the freed heap's release (Linux:
// getrusage, /proc, glibc's malloc_trim).
#include "scene/memory.h"

#include <malloc.h>
#include <sys/resource.h>
#include <unistd.h>

#include <algorithm>
#include <cstdint>
#include <cstdlib>
#include <fstream>
#include <mutex>
#include <set>
#include <sstream>
#include <variant>

#include "scene/error.h"
#include "scene/scene.h"

namespace shadowlab::scene {

std::uint64_t frameBytes(const Scene& scene) {
    // beauty (3 floats), visibility, object id, N·L, Z and blocker id: 8 floats a pixel, and one
    // visibility per light when there is more than one.
    const std::uint64_t floats = 8 + (scene.lights.size() > 1 ? scene.lights.size() : 0);
    return std::uint64_t(scene.camera.width) * std::uint64_t(scene.camera.height) * floats * sizeof(float);
}

std::uint64_t frameWriteBytes(const Scene& scene) { return 2 * frameBytes(scene); }

std::uint64_t sceneBytes(const Scene& scene) {
    std::uint64_t bytes = scene.loadBytes + sizeof(Scene);
    std::set<const TriangleMesh*> geometries;
    for (const Object& o : scene.objects) {
        bytes += sizeof(Object) + (o.name.size() > 15 ? o.name.capacity() + 1 : 0);
        if (const auto* m = std::get_if<Mesh>(&o.shape)) {
            bytes += m->file.native().capacity() + m->instances.capacity() * sizeof(MeshInstance);
            for (const MeshInstance& inst : m->instances) {
                const TriangleMesh* g = inst.geometry.get();
                if (!g || !geometries.insert(g).second) continue;
                bytes += sizeof(TriangleMesh) + 32 /* shared_ptr control block */ +
                         (g->positions.capacity() + g->normals.capacity()) * sizeof(Vec3) +
                         g->indices.capacity() * sizeof(std::uint32_t) + g->uvs.capacity() * sizeof(Vec2);
            }
        }
    }
    // Alpha textures, each shared one once.
    std::set<const AlphaTexture*> textures;
    for (const Material& m : scene.materials)
        if (m.alphaTexture && textures.insert(m.alphaTexture.get()).second) bytes += m.alphaTexture->bytes();
    return bytes;
}

std::uint64_t alphaTextureBytes(const Scene& scene) {
    std::set<const AlphaTexture*> textures;
    std::uint64_t bytes = 0;
    for (const Material& m : scene.materials)
        if (m.alphaTextured() && textures.insert(m.alphaTexture.get()).second)
            bytes += std::uint64_t(m.alphaTexture->alpha.size()) * 4;
    return bytes;
}

std::uint64_t alphaTexturedTriangles(const Scene& scene) {
    std::uint64_t n = 0;
    for (const Object& o : scene.objects)
        if (scene.materialOf(o).alphaTextured()) {
            if (const auto* m = std::get_if<Mesh>(&o.shape))
                n += m->triangleCount();
            else
                n += 2;  // a quad
        }
    return n;
}

std::uint64_t peakResidentBytes() {
    rusage usage{};
    if (::getrusage(RUSAGE_SELF, &usage) != 0) return 0;
    return std::uint64_t(usage.ru_maxrss) * 1024;  // Linux reports kilobytes
}

std::uint64_t residentBytes() {
    std::ifstream statm("/proc/self/statm");
    std::uint64_t size = 0, resident = 0;
    if (!(statm >> size >> resident)) return 0;
    return resident * std::uint64_t(::sysconf(_SC_PAGESIZE));
}

namespace {
// The innermost live FreedHeapBudget's figures (estimate 0: none), under budgetMutex (a renderer
// may end on any thread).
std::mutex budgetMutex;
std::uint64_t budgetEstimate = 0;
std::uint64_t budgetHeadroom = 0;
}  // namespace

FreedHeapBudget::FreedHeapBudget(std::uint64_t estimate, std::uint64_t headroom) {
    // At most what the process holds now and the machine still offers: a job that was not refused
    // on its estimate (a sweep) keeps no more than fits.
    if (const std::uint64_t available = availableMemoryBytes(); available > 0) {
        const std::uint64_t resident = residentBytes();
        estimate = std::min(estimate, available > UINT64_MAX - resident ? UINT64_MAX : available + resident);
    }
    const std::lock_guard lock(budgetMutex);
    outerEstimate_ = budgetEstimate;
    outerHeadroom_ = budgetHeadroom;
    budgetEstimate = estimate;
    budgetHeadroom = headroom;
}

FreedHeapBudget::~FreedHeapBudget() {
    const std::lock_guard lock(budgetMutex);
    budgetEstimate = outerEstimate_;
    budgetHeadroom = outerHeadroom_;
}

bool releaseFreedHeap() {
    std::uint64_t estimate = 0, headroom = 0;
    {
        const std::lock_guard lock(budgetMutex);
        estimate = budgetEstimate;
        headroom = budgetHeadroom;
    }
    if (estimate > 0) {
        const std::uint64_t resident = residentBytes();
        if (resident > 0 && headroom <= estimate && resident <= estimate - headroom) return false;
    }
    ::malloc_trim(0);
    return true;
}

std::uint64_t availableMemoryBytes() {
    if (const char* limit = std::getenv("SHADOWLAB_MEMORY_LIMIT_MB"); limit && *limit) {
        char* end = nullptr;
        const unsigned long long mb = std::strtoull(limit, &end, 10);
        if (end && *end == '\0' && mb > 0) return mb >= UINT64_MAX / kMiB ? UINT64_MAX : mb * kMiB;
        throw InputError(std::string("SHADOWLAB_MEMORY_LIMIT_MB: expected a positive whole number of MiB, got '") +
                         limit + "'");
    }
    std::ifstream meminfo("/proc/meminfo");
    for (std::string line; std::getline(meminfo, line);) {
        std::istringstream fields(line);
        std::string key;
        std::uint64_t kb = 0;
        if (fields >> key >> kb && key == "MemAvailable:") return kb * 1024;
    }
    return 0;
}

void checkMemory(std::uint64_t needed, const std::string& what) {
    const std::uint64_t available = availableMemoryBytes();
    if (available == 0 || needed <= available) return;
    throw InputError(what + " needs about " + std::to_string(needed / kMiB) + " MiB, but only " +
                     std::to_string(available / kMiB) + " MiB are available" +
                     (std::getenv("SHADOWLAB_MEMORY_LIMIT_MB") ? " (SHADOWLAB_MEMORY_LIMIT_MB)" : " (MemAvailable)") +
                     "; lower --resolution (or --shadow-map-size for raster)");
}

}  // namespace shadowlab::scene
