// raster/shadow_layers.cpp: plans the shadow-map layers: which lights get maps, each map's
// frustum (fitted, cascaded, a spot cone, cube faces), its bias and the casters drawn into it.
#include "raster/shadow_layers.h"

#include <algorithm>
#include <cmath>
#include <cstdio>

#include "raster/cascades.h"
#include "scene/camera.h"

namespace shadowlab::raster {

namespace {

bool needsShadowTest(const scene::RenderPlan& plan, std::size_t light) {
    // A plan made for another scene (or by hand) without this light: test, to be safe.
    for (const scene::LightPlan& lp : plan.lights)
        if (lp.light == int(light)) return lp.needsShadowTest;
    return true;
}

std::string formatNumber(double v) {
    char buf[64];
    std::snprintf(buf, sizeof buf, "%.9g", v);
    return buf;
}

}  // namespace

std::vector<ShadowLayer> planShadowLayers(const scene::Scene& scene, const scene::RenderPlan& plan,
                                          const scene::RasterSettings& settings, const scene::Vec3& origin) {
    std::vector<ShadowLayer> layers;
    // Caster culling: per layer, which objects are drawn into it, and how many are not.
    // Not with a transmittance map: an opaque caster left out would let semi-transparent ones
    // behind it into the map, and a receiver between the two would get the nearer layer's factor
    // with one more rounding (T_all / T_rest), so the frame would not stay the same bit for bit.
    const bool cull = settings.cullCasters && !plan.needsTransmittanceMap;
    // The receivers also bound each layer's read window (layerReadWindow), which holds with a
    // transmittance map too: it leaves out texels, not casters, so nothing read changes.
    const bool window = settings.cullCasters;
    const std::vector<scene::Vec3> receivers = window ? visibleReceiverPoints(scene) : std::vector<scene::Vec3>{};
    // The hardware bias of an orthographic map (settings.hardwareBias): the world constant bias
    // in units of r (its depth is linear: bias / depth range), the slope bias in texels as it is
    // (the rasterizer's slope is depth per texel, as the shader's slope term is per texel).
    auto hardwareDepthBias = [&](double depthBias, const LightFrustum& map) {
        return DepthBiasFactors{float(depthBias / map.depthRange() / kShadowDepthUnitR), float(settings.slopeBias)};
    };
    auto add = [&](std::size_t light, LayerReason reason, int index, int count, std::string label,
                   const LightFrustum& f, const std::vector<scene::Vec3>& layerReceivers) -> ShadowLayer& {
        ShadowLayer& layer = layers.emplace_back();
        layer.light = int(light);
        layer.reason = reason;
        layer.index = index;
        layer.count = count;
        layer.label = std::move(label);
        layer.frustum = f;
        layer.matrix = glm::mat4(f.toClip(origin));
        if (window) {
            layer.blurRadius = momentBlurRadius(settings);
            layer.receivers = layerReceivers;
            layer.cullReachTexels = cullReachTexels(settings, scene.lights[light], f.mapSize);
            layer.cullOffsetTexels = lookupOffsetTexels(settings);
        }
        if (cull) {
            layer.casters = castsOnto(scene, f, layer.receivers, layer.cullReachTexels, layer.cullOffsetTexels);
            for (const bool k : layer.casters) layer.culled += k ? 0 : 1;
        }
        return layer;
    };
    const scene::Bounds bounds = scene.bounds();
    for (std::size_t i = 0; i < scene.lights.size(); ++i) {
        if (!needsShadowTest(plan, i)) continue;
        const scene::Light& light = scene.lights[i];
        const std::string name = "L" + std::to_string(i);
        if (light.type == scene::LightType::Point) {
            // Six layers, +X −X +Y −Y +Z −Z, each drawing only its own casters; a point light
            // keeps the shader's bias.
            static const char* const kFaces[] = {"+X", "-X", "+Y", "-Y", "+Z", "-Z"};
            for (int face = 0; face < kCubeFaces; ++face) {
                ShadowLayer& layer =
                    add(i, LayerReason::kCubeFace, face, kCubeFaces, name + " " + kFaces[face],
                        pointLightFaceFrustum(scene, settings, light, face, settings.shadowMapSize), receivers);
                layer.depthBias = layer.shaderDepthBias = settings.depthBias;
                layer.shaderSlopeBias = settings.slopeBias;
            }
            continue;
        }
        if (light.type == scene::LightType::Spot) {
            // A spot map keeps the shader's bias, also with the hardware bias (docs/raster.md).
            ShadowLayer& layer = add(i, LayerReason::kSpot, 0, 1, name,
                                     spotLightFrustum(scene, settings, light, settings.shadowMapSize), receivers);
            layer.depthBias = layer.shaderDepthBias = settings.depthBias;
            layer.shaderSlopeBias = settings.slopeBias;
            continue;
        }
        const CascadeSet cascades = settings.cascades > 1
                                        ? fitCascades(scene, light.direction, settings.cascades, settings.shadowMapSize,
                                                      cascadeBandCover(settings), settings.snapLightFrustum)
                                        : CascadeSet{};
        // With the hardware bias a directional map's depth pass applies both terms, and the lit
        // shader none.
        auto setBias = [&](ShadowLayer& layer, double depthBias) {
            layer.depthBias = depthBias;
            layer.biasInDepthPass = settings.hardwareBias;
            layer.hardwareBias =
                settings.hardwareBias ? hardwareDepthBias(depthBias, layer.frustum) : DepthBiasFactors{};
            layer.shaderDepthBias = settings.hardwareBias ? 0.0 : depthBias;
            layer.shaderSlopeBias = settings.hardwareBias ? 0.0 : settings.slopeBias;
        };
        if (!cascades.frusta.empty()) {
            // Cascaded: one layer per slice; the shader picks the cascade by view depth (lit.frag
            // cascadeOf). Cascades are fitted to their slices, so fitLightFrustum does not apply.
            // A default constant bias is half of each cascade's texel, as for a fitted map. Each
            // cascade draws only the casters of the receivers of its own slice.
            const int count = int(cascades.frusta.size());
            for (std::size_t c = 0; c < cascades.frusta.size(); ++c) {
                const LightFrustum& cf = cascades.frusta[c];
                ShadowLayer& layer =
                    add(i, LayerReason::kCascade, int(c), count, name + " C" + std::to_string(c), cf,
                        window ? cascadeReceivers(scene, cascades.splits, c, cascadeBandCover(settings))
                               : std::vector<scene::Vec3>{});
                setBias(layer, settings.depthBiasIsDefault ? 0.5 * cf.texelWorldSize() : settings.depthBias);
                layer.sliceNear = cascades.splits[c];
                layer.sliceFar = cascades.splits[c + 1];
            }
            continue;
        }
        // Objects that cannot cast onto the visible receivers stay out of this map.
        ShadowLayer& layer = add(i, LayerReason::kDirectional, 0, 1, name,
                                 settings.fitLightFrustum
                                     ? fitDirectionalLightToReceivers(scene, light.direction, settings.shadowMapSize,
                                                                      settings.snapLightFrustum)
                                     : fitDirectionalLight(bounds, light.direction, settings.shadowMapSize),
                                 receivers);
        // The default constant bias is half a texel of the bounding-sphere map
        // (scene::defaultDepthBias); a fitted map's texel is smaller, so the default becomes half
        // of *its* texel. A bias the user gave is kept as given.
        setBias(layer, settings.depthBiasIsDefault && settings.fitLightFrustum ? 0.5 * layer.frustum.texelWorldSize()
                                                                               : settings.depthBias);
    }
    return layers;
}

std::vector<ShadowLayer> planShadowLayers(const scene::Scene& scene, const scene::RenderPlan& plan,
                                          const scene::RasterSettings& settings) {
    return planShadowLayers(scene, plan, settings, scene::cameraBasis(scene.camera).position);
}

TexelRect grownWithin(const TexelRect& w, std::uint32_t dx, std::uint32_t dy, std::uint32_t size) {
    if (w.empty()) return w;
    return TexelRect{w.x0 - std::min(w.x0, dx), w.y0 - std::min(w.y0, dy), std::min(size, w.x1 + dx),
                     std::min(size, w.y1 + dy)};
}

TexelRect layerLookupWindow(const ShadowLayer& layer) {
    const auto size = std::uint32_t(std::max(layer.frustum.mapSize, 1));
    return receiverTexels(layer.frustum, layer.receivers, layer.cullReachTexels - layer.blurRadius,
                          layer.cullOffsetTexels)
        .value_or(TexelRect{0, 0, size, size});
}

TexelRect layerReadWindow(const ShadowLayer& layer) {
    const auto size = std::uint32_t(std::max(layer.frustum.mapSize, 1));
    const auto r = std::uint32_t(layer.blurRadius);
    return grownWithin(layerLookupWindow(layer), r, r, size);
}

std::vector<bool> layerCastingBoxes(const ShadowLayer& layer, std::span<const scene::Bounds> boxes) {
    if (layer.casters.empty()) return std::vector<bool>(boxes.size(), true);
    return boxesCastOnto(boxes, layer.frustum, layer.receivers, layer.cullReachTexels, layer.cullOffsetTexels);
}

std::vector<double> cascadeSplits(const std::vector<ShadowLayer>& layers) {
    std::vector<double> splits;
    for (const ShadowLayer& l : layers) {
        if (l.reason != LayerReason::kCascade) continue;
        if (l.index == 0) splits.assign(1, l.sliceNear);  // the last cascaded light's
        splits.push_back(l.sliceFar);
    }
    return splits;
}

std::vector<double> cascadeTexels(const std::vector<ShadowLayer>& layers) {
    std::vector<double> texels;
    for (const ShadowLayer& l : layers) {
        if (l.reason != LayerReason::kCascade) continue;
        if (l.index == 0) texels.clear();  // the last cascaded light's
        texels.push_back(l.frustum.texelWorldSize());
    }
    return texels;
}

int LightCulling::total() const {
    int n = 0;
    for (const int c : culled) n += c;
    return n;
}

std::vector<LightCulling> culledCasters(const scene::Scene& scene, const scene::RasterSettings& settingsIn,
                                        const scene::RenderPlan* plan) {
    const scene::RasterSettings settings = resolveAutomaticChoices(scene, settingsIn, plan);
    std::vector<LightCulling> out(scene.lights.size());
    if (!settings.cullCasters || (plan && plan->needsTransmittanceMap)) return out;
    for (const ShadowLayer& l : planShadowLayers(scene, plan ? *plan : scene::RenderPlan{}, settings)) {
        // The label without the light's name: "" for a single map, "C0".., "+X"..
        const std::size_t space = l.label.find(' ');
        out[std::size_t(l.light)].layers.push_back(space == std::string::npos ? "" : l.label.substr(space + 1));
        out[std::size_t(l.light)].culled.push_back(l.culled);
    }
    return out;
}

std::string explainShadowLayers(const std::vector<ShadowLayer>& layers, std::size_t objectCount) {
    std::string out;
    if (layers.empty()) return "raster shadow-map layers: none (no light needs a shadow test)\n";
    out = "raster shadow-map layers (" + std::to_string(layers.size()) + "):\n";
    for (const ShadowLayer& l : layers) {
        out += "  " + l.label + ": ";
        switch (l.reason) {
            case LayerReason::kDirectional: out += "directional light's map"; break;
            case LayerReason::kSpot: out += "spot light's map"; break;
            case LayerReason::kCascade:
                out += "cascade " + std::to_string(l.index) + " of " + std::to_string(l.count) + " (view depth " +
                       formatNumber(l.sliceNear) + ".." + formatNumber(l.sliceFar) + ")";
                break;
            case LayerReason::kCubeFace: out += "point light's cube face " + std::to_string(l.index); break;
        }
        out += "; " + l.frustum.describe() + "; texel " + formatNumber(l.frustum.texelWorldSize()) +
               (l.frustum.perspective ? "*d" : "") + "; bias ";
        if (l.biasInDepthPass)
            out += formatNumber(l.depthBias) + " world in the depth pass (factors " +
                   formatNumber(l.hardwareBias.constant) + ", " + formatNumber(l.hardwareBias.slope) + ")";
        else
            out += formatNumber(l.shaderDepthBias) + " world, slope " + formatNumber(l.shaderSlopeBias) +
                   " texels in the lit shader";
        out += l.casters.empty()
                   ? "; every caster drawn"
                   : "; " + std::to_string(l.culled) + " of " + std::to_string(objectCount) + " objects culled";
        const TexelRect w = layerReadWindow(l);
        const double mapArea = double(l.frustum.mapSize) * double(l.frustum.mapSize);
        if (w.area() < std::uint64_t(mapArea))
            out += "; drawn in texels [" + std::to_string(w.x0) + ", " + std::to_string(w.x1) + ") x [" +
                   std::to_string(w.y0) + ", " + std::to_string(w.y1) + ") (" +
                   formatNumber(std::round(1000.0 * double(w.area()) / mapArea) / 10.0) + "% of the map)";
        out += "\n";
    }
    return out;
}

}  // namespace shadowlab::raster
