// studies/backend.cpp: the backends behind BackendRenderer, chosen by scene::Backend.
#include "studies/backend.h"

#include <optional>
#include <stdexcept>

#include "raster/memory.h"
#include "raster/renderer.h"
#include "raytrace/memory.h"
#include "raytrace/renderer.h"
#include "scene/memory.h"

namespace shadowlab::studies {

// scene::releaseFreedHeap: within a job's budget the next renderer reuses what this one freed.
BackendRenderer::~BackendRenderer() { scene::releaseFreedHeap(); }

void BackendRenderer::setRasterBiases(const scene::Scene&, double, double) {
    throw std::logic_error("setRasterBiases: only the raster backend has shadow-map biases");
}

namespace {

class RasterRenderer final : public BackendRenderer {
public:
    RasterRenderer(const scene::Scene& scene, const scene::RenderPlan& plan, const scene::RasterSettings& settings)
        : renderer_(scene, plan, settings) {}
    void update(const scene::Scene& scene) override { renderer_.update(scene); }
    void update(const scene::Scene& scene, const scene::Camera& view) override { renderer_.update(scene, view); }
    void setRasterBiases(const scene::Scene& scene, double depthBias, double slopeBias) override {
        renderer_.setBiases(scene, depthBias, slopeBias);
    }
    scene::Frame render(scene::ChannelMask channels) override { return renderer_.render(channels); }
    double setupMs() const override { return renderer_.setupMs(); }
    int validationMessages() const override { return renderer_.validationMessages(); }

private:
    raster::Renderer renderer_;
};

// The ray tracer takes the scene and its plan with every frame: update() keeps them.
class RaytraceRenderer final : public BackendRenderer {
public:
    RaytraceRenderer(const scene::Scene& scene, const scene::RenderPlan& plan, const scene::RenderSettings& settings,
                     bool reference)
        : settings_(settings), tracer_(scene, settings.raytrace, reference), scene_(&scene), plan_(plan) {}
    void update(const scene::Scene& scene) override {
        scene_ = &scene;
        plan_ = scene::makeRenderPlan(scene, settings_);
    }
    void update(const scene::Scene&, const scene::Camera&) override {
        throw std::logic_error("a held view needs a shadow setup apart from the image: raster only");
    }
    scene::Frame render(scene::ChannelMask) override { return tracer_.render(*scene_, plan_); }
    double setupMs() const override { return tracer_.setupMs(); }

private:
    scene::RenderSettings settings_;
    raytrace::Renderer tracer_;
    const scene::Scene* scene_;  // the caller's: a copy per frame would copy every mesh
    scene::RenderPlan plan_;
};

}  // namespace

std::unique_ptr<BackendRenderer> makeRenderer(scene::Backend backend, const scene::Scene& scene,
                                              const scene::RenderPlan& plan, const scene::RenderSettings& settings) {
    switch (backend) {
        case scene::Backend::Raster: return std::make_unique<RasterRenderer>(scene, plan, settings.raster);
        case scene::Backend::Raytrace: return std::make_unique<RaytraceRenderer>(scene, plan, settings, false);
        case scene::Backend::Reference: return std::make_unique<RaytraceRenderer>(scene, plan, settings, true);
    }
    throw std::logic_error("makeRenderer: unknown backend");
}

namespace {
scene::Frame renderOnce(scene::Backend backend, const scene::Scene& scene, const scene::RenderPlan& plan,
                        const scene::RenderSettings& settings, scene::ChannelMask channels,
                        raster::RenderDebug* debug) {
    switch (backend) {
        case scene::Backend::Raster:
            return debug ? raster::render(scene, plan, settings.raster, debug)
                         : raster::render(scene, plan, settings.raster, channels);
        case scene::Backend::Raytrace: return raytrace::render(scene, plan, settings.raytrace);
        case scene::Backend::Reference: return raytrace::renderReference(scene, plan, settings.raytrace);
    }
    throw std::logic_error("renderFrame: unknown backend");
}
}  // namespace

scene::Frame renderFrame(scene::Backend backend, const scene::Scene& scene, const scene::RenderPlan& plan,
                         const scene::RenderSettings& settings, scene::ChannelMask channels,
                         raster::RenderDebug* debug) {
    scene::Frame frame = renderOnce(backend, scene, plan, settings, channels, debug);
    scene::releaseFreedHeap();  // as after a BackendRenderer: the one-shot renderer is gone here
    return frame;
}

std::uint64_t estimateMemoryBytes(scene::Backend backend, const scene::Scene& scene, const scene::RenderPlan& plan,
                                  const scene::RenderSettings& settings) {
    return backend == scene::Backend::Raster ? raster::estimateMemoryBytes(scene, plan, settings.raster)
                                             : raytrace::estimateMemoryBytes(scene, plan);
}

}  // namespace shadowlab::studies
