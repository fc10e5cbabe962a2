// shaders/transmit.frag: one semi-transparent caster's fragment in the transmittance map
// (raster/shadow_pass.h). Target 0 is blended multiplicatively (dst · src): it holds the product
// of (1 − opacity) of every counted fragment in front of the opaque depth; target 1 is blended
// with MIN: the nearest counted fragment's depth, so the lit pass applies the product only to
// receivers behind it.
// Compiled again with SHADOWLAB_REST_LAYER (kTransmitFragRestSpv): the second pass, which
// reads the first pass's nearest depth D1 and counts only fragments behind it, so its targets hold
// the product of everything behind the nearest layer (T_rest) and the nearest depth of that (D2).
// With SHADOWLAB_ALPHA (and SHADOWLAB_REST_ALPHA, the second pass so) the object's alpha record
// decides per fragment: MASK texels below the cutoff are discarded, textured BLEND lets
// 1 − opacity·alpha(uv) through (scene::Material::transmittance).
#version 450
#extension GL_GOOGLE_include_directive : require
#include "interface.h"
#ifdef SHADOWLAB_REST_ALPHA
#define SHADOWLAB_REST_LAYER 1
#define SHADOWLAB_ALPHA 1
#define SHADOWLAB_ALPHA_SET 1
#endif
#ifdef SHADOWLAB_ALPHA
#include "alpha.glsl"
layout(location = 2) flat in uint inObjectId;
layout(location = 3) in vec2 inUv;
#endif

#ifdef SHADOWLAB_REST_LAYER
// The first pass's nearest depths (TransmittanceMaps::nearDepth), read at this fragment's texel.
layout(set = 0, binding = 0) uniform sampler2DArray nearDepths;
#endif

layout(location = 0) in vec3 inPosition;
layout(location = 1) in vec3 inNormal;
// TransmitPush's light and params (shaders/interface.h), from transmit.vert.
layout(location = 4) flat in vec4 inLight;
layout(location = 5) flat in vec4 inParams;

layout(location = 0) out float outTransmittance;
layout(location = 1) out float outNearDepth;

void main() {
    // DESIGN.md: an object multiplies the light by 1 − opacity once, however many of its surfaces
    // a ray crosses. A ray from the light enters a closed convex object through exactly one
    // surface facing the light, so a closed object counts only those (decided by its normal, not
    // by the winding, so it holds for every mesh's index order); an open surface (a quad) counts
    // every fragment (a ray crosses it once).
    if (inParams.y > 0.5) {
        const vec3 toLight = inLight.w > 0.5 ? inLight.xyz - inPosition : inLight.xyz;
        if (dot(inNormal, toLight) <= 0.0) discard;
    }
#ifdef SHADOWLAB_REST_LAYER
    // Only fragments clearly behind the nearest layer: the nearest layer's own fragment is drawn
    // by the same vertex shader and matrix in both passes and has exactly D1 (params.w, the
    // separation raster/tolerances.h gives, only absorbs rounding differences between pipelines).
    const float nearest = texelFetch(nearDepths, ivec3(ivec2(gl_FragCoord.xy), int(inParams.z)), 0).r;
    if (!(gl_FragCoord.z > nearest + inParams.w)) discard;
#endif
#ifdef SHADOWLAB_ALPHA
    if (alphaMasked(inObjectId, inUv)) discard;
    const AlphaRecord alpha = alphaRecords[inObjectId];
    // (An untextured caster's is inParams.x, as without the variant: rounded once from the double.)
    outTransmittance =
        alpha.params.x == 2.0 && alpha.texture.y > 0u ? 1.0 - alpha.params.w * alphaAt(inObjectId, inUv) : inParams.x;
#else
    outTransmittance = inParams.x;
#endif
    outNearDepth = gl_FragCoord.z;
}
