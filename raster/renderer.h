// raster/renderer.h: the raster backend's entry points: render a Scene with shadow maps into a
// Frame, and list the Vulkan devices for `shadowlab info`.
#pragma once

#include <cstdint>
#include <memory>
#include <string>
#include <vector>

#include "raster/devices.h"
#include "raster/light_frustum.h"
#include "raster/shadow_layers.h"
#include "raster/vulkan_error.h"
#include "scene/frame.h"
#include "scene/render_plan.h"
#include "scene/scene.h"
#include "scene/settings.h"

namespace shadowlab::raster {

struct ValidationLog;

// What a render used, for the debug views (raster/debug_views.h) and tests.
struct RenderDebug {
    bool captureShadowMaps = false;  // in: read every layer back after the shadow pass
    // Out: the shadow-map layers the render drew (raster/shadow_layers.h: frustum, light, label
    // "L0", "L0 C2", "L1 +X", biases, casters; cascadeSplits(layers) for the cascades) and, when
    // captured, each layer's depths (mapSize² floats, row 0 first; 1 = cleared, nothing there).
    std::vector<ShadowLayer> layers;
    std::vector<std::vector<float>> layerDepths;
    std::uint32_t mapSize = 0;
    // Out: the background came from the attachments (the Frame's planes were new: zeros and the
    // background color; the per-light targets, before their first frame, zeroed on the host)
    // instead of the lit pass's background pipeline.
    bool backgroundFromFrame = false;
    // Out: the triangles the lit pass drew with the pipeline without the slope bias's lift
    // (RendererOptions::liftFreeDraws; 0 in the frame that made that pipeline, a Renderer's first).
    std::size_t liftFreeTriangles = 0;
    // Out: the triangles the lit pass drew (all but those RendererOptions::viewCull left out).
    std::size_t litTriangles = 0;
    // Out: of those, the triangles drawn with the alpha-tested pipeline (surfaces whose alpha can
    // cut, RendererOptions::idleAlphaTestsLeftOut).
    std::size_t alphaTestedLitTriangles = 0;
    // Out: the Renderer made UVs and alpha records (raster::planAlpha: some test can cut, or the
    // transmittance passes read alpha), and the transmittance passes ran their alpha shaders.
    bool alphaData = false;
    bool transmittanceAlpha = false;
    // Out: the RGBA32F targets that hold the per-light visibility (one per four lights, none for
    // one light), each rendered with every channel.
    std::size_t lightTargets = 0;
    // Out: the first per-light target's texels where the host maps them (null otherwise): which
    // memory the target took.
    const void* lightTargetTexels = nullptr;
};

// Where the lit pass's fragment shader reads the one light's constants and map matrix, where there
// is one light with one map (a directional light without cascades, or a spot;
// shaders/lit_constants.glsl kOneMapLight):
// - kSpecialization (the default): baked into the lit pipelines as specialization constants, which
//   cost nothing per triangle or pixel. A Renderer whose update() changes them (a moving light or
//   camera) switches to kVertexOutputs for the rest of its life, compiling those pipelines once,
//   instead of compiling new ones for every frame;
// - kVertexOutputs: flat outputs of the vertex shader (lavapipe reads a uniform lane by lane for
//   every eight pixels, a flat input once per triangle; docs/performance.md);
// - kUniformBuffer: the uniform buffer.
// Where there is no such light (several lights, a point light, the receiver-plane bias; one
// cascaded sun bakes its own values and its cascades'), kSpecialization bakes every light's
// constants in and kVertexOutputs reads the uniform buffer; a moving light or camera switches to
// the buffer then.
// The frames are the same bit for bit (tests render all three); with every light baked in, within
// a rounding NIR's folding of the constants brings (docs/raster.md, tests bound it).
enum class LightConstants { kSpecialization, kVertexOutputs, kUniformBuffer };

struct RendererOptions {
    // Read the targets in place where the device's memory is the host's (lavapipe); false
    // copies them into readback buffers first, as on other devices (tests compare the two).
    bool readTargetsInPlace = true;
    // Where the targets are read in place and the device imports host memory (lavapipe): render
    // each channel asked for straight into the Frame's vector, so there is nothing to read back;
    // false renders into the Renderer's own targets and copies them (tests compare the two).
    bool renderIntoFrame = true;
    // Semi-transparent casters: draw each layer's transmittance maps only within the casters'
    // window (raster/shadow_pass.h transmittanceWindow); false draws every layer whole, as a map
    // without windows (tests compare the two).
    bool transmittanceWindows = true;
    LightConstants lightConstants = LightConstants::kSpecialization;
    // The lit pass's size-optimized shader modules where the scene allows them
    // (LitVariant::oneLightModules); false: the general ones (tests compare the two).
    bool oneLightModules = true;
    // With the size-optimized modules (oneLightModules), the lit pass draws the triangles on which no
    // fragment takes the slope bias's lift past its cap (raster/lift_free.h) with a pipeline without
    // that path, the rest with it, from the frame after the one that made that pipeline (its shader
    // is compiled at its first draw); the same frames (tests compare). false: every triangle with it.
    bool liftFreeDraws = true;
    // The lit pass leaves out runs of triangles whose box lies outside the camera's clip volume
    // (raster/view_cull.h); the same frames (tests compare). false: it draws every triangle.
    bool viewCull = true;
    // Objects whose alpha can never cut (scene::Material::alphaCanFallBelow: a constant alpha at or
    // above the cutoff, or a texture whose every texel passes) take the depth and lit pipelines
    // without the alpha test, which llvmpipe then need not compile; the same frames (tests
    // compare). false: every MASK caster and every MASK or BLEND surface is alpha-tested.
    bool idleAlphaTestsLeftOut = true;
};

// A reusable raster renderer for one scene and its settings: the constructor does the setup
// once (instance, device, tessellation, geometry upload into device-local buffers, shadow maps,
// targets, readback buffers, uniforms); render() then runs the two passes and the readback of
// the channels asked for, and can be called any number of times. Pipelines are made on the
// first render() that needs them (the blocker-id variant only when blocker ids are asked for).
// The first frame's "setup" timing is the constructor's time plus any pipeline creation; later
// frames have "setup" 0 unless they had to create a pipeline. Call from one thread at a time.
class Renderer {
public:
    Renderer(const scene::Scene& scene, const scene::RenderPlan& plan, const scene::RasterSettings& settings,
             const RendererOptions& options = {});
    ~Renderer();
    Renderer(Renderer&&) noexcept;
    Renderer& operator=(Renderer&&) noexcept;

    // The two passes and the readback of `channels` (scene/frame.h). Vectors of channels not
    // asked for are left empty; lightVisibility is filled only for scenes with > 1 light.
    // With `debug`, also fills it: what each shadow-map layer holds and, with
    // debug->captureShadowMaps, every layer's depths (read back after the shadow pass, outside
    // its timing).
    scene::Frame render(scene::ChannelMask channels = scene::kAllChannels, RenderDebug* debug = nullptr);
    // The same into `frame`, reusing its vectors' memory (a loop over frames allocates nothing).
    void render(scene::Frame& frame, scene::ChannelMask channels = scene::kAllChannels, RenderDebug* debug = nullptr);
    // Per-frame change along a path (a moving camera or light): `scene` must have the objects, the
    // number of lights and the resolution the Renderer was made for; its camera and lights may
    // differ. Redoes what depends on them (light frusta, cascades, caster culling, the lit pass's
    // uniforms) and keeps the rest: geometry stays in the buffer made relative to the first
    // camera, the map size is the first frame's. Throws RasterError when the change needs other
    // maps (another number of layers or cascades). Cheap next to a frame: no allocation on the
    // device but one staging buffer for the uniforms.
    void update(const scene::Scene& scene);
    // The same with the maps fitted for scene.camera but the image drawn from `view` (same
    // resolution): the held-view frames of a camera path (docs/temporal.md). Cascades are chosen,
    // and the Frame's Z measured, along scene.camera's view axis: the shadow setup is that camera's.
    void update(const scene::Scene& scene, const scene::Camera& view);
    // The next frames with other shader biases (constant in world units, slope in texels) for
    // `scene` (update()'s rules), as a new Renderer given them draws: the layers, caster culling
    // and read windows are placed again (the culling margin counts the slope bias). A bias search
    // renders its points with one Renderer instead of a device, upload and pipelines per point.
    void setBiases(const scene::Scene& scene, double depthBias, double slopeBias);
    double setupMs() const;  // the constructor's time
    // Validation messages counted so far (settings.validate); messages raised when the Renderer
    // is destroyed are not in any frame: raster::render() adds them to its frame.
    int validationMessages() const;
    std::shared_ptr<const ValidationLog> validationLog() const { return log_; }

private:
    struct Impl;
    std::shared_ptr<ValidationLog> log_;  // outlives the device, which can still report
    std::unique_ptr<Impl> impl_;
};

// Renders on a headless Vulkan 1.3 device (lavapipe unless settings.device names another):
// one depth pass per directional (one per cascade with settings.cascades > 1) or spot light,
// six (a cube map) per point light, for each
// light whose plan says it needs a shadow test, then
// the lit camera pass, then the readback. Fills every Frame AOV including blockerId, the
// timings "setup", "shadow_pass", "lit_pass", "readback" and the attributes backend, device,
// shadow_map_size, filter, pcf_size, depth_bias (the value used, see depthBiasIsDefault),
// depth_bias_default, slope_bias, normal_offset, texel_world_size, texel_axis,
// light_frustum, light_frustum_fit, triangles, sphere_segments and, with settings.validate,
// validation_messages (the count; each is printed to stderr). Throws RasterError (no loader,
// driver or device; bad settings) or VulkanError (a failed call). Call it from one thread at a time: the Vulkan
// function pointers it loads are shared by the process.
// One frame from a Renderer made for it (setup included in the "setup" timing); with `debug`,
// as Renderer::render.
scene::Frame render(const scene::Scene& scene, const scene::RenderPlan& plan, const scene::RasterSettings& settings,
                    scene::ChannelMask channels = scene::kAllChannels, RenderDebug* debug = nullptr);
// All channels, with `debug` (the debug views).
scene::Frame render(const scene::Scene& scene, const scene::RenderPlan& plan, const scene::RasterSettings& settings,
                    RenderDebug* debug);

}  // namespace shadowlab::raster
