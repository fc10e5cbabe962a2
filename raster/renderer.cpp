// raster/renderer.cpp: puts the passes together: context, geometry upload, shadow maps, lit
// pass, readback into a Frame, timings and metadata.
#include "raster/renderer.h"

#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstring>

#include "raster/cascades.h"
#include "raster/context.h"
#include "raster/geometry.h"
#include "raster/light_frustum.h"
#include "raster/lit_pass.h"
#include "raster/shadow_pass.h"
#include "raster/tolerances.h"
#include "scene/camera.h"

namespace shadowlab::raster {

namespace {

using Clock = std::chrono::steady_clock;

double msSince(Clock::time_point start) {
    return std::chrono::duration<double, std::milli>(Clock::now() - start).count();
}

std::string formatNumber(double v) {
    char buf[64];
    std::snprintf(buf, sizeof buf, "%.9g", v);
    return buf;
}

bool needsShadowTest(const scene::RenderPlan& plan, std::size_t light) {
    // A plan made for another scene (or by hand) without this light: test, to be safe.
    for (const scene::LightPlan& lp : plan.lights)
        if (lp.light == int(light)) return lp.needsShadowTest;
    return true;
}

void checkSupported(const scene::Scene& scene, const scene::RasterSettings& settings) {
    if (scene.lights.size() > SHADOWLAB_MAX_LIGHTS)
        throw RasterError("the scene has " + std::to_string(scene.lights.size()) +
                          " lights; the raster backend handles at most " + std::to_string(SHADOWLAB_MAX_LIGHTS));
    if (scene.camera.width < 1 || scene.camera.height < 1)
        throw RasterError("the camera resolution must be at least 1x1");
    if (settings.pcfSize < 1 || settings.pcfSize > kMaxPcfSize)
        throw RasterError("--pcf-size: must be in 1.." + std::to_string(kMaxPcfSize) + ", got " +
                          std::to_string(settings.pcfSize));
    if (!std::isfinite(settings.normalOffset) || settings.normalOffset < 0.0)
        throw RasterError("--normal-offset: must be a finite value >= 0 (texels)");
}

const char* filterName(scene::ShadowFilter f) {
    switch (f) {
        case scene::ShadowFilter::None: return "none";
        case scene::ShadowFilter::Pcf2x2: return "pcf2x2";
        case scene::ShadowFilter::Pcf: return "pcf";
        case scene::ShadowFilter::Poisson: return "poisson";
        case scene::ShadowFilter::Pcss: return "pcss";
    }
    return "?";
}

}  // namespace

static_assert(SHADOWLAB_MAX_CASCADES == scene::kMaxCascades, "shaders/interface.h and scene/settings.h disagree");

scene::Frame render(const scene::Scene& scene, const scene::RenderPlan& plan, const scene::RasterSettings& settings,
                    RenderDebug* debug) {
    checkSupported(scene, settings);
    const scene::CameraBasis cam = scene::cameraBasis(scene.camera);
    const scene::Vec3 origin = cam.position;  // camera-relative rendering
    const auto width = std::uint32_t(scene.camera.width);
    const auto height = std::uint32_t(scene.camera.height);

    // The pixels are allocated at readback, after the device has accepted the image size.
    scene::Frame frame;
    ValidationLog log;
    std::vector<LightFrustum> frusta;
    std::vector<double> usedDepthBias;  // per shadow-mapped light (spot, directional)
    std::vector<int> layerLight;        // per layer: the light it belongs to
    std::vector<std::string> layerLabels;
    std::vector<double> cascadeSplits, cascadeTexels;
    int cascadesUsed = 1;
    std::size_t triangles = 0;
    int sphereSegmentsUsed = 0;
    {
        // --- setup: instance, device, pipelines, geometry upload ---
        const auto setupStart = Clock::now();
        const Context ctx(ContextOptions{.device = settings.device, .validate = settings.validate, .log = &log});
        frame.attributes["device"] = ctx.deviceReport.name;

        const SceneGeometry geometry = tessellateScene(scene, origin);
        triangles = geometry.triangleCount();
        sphereSegmentsUsed = geometry.maxSphereSegments;
        const Buffer vertexBuffer = uploadBuffer(ctx, geometry.vertices, VK_BUFFER_USAGE_VERTEX_BUFFER_BIT);
        const Buffer indexBuffer = uploadBuffer(ctx, geometry.indices, VK_BUFFER_USAGE_INDEX_BUFFER_BIT);
        const DrawGeometry draw{vertexBuffer.buffer.get(), indexBuffer.buffer.get(),
                                std::uint32_t(geometry.indices.size())};

        // One shadow-map layer per light that needs a shadow test.
        const scene::Bounds bounds = scene.bounds();
        shaders::LitUniforms uniforms{};
        const glm::dmat4 viewProj = scene::projectionMatrix(cam, scene.camera.near, scene.camera.far) *
                                    scene::viewMatrix(cam, origin);
        uniforms.viewProj = glm::mat4(viewProj);
        uniforms.forward = glm::vec4(glm::vec3(cam.forward), float(scene.ambient));
        uniforms.background = glm::vec4(glm::vec3(scene.background), 0.0f);
        uniforms.counts = glm::vec4(float(scene.lights.size()), 0, 0, 0);
        std::vector<glm::mat4> lightMatrices;
        for (std::size_t i = 0; i < scene.lights.size(); ++i) {
            const scene::Light& light = scene.lights[i];
            const bool spot = light.type == scene::LightType::Spot;
            const bool point = light.type == scene::LightType::Point;
            shaders::LightData& l = uniforms.lights[i];
            const double meanColor = (light.color.r + light.color.g + light.color.b) / 3.0;
            l.radiance = glm::vec4(glm::vec3(light.color * light.intensity), float(light.intensity * meanColor));
            float layer = -1.0f;
            LightFrustum f;
            CascadeSet cascades;  // filled for a cascaded directional light
            if (needsShadowTest(plan, i)) {
                if (point) {
                    // Six layers, +X −X +Y −Y +Z −Z; the shader picks the face and builds its
                    // projection itself, so toShadow stays unused.
                    layer = float(lightMatrices.size());
                    for (int face = 0; face < kCubeFaces; ++face) {
                        f = fitPointLightFace(bounds, light.position, face, settings.shadowMapSize);
                        lightMatrices.push_back(glm::mat4(f.toClip(origin)));
                        frusta.push_back(f);
                        static const char* const kFaces[] = {"+X", "-X", "+Y", "-Y", "+Z", "-Z"};
                        layerLight.push_back(int(i));
                        layerLabels.push_back("L" + std::to_string(i) + " " + kFaces[face]);
                    }
                    l.bias = glm::vec4(float(settings.depthBias), float(settings.slopeBias), float(f.texelWorldSize()), 0.0f);
                } else if (spot)
                    f = fitSpotLight(bounds, light.position, light.direction, light.coneAngleDegrees,
                                     settings.shadowMapSize);
                else if (settings.cascades > 1 &&
                         !(cascades = fitCascades(scene, light.direction, settings.cascades, settings.shadowMapSize))
                              .frusta.empty()) {
                    // Cascaded: one layer per slice; the shader picks the cascade by view depth
                    // (lit.frag cascadeOf). Cascades are fitted to their slices, so
                    // fitLightFrustum does not apply. A default constant bias is half of each
                    // cascade's texel, as for a fitted map.
                    layer = float(lightMatrices.size());
                    cascadesUsed = int(cascades.frusta.size());
                    cascadeSplits = cascades.splits;
                    cascadeTexels.clear();
                    for (std::size_t c = 0; c < cascades.frusta.size(); ++c) {
                        const LightFrustum& cf = cascades.frusta[c];
                        const double depthBias = settings.depthBiasIsDefault ? 0.5 * cf.texelWorldSize() : settings.depthBias;
                        lightMatrices.push_back(glm::mat4(cf.toClip(origin)));
                        frusta.push_back(cf);
                        usedDepthBias.push_back(depthBias);
                        cascadeTexels.push_back(cf.texelWorldSize());
                        layerLight.push_back(int(i));
                        layerLabels.push_back("L" + std::to_string(i) + " C" + std::to_string(c));
                        shaders::CascadeData& cd = uniforms.cascades[i * SHADOWLAB_MAX_CASCADES + c];
                        cd.toShadow = glm::mat4(cf.toTexture(origin));
                        cd.params = glm::vec4(float(cascades.splits[c + 1]), float(cf.texelWorldSize()),
                                              float(1.0 / cf.depthRange()), float(depthBias));
                    }
                    // Cascade 0 also fills the light's own map fields (what count <= 1 would use).
                    f = cascades.frusta[0];
                    l.toShadow = uniforms.cascades[i * SHADOWLAB_MAX_CASCADES].toShadow;
                    l.bias = glm::vec4(float(usedDepthBias[usedDepthBias.size() - cascades.frusta.size()]),
                                       float(settings.slopeBias), float(f.texelWorldSize()),
                                       float(1.0 / f.depthRange()));
                } else if (settings.fitLightFrustum)
                    f = fitDirectionalLightToReceivers(scene, light.direction, settings.shadowMapSize);
                else
                    f = fitDirectionalLight(bounds, light.direction, settings.shadowMapSize);
                if (!point && cascades.frusta.empty()) {
                    layerLight.push_back(int(i));
                    layerLabels.push_back("L" + std::to_string(i));
                    layer = float(lightMatrices.size());
                    lightMatrices.push_back(glm::mat4(f.toClip(origin)));
                    l.toShadow = glm::mat4(f.toTexture(origin));
                    // The default constant bias is half a texel of the bounding-sphere map
                    // (scene::defaultDepthBias); a fitted map's texel is smaller, so the default
                    // becomes half of *its* texel. A bias the user gave is kept as given.
                    const double depthBias = settings.depthBiasIsDefault && settings.fitLightFrustum && !spot
                                                 ? 0.5 * f.texelWorldSize()
                                                 : settings.depthBias;
                    usedDepthBias.push_back(depthBias);
                    l.bias = glm::vec4(float(depthBias), float(settings.slopeBias), float(f.texelWorldSize()),
                                       spot ? 0.0f : float(1.0 / f.depthRange()));
                    frusta.push_back(f);
                }
            }
            if (point) {
                l.axis = glm::vec4(0.0f, 0.0f, 0.0f, float(2.0 * light.radius));  // w: light size (PCSS)
                l.toLight = glm::vec4(glm::vec3(light.position - origin), layer);
                // Without a shadow test f is default; near/far are then unused.
                l.kind = glm::vec4(float(SHADOWLAB_LIGHT_POINT), float(cubeFaceTanHalfFov(settings.shadowMapSize)),
                                   float(f.near), float(f.far));
            } else if (spot) {
                constexpr double kPi = 3.14159265358979323846;
                l.toLight = glm::vec4(glm::vec3(light.position - origin), layer);
                l.kind = glm::vec4(float(SHADOWLAB_LIGHT_SPOT), float(std::cos(light.coneAngleDegrees * kPi / 180.0)),
                                   float(f.near), float(f.far));
                l.axis = glm::vec4(glm::vec3(glm::normalize(light.direction)), float(2.0 * light.radius));
            } else {
                l.toLight = glm::vec4(glm::vec3(-light.direction), layer);
                l.kind = glm::vec4(float(SHADOWLAB_LIGHT_DIRECTIONAL),
                                   cascades.frusta.empty() ? 0.0f : float(cascades.frusta.size()), 0, 0);
            }
            l.params = glm::vec4(float(kMaxSlopeTan), float(int(settings.filter)), float(settings.normalOffset),
                                 float(settings.pcfSize));
        }
        std::vector<glm::vec4> albedos;
        for (const scene::Object& o : scene.objects)
            albedos.emplace_back(glm::vec3(scene.materialOf(o).albedo), 1.0f);

        // Without a shadowed light a 1x1 cleared layer keeps the descriptor valid.
        const auto mapSize = lightMatrices.empty() ? 1u : std::uint32_t(settings.shadowMapSize);
        const auto layers = std::max<std::uint32_t>(1, std::uint32_t(lightMatrices.size()));
        const ShadowPipeline shadowPipeline = createShadowPipeline(ctx);
        const ShadowMaps maps = createShadowMaps(ctx, mapSize, layers);
        const LitPipeline litPipeline = createLitPipeline(ctx);
        const LitTargets targets = createLitTargets(ctx, width, height);
        const LitBindings bindings = createLitBindings(ctx, litPipeline, uniforms, albedos, maps);
        const Readback readback = createReadback(ctx, targets);
        // GPU timestamps around each pass, where the queue has them (a bonus to the CPU clock,
        // which also counts submission and the fence wait).
        const bool timestamps = ctx.properties.limits.timestampComputeAndGraphics == VK_TRUE;
        QueryPoolHandle queries;
        if (timestamps) {
            const VkQueryPoolCreateInfo queryInfo{
                .sType = VK_STRUCTURE_TYPE_QUERY_POOL_CREATE_INFO,
                .queryType = VK_QUERY_TYPE_TIMESTAMP,
                .queryCount = 4,
            };
            VkQueryPool pool = VK_NULL_HANDLE;
            VK_CHECK(vkCreateQueryPool(ctx.device.get(), &queryInfo, nullptr, &pool));
            queries = QueryPoolHandle(ctx.device.get(), pool);
        }
        auto stamp = [&](VkCommandBuffer cb, std::uint32_t query) {
            if (timestamps) vkCmdWriteTimestamp2(cb, VK_PIPELINE_STAGE_2_ALL_COMMANDS_BIT, queries.get(), query);
        };
        frame.timingsMs.emplace_back("setup", msSince(setupStart));

        // --- shadow pass ---
        const auto shadowStart = Clock::now();
        VkCommandBuffer commands = ctx.beginCommands();
        if (timestamps) vkCmdResetQueryPool(commands, queries.get(), 0, 4);
        stamp(commands, 0);
        recordShadowPass(commands, shadowPipeline, maps, draw, lightMatrices);
        stamp(commands, 1);
        ctx.submitAndWait(commands);
        frame.timingsMs.emplace_back("shadow_pass", msSince(shadowStart));
        if (debug && debug->captureShadowMaps) {
            debug->layerDepths.clear();
            for (std::uint32_t k = 0; k < std::uint32_t(lightMatrices.size()); ++k)
                debug->layerDepths.push_back(readShadowMap(ctx, maps, k));
        }

        // --- lit pass ---
        const auto litStart = Clock::now();
        commands = ctx.beginCommands();
        stamp(commands, 2);
        recordLitPass(commands, litPipeline, bindings, targets, draw, glm::vec3(scene.background));
        stamp(commands, 3);
        ctx.submitAndWait(commands);
        frame.timingsMs.emplace_back("lit_pass", msSince(litStart));

        // --- readback: rows come out top first, as the Frame wants them ---
        const auto readStart = Clock::now();
        commands = ctx.beginCommands();
        recordReadback(commands, targets, readback);
        ctx.submitAndWait(commands);
        invalidate(ctx, readback.beauty);
        invalidate(ctx, readback.aovs);
        scene::Frame pixels = scene::Frame::allocate(int(width), int(height), true);
        pixels.attributes = std::move(frame.attributes);
        pixels.timingsMs = std::move(frame.timingsMs);
        frame = std::move(pixels);
        const auto* beauty = static_cast<const float*>(readback.beauty.mapped);
        const auto* aovs = static_cast<const float*>(readback.aovs.mapped);
        for (std::size_t i = 0; i < frame.pixelCount(); ++i) {
            frame.beauty[3 * i + 0] = beauty[4 * i + 0];
            frame.beauty[3 * i + 1] = beauty[4 * i + 1];
            frame.beauty[3 * i + 2] = beauty[4 * i + 2];
            frame.visibility[i] = beauty[4 * i + 3];
            frame.objectId[i] = aovs[4 * i + 0];
            frame.ndotl[i] = aovs[4 * i + 1];
            frame.depth[i] = aovs[4 * i + 2];
            frame.blockerId[i] = aovs[4 * i + 3];
        }
        frame.timingsMs.emplace_back("readback", msSince(readStart));
        if (timestamps) {
            std::uint64_t ticks[4] = {};
            VK_CHECK(vkGetQueryPoolResults(ctx.device.get(), queries.get(), 0, 4, sizeof ticks, ticks,
                                           sizeof(std::uint64_t), VK_QUERY_RESULT_64_BIT | VK_QUERY_RESULT_WAIT_BIT));
            const double msPerTick = double(ctx.properties.limits.timestampPeriod) * 1e-6;
            frame.attributes["gpu_shadow_pass_ms"] = formatNumber(double(ticks[1] - ticks[0]) * msPerTick);
            frame.attributes["gpu_lit_pass_ms"] = formatNumber(double(ticks[3] - ticks[2]) * msPerTick);
        }
    }  // the context is destroyed here; validation messages raised by that still count

    frame.attributes["backend"] = "raster";
    frame.attributes["shadow_map_size"] = std::to_string(settings.shadowMapSize);
    frame.attributes["filter"] = filterName(settings.filter);
    if (settings.filter == scene::ShadowFilter::Pcf || settings.filter == scene::ShadowFilter::Poisson ||
        settings.filter == scene::ShadowFilter::Pcss)
        frame.attributes["pcf_size"] = std::to_string(settings.pcfSize);
    frame.attributes["normal_offset"] = formatNumber(settings.normalOffset);
    frame.attributes["light_frustum_fit"] = settings.fitLightFrustum ? "receivers" : "bounding-sphere";
    // The constant bias actually used: one value, or one per light (';') when a default was
    // re-derived per fitted map and the maps differ.
    std::string depthBias = formatNumber(settings.depthBias);
    if (!usedDepthBias.empty()) {
        depthBias = formatNumber(usedDepthBias[0]);
        for (std::size_t i = 1; i < usedDepthBias.size(); ++i)
            if (usedDepthBias[i] != usedDepthBias[0]) {
                depthBias.clear();
                for (std::size_t k = 0; k < usedDepthBias.size(); ++k)
                    depthBias += (k ? ";" : "") + formatNumber(usedDepthBias[k]);
                break;
            }
    }
    frame.attributes["depth_bias"] = depthBias;
    frame.attributes["depth_bias_default"] = settings.depthBiasIsDefault ? "true" : "false";
    frame.attributes["slope_bias"] = formatNumber(settings.slopeBias);
    frame.attributes["max_slope_tan"] = formatNumber(kMaxSlopeTan);
    frame.attributes["triangles"] = std::to_string(triangles);
    frame.attributes["sphere_segments"] = std::to_string(sphereSegmentsUsed);
    frame.attributes["shadow_maps"] = std::to_string(frusta.size());
    if (!frusta.empty()) {
        std::string texel, frustum;
        for (std::size_t i = 0; i < frusta.size(); ++i) {
            // A spot map's texel grows with distance: "<size per unit distance>*d".
            texel += (i ? ";" : "") + formatNumber(frusta[i].texelWorldSize()) + (frusta[i].perspective ? "*d" : "");
            frustum += (i ? "; " : "") + frusta[i].describe();
        }
        frame.attributes["texel_world_size"] = texel;
        frame.attributes["light_frustum"] = frustum;
    }
    frame.attributes["cascades"] = std::to_string(cascadesUsed);
    if (!cascadeSplits.empty()) {
        std::string splits, texels;
        for (std::size_t k = 0; k < cascadeSplits.size(); ++k) splits += (k ? ";" : "") + formatNumber(cascadeSplits[k]);
        for (std::size_t k = 0; k < cascadeTexels.size(); ++k) texels += (k ? ";" : "") + formatNumber(cascadeTexels[k]);
        frame.attributes["cascade_splits"] = splits;
        frame.attributes["cascade_texel_world_size"] = texels;
    }
    if (settings.validate) frame.attributes["validation_messages"] = std::to_string(log.count.load());
    if (debug) {
        debug->frusta = frusta;
        debug->layerLight = layerLight;
        debug->layerLabels = layerLabels;
        debug->mapSize = frusta.empty() ? 1u : std::uint32_t(settings.shadowMapSize);
        debug->cascadeSplits = cascadeSplits;
        debug->cascadeTexels = cascadeTexels;
    }
    return frame;
}

}  // namespace shadowlab::raster
