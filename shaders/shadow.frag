// shaders/shadow.frag: writes which object is nearest the light in each texel (the blocker-id
// map), so that the lit pass can tell which object shadowed a point, the receiver itself
// (self-shadow acne) or another one.
#version 450

layout(location = 0) flat in uint inObjectId;
layout(location = 0) out uint outBlockerId;

void main() {
    outBlockerId = inObjectId;
}
