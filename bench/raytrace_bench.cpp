// bench/raytrace_bench.cpp: our float tracer against Embree 3 on the same rays: primary rays
// (closest hit, one per pixel center) and shadow rays (any hit, toward a directional light,
// from the primary hits). Scenes: the seed scene (analytic sphere + quad; Embree uses its
// sphere-point and quad primitives), Sponza (triangles) when the file is present, and a
// generated terrain of about one million triangles (hills under a low sun, long shadows).
// Times are process CPU time (all threads), so figures are rays per CPU-second: on a shared
// machine that is far steadier than wall time, and both tracers run the same parallel loop.
// Prints Google Benchmark's table, then the median (min-max) Mrays per CPU-second over the
// repetitions, the ratio ours / Embree, hit counts of both, setup times and bytes per triangle.
#include <benchmark/benchmark.h>

#include <algorithm>
#include <array>
#include <atomic>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <ctime>
#include <filesystem>
#include <map>
#include <memory>
#include <string>
#include <vector>

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>
#include <tbb/task_arena.h>

#include "raytrace/intersect.h"
#include "raytrace/shadow_ray.h"
#include "raytrace/tracer.h"
#include "raytrace/wide_bvh.h"
#include "scene/camera.h"
#include "scene/loader.h"
#include "scene/mesh_loader.h"
#include "terrain_scene.h"

#ifdef SHADOWLAB_HAVE_EMBREE
#include <embree3/rtcore.h>
#endif

namespace {

using namespace shadowlab;
using Real = float;
using V = raytrace::Vec3T<Real>;

// Where Sponza is looked for; the environment variable SHADOWLAB_SPONZA overrides it.
const char* kDefaultSponzaPath = "/work/shared/scenes/Sponza/Sponza.gltf";
constexpr int kWidth = 1280, kHeight = 720;
constexpr std::size_t kBlock = 1024;  // rays per parallel task, same for both tracers

struct Workload {
    std::string name;
    scene::Scene scene;
    std::unique_ptr<raytrace::Tracer<Real>> tracer;
    // The same float tracer on the reference's (double-built) trees: what the tree is worth.
    std::unique_ptr<raytrace::Tracer<Real>> refTree;
    double ourSetupMs = 0;
    std::vector<raytrace::Ray<Real>> primary;
    std::vector<raytrace::Ray<Real>> shadow;  // origins offset by the robust bound
#ifdef SHADOWLAB_HAVE_EMBREE
    RTCDevice device = nullptr;
    RTCScene embree = nullptr;
    double embreeSetupMs = 0;
    long long embreeBytes = 0;  // held by the device after the build (memory monitor)
#endif
};

int envInt(const char* name, int fallback) {
    const char* v = std::getenv(name);
    return v && *v ? std::atoi(v) : fallback;
}

// Process CPU time (all threads) in ms: steadier than wall time on a shared machine.
double cpuMs() {
    timespec ts;
    clock_gettime(CLOCK_PROCESS_CPUTIME_ID, &ts);
    return 1e3 * double(ts.tv_sec) + 1e-6 * double(ts.tv_nsec);
}

std::array<double, 3> medianMinMax(std::vector<double> v) {
    if (v.empty()) return {0, 0, 0};
    std::sort(v.begin(), v.end());
    const std::size_t n = v.size();
    return {n % 2 ? v[n / 2] : 0.5 * (v[n / 2 - 1] + v[n / 2]), v.front(), v.back()};
}

double msSince(std::chrono::steady_clock::time_point t0) {
    return std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count();
}

// Rays are made once, by our tracer, and given to both: primary rays through pixel centers,
// shadow rays from every primary hit that faces the light.
void makeRays(Workload& w) {
    scene::Camera cam = w.scene.camera;
    cam.width = kWidth;
    cam.height = kHeight;
    const scene::CameraBasis basis = scene::cameraBasis(cam);
    const V eye(basis.position);
    for (int y = 0; y < kHeight; ++y)
        for (int x = 0; x < kWidth; ++x) w.primary.emplace_back(eye, V(scene::pixelDirection(basis, x, y)));
    scene::RaytraceSettings robust;
    robust.robustOffset = true;
    const scene::Vec3 toLight = -w.scene.lights.at(0).direction;
    const V l(toLight);
    for (const auto& ray : w.primary) {
        raytrace::Hit<Real> h;
        if (!w.tracer->closestHit(ray, std::numeric_limits<Real>::infinity(), false, h)) continue;
        const raytrace::SurfacePoint<Real> sp = w.tracer->surfacePoint(ray, h, true);
        if (glm::dot(sp.ns, l) <= 0) continue;
        w.shadow.emplace_back(raytrace::shadowOrigin(sp, l, robust), l);
    }
}

#ifdef SHADOWLAB_HAVE_EMBREE
void addEmbreeQuads(RTCDevice device, RTCScene scene, const std::vector<scene::Vec3>& corners) {
    RTCGeometry g = rtcNewGeometry(device, RTC_GEOMETRY_TYPE_QUAD);
    auto* v = static_cast<float*>(
        rtcSetNewGeometryBuffer(g, RTC_BUFFER_TYPE_VERTEX, 0, RTC_FORMAT_FLOAT3, 3 * sizeof(float), corners.size()));
    for (std::size_t i = 0; i < corners.size(); ++i)
        for (int k = 0; k < 3; ++k) v[3 * i + k] = float(corners[i][k]);
    auto* idx = static_cast<unsigned*>(rtcSetNewGeometryBuffer(g, RTC_BUFFER_TYPE_INDEX, 0, RTC_FORMAT_UINT4,
                                                               4 * sizeof(unsigned), corners.size() / 4));
    for (std::size_t i = 0; i < corners.size(); ++i) idx[i] = unsigned(i);
    rtcCommitGeometry(g);
    rtcAttachGeometry(scene, g);
    rtcReleaseGeometry(g);
}

// Bytes Embree holds now and at most, counted by its memory monitor (all devices together).
std::atomic<long long> embreeBytes{0}, embreePeakBytes{0};
bool embreeMonitor(void*, ssize_t bytes, bool) {
    const long long now = embreeBytes += bytes;
    long long peak = embreePeakBytes.load();
    while (now > peak && !embreePeakBytes.compare_exchange_weak(peak, now)) {
    }
    return true;
}

struct EmbreeScene {
    RTCDevice device;
    RTCScene scene;
};

// Device, geometry (converted to float) and the committed scene: what Embree's setup is.
EmbreeScene embreeBuild(const scene::Scene& sc) {
    EmbreeScene w;
    w.device = rtcNewDevice(nullptr);
    rtcSetDeviceMemoryMonitorFunction(w.device, embreeMonitor, nullptr);
    w.scene = rtcNewScene(w.device);
    for (const scene::Object& o : sc.objects) {
        if (const auto* s = std::get_if<scene::Sphere>(&o.shape)) {
            RTCGeometry g = rtcNewGeometry(w.device, RTC_GEOMETRY_TYPE_SPHERE_POINT);
            auto* v = static_cast<float*>(
                rtcSetNewGeometryBuffer(g, RTC_BUFFER_TYPE_VERTEX, 0, RTC_FORMAT_FLOAT4, 4 * sizeof(float), 1));
            v[0] = float(s->center.x), v[1] = float(s->center.y), v[2] = float(s->center.z);
            v[3] = float(s->radius);
            rtcCommitGeometry(g);
            rtcAttachGeometry(w.scene, g);
            rtcReleaseGeometry(g);
        } else if (const auto* q = std::get_if<scene::Quad>(&o.shape)) {
            const scene::Vec3 du = 0.5 * q->size.x * q->uAxis, dv = 0.5 * q->size.y * q->vAxis;
            addEmbreeQuads(w.device, w.scene,
                           {q->center - du - dv, q->center + du - dv, q->center + du + dv, q->center - du + dv});
        } else if (const auto* b = std::get_if<scene::Box>(&o.shape)) {
            const scene::Vec3 lo = b->min, hi = b->max;
            auto c = [&](int i) { return scene::Vec3(i & 1 ? hi.x : lo.x, i & 2 ? hi.y : lo.y, i & 4 ? hi.z : lo.z); };
            const int faces[6][4] = {{0, 2, 6, 4}, {1, 5, 7, 3}, {0, 4, 5, 1},
                                     {2, 3, 7, 6}, {0, 1, 3, 2}, {4, 6, 7, 5}};
            std::vector<scene::Vec3> corners;
            for (const auto& f : faces)
                for (int k : f) corners.push_back(c(k));
            addEmbreeQuads(w.device, w.scene, corners);
        } else if (const auto* m = std::get_if<scene::Mesh>(&o.shape)) {
            const scene::TriangleMesh tm = scene::flattenInstances(m->instances);
            RTCGeometry g = rtcNewGeometry(w.device, RTC_GEOMETRY_TYPE_TRIANGLE);
            auto* v = static_cast<float*>(rtcSetNewGeometryBuffer(g, RTC_BUFFER_TYPE_VERTEX, 0, RTC_FORMAT_FLOAT3,
                                                                  3 * sizeof(float), tm.positions.size()));
            for (std::size_t i = 0; i < tm.positions.size(); ++i)
                for (int k = 0; k < 3; ++k) v[3 * i + k] = float(tm.positions[i][k]);
            auto* idx = static_cast<unsigned*>(rtcSetNewGeometryBuffer(g, RTC_BUFFER_TYPE_INDEX, 0, RTC_FORMAT_UINT3,
                                                                       3 * sizeof(unsigned), tm.triangleCount()));
            for (std::size_t i = 0; i < tm.indices.size(); ++i) idx[i] = tm.indices[i];
            rtcCommitGeometry(g);
            rtcAttachGeometry(w.scene, g);
            rtcReleaseGeometry(g);
        }
    }
    rtcCommitScene(w.scene);
    return w;
}

void buildEmbree(Workload& w) {
    const auto t0 = std::chrono::steady_clock::now();
    const long long before = embreeBytes.load();
    const EmbreeScene e = embreeBuild(w.scene);
    w.embreeSetupMs = msSince(t0);
    w.embreeBytes = embreeBytes.load() - before;
    w.device = e.device;
    w.embree = e.scene;
}

std::size_t embreePrimary(const Workload& w) {
    std::atomic<std::size_t> hits{0};
    tbb::parallel_for(tbb::blocked_range<std::size_t>(0, w.primary.size(), kBlock), [&](auto r) {
        RTCIntersectContext ctx;
        rtcInitIntersectContext(&ctx);
        std::size_t local = 0;
        for (std::size_t i = r.begin(); i != r.end(); ++i) {
            const auto& ray = w.primary[i];
            RTCRayHit rh{};
            rh.ray.org_x = ray.o.x, rh.ray.org_y = ray.o.y, rh.ray.org_z = ray.o.z;
            rh.ray.dir_x = ray.d.x, rh.ray.dir_y = ray.d.y, rh.ray.dir_z = ray.d.z;
            rh.ray.tnear = 0.0f;
            rh.ray.tfar = std::numeric_limits<float>::infinity();
            rh.ray.mask = ~0u;
            rh.hit.geomID = RTC_INVALID_GEOMETRY_ID;
            rtcIntersect1(w.embree, &ctx, &rh);
            local += rh.hit.geomID != RTC_INVALID_GEOMETRY_ID;
        }
        hits += local;
    });
    return hits;
}

// Embree's 8-wide packets: eight consecutive rays of the list (neighbouring pixels of a row,
// or shadow rays from them) per rtcIntersect8 / rtcOccluded8 call, the tail masked off.
std::size_t embreePrimary8(const Workload& w) {
    std::atomic<std::size_t> hits{0};
    tbb::parallel_for(tbb::blocked_range<std::size_t>(0, w.primary.size(), kBlock), [&](auto r) {
        RTCIntersectContext ctx;
        rtcInitIntersectContext(&ctx);
        std::size_t local = 0;
        for (std::size_t i = r.begin(); i < r.end(); i += 8) {
            alignas(32) RTCRayHit8 rh{};
            alignas(32) int valid[8];
            for (int j = 0; j < 8; ++j) {
                valid[j] = i + j < r.end() ? -1 : 0;
                const auto& ray = w.primary[std::min(i + j, r.end() - 1)];
                rh.ray.org_x[j] = ray.o.x, rh.ray.org_y[j] = ray.o.y, rh.ray.org_z[j] = ray.o.z;
                rh.ray.dir_x[j] = ray.d.x, rh.ray.dir_y[j] = ray.d.y, rh.ray.dir_z[j] = ray.d.z;
                rh.ray.tnear[j] = 0.0f;
                rh.ray.tfar[j] = std::numeric_limits<float>::infinity();
                rh.ray.mask[j] = ~0u;
                rh.hit.geomID[j] = RTC_INVALID_GEOMETRY_ID;
            }
            rtcIntersect8(valid, w.embree, &ctx, &rh);
            for (int j = 0; j < 8; ++j) local += valid[j] && rh.hit.geomID[j] != RTC_INVALID_GEOMETRY_ID;
        }
        hits += local;
    });
    return hits;
}

std::size_t embreeShadow8(const Workload& w) {
    std::atomic<std::size_t> blocked{0};
    tbb::parallel_for(tbb::blocked_range<std::size_t>(0, w.shadow.size(), kBlock), [&](auto r) {
        RTCIntersectContext ctx;
        rtcInitIntersectContext(&ctx);
        std::size_t local = 0;
        for (std::size_t i = r.begin(); i < r.end(); i += 8) {
            alignas(32) RTCRay8 rr{};
            alignas(32) int valid[8];
            for (int j = 0; j < 8; ++j) {
                valid[j] = i + j < r.end() ? -1 : 0;
                const auto& ray = w.shadow[std::min(i + j, r.end() - 1)];
                rr.org_x[j] = ray.o.x, rr.org_y[j] = ray.o.y, rr.org_z[j] = ray.o.z;
                rr.dir_x[j] = ray.d.x, rr.dir_y[j] = ray.d.y, rr.dir_z[j] = ray.d.z;
                rr.tnear[j] = 0.0f;
                rr.tfar[j] = std::numeric_limits<float>::infinity();
                rr.mask[j] = ~0u;
            }
            rtcOccluded8(valid, w.embree, &ctx, &rr);
            for (int j = 0; j < 8; ++j) local += valid[j] && rr.tfar[j] < 0;
        }
        blocked += local;
    });
    return blocked;
}

std::size_t embreeShadow(const Workload& w) {
    std::atomic<std::size_t> blocked{0};
    tbb::parallel_for(tbb::blocked_range<std::size_t>(0, w.shadow.size(), kBlock), [&](auto r) {
        RTCIntersectContext ctx;
        rtcInitIntersectContext(&ctx);
        std::size_t local = 0;
        for (std::size_t i = r.begin(); i != r.end(); ++i) {
            const auto& ray = w.shadow[i];
            RTCRay rr{};
            rr.org_x = ray.o.x, rr.org_y = ray.o.y, rr.org_z = ray.o.z;
            rr.dir_x = ray.d.x, rr.dir_y = ray.d.y, rr.dir_z = ray.d.z;
            rr.tnear = 0.0f;
            rr.tfar = std::numeric_limits<float>::infinity();
            rr.mask = ~0u;
            rtcOccluded1(w.embree, &ctx, &rr);
            local += rr.tfar < 0;
        }
        blocked += local;
    });
    return blocked;
}
#endif

std::size_t ourPrimary(const Workload& w, const raytrace::Tracer<Real>* tracer = nullptr) {
    if (!tracer) tracer = w.tracer.get();
    std::atomic<std::size_t> hits{0};
    tbb::parallel_for(tbb::blocked_range<std::size_t>(0, w.primary.size(), kBlock), [&](auto r) {
        std::size_t local = 0;
        for (std::size_t i = r.begin(); i != r.end(); ++i) {
            raytrace::Hit<Real> h;
            local += tracer->closestHit(w.primary[i], std::numeric_limits<Real>::infinity(), false, h);
        }
        hits += local;
    });
    return hits;
}

std::size_t ourShadow(const Workload& w, bool conservative, const raytrace::Tracer<Real>* tracer = nullptr) {
    if (!tracer) tracer = w.tracer.get();
    std::atomic<std::size_t> blocked{0};
    tbb::parallel_for(tbb::blocked_range<std::size_t>(0, w.shadow.size(), kBlock), [&](auto r) {
        std::size_t local = 0;
        for (std::size_t i = r.begin(); i != r.end(); ++i) {
            int b;
            local += tracer->anyHit(w.shadow[i], std::numeric_limits<Real>::infinity(), conservative, b);
        }
        blocked += local;
    });
    return blocked;
}

// Runs fn with the AVX box test and the occluder cache switched as asked, then back on.
template <typename Fn>
std::size_t variant(bool avx, bool cache, Fn fn) {
    raytrace::detail::setUseAvx(avx);
    raytrace::setOccluderCache(cache);
    const std::size_t n = fn();
    raytrace::detail::setUseAvx(true);
    raytrace::setOccluderCache(true);
    return n;
}

// Exact closest-hit ties on a scene of one mesh placed once (Sponza, the terrain): primary rays
// whose nearest t is met by two or more triangles (the float watertight test, as the tracer
// runs it), found with a tree of its own over every triangle, walked with tMax the next float
// above the tracer's t and a leaf that records every triangle hit at exactly that t. For each
// such ray the shadow answer (faces the light? blocked?) is worked out from every tied
// triangle as makeRays does from the reported one: the tie rule can change the triangle id
// of those pixels only, and the shadow mask only where the tied triangles disagree.
void countTies(const Workload& w) {
    if (w.scene.objects.size() != 1) return;
    const auto* mesh = std::get_if<scene::Mesh>(&w.scene.objects[0].shape);
    if (!mesh || mesh->instances.size() != 1) return;
    const scene::MeshInstance& inst = mesh->instances[0];
    const scene::TriangleMesh& g = *inst.geometry;
    const std::size_t n = g.triangleCount();
    std::vector<V> p(g.positions.size());
    for (std::size_t i = 0; i < p.size(); ++i) {
        const scene::Vec3 q = scene::transformPoint(inst.transform, g.positions[i]);
        p[i] = V(Real(q.x), Real(q.y), Real(q.z));
    }
    std::vector<scene::Bounds> bounds(n);
    for (std::size_t t = 0; t < n; ++t) {
        scene::Bounds b;
        for (int k = 0; k < 3; ++k) b.extend(scene::Vec3(p[g.indices[3 * t + k]]));
        bounds[t] = b;
    }
    const raytrace::Bvh8 bvh = raytrace::Bvh8::build(bounds);
    scene::RaytraceSettings robust;
    robust.robustOffset = true;
    const V l(-w.scene.lights.at(0).direction);
    std::size_t hits = 0, tied = 0, idFromLowest = 0, maskDiffers = 0, facingDiffers = 0, refAgrees = 0, most = 0;
    const raytrace::Tracer<double> reference(w.scene);
    scene::Camera cam = w.scene.camera;
    cam.width = kWidth;
    cam.height = kHeight;
    const scene::CameraBasis basis = scene::cameraBasis(cam);
    for (const auto& ray : w.primary) {
        raytrace::Hit<Real> h;
        if (!w.tracer->closestHit(ray, std::numeric_limits<Real>::infinity(), false, h)) continue;
        ++hits;
        Real bound = std::nextafter(h.t, std::numeric_limits<Real>::infinity());
        std::vector<raytrace::Hit<Real>> same;
        bvh.traverse(ray, bound, false, [&](std::uint32_t first, std::uint32_t count, Real&) {
            for (std::uint32_t s = first; s < first + count; ++s) {
                const std::uint32_t t = bvh.primitives()[s];
                if (t == raytrace::WideRef::kEmpty) continue;
                raytrace::Hit<Real> c = h;
                if (raytrace::intersectTriangle(ray, p[g.indices[3 * t]], p[g.indices[3 * t + 1]],
                                                p[g.indices[3 * t + 2]], bound, false, c.t, c.b0, c.b1, c.b2) &&
                    c.t == h.t) {
                    c.prim = int(t);
                    same.push_back(c);
                }
            }
            return false;
        });
        if (same.size() < 2) continue;
        ++tied;
        most = std::max(most, same.size());
        int lowest = same[0].prim;
        for (const auto& c : same) lowest = std::min(lowest, c.prim);
        idFromLowest += h.prim == lowest;
        // -1: faces away from the light; 0: lit; 1: blocked.
        auto answerOf = [&](const raytrace::Hit<Real>& c) {
            const raytrace::SurfacePoint<Real> sp = w.tracer->surfacePoint(ray, c, true);
            if (glm::dot(sp.ns, l) <= 0) return -1;
            int blocker;
            return int(w.tracer->anyHit(raytrace::Ray<Real>(raytrace::shadowOrigin(sp, l, robust), l),
                                        std::numeric_limits<Real>::infinity(), false, blocker));
        };
        const int reported = answerOf(h);
        bool differs = false, facing = false;
        for (const auto& c : same) {
            const int a = answerOf(c);
            differs = differs || a != reported;
            facing = facing || (a == -1) != (reported == -1);
        }
        maskDiffers += differs;
        facingDiffers += facing;
        if (!differs) continue;
        // What the double reference answers there: its own ray through the same pixel center.
        const std::size_t i = std::size_t(&ray - w.primary.data());
        const raytrace::Ray<double> rd(basis.position, scene::pixelDirection(basis, int(i % kWidth), int(i / kWidth)));
        raytrace::Hit<double> hd;
        int refAnswer = -1;
        if (reference.closestHit(rd, std::numeric_limits<double>::infinity(), true, hd)) {
            const raytrace::SurfacePoint<double> sp = reference.surfacePoint(rd, hd, true);
            const scene::Vec3 ld = -w.scene.lights.at(0).direction;
            if (glm::dot(sp.ns, ld) > 0) {
                int blocker;
                refAnswer = int(reference.anyHit(raytrace::Ray<double>(raytrace::shadowOrigin(sp, ld, robust), ld),
                                                 std::numeric_limits<double>::infinity(), true, blocker));
            }
        }
        refAgrees += refAnswer == reported;
        std::printf("%-8s tie at pixel (%zu, %zu): triangles", w.name.c_str(), i % kWidth, i / kWidth);
        for (const auto& c : same) std::printf(" %d -> %d", c.prim, answerOf(c));
        std::printf(" (reported %d; the double reference: triangle %d -> %d)\n", h.prim, hd.prim, refAnswer);
    }
    std::printf(
        "%-8s exact closest-hit ties: %zu of %zu primary hits (%zu reported the lowest index; at most "
        "%zu triangles at one t); the shadow answer (-1 faces away, 0 lit, 1 blocked) differs between "
        "the tied triangles on %zu (the facing test on %zu); the double reference agrees with the "
        "reported triangle on %zu of those\n",
        w.name.c_str(), tied, hits, idFromLowest, most, maskDiffers, facingDiffers, refAgrees);
}

// Collects items/s of every repetition per benchmark name while printing the usual table, so
// the summary can give the median and the spread (run with --benchmark_repetitions=N and
// --benchmark_enable_random_interleaving=true to spread a busy machine's load over all cases).
class RatioReporter : public benchmark::ConsoleReporter {
public:
    std::map<std::string, std::vector<double>> itemsPerSecond;
    void ReportRuns(const std::vector<Run>& runs) override {
        for (const Run& r : runs) {
            if (r.run_type != Run::RT_Iteration) continue;
            const auto it = r.counters.find("items_per_second");
            // Keyed by the registered name, without the "/min_time:.../real_time" suffixes.
            if (it != r.counters.end()) itemsPerSecond[r.run_name.function_name].push_back(it->second);
        }
        ConsoleReporter::ReportRuns(runs);
    }
    // Median, min and max in Mrays/s; zeros when the case did not run.
    std::array<double, 3> stats(const std::string& name) {
        std::vector<double> v = itemsPerSecond[name];
        if (v.empty()) return {0, 0, 0};
        std::sort(v.begin(), v.end());
        const std::size_t n = v.size();
        const double median = n % 2 ? v[n / 2] : 0.5 * (v[n / 2 - 1] + v[n / 2]);
        return {median / 1e6, v.front() / 1e6, v.back() / 1e6};
    }
};

}  // namespace

int main(int argc, char** argv) {
    benchmark::Initialize(&argc, argv);
    std::vector<std::unique_ptr<Workload>> workloads;

    auto add = [&](const std::string& name, scene::Scene s) {
        auto w = std::make_unique<Workload>();
        w->name = name;
        w->scene = std::move(s);
        const auto t0 = std::chrono::steady_clock::now();
        w->tracer = std::make_unique<raytrace::Tracer<Real>>(w->scene);
        w->ourSetupMs = msSince(t0);
        raytrace::detail::setFastFloatBuild(false);
        w->refTree = std::make_unique<raytrace::Tracer<Real>>(w->scene);
        raytrace::detail::setFastFloatBuild(true);
        makeRays(*w);
#ifdef SHADOWLAB_HAVE_EMBREE
        buildEmbree(*w);
#endif
        workloads.push_back(std::move(w));
    };
    // SHADOWLAB_BENCH_SCENES: a comma list of seed, sponza, terrain (default all three);
    // SHADOWLAB_BENCH_TERRAIN_TRIS: the terrain's size (two triangles per cell, rounded).
    const char* only = std::getenv("SHADOWLAB_BENCH_SCENES");
    auto wanted = [&](const char* name) { return !only || !*only || std::strstr(only, name) != nullptr; };
    if (wanted("seed")) add("seed", scene::loadScene(scene::findScene("seed")));
    const char* env = std::getenv("SHADOWLAB_SPONZA");
    const std::string sponza = env && *env ? env : kDefaultSponzaPath;
    const char* kSponzaPath = sponza.c_str();
    if (!wanted("sponza")) {
    } else if (std::filesystem::exists(kSponzaPath)) {
        scene::Scene s;
        s.file = kSponzaPath;
        s.camera.position = {-11, 1.5, -0.5};
        s.camera.lookAt = {5, 4, 0.5};
        s.camera.fovYDegrees = 60;
        scene::Light sun;
        sun.direction = glm::normalize(scene::Vec3(0.15, -1, 0.1));
        s.lights.push_back(sun);
        s.materials.push_back(scene::Material{"matte"});
        scene::Object o;
        o.name = "sponza";
        o.shape = scene::Mesh::single(kSponzaPath, scene::loadMesh(kSponzaPath, glm::dmat4(1.0), kSponzaPath, {}));
        s.objects.push_back(o);
        add("sponza", std::move(s));
    } else {
        std::printf(
            "Sponza: %s is absent (set SHADOWLAB_SPONZA to its .gltf); only the seed "
            "scene is measured.\n",
            kSponzaPath);
    }
    if (wanted("terrain")) {
        const int tris = envInt("SHADOWLAB_BENCH_TERRAIN_TRIS", 2 * bench::kTerrainCells * bench::kTerrainCells);
        add("terrain", bench::terrainScene(bench::terrainCellsFor(tris)));
    }
#ifndef SHADOWLAB_HAVE_EMBREE
    std::printf("Embree 3 was not found at configure time: our tracer is measured alone.\n");
#endif

    for (const auto& wp : workloads) {
        const Workload* w = wp.get();
        auto reg = [&](const std::string& n, std::size_t count, auto fn) {
            benchmark::RegisterBenchmark((w->name + "/" + n).c_str(),
                                         [w, count, fn](benchmark::State& st) {
                                             for (auto _ : st) benchmark::DoNotOptimize(fn(*w));
                                             st.SetItemsProcessed(std::int64_t(st.iterations()) * std::int64_t(count));
                                         })
                ->Unit(benchmark::kMillisecond)
                ->MeasureProcessCPUTime()
                ->MinTime(0.5);
        };
        reg("primary/ours", w->primary.size(), [](const Workload& x) { return ourPrimary(x); });
        reg("shadow/ours", w->shadow.size(), [](const Workload& x) { return ourShadow(x, false); });
        reg("shadow/ours_conservative", w->shadow.size(), [](const Workload& x) { return ourShadow(x, true); });
        // The same walk without the AVX box test and/or the occluder cache, for the record.
        reg("primary/ours_sse", w->primary.size(),
            [](const Workload& x) { return variant(false, true, [&] { return ourPrimary(x); }); });
        reg("shadow/ours_nocache", w->shadow.size(),
            [](const Workload& x) { return variant(true, false, [&] { return ourShadow(x, false); }); });
        reg("primary/ours_reftree", w->primary.size(),
            [](const Workload& x) { return ourPrimary(x, x.refTree.get()); });
        reg("shadow/ours_nocache_reftree", w->shadow.size(), [](const Workload& x) {
            return variant(true, false, [&] { return ourShadow(x, false, x.refTree.get()); });
        });
        reg("shadow/ours_sse_nocache", w->shadow.size(),
            [](const Workload& x) { return variant(false, false, [&] { return ourShadow(x, false); }); });
#ifdef SHADOWLAB_HAVE_EMBREE
        reg("primary/embree", w->primary.size(), [](const Workload& x) { return embreePrimary(x); });
        reg("shadow/embree", w->shadow.size(), [](const Workload& x) { return embreeShadow(x); });
        reg("primary/embree8", w->primary.size(), [](const Workload& x) { return embreePrimary8(x); });
        reg("shadow/embree8", w->shadow.size(), [](const Workload& x) { return embreeShadow8(x); });
#endif
    }
    RatioReporter reporter;
    benchmark::RunSpecifiedBenchmarks(&reporter);

    std::printf(
        "\nMrays/s: median (min-max) over the repetitions; ratio = ours / Embree medians "
        "(embree: rtcIntersect1/rtcOccluded1, embree8: rtcIntersect8/rtcOccluded8)\n");
    std::printf("%-8s %-22s %8s %20s %20s %7s %20s %7s %s\n", "scene", "rays", "count", "ours", "embree", "ratio",
                "embree8", "ratio8", "agreement");
    for (const auto& wp : workloads) {
        const Workload& w = *wp;
        const std::vector<std::pair<const char*, const char*>> rows = {{"primary", "ours"},
                                                                       {"primary", "ours_sse"},
                                                                       {"shadow", "ours"},
                                                                       {"shadow", "ours_nocache"},
                                                                       {"shadow", "ours_sse_nocache"},
                                                                       {"primary", "ours_reftree"},
                                                                       {"shadow", "ours_nocache_reftree"}};
        for (const auto& [kind, who] : rows) {
            const bool prim = std::string(kind) == "primary";
            const std::size_t count = prim ? w.primary.size() : w.shadow.size();
            const auto ours = reporter.stats(w.name + "/" + kind + "/" + who);
            char oursText[64];
            std::snprintf(oursText, sizeof oursText, "%.2f (%.2f-%.2f)", ours[0], ours[1], ours[2]);
            const bool avx = std::string(who).find("sse") == std::string::npos;
            const bool cache = std::string(who).find("nocache") == std::string::npos;
            const raytrace::Tracer<Real>* tr =
                std::string(who).find("reftree") != std::string::npos ? w.refTree.get() : w.tracer.get();
            const std::size_t a =
                variant(avx, cache, [&] { return prim ? ourPrimary(w, tr) : ourShadow(w, false, tr); });
            const std::string label = std::string(kind) + "/" + who;
#ifdef SHADOWLAB_HAVE_EMBREE
            const auto emb = reporter.stats(w.name + "/" + kind + "/embree");
            char embText[64];
            std::snprintf(embText, sizeof embText, "%.2f (%.2f-%.2f)", emb[0], emb[1], emb[2]);
            const auto emb8 = reporter.stats(w.name + "/" + kind + "/embree8");
            char emb8Text[64];
            std::snprintf(emb8Text, sizeof emb8Text, "%.2f (%.2f-%.2f)", emb8[0], emb8[1], emb8[2]);
            const std::size_t b = prim ? embreePrimary(w) : embreeShadow(w);
            const std::size_t b8 = prim ? embreePrimary8(w) : embreeShadow8(w);
            std::printf("%-8s %-22s %8zu %20s %20s %7.3f %20s %7.3f hits ours %zu, embree %zu, embree8 %zu\n",
                        w.name.c_str(), label.c_str(), count, oursText, embText, emb[0] > 0 ? ours[0] / emb[0] : 0.0,
                        emb8Text, emb8[0] > 0 ? ours[0] / emb8[0] : 0.0, a, b, b8);
#else
            std::printf("%-8s %-22s %8zu %20s %20s %7s hits ours %zu\n", w.name.c_str(), label.c_str(), count, oursText,
                        "-", "-", a);
#endif
        }
        // Our setup (conversion, BVH build, collapse, packets) and Embree's (flattening,
        // conversion, rtcCommitScene), alternating, process CPU time and wall time of each.
        const int reps = envInt("SHADOWLAB_BENCH_SETUP_REPS", 5);
        std::vector<double> oursCpu, oursWall, embCpu, embWall, refCpu;
        for (int i = 0; i < reps && w.tracer->triangleCount() > 0; ++i) {
            double c0 = cpuMs();
            auto t0 = std::chrono::steady_clock::now();
            { const raytrace::Tracer<Real> t(w.scene); }
            oursCpu.push_back(cpuMs() - c0);
            oursWall.push_back(msSince(t0));
            raytrace::detail::setFastFloatBuild(false);
            c0 = cpuMs();
            { const raytrace::Tracer<Real> t(w.scene); }
            refCpu.push_back(cpuMs() - c0);
            raytrace::detail::setFastFloatBuild(true);
#ifdef SHADOWLAB_HAVE_EMBREE
            c0 = cpuMs();
            t0 = std::chrono::steady_clock::now();
            const EmbreeScene e = embreeBuild(w.scene);
            rtcReleaseScene(e.scene);
            rtcReleaseDevice(e.device);
            embCpu.push_back(cpuMs() - c0);
            embWall.push_back(msSince(t0));
#endif
        }
        const auto oc = medianMinMax(oursCpu), ow = medianMinMax(oursWall);
        const auto ec = medianMinMax(embCpu), ew = medianMinMax(embWall);
        const auto rc = medianMinMax(refCpu);
        if (!refCpu.empty())
            std::printf("%-8s setup with the reference's (double) build, CPU ms: %.1f (%.1f-%.1f), / embree %.2f\n",
                        w.name.c_str(), rc[0], rc[1], rc[2], ec[0] > 0 ? rc[0] / ec[0] : 0.0);
        const std::size_t tris = w.tracer->uniqueTriangleCount();
        const double oursBpt = tris > 0 ? double(w.tracer->meshBytes()) / double(tris) : 0.0;
        double embBpt = 0;
#ifdef SHADOWLAB_HAVE_EMBREE
        embBpt = tris > 0 ? double(w.embreeBytes) / double(tris) : 0.0;
#endif
        if (!oursCpu.empty()) {
            std::printf(
                "%-8s setup, %d alternating builds, CPU ms median (min-max): ours %.1f (%.1f-%.1f), "
                "embree %.1f (%.1f-%.1f), ratio %.2f; wall ms: ours %.1f (%.1f-%.1f), embree %.1f "
                "(%.1f-%.1f), ratio %.2f\n",
                w.name.c_str(), reps, oc[0], oc[1], oc[2], ec[0], ec[1], ec[2], ec[0] > 0 ? oc[0] / ec[0] : 0.0, ow[0],
                ow[1], ow[2], ew[0], ew[1], ew[2], ew[0] > 0 ? ow[0] / ew[0] : 0.0);
        }
        std::printf(
            "%-8s %zu triangles: BVH + mesh %.1f bytes/triangle ours, %.1f embree (device bytes after "
            "the build)\n",
            w.name.c_str(), tris, oursBpt, embBpt);
        // A fingerprint of every answer (primary: object, triangle, t and barycentric bits;
        // shadow: blocked or not), to show that two builds of the bench give the same hits.
        auto fingerprint = [&](const raytrace::Tracer<Real>& tracer) {
            std::uint64_t fp = 1469598103934665603ull;
            auto mix = [&](std::uint64_t v) { fp = (fp ^ v) * 1099511628211ull; };
            for (const auto& ray : w.primary) {
                raytrace::Hit<Real> h;
                const bool hit = tracer.closestHit(ray, std::numeric_limits<Real>::infinity(), false, h);
                mix(hit);
                if (!hit) continue;
                std::uint32_t tb, bb;
                std::memcpy(&tb, &h.t, 4);
                std::memcpy(&bb, &h.b1, 4);
                mix(std::uint64_t(h.object) << 32 | std::uint32_t(h.prim));
                mix(std::uint64_t(tb) << 32 | bb);
            }
            raytrace::setOccluderCache(false);
            for (const auto& ray : w.shadow) {
                int blocker = -1;
                mix(tracer.anyHit(ray, std::numeric_limits<Real>::infinity(), false, blocker));
                mix(std::uint64_t(blocker + 1));
            }
            raytrace::setOccluderCache(true);
            return fp;
        };
        std::printf("%-8s hits fingerprint %016llx, on the reference's trees %016llx\n", w.name.c_str(),
                    (unsigned long long)fingerprint(*w.tracer), (unsigned long long)fingerprint(*w.refTree));
        if (std::getenv("SHADOWLAB_BENCH_TIES")) countTies(w);
        std::printf(
            "SCALE | %s | %zu | setup cpu ms ours %.1f embree %.1f | bytes/tri ours %.1f embree %.1f | "
            "primary Mrays/s ours %.2f embree %.2f embree8 %.2f reftree %.2f | shadow(no cache) ours %.2f embree %.2f "
            "embree8 %.2f reftree %.2f | setup cpu ms reftree %.1f\n",
            w.name.c_str(), tris, oc[0], ec[0], oursBpt, embBpt, reporter.stats(w.name + "/primary/ours")[0],
            reporter.stats(w.name + "/primary/embree")[0], reporter.stats(w.name + "/primary/embree8")[0],
            reporter.stats(w.name + "/primary/ours_reftree")[0], reporter.stats(w.name + "/shadow/ours_nocache")[0],
            reporter.stats(w.name + "/shadow/embree")[0], reporter.stats(w.name + "/shadow/embree8")[0],
            reporter.stats(w.name + "/shadow/ours_nocache_reftree")[0], rc[0]);
    }
#ifdef SHADOWLAB_HAVE_EMBREE
    for (auto& wp : workloads) {
        rtcReleaseScene(wp->embree);
        rtcReleaseDevice(wp->device);
    }
#endif
    benchmark::Shutdown();
    return 0;
}
