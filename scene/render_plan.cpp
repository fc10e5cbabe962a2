// scene/render_plan.cpp: decides what each render leaves out, with the reason for each choice.
#include "scene/render_plan.h"

#include <algorithm>
#include <cmath>
#include <sstream>

namespace shadowlab::scene {

namespace {

bool isConvex(const Shape& shape) {
    return std::holds_alternative<Sphere>(shape) || std::holds_alternative<Box>(shape) ||
           std::holds_alternative<Quad>(shape);
}

// Whether a spot light's cone can reach any part of `b`: the box's bounding sphere (center c,
// radius R) meets the infinite one-sided cone from the apex with half-angle α when c is within R
// of the apex, or when the angle between the axis and the direction to c is at most α + asin(R/|c|)
// (the sphere's angular radius seen from the apex). Conservative: a box's sphere is larger than
// the box.
bool coneReaches(const Light& spot, const Bounds& b) {
    if (b.empty()) return false;
    constexpr double kPi = 3.14159265358979323846;
    const Vec3 v = b.center() - spot.position;
    const double d = glm::length(v);
    const double radius = 0.5 * b.diagonal();
    if (d <= radius) return true;
    const double cosAngle = std::clamp(glm::dot(v, glm::normalize(spot.direction)) / d, -1.0, 1.0);
    const double reach = spot.coneAngleDegrees * kPi / 180.0 + std::asin(std::min(radius / d, 1.0));
    return reach >= kPi || std::acos(cosAngle) <= reach;
}

}  // namespace

RenderPlan makeRenderPlan(const Scene& scene, const RenderSettings& settings) {
    RenderPlan plan;
    plan.anyHitShadowRays = scene.allOpaque();
    for (const Object& o : scene.objects)
        if (std::holds_alternative<Mesh>(o.shape)) plan.needsTriangleBvh = true;
    for (const Object& o : scene.objects)
        if (!scene.materialOf(o).opaque()) plan.needsTransmittanceMap = true;

    // A convex object never shadows its own lit points (a ray leaving a convex surface with
    // N·L > 0 cannot re-enter it), so a scene of one convex object needs no shadow test at all.
    const bool canShadow = scene.objects.size() > 1 || (scene.objects.size() == 1 && !isConvex(scene.objects[0].shape));
    for (std::size_t i = 0; i < scene.lights.size(); ++i) {
        const Light& light = scene.lights[i];
        LightPlan lp;
        lp.light = int(i);
        lp.needsShadowTest = canShadow;
        lp.reason = canShadow ? "objects can cast shadows"
                              : (scene.objects.empty() ? "the scene has no objects"
                                                       : "a single convex object cannot shadow itself");
        if (canShadow && light.type == LightType::Spot) {
            // A spot lights only what its cone holds, and a blocker must lie on the segment from
            // a lit point to the apex, which the (convex) cone also holds: with nothing in the
            // cone, or one convex object alone, its map would shadow nothing.
            std::vector<const Object*> inCone;
            for (const Object& o : scene.objects)
                if (coneReaches(light, boundsOf(o.shape))) inCone.push_back(&o);
            if (inCone.empty()) {
                lp.needsShadowTest = false;
                lp.reason = "no object inside the spot's cone";
            } else if (inCone.size() == 1 && isConvex(inCone[0]->shape)) {
                lp.needsShadowTest = false;
                lp.reason = "only one convex object inside the spot's cone, which cannot shadow itself";
            }
        }
        if (light.type == LightType::Point && lp.needsShadowTest) plan.needsCubeMap = true;
        if (light.radius > 0.0 && light.type != LightType::Directional) plan.hasAreaLights = true;
        plan.lights.push_back(lp);
    }

    // Cascades split a directional light's orthographic map along the view; spot and point maps
    // are perspective from the light already and are not split.
    bool shadowedDirectional = false;
    for (const LightPlan& lp : plan.lights)
        if (lp.needsShadowTest && scene.lights[std::size_t(lp.light)].type == LightType::Directional)
            shadowedDirectional = true;
    const int asked = settings.raster.cascades;
    if (asked <= 1 && settings.raster.cascadesIsDefault && shadowedDirectional) {
        plan.cascades = 1;
        plan.cascadesReason = "by default chosen per view by the raster backend: see 'raster cascades'";
    } else if (asked <= 1) {
        plan.cascades = 1;
        plan.cascadesReason = "one map per directional light (cascades = 1)";
    } else if (!shadowedDirectional) {
        plan.cascades = 1;
        plan.cascadesReason = "cascades = " + std::to_string(asked) +
                              " ignored: no shadowed directional light (only directional maps are split)";
    } else {
        plan.cascades = asked;
        plan.cascadesReason =
            std::to_string(asked) + " per directional light, split along the view depth of the visible receivers";
    }
    const double blend = settings.raster.cascadeBlend;
    std::ostringstream band;
    band << blend;
    if (blend <= 0.0) {
        plan.cascadeBlendReason = "off: each split switches cascades abruptly (cascade_blend = 0)";
    } else if (plan.cascades <= 1 && settings.raster.cascadesIsDefault && shadowedDirectional) {
        plan.cascadeBlendReason =
            "cascade_blend = " + band.str() + " applies if the raster backend splits the view (see 'raster cascades')";
    } else if (plan.cascades <= 1) {
        plan.cascadeBlendReason = "cascade_blend = " + band.str() + " ignored: no cascades";
    } else {
        plan.cascadeBlend = blend;
        plan.cascadeBlendReason =
            "the last " + band.str() + " of each slice but the last mixes its cascade's visibility with the next's";
    }
    return plan;
}

std::string RenderPlan::explain() const {
    std::ostringstream s;
    s << "shadow rays: "
      << (anyHitShadowRays ? "any-hit, stop at the first blocker (every material is opaque)"
                           : "go on to the light multiplying transmittances (semi-transparent materials)")
      << "\n";
    s << "triangle BVH: "
      << (needsTriangleBvh ? "built (the scene has meshes)"
                           : "not built (spheres, quads and boxes are intersected analytically)")
      << "\n";
    s << "point-light cube map: " << (needsCubeMap ? "needed" : "not needed (no shadowed point light)") << "\n";
    s << "transmittance map: "
      << (needsTransmittanceMap ? "needed (semi-transparent casters)" : "not needed (all casters opaque)") << "\n";
    s << "area lights: " << (hasAreaLights ? "yes, soft shadows are sampled" : "none, shadows are hard") << "\n";
    s << "cascades: " << cascades << " (" << cascadesReason << ")\n";
    s << "cascade blend: " << cascadeBlend << " (" << cascadeBlendReason << ")\n";
    for (const LightPlan& lp : lights)
        s << "light " << lp.light << ": shadow pass " << (lp.needsShadowTest ? "rendered" : "skipped") << " ("
          << lp.reason << ")\n";
    return s.str();
}

}  // namespace shadowlab::scene
