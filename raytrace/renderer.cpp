// raytrace/renderer.cpp: the two passes of a ray-traced frame (primary hits, then shadow rays
// and shading), run over 16x16 tiles with TBB and timed separately.
#include "raytrace/renderer.h"

#include <chrono>
#include <cmath>
#include <iomanip>
#include <limits>
#include <memory>
#include <optional>
#include <sstream>
#include <stdexcept>
#include <string>
#include <vector>

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>
#include <tbb/task_arena.h>

#include "raytrace/shadow_ray.h"
#include "raytrace/tolerances.h"
#include "raytrace/tracer.h"
#include "scene/camera.h"
#include "scene/shading.h"

namespace shadowlab::raytrace {

namespace {

using Clock = std::chrono::steady_clock;

double msSince(Clock::time_point start) {
    return std::chrono::duration<double, std::milli>(Clock::now() - start).count();
}

template <typename Real>
Vec3T<Real> toReal(const scene::Vec3& v) {
    return Vec3T<Real>(Real(v.x), Real(v.y), Real(v.z));
}

std::string formatNumber(double v) {
    std::ostringstream s;
    s << std::setprecision(9) << v;
    return s.str();
}

std::uint64_t sampleSeed(std::size_t pixel, int light) {
    return kSampleSeed ^ (std::uint64_t(pixel) * 0x9E3779B97F4A7C15ull) ^ (std::uint64_t(light + 1) << 48);
}

// With `prebuilt`, its acceleration structures are used and "setup" is 0 (Renderer).
template <typename Real>
scene::Frame renderT(const scene::Scene& scene, const scene::RenderPlan& plan, const scene::RaytraceSettings& settings,
                     scene::Backend backend, const Tracer<Real>* prebuilt = nullptr) {
    const scene::CameraBasis cam = scene::cameraBasis(scene.camera);
    const int width = cam.width, height = cam.height;
    scene::Frame frame = scene::Frame::allocate(width, height, true);
    frame.blockerDistance.assign(frame.pixelCount(), 0.0f);
    // The reference's blocker distance is the nearest blocker's (compare's bleeding test reads
    // it); the ray tracer's any-hit rays give the found blocker's, at no extra ray.
    const bool nearestDistance = backend == scene::Backend::Reference;
    // Per-light visibility only when it adds something: with one light it is `visibility`.
    if (scene.lights.size() > 1)
        frame.lightVisibility.assign(scene.lights.size(), std::vector<float>(frame.pixelCount(), 0.0f));
    tbb::task_arena arena(settings.threads > 0 ? settings.threads : tbb::task_arena::automatic);
    const bool robust = settings.robustOffset;
    // Semi-transparent objects need the whole segment; the plan allows any-hit otherwise.
    const bool anyHit = plan.anyHitShadowRays && scene.allOpaque();
    std::vector<bool> needsShadowTest(scene.lights.size(), true);
    for (const scene::LightPlan& lp : plan.lights)
        if (lp.light >= 0 && std::size_t(lp.light) < needsShadowTest.size())
            needsShadowTest[lp.light] = lp.needsShadowTest;

    const auto setupStart = Clock::now();
    std::optional<Tracer<Real>> own;
    if (!prebuilt) own.emplace(scene);
    const Tracer<Real>& tracer = prebuilt ? *prebuilt : *own;
    frame.timingsMs.emplace_back("setup", prebuilt ? 0.0 : msSince(setupStart));

    const int tilesX = (width + kTileSize - 1) / kTileSize;
    const int tilesY = (height + kTileSize - 1) / kTileSize;
    auto forEachPixel = [&](auto&& body) {
        arena.execute([&] {
            tbb::parallel_for(tbb::blocked_range<int>(0, tilesX * tilesY), [&](const tbb::blocked_range<int>& r) {
                for (int tile = r.begin(); tile != r.end(); ++tile) {
                    const int x0 = (tile % tilesX) * kTileSize;
                    const int y0 = (tile / tilesX) * kTileSize;
                    const int x1 = std::min(x0 + kTileSize, width);
                    const int y1 = std::min(y0 + kTileSize, height);
                    for (int y = y0; y < y1; ++y)
                        for (int x = x0; x < x1; ++x) body(x, y);
                }
            });
        });
    };

    // Pass 1: primary rays. The surface point (and its error bound) is kept for pass 2. The
    // camera is not on a surface, so primary rays need no conservative t test.
    const auto primaryStart = Clock::now();
    const std::size_t n = frame.pixelCount();
    std::vector<SurfacePoint<Real>> points(n);
    // The near and far planes clip what the camera sees, as the raster pipeline clips there
    // (view depth is t: a pixel direction's forward component is 1). Rays start on the near
    // plane only where some geometry may lie nearer, so no other scene's rays change.
    const scene::Bounds bounds = scene.bounds();
    const scene::Vec3 closest = glm::clamp(cam.position, bounds.min, bounds.max);
    const double tNear =
        !bounds.empty() && glm::length(closest - cam.position) < scene.camera.near ? scene.camera.near : 0.0;
    const Real tFar = Real(scene.camera.far - tNear);
    forEachPixel([&](int x, int y) {
        const std::size_t i = std::size_t(y) * width + x;
        const scene::Vec3 dir = scene::pixelDirection(cam, x, y);
        const Ray<Real> ray(toReal<Real>(cam.position + tNear * dir), toReal<Real>(dir));
        Hit<Real> hit;
        if (!tracer.closestHit(ray, tFar, false, hit)) {
            for (int c = 0; c < 3; ++c) frame.beauty[3 * i + c] = float(scene.background[c]);
            return;
        }
        points[i] = tracer.surfacePoint(ray, hit, robust);
        frame.objectId[i] = float(hit.object + 1);
        frame.depth[i] = float(glm::dot(scene::Vec3(points[i].p) - cam.position, cam.forward));
    });
    frame.timingsMs.emplace_back("primary", msSince(primaryStart));

    // Pass 2: shadow rays and shading (scene/shading.h).
    const auto shadowStart = Clock::now();
    forEachPixel([&](int x, int y) {
        const std::size_t i = std::size_t(y) * width + x;
        const SurfacePoint<Real>& sp = points[i];
        if (sp.object < 0) return;
        const scene::Material& mat = scene.materialOf(scene.objects[sp.object]);
        const scene::Vec3 p(sp.p);
        const scene::Vec3 ns(sp.ns);
        scene::Vec3 color = scene.ambient * mat.albedo;
        scene::RaytraceSettings pixelSettings = settings;
        if (!robust)
            pixelSettings.rayBias =
                scene::rayBiasAt(settings, double(frame.depth[i]), scene.camera.fovYDegrees, height);
        double weightSum = 0.0, weightedVisibility = 0.0;
        double maxNdotL = scene.lights.empty() ? 0.0 : -std::numeric_limits<double>::infinity();
        int blocker = 0;
        double blockerDistance = 0.0;
        for (std::size_t li = 0; li < scene.lights.size(); ++li) {
            const scene::Light& light = scene.lights[li];
            const scene::LightSample<scene::Vec3> ls = scene::sampleLight(light, p);
            const double ndotl = glm::dot(ns, ls.toLight);
            // Only lights that reach the point (lit.frag does the same): outside every spot's cone
            // ndotl is -1, so compare leaves the pixel out as it does a back face. Reaching is
            // geometric, as in lit.frag: a light of intensity 0 is still tested, with weight 0.
            maxNdotL = std::max(maxNdotL, ls.reaches ? ndotl : -1.0);
            if (!(ndotl > 0) || !ls.reaches) continue;  // visibility 0, weight 0
            double v = 1.0;
            if (needsShadowTest[li]) {
                Rng rng(sampleSeed(i, int(li)));
                const ShadowResult r = lightVisibility(tracer, light, sp, pixelSettings, anyHit, rng, nearestDistance);
                v = r.transmittance;
                if (blocker == 0 && r.blocker >= 0) {
                    blocker = r.blocker + 1;
                    blockerDistance = r.distance;
                }
            }
            if (!frame.lightVisibility.empty()) frame.lightVisibility[li][i] = float(v);
            // The visibility AOV weighs each light by what it would add unshadowed.
            const double w = ls.irradiance * ndotl * (light.color.r + light.color.g + light.color.b) / 3.0;
            weightSum += w;
            weightedVisibility += w * v;
            color += mat.albedo * light.color * (ls.irradiance * ndotl * v);
        }
        for (int c = 0; c < 3; ++c) frame.beauty[3 * i + c] = float(color[c]);
        frame.visibility[i] = weightSum > 0 ? float(weightedVisibility / weightSum) : 0.0f;
        frame.ndotl[i] = float(maxNdotL);
        frame.blockerId[i] = float(blocker);
        frame.blockerDistance[i] = float(blockerDistance);
    });
    frame.timingsMs.emplace_back("shadow", msSince(shadowStart));

    frame.attributes["backend"] = scene::toString(backend);
    frame.attributes["precision"] = scene::toString(settings.precision);
    frame.attributes["ray_bias"] = robust ? "robust" : formatNumber(settings.rayBias);
    if (!robust && settings.rayBiasPixels > 0) {
        // The default's view scaling: ray_bias is then the largest offset used.
        frame.attributes["ray_bias_pixels"] = formatNumber(settings.rayBiasPixels);
        frame.attributes["ray_bias_floor"] = formatNumber(settings.rayBiasFloor);
    }
    frame.attributes["samples"] = std::to_string(plan.hasAreaLights ? settings.samples : 1);
    frame.attributes["threads"] = std::to_string(arena.max_concurrency());
    frame.attributes["shadow_rays"] = anyHit ? "any-hit" : "closest-hit";
    frame.attributes["triangles"] = std::to_string(tracer.triangleCount());
    return frame;
}

scene::Frame renderWith(const scene::Scene& scene, const scene::RenderPlan& plan,
                        const scene::RaytraceSettings& settings, scene::Backend backend) {
    if (settings.precision == scene::Precision::Double) return renderT<double>(scene, plan, settings, backend);
    return renderT<float>(scene, plan, settings, backend);
}

}  // namespace

scene::Frame render(const scene::Scene& scene, const scene::RenderPlan& plan, const scene::RaytraceSettings& settings) {
    return renderWith(scene, plan, settings, scene::Backend::Raytrace);
}

scene::Frame renderReference(const scene::Scene& scene, const scene::RenderPlan& plan,
                             const scene::RaytraceSettings& base) {
    return renderWith(scene, plan, scene::referenceSettings(base), scene::Backend::Reference);
}

struct Renderer::Impl {
    scene::RaytraceSettings settings;
    scene::Backend backend = scene::Backend::Raytrace;
    std::unique_ptr<Tracer<float>> single;
    std::unique_ptr<Tracer<double>> twice;
    double setupMs = 0.0;
};

Renderer::Renderer(const scene::Scene& scene, const scene::RaytraceSettings& settings, bool reference)
    : impl_(std::make_unique<Impl>()) {
    impl_->settings = reference ? scene::referenceSettings(settings) : settings;
    impl_->backend = reference ? scene::Backend::Reference : scene::Backend::Raytrace;
    const auto start = Clock::now();
    if (impl_->settings.precision == scene::Precision::Double)
        impl_->twice = std::make_unique<Tracer<double>>(scene);
    else
        impl_->single = std::make_unique<Tracer<float>>(scene);
    impl_->setupMs = msSince(start);
}
Renderer::~Renderer() = default;
Renderer::Renderer(Renderer&&) noexcept = default;
Renderer& Renderer::operator=(Renderer&&) noexcept = default;

scene::Frame Renderer::render(const scene::Scene& scene, const scene::RenderPlan& plan) const {
    if (impl_->twice) return renderT<double>(scene, plan, impl_->settings, impl_->backend, impl_->twice.get());
    return renderT<float>(scene, plan, impl_->settings, impl_->backend, impl_->single.get());
}
double Renderer::setupMs() const { return impl_->setupMs; }

template <typename Real>
double visibilityAt(const scene::Scene& scene, const scene::Vec3& p, const scene::Vec3& n, int light,
                    const scene::RaytraceSettings& settings) {
    if (light < 0 || std::size_t(light) >= scene.lights.size())
        throw std::out_of_range("visibilityAt: light " + std::to_string(light) + " of " +
                                std::to_string(scene.lights.size()));
    const scene::Vec3 nUnit = glm::normalize(n);
    const scene::LightSample<scene::Vec3> ls = scene::sampleLight(scene.lights[light], p);
    if (!(glm::dot(nUnit, ls.toLight) > 0)) return 0.0;
    const Tracer<Real> tracer(scene);
    SurfacePoint<Real> sp;
    sp.p = toReal<Real>(p);
    sp.ng = sp.ns = toReal<Real>(nUnit);
    if (settings.robustOffset) {
        // The caller's point is on the surface up to the rounding of its own computation and
        // of the conversion to Real: one rounding relative to its magnitude.
        sp.pError = gamma<Real>(1) * glm::abs(sp.p);
        sp.errorAlongNormal = glm::dot(glm::abs(sp.ng), sp.pError);
    }
    Rng rng(kSampleSeed);
    return lightVisibility(tracer, scene.lights[light], sp, settings, scene.allOpaque(), rng).transmittance;
}

template double visibilityAt<float>(const scene::Scene&, const scene::Vec3&, const scene::Vec3&, int,
                                    const scene::RaytraceSettings&);
template double visibilityAt<double>(const scene::Scene&, const scene::Vec3&, const scene::Vec3&, int,
                                     const scene::RaytraceSettings&);

}  // namespace shadowlab::raytrace
