// bench/shaders/bare_aov.vert: bare_lit.vert plus what the AOV floor's fragment shader needs: the
// object id (flat) and the view depth.
#version 450

layout(set = 0, binding = 0, std140) uniform Uniforms {
    mat4 viewProj;
    mat4 toShadow;
    vec4 toLight;
    vec4 color;
    vec4 slope;
};
layout(location = 0) in vec3 inPosition;
layout(location = 1) in vec3 inNormal;
layout(location = 2) in uint inObjectId;

layout(location = 0) out vec3 outShadow;
layout(location = 1) out vec3 outNormal;
layout(location = 2) flat out uint outObjectId;

void main() {
    outShadow = (toShadow * vec4(inPosition, 1.0)).xyz;
    outNormal = inNormal;
    outObjectId = inObjectId;
    gl_Position = viewProj * vec4(inPosition, 1.0);
}
