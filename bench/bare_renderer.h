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

enum class BareTarget {
    Unorm,  // one R8G8B8A8_UNORM target
    Srgb,   // one R8G8B8A8_SRGB target (the device encodes on store, as ours does for a PNG)
    // A float RGB beauty and five R32F planes (visibility, object id, N·L, depth, blocker id), not
    // cleared and not read back, and an R32_UINT blocker-id map in the depth pass: what any
    // renderer filling a Frame's channels has to write.
    Aovs,
    // The float RGB beauty alone (the same format, not cleared and not read back): what any
    // renderer of `render --channels beauty` writes, against ours' float-beauty frame.
    FloatBeauty,
};

class BareRenderer {
public:
    // The first directional light of `scene` (else straight down) casts; others are ignored.
    BareRenderer(const scene::Scene& scene, const scene::RasterSettings& settings,
                 BareTarget target = BareTarget::Unorm);
    ~BareRenderer();
    // One frame: both passes and the readback into an RGBA8 image (row 0 on top; BareTarget::Aovs
    // and FloatBeauty read nothing back and leave `rgba` as it is).
    BareTimings render(std::vector<std::uint8_t>& rgba);
    double setupMs() const;
    std::string pcfKind() const;  // "hardware (LINEAR compare sampler)" or "gather"

private:
    struct Impl;
    std::unique_ptr<Impl> impl_;
};

}  // namespace shadowlab::bench
