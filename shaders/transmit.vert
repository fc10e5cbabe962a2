// shaders/transmit.vert: the transmittance pass from a light (raster/shadow_pass.h): the
// semi-transparent casters, with their position and normal for the facing test of transmit.frag.
// Compiled again with SHADOWLAB_ALPHA: also the object id and texture coordinates, for the alpha of
// MASK and textured BLEND casters.
#version 450
#extension GL_GOOGLE_include_directive : require
#include "interface.h"

layout(push_constant) uniform Push { TransmitPush push; };

layout(location = 0) in vec3 inPosition;  // camera-relative world position
layout(location = 1) in vec3 inNormal;

layout(location = 0) out vec3 outPosition;
layout(location = 1) out vec3 outNormal;
// The push constants transmit.frag reads, as flat outputs: lavapipe reads a push constant in a
// fragment shader lane by lane for every eight fragments, a flat input once per triangle.
layout(location = 4) flat out vec4 outLight;
layout(location = 5) flat out vec4 outParams;
#ifdef SHADOWLAB_ALPHA
layout(location = 2) in uint inObjectId;
layout(location = 3) in vec2 inUv;
layout(location = 2) flat out uint outObjectId;
layout(location = 3) out vec2 outUv;
#endif

void main() {
    outPosition = inPosition;
    outNormal = inNormal;
    outLight = push.light;
    outParams = push.params;
#ifdef SHADOWLAB_ALPHA
    outObjectId = inObjectId;
    outUv = inUv;
#endif
    gl_Position = push.lightMatrix * vec4(inPosition, 1.0);
}
