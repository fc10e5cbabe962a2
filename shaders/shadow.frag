// shaders/shadow.frag: writes which object is nearest the light in each texel (the blocker-id
// map), so that the lit pass can tell which object shadowed a point, the receiver itself
// (self-shadow acne) or another one.
// Compiled again with SHADOWLAB_ALPHA (alpha-tested casters: MASK texels below the cutoff are
// discarded, so they neither write depth nor an id) and with SHADOWLAB_ALPHA_DEPTH_ONLY (the same
// test for a depth pass without the id target).
#version 450
#extension GL_GOOGLE_include_directive : require
#ifdef SHADOWLAB_ALPHA_DEPTH_ONLY
#define SHADOWLAB_ALPHA 1
#endif
#ifdef SHADOWLAB_ALPHA
#include "alpha.glsl"
layout(location = 1) in vec2 inUv;
#endif

layout(location = 0) flat in uint inObjectId;
#ifndef SHADOWLAB_ALPHA_DEPTH_ONLY
layout(location = 0) out uint outBlockerId;
#endif

void main() {
#ifdef SHADOWLAB_ALPHA
    if (alphaMasked(inObjectId, inUv)) discard;
#endif
#ifndef SHADOWLAB_ALPHA_DEPTH_ONLY
    outBlockerId = inObjectId;
#endif
}
