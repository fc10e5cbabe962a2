// raster/memory.cpp: the raster backend's memory estimate (see raster/memory.h).
#include "raster/memory.h"

#include <algorithm>
#include <variant>

#include "raster/alpha_casters.h"
#include "raster/cascades.h"
#include "raster/geometry.h"
#include "raster/moment_maps.h"
#include "raster/tolerances.h"
#include "scene/camera.h"
#include "scene/memory.h"

namespace shadowlab::raster {

namespace {
// Measured on lavapipe (Mesa 22.3): a 16x9 raster render of the seed scene peaks 108 MiB above
// a ray-traced one, nearly all of it the driver and LLVM; the allowance is rounded up.
constexpr std::uint64_t kDriverAllowance = 160 * scene::kMiB;
// The lit pass has a target per channel, the RGB32F beauty and five R32F AOV planes (32 bytes a
// pixel, as two RGBA32F targets), and with more than one light an RGBA32F target for each four
// lights' visibility, over a D32 depth buffer; devices that cannot read the targets in place copy
// them into host-visible buffers of the same size (counted, as an upper bound; on lavapipe the
// planes asked for are rendered into the Frame, and the Renderer's own are then never touched).
std::uint64_t litBytesPerPixel(std::size_t lights) {
    const std::uint64_t targets = 2 + (lights > 1 ? (lights + 3) / 4 : 0);
    return targets * 16 * 2 + 4;
}
// A tessellated sphere (raster/geometry.cpp) stays well under this many triangles.
constexpr std::uint64_t kSphereTriangles = 1 << 16;
constexpr std::uint64_t kBytesPerTriangle = 3 * 32 + 3 * 4;  // vertices (position, normal, id) + indices
// Lift-free draws (one directional light, none or pcf2x2): the host keeps each vertex's position and
// normal and the indices, and each split adds per vertex its light bits and projected point and per
// triangle its area; counted with three vertices a triangle, an upper bound.
constexpr std::uint64_t kLiftFreeBytesPerTriangle = 3 * (12 + 12) + 3 * 4 + 3 * (4 + 8) + 4;
// View and caster culling by clusters (raster/view_cull.h): a 32-byte box per cluster of
// kViewCullClusterTriangles (a cluster more per object, where one ends) and its 48-byte world box,
// and per frame up to two 12-byte cut ranges per cluster in each of the visible runs and the two
// range lists, and one more per shadow layer's casters (four cascades counted).
std::uint64_t viewCullBytes(std::uint64_t triangles, std::uint64_t objects) {
    return (triangles / kViewCullClusterTriangles + objects) * (32 + 48 + 3 * 2 * 12 + 4 * 12);
}
// Filterable maps (raster/moment_maps.h): an RGBA32F array the size of the shadow maps and one
// intermediate layer (momentBytes), and the compute pipeline's compilation, measured on lavapipe
// (Mesa 22.3) as about 97 MiB above the images on the seed scene at 1024².
constexpr std::uint64_t kMomentPipelineAllowance = 112 * scene::kMiB;
}  // namespace

std::uint64_t estimateMemoryBytes(const scene::Scene& scene, const scene::RenderPlan& plan,
                                  const scene::RasterSettings& settings) {
    const std::uint64_t pixels = std::uint64_t(scene.camera.width) * std::uint64_t(scene.camera.height);
    // Per shadow-map texel: depth and blocker id, and with semi-transparent casters the
    // transmittance map's four R32F values (T_all, D1, and behind the nearest layer T_rest, D2).
    const std::uint64_t layers = shadowMapLayers(scene, plan, settings);
    const std::uint64_t texels = std::uint64_t(settings.shadowMapSize) * std::uint64_t(settings.shadowMapSize);
    // Spheres as tessellated (raster/geometry.cpp): segments by their size on screen, about
    // segments² triangles; many small spheres are cheap, not kSphereTriangles each.
    const scene::CameraBasis cam = scene::cameraBasis(scene.camera);
    std::uint64_t triangles = 0;
    for (const scene::Object& o : scene.objects) {
        if (const auto* m = std::get_if<scene::Mesh>(&o.shape)) {
            triangles += m->triangleCount();
        } else if (const auto* s = std::get_if<scene::Sphere>(&o.shape)) {
            const double d = std::max(glm::length(s->center - cam.position) - s->radius, scene.camera.near);
            const std::uint64_t n = std::uint64_t(sphereSegments(s->radius, d, cam.tanHalfFovY, scene.camera.height));
            triangles += std::min<std::uint64_t>(n * n + 2 * n, kSphereTriangles);
        } else {
            triangles += 12;
        }
    }
    return kDriverAllowance + scene::frameBytes(scene) + pixels * litBytesPerPixel(scene.lights.size()) +
           layers * texels * (plan.needsTransmittanceMap ? 4 + 4 + 16 : 4 + 4) + triangles * kBytesPerTriangle +
           (scene::isFilterable(settings.filter) && layers > 0
                ? momentBytes(settings.shadowMapSize, layers) + kMomentPipelineAllowance
                : 0) +
           // Alpha data where the renderer makes it (with the default RendererOptions): a UV per
           // vertex (every vertex of the scene gets a slot in the UV buffer, 3 · 8 bytes a
           // triangle), the texels and one record per object id (0 unused).
           (planAlpha(scene, plan.needsTransmittanceMap).data
                ? triangles * 24 + scene::alphaTextureBytes(scene) + (scene.objects.size() + 1) * 32
                : 0) +
           scene.objects.size() * scene::kBackendBytesPerObject + viewCullBytes(triangles, scene.objects.size()) +
           (scene.lights.size() == 1 && scene.lights[0].type == scene::LightType::Directional &&
                    (settings.filter == scene::ShadowFilter::None || settings.filter == scene::ShadowFilter::Pcf2x2)
                ? triangles * kLiftFreeBytesPerTriangle
                : 0);
}

std::uint64_t shadowMapLayers(const scene::Scene& scene, const scene::RenderPlan& plan,
                              const scene::RasterSettings& settings) {
    std::uint64_t layers = 0;
    int cascades = 0;  // chosen once, for the first shadowed directional light: one count serves all
    for (const scene::LightPlan& lp : plan.lights) {
        if (!lp.needsShadowTest) continue;
        // A point light's cube map has six layers; a directional light one per cascade (at
        // most: fitCascades may fall back to one map). With the default, the count the renderer
        // will choose for this view (raster/cascades.h), which can be more than one.
        const scene::LightType type = scene.lights[lp.light].type;
        if (type == scene::LightType::Directional && cascades == 0)
            cascades = std::max(1, chooseCascades(scene, settings, &plan).count);
        layers += type == scene::LightType::Point         ? 6
                  : type == scene::LightType::Directional ? std::uint64_t(cascades)
                                                          : 1;
    }
    return layers;
}

std::uint64_t debugViewBytes(const scene::Scene& scene, const scene::RenderPlan& plan,
                             const scene::RasterSettings& settings, std::string_view view) {
    if (view == "shadow-map") {
        const std::uint64_t texels = std::uint64_t(settings.shadowMapSize) * std::uint64_t(settings.shadowMapSize);
        return shadowMapLayers(scene, plan, settings) * texels * (4 + 12 + 3);
    }
    const std::uint64_t pixels = std::uint64_t(scene.camera.width) * std::uint64_t(scene.camera.height);
    return pixels * (view == "light-frustum" ? 12 + 4 + 16 : 12 + 4);
}

}  // namespace shadowlab::raster
