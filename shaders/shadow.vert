// shaders/shadow.vert: the depth pass from a light into its shadow map.
#version 450
#extension GL_GOOGLE_include_directive : require
#include "interface.h"

layout(push_constant) uniform Push { ShadowPush push; };

layout(location = 0) in vec3 inPosition;  // camera-relative world position
layout(location = 2) in uint inObjectId;

layout(location = 0) flat out uint outObjectId;

void main() {
    outObjectId = inObjectId;
    gl_Position = push.lightMatrix * vec4(inPosition, 1.0);
}
