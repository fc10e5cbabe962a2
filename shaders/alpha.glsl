// shaders/alpha.glsl: alpha-tested and blended casters (raster/alpha_casters.h), included by
// shadow.frag and transmit.frag in their SHADOWLAB_ALPHA variants. One record per object id and
// every texture's alpha in one float array; sampled nearest, texel (floor(u·w), floor(v·h)) after
// the wrap, exactly as scene::sampleAlpha does for the ray tracer.
#ifndef SHADOWLAB_ALPHA_SET
#define SHADOWLAB_ALPHA_SET 0
#endif

struct AlphaRecord {
    // x: mode (0 opaque, 1 mask, 2 blend), y: the camera's cutoff (scene::Material::cameraCutoff:
    // MASK's alphaCutoff, BLEND's kBlendVisibleAlpha), z: alpha factor, w: opacity
    vec4 params;
    uvec4 texture; // x: first texel, y: width (0: no texture), z: height, w: wrapS + 4·wrapT
};
layout(std430, set = SHADOWLAB_ALPHA_SET, binding = 0) readonly buffer AlphaRecords { AlphaRecord alphaRecords[]; };
layout(std430, set = SHADOWLAB_ALPHA_SET, binding = 1) readonly buffer AlphaTexels { float alphaTexels[]; };

// scene::wrapTexel: 0 repeat, 1 clamp to edge, 2 mirrored repeat.
int alphaWrap(float c, int size, uint wrap) {
    const float limit = 1073741824.0;  // 2^30, as the C++ clamps before its cast
    const int i = int(clamp(floor(c * float(size)), -limit, limit));
    if (wrap == 1u) return clamp(i, 0, size - 1);
    if (wrap == 2u) {
        const int m = ((i % (2 * size)) + 2 * size) % (2 * size);
        return m < size ? m : 2 * size - 1 - m;
    }
    return ((i % size) + size) % size;
}

// alpha(uv) = factor × the texture's alpha (1 without a texture).
float alphaAt(uint id, vec2 uv) {
    const AlphaRecord r = alphaRecords[id];
    float a = r.params.z;
    if (r.texture.y > 0u) {
        const int w = int(r.texture.y), h = int(r.texture.z);
        const int x = alphaWrap(uv.x, w, r.texture.w & 3u), y = alphaWrap(uv.y, h, r.texture.w >> 2u);
        a *= alphaTexels[r.texture.x + uint(y * w + x)];
    }
    return a;
}

// MASK: alpha below the cutoff is fully transparent (glTF 2.0, 3.9.4).
bool alphaMasked(uint id, vec2 uv) {
    const AlphaRecord r = alphaRecords[id];
    return r.params.x == 1.0 && alphaAt(id, uv) < r.params.y;
}

// The camera looks through the texel (scene::Material::cameraSkips): MASK below the cutoff,
// BLEND below scene::kBlendVisibleAlpha; OPAQUE never.
bool alphaCameraSkips(uint id, vec2 uv) {
    const AlphaRecord r = alphaRecords[id];
    return r.params.x != 0.0 && alphaAt(id, uv) < r.params.y;
}
