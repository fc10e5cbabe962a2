// shaders/moments.comp: the filterable shadow maps' moments (raster/moment_maps.h), in two
// passes of a separable box blur, one dispatch per layer and pass. Pass 0 turns each depth texel
// into the technique's moments (of linear depth: perspective layers' stored depths are made
// linear) and averages `width` of them along x into the intermediate image (one layer, which each
// layer's pair of passes uses in turn); pass 1 averages `width` of those along y into the moment
// array the lit pass samples. Texel coordinates are clamped to the map, as the lit pass's
// clamp-to-edge sampler does. Each dispatch writes only its window of the layer
// (raster/moment_maps.h says which texels that is and why the reads stay within what was drawn).
#version 450
#extension GL_GOOGLE_include_directive : require
#include "interface.h"

layout(local_size_x = 8, local_size_y = 8, local_size_z = 1) in;

layout(set = 0, binding = 0) uniform sampler2DArray depths;  // the shadow maps (NEAREST, no compare)
layout(set = 0, binding = 1, rgba32f) uniform image2DArray blurredX;  // one layer
layout(set = 0, binding = 2, rgba32f) uniform image2DArray moments;

layout(push_constant) uniform Push { MomentPush push; };
// Baked into each pipeline (raster/moment_maps.cpp): llvmpipe loads a push constant lane by lane
// wherever it is read, and with the radius known the blur's loop unrolls. The defaults here are
// no render's (no filter, no blur, no exponent), so that a constant the pipeline does not set shows.
layout(constant_id = 0) const int kPass = 0;  // 0: moments + blur along x, 1: blur along y
layout(constant_id = 1) const int kFilter = SHADOWLAB_FILTER_NONE;
layout(constant_id = 2) const int kRadius = 0;  // blur radius in texels
layout(constant_id = 3) const int kSize = 1;    // the maps' side in texels
layout(constant_id = 4) const float kEvsmPositive = 0.0;
layout(constant_id = 5) const float kEvsmNegative = 0.0;
layout(constant_id = 6) const float kEsmExponent = 0.0;

// A perspective layer's stored depth z = far/(far − near)·(1 − near/d) of the distance d along
// its axis, as (d − near)/(far − near): linear in d, so that a gap between caster and receiver
// is its length over the depth range wherever it lies. The stored depth's slope is near·far/d²
// times that (0.75% at 3 units from a light with near 0.008 and far 8.2), and the moments' bounds,
// whose parameters are in units of the 0..1 range, then barely tell caster from receiver.
// Cleared texels (1) stay 1.
// Written as z·near / (far·(1 − z) + near·z): 1 − z is exact in float for z >= 0.5, so each term
// rounds once (far − z·(far − near) would cancel to a few digits near z = 1, where the depths of
// distant surfaces lie), and z = 1 gives exactly 1.
float linearDepth(float z) {
    const float near = push.range.x, far = push.range.y;
    return z * near / (far * (1.0 - z) + near * z);
}

// The moments of one stored depth z (0..1) for the filter code.
vec4 momentsOf(float z, int code) {
    if (code == SHADOWLAB_FILTER_VSM) return vec4(z, z * z, 0.0, 0.0);
    if (code == SHADOWLAB_FILTER_EVSM2 || code == SHADOWLAB_FILTER_EVSM4) {
        // Warped to [-1, 1] first, so both exponents act on the same range (Lauritzen & McCool 2008).
        const float w = 2.0 * z - 1.0;
        const float p = exp(kEvsmPositive * w);
        const float n = -exp(-kEvsmNegative * w);
        return code == SHADOWLAB_FILTER_EVSM2 ? vec4(p, p * p, 0.0, 0.0) : vec4(p, p * p, n, n * n);
    }
    if (code == SHADOWLAB_FILTER_ESM) return vec4(exp(kEsmExponent * z), 0.0, 0.0, 0.0);
    // MSM: the plain powers in 32-bit float (no optimised quantisation: nothing is 16-bit here).
    const float z2 = z * z;
    return vec4(z, z2, z2 * z, z2 * z2);
}

void main() {
    const ivec3 size = ivec3(kSize, kSize, 0);
    const ivec3 at = ivec3(ivec2(gl_GlobalInvocationID.xy) + push.window.xy, push.layer.x);
    if (at.x >= push.window.z || at.y >= push.window.w) return;
    const int code = kFilter;
    const int radius = kRadius;
    vec4 sum = vec4(0.0);
    if (kPass == 0) {
        for (int k = -radius; k <= radius; ++k) {
            const ivec3 t = ivec3(clamp(at.x + k, 0, size.x - 1), at.y, at.z);
            const float z = texelFetch(depths, t, 0).r;
            sum += momentsOf(push.layer.y != 0 ? linearDepth(z) : z, code);
        }
        imageStore(blurredX, ivec3(at.xy, 0), sum / float(2 * radius + 1));
    } else {
        for (int k = -radius; k <= radius; ++k)
            sum += imageLoad(blurredX, ivec3(at.x, clamp(at.y + k, 0, size.y - 1), 0));
        imageStore(moments, at, sum / float(2 * radius + 1));
    }
}
