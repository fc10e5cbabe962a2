// scene/render_plan.h: what this scene needs, decided once from Scene + settings, so that
// each backend leaves out the work the scene does not need. `--explain` prints it.
#pragma once

#include <string>
#include <vector>

#include "scene/scene.h"
#include "scene/settings.h"

namespace shadowlab::scene {

struct LightPlan {
    int light = 0;                // index into Scene::lights
    bool needsShadowTest = true;  // false: no object can cast onto a lit receiver for this light
    std::string reason;           // why, in words
};

struct RenderPlan {
    // Shadow rays may stop at the first hit: every material is opaque.
    bool anyHitShadowRays = true;
    // A triangle BVH is built only when the scene has meshes; spheres, quads, boxes stay analytic.
    bool needsTriangleBvh = false;
    bool needsCubeMap = false;           // a point light is shadowed (raster)
    bool needsTransmittanceMap = false;  // semi-transparent casters (raster)
    bool hasAreaLights = false;
    // Cascaded shadow maps per shadowed directional light (raster): settings.raster.cascades, or 1
    // when more were asked for but no directional light is shadowed; cascadesReason says which.
    int cascades = 1;
    std::string cascadesReason;
    // The blend band before each split (settings.raster.cascadeBlend), 0 when off or without
    // cascades; cascadeBlendReason says which.
    double cascadeBlend = 0.0;
    std::string cascadeBlendReason;
    std::vector<LightPlan> lights;

    std::string explain() const;  // human-readable, one decision per line with its reason
};

RenderPlan makeRenderPlan(const Scene& scene, const RenderSettings& settings);

}  // namespace shadowlab::scene
