// bench/shaders/bare_lit.frag: the bare baseline's shading: N·L times one shadow lookup with
// 2x2 PCF, into one RGBA8 target. HARDWARE_PCF: a LINEAR compare sampler does the 2x2 PCF;
// otherwise (the device cannot filter the map's format linearly) one compare gather and the
// bilinear weights in the shader, which is the same 2x2 PCF.
#version 450

layout(set = 0, binding = 0, std140) uniform Uniforms {
    mat4 viewProj;
    mat4 toShadow;
    vec4 toLight;
    vec4 color;
    vec4 slope;
};
layout(set = 0, binding = 1) uniform sampler2DShadow shadowMap;
layout(constant_id = 0) const bool kHardwarePcf = true;

layout(location = 0) in vec3 inShadow;
layout(location = 1) in vec3 inNormal;
layout(location = 0) out vec4 outColor;

void main() {
    const float ndotl = abs(dot(normalize(inNormal), toLight.xyz));
    // Constant + slope-scaled bias (tan(theta) clamped at 10), as a bare renderer has to have.
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
    outColor = vec4(color.rgb * (ndotl * v) + color.w, 1.0);
}
