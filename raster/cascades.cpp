// raster/cascades.cpp: split depths and the fitted, texel-snapped map of each cascade.
#include "raster/cascades.h"

#include <algorithm>
#include <cmath>
#include <cstdio>

#include "raster/tolerances.h"

namespace shadowlab::raster {

using scene::Vec3;

namespace {

// The view depths `points` span, clamped to the camera's near and far planes; none when empty.
std::optional<std::array<double, 2>> viewDepthRange(const scene::Scene& scene, const std::vector<Vec3>& points) {
    const scene::CameraBasis cam = scene::cameraBasis(scene.camera);
    double lo = INFINITY, hi = -INFINITY;
    for (const Vec3& p : points) {
        const double z = glm::dot(p - cam.position, cam.forward);
        lo = std::min(lo, z);
        hi = std::max(hi, z);
    }
    lo = std::max(lo, scene.camera.near);
    hi = std::min(hi, scene.camera.far);
    if (!(hi > lo)) return std::nullopt;
    return std::array<double, 2>{lo, hi};
}

}  // namespace

std::optional<std::array<double, 2>> visibleDepthRange(const scene::Scene& scene) {
    // Each object's bounds clipped to the camera frustum: tighter than the scene's box, which is
    // mostly empty space in a scene of a floor and a few objects (its near corner is often at the
    // camera's near plane, where no receiver is).
    std::vector<Vec3> points;
    for (const scene::Object& o : scene.objects) {
        const std::vector<Vec3> v = visibleReceiverPoints(scene, scene::boundsOf(o.shape));
        points.insert(points.end(), v.begin(), v.end());
    }
    return viewDepthRange(scene, points);
}

std::optional<std::array<double, 2>> shadowableDepthRange(const scene::Scene& scene, const Vec3& direction) {
    return viewDepthRange(scene, visibleShadowableReceiverPoints(scene, direction));
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
                       bool snap, const std::vector<Vec3>* shadowable) {
    CascadeSet set;
    auto range = shadowable ? viewDepthRange(scene, *shadowable) : shadowableDepthRange(scene, direction);
    if (!range) range = visibleDepthRange(scene);  // nothing visible can be shaded: the old fit
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

CascadeChoice chooseCascades(const scene::Scene& scene, const scene::RasterSettings& settings,
                             const scene::RenderPlan* plan) {
    const int asked = settings.cascades;
    // A count other than 1 set after resolveSettings() (a test, the sweep) is forced too.
    if (!settings.cascadesIsDefault || asked != 1)
        return {asked, std::to_string(asked) + " (set by --cascades or the scene)"};
    std::vector<std::size_t> lights;
    for (std::size_t i = 0; i < scene.lights.size(); ++i) {
        if (scene.lights[i].type != scene::LightType::Directional) continue;
        bool shadowed = true;
        if (plan)
            for (const scene::LightPlan& lp : plan->lights)
                if (std::size_t(lp.light) == i) shadowed = lp.needsShadowTest;
        if (shadowed) lights.push_back(i);
    }
    if (lights.empty()) return {asked, std::to_string(asked) + " (default: no shadowed directional light)"};
    if (!visibleDepthRange(scene)) return {asked, std::to_string(asked) + " (default: the camera sees no receiver)"};
    // The depths the maps must cover: those of the visible receivers some caster can shade, over
    // every shadowed light; all visible receivers when none can be shaded. Each light's receivers
    // are found once, for every count tried below.
    std::vector<std::vector<Vec3>> receivers(scene.lights.size());
    std::optional<std::array<double, 2>> range;
    for (const std::size_t i : lights) {
        receivers[i] = visibleShadowableReceiverPoints(scene, scene.lights[i].direction);
        if (const auto r = viewDepthRange(scene, receivers[i]))
            range = range ? std::array<double, 2>{std::min((*range)[0], (*r)[0]), std::max((*range)[1], (*r)[1])} : *r;
    }
    const bool shadowable = range.has_value();
    if (!shadowable) range = visibleDepthRange(scene);
    // The size as set: a default one is kDefaultShadowMapSize, the most chooseShadowMapSize keeps
    // (cascades keep it whole).
    const int size = settings.shadowMapSize;
    const scene::CameraBasis cam = scene::cameraBasis(scene.camera);
    // World size of a pixel on a receiver facing the camera at view depth z (debug_views.h).
    auto pixelAt = [&](double z) { return 2.0 * cam.tanHalfFovY * z / std::max(scene.camera.height, 1); };
    const double zMin = (*range)[0];
    // Worst texels per pixel of `count` maps over every shadowed directional light.
    auto worst = [&](int count) {
        double ratio = 0.0;
        for (const std::size_t i : lights) {
            const scene::Vec3 dir = scene.lights[i].direction;
            if (count == 1) {
                const LightFrustum f = settings.fitLightFrustum
                                           ? fitDirectionalLightToReceivers(scene, dir, size, true, &receivers[i])
                                           : fitDirectionalLight(scene.bounds(), dir, size);
                ratio = std::max(ratio, f.texelWorldSize() / pixelAt(zMin));
                continue;
            }
            const CascadeSet cs = fitCascades(scene, dir, count, size, cascadeBandCover(settings), true, &receivers[i]);
            for (std::size_t c = 0; c < cs.frusta.size(); ++c)
                ratio = std::max(ratio, cs.frusta[c].texelWorldSize() / pixelAt(std::max(cs.splits[c], zMin)));
        }
        return ratio;
    };
    double ratios[scene::kMaxCascades + 1] = {};
    std::string table;
    char buf[160];
    for (int n = 1; n <= scene::kMaxCascades; ++n) {
        ratios[n] = worst(n);
        std::snprintf(buf, sizeof buf, "%s%d: %.3g", n == 1 ? "" : ", ", n, ratios[n]);
        table += buf;
    }
    std::snprintf(buf, sizeof buf, "; map %d, %s view depths %.4g..%.4g)", size,
                  shadowable ? "shadowable" : "no visible receiver can be shaded: visible", zMin, (*range)[1]);
    const std::string what = "worst shadow texel / pixel footprint by cascade count (" + table + buf;
    if (ratios[1] <= kCascadeTexelsPerPixel)
        return {1, "1 (default: one map keeps its texel within 2 pixels; " + what + ")"};
    for (int n = 2; n <= scene::kMaxCascades; ++n)
        if (ratios[n] <= kCascadeTexelsPerPixel)
            return {n, std::to_string(n) +
                           " (default: the fewest cascades that keep every slice's texel within 2 "
                           "pixels; " +
                           what + ")"};
    int best = 1;
    for (int n = 2; n <= scene::kMaxCascades; ++n)
        if (ratios[n] * kCascadeGainTolerance < ratios[best]) best = n;
    return {best, std::to_string(best) +
                      " (default: no count keeps the texel within 2 pixels; the finest worst "
                      "slice" +
                      (best == 1 ? ", cascades gain nothing" : "") + "; " + what + ")"};
}

scene::RasterSettings resolveAutomaticChoices(const scene::Scene& scene, const scene::RasterSettings& settingsIn,
                                              const scene::RenderPlan* plan, CascadeChoice* cascades,
                                              ShadowMapSizeChoice* mapSize) {
    scene::RasterSettings settings = settingsIn;
    const CascadeChoice cc = chooseCascades(scene, settings, plan);
    settings.cascades = cc.count;
    const ShadowMapSizeChoice mc = chooseShadowMapSize(scene, settings, plan);
    if (mc.size != settings.shadowMapSize) {
        settings.shadowMapSize = mc.size;
        if (settings.depthBiasIsDefault) settings.depthBias = scene::defaultDepthBias(scene, mc.size);
    }
    if (cascades) *cascades = cc;
    if (mapSize) *mapSize = mc;
    return settings;
}

}  // namespace shadowlab::raster
