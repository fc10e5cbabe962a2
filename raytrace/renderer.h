// raytrace/renderer.h: the CPU ray tracer's entry points: the method (float or double, the
// lesson's bias or robust offsets) and the double-precision reference the method is judged by.
#pragma once

#include <memory>

#include "scene/frame.h"
#include "scene/render_plan.h"
#include "scene/scene.h"
#include "scene/settings.h"

namespace shadowlab::raytrace {

// One primary ray per pixel center, one shadow test per light (settings.samples rays for
// spherical lights), shaded per scene/shading.h. Fills every AOV including blockerId, the
// timings "setup", "primary", "shadow" and the attributes backend="raytrace", precision,
// ray_bias (value or "robust"), samples, threads, shadow_rays. Throws std::invalid_argument
// for a scene it cannot trace (a mesh without loaded geometry).
scene::Frame render(const scene::Scene& scene, const scene::RenderPlan& plan, const scene::RaytraceSettings& settings);

// The reference: render() with scene::referenceSettings(base) (double precision, robust
// offsets, no tunable bias, many area-light samples); backend attribute "reference".
scene::Frame renderReference(const scene::Scene& scene, const scene::RenderPlan& plan,
                             const scene::RaytraceSettings& base);

// The ray tracer with its acceleration structures built once (the constructor: the "setup"),
// for many frames of one scene's objects: render() takes the scene again, whose camera and lights
// may differ from frame to frame but whose objects must be the constructor's (the trees hold
// them). Frames from render() have "setup" 0; setupMs() is the build. With `reference`, the
// settings are scene::referenceSettings(settings) and frames say backend "reference".
class Renderer {
public:
    Renderer(const scene::Scene& scene, const scene::RaytraceSettings& settings, bool reference = false);
    ~Renderer();
    Renderer(Renderer&&) noexcept;
    Renderer& operator=(Renderer&&) noexcept;
    scene::Frame render(const scene::Scene& scene, const scene::RenderPlan& plan) const;
    double setupMs() const;

private:
    struct Impl;
    std::unique_ptr<Impl> impl_;
};

// Diagnostic/test entry: the shadow test at world point p with normal n (unit, the side the
// light should be on) for scene.lights[light], in precision Real, with the given offsets.
// Returns 0 when n·L <= 0, else the visibility in 0..1. Builds the tracer on every call: for
// many queries use Tracer and lightVisibility directly (raytrace/shadow_ray.h).
template <typename Real>
double visibilityAt(const scene::Scene& scene, const scene::Vec3& p, const scene::Vec3& n, int light,
                    const scene::RaytraceSettings& settings);

extern template double visibilityAt<float>(const scene::Scene&, const scene::Vec3&, const scene::Vec3&, int,
                                           const scene::RaytraceSettings&);
extern template double visibilityAt<double>(const scene::Scene&, const scene::Vec3&, const scene::Vec3&, int,
                                            const scene::RaytraceSettings&);

}  // namespace shadowlab::raytrace
