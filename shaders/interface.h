// shaders/interface.h: the uniform and push-constant layouts shared by the GLSL shaders and
// raster/ (C++). Only vec4 and mat4 members, so std140 and C++ (glm) layouts are identical.
#ifndef SHADOWLAB_SHADERS_INTERFACE_H
#define SHADOWLAB_SHADERS_INTERFACE_H

// Shadowed lights one lit pass handles; a UBO array needs a fixed size, and eight directional
// lights is far more than any scene we ship (the renderer throws above it).
#define SHADOWLAB_MAX_LIGHTS 8
// Cascaded shadow maps per directional light (scene::kMaxCascades; raster/ static_asserts that).
#define SHADOWLAB_MAX_CASCADES 4
// Shadow-map layers: a point light has six (its cube faces), a cascaded light four.
#define SHADOWLAB_MAX_LAYERS (SHADOWLAB_MAX_LIGHTS * 6)

// Filter codes in LightData.params.y (floats: the interface has vec4s only); the values
// follow scene::ShadowFilter.
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

// Light kinds in LightData.kind.x.
#define SHADOWLAB_LIGHT_DIRECTIONAL 0
#define SHADOWLAB_LIGHT_SPOT 1
#define SHADOWLAB_LIGHT_POINT 2

#ifdef __cplusplus
#include <glm/glm.hpp>
namespace shadowlab::shaders {
using vec4 = glm::vec4;
using mat4 = glm::mat4;
using ivec4 = glm::ivec4;
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

// Push constants of the moment passes (shaders/moments.comp, raster/moment_maps.h).
struct MomentPush {
    ivec4 info;   // x: filter code, y: pass (0: moments + blur along x, 1: blur along y), z: blur
                  // radius in texels, w: the maps' side in texels
    vec4 params;  // x: EVSM positive exponent, y: EVSM negative exponent, z: ESM exponent
};

struct LightData {
    // Camera-relative world position -> homogeneous shadow-map coordinates: (u, v) = xy / w in
    // 0..1. Directional: orthographic, w = 1 and z = depth 0..1 (linear along the light). Point:
    // no matrix (lit.frag builds each face's projection) but each cube face's near and far (face
    // k = 0..5, +X −X +Y −Y +Z −Z: near in column k / 4, far in column 2 + k / 4, row k % 4).
    mat4 toShadow;
    vec4 toLight;    // directional: xyz unit vector toward the light; spot, point: xyz
                     // camera-relative position. w: shadow-map layer (point: of its +X face,
                     // the six faces +X −X +Y −Y +Z −Z follow), -1 = no shadow test
    vec4 radiance;   // rgb: color * intensity; w: intensity * mean of color (the visibility weight)
    vec4 bias;       // x: depth bias (world), y: slope bias (texels), z: texel world size
                     // (spot, point: per unit of distance along its axis), w: directional: shadow-map
                     // depth per world unit
    vec4 params;     // x: max tan(theta) for the slope bias, y: filter code, z: normal offset
                     // (texels), w: pcf size (taps per side / Poisson diameter in texels)
    vec4 kind;       // x: SHADOWLAB_LIGHT_*, y: spot: cos(cone half-angle); point: tan of each
                     // cube face's half field of view; directional: number of cascades (0 or 1:
                     // one map, described by this struct), z: spot: near, w: spot: far (distances
                     // along the map's axis; a point light's faces have theirs in toShadow)
    vec4 axis;       // spot: xyz unit direction the light travels; w: spot, point: light size
                     // (diameter, world units; 0 = a point), for PCSS
};

// One cascade of a directional light's cascaded shadow map; its layer is the light's layer
// (LightData.toLight.w) plus the cascade's index.
struct CascadeData {
    mat4 toShadow;  // as LightData.toShadow, for this cascade's map
    vec4 params;    // x: far end of the cascade's slice (view depth); y: texel world size;
                    // z: shadow-map depth per world unit; w: depth bias (world)
};

// The lit pass's uniform buffer.
struct LitUniforms {
    mat4 viewProj;    // camera-relative world position -> clip (reversed Z)
    vec4 forward;     // xyz: camera forward (view depth = dot(position, forward)); w: ambient
    vec4 background;  // rgb: background color; w: unused
    vec4 counts;      // x: number of lights; y: the shadow maps' side in texels (every layer); z: cascade
                      // blend band (fraction of a slice, 0 = off); w: near end of cascade 0's slice
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
static_assert(sizeof(MomentPush) == 2 * 16, "MomentPush must match std430 push constants");
static_assert(sizeof(TransmitPush) == 64 + 2 * 16, "TransmitPush must match std430 push constants");
static_assert(sizeof(LightData) == 64 + 6 * 16, "LightData must match std140");
static_assert(sizeof(CascadeData) == 64 + 16, "CascadeData must match std140");
static_assert(sizeof(LitUniforms) == 64 + 3 * 16 + SHADOWLAB_MAX_LIGHTS * sizeof(LightData) +
                                         SHADOWLAB_MAX_LIGHTS * SHADOWLAB_MAX_CASCADES * sizeof(CascadeData),
              "LitUniforms must match std140");
}  // namespace shadowlab::shaders
#endif

#endif  // SHADOWLAB_SHADERS_INTERFACE_H
