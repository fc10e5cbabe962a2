// bench/shaders/bare_ids.vert: the AOV floor's depth pass from the light, with the object id for
// the blocker-id map.
#version 450

layout(push_constant) uniform Push { mat4 lightMatrix; };
layout(location = 0) in vec3 inPosition;
layout(location = 2) in uint inObjectId;
layout(location = 0) flat out uint outObjectId;

void main() {
    outObjectId = inObjectId;
    gl_Position = lightMatrix * vec4(inPosition, 1.0);
}
