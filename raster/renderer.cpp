// raster/renderer.cpp: puts the passes together: context, geometry upload, shadow maps, lit
// pass, readback into a Frame, timings and metadata.
#include "raster/renderer.h"

#include <algorithm>
#include <array>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <ctime>
#include <map>
#include <memory>
#include <set>
#include <span>
#include <tuple>
#include <variant>

#include "raster/alpha_casters.h"
#include "raster/cascades.h"
#include "raster/context.h"
#include "raster/geometry.h"
#include "raster/lift_free.h"
#include "raster/light_data.h"
#include "raster/light_frustum.h"
#include "raster/lit_pass.h"
#include "raster/moment_maps.h"
#include "raster/shadow_layers.h"
#include "raster/shadow_pass.h"
#include "raster/tolerances.h"
#include "raster/view_cull.h"
#include "scene/camera.h"
#include "scene/frame_io.h"

#include <sys/mman.h>
#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

namespace shadowlab::raster {

namespace {

using Clock = std::chrono::steady_clock;

double msSince(Clock::time_point start) {
    return std::chrono::duration<double, std::milli>(Clock::now() - start).count();
}

// Process CPU time (every thread, lavapipe's included), ms: on a machine shared with other work
// steadier than the wall clock around a pass.
double processCpuMs() {
    timespec t{};
    clock_gettime(CLOCK_PROCESS_CPUTIME_ID, &t);
    return double(t.tv_sec) * 1e3 + double(t.tv_nsec) * 1e-6;
}

std::string formatNumber(double v) {
    char buf[64];
    std::snprintf(buf, sizeof buf, "%.9g", v);
    return buf;
}

// An attribute listing one value per light, layer or cascade: text(item) for each, joined by sep.
template <class T, class Text>
std::string joined(const std::vector<T>& items, Text text, const char* sep = ";") {
    std::string out;
    for (std::size_t i = 0; i < items.size(); ++i) {
        if (i) out += sep;
        out += text(items[i]);
    }
    return out;
}
std::string joinedNumbers(const std::vector<double>& values) {
    return joined(values, [](double v) { return formatNumber(v); });
}

// Whether lit.frag moves the lookup point along the normal: for the user's normal offset, and for
// the slope bias beyond its cap (kMaxSlopeTan) wherever a layer applies its slope bias in the shader.
bool normalOffsetUsed(const scene::RasterSettings& settings, const std::vector<ShadowLayer>& layers) {
    return settings.normalOffset != 0.0 ||
           std::any_of(layers.begin(), layers.end(), [](const ShadowLayer& l) { return l.shaderSlopeBias > 0.0; });
}

// A closed surface: every edge (a pair of positions) is shared by exactly two of its triangles.
// Meshes repeat positions at seams of normals or texture coordinates, so edges are compared by
// position, not by vertex index.
bool isClosed(const SceneGeometry& g, std::size_t first, std::size_t count) {
    std::map<std::array<float, 6>, int> edges;
    auto key = [&](std::uint32_t a, std::uint32_t b) {
        glm::vec3 p = g.vertices[a].position, q = g.vertices[b].position;
        if (std::tie(q.x, q.y, q.z) < std::tie(p.x, p.y, p.z)) std::swap(p, q);
        return std::array<float, 6>{p.x, p.y, p.z, q.x, q.y, q.z};
    };
    for (std::size_t t = first; t < first + count; t += 3)
        for (int e = 0; e < 3; ++e)
            ++edges[key(g.indices[t + std::size_t(e)], g.indices[t + std::size_t((e + 1) % 3)])];
    for (const auto& [edge, uses] : edges)
        if (uses != 2) return false;
    return !edges.empty();
}

// Reorders the triangles: the opaque objects' first (in their order), then each semi-transparent
// object's as one range (returned; `transmittance` = 1 − opacity). Only for a transmittance map.
std::vector<TransparentDraw> separateTransparent(const scene::Scene& scene, SceneGeometry& g,
                                                 std::uint32_t& opaqueIndexCount) {
    std::vector<std::uint32_t> opaque, transparent;
    std::vector<std::vector<std::uint32_t>> perObject(scene.objects.size());
    for (std::size_t t = 0; t + 2 < g.indices.size(); t += 3) {
        const std::uint32_t id = g.vertices[g.indices[t]].objectId;  // object index + 1
        const bool isOpaque = id == 0 || scene.materialOf(scene.objects[id - 1]).opaque();
        std::vector<std::uint32_t>& to = isOpaque ? opaque : perObject[id - 1];
        to.insert(to.end(), g.indices.begin() + std::ptrdiff_t(t), g.indices.begin() + std::ptrdiff_t(t + 3));
    }
    opaqueIndexCount = std::uint32_t(opaque.size());
    std::vector<TransparentDraw> draws;
    g.indices = std::move(opaque);
    for (std::size_t o = 0; o < perObject.size(); ++o) {
        if (perObject[o].empty()) continue;
        TransparentDraw d;
        d.firstIndex = std::uint32_t(g.indices.size());
        d.indexCount = std::uint32_t(perObject[o].size());
        // 1 − opacity (BLEND: 1 − opacity·factor; a textured BLEND's fragments take their own).
        d.transmittance = float(scene.materialOf(scene.objects[o]).transmittance(1.0));
        g.indices.insert(g.indices.end(), perObject[o].begin(), perObject[o].end());
        d.boundsMin = d.boundsMax = g.vertices[perObject[o][0]].position;
        for (const std::uint32_t i : perObject[o]) {
            d.boundsMin = glm::min(d.boundsMin, g.vertices[i].position);
            d.boundsMax = glm::max(d.boundsMax, g.vertices[i].position);
        }
        if (perObject[o].size() / 3 <= kTransmittanceWindowTriangles)
            for (const std::uint32_t i : perObject[o]) d.triangles.push_back(g.vertices[i].position);
        // Quads are open (one surface: every crossing counts); spheres and boxes closed; a mesh
        // by its edges.
        const scene::Shape& shape = scene.objects[o].shape;
        d.closed = std::holds_alternative<scene::Quad>(shape)   ? false
                   : std::holds_alternative<scene::Mesh>(shape) ? isClosed(g, d.firstIndex, d.indexCount)
                                                                : true;
        draws.push_back(d);
    }
    return draws;
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
        default: return scene::toString(f);  // the filterable maps
    }
}

}  // namespace

static_assert(SHADOWLAB_MAX_CASCADES == scene::kMaxCascades, "shaders/interface.h and scene/settings.h disagree");

struct Renderer::Impl {
    Impl(const scene::Scene& scene, const scene::RenderPlan& plan, const scene::RasterSettings& settingsIn,
         const RendererOptions& options, ValidationLog& log);
    void render(scene::Frame& frame, scene::ChannelMask channels, const ValidationLog& log, RenderDebug* debug);
    // The Frame's vectors for `channels` sized (the others emptied), and where each plane of the
    // frame's pipeline is rendered: `frameImages` over the Frame's vectors where possible (their
    // planes set in `intoFrame`), the Renderer's own targets for the rest.
    // Returns true where every attachment already holds the background (see there): a new plane
    // of the Frame, or a per-light target before its first frame, zeroed on the host. The lit pass
    // then draws no background.
    bool prepareFrame(scene::Frame& frame, scene::ChannelMask channels, LitOutputs outputs, LitAttachments& attachments,
                      std::vector<Image>& frameImages, std::array<bool, kLitPlanes>& intoFrame);
    void readPixels(scene::Frame& frame, scene::ChannelMask channels,
                    const std::array<bool, kLitPlanes>& intoFrame) const;
    void readDisplayPixels(scene::Frame& frame) const;
    void invalidateMemory(VkDeviceMemory memory) const {
        const VkMappedMemoryRange range{
            .sType = VK_STRUCTURE_TYPE_MAPPED_MEMORY_RANGE, .memory = memory, .size = VK_WHOLE_SIZE};
        VK_CHECK(vkInvalidateMappedMemoryRanges(ctx.device.get(), 1, &range));
    }
    void flushMemory(VkDeviceMemory memory) const {
        const VkMappedMemoryRange range{
            .sType = VK_STRUCTURE_TYPE_MAPPED_MEMORY_RANGE, .memory = memory, .size = VK_WHOLE_SIZE};
        VK_CHECK(vkFlushMappedMemoryRanges(ctx.device.get(), 1, &range));
    }

    scene::RasterSettings settings;
    std::uint32_t width = 0;
    std::uint32_t height = 0;
    std::size_t lightCount = 0;
    std::uint32_t lightKinds = 0;  // bit 1 << SHADOWLAB_LIGHT_* per kind present
    glm::vec3 background{0.0f};
    std::map<std::string, std::string> attributes;  // what every frame of this scene records
    // The shadow-map layers (planShadowLayers), in the array's order; what follows is derived.
    std::vector<ShadowLayer> layers;
    std::vector<glm::mat4> lightMatrices;  // per layer, recordShadowPass's input
    // The split depths of the cascades (cascadeSplits(layers)); empty without cascades.
    std::vector<double> splits;
    int cascadesUsed = 1;  // lit.frag's cascade count (specialization constant)
    // The blend band before each split (settings.cascadeBlend), 0 without cascades: when > 0,
    // lit.frag's blend code is compiled in (specialization constant) and reads it from cascadeBlendBand.
    double cascadeBlendUsed = 0.0;
    bool vertexLightConstants = false;  // LitVariant::vertexLightConstants of every lit pipeline
    // LitVariant::specializedLightConstants of the lit pipelines made from now on, and the values the
    // existing ones baked in; update() turns it off when the values change (RendererOptions::lightConstants).
    bool specializedLightConstants = false;
    bool bakedAtConstruction = false;  // setBiases() bakes the new values in again
    bool everyLightBaked = false;      // bakesEveryLight() of the lit pipelines, where they bake
    std::array<float, kPackedLightConstants> bakedLightConstants{};
    bool renderIntoFrame = true;       // RendererOptions::renderIntoFrame
    bool transmittanceWindows = true;  // RendererOptions::transmittanceWindows
    bool oneLightModules = true;       // RendererOptions::oneLightModules
    double setupMs = 0.0;
    double pendingSetupMs = 0.0;  // setup not yet reported in a frame (the constructor's)

    // Vulkan objects in creation order (destroyed in reverse); the context first.
    Context ctx;
    Buffer vertexBuffer;
    Buffer indexBuffer;
    AlphaCasters alpha;          // where an alpha test can cut (set == VK_NULL_HANDLE otherwise)
    bool transmitAlpha = false;  // the transmittance passes' alpha shaders (AlphaPlan::transmittanceReads)
    DrawGeometry draw;
    ShadowMaps maps;
    LitTargets targets;
    // Per target of `targets` (the planes, then the light targets): whether a frame has rendered
    // into it, its pages faulted in or, a light target's under a new Frame, zeroed first (prepareFrame).
    std::vector<bool> ownTargetsTouched;
    Readback readback;
    bool timestamps = false;
    QueryPoolHandle queries;
    // Made on first use. Shadow: without and with blocker ids (index 0, 1). Lit: beauty target
    // only, all targets without blocker ids, all with, the display target only (index 0..3). The
    // second index: without the alpha test, with it (DrawObject::depthAlpha, cameraAlpha).
    ShadowPipeline shadowPipelines[2][2];
    // Semi-transparent casters (RenderPlan::needsTransmittanceMap): the transmittance pass, its
    // maps (1x1x1 placeholders without), and per layer the light it is drawn from.
    bool transmit = false;
    ShadowPipeline transmitPipeline;
    TransmittanceMaps transmittanceMaps;
    TransmittanceRestPipeline transmitRestPipeline;  // the second pass, bound to transmittanceMaps
    // Filterable maps (scene::isFilterable): the moment arrays (1x1x1 placeholders without) and
    // their compute passes, made with the first frame's pipelines.
    MomentMaps momentMaps;
    MomentPipeline momentPipeline;
    std::vector<glm::vec4> layerLights;             // per layer, its light (TransmittancePass)
    std::vector<TexelRect> transmitWindows;         // per layer, its window (TransmittancePass)
    shaders::TransmitWindows transmitWindowData{};  // the same for lit.frag (LitBindings)
    std::vector<DepthBiasFactors> layerBias;        // per layer, recordShadowPass's input (settings.hardwareBias)
    // Per layer, the texels its depth pass clears and draws (layerReadWindow); empty: whole layers.
    std::vector<TexelRect> shadowWindows;
    // Per layer, the texels the lit pass's lookups read (layerLookupWindow): the moment passes'.
    std::vector<TexelRect> lookupWindows;
    LitPipeline litPipelines[4][2];
    // The same four without the slope bias's lift past its cap (LitVariant::normalOffset false, no
    // alpha test), for the lift-free triangles (draw.litRangesByLift), with the *_sun modules.
    LitPipeline liftFreePipelines[4];
    // Lit pipelines with light constants baked in that update() replaced; kept until the Renderer
    // goes, as the descriptor set was allocated with one of their (identical) set layouts.
    std::vector<LitPipeline> retiredLitPipelines;
    bool liftFreeDraws = true;  // RendererOptions::liftFreeDraws
    // The vertex normals, positions and the index buffer as uploaded, for the lift-free triangles (placeLights);
    // kept only where they can be used (liftFreeDraws).
    std::vector<glm::vec3> hostNormals;
    std::vector<glm::vec3> hostPositions;  // camera-relative, as the vertex buffer (the runs' pixel areas)
    std::vector<std::uint32_t> hostIndices;
    void splitByLift();  // draw.litRangesByLift for the current lights
    // The index buffer's clusters (raster/view_cull.h), made once, and their world boxes: the
    // draw's camera-visible ranges from them for the current view (RendererOptions::viewCull), and
    // each culled layer's casters cut to the clusters that can cast onto its receivers.
    std::vector<IndexCluster> clusters;
    std::vector<scene::Bounds> clusterBoxes;
    bool viewCull = true;  // RendererOptions::viewCull
    void cullToView();
    // The vertices' lift-free bits (liftFreeVertexBits) and the lights and threshold they were made for.
    std::vector<std::uint32_t> liftBits;
    std::vector<glm::vec3> liftBitsLights;
    double liftBitsThreshold = -1.0;
    LitBindings bindings;  // allocated with the first lit pipeline's (identical) set layout
    shaders::LitUniforms uniforms{};
    std::vector<glm::vec4> albedos;

    // What update() needs to redo the per-camera, per-light part of the setup (placeLights).
    scene::Vec3 origin{0.0};  // the first camera's position: the vertex buffer is relative to it
    scene::RenderPlan plan;
    std::vector<std::uint32_t> objectFirstIndex;
    // The objects in index-buffer order, where each one's triangles are and which passes test its
    // alpha (the constructor); placeLights() draws the depth pass's ranges from them.
    struct DrawObject {
        std::uint32_t object = 0;
        std::uint32_t first = 0, count = 0;
        bool depthAlpha = false;   // a MASK caster that can cut: the depth pass's alpha-tested pipeline
        bool cameraAlpha = false;  // MASK or BLEND that can cut: the lit pass's alpha-tested pipeline
        bool depthPass = true;     // drawn by the depth pass (not a semi-transparent caster)
    };
    std::vector<DrawObject> drawObjects;
    std::size_t triangles = 0;
    int sphereSegmentsUsed = 0;
    // The view depth of the camera the image is drawn from minus the depth the shaders compute
    // relative to `origin` (0 for the first camera): added to Z on readback, taken off the
    // cascade splits (update()).
    double viewDepthOffset = 0.0;
    double pendingUpdateMs = 0.0;  // the last update()'s time, reported by the next frame as "update"
    // The layers (light frusta, cascades, caster culling) and the lit pass's uniforms for `scene`
    // (its camera fits the maps) drawn from `view`.
    void placeLights(const scene::Scene& scene, const scene::Camera& view);
    void setLayerLights(const scene::Scene& scene);  // layerLights from layers
    // The rest of the constructor: shadow maps, targets, readback, queries, attributes.
    void createTargets(const scene::Scene& scene, const RendererOptions& options);
    void describeLayers();           // the attributes that follow the frusta
    void describeTransmitWindows();  // transmittance_windows: each layer's window (x0,y0,x1,y1 or none)
    void update(const scene::Scene& scene, const scene::Camera& view);
    void setBiases(const scene::Scene& scene, double depthBias, double slopeBias);
    void retireLitPipelines();  // into retiredLitPipelines: the next frame makes them again
};

Renderer::Impl::Impl(const scene::Scene& scene, const scene::RenderPlan& planIn,
                     const scene::RasterSettings& settingsIn, const RendererOptions& options, ValidationLog& log)
    : settings(settingsIn),
      ctx((checkSupported(scene, settingsIn),
           ContextOptions{.device = settingsIn.device, .validate = settingsIn.validate, .log = &log})) {
    const auto setupStart = Clock::now();
    transmittanceWindows = options.transmittanceWindows;
    origin = scene::cameraBasis(scene.camera).position;  // camera-relative rendering
    width = std::uint32_t(scene.camera.width);
    height = std::uint32_t(scene.camera.height);
    lightCount = scene.lights.size();
    background = glm::vec3(scene.background);
    attributes["device"] = ctx.deviceReport.name;

    // Which objects' alpha tests can cut, per material: the depth pass's (MASK) and the camera's; a
    // test that never cuts is left out (idleAlphaTestsLeftOut). UVs and alpha records only where a
    // test can cut, or where the transmittance passes read a textured BLEND caster's alpha.
    const AlphaPlan alphaPlan = planAlpha(scene, planIn.needsTransmittanceMap, options.idleAlphaTestsLeftOut);
    const bool alphaData = alphaPlan.data;
    SceneGeometry geometry = tessellateScene(scene, origin, alphaData);
    std::vector<TransparentDraw> transparentDraws;
    std::uint32_t opaqueIndexCount = ~0u;
    if (planIn.needsTransmittanceMap) transparentDraws = separateTransparent(scene, geometry, opaqueIndexCount);
    triangles = geometry.triangleCount();
    sphereSegmentsUsed = geometry.maxSphereSegments;
    objectFirstIndex = geometry.objectFirstIndex;
    plan = planIn;
    // Device-local, uploaded once for every frame of this Renderer.
    vertexBuffer = uploadBuffer(ctx, geometry.vertices, VK_BUFFER_USAGE_VERTEX_BUFFER_BIT);
    // Lift-free draws need the *_sun modules (one directional light, none or pcf2x2, no
    // semi-transparent casters, no receiver plane) and no normal offset asked for.
    liftFreeDraws = options.liftFreeDraws && options.oneLightModules && scene.lights.size() == 1 &&
                    scene.lights[0].type == scene::LightType::Directional &&
                    (settings.filter == scene::ShadowFilter::None || settings.filter == scene::ShadowFilter::Pcf2x2) &&
                    !settings.receiverPlaneBias && !planIn.needsTransmittanceMap && settings.normalOffset == 0.0;
    if (liftFreeDraws) {
        hostNormals.reserve(geometry.vertices.size());
        hostPositions.reserve(geometry.vertices.size());
        for (const Vertex& v : geometry.vertices) {
            hostNormals.push_back(v.normal);
            hostPositions.push_back(v.position);
        }
        hostIndices = geometry.indices;
    }
    indexBuffer = uploadBuffer(ctx, geometry.indices, VK_BUFFER_USAGE_INDEX_BUFFER_BIT);
    draw = DrawGeometry{vertexBuffer.buffer.get(), indexBuffer.buffer.get(), std::uint32_t(geometry.indices.size()),
                        opaqueIndexCount, transparentDraws};
    if (alphaData) {
        alpha = createAlphaCasters(ctx, scene, geometry);
        draw.uvs = alpha.uvs.buffer.get();
        draw.alphaSet = alpha.descriptors.set;
        transmitAlpha = alphaPlan.transmittanceReads;
    }
    // Each object's triangles in the index buffer (reordered with a transmittance map: the opaque
    // objects' first, in object order, then each semi-transparent one's) and the objects in that
    // order; which pass tests its alpha: the depth pass a MASK caster's, the camera MASK and BLEND.
    drawObjects.clear();
    const std::size_t objectCount = scene.objects.size();
    std::uint32_t opaqueCursor = 0;
    std::size_t nextTransparent = 0;
    std::vector<DrawObject> transparentObjects;
    for (std::size_t o = 0; o < objectCount; ++o) {
        const scene::Material& m = scene.materialOf(scene.objects[o]);
        const AlphaTests tests = alphaPlan.byMaterial[std::size_t(scene.objects[o].material)];
        DrawObject d{.object = std::uint32_t(o),
                     .first = objectFirstIndex[o],
                     .count = objectFirstIndex[o + 1] - objectFirstIndex[o],
                     .depthAlpha = tests.depth,
                     .cameraAlpha = tests.camera,
                     .depthPass = true};
        if (planIn.needsTransmittanceMap && !m.opaque()) {
            if (d.count == 0) continue;                                // (separateTransparent makes no draw for it)
            d.first = transparentDraws[nextTransparent++].firstIndex;  // (in object order)
            d.depthPass = false;
            transparentObjects.push_back(d);
            continue;
        }
        if (planIn.needsTransmittanceMap) {
            d.first = opaqueCursor;
            opaqueCursor += d.count;
        }
        drawObjects.push_back(d);
    }
    drawObjects.insert(drawObjects.end(), transparentObjects.begin(), transparentObjects.end());
    if (std::any_of(drawObjects.begin(), drawObjects.end(),
                    [](const DrawObject& d) { return d.depthAlpha && d.depthPass; }))
        attributes["alpha_casters"] = "alpha-tested in the depth pass";  // only where a test can cut
    for (const DrawObject& d : drawObjects) {
        if (!draw.litRanges.empty() && draw.litRanges.back().alpha == d.cameraAlpha &&
            draw.litRanges.back().first + draw.litRanges.back().count == d.first)
            draw.litRanges.back().count += d.count;
        else
            draw.litRanges.push_back(IndexRange{d.first, d.count, d.cameraAlpha});
    }
    viewCull = options.viewCull;
    {
        std::vector<IndexRange> pieces;
        for (const DrawObject& d : drawObjects) pieces.push_back(IndexRange{d.first, d.count});
        clusters = indexClusters(geometry.vertices, geometry.indices, pieces, kViewCullClusterTriangles);
        clusterBoxes = worldBoxes(clusters, origin);
    }

    // The automatic choices: a default cascade count follows the view, then a default size follows
    // the receivers' and casters' detail, and a default constant bias follows the size.
    CascadeChoice cascadeChoice;
    ShadowMapSizeChoice mapChoice;
    settings = resolveAutomaticChoices(scene, settings, &plan, &cascadeChoice, &mapChoice);
    attributes["shadow_map_size_reason"] = mapChoice.reason;
    if (mapChoice.needed > 0.0) attributes["shadow_map_size_needed"] = std::to_string(int(std::ceil(mapChoice.needed)));
    attributes["cascades_reason"] = cascadeChoice.reason;
    placeLights(scene, scene.camera);
    createTargets(scene, options);
    setupMs = msSince(setupStart);
    pendingSetupMs = setupMs;
}

void Renderer::Impl::placeLights(const scene::Scene& scene, const scene::Camera& view) {
    const scene::CameraBasis cam = scene::cameraBasis(view);
    draw.layerRanges.clear();
    cascadesUsed = 1;
    lightKinds = 0;
    std::fill(std::begin(uniforms.lights), std::end(uniforms.lights), shaders::LightData{});
    std::fill(std::begin(uniforms.cascades), std::end(uniforms.cascades), shaders::CascadeData{});
    // Cascades are chosen by the view depth of the camera the maps are fitted for (scene.camera):
    // which cascade a point reads is part of that camera's shadow setup, also when the image is
    // drawn from another view (a held view); the Frame's Z is that depth too.
    const scene::CameraBasis fitCam = scene::cameraBasis(scene.camera);
    viewDepthOffset = glm::dot(origin - fitCam.position, fitCam.forward);

    layers = planShadowLayers(scene, plan, settings, origin);
    lightMatrices.clear();
    layerBias.clear();
    for (const ShadowLayer& layer : layers) {
        lightMatrices.push_back(layer.matrix);
        layerBias.push_back(layer.hardwareBias);
    }
    splits = cascadeSplits(layers);

    const glm::dmat4 viewProj = scene::projectionMatrix(cam, view.near, view.far) * scene::viewMatrix(cam, origin);
    uniforms.viewProj = glm::mat4(viewProj);
    uniforms.forward = glm::vec3(fitCam.forward);
    uniforms.ambient = float(scene.ambient);
    uniforms.background = glm::vec3(scene.background);
    uniforms.lightCount = int(scene.lights.size());
    uniforms.mapSize = 0.0f;
    uniforms.cascadeBlendBand = 0.0f;
    uniforms.cascadeStart = 0.0f;
    for (std::size_t i = 0; i < scene.lights.size(); ++i) {
        const std::span<shaders::CascadeData, SHADOWLAB_MAX_CASCADES> cascades(
            uniforms.cascades + i * SHADOWLAB_MAX_CASCADES, SHADOWLAB_MAX_CASCADES);
        const shaders::LightData& l = uniforms.lights[i] =
            lightData(scene.lights[i], int(i), layers, settings, origin, viewDepthOffset, cascades);
        lightKinds |= 1u << l.kind;
        if (l.cascadeCount > 0) cascadesUsed = l.cascadeCount;
    }
    albedos.clear();
    for (const scene::Object& o : scene.objects)
        // a: 1 − opacity, divided out of a semi-transparent receiver's own transmittance (lit.frag).
        albedos.emplace_back(glm::vec3(scene.materialOf(o).albedo),
                             scene.materialOf(o).opaque() ? 1.0f : float(scene.materialOf(o).transmittance(1.0)));
    // Each layer's index ranges: every object the depth pass draws, or the culled layer's casters,
    // in index order, runs of them merged where they take the same pipeline; a culled layer's then
    // cut to the clusters that can cast onto its receivers (an object's box can reach them while
    // most of its triangles cannot: a large ground, a building's far wing).
    std::vector<int> trianglesPerLayer;
    for (std::size_t k = 0; k < layers.size(); ++k) {
        std::vector<IndexRange> ranges;
        const std::vector<bool>& casters = layers[k].casters;
        for (const DrawObject& d : drawObjects) {
            if (!d.depthPass || (!casters.empty() && !casters[d.object])) continue;
            if (!ranges.empty() && ranges.back().alpha == d.depthAlpha &&
                ranges.back().first + ranges.back().count == d.first)
                ranges.back().count += d.count;
            else
                ranges.push_back(IndexRange{d.first, d.count, d.depthAlpha});
        }
        if (!casters.empty() && !clusters.empty())
            ranges = intersectRanges(ranges, keptIndexRuns(clusters, layerCastingBoxes(layers[k], clusterBoxes)));
        std::uint64_t indices = 0;
        for (const IndexRange& r : ranges) indices += r.count;
        trianglesPerLayer.push_back(int(indices / 3));
        draw.layerRanges.push_back(std::move(ranges));
    }
    std::vector<int> culledPerLight(scene.lights.size(), 0), culledPerLayer;
    for (const ShadowLayer& layer : layers) {
        culledPerLight[std::size_t(layer.light)] += layer.culled;
        culledPerLayer.push_back(layer.culled);
    }
    const auto count = [](int n) { return std::to_string(n); };
    attributes["culled_casters"] = joined(culledPerLight, count);
    // Per layer (in layer order, as shadow_maps and light_frustum list them), when a light has more
    // than one (cascades, cube faces).
    std::set<int> shadowed;
    for (const ShadowLayer& layer : layers) shadowed.insert(layer.light);
    if (layers.size() > shadowed.size()) attributes["culled_casters_per_layer"] = joined(culledPerLayer, count);
    // The triangles each layer's depth pass draws, in layer order (opaque casters; the
    // transmittance pass draws the semi-transparent ones).
    attributes["shadow_triangles_per_layer"] = joined(trianglesPerLayer, count);
    // Each layer's depth pass clears and draws only the texels its receivers can read
    // (layerReadWindow), but not for a held view (update() with another view than scene.camera,
    // whose receivers the layers were not planned for: it would read texels no pass drew).
    const bool heldView = view.position != scene.camera.position || view.lookAt != scene.camera.lookAt ||
                          view.up != scene.camera.up || view.fovYDegrees != scene.camera.fovYDegrees ||
                          view.near != scene.camera.near || view.far != scene.camera.far ||
                          view.width != scene.camera.width || view.height != scene.camera.height;
    shadowWindows.clear();
    lookupWindows.clear();
    std::vector<std::uint64_t> texelsPerLayer;
    for (const ShadowLayer& layer : layers) {
        const auto size = std::uint32_t(layer.frustum.mapSize);
        const TexelRect whole{0, 0, size, size};
        const TexelRect w = heldView ? whole : layerReadWindow(layer);
        shadowWindows.push_back(w);
        lookupWindows.push_back(heldView ? whole : layerLookupWindow(layer));
        texelsPerLayer.push_back(w.area());
    }
    attributes["shadow_texels_per_layer"] = joined(texelsPerLayer, [](std::uint64_t n) { return std::to_string(n); });
    splitByLift();
    cullToView();
}

void Renderer::Impl::cullToView() {
    draw.litCulled = viewCull && !clusters.empty();
    if (!draw.litCulled) return;
    const std::vector<IndexRange> visible = visibleIndexRuns(clusters, uniforms.viewProj);
    draw.litRangesVisible = intersectRanges(draw.litRanges, visible);
    draw.litRangesByLiftVisible = intersectRanges(draw.litRangesByLift, visible);
}

void Renderer::Impl::splitByLift() {
    draw.litRangesByLift.clear();
    // Only directional lights (N·L constant over a triangle's plane of normals), and only where the
    // lift is the one use of the normal-offset path.
    if (hostNormals.empty() || lightKinds != (1u << SHADOWLAB_LIGHT_DIRECTIONAL) || settings.normalOffset != 0.0 ||
        !normalOffsetUsed(settings, layers))
        return;
    std::vector<glm::vec3> towardLights;  // the lights whose shadow test applies the slope bias in the shader
    for (std::size_t i = 0; i < lightCount; ++i) {
        const shaders::LightData& l = uniforms.lights[i];
        if (l.layer >= 0.0f && l.slopeBiasTexels > 0.0f) towardLights.push_back(l.towardLight);
    }
    // The vertices' bits depend on the lights alone: a camera that moves reuses them.
    const double threshold = liftFreeThreshold(double(uniforms.lights[0].maxSlopeTan));
    if (towardLights != liftBitsLights || threshold != liftBitsThreshold || liftBits.empty()) {
        liftBits = liftFreeVertexBits(hostNormals, towardLights, threshold);
        liftBitsLights = towardLights;
        liftBitsThreshold = threshold;
    }
    std::vector<IndexRange> ranges = raster::splitByLift(
        liftBits, hostIndices, draw.litRanges, pixelAreas(hostPositions, hostIndices, uniforms.viewProj, width, height),
        kLiftFreeMinPixels);
    if (std::any_of(ranges.begin(), ranges.end(), [](const IndexRange& r) { return r.liftFree; }))
        draw.litRangesByLift = std::move(ranges);
}

void Renderer::Impl::setLayerLights(const scene::Scene& scene) {
    layerLights.clear();
    transmitWindows.clear();
    shaders::TransmitWindows& windows = transmitWindowData;
    windows = shaders::TransmitWindows{};
    for (std::size_t k = 0; k < layers.size() && transmit; ++k) {
        const std::uint32_t size = std::uint32_t(settings.shadowMapSize);
        transmitWindows.push_back(transmittanceWindows ? transmittanceWindow(lightMatrices[k], draw.transparent, size)
                                                       : TexelRect{0, 0, size, size});
        const TexelRect& w = transmitWindows.back();
        windows.rect[k] = glm::vec4(float(w.x0), float(w.y0), float(w.x1), float(w.y1));
    }
    for (const ShadowLayer& layer : layers) {
        const scene::Light& light = scene.lights[std::size_t(layer.light)];
        layerLights.push_back(light.type == scene::LightType::Directional
                                  ? glm::vec4(glm::vec3(-glm::normalize(light.direction)), 0.0f)
                                  : glm::vec4(glm::vec3(light.position - origin), 1.0f));
    }
}

void Renderer::Impl::createTargets(const scene::Scene& scene, const RendererOptions& options) {
    // Without a shadowed light a 1x1 cleared layer keeps the descriptor valid.
    const auto mapSize = layers.empty() ? 1u : std::uint32_t(settings.shadowMapSize);
    const auto arrayLayers = std::max<std::uint32_t>(1, std::uint32_t(layers.size()));
    maps = createShadowMaps(ctx, mapSize, arrayLayers);
    uniforms.mapSize = float(mapSize);  // lit.frag's map size, instead of a textureSize() per fragment
    if (cascadesUsed > 1 && settings.cascadeBlend > 0.0) {
        cascadeBlendUsed = settings.cascadeBlend;
        uniforms.cascadeBlendBand = float(cascadeBlendUsed);
        uniforms.cascadeStart = float(splits[0] - viewDepthOffset);  // cascade 0's slice starts here (the band's width)
    }
    transmit = !draw.transparent.empty() && !layers.empty();
    transmittanceMaps = createTransmittanceMaps(ctx, transmit ? mapSize : 1, transmit ? arrayLayers : 1);
    setLayerLights(scene);
    attributes["transmittance_map"] = transmit ? "made" : "none";
    describeTransmitWindows();
    const bool moments = scene::isFilterable(settings.filter) && !layers.empty();
    momentMaps = createMomentMaps(ctx, moments ? mapSize : 1, moments ? arrayLayers : 1);
    if (moments)
        attributes["moment_maps"] =
            describeMomentCost(settings.filter, mapSize, arrayLayers, settings.moments.blurWidth);
    targets = createLitTargets(ctx, width, height, lightCount > 1 ? std::uint32_t(lightCount + 3) / 4 : 0,
                               options.readTargetsInPlace);
    ownTargetsTouched.assign(kLitPlanes + targets.lights.size(), false);
    renderIntoFrame = options.renderIntoFrame;
    oneLightModules = options.oneLightModules;
    if (!targets.hostReadable) readback = createReadback(ctx, targets);
    // How the targets reach the Frame: read in place (lavapipe) or copied into buffers first.
    attributes["readback"] = targets.hostReadable ? "in-place" : "copy";
    // GPU timestamps around each pass, where the queue has them (a bonus to the CPU clock,
    // which also counts submission and the fence wait).
    timestamps = ctx.properties.limits.timestampComputeAndGraphics == VK_TRUE;
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

    // Where lit.frag reads the light's constants (RendererOptions::lightConstants).
    const LitVariant lights{.lightCount = std::uint32_t(lightCount),
                            .lightKinds = lightKinds,
                            .cascades = std::uint32_t(cascadesUsed),
                            .receiverPlane = settings.receiverPlaneBias};
    vertexLightConstants = hasOneMapLight(lights) && options.lightConstants != LightConstants::kUniformBuffer;
    // Light 0's alone where it is the one light lit.vert can carry, else every light's.
    specializedLightConstants = (bakesLightConstants(lights) || bakesEveryLight(lights)) &&
                                options.lightConstants == LightConstants::kSpecialization;
    bakedAtConstruction = specializedLightConstants;
    everyLightBaked = bakesEveryLight(lights);
    bakedLightConstants = packLightConstants(uniforms, everyLightBaked);
    attributes["light_constants"] = specializedLightConstants ? "specialization"
                                    : vertexLightConstants    ? "vertex-outputs"
                                                              : "uniform-buffer";
    describeLayers();
}

void Renderer::Impl::describeTransmitWindows() {
    if (!transmit) return;
    attributes["transmittance_windows"] = joined(transmitWindows, [](const TexelRect& w) {
        return w.empty() ? std::string("none")
                         : std::to_string(w.x0) + "," + std::to_string(w.y0) + "," + std::to_string(w.x1) + "," +
                               std::to_string(w.y1);
    });
}

void Renderer::Impl::describeLayers() {
    attributes["backend"] = scene::toString(scene::Backend::Raster);
    attributes["shadow_map_size"] = std::to_string(settings.shadowMapSize);
    attributes["filter"] = filterName(settings.filter);
    if (settings.filter == scene::ShadowFilter::Pcf || settings.filter == scene::ShadowFilter::Poisson ||
        settings.filter == scene::ShadowFilter::Pcss)
        attributes["pcf_size"] = std::to_string(settings.pcfSize);
    if (scene::isFilterable(settings.filter)) {
        const scene::MomentSettings& m = settings.moments;
        attributes["blur_width"] = std::to_string(m.blurWidth);
        if (settings.filter == scene::ShadowFilter::Vsm || settings.filter == scene::ShadowFilter::Evsm2 ||
            settings.filter == scene::ShadowFilter::Evsm4) {
            attributes["min_variance"] = formatNumber(m.minVariance);
            attributes["light_bleeding_reduction"] = formatNumber(m.bleedReduction);
        }
        if (settings.filter == scene::ShadowFilter::Evsm2 || settings.filter == scene::ShadowFilter::Evsm4)
            attributes["evsm_positive_exponent"] = formatNumber(m.evsmPositive);
        if (settings.filter == scene::ShadowFilter::Evsm4)
            attributes["evsm_negative_exponent"] = formatNumber(m.evsmNegative);
        if (settings.filter == scene::ShadowFilter::Esm) attributes["esm_exponent"] = formatNumber(m.esmExponent);
        if (settings.filter == scene::ShadowFilter::Msm) attributes["moment_bias"] = formatNumber(m.momentBias);
    }
    attributes["normal_offset"] = formatNumber(settings.normalOffset);
    attributes["light_frustum_fit"] = settings.fitLightFrustum ? "receivers" : "bounding-sphere";
    attributes["light_frustum_fit_reason"] =
        settings.fitLightFrustumIsDefault ? "default" : "set by --fit-light-frustum, the scene or code";
    if (!settings.snapLightFrustum) attributes["light_frustum_snap"] = "off";
    // The constant bias actually used: one value, or one per shadow-mapped light (';'; per cascade;
    // point lights keep the setting) when a default was re-derived per fitted map and the maps differ.
    std::vector<double> usedDepthBias;
    for (const ShadowLayer& layer : layers)
        if (layer.reason != LayerReason::kCubeFace) usedDepthBias.push_back(layer.depthBias);
    const bool oneBias =
        std::all_of(usedDepthBias.begin(), usedDepthBias.end(), [&](double b) { return b == usedDepthBias[0]; });
    attributes["depth_bias"] = usedDepthBias.empty() ? formatNumber(settings.depthBias)
                               : oneBias             ? formatNumber(usedDepthBias[0])
                                                     : joinedNumbers(usedDepthBias);
    attributes["depth_bias_default"] = settings.depthBiasIsDefault ? "true" : "false";
    attributes["slope_bias"] = formatNumber(settings.slopeBias);
    // The slope bias that lit.frag continues along the normal past max_slope_tan (texels; its lift
    // is that x texel x max(0, sin θ − max_slope_tan·cos θ)): the shader's slope bias, 0 in layers
    // whose slope bias the rasterizer applies. One value, or one per layer where they differ.
    std::vector<double> grazing;
    for (const ShadowLayer& layer : layers) grazing.push_back(layer.shaderSlopeBias);
    const bool oneGrazing = std::all_of(grazing.begin(), grazing.end(), [&](double g) { return g == grazing[0]; });
    attributes["grazing_normal_offset"] = grazing.empty() ? "0"
                                          : oneGrazing    ? formatNumber(grazing[0])
                                                          : joinedNumbers(grazing);
    // On, the receiver's plane replaces the slope term in every tap (lit.frag), so slope_bias is unused.
    attributes["receiver_plane_bias"] = settings.receiverPlaneBias ? "true" : "false";
    // Where the constant and slope bias are applied, and with the hardware bias the factors each
    // directional layer's depth pass was given (docs/raster.md "Hardware depth bias").
    attributes["bias_mode"] = settings.hardwareBias ? "hardware" : "shader";
    if (settings.hardwareBias) {
        attributes["hardware_depth_bias_constant_factor"] =
            joined(layerBias, [](const DepthBiasFactors& b) { return formatNumber(b.constant); });
        attributes["hardware_depth_bias_slope_factor"] =
            joined(layerBias, [](const DepthBiasFactors& b) { return formatNumber(b.slope); });
        attributes["hardware_depth_bias_unit"] =
            "r = 2^-24 (D32_SFLOAT, depths in [0.5, 1)); spot and point layers 0: they keep the shader bias";
    }
    attributes["max_slope_tan"] = formatNumber(kMaxSlopeTan);
    attributes["triangles"] = std::to_string(triangles);
    attributes["sphere_segments"] = std::to_string(sphereSegmentsUsed);
    attributes["shadow_maps"] = std::to_string(layers.size());
    if (!layers.empty()) {
        // A spot map's texel grows with distance: "<size per unit distance>*d".
        attributes["texel_world_size"] = joined(layers, [](const ShadowLayer& l) {
            return formatNumber(l.frustum.texelWorldSize()) + (l.frustum.perspective ? "*d" : "");
        });
        attributes["light_frustum"] = joined(
            layers, [](const ShadowLayer& l) { return l.frustum.describe(); }, "; ");
        // Where a perspective map's texel grows from: its apex and unit axis in world coordinates,
        // "x,y,z,dx,dy,dz", so that compare takes the texel at a pixel's distance (p − apex)·axis
        // (docs/compare.md, contact distance); "-" for an orthographic map.
        attributes["texel_axis"] = joined(layers, [](const ShadowLayer& l) {
            if (!l.frustum.perspective) return std::string("-");
            const scene::Vec3 a = l.frustum.position, d = l.frustum.direction;
            char buf[160];
            std::snprintf(buf, sizeof buf, "%.9g,%.9g,%.9g,%.9g,%.9g,%.9g", a.x, a.y, a.z, d.x, d.y, d.z);
            return std::string(buf);
        });
    }
    attributes["cascades"] = std::to_string(cascadesUsed);
    if (!splits.empty()) {
        attributes["cascade_splits"] = joinedNumbers(splits);
        attributes["cascade_texel_world_size"] = joinedNumbers(cascadeTexels(layers));
        attributes["cascade_blend"] = formatNumber(cascadeBlendUsed);
    }
}

void Renderer::Impl::update(const scene::Scene& scene, const scene::Camera& view) {
    if (scene.lights.size() != lightCount || scene.objects.size() + 1 != objectFirstIndex.size() ||
        std::uint32_t(view.width) != width || std::uint32_t(view.height) != height)
        throw RasterError(
            "Renderer::update: the scene must keep the objects, the number of lights and the "
            "resolution the Renderer was made for");
    const auto updateStart = Clock::now();
    const std::size_t layerCount = lightMatrices.size();
    const int cascadeCount = cascadesUsed;
    const std::uint32_t kinds = lightKinds;
    const float mapSize = uniforms.mapSize, cascadeBlendBand = uniforms.cascadeBlendBand;
    placeLights(scene, view);
    // The maps, pipelines and descriptor set were made for this many layers of these kinds.
    if (lightMatrices.size() != layerCount || cascadesUsed != cascadeCount || lightKinds != kinds)
        throw RasterError("Renderer::update: the new camera or lights change the number of shadow-map layers (" +
                          std::to_string(layerCount) + " -> " + std::to_string(lightMatrices.size()) +
                          ") or cascades; make a new Renderer");
    uniforms.mapSize = mapSize;
    if (cascadeBlendUsed > 0.0) {
        uniforms.cascadeBlendBand = cascadeBlendBand;
        uniforms.cascadeStart = float(splits[0] - viewDepthOffset);
    }
    setLayerLights(scene);
    const std::array<float, kPackedLightConstants> packed = packLightConstants(uniforms, everyLightBaked);
    if (specializedLightConstants && std::memcmp(packed.data(), bakedLightConstants.data(), sizeof packed) != 0) {
        // The values baked into the lit pipelines changed: from now on lit.vert passes them, or
        // (cascades, every light baked) the uniform buffer (a moving light or camera would otherwise compile new
        // pipelines every frame).
        specializedLightConstants = false;
        attributes["light_constants"] = vertexLightConstants ? "vertex-outputs" : "uniform-buffer";
        retireLitPipelines();
    }
    describeLayers();
    describeTransmitWindows();
    // The descriptor set's uniform buffers are device-local: refill them through a staging buffer.
    if (bindings.uniforms.buffer) {
        Buffer staging =
            createBuffer(ctx, sizeof uniforms + sizeof transmitWindowData, VK_BUFFER_USAGE_TRANSFER_SRC_BIT,
                         VK_MEMORY_PROPERTY_HOST_VISIBLE_BIT | VK_MEMORY_PROPERTY_HOST_COHERENT_BIT);
        std::memcpy(staging.mapped, &uniforms, sizeof uniforms);
        std::memcpy(static_cast<char*>(staging.mapped) + sizeof uniforms, &transmitWindowData,
                    sizeof transmitWindowData);
        VkCommandBuffer commands = ctx.beginCommands();
        const VkBufferCopy region{.size = sizeof uniforms};
        vkCmdCopyBuffer(commands, staging.buffer.get(), bindings.uniforms.buffer.get(), 1, &region);
        const VkBufferCopy windowRegion{.srcOffset = sizeof uniforms, .size = sizeof transmitWindowData};
        vkCmdCopyBuffer(commands, staging.buffer.get(), bindings.transmitWindows.buffer.get(), 1, &windowRegion);
        ctx.submitAndWait(commands);  // the fence makes the copy visible to the next submission
    }
    pendingUpdateMs = msSince(updateStart);
}

void Renderer::Impl::retireLitPipelines() {
    for (auto& pair : litPipelines)
        for (LitPipeline& p : pair)
            if (p.pipeline) retiredLitPipelines.push_back(std::move(p));
    for (LitPipeline& p : liftFreePipelines)
        if (p.pipeline) retiredLitPipelines.push_back(std::move(p));
}

void Renderer::Impl::setBiases(const scene::Scene& scene, double depthBias, double slopeBias) {
    // As resolveSettings() leaves a bias given explicitly; the map size and cascades do not follow
    // the biases (resolveAutomaticChoices), so they stay the constructor's.
    settings.depthBias = depthBias;
    settings.depthBiasIsDefault = false;
    settings.slopeBias = slopeBias;
    update(scene, scene.camera);
    // The lit pipelines are made again at the next frame, as a new Renderer's: with the new
    // constants baked in, and with or without the normal-offset path, which the slope bias switches.
    retireLitPipelines();
    if (bakedAtConstruction) {
        specializedLightConstants = true;
        bakedLightConstants = packLightConstants(uniforms, everyLightBaked);
        attributes["light_constants"] = "specialization";
    }
}

void Renderer::Impl::render(scene::Frame& frame, scene::ChannelMask channels, const ValidationLog& log,
                            RenderDebug* debug) {
    using namespace scene;
    const bool wantIds = (channels & kChannelBlockerId) != 0;
    const bool wantAovs =
        (channels & (kChannelVisibility | kChannelObjectId | kChannelNdotL | kChannelDepth | kChannelBlockerId)) != 0;
    const bool wantLights = (channels & kChannelLightVisibility) != 0 && !targets.lights.empty();

    // --- setup still owed: the pipelines this frame needs (shader compilation) ---
    // Which pipelines the objects need: with and without the alpha test.
    bool depthPlain = false, depthAlpha = false, litPlain = false, litAlpha = false;
    for (const DrawObject& d : drawObjects) {
        (d.depthAlpha ? depthAlpha : depthPlain) |= d.depthPass;
        (d.cameraAlpha ? litAlpha : litPlain) = true;
    }
    ShadowPipeline* const shadowPipeline = shadowPipelines[wantIds ? 1 : 0];
    const bool beautyOnly = !wantAovs && !wantLights;  // the beauty target alone
    // Only the beauty, only for an 8-bit sRGB image: the display target, where there is one.
    const bool display = beautyOnly && (channels & kBeautyForDisplay) && targets.display.image;
    const LitOutputs outputs = display ? LitOutputs::kDisplay : beautyOnly ? LitOutputs::kBeauty : LitOutputs::kAll;
    const int litIndex = display ? 3 : beautyOnly ? 0 : wantIds ? 2 : 1;
    LitPipeline* const litPipeline = litPipelines[litIndex];
    auto litVariant = [&](bool normalOffset) {
        return LitVariant{.filter = settings.filter,
                          .blockerIds = wantIds,
                          .aovTarget = !beautyOnly,
                          .displayTarget = display,
                          .normalOffset = normalOffset,
                          .beautyFormat = targets.beautyFormat,
                          .lightTargets = std::uint32_t(targets.lights.size()),
                          .lightCount = std::uint32_t(lightCount),
                          .lightKinds = lightKinds,
                          .cascades = std::uint32_t(cascadesUsed),
                          .transmittance = transmit,
                          .receiverPlane = settings.receiverPlaneBias,
                          .cascadeBlend = cascadeBlendUsed > 0.0,
                          .vertexLightConstants = vertexLightConstants,
                          .specializedLightConstants = specializedLightConstants,
                          .lightConstants = bakedLightConstants,
                          .moments = settings.moments,
                          .oneLightModules = oneLightModules};
    };
    // The lift-free triangles' pipeline (docs/raster.md "Lift-free draws"): with the *_sun modules
    // only, whose pipelines are made in about 5 ms of CPU, so that it is made with the frame's others.
    // It draws from the frame after the one that made it: its shader is compiled at its first draw, so
    // a one-frame render compiles one lit shader.
    LitPipeline& liftFree = liftFreePipelines[litIndex];
    const bool liftFreeWanted = !draw.litRangesByLift.empty() && usesSunModules(litVariant(false));
    const bool byLift = liftFreeWanted && liftFree.pipeline;
    double setup = pendingSetupMs;  // 0 for a frame that creates nothing
    pendingSetupMs = 0.0;
    // (A scene without objects, or without any drawn by the depth pass, still gets each pass's
    // pipeline without the alpha test.)
    const bool needDepthPlain = depthPlain || !depthAlpha, needLitPlain = litPlain || !litAlpha;
    if ((needDepthPlain && !shadowPipeline[0].pipeline) || (depthAlpha && !shadowPipeline[1].pipeline) ||
        (needLitPlain && !litPipeline[0].pipeline) || (litAlpha && !litPipeline[1].pipeline) ||
        (liftFreeWanted && !liftFree.pipeline)) {
        const auto pipelineStart = Clock::now();
        for (int a = 0; a < 2; ++a)
            if ((a ? depthAlpha : needDepthPlain) && !shadowPipeline[a].pipeline)
                shadowPipeline[a] = createShadowPipeline(ctx, wantIds, settings.hardwareBias,
                                                         a ? alpha.descriptors.layout.get() : VK_NULL_HANDLE);
        // One transmittance pipeline for every semi-transparent caster: with the alpha shaders where
        // one of them needs alpha (AlphaPlan::transmittanceReads).
        const VkDescriptorSetLayout alphaLayout = transmitAlpha ? alpha.descriptors.layout.get() : VK_NULL_HANDLE;
        if (momentMaps.size > 1 && !momentPipeline.pipeline)
            momentPipeline = createMomentPipeline(ctx, maps, momentMaps, settings.filter, settings.moments);
        if (transmit && !transmitPipeline.pipeline) transmitPipeline = createTransmittancePipeline(ctx, alphaLayout);
        if (transmit && !transmitRestPipeline.pipeline)
            transmitRestPipeline = createTransmittanceRestPipeline(ctx, transmittanceMaps, alphaLayout);
        for (int a = 0; a < 2; ++a)
            if ((a ? litAlpha : needLitPlain) && !litPipeline[a].pipeline)
                litPipeline[a] = createLitPipeline(ctx, litVariant(normalOffsetUsed(settings, layers)),
                                                   a ? alpha.descriptors.layout.get() : VK_NULL_HANDLE, background);
        if (liftFreeWanted && !liftFree.pipeline)
            liftFree = createLitPipeline(ctx, litVariant(false), VK_NULL_HANDLE, background, false);
        if (bindings.set == VK_NULL_HANDLE)
            bindings = createLitBindings(ctx, litPipeline[litPipeline[0].pipeline ? 0 : 1], uniforms,
                                         transmitWindowData, albedos, maps, transmittanceMaps, momentMaps);
        setup += msSince(pipelineStart);
    }

    frame.attributes = attributes;
    if (debug && debug->captureShadowMaps && !layers.empty())  // a capture draws whole layers
        frame.attributes["shadow_texels_per_layer"] = joined(layers, [](const ShadowLayer& l) {
            return std::to_string(std::uint64_t(l.frustum.mapSize) * l.frustum.mapSize);
        });
    frame.timingsMs.assign(1, {"setup", setup});
    if (pendingUpdateMs > 0.0) frame.timingsMs.emplace_back("update", pendingUpdateMs);
    pendingUpdateMs = 0.0;
    auto stamp = [&](VkCommandBuffer cb, std::uint32_t query) {
        if (timestamps) vkCmdWriteTimestamp2(cb, VK_PIPELINE_STAGE_2_ALL_COMMANDS_BIT, queries.get(), query);
    };

    // --- shadow pass ---
    const auto shadowStart = Clock::now();
    const double shadowCpuStart = processCpuMs();
    VkCommandBuffer commands = ctx.beginCommands();
    if (timestamps) vkCmdResetQueryPool(commands, queries.get(), 0, 4);
    stamp(commands, 0);
    const TransmittancePass transmittancePass{transmit ? &transmitPipeline : nullptr, &transmittanceMaps, layerLights,
                                              transmit ? &transmitRestPipeline : nullptr, transmitWindows};
    recordShadowPass(commands, shadowPipeline[shadowPipeline[0].pipeline ? 0 : 1], maps, draw, lightMatrices, wantIds,
                     &transmittancePass, &layerBias, shadowPipeline[1].pipeline ? &shadowPipeline[1] : nullptr,
                     // A capture shows whole layers (the debug views draw them all).
                     debug && debug->captureShadowMaps ? nullptr : &shadowWindows);
    if (momentPipeline.pipeline)
        recordMomentPasses(commands, momentPipeline, maps, momentMaps, layers,
                           debug && debug->captureShadowMaps ? nullptr : &lookupWindows);
    stamp(commands, 1);
    ctx.submitAndWait(commands);
    frame.timingsMs.emplace_back("shadow_pass", msSince(shadowStart));
    frame.attributes["cpu_shadow_pass_ms"] = formatNumber(processCpuMs() - shadowCpuStart);
    if (debug) {
        // What each layer holds (fixed by the constructor) and, when asked, its depths (read
        // back outside the pass timings).
        debug->layers = layers;
        debug->mapSize = layers.empty() ? 1u : std::uint32_t(settings.shadowMapSize);
        debug->layerDepths.clear();
        if (debug->captureShadowMaps)
            for (std::uint32_t k = 0; k < std::uint32_t(lightMatrices.size()); ++k)
                debug->layerDepths.push_back(readShadowMap(ctx, maps, k));
    }

    // --- lit pass ---
    // The Frame's vectors first (counted as readback: where they are new, their pages are faulted
    // in and zeroed here), and the images over them.
    const auto prepareStart = Clock::now();
    LitAttachments attachments;
    std::vector<Image> frameImages;  // over the Frame's vectors, released after this frame
    std::array<bool, kLitPlanes> intoFrame{};
    const bool backgroundInFrame = prepareFrame(frame, channels, outputs, attachments, frameImages, intoFrame);
    if (debug) {
        debug->backgroundFromFrame = backgroundInFrame;
        debug->alphaData = draw.alphaSet != VK_NULL_HANDLE;
        debug->transmittanceAlpha = transmit && transmitPipeline.alpha;
        debug->lightTargets = targets.lights.size();
        debug->lightTargetTexels = targets.lights.empty() ? nullptr : targets.lights[0].mapped;
    }
    const double prepareMs = msSince(prepareStart);
    const auto litStart = Clock::now();
    const double litCpuStart = processCpuMs();
    commands = ctx.beginCommands();
    stamp(commands, 2);
    recordLitPass(commands, litPipeline[litPipeline[0].pipeline ? 0 : 1], bindings, targets, attachments, draw,
                  background, outputs, litPipeline[1].pipeline ? &litPipeline[1] : nullptr,
                  byLift ? &liftFree : nullptr, backgroundInFrame);
    stamp(commands, 3);
    ctx.submitAndWait(commands);
    frame.timingsMs.emplace_back("lit_pass", msSince(litStart));
    frame.attributes["cpu_lit_pass_ms"] = formatNumber(processCpuMs() - litCpuStart);

    // --- readback of what was asked for and not rendered into the Frame ---
    const auto readStart = Clock::now();
    if (display) {
        invalidateMemory(targets.display.memory.get());
        readDisplayPixels(frame);
        frame.attributes["beauty_precision"] = "srgb8";
    } else {
        std::array<bool, kLitPlanes> copy{};
        const ChannelMask planeChannels[kLitPlanes] = {kChannelBeauty, kChannelVisibility, kChannelObjectId,
                                                       kChannelNdotL,  kChannelDepth,      kChannelBlockerId};
        for (std::uint32_t p = 0; p < kLitPlanes; ++p)
            // Z needs the object ids (the background's Z gets no offset) when it is offset.
            copy[p] = !intoFrame[p] &&
                      ((channels & planeChannels[p]) || (p == std::uint32_t(LitPlane::kObjectId) &&
                                                         (channels & kChannelDepth) && viewDepthOffset != 0.0));
        if (targets.hostReadable) {
            // The lit pass's barrier made the writes visible to the host; coherent memory needs no
            // invalidation, the rest does.
            for (std::uint32_t p = 0; p < kLitPlanes; ++p)
                if (copy[p]) invalidateMemory(targets.planes[p].memory.get());
            if (wantLights)
                for (const Image& image : targets.lights) invalidateMemory(image.memory.get());
        } else {
            commands = ctx.beginCommands();
            recordReadback(commands, targets, readback, ReadbackSelection{.planes = copy, .lights = wantLights});
            ctx.submitAndWait(commands);
            for (std::uint32_t p = 0; p < kLitPlanes; ++p)
                if (copy[p]) invalidate(ctx, readback.planes[p]);
            if (wantLights)
                for (const Buffer& b : readback.lights) invalidate(ctx, b);
        }
        readPixels(frame, channels, intoFrame);
        bool allIntoFrame = true;
        for (std::uint32_t p = 0; p < kLitPlanes; ++p)
            allIntoFrame = allIntoFrame && (!(channels & planeChannels[p]) || intoFrame[p]);
        frame.attributes["readback"] = !targets.hostReadable ? "copy" : allIntoFrame ? "into-frame" : "in-place";
    }
    frameImages.clear();  // the images over the Frame's memory go before anything can free it
    frame.timingsMs.emplace_back("readback", prepareMs + msSince(readStart));
    if (timestamps) {
        std::uint64_t ticks[4] = {};
        VK_CHECK(vkGetQueryPoolResults(ctx.device.get(), queries.get(), 0, 4, sizeof ticks, ticks,
                                       sizeof(std::uint64_t), VK_QUERY_RESULT_64_BIT | VK_QUERY_RESULT_WAIT_BIT));
        const double msPerTick = double(ctx.properties.limits.timestampPeriod) * 1e-6;
        frame.attributes["gpu_shadow_pass_ms"] = formatNumber(double(ticks[1] - ticks[0]) * msPerTick);
        frame.attributes["gpu_lit_pass_ms"] = formatNumber(double(ticks[3] - ticks[2]) * msPerTick);
    }
    if (settings.validate) frame.attributes["validation_messages"] = std::to_string(log.count.load());
    if (debug) {
        debug->liftFreeTriangles = 0;
        if (byLift)
            for (const IndexRange& r : *litDrawRanges(draw, true))
                debug->liftFreeTriangles += r.liftFree ? r.count / 3 : 0;
        debug->litTriangles = litTrianglesDrawn(draw, byLift);
        debug->alphaTestedLitTriangles = 0;
        if (const std::vector<IndexRange>* ranges = litDrawRanges(draw, byLift))
            for (const IndexRange& r : *ranges) debug->alphaTestedLitTriangles += r.alpha ? r.count / 3 : 0;
    }
}

namespace {

// Room in the Frame's vector for `values` floats, and for `reserveBytes` (a driver may want more
// behind an image than its rows); new memory has its pages faulted in. Returns the data.
float* reservePlane(std::vector<float>& v, std::size_t values, std::size_t reserveBytes) {
    const std::size_t capacity = v.capacity();
    v.reserve(std::max(values, (reserveBytes + sizeof(float) - 1) / sizeof(float)));
    // New memory: its pages in one call instead of a fault each as resize() zeroes them.
    if (v.capacity() != capacity) prefaultPages(v.data(), v.capacity() * sizeof(float));
    return v.data();
}

// The Frame's vector for a plane: sized for `pixels` (`perPixel` floats each) when the channel is
// asked for, else emptied; null when not asked for.
float* framePlane(std::vector<float>& v, bool wanted, std::size_t pixels, std::size_t perPixel) {
    if (!wanted) {
        v.clear();
        return nullptr;
    }
    reservePlane(v, perPixel * pixels, 0);
    v.resize(perPixel * pixels);
    return v.data();
}

}  // namespace

bool Renderer::Impl::prepareFrame(scene::Frame& frame, scene::ChannelMask channels, LitOutputs outputs,
                                  LitAttachments& attachments, std::vector<Image>& frameImages,
                                  std::array<bool, kLitPlanes>& intoFrame) {
    using namespace scene;
    frame.width = int(width);
    frame.height = int(height);
    const std::size_t n = frame.pixelCount();
    intoFrame.fill(false);
    if (outputs == LitOutputs::kDisplay) {
        attachments.add(targets.display);
        return false;  // readDisplayPixels sizes the Frame
    }
    // A reused frame keeps its vectors' memory: no new pages to fault in and zero (on a
    // 1920x1080 frame that cost more than rendering it).
    std::vector<float>* const vectors[kLitPlanes] = {&frame.beauty, &frame.visibility, &frame.objectId,
                                                     &frame.ndotl,  &frame.depth,      &frame.blockerId};
    const ChannelMask bits[kLitPlanes] = {kChannelBeauty, kChannelVisibility, kChannelObjectId,
                                          kChannelNdotL,  kChannelDepth,      kChannelBlockerId};
    const std::uint32_t planes = outputs == LitOutputs::kAll ? kLitPlanes : 1;
    // An empty vector is value-initialized whole by resize(): all zeros, the background's AOVs.
    // The per-light targets before their first frame are zeroed on the host below (mapped ones).
    bool fresh = true;
    if (outputs == LitOutputs::kAll)
        for (std::size_t t = 0; t < targets.lights.size(); ++t)
            fresh = fresh && !ownTargetsTouched[kLitPlanes + t] && targets.lights[t].mapped;
    for (std::uint32_t p = 0; p < kLitPlanes; ++p) {
        const bool wanted = (channels & bits[p]) != 0;
        const bool direct = wanted && p < planes && renderIntoFrame && targets.frameImageBytes[p] > 0;
        const std::size_t perPixel = p == 0 ? 3 : 1;
        if (!direct) {
            framePlane(*vectors[p], wanted, n, perPixel);
            fresh = fresh && p >= planes;
            continue;
        }
        fresh = fresh && vectors[p]->empty();
        float* data = reservePlane(*vectors[p], perPixel * n, targets.frameImageBytes[p]);
        Image image =
            importHostImage(ctx, p == 0 ? targets.beautyFormat : kLitPlaneFormat, width, height, kLitTargetUsage,
                            litPlaneTexelBytes(targets, LitPlane(p)), data, vectors[p]->capacity() * sizeof(float));
        if (!image.image) {
            fresh = false;  // a pointer the device cannot import: the Renderer's target, copied
            framePlane(*vectors[p], true, n, perPixel);
            continue;
        }
        intoFrame[p] = true;
        frameImages.push_back(std::move(image));
    }
    if (fresh) {
        // Every attachment is a new plane of the Frame or a per-light target before its first
        // frame: its zeros, with the beauty set to the background color, are the background, and
        // the lit pass draws none (on a first frame its pipeline's shaders are not compiled then).
        // The images go to GENERAL before the host writes them, so that the pass's transition
        // (from GENERAL, load) keeps what is written.
        std::vector<ImageTransition> toGeneral;
        auto general = [&](const Image& image) {
            toGeneral.push_back({image.image.get(), VK_IMAGE_ASPECT_COLOR_BIT, 1, VK_IMAGE_LAYOUT_UNDEFINED,
                                 VK_IMAGE_LAYOUT_GENERAL, VK_PIPELINE_STAGE_2_NONE, VK_ACCESS_2_NONE,
                                 VK_PIPELINE_STAGE_2_HOST_BIT, VK_ACCESS_2_NONE});
        };
        for (const Image& image : frameImages) general(image);
        if (outputs == LitOutputs::kAll)
            for (const Image& image : targets.lights) general(image);
        VkCommandBuffer commands = ctx.beginCommands();
        transition(commands, toGeneral);
        ctx.submitAndWait(commands);
    }
    // Bitwise: a background of −0.0 is written as the background pipeline would write it.
    const glm::vec3 zero(0.0f);
    const bool colored = fresh && std::memcmp(&background, &zero, sizeof zero) != 0;
    for (std::uint32_t p = colored ? 1 : 0; p < planes; ++p)
        if (intoFrame[p]) vectors[p]->resize((p == 0 ? 3 : 1) * n);
    if (colored) {
        // Row by row from one row of the color (each float written once; resize() would zero
        // them first). The vector is empty and has the room: nothing is reallocated.
        std::vector<float> row(3 * std::size_t(width));
        for (std::size_t x = 0; x < width; ++x) std::memcpy(&row[3 * x], &background[0], 3 * sizeof(float));
        for (std::uint32_t y = 0; y < height; ++y) frame.beauty.insert(frame.beauty.end(), row.begin(), row.end());
    }
    // The Renderer's own targets (never cleared) are read under partly covered blocks before they
    // are written: their pages are faulted in writable before the first frame that renders them,
    // a per-light target's by writing its zeros where that frame takes them for the background.
    auto own = [&](const Image& image, std::size_t index) {
        const std::size_t bytes = std::size_t(image.rowPitch) * height;
        if (!ownTargetsTouched[index] && image.mapped) {
            if (fresh && index >= kLitPlanes) {
                std::memset(image.mapped, 0, bytes);
                flushMemory(image.memory.get());
            } else
                prefaultPages(image.mapped, bytes);
        }
        ownTargetsTouched[index] = true;
        attachments.add(image);
    };
    std::size_t next = 0;
    for (std::uint32_t p = 0; p < planes; ++p) {
        if (intoFrame[p])
            attachments.add(frameImages[next++]);
        else
            own(targets.planes[p], p);
    }
    if (outputs == LitOutputs::kAll)
        for (std::size_t t = 0; t < targets.lights.size(); ++t) own(targets.lights[t], kLitPlanes + t);
    frame.lightVisibility.resize((channels & kChannelLightVisibility) && !targets.lights.empty() ? lightCount : 0);
    for (std::vector<float>& v : frame.lightVisibility) framePlane(v, true, n, 1);
    return fresh;
}

// Copies the planes asked for that were not rendered into the Frame (from the targets in place,
// or from their readback buffers), rows top first as the Frame wants them, and the per-light
// visibility out of its four-light targets; adds the view-depth offset of a held view to Z.
void Renderer::Impl::readPixels(scene::Frame& frame, scene::ChannelMask channels,
                                const std::array<bool, kLitPlanes>& intoFrame) const {
    using namespace scene;
    const std::size_t w = width;
    // Where each target's rows are: the targets themselves (host-readable) or their buffers.
    struct Rows {
        const char* base = nullptr;
        std::size_t pitch = 0;
        const float* row(std::size_t y) const { return reinterpret_cast<const float*>(base + y * pitch); }
    };
    auto rows = [&](const Image& image, const Buffer* buffer, std::size_t texelBytes) {
        return targets.hostReadable ? Rows{static_cast<const char*>(image.mapped), std::size_t(image.rowPitch)}
                                    : Rows{static_cast<const char*>(buffer->mapped), w * texelBytes};
    };
    std::vector<float>* const vectors[kLitPlanes] = {&frame.beauty, &frame.visibility, &frame.objectId,
                                                     &frame.ndotl,  &frame.depth,      &frame.blockerId};
    const ChannelMask bits[kLitPlanes] = {kChannelBeauty, kChannelVisibility, kChannelObjectId,
                                          kChannelNdotL,  kChannelDepth,      kChannelBlockerId};
    std::array<Rows, kLitPlanes> source;
    for (std::uint32_t p = 0; p < kLitPlanes; ++p)
        source[p] = rows(targets.planes[p], targets.hostReadable ? nullptr : &readback.planes[p],
                         litPlaneTexelBytes(targets, LitPlane(p)));
    std::vector<Rows> lightRows;
    for (std::size_t t = 0; t < targets.lights.size(); ++t)
        lightRows.push_back(rows(targets.lights[t], targets.hostReadable ? nullptr : &readback.lights[t], 16));
    const bool rgba = targets.beautyTexelBytes == 16;
    // The object ids that tell the background (no Z offset) where Z is offset: the Frame's or the target's.
    const float depthOffset = float(viewDepthOffset);  // 0 for the camera the Renderer was made for
    const bool offsetDepth = (channels & kChannelDepth) && depthOffset != 0.0f;
    const bool idsInFrame = (channels & kChannelObjectId) != 0;
    bool copies = offsetDepth || !frame.lightVisibility.empty();
    for (std::uint32_t p = 0; p < kLitPlanes; ++p) copies = copies || ((channels & bits[p]) && !intoFrame[p]);
    // Rendered into the Frame, nothing to do: no parallel loop (a process's first one starts
    // the thread pool: a few ms of CPU on a first frame).
    if (!copies) return;
    tbb::parallel_for(tbb::blocked_range<std::size_t>(0, height, 16), [&](const tbb::blocked_range<std::size_t>& r) {
        for (std::size_t y = r.begin(); y < r.end(); ++y) {
            for (std::uint32_t p = 0; p < kLitPlanes; ++p) {
                if (!(channels & bits[p]) || intoFrame[p]) continue;
                float* out = vectors[p]->data() + y * w * (p == 0 ? 3 : 1);
                const float* in = source[p].row(y);
                if (p == 0 && rgba) {
                    for (std::size_t x = 0; x < w; ++x)
                        for (std::size_t c = 0; c < 3; ++c) out[3 * x + c] = in[4 * x + c];
                } else {
                    std::memcpy(out, in, w * (p == 0 ? 3 : 1) * sizeof(float));
                }
            }
            if (offsetDepth) {
                float* z = frame.depth.data() + y * w;
                const float* id =
                    idsInFrame ? frame.objectId.data() + y * w : source[std::size_t(LitPlane::kObjectId)].row(y);
                for (std::size_t x = 0; x < w; ++x)
                    if (id[x] != 0.0f) z[x] += depthOffset;
            }
            for (std::size_t l = 0; l < frame.lightVisibility.size(); ++l) {
                const float* p = lightRows[l / 4].row(y) + l % 4;
                float* out = frame.lightVisibility[l].data() + y * w;
                for (std::size_t x = 0; x < w; ++x) out[x] = p[4 * x];
            }
        }
    });
}

// The display target's sRGB codes, decoded to the linear values that encode to the same codes
// (the Frame's beauty is linear); every other channel is left empty.
void Renderer::Impl::readDisplayPixels(scene::Frame& frame) const {
    using namespace scene;
    frame.width = int(width);
    frame.height = int(height);
    const std::size_t n = frame.pixelCount();
    frame.beauty.resize(3 * n);
    for (std::vector<float>* v : {&frame.visibility, &frame.objectId, &frame.ndotl, &frame.depth, &frame.blockerId})
        v->clear();
    frame.lightVisibility.clear();
    std::array<float, 256> decode{};
    for (int k = 0; k < 256; ++k) decode[std::size_t(k)] = srgbCodeToLinear(std::uint8_t(k));
    const auto* base = static_cast<const std::uint8_t*>(targets.display.mapped);
    const std::size_t pitch = std::size_t(targets.display.rowPitch), w = width;
    float* const rgb = frame.beauty.data();
    tbb::parallel_for(tbb::blocked_range<std::size_t>(0, height, 16), [&](const tbb::blocked_range<std::size_t>& r) {
        for (std::size_t y = r.begin(); y < r.end(); ++y) {
            const std::uint8_t* p = base + y * pitch;
            float* out = rgb + 3 * y * w;
            for (std::size_t x = 0; x < w; ++x)
                for (std::size_t c = 0; c < 3; ++c) out[3 * x + c] = decode[p[4 * x + c]];
        }
    });
}

Renderer::Renderer(const scene::Scene& scene, const scene::RenderPlan& plan, const scene::RasterSettings& settings,
                   const RendererOptions& options)
    : log_(std::make_shared<ValidationLog>()), impl_(std::make_unique<Impl>(scene, plan, settings, options, *log_)) {}
Renderer::~Renderer() = default;
Renderer::Renderer(Renderer&&) noexcept = default;
Renderer& Renderer::operator=(Renderer&&) noexcept = default;

scene::Frame Renderer::render(scene::ChannelMask channels, RenderDebug* debug) {
    scene::Frame frame;
    impl_->render(frame, channels, *log_, debug);
    return frame;
}
void Renderer::render(scene::Frame& frame, scene::ChannelMask channels, RenderDebug* debug) {
    impl_->render(frame, channels, *log_, debug);
}
void Renderer::update(const scene::Scene& scene) { impl_->update(scene, scene.camera); }
void Renderer::update(const scene::Scene& scene, const scene::Camera& view) { impl_->update(scene, view); }
void Renderer::setBiases(const scene::Scene& scene, double depthBias, double slopeBias) {
    impl_->setBiases(scene, depthBias, slopeBias);
}
double Renderer::setupMs() const { return impl_->setupMs; }
int Renderer::validationMessages() const { return log_->count.load(); }

scene::Frame render(const scene::Scene& scene, const scene::RenderPlan& plan, const scene::RasterSettings& settings,
                    scene::ChannelMask channels, RenderDebug* debug) {
    std::shared_ptr<const ValidationLog> log;
    scene::Frame frame;
    {
        Renderer renderer(scene, plan, settings);
        log = renderer.validationLog();
        frame = renderer.render(channels, debug);
    }  // the device is destroyed here; validation messages raised by that still count
    if (settings.validate) frame.attributes["validation_messages"] = std::to_string(log->count.load());
    return frame;
}

scene::Frame render(const scene::Scene& scene, const scene::RenderPlan& plan, const scene::RasterSettings& settings,
                    RenderDebug* debug) {
    return render(scene, plan, settings, scene::kAllChannels, debug);
}

}  // namespace shadowlab::raster
