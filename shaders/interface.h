// shaders/interface.h: the uniform and push-constant layouts shared by the GLSL shaders and
// raster/ (C++). The lit pass's uniforms have one named member per meaning, laid out so that
// std140 and C++ (glm) place every member at the same offset:
// - float and int are 4 bytes with 4-byte alignment in both;
// - a vec3 is 16-byte aligned in std140 but 4-byte aligned in glm, so every vec3 here starts a
//   16-byte group, and the float or int after it fills the group's last 4 bytes (std140 packs a
//   scalar right after a vec3, as C++ does);
// - std140 pads each array element and each struct to a multiple of 16 bytes: the one array of
//   small structs (LightData::pointFaces) has SHADOWLAB_ALIGN16, which C++ reads as alignas(16);
// - no bool (4 bytes in GLSL, 1 in C++), no float or vec2 arrays (16-byte elements in std140).
// The static_asserts below check sizes and offsets on the C++ side; tests/shaders/interface_test.cpp
// checks them against the offsets glslang gives lit.frag's uniform block.
#ifndef SHADOWLAB_SHADERS_INTERFACE_H
#define SHADOWLAB_SHADERS_INTERFACE_H

// Shadowed lights one lit pass handles; a UBO array needs a fixed size, and eight directional
// lights is far more than any scene we ship (the renderer throws above it).
#define SHADOWLAB_MAX_LIGHTS 8
// Cascaded shadow maps per directional light (scene::kMaxCascades; raster/ static_asserts that).
#define SHADOWLAB_MAX_CASCADES 4
// Shadow-map layers: a point light has six (its cube faces), a cascaded light four.
#define SHADOWLAB_MAX_LAYERS (SHADOWLAB_MAX_LIGHTS * 6)

// Filter codes (LightData::filterCode, moments.comp's kFilter); the values follow scene::ShadowFilter.
#define SHADOWLAB_FILTER_NONE 0
#define SHADOWLAB_FILTER_PCF2X2 1
#define SHADOWLAB_FILTER_PCF 2
#define SHADOWLAB_FILTER_POISSON 3
#define SHADOWLAB_FILTER_PCSS 4
#define SHADOWLAB_FILTER_VSM 5
#define SHADOWLAB_FILTER_EVSM2 6
#define SHADOWLAB_FILTER_EVSM4 7
#define SHADOWLAB_FILTER_ESM 8
#define SHADOWLAB_FILTER_MSM 9

// Light kinds (LightData::kind).
#define SHADOWLAB_LIGHT_DIRECTIONAL 0
#define SHADOWLAB_LIGHT_SPOT 1
#define SHADOWLAB_LIGHT_POINT 2

#ifdef __cplusplus
#include <cstddef>

#include <glm/glm.hpp>
namespace shadowlab::shaders {
using vec3 = glm::vec3;
using vec4 = glm::vec4;
using mat4 = glm::mat4;
using ivec4 = glm::ivec4;
// std140 aligns every struct to 16 bytes; C++ must be told (see the top of this file).
#define SHADOWLAB_ALIGN16 alignas(16)
#else
#define SHADOWLAB_ALIGN16
#endif

// Push constants of the shadow (depth-only) pass.
struct ShadowPush {
    mat4 lightMatrix;  // camera-relative world position -> light clip space (z 0..1, light side 0)
};

// Push constants of the transmittance pass (semi-transparent casters; raster/shadow_pass.h).
struct TransmitPush {
    mat4 lightMatrix;  // as ShadowPush
    vec4 light;        // w = 0: xyz unit vector toward a directional light; w = 1: xyz the light's
                       // camera-relative position
    vec4 params;       // x: the object's transmittance 1 − opacity; y: 1 = closed (count only the
                       // surfaces facing the light), 0 = open (count every fragment); second pass
                       // only (behind the nearest layer): z: the layer, w: the depth separation
};

// Push constants of the moment passes (shaders/moments.comp, raster/moment_maps.h), one
// dispatch per layer and pass.
// (The pass, the filter code, the blur radius, the maps' side and the exponents are the pipeline's
// specialization constants: shaders/moments.comp.)
struct MomentPush {
    ivec4 layer;   // x: the array layer this dispatch writes; y: 1 = perspective (spot, cube face):
                   // its stored depths are made linear over `range` first, 0 = orthographic (kept)
    vec4 range;    // perspective layers: x: near, y: far (distances along the layer's axis)
    ivec4 window;  // the texels this dispatch writes: [x, z) x [y, w), within the map
};

// A point light's cube face: its depth range along the face's axis (each face's is fitted on its
// own), the near and far of the face's perspective map.
struct SHADOWLAB_ALIGN16 PointFace {
    float near;
    float far;
};

// One light of the lit pass. Members that belong to one kind of light are named for it or say so;
// the others are zero for it.
struct LightData {
    // Camera-relative world position -> homogeneous shadow-map coordinates: (u, v) = xy / w in
    // 0..1. Directional: orthographic, w = 1 and z = depth 0..1 (linear along the light); a
    // cascaded light: cascade 0's (CascadeData has every cascade's). Spot: perspective, w the
    // distance along its axis. Point: unused (lit.frag builds each face's projection).
    mat4 toShadow;
    vec3 position;  // spot, point: camera-relative position
    // The light's first shadow-map layer, -1 = no shadow test. Point: its +X face's, the six faces
    // +X −X +Y −Y +Z −Z follow; cascaded: cascade 0's, the others follow.
    float layer;
    vec3 towardLight;          // directional: unit vector toward the light
    int cascadeCount;          // directional: number of cascades (0 or 1: one map, described by this struct)
    vec3 spotDirection;        // spot: unit vector the light travels along, its map's axis
    float spotCosCone;         // spot: cosine of the cone's half-angle
    vec3 radiance;             // color · intensity
    float visibilityWeight;    // intensity · mean of color: the light's weight in the visibility AOV
    float depthBiasWorld;      // constant depth bias, world units
    float slopeBiasTexels;     // slope-scaled bias, texels per unit of tan(θ)
    float texelWorldSize;      // a map texel's world size (spot, point: per unit of distance along the axis)
    float depthPerWorld;       // directional: shadow-map depth per world unit (1 / depth range)
    float maxSlopeTan;         // cap on tan(θ) in the slope bias
    int filterCode;            // SHADOWLAB_FILTER_* (lit.frag uses kFilter, the same code)
    float normalOffsetTexels;  // receivers move this many texels along their normal before the lookup
    int pcfSize;               // pcf: taps per side; poisson: kernel diameter in texels
    int kind;                  // SHADOWLAB_LIGHT_*
    float lightSize;           // spot, point: diameter (world units; 0 = a point), for PCSS
    // The near and far distance, along its axis, of the perspective map being read: a spot's
    // one map. Point: zero here; lit.frag sets them to the face it reads (pointFaces).
    float mapNear;
    float mapFar;
    float pointFaceTan;  // point: tan of each cube face's half field of view (> 1: the faces overlap)
    // spot: cosine of the inner cone's half-angle, within which it is at full intensity (scene::Light
    // innerConeAngleDegrees); at or below spotCosCone the edge is hard
    float spotCosInner;
    PointFace pointFaces[6];  // point: face k = 0..5, +X −X +Y −Y +Z −Z (layer + k)
};

// One cascade of a directional light's cascaded shadow map; its layer is the light's layer
// (LightData::layer) plus the cascade's index. The last three replace the light's members of the
// same names.
struct CascadeData {
    mat4 toShadow;   // as LightData::toShadow, for this cascade's map
    float sliceFar;  // view depth where the cascade's slice ends
    float texelWorldSize;
    float depthPerWorld;
    float depthBiasWorld;
};

// The lit pass's uniform buffer.
struct LitUniforms {
    mat4 viewProj;  // camera-relative world position -> clip (reversed Z)
    vec3 forward;   // camera forward (view depth = dot(position, forward))
    float ambient;
    vec3 background;         // background color
    int lightCount;          // number of lights (lit.frag uses kLightCount, the same number)
    float mapSize;           // the shadow maps' side in texels (every layer)
    float cascadeBlendBand;  // cascade blend band, a fraction of a slice (0 = off)
    float cascadeStart;      // view depth where cascade 0's slice starts
    LightData lights[SHADOWLAB_MAX_LIGHTS];
    CascadeData cascades[SHADOWLAB_MAX_LIGHTS * SHADOWLAB_MAX_CASCADES];  // light i: i*MAX_CASCADES + c
};

// Per shadow-map layer, the texels its transmittance maps hold this frame (raster/shadow_pass.h
// TransmittanceMaps): x0, y0, x1, y1, x1 and y1 excluded (empty: nothing). Outside it the maps are
// neither drawn nor cleared, and lit.frag reads "nothing semi-transparent" there.
struct TransmitWindows {
    vec4 rect[SHADOWLAB_MAX_LAYERS];
};

#ifdef __cplusplus
static_assert(sizeof(TransmitWindows) == SHADOWLAB_MAX_LAYERS * 16, "TransmitWindows must match std140");
static_assert(sizeof(ShadowPush) == 64, "ShadowPush must match std430 push constants");
static_assert(sizeof(MomentPush) == 3 * 16, "MomentPush must match std430 push constants");
static_assert(sizeof(TransmitPush) == 64 + 2 * 16, "TransmitPush must match std430 push constants");
static_assert(sizeof(PointFace) == 16, "PointFace must match std140 (an array element)");
// The offsets std140 gives (16-byte groups; pointFaces and lights aligned to 16).
static_assert(offsetof(LightData, position) == 64 && offsetof(LightData, layer) == 76);
static_assert(offsetof(LightData, towardLight) == 80 && offsetof(LightData, cascadeCount) == 92);
static_assert(offsetof(LightData, spotDirection) == 96 && offsetof(LightData, spotCosCone) == 108);
static_assert(offsetof(LightData, radiance) == 112 && offsetof(LightData, visibilityWeight) == 124);
static_assert(offsetof(LightData, depthBiasWorld) == 128 && offsetof(LightData, depthPerWorld) == 140);
static_assert(offsetof(LightData, maxSlopeTan) == 144 && offsetof(LightData, pcfSize) == 156);
static_assert(offsetof(LightData, kind) == 160 && offsetof(LightData, mapFar) == 172);
static_assert(offsetof(LightData, pointFaceTan) == 176 && offsetof(LightData, spotCosInner) == 180 &&
              offsetof(LightData, pointFaces) == 192);
static_assert(sizeof(LightData) == 192 + 6 * 16, "LightData must match std140");
static_assert(offsetof(CascadeData, sliceFar) == 64 && offsetof(CascadeData, depthBiasWorld) == 76);
static_assert(sizeof(CascadeData) == 64 + 16, "CascadeData must match std140");
static_assert(offsetof(LitUniforms, forward) == 64 && offsetof(LitUniforms, ambient) == 76);
static_assert(offsetof(LitUniforms, background) == 80 && offsetof(LitUniforms, lightCount) == 92);
static_assert(offsetof(LitUniforms, mapSize) == 96 && offsetof(LitUniforms, cascadeStart) == 104);
static_assert(offsetof(LitUniforms, lights) == 112);
static_assert(sizeof(LitUniforms) == 112 + SHADOWLAB_MAX_LIGHTS * sizeof(LightData) +
                                         SHADOWLAB_MAX_LIGHTS * SHADOWLAB_MAX_CASCADES * sizeof(CascadeData),
              "LitUniforms must match std140");
}  // namespace shadowlab::shaders
#endif

#endif  // SHADOWLAB_SHADERS_INTERFACE_H
