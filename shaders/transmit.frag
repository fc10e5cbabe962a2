// shaders/transmit.frag: one semi-transparent caster's fragment in the transmittance map
// (raster/shadow_pass.h). Target 0 is blended multiplicatively (dst · src): it holds the product
// of (1 − opacity) of every counted fragment in front of the opaque depth; target 1 is blended
// with MIN: the nearest counted fragment's depth, so the lit pass applies the product only to
// receivers behind it.
// Compiled again with SHADOWLAB_REST_LAYER (kTransmitFragRestSpv): the second pass, which
// reads the first pass's nearest depth D1 and counts only fragments behind it, so its targets hold
// the product of everything behind the nearest layer (T_rest) and the nearest depth of that (D2).
#version 450
#extension GL_GOOGLE_include_directive : require
#include "interface.h"

layout(push_constant) uniform Push { TransmitPush push; };
#ifdef SHADOWLAB_REST_LAYER
// The first pass's nearest depths (TransmittanceMaps::nearDepth), read at this fragment's texel.
layout(set = 0, binding = 0) uniform sampler2DArray nearDepths;
#endif

layout(location = 0) in vec3 inPosition;
layout(location = 1) in vec3 inNormal;

layout(location = 0) out float outTransmittance;
layout(location = 1) out float outNearDepth;

void main() {
    // DESIGN.md: an object multiplies the light by 1 − opacity once, however many of its surfaces
    // a ray crosses. A ray from the light enters a closed convex object through exactly one
    // surface facing the light, so a closed object counts only those (decided by its normal, not
    // by the winding, so it holds for every mesh's index order); an open surface (a quad) counts
    // every fragment (a ray crosses it once).
    if (push.params.y > 0.5) {
        const vec3 toLight = push.light.w > 0.5 ? push.light.xyz - inPosition : push.light.xyz;
        if (dot(inNormal, toLight) <= 0.0) discard;
    }
#ifdef SHADOWLAB_REST_LAYER
    // Only fragments clearly behind the nearest layer: the nearest layer's own fragment is drawn
    // by the same vertex shader and matrix in both passes and has exactly D1 (params.w, the
    // separation raster/tolerances.h gives, only absorbs rounding differences between pipelines).
    const float nearest = texelFetch(nearDepths, ivec3(ivec2(gl_FragCoord.xy), int(push.params.z)), 0).r;
    if (!(gl_FragCoord.z > nearest + push.params.w)) discard;
#endif
    outTransmittance = push.params.x;
    outNearDepth = gl_FragCoord.z;
}
