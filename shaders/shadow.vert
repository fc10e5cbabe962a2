// shaders/shadow.vert: the depth pass from a light into its shadow map.
// Compiled again with SHADOWLAB_ALPHA: also passes the texture coordinates (vertex binding 1)
// to the alpha test of shadow.frag.
#version 450
#extension GL_GOOGLE_include_directive : require
#include "interface.h"

layout(push_constant) uniform Push { ShadowPush push; };

layout(location = 0) in vec3 inPosition;  // camera-relative world position
layout(location = 2) in uint inObjectId;

layout(location = 0) flat out uint outObjectId;
#ifdef SHADOWLAB_ALPHA
layout(location = 3) in vec2 inUv;
layout(location = 1) out vec2 outUv;
#endif

void main() {
    outObjectId = inObjectId;
#ifdef SHADOWLAB_ALPHA
    outUv = inUv;
#endif
    gl_Position = push.lightMatrix * vec4(inPosition, 1.0);
}
