// scene/scene.cpp: bounds and small queries on the scene model.
#include "scene/scene.h"

#include <algorithm>
#include <cmath>

namespace shadowlab::scene {

double Bounds::maxAbsCoordinate() const {
    if (empty()) return 0.0;
    const Vec3 a = glm::max(glm::abs(min), glm::abs(max));
    return std::max({a.x, a.y, a.z});
}

void quadAxes(const Vec3& normal, Vec3& uAxis, Vec3& vAxis) {
    // Project world X onto the plane; if the normal is nearly X, project world Z instead.
    const Vec3 ref = std::abs(normal.x) > 0.9 ? Vec3(0, 0, 1) : Vec3(1, 0, 0);
    uAxis = glm::normalize(ref - glm::dot(ref, normal) * normal);
    vAxis = glm::cross(normal, uAxis);
}

Bounds boundsOf(const Shape& shape) {
    Bounds b;
    if (const auto* s = std::get_if<Sphere>(&shape)) {
        b.extend(s->center - Vec3(s->radius));
        b.extend(s->center + Vec3(s->radius));
    } else if (const auto* q = std::get_if<Quad>(&shape)) {
        const Vec3 du = 0.5 * q->size.x * q->uAxis;
        const Vec3 dv = 0.5 * q->size.y * q->vAxis;
        for (double su : {-1.0, 1.0})
            for (double sv : {-1.0, 1.0}) b.extend(q->center + su * du + sv * dv);
    } else if (const auto* box = std::get_if<Box>(&shape)) {
        b.extend(box->min);
        b.extend(box->max);
    } else if (const auto* m = std::get_if<Mesh>(&shape)) {
        for (const MeshInstance& inst : m->instances)
            if (inst.geometry)
                for (const Vec3& p : inst.geometry->positions) b.extend(transformPoint(inst.transform, p));
    }
    return b;
}

std::size_t Mesh::triangleCount() const {
    std::size_t n = 0;
    for (const MeshInstance& inst : instances)
        if (inst.geometry) n += inst.geometry->triangleCount();
    return n;
}

bool Scene::allOpaque() const {
    for (const Object& o : objects)
        if (!materialOf(o).opaque()) return false;
    return true;
}

bool Material::alphaCanFallBelow(double cutoff) const {
    // The loaders keep the factor and texels in [0, 1]; outside it (a scene made in code) a
    // negative factor turns the largest texel into the smallest product: no claim then.
    if (!(alphaFactor >= 0.0 && alphaFactor <= 1.0)) return true;
    float lowest = 1.0f;  // the texture's alpha (1 without one)
    if (alphaTextured()) {
        if (alphaTexture->alpha.empty()) return true;
        lowest = *std::min_element(alphaTexture->alpha.begin(), alphaTexture->alpha.end());
    }
    // Rounding is monotonic, so the smallest texel gives the smallest product in either precision.
    return float(alphaFactor) * lowest < float(cutoff) || alphaFactor * double(lowest) < cutoff;
}

Bounds Scene::bounds() const {
    Bounds b;
    for (const Object& o : objects) b.extend(boundsOf(o.shape));
    return b;
}

ShadowDefaults ShadowDefaults::overriddenBy(const ShadowDefaults& over) const {
    ShadowDefaults out = *this;
    auto take = [](auto& into, const auto& from) {
        if (from) into = from;
    };
    take(out.shadowMapSize, over.shadowMapSize);
    take(out.depthBias, over.depthBias);
    take(out.slopeBias, over.slopeBias);
    take(out.filter, over.filter);
    take(out.pcfSize, over.pcfSize);
    take(out.minVariance, over.minVariance);
    take(out.bleedReduction, over.bleedReduction);
    take(out.evsmPositive, over.evsmPositive);
    take(out.evsmNegative, over.evsmNegative);
    take(out.esmExponent, over.esmExponent);
    take(out.momentBias, over.momentBias);
    take(out.blurWidth, over.blurWidth);
    take(out.normalOffset, over.normalOffset);
    take(out.receiverPlaneBias, over.receiverPlaneBias);
    take(out.hardwareBias, over.hardwareBias);
    take(out.fitLightFrustum, over.fitLightFrustum);
    take(out.cascades, over.cascades);
    take(out.cascadeBlend, over.cascadeBlend);
    if (over.rayBias || over.robustRayOffset) {
        out.rayBias = over.rayBias;
        out.robustRayOffset = over.robustRayOffset;
    }
    take(out.precision, over.precision);
    take(out.samples, over.samples);
    return out;
}

}  // namespace shadowlab::scene
