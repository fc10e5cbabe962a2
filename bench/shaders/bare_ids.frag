// bench/shaders/bare_ids.frag: the AOV floor's blocker-id map: the nearest object's id per texel.
#version 450

layout(location = 0) flat in uint inObjectId;
layout(location = 0) out uint outBlockerId;

void main() { outBlockerId = inObjectId; }
