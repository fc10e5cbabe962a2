// shaders/lit.vert: the camera pass; passes the camera-relative position on so that the
// fragment shader can find its place in every shadow map, and where lit.frag asks for them
// (kVertexLightConstants) the one light's constants, which it then need not read per pixel.
// No map coordinates: lit.frag forms them, with the matrix baked in where it can be, which costs
// llvmpipe less than a vertex output it stores, sets up and interpolates (docs/performance.md).
#version 450
#extension GL_GOOGLE_include_directive : require
#include "interface.h"
#include "lit_constants.glsl"

layout(set = 0, binding = 0, std140) uniform Uniforms { LitUniforms u; };
layout(set = 0, binding = 1, std430) readonly buffer Albedos { vec4 albedo[]; };  // per object; a: 1 − opacity

layout(location = 0) in vec3 inPosition;  // camera-relative world position
layout(location = 1) in vec3 inNormal;
layout(location = 2) in uint inObjectId;

layout(location = 0) out vec3 outPosition;
layout(location = 1) out vec3 outNormal;
#ifndef SHADOWLAB_NO_OBJECT_ID
layout(location = 2) flat out uint outObjectId;
#endif
// The object's albedo (lit.frag's), read here once per vertex instead of once per fragment.
layout(location = 15) flat out vec4 outAlbedo;
// kVertexLightConstants (lit_constants.glsl): the members of light 0's LightData that lit.frag reads
// there (its kind is a constant then: kLightKinds has one bit), packed into vec4s as lit.frag's
// lightAt() unpacks them, and LitUniforms' forward, ambient and map size; its toShadow's first
// three rows (a spot's last row in the slots' spare components); written only then. The
// lit_vert*_sun builds (SHADOWLAB_ONE_SUN, for the *_sun_map modules) put the rows in the slots a
// sun leaves spare (outLight[4], outLight[5], then outLight[3].w and outFrame[1].yzw) instead of
// three flat outputs more, which llvmpipe would set up per triangle (lit.frag oneMapMatrix).
// (The general build with the alpha test's coordinates declares locations 0..15, 64 components
// counted by whole locations: the most every Vulkan device must take, maxVertexOutputComponents and
// maxFragmentInputComponents; the *_sun builds 13.) None of them is declared in the variants for
// lit.frag's modules without them (SHADOWLAB_BAKED_LIGHT: lit_constants.glsl), since llvmpipe
// stores every declared output.
#ifndef SHADOWLAB_BAKED_LIGHT
#ifndef SHADOWLAB_ONE_SUN
layout(location = 3) flat out vec4 outMapRows[3];
#endif
layout(location = 6) flat out vec4 outLight[6];
layout(location = 12) flat out vec4 outFrame[2];
#endif
#ifdef SHADOWLAB_ALPHA
// The lit_vert_alpha variant (MASK or BLEND surfaces whose alpha can cut): the texture coordinates of
// vertex binding 1 for lit.frag's alpha test.
layout(location = 3) in vec2 inUv;
layout(location = 14) out vec2 outUv;
#endif

void main() {
    outPosition = inPosition;
    outNormal = inNormal;
#ifndef SHADOWLAB_NO_OBJECT_ID
    // (The lit_vert_no_id variant: for the size-optimized beauty-only fragment shaders without the
    // alpha test, from which spirv-opt removes the object id they do not read.)
    outObjectId = inObjectId;
#endif
#ifdef SHADOWLAB_ALPHA
    outUv = inUv;
#endif
    outAlbedo = albedo[inObjectId - 1u];
#ifndef SHADOWLAB_BAKED_LIGHT
    if (kVertexLightConstants && !kSpecializedLightConstants) {
        const LightData light = u.lights[0];
        const mat4 m = light.toShadow;  // (columns: row r is m[0][r], m[1][r], m[2][r], m[3][r])
        vec4 rows[4];
        for (int r = 0; r < 4; ++r) rows[r] = vec4(m[0][r], m[1][r], m[2][r], m[3][r]);
#ifdef SHADOWLAB_ONE_SUN
        // (The *_sun builds: the first three rows in the slots a sun leaves spare.)
        const vec4 spare = rows[2];
        outLight[4] = rows[0];
        outLight[5] = rows[1];
        outFrame[1] = vec4(u.mapSize, rows[2].yzw);
#else
        for (int r = 0; r < 3; ++r) outMapRows[r] = rows[r];
        const vec4 spare = kOneSpot ? rows[3] : vec4(0.0);  // a spot's last row
        outFrame[1] = vec4(u.mapSize, spare.zw, kOneSpot ? light.spotCosInner : 0.0);
#endif
        outLight[0] = vec4(kOneSpot ? light.position : light.towardLight, light.layer);
        outLight[1] = vec4(light.radiance, light.visibilityWeight);
        outLight[2] = vec4(light.depthBiasWorld, light.slopeBiasTexels, light.texelWorldSize, light.depthPerWorld);
        outLight[3] = vec4(light.maxSlopeTan, light.normalOffsetTexels, float(light.pcfSize), spare.x);
        if (kOneSpot) {
            outLight[4] = vec4(light.spotDirection, light.spotCosCone);
            outLight[5] = vec4(light.mapNear, light.mapFar, light.lightSize, spare.y);
        }
        outFrame[0] = vec4(u.forward, u.ambient);
    }
#endif
    gl_Position = u.viewProj * vec4(inPosition, 1.0);
}
