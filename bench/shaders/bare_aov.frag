// bench/shaders/bare_aov.frag: the least a lit pass does that fills every channel of a Frame:
// bare_lit.frag's N·L and 2x2 PCF into a float RGB beauty, and the five R32F planes (visibility,
// object id, N·L, depth, blocker id) with the blocker id read from the id map (one nearest texel)
// where the point is shadowed. The floor under the AOV contract, not a design to ship.
#version 450

layout(set = 0, binding = 0, std140) uniform Uniforms {
    mat4 viewProj;
    mat4 toShadow;
    vec4 toLight;
    vec4 color;
    vec4 slope;
};
layout(set = 0, binding = 1) uniform sampler2DShadow shadowMap;
layout(set = 0, binding = 2) uniform usampler2D blockerIds;
layout(constant_id = 0) const bool kHardwarePcf = true;

layout(location = 0) in vec3 inShadow;
layout(location = 1) in vec3 inNormal;
layout(location = 2) flat in uint inObjectId;
layout(location = 0) out vec3 outBeauty;
layout(location = 1) out float outVisibility;
layout(location = 2) out float outObjectId;
layout(location = 3) out float outNdotL;
layout(location = 4) out float outDepth;
layout(location = 5) out float outBlockerId;

void main() {
    const float ndotl = abs(dot(normalize(inNormal), toLight.xyz));
    const float tanTheta = min(sqrt(max(1.0 - ndotl * ndotl, 0.0)) / ndotl, 10.0);
    const float ref = inShadow.z - toLight.w - slope.x * tanTheta;
    float v;
    if (kHardwarePcf) {
        v = texture(shadowMap, vec3(inShadow.xy, ref));
    } else {
        const float size = float(textureSize(shadowMap, 0).x);
        const vec2 t = inShadow.xy * size - 0.5;
        const vec2 i0 = floor(t);
        const vec2 f = t - i0;
        const vec4 g = textureGather(shadowMap, (i0 + 1.0) / size, ref);
        v = mix(mix(g.w, g.z, f.x), mix(g.x, g.y, f.x), f.y);
    }
    uint blocker = 0u;
    if (v < 0.5) blocker = texture(blockerIds, inShadow.xy).r;
    outBeauty = color.rgb * (ndotl * v) + color.w;
    outVisibility = v;
    outObjectId = float(inObjectId);
    outNdotL = ndotl;
    outDepth = 1.0 / gl_FragCoord.w;
    outBlockerId = float(blocker);
}
