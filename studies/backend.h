// studies/backend.h: the one seam between the studies and the backends. A scene::Backend names a
// backend (scene::parseBackend reads it, scene::toString prints it); this makes its renderer,
// renders one frame with it, or estimates its memory, so no study dispatches on the name itself.
#pragma once

#include <cstdint>
#include <memory>

#include "scene/backend.h"
#include "scene/frame.h"
#include "scene/render_plan.h"
#include "scene/scene.h"
#include "scene/settings.h"

namespace shadowlab::raster {
struct RenderDebug;
}

namespace shadowlab::studies {

// A backend's renderer for one scene's objects, reused across frames: the constructor does the
// setup once (the raster device, maps and buffers; the ray tracer's trees), update() takes the
// next frame's camera and lights, render() draws into a Frame.
class BackendRenderer {
public:
    // Returns the freed heap to the system unless the job's scene::FreedHeapBudget leaves room for
    // the next renderer beside it (scene::releaseFreedHeap): runs after the backend's members are
    // gone, so that the next renderer either reuses their pages or does not stack on them.
    virtual ~BackendRenderer();
    // The next frame's scene: the objects, the number of lights and the resolution must be the
    // constructor's; the camera and the lights may differ. The scene given here (or to
    // makeRenderer) must outlive the render() calls that follow: the ray tracers read it there.
    virtual void update(const scene::Scene& scene) = 0;
    // The same with the shadow setup made for scene.camera and the image drawn from `view` (the
    // held-view frames of a camera path). Only the raster backend has a shadow setup that differs
    // from the image's: the others throw std::logic_error.
    virtual void update(const scene::Scene& scene, const scene::Camera& view) = 0;
    // The next frames with other shader biases (raster::Renderer::setBiases: the frames a new
    // renderer given them draws). Only the raster backend has them: the others throw
    // std::logic_error.
    virtual void setRasterBiases(const scene::Scene& scene, double depthBias, double slopeBias);
    // The raster backend reads back only `channels` (scene/frame.h); the ray tracers fill every AOV.
    virtual scene::Frame render(scene::ChannelMask channels = scene::kAllChannels) = 0;
    virtual double setupMs() const = 0;  // the constructor's time
    // Vulkan validation messages so far (raster with settings.validate), else 0.
    virtual int validationMessages() const { return 0; }
};

// The renderer of `backend` for `scene` as planned, with settings.raster or settings.raytrace
// (the reference: scene::referenceSettings(settings.raytrace)). Frames carry the backend's own
// attributes and timings (raytrace: "setup" 0 after the constructor; raster: see raster::Renderer).
std::unique_ptr<BackendRenderer> makeRenderer(scene::Backend backend, const scene::Scene& scene,
                                              const scene::RenderPlan& plan, const scene::RenderSettings& settings);

// One frame of `backend` with its one-shot entry point: setup included in the "setup" timing and,
// for raster with settings.raster.validate, the messages raised while the device is destroyed
// counted in "validation_messages". `debug` (raster only, ignored by the others) is filled as
// raster::Renderer::render fills it, with every channel read back.
scene::Frame renderFrame(scene::Backend backend, const scene::Scene& scene, const scene::RenderPlan& plan,
                         const scene::RenderSettings& settings, scene::ChannelMask channels = scene::kAllChannels,
                         raster::RenderDebug* debug = nullptr);

// An upper estimate of the memory rendering `backend` takes (scene/memory.h).
std::uint64_t estimateMemoryBytes(scene::Backend backend, const scene::Scene& scene, const scene::RenderPlan& plan,
                                  const scene::RenderSettings& settings);

// A study's memory at its peak, estimated before it renders (`total`), and the largest single
// renderer it makes, which scene::FreedHeapBudget keeps room for.
struct JobMemory {
    std::uint64_t total = 0;
    std::uint64_t largestRenderer = 0;
};

}  // namespace shadowlab::studies
