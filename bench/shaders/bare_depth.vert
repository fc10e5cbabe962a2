// bench/shaders/bare_depth.vert: the bare baseline's depth pass from the light (no fragment
// shader: depth only).
#version 450

layout(push_constant) uniform Push { mat4 lightMatrix; };
layout(location = 0) in vec3 inPosition;

void main() { gl_Position = lightMatrix * vec4(inPosition, 1.0); }
