// bench/shaders/bare_lit.vert: the bare baseline's camera pass: clip position, the point in
// shadow-map space, the normal.
#version 450

layout(set = 0, binding = 0, std140) uniform Uniforms {
    mat4 viewProj;
    mat4 toShadow;  // camera-relative position -> (u, v, depth) of the map
    vec4 toLight;   // xyz: unit vector toward the light; w: depth bias in map depth units
    vec4 color;     // rgb: albedo * light color * intensity; w: ambient
    vec4 slope;     // x: slope bias per unit of tan(theta), in map depth units
};
layout(location = 0) in vec3 inPosition;
layout(location = 1) in vec3 inNormal;

layout(location = 0) out vec3 outShadow;
layout(location = 1) out vec3 outNormal;

void main() {
    outShadow = (toShadow * vec4(inPosition, 1.0)).xyz;
    outNormal = inNormal;
    gl_Position = viewProj * vec4(inPosition, 1.0);
}
