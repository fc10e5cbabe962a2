// shaders/lit.vert: the camera pass; passes the camera-relative position on so that the
// fragment shader can find its place in every shadow map, and where lit.frag asks for them
// (kVertexLightConstants) the one light's constants, which it then need not read per pixel.
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
// The first light's homogeneous map coordinates of the position (toShadow · (p, 1)) and of the
// normal (toShadow · (n, 0)), which lit.frag interpolates instead of a matrix product per fragment
// where that light is the only one and directional or a spot (kVertexLightCoordinates); unused
// otherwise. The w row matters for a spot (its perspective divide and its distance along the axis).
#ifndef SHADOWLAB_NO_VERTEX_LIGHT
layout(location = 3) out vec4 outLightCoordinates;
layout(location = 4) out vec4 outLightNormal;
#endif
// The object's albedo (lit.frag's), read here once per vertex instead of once per fragment.
layout(location = 5) flat out vec4 outAlbedo;
// kVertexLightConstants (lit_constants.glsl): the members of light 0's LightData that lit.frag reads
// there (its kind is a constant then: kLightKinds has one bit), packed into vec4s as lit.frag's
// lightAt() unpacks them, and LitUniforms' forward, ambient and map size; written only then.
// (Locations 0..13, 56 components: within the 64 every Vulkan device must take,
// maxVertexOutputComponents and maxFragmentInputComponents.)
// Neither is declared in the variants for lit.frag's modules without them (SHADOWLAB_BAKED_LIGHT,
// SHADOWLAB_NO_VERTEX_LIGHT: lit_constants.glsl), since llvmpipe stores every declared output.
#ifndef SHADOWLAB_BAKED_LIGHT
layout(location = 6) flat out vec4 outLight[6];
layout(location = 12) flat out vec4 outFrame[2];
#endif
#ifdef SHADOWLAB_ALPHA
// The lit_vert_alpha variant (scenes with MASK or BLEND materials): the texture coordinates of
// vertex binding 1 for lit.frag's alpha test (58 components in all).
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
#ifndef SHADOWLAB_NO_VERTEX_LIGHT
    outLightCoordinates = u.lights[0].toShadow * vec4(inPosition, 1.0);
    outLightNormal = u.lights[0].toShadow * vec4(inNormal, 0.0);
#endif
#ifndef SHADOWLAB_BAKED_LIGHT
    if (kVertexLightConstants && !kSpecializedLightConstants) {
        const LightData light = u.lights[0];
        outLight[0] = vec4(kVertexSpot ? light.position : light.towardLight, light.layer);
        outLight[1] = vec4(light.radiance, light.visibilityWeight);
        outLight[2] = vec4(light.depthBiasWorld, light.slopeBiasTexels, light.texelWorldSize, light.depthPerWorld);
        outLight[3] = vec4(light.maxSlopeTan, light.normalOffsetTexels, float(light.pcfSize), 0.0);
        if (kVertexSpot) {
            outLight[4] = vec4(light.spotDirection, light.spotCosCone);
            outLight[5] = vec4(light.mapNear, light.mapFar, light.lightSize, 0.0);
        }
        outFrame[0] = vec4(u.forward, u.ambient);
        outFrame[1] = vec4(u.mapSize, 0.0, 0.0, 0.0);
    }
#endif
    gl_Position = u.viewProj * vec4(inPosition, 1.0);
}
