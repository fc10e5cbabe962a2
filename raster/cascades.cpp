// raster/cascades.cpp: split depths and the fitted, texel-snapped map of each cascade.
#include "raster/cascades.h"

#include <algorithm>
#include <cmath>

#include "raster/tolerances.h"

namespace shadowlab::raster {

using scene::Vec3;

std::optional<std::array<double, 2>> visibleDepthRange(const scene::Scene& scene) {
    // Each object's bounds clipped to the camera frustum: tighter than the scene's box, which is
    // mostly empty space in a scene of a floor and a few objects (its near corner is often at the
    // camera's near plane, where no receiver is).
    const scene::CameraBasis cam = scene::cameraBasis(scene.camera);
    double lo = INFINITY, hi = -INFINITY;
    for (const scene::Object& o : scene.objects)
        for (const Vec3& p : visibleReceiverPoints(scene, scene::boundsOf(o.shape))) {
            const double z = glm::dot(p - cam.position, cam.forward);
            lo = std::min(lo, z);
            hi = std::max(hi, z);
        }
    lo = std::max(lo, scene.camera.near);
    hi = std::min(hi, scene.camera.far);
    if (!(hi > lo)) return std::nullopt;
    return std::array<double, 2>{lo, hi};
}

std::vector<double> practicalSplits(double near, double far, int count, double lambda) {
    std::vector<double> s(std::size_t(count) + 1);
    for (int i = 0; i <= count; ++i) {
        const double t = double(i) / count;
        const double logarithmic = near * std::pow(far / near, t);
        const double uniform = near + (far - near) * t;
        s[std::size_t(i)] = lambda * logarithmic + (1.0 - lambda) * uniform;
    }
    // The ends exactly, whatever pow() rounds to.
    s.front() = near;
    s.back() = far;
    return s;
}

std::array<Vec3, 8> sliceCorners(const scene::CameraBasis& cam, double d0, double d1) {
    const double tx = cam.tanHalfFovY * cam.aspect, ty = cam.tanHalfFovY;
    std::array<Vec3, 8> c;
    int k = 0;
    for (const double d : {d0, d1})
        for (const double sy : {-1.0, 1.0})
            for (const double sx : {-1.0, 1.0})
                c[std::size_t(k++)] = cam.position + d * (cam.forward + sx * tx * cam.right + sy * ty * cam.up);
    return c;
}

BoundingSphere sliceBoundingSphere(const scene::CameraBasis& cam, double d0, double d1) {
    // The corners at depth d lie d·k from the axis, k² = tx² + ty². A center on the axis at depth
    // z is equally far from both rings when (z − d0)² + d0²k² = (d1 − z)² + d1²k², i.e.
    // z = (d0 + d1)(1 + k²)/2; past d1, the sphere around the far ring's center holds the near ring.
    const double tx = cam.tanHalfFovY * cam.aspect, ty = cam.tanHalfFovY;
    const double k2 = tx * tx + ty * ty;
    const double z = std::min(0.5 * (d0 + d1) * (1.0 + k2), d1);
    const double r = std::sqrt(std::max((z - d0) * (z - d0) + d0 * d0 * k2, (d1 - z) * (d1 - z) + d1 * d1 * k2));
    return {cam.position + z * cam.forward, r};
}

LightFrustum fitCascade(const scene::Scene& scene, const scene::CameraBasis& cam, double d0, double d1,
                        const Vec3& direction, int mapSize, bool snap) {
    LightFrustum f;
    setBasis(f, direction);
    f.mapSize = std::max(mapSize, 1);
    const BoundingSphere s = sliceBoundingSphere(cam, d0, d1);
    const double size = f.mapSize;
    const double margin = std::min(kCascadeMarginTexels, size / 8.0);
    // The sphere (with the usual 1% margin) fills the map but `margin` texels on each side.
    double half = std::max(s.radius, 1e-12) * kLightFrustumMargin * size / (size - 2.0 * margin);
    // Quantized up to 1/16 of its power of two: the texel size stays the same while the slice
    // changes a little (a moving camera changes the visible depth range, hence the slices).
    const double quantum = std::exp2(std::floor(std::log2(half)) - 4.0);
    if (snap) half = std::ceil(half / quantum) * quantum;
    f.halfWidth = half;
    // Snap the center across the light to the world-fixed grid of texels (multiples of the texel
    // along right and up, from the world origin): the map then moves by whole texels only, and a
    // static scene's shadow edges do not swim as the camera moves. The map's edges are
    // ±size/2 texels from the center, on the grid too.
    const double texel = f.texelWorldSize();
    const double u = glm::dot(s.center, f.right), v = glm::dot(s.center, f.up);
    const double du = snap ? std::round(u / texel) * texel - u : 0.0;
    const double dv = snap ? std::round(v / texel) * texel - v : 0.0;
    f.center = s.center + du * f.right + dv * f.up;
    // Depth: the sphere, and back toward the light to every caster over the map's square.
    const double reach = s.radius * kLightFrustumMargin;
    f.farDepth = reach;
    const double casters = nearestCasterDepth(scene, f, -half, half, -half, half);
    const double nearest = std::min(-reach, casters);
    f.nearDepth = nearest - (kLightFrustumMargin - 1.0) * (f.farDepth - nearest);
    return f;
}

CascadeSet fitCascades(const scene::Scene& scene, const Vec3& direction, int count, int mapSize, double blend,
                       bool snap) {
    CascadeSet set;
    const auto range = visibleDepthRange(scene);
    if (!range || count < 1) return set;
    set.splits = practicalSplits((*range)[0], (*range)[1], count);
    const scene::CameraBasis cam = scene::cameraBasis(scene.camera);
    // A far slice of a wide view can be larger than the whole scene: its map is then the scene's
    // bounding-sphere map, which is finer, and (fixed in the world) cannot swim either.
    const LightFrustum whole = fitDirectionalLight(scene.bounds(), direction, mapSize);
    for (int i = 0; i < count; ++i) {
        // With blending, the pixels in the band before split i read this map too: it starts there.
        const double d0 = set.splits[std::size_t(i)] -
                          (i > 0 ? blend * (set.splits[std::size_t(i)] - set.splits[std::size_t(i) - 1]) : 0.0);
        const LightFrustum f = fitCascade(scene, cam, d0, set.splits[std::size_t(i) + 1], direction, mapSize, snap);
        set.frusta.push_back(f.halfWidth < whole.halfWidth ? f : whole);
    }
    return set;
}

std::vector<Vec3> cascadeReceivers(const scene::Scene& scene, const std::vector<double>& splits, std::size_t c,
                                   double blend) {
    const double lo =
        c == 0 ? -INFINITY : (splits[c] - blend * (splits[c] - splits[c - 1])) * (1.0 - kCascadeSplitSlack);
    const double hi = c + 2 >= splits.size() ? INFINITY : splits[c + 1] * (1.0 + kCascadeSplitSlack);
    return visibleReceiverPointsInSlice(scene, lo, hi);
}

}  // namespace shadowlab::raster
