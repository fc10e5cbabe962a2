// bench/bare_renderer.h: the baseline raster_bench compares raster::Renderer with: the least a
// two-pass shadow-map renderer on lavapipe does. A depth-only pass into a 2048² D32 map (no
// fragment shader), a camera pass into one RGBA8 target with N·L shading and one 2x2-PCF
// lookup (a LINEAR compare sampler where the device filters the map's format; otherwise one
// compare gather with the bilinear weights in the shader), and the readback of that target.
// No AOVs, ids, per-pixel filter choice, normal offset or slope bias. It reuses raster/ for
// the instance and device (Context), buffer/image helpers, the pipeline builder, the
// tessellation (the same triangles as ours) and the light frustum (the same map), so that the
// difference in time is the passes themselves.
#pragma once

#include <cstdint>
#include <memory>
#include <string>
#include <vector>

#include "scene/scene.h"
#include "scene/settings.h"

namespace shadowlab::bench {

struct BareTimings {
    double setup = 0, shadowPass = 0, litPass = 0, readback = 0;
    double cpuShadowPass = 0, cpuLitPass = 0;  // process CPU time during each pass (all threads)
    double perFrame() const { return shadowPass + litPass + readback; }
};

class BareRenderer {
public:
    // The first directional light of `scene` (else straight down) casts; others are ignored.
    // srgbTarget: an R8G8B8A8_SRGB target (the device encodes on store, as ours does for a PNG)
    // instead of R8G8B8A8_UNORM.
    BareRenderer(const scene::Scene& scene, const scene::RasterSettings& settings, bool srgbTarget = false);
    ~BareRenderer();
    // One frame: both passes and the readback into an RGBA8 image (row 0 on top).
    BareTimings render(std::vector<std::uint8_t>& rgba);
    double setupMs() const;
    std::string pcfKind() const;  // "hardware (LINEAR compare sampler)" or "gather"

private:
    struct Impl;
    std::unique_ptr<Impl> impl_;
};

}  // namespace shadowlab::bench
