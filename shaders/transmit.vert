// shaders/transmit.vert: the transmittance pass from a light (raster/shadow_pass.h): the
// semi-transparent casters, with their position and normal for the facing test of transmit.frag.
#version 450
#extension GL_GOOGLE_include_directive : require
#include "interface.h"

layout(push_constant) uniform Push { TransmitPush push; };

layout(location = 0) in vec3 inPosition;  // camera-relative world position
layout(location = 1) in vec3 inNormal;

layout(location = 0) out vec3 outPosition;
layout(location = 1) out vec3 outNormal;

void main() {
    outPosition = inPosition;
    outNormal = inNormal;
    gl_Position = push.lightMatrix * vec4(inPosition, 1.0);
}
