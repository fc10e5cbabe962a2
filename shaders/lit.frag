// shaders/lit.frag: shading of scene/shading.h with a shadow-map test per light, and the
// Frame's AOVs. Biases are applied here in world units, so they mean the same on every driver
// and depth format (the hardware depth-bias state is not used).
#version 450
#extension GL_GOOGLE_include_directive : require
#extension GL_EXT_control_flow_attributes : require
#include "interface.h"

layout(set = 0, binding = 0, std140) uniform Uniforms { LitUniforms u; };
// NEAREST depth-compare sampler: each tap returns "ref <= stored" for one texel.
layout(set = 0, binding = 2) uniform sampler2DArrayShadow shadowMaps;
// The object nearest the light in each texel (0 = none), same layout as shadowMaps.
layout(set = 0, binding = 3) uniform usampler2DArray blockerIds;
// The same maps' raw depths (NEAREST, no compare; 1 outside): the PCSS blocker search reads them.
layout(set = 0, binding = 4) uniform sampler2DArray shadowDepths;
// Semi-transparent casters (raster/shadow_pass.h TransmittanceMaps, same layout; NEAREST, 1
// outside): the product of 1 − opacity of those in front of the opaque depth, and the depth of
// the nearest of them.
layout(set = 0, binding = 5) uniform sampler2DArray transmittanceMaps;
layout(set = 0, binding = 6) uniform sampler2DArray transparentDepths;
// The same two for the semi-transparent fragments behind the nearest one only (its layer
// excluded): T_rest and D2, so that a receiver on the second layer gets the first layer's factor.
layout(set = 0, binding = 7) uniform sampler2DArray restTransmittanceMaps;
layout(set = 0, binding = 8) uniform sampler2DArray secondTransparentDepths;
// The filterable maps' blurred moments (raster/moment_maps.h; LINEAR, clamp to edge).
layout(set = 0, binding = 9) uniform sampler2DArray momentMaps;
// Each layer's transmittance window: the four maps above are drawn only there (raster/shadow_pass.h).
layout(set = 0, binding = 10, std140) uniform TransmitWindowBlock { TransmitWindows transmitWindows; };

// PCSS: the blocker search looks at most this fraction of the map's side from the point, and the
// penumbra filter is at most this fraction wide (diameter). The tap count is fixed (16 each), so
// these bound how sparse the taps get, not the cost; a fraction, not texels, so a finer map of the
// same scene keeps the same world-size limits.
const float kPcssMaxSearchFraction = 1.0 / 16.0;
const float kPcssMaxFilterFraction = 1.0 / 8.0;

layout(location = 0) in vec3 inPosition;  // camera-relative world position
layout(location = 1) in vec3 inNormal;
layout(location = 2) flat in uint inObjectId;
// The object's albedo (rgb) and 1 − opacity (a), which lit.vert reads from the per-object buffer
// (binding 1): flat, so the same value as a read here, without a buffer lookup per fragment.
layout(location = 15) flat in vec4 inAlbedo;
// kVertexLightConstants: light 0's constants, and LitUniforms' forward, ambient and map size, from
// lit.vert (lightAt(), viewForward(), ambient(), mapSize()). Not declared in the modules for baked
// constants (SHADOWLAB_BAKED_LIGHT, lit_constants.glsl): llvmpipe sets up every declared input
// per triangle, read or not.
#ifndef SHADOWLAB_BAKED_LIGHT
#ifndef SHADOWLAB_ONE_SUN
layout(location = 3) flat in vec4 inMapRows[3];  // kOneMapLight: its toShadow's first three rows
#endif
layout(location = 6) flat in vec4 inLight[6];
layout(location = 12) flat in vec4 inFrame[2];
#endif

// One color attachment per Frame channel (raster/lit_pass.h LitPlane), so that each is the
// Frame's own layout and lavapipe can render into the Frame's memory (no readback copy).
layout(location = 0) out vec4 outBeauty;  // rgb: linear color (an RGB target keeps only that)
#ifndef SHADOWLAB_BEAUTY_ONLY
// (The lit_beauty.frag variant, for frames that want only the beauty, float or the 8-bit display
// target, has no AOV outputs: the targets it would leave unwritten are not attached.)
layout(location = 1) out float outVisibility;
layout(location = 2) out float outObjectId;
layout(location = 3) out float outNdotL;  // max over lights
layout(location = 4) out float outDepth;  // view depth
layout(location = 5) out float outBlockerId;
#endif
#ifdef SHADOWLAB_LIGHT_OUTPUTS
// Per-light visibility (the lit_lights.frag variant, for scenes with more than one light):
// light i in component i % 4 of target i / 4; 0 where the light does not reach (N·L <= 0,
// outside a spot's cone), as the total's weights.
layout(location = 6) out vec4 outLights0;
layout(location = 7) out vec4 outLights1;
#endif

#include "lit_constants.glsl"
#ifdef SHADOWLAB_ALPHA
// The *_alpha variants (MASK or BLEND surfaces whose alpha can cut): the camera looks through what
// camera rays skip (shaders/alpha.glsl alphaCameraSkips), so the AOVs describe the surface behind.
#define SHADOWLAB_ALPHA_SET 1
#include "alpha.glsl"
layout(location = 14) in vec2 inUv;
#endif

// Slot k of those constants: baked into the pipeline (kSpecializedLightConstants) or lit.vert's.
vec4 lightSlot(int k) {
    if (kSpecializedLightConstants) {
        if (k == 0) return vec4(kL00, kL01, kL02, kL03);
        if (k == 1) return vec4(kL10, kL11, kL12, kL13);
        if (k == 2) return vec4(kL20, kL21, kL22, kL23);
        if (k == 3) return vec4(kL30, kL31, kL32, kL33);
        if (k == 4) return vec4(kL40, kL41, kL42, kL43);
        return vec4(kL50, kL51, kL52, kL53);
    }
#ifdef SHADOWLAB_BAKED_LIGHT
    return vec4(0.0);  // not reached: kVertexLightConstants is false there
#else
    return inLight[k];
#endif
}
vec4 frameSlot(int k) {
    if (kFrameBakedIn) return k == 0 ? vec4(kF00, kF01, kF02, kF03) : vec4(kF10, kF11, kF12, kF13);
#ifdef SHADOWLAB_BAKED_LIGHT
    return vec4(0.0);
#else
    return inFrame[k];
#endif
}
// The matrix with rows r0..r3 (mat4 takes columns: column k is (r0[k], r1[k], r2[k], r3[k])).
mat4 matrixFromRows(vec4 r0, vec4 r1, vec4 r2, vec4 r3) {
    return mat4(vec4(r0.x, r1.x, r2.x, r3.x), vec4(r0.y, r1.y, r2.y, r3.y), vec4(r0.z, r1.z, r2.z, r3.z),
                vec4(r0.w, r1.w, r2.w, r3.w));
}
// kOneMapLight: light 0's toShadow, its first three rows baked in as cascade 0's
// (kSpecializedLightConstants) or from lit.vert (in the slots a sun leaves spare where the module
// is for a sun: lit.vert), a spot's last row in the slots' spare components
// (raster::packLightConstants), a sun's (0, 0, 0, 1). lit.frag forms the map coordinates with it
// instead of interpolating lit.vert's, which llvmpipe would store, set up per triangle and
// interpolate per pixel (docs/performance.md).
mat4 oneMapMatrix() {
    vec4 r0 = vec4(0.0), r1 = vec4(0.0), r2 = vec4(0.0);
    if (kSpecializedLightConstants) {
        r0 = vec4(kC0_00, kC0_01, kC0_02, kC0_03);
        r1 = vec4(kC0_04, kC0_05, kC0_06, kC0_07);
        r2 = vec4(kC0_08, kC0_09, kC0_10, kC0_11);
    } else {
#if defined(SHADOWLAB_BAKED_LIGHT)
#elif defined(SHADOWLAB_ONE_SUN)
        r0 = inLight[4];
        r1 = inLight[5];
        r2 = vec4(inLight[3].w, inFrame[1].yzw);
#else
        r0 = inMapRows[0];
        r1 = inMapRows[1];
        r2 = inMapRows[2];
#endif
    }
    const vec4 r3 = kOneSpot ? vec4(lightSlot(3).w, lightSlot(5).w, frameSlot(1).y, frameSlot(1).z) : vec4(0.0, 0.0, 0.0, 1.0);
    return matrixFromRows(r0, r1, r2, r3);
}
// Light i's constants: the uniform buffer's, or (kVertexLightConstants: the one light) light 0's as
// lit.vert packs them, its flat outputs or the same values baked in. The members lit.vert does not
// pass come from the buffer, and only where code reads them (none does).
#ifdef SHADOWLAB_EVERY_LIGHT
#define SHADOWLAB_LIGHT_SLOT_VALUE(i, s) vec4(kB##i##_##s##x, kB##i##_##s##y, kB##i##_##s##z, kB##i##_##s##w)
#define SHADOWLAB_LIGHT_SLOT_VALUES(i)                                                                          \
    vec4[14](SHADOWLAB_LIGHT_SLOT_VALUE(i, 0), SHADOWLAB_LIGHT_SLOT_VALUE(i, 1), SHADOWLAB_LIGHT_SLOT_VALUE(i, 2), \
             SHADOWLAB_LIGHT_SLOT_VALUE(i, 3), SHADOWLAB_LIGHT_SLOT_VALUE(i, 4), SHADOWLAB_LIGHT_SLOT_VALUE(i, 5), \
             SHADOWLAB_LIGHT_SLOT_VALUE(i, 6), SHADOWLAB_LIGHT_SLOT_VALUE(i, 7), SHADOWLAB_LIGHT_SLOT_VALUE(i, 8), \
             SHADOWLAB_LIGHT_SLOT_VALUE(i, 9), SHADOWLAB_LIGHT_SLOT_VALUE(i, 10), SHADOWLAB_LIGHT_SLOT_VALUE(i, 11), \
             SHADOWLAB_LIGHT_SLOT_VALUE(i, 12), SHADOWLAB_LIGHT_SLOT_VALUE(i, 13))
// Light i's baked slots (kEveryLightBaked); i is a constant in each iteration of the unrolled light
// loop, so the selects fold away.
vec4[14] bakedLightSlots(int i) {
    if (i == 0) return SHADOWLAB_LIGHT_SLOT_VALUES(0);
    if (i == 1) return SHADOWLAB_LIGHT_SLOT_VALUES(1);
    if (i == 2) return SHADOWLAB_LIGHT_SLOT_VALUES(2);
    if (i == 3) return SHADOWLAB_LIGHT_SLOT_VALUES(3);
    if (i == 4) return SHADOWLAB_LIGHT_SLOT_VALUES(4);
    if (i == 5) return SHADOWLAB_LIGHT_SLOT_VALUES(5);
    if (i == 6) return SHADOWLAB_LIGHT_SLOT_VALUES(6);
    return SHADOWLAB_LIGHT_SLOT_VALUES(7);
}
// Light i as the uniform buffer holds it, from its baked slots (raster::packLightConstants' order;
// the members of other kinds are zero there, as in the buffer).
LightData bakedLightAt(int i) {
    LightData light;
    const vec4 s[14] = bakedLightSlots(i);
    light.kind = int(s[3].w);
    const bool directional = light.kind == SHADOWLAB_LIGHT_DIRECTIONAL;
    light.towardLight = directional ? s[0].xyz : vec3(0.0);
    light.position = directional ? vec3(0.0) : s[0].xyz;
    light.layer = s[0].w;
    light.radiance = s[1].rgb;
    light.visibilityWeight = s[1].w;
    light.depthBiasWorld = s[2].x;
    light.slopeBiasTexels = s[2].y;
    light.texelWorldSize = s[2].z;
    light.depthPerWorld = s[2].w;
    light.maxSlopeTan = s[3].x;
    light.normalOffsetTexels = s[3].y;
    light.pcfSize = int(s[3].z);
    light.spotDirection = s[4].xyz;
    light.spotCosCone = s[4].w;
    light.mapNear = s[5].x;
    light.mapFar = s[5].y;
    light.lightSize = s[5].z;
    light.cascadeCount = int(s[5].w);
    light.toShadow = mat4(s[6], s[7], s[8], s[9]);
    light.pointFaceTan = s[10].x;
    light.filterCode = int(s[10].y);
    light.spotCosInner = s[10].z;
    for (int face = 0; face < 6; ++face) {
        const vec4 pair = s[11 + face / 2];
        light.pointFaces[face].near = face % 2 == 0 ? pair.x : pair.z;
        light.pointFaces[face].far = face % 2 == 0 ? pair.y : pair.w;
    }
    return light;
}
#endif
LightData lightAt(int i) {
#ifdef SHADOWLAB_EVERY_LIGHT
    if (kEveryLightBaked) return bakedLightAt(i);
#endif
    if (!kLightFromSlots) return u.lights[i];
    LightData light = u.lights[0];
    const vec4 slot[6] = vec4[](lightSlot(0), lightSlot(1), lightSlot(2), lightSlot(3), lightSlot(4), lightSlot(5));
    if (kOneSpot) light.position = slot[0].xyz;
    else light.towardLight = slot[0].xyz;
    light.layer = slot[0].w;
    light.radiance = slot[1].rgb;
    light.visibilityWeight = slot[1].w;
    light.depthBiasWorld = slot[2].x;
    light.slopeBiasTexels = slot[2].y;
    light.texelWorldSize = slot[2].z;
    light.depthPerWorld = slot[2].w;
    light.maxSlopeTan = slot[3].x;
    light.normalOffsetTexels = slot[3].y;
    light.pcfSize = int(slot[3].z);
    if (kOneSpot) {
        light.spotDirection = slot[4].xyz;
        light.spotCosCone = slot[4].w;
        light.mapNear = slot[5].x;
        light.mapFar = slot[5].y;
        light.lightSize = slot[5].z;
        light.spotCosInner = frameSlot(1).w;
    }
    if (kOneMapLight) light.toShadow = oneMapMatrix();
    return light;
}
// LitUniforms' members that lit.vert passes with the light.
vec3 viewForward() { return kFrameFromSlots ? frameSlot(0).xyz : u.forward; }
float ambient() { return kFrameFromSlots ? frameSlot(0).w : u.ambient; }
float mapSize() { return kFrameFromSlots ? frameSlot(1).x : u.mapSize; }

// Cascade c of light `lightIndex`: the uniform buffer's, or (kSpecializedCascades: light 0 is the
// only light) baked in. c varies per pixel, so the baked values are chosen by selects, where the
// buffer's are loaded lane by lane.
CascadeData cascadeFromRows(vec4 r0, vec4 r1, vec4 r2, vec4 rest) {
    CascadeData d;
    d.toShadow = matrixFromRows(r0, r1, r2, vec4(0.0, 0.0, 0.0, 1.0));  // an orthographic map's last row
    d.sliceFar = rest.x;
    d.texelWorldSize = rest.y;
    d.depthPerWorld = rest.z;
    d.depthBiasWorld = rest.w;
    return d;
}
#ifdef SHADOWLAB_EVERY_LIGHT
#define SHADOWLAB_CASCADE_ROW(i, c, s) vec4(kD##i##_##c##_##s##x, kD##i##_##c##_##s##y, kD##i##_##c##_##s##z, kD##i##_##c##_##s##w)
#define SHADOWLAB_CASCADE_ROWS(i, c)                                                                \
    rows = vec4[4](SHADOWLAB_CASCADE_ROW(i, c, 0), SHADOWLAB_CASCADE_ROW(i, c, 1), SHADOWLAB_CASCADE_ROW(i, c, 2), \
                   SHADOWLAB_CASCADE_ROW(i, c, 3))
#define SHADOWLAB_PICK_CASCADE(i)     \
    if (c == 0)                       \
        SHADOWLAB_CASCADE_ROWS(i, 0); \
    else if (c == 1)                  \
        SHADOWLAB_CASCADE_ROWS(i, 1); \
    else if (c == 2)                  \
        SHADOWLAB_CASCADE_ROWS(i, 2); \
    else                              \
        SHADOWLAB_CASCADE_ROWS(i, 3);
// Light i's cascade c, baked in (kEveryLightBaked): i is a constant in each unrolled iteration, c
// varies per pixel and is picked by selects.
CascadeData bakedCascadeAt(int i, int c) {
    vec4 rows[4];
    if (i == 0) {
        SHADOWLAB_PICK_CASCADE(0)
    } else if (i == 1) {
        SHADOWLAB_PICK_CASCADE(1)
    } else if (i == 2) {
        SHADOWLAB_PICK_CASCADE(2)
    } else if (i == 3) {
        SHADOWLAB_PICK_CASCADE(3)
    } else if (i == 4) {
        SHADOWLAB_PICK_CASCADE(4)
    } else if (i == 5) {
        SHADOWLAB_PICK_CASCADE(5)
    } else if (i == 6) {
        SHADOWLAB_PICK_CASCADE(6)
    } else {
        SHADOWLAB_PICK_CASCADE(7)
    }
    return cascadeFromRows(rows[0], rows[1], rows[2], rows[3]);
}
#endif
CascadeData cascadeAt(int lightIndex, int c) {
#ifdef SHADOWLAB_EVERY_LIGHT
    if (kEveryLightBaked) return bakedCascadeAt(lightIndex, c);
#endif
    if (!kSpecializedCascades) return u.cascades[lightIndex * SHADOWLAB_MAX_CASCADES + c];
    vec4 r0, r1, r2, rest;
    if (c == 0) {
        r0 = vec4(kC0_00, kC0_01, kC0_02, kC0_03);
        r1 = vec4(kC0_04, kC0_05, kC0_06, kC0_07);
        r2 = vec4(kC0_08, kC0_09, kC0_10, kC0_11);
        rest = vec4(kC0_12, kC0_13, kC0_14, kC0_15);
    } else if (c == 1) {
        r0 = vec4(kC1_00, kC1_01, kC1_02, kC1_03);
        r1 = vec4(kC1_04, kC1_05, kC1_06, kC1_07);
        r2 = vec4(kC1_08, kC1_09, kC1_10, kC1_11);
        rest = vec4(kC1_12, kC1_13, kC1_14, kC1_15);
    } else if (c == 2) {
        r0 = vec4(kC2_00, kC2_01, kC2_02, kC2_03);
        r1 = vec4(kC2_04, kC2_05, kC2_06, kC2_07);
        r2 = vec4(kC2_08, kC2_09, kC2_10, kC2_11);
        rest = vec4(kC2_12, kC2_13, kC2_14, kC2_15);
    } else {
        r0 = vec4(kC3_00, kC3_01, kC3_02, kC3_03);
        r1 = vec4(kC3_04, kC3_05, kC3_06, kC3_07);
        r2 = vec4(kC3_08, kC3_09, kC3_10, kC3_11);
        rest = vec4(kC3_12, kC3_13, kC3_14, kC3_15);
    }
    return cascadeFromRows(r0, r1, r2, rest);
}
const bool kCascadesBaked = !(!kSpecializedCascades && !kEveryLightBaked);
float cascadeStart() { return kCascadesBaked ? kCascadeStart : u.cascadeStart; }
float cascadeBlendBand() { return kCascadesBaked ? kCascadeBlendBand : u.cascadeBlendBand; }

// Whether the light is of this kind: constant false for a kind the scene lacks, which removes its
// code, and constant true where the scene has lights of that kind only, so the kind is not read
// (and lit.vert need not pass it).
bool isKind(LightData light, int kind) {
    if ((kLightKinds & (1 << kind)) == 0) return false;
    if (kLightKinds == (1 << kind)) return true;
    return light.kind == kind;
}
bool isPerspective(LightData light) { return kAnyPerspective && !isKind(light, SHADOWLAB_LIGHT_DIRECTIONAL); }

const float kPi = 3.14159265358979323846;

// 16 points in the unit disk at least 0.43 apart (dart throwing with a fixed seed).
const vec2 kPoisson[16] = vec2[](
    vec2(-0.6984, -0.6662), vec2(-0.8384, 0.4904), vec2(-0.9425, -0.0572), vec2(0.0215, 0.1584),
    vec2(0.5386, -0.0345), vec2(-0.0932, 0.9513), vec2(0.6755, 0.7325), vec2(0.4978, -0.7298),
    vec2(0.0952, -0.9609), vec2(-0.0199, -0.4177), vec2(-0.5116, 0.0720), vec2(0.1606, 0.5888),
    vec2(-0.3732, 0.5695), vec2(0.9588, -0.1544), vec2(0.8339, 0.2965), vec2(-0.3374, -0.9138));

// Per-pixel rotation for the Poisson disk: interleaved gradient noise (Jimenez, "Next
// Generation Post Processing in Call of Duty: Advanced Warfare", 2014), which spreads the
// rotations so that neighbouring pixels sample differently.
float interleavedGradientNoise(vec2 pixel) {
    return fract(52.9829189 * fract(dot(pixel, vec2(0.06711056, 0.00583715))));
}

// The light left by the semi-transparent casters of (up to four) texels for a receiver at map
// depth ref, from each texel's product T_all and nearest depth D1, and the product T_rest and
// nearest depth D2 of what lies behind that nearest layer:
// - ref <= D1: 1 (a receiver in front of them, or on the nearest one itself, which the bias keeps
//   in front);
// - D1 < ref <= D2: T_all / T_rest, the nearest layer's factor alone. Exact for a receiver on the
//   second layer (its own surface is D2, the bias keeps it in front of that), whose own
//   1 − opacity and everything below it are in T_rest;
// - ref > D2: T_all divided by the receiver's own 1 − opacity (a semi-transparent receiver lies
//   in front of the opaque depth, so it is in the product; inAlbedo.a, 1 for opaque receivers),
//   clamped to 1 (taps past the receiver's outline). Exact for opaque receivers and for the
//   deepest semi-transparent one; a third layer of four also gets the fourth's factor.
float receiverTransmittance = 1.0;
vec4 layeredTransmittance(vec4 all, vec4 near, vec4 rest, vec4 second, float ref) {
    const vec4 behindAll = min(all / receiverTransmittance, vec4(1.0));
    const vec4 nearestOnly = min(all / max(rest, vec4(1e-30)), vec4(1.0));  // (rest 0 only by underflow)
    const vec4 behindNearest = mix(nearestOnly, behindAll, greaterThan(vec4(ref), second));
    return mix(vec4(1.0), behindNearest, greaterThan(vec4(ref), near));
}
// Whether texel (x, y) of `layer` lies in the layer's transmittance window. Outside it the maps
// hold nothing defined, and nothing semi-transparent is there: T 1, depths 1, which
// layeredTransmittance turns into 1 (so a tap there is 1, as a map cleared to 1 gave). The window
// keeps a margin of such texels around the casters (raster/tolerances.h), so a texel on its edge
// gives 1 either way, whichever of two neighbours floor(uv · size) and the sampler pick.
bool inTransmitWindow(vec2 texel, float layer) {
    const vec4 w = transmitWindows.rect[int(layer)];
    return all(greaterThanEqual(texel, w.xy)) && all(lessThan(texel, w.zw));
}
float transmittanceTap(vec2 uv, float layer, float ref) {
    const vec3 at = vec3(uv, layer);
    const float t = layeredTransmittance(vec4(texture(transmittanceMaps, at).r), vec4(texture(transparentDepths, at).r),
                                         vec4(texture(restTransmittanceMaps, at).r),
                                         vec4(texture(secondTransparentDepths, at).r), ref)
                        .x;
    return inTransmitWindow(floor(uv * mapSize()), layer) ? t : 1.0;
}

// One compare tap; records the object stored there when it shadows and none was found yet
// (opaque casters only: the blocker-id map holds no semi-transparent ones).
float tap(vec2 uv, float layer, float ref, inout uint blocker) {
    const float lit = texture(shadowMaps, vec4(uv, layer, ref));
    if (kBlockerIds && lit < 0.5 && blocker == 0u) blocker = texture(blockerIds, vec3(uv, layer)).r;
    return kTransmittance ? lit * transmittanceTap(uv, layer, ref) : lit;
}

// Where the receiver is, in the light's map, and how its depth is compared.
struct Receiver {
    vec2 uv;          // map coordinates of the (normal-offset) point
    float axial;      // spot: distance along the light's axis; directional: its linear depth 0..1
    float biasWorld;  // depthBias + slopeBias·texel·tan(θ): the bias of a tap at the point
    float slopeStep;  // what one texel of tap distance adds to the bias (slopeBias·texel·tan(θ))
    // Receiver-plane bias (kReceiverPlane): the receiver's depth gradient, world units per texel
    // of (u, v); plane = false where the derivatives cannot give one (then the slope bias is used).
    vec2 grad;
    bool plane;
};

// The compare reference for a receiver biased by `bias` world units toward the light.
float reference(LightData light, Receiver r, float bias) {
    if (isPerspective(light)) {
        // Perspective depth of a point at distance d along the axis: far/(far−near)·(1 − near/d);
        // the bias is subtracted from d, so it stays in world units at every distance.
        const float near = light.mapNear, far = light.mapFar;
        return far / (far - near) * (1.0 - near / max(r.axial - bias, near));
    }
    return r.axial - bias * light.depthPerWorld;  // orthographic depth is linear: bias / depth range
}

// The filterable maps' depth of a receiver biased by `bias` world units toward the light: a
// directional map's linear depth as reference() gives it; a perspective layer's moments are of
// (d − near)/(far − near), d the distance along its axis (shaders/moments.comp linearDepth).
float momentReference(LightData light, Receiver r, float bias) {
    if (isPerspective(light)) {
        const float near = light.mapNear, far = light.mapFar;
        return (r.axial - bias - near) / (far - near);
    }
    return reference(light, r, bias);
}

// Filterable maps: the visibility of a receiver at map depth t from the filtered moments m.
// linstep(a, 1, p) is the light-bleeding reduction: visibilities below a become 0, the rest is
// stretched over 0..1 (Lauritzen 2007).
float linstep(float lo, float hi, float v) { return clamp((v - lo) / (hi - lo), 0.0, 1.0); }
// One-sided Chebyshev: P(z >= t) <= σ²/(σ² + (t − μ)²) for t > μ, 1 for t <= μ.
float chebyshev(vec2 m, float t, float minVariance) {
    if (t <= m.x) return 1.0;
    const float variance = max(m.y - m.x * m.x, minVariance);
    const float d = t - m.x;
    return linstep(kBleedReduction, 1.0, variance / (variance + d * d));
}
// Hamburger 4-moment shadow map (Peters & Klein, "Moment Shadow Mapping", I3D 2015, algorithm 3):
// the biased moments' 3x3 Hankel matrix solved by Cholesky for the polynomial whose roots z2, z3
// with the receiver's depth are the support of the distribution that shadows most; G the bound.
float hamburger(vec4 b, float t) {
    b = mix(b, vec4(0.5), kMomentBias);
    // B = [[1, b1, b2], [b1, b2, b3], [b2, b3, b4]] = L D Lᵀ, solve B c = (1, t, t²).
    const float d2 = max(b.y - b.x * b.x, 1e-12);
    const float l32 = (b.z - b.x * b.y) / d2;
    const float d3 = max(b.w - b.y * b.y - l32 * l32 * d2, 1e-12);
    const float y2 = t - b.x;
    const float y3 = t * t - b.y - l32 * y2;
    const float c3 = y3 / d3;
    const float c2 = y2 / d2 - l32 * c3;
    const float c1 = 1.0 - b.x * c2 - b.y * c3;
    // c3 z² + c2 z + c1 = 0.
    const float p = c2 / c3, q = c1 / c3;
    const float r = sqrt(max(0.25 * p * p - q, 0.0));
    const float z2 = -0.5 * p - r, z3 = -0.5 * p + r;
    float shadow;
    if (t <= z2) shadow = 0.0;
    else if (t <= z3) shadow = (t * z3 - b.x * (t + z3) + b.y) / ((z3 - z2) * (t - z2));
    else shadow = 1.0 - (z2 * z3 - b.x * (z2 + z3) + b.y) / ((t - z2) * (t - z3));
    return clamp(1.0 - shadow, 0.0, 1.0);
}
float momentVisibility(vec4 m, float t) {
    if (kFilter == SHADOWLAB_FILTER_VSM) return chebyshev(m.xy, t, kMinVariance);
    if (kFilter == SHADOWLAB_FILTER_EVSM2 || kFilter == SHADOWLAB_FILTER_EVSM4) {
        // The receiver warped as the moments were (moments.comp); the variance floor scaled by
        // the warp's derivative, so it means the same depth spread as for vsm.
        const float w = 2.0 * t - 1.0;
        const float pt = exp(kEvsmPositive * w);
        const float dp = 2.0 * kEvsmPositive * pt;
        float v = chebyshev(m.xy, pt, kMinVariance * dp * dp);
        if (kFilter == SHADOWLAB_FILTER_EVSM4) {
            const float nt = -exp(-kEvsmNegative * w);
            const float dn = 2.0 * kEvsmNegative * nt;
            v = min(v, chebyshev(m.zw, nt, kMinVariance * dn * dn));
        }
        return v;
    }
    if (kFilter == SHADOWLAB_FILTER_ESM) return clamp(m.x * exp(-kEsmExponent * t), 0.0, 1.0);
    return hamburger(m, t);
}

// A point light's cube face for the direction d from the light (its major axis: +X −X +Y −Y +Z
// −Z, as raster/light_frustum.h cubeFaceDirection), and the face's basis as
// LightFrustum::toTexture (setBasis()'s rule: right = axis × (world Y, or X for a vertical axis),
// up = right × axis). Returns the face's layer offset 0..5.
int cubeFace(vec3 d, out vec3 axis, out vec3 right, out vec3 up) {
    const vec3 a = abs(d);
    const int k = a.x >= a.y && a.x >= a.z ? 0 : a.y >= a.z ? 1 : 2;
    const bool negative = d[k] < 0.0;
    axis = vec3(0.0);
    axis[k] = negative ? -1.0 : 1.0;
    const vec3 ref = abs(axis.y) < 0.99 ? vec3(0.0, 1.0, 0.0) : vec3(1.0, 0.0, 0.0);
    right = normalize(cross(axis, ref));
    up = cross(right, axis);
    return 2 * k + (negative ? 1 : 0);
}

// Near and far of a point light's cube face 0..5 (each face's depth range is fitted on its own).
vec2 faceRange(LightData light, int face) { return vec2(light.pointFaces[face].near, light.pointFaces[face].far); }

// A PCSS tap of a point light at map coordinates uv of the receiver's face (basis axis, right,
// up), which may lie past that face's edge: the tap's direction from the light is looked up in
// the face it falls in (xy: map coordinates there, z: layer), and `axial` becomes the receiver's
// (qd: the normal-offset point minus the light) distance along that face's axis, so its compare
// reference and blocker test use the same face's depths (and `range`, its near and far). A face map holds only
// kPointFaceMarginTexels past its 90° edge; PCSS kernels reach up to 1/8 of the map, and without
// this the taps beyond the margin read nothing (border: lit), cutting the penumbra along the seam.
vec3 cubeTap(LightData light, vec3 axis, vec3 right, vec3 up, vec3 qd, vec2 uv, out float axial, out vec2 range) {
    const vec2 s = (2.0 * uv - 1.0) * light.pointFaceTan;  // tan of the tap's angles in the face
    const vec3 d = axis + s.x * right + s.y * up;
    vec3 fAxis, fRight, fUp;
    const int face = cubeFace(d, fAxis, fRight, fUp);
    const float along = dot(d, fAxis);
    axial = dot(qd, fAxis);
    range = faceRange(light, face);
    return vec3(0.5 + 0.5 * vec2(dot(d, fRight), dot(d, fUp)) / (along * light.pointFaceTan),
                light.layer + float(face));
}

// Map coordinates (u, v) and axial depth (as Receiver.uv, .axial) of camera-relative point q, for
// the face whose axis is `axis` (point lights) or the light's own map.
vec3 mapCoordinates(LightData light, vec3 axis, vec3 q) {
    if (isKind(light, SHADOWLAB_LIGHT_POINT)) {
        const vec3 ref = abs(axis.y) < 0.99 ? vec3(0.0, 1.0, 0.0) : vec3(1.0, 0.0, 0.0);
        const vec3 right = normalize(cross(axis, ref));
        const vec3 up = cross(right, axis);
        const vec3 d = q - light.position;
        const float axial = dot(d, axis);
        return vec3(0.5 + 0.5 * vec2(dot(d, right), dot(d, up)) / (axial * light.pointFaceTan), axial);
    }
    const vec4 s = light.toShadow * vec4(q, 1.0);
    const bool perspective = isPerspective(light);
    return vec3(perspective ? s.xy / s.w : s.xy, perspective ? dot(q - light.position, axis) : s.z);
}

// Receiver-plane depth bias (Isidoro, "Shadow Mapping: GPU-based Tips and Techniques", GDC 2006).
// The neighbouring pixels' positions (q + dFdx, q + dFdy of the position) mapped into the light's
// map give the screen-space derivatives of (u, v, depth); solving
//   [du/dx dv/dx; du/dy dv/dy] · (dz/du, dz/dv) = (dz/dx, dz/dy)
// gives the receiver's depth gradient in the map. The derivatives come in from main(), taken in
// uniform control flow (inside the per-light branch they would be undefined). Where the 2x2 matrix
// is near singular (the surface seen edge-on by the camera, or its footprint in the map a line)
// there is no plane, and the slope bias is used instead; the gradient is capped as the slope bias
// is (kMaxSlopeTan texels of depth per texel), so a grazing plane cannot push taps far behind.
void receiverPlane(LightData light, vec3 axis, vec3 q, vec3 dpdx, vec3 dpdy, float size, float texel,
                   inout Receiver r) {
    const vec3 c = mapCoordinates(light, axis, q);
    const vec3 cx = mapCoordinates(light, axis, q + dpdx) - c;
    const vec3 cy = mapCoordinates(light, axis, q + dpdy) - c;
    const vec2 ux = cx.xy * size, uy = cy.xy * size;  // texels per pixel
    // World units per unit of axial depth: orthographic depth is 0..1 over the depth range.
    const float worldPerAxial = isPerspective(light) ? 1.0 : 1.0 / light.depthPerWorld;
    const float zx = cx.z * worldPerAxial, zy = cy.z * worldPerAxial;
    const float det = ux.x * uy.y - ux.y * uy.x;
    // Near singular: the two footprint vectors less than ~0.06° apart (|sin| < 1e-3).
    r.plane = abs(det) > 1e-3 * length(ux) * length(uy) && det != 0.0;
    if (!r.plane) return;
    vec2 g = vec2(uy.y * zx - ux.y * zy, ux.x * zy - uy.x * zx) / det;
    const float cap = light.maxSlopeTan * texel;
    const float len = length(g);
    if (!(len <= cap)) g = len > 0.0 && !isinf(len) ? g * (cap / len) : vec2(0.0);  // also NaN -> 0
    r.grad = g;
}

// The tap `o` texels from the point. Receiver plane: the tap reads the texel holding that
// position at its center, and compares against the plane's depth there (where that texel's depth
// was rasterized) minus the constant bias; sampling at the center makes sure the texel compared
// is the one the plane was evaluated for. Else the constant bias plus the slope term grown with
// the tap's distance.
float biasedTap(LightData light, Receiver r, vec2 o, float size, float layer, inout uint blocker) {
    if (kReceiverPlane && r.plane) {
        const vec2 t = r.uv * size;
        const vec2 center = floor(t + o) + 0.5;
        return tap(center / size, layer, reference(light, r, r.biasWorld - dot(r.grad, center - t)), blocker);
    }
    return tap(r.uv + o / size, layer, reference(light, r, r.biasWorld + r.slopeStep * length(o)), blocker);
}

// Visibility 0..1 of `light` at camera-relative position p with unit normal n (facing the
// viewer), N·L = ndotl > 0; dpdx, dpdy: p's screen-space derivatives (receiver plane only).
// `blocker` gets the id of the object that shadowed, if any.
float shadowTest(LightData light, vec3 p, vec3 n, float ndotl, vec3 dpdx, vec3 dpdy, inout uint blocker) {
    const bool perspective = isPerspective(light);
    const bool point = isKind(light, SHADOWLAB_LIGHT_POINT);
    vec3 axis = light.spotDirection;
    vec3 right = vec3(0.0), up = vec3(0.0);  // point: the face's basis
    float layer = light.layer;
    if (point) {
        // The cube face is the major axis of the direction from the light. Each face map
        // reaches a few texels past its edge, so the normal offset and the pcf/poisson taps
        // below stay inside this one face (PCSS taps may not: cubeTap).
        const int face = cubeFace(p - light.position, axis, right, up);
        layer += float(face);
        light.mapNear = light.pointFaces[face].near;  // reference() and PCSS read them there
        light.mapFar = light.pointFaces[face].far;
    }
    // World size of a texel at p: constant for an orthographic map, growing with distance
    // along the axis for a perspective one.
    const float axialP = dot(p - light.position, axis);
    const float texel = light.texelWorldSize * (perspective ? axialP : 1.0);
    // Normal offset: look the map up from a point moved off the surface along its normal, by the
    // user's k texels plus the slope bias beyond its cap: s·texel·(sin θ − maxTan·cos θ) puts the
    // point s·texel·(tan θ − maxTan) in front of its own plane along the light while moving it
    // less than s texels, where the same margin along the light would pass through casters.
    const float sinTheta = sqrt(max(1.0 - ndotl * ndotl, 0.0));
    const float offset = (light.normalOffsetTexels + light.slopeBiasTexels * max(sinTheta - light.maxSlopeTan * ndotl, 0.0)) * texel;
    const vec3 q = kNormalOffset ? p + n * offset : p;
    // bias_world = depthBias + slopeBias * texel * min(tan(theta), maxTan), cos(theta) = N·L.
    const float tanTheta = min(sinTheta / ndotl, light.maxSlopeTan);
    Receiver r;
    r.slopeStep = light.slopeBiasTexels * texel * tanTheta;
    r.biasWorld = light.depthBiasWorld + r.slopeStep;
    if (point) {
        // The face's perspective map, as LightFrustum::toTexture.
        const vec3 d = q - light.position;
        r.axial = dot(d, axis);
        r.uv = 0.5 + 0.5 * vec2(dot(d, right), dot(d, up)) / (r.axial * light.pointFaceTan);
    } else {
        const vec4 s = light.toShadow * vec4(q, 1.0);
        // Orthographic (directional): toShadow's last row is exactly (0, 0, 0, 1), so w = 1 and
        // the division would change nothing; without it the w row is not computed either.
        r.uv = perspective ? s.xy / s.w : s.xy;
        r.axial = perspective ? dot(q - light.position, axis) : s.z;
    }
    // An orthographic map's depth ends past the farthest receiver a caster can shade
    // (fitDirectionalLightToReceivers): a point beyond it has nothing between it and the light.
    if (!perspective && r.axial > 1.0) return 1.0;
    const int filterCode = kFilter;  // light.filterCode holds the same code
    const float size = mapSize();  // = textureSize(shadowMaps, 0).x, without a query per fragment
    r.plane = false;
    r.grad = vec2(0.0);
    if (kReceiverPlane) {
        receiverPlane(light, axis, q, dpdx, dpdy, size, texel, r);
        // The plane replaces the slope term; the constant bias stays.
        if (r.plane) r.biasWorld = light.depthBiasWorld;
    }
#ifndef SHADOWLAB_TAPS_ONLY
    if (filterCode >= SHADOWLAB_FILTER_VSM) {
        // Filterable maps: one linear lookup of the blurred moments (the filter is in the blur),
        // the receiver at the constant and slope bias as for `none`, in the moments' linear depth.
        // Blocker ids and semi-transparent casters as one compare tap would give them (the
        // transmittance maps hold the depth pass's depths: `ref`).
        const float ref = reference(light, r, r.biasWorld);
        float v = momentVisibility(texture(momentMaps, vec3(r.uv, layer)), momentReference(light, r, r.biasWorld));
        if (kBlockerIds && v < 0.5 && blocker == 0u) blocker = texture(blockerIds, vec3(r.uv, layer)).r;
        if (kTransmittance) v *= transmittanceTap(r.uv, layer, ref);
        return v;
    }
#endif
    if (filterCode == SHADOWLAB_FILTER_NONE) {
        if (kReceiverPlane && r.plane) return biasedTap(light, r, vec2(0.0), size, layer, blocker);
        return tap(r.uv, layer, reference(light, r, r.biasWorld), blocker);
    }
    if (filterCode == SHADOWLAB_FILTER_PCF2X2 && kReceiverPlane && r.plane) {
        // The same bilinear weights, but each of the four texels compared against the plane at
        // its own center (a gather has one reference for all four).
        const vec2 t = r.uv * size - 0.5;
        const vec2 i0 = floor(t);
        const vec2 f = t - i0;
        const vec2 c00 = i0 + 0.5;  // texel-center coordinates of (i0, j0), in texels
        const vec2 fromPoint = c00 - r.uv * size;
        float v[4];
        [[unroll]] for (int k = 0; k < 4; ++k) {
            const vec2 ab = vec2(k & 1, k >> 1);
            v[k] = tap((c00 + ab) / size, layer, reference(light, r, r.biasWorld - dot(r.grad, fromPoint + ab)), blocker);
        }
        return mix(mix(v[0], v[1], f.x), mix(v[2], v[3], f.x), f.y);
    }
    if (filterCode == SHADOWLAB_FILTER_PCF2X2) {
        // The bilinear mix of the four comparisons around the point: what a LINEAR compare
        // sampler does in hardware, done here because lavapipe cannot filter D32_SFLOAT
        // linearly, and so the weights are the same on every driver. One gather at the corner
        // shared by the four texels, where its footprint cannot round to a neighbour. Its four
        // texel centers lie up to √2 texels from the point (nearest: √2/2), so the slope term
        // covers one more texel than for `none`.
        const vec2 t = r.uv * size - 0.5;  // texel-center coordinates
        const vec2 i0 = floor(t);
        const vec2 f = t - i0;
        const vec3 corner = vec3((i0 + 1.0) / size, layer);
        // Components: x = (i0, j0+1), y = (i0+1, j0+1), z = (i0+1, j0), w = (i0, j0).
        const float ref = reference(light, r, r.biasWorld + r.slopeStep);
        vec4 g = textureGather(shadowMaps, corner, ref);
        if (kBlockerIds && blocker == 0u && min(min(g.x, g.y), min(g.z, g.w)) < 0.5) {
            const uvec4 ids = textureGather(blockerIds, corner);
            blocker = g.w < 0.5 ? ids.w : g.z < 0.5 ? ids.z : g.x < 0.5 ? ids.x : ids.y;
        }
        if (kTransmittance) {
            // The same four texels' transmittance, each by where the receiver lies among their layers.
            const vec4 layered = layeredTransmittance(textureGather(transmittanceMaps, corner),
                                                      textureGather(transparentDepths, corner),
                                                      textureGather(restTransmittanceMaps, corner),
                                                      textureGather(secondTransparentDepths, corner), ref);
            // Texels outside the layer's window give 1 (inTransmitWindow).
            const bvec4 inside = bvec4(inTransmitWindow(i0 + vec2(0.0, 1.0), layer), inTransmitWindow(i0 + 1.0, layer),
                                       inTransmitWindow(i0 + vec2(1.0, 0.0), layer), inTransmitWindow(i0, layer));
            g *= mix(vec4(1.0), layered, inside);
        }
        return mix(mix(g.w, g.z, f.x), mix(g.x, g.y, f.x), f.y);
    }
#ifdef SHADOWLAB_TAPS_ONLY
    // (The lit_frag*_taps variants, for none and pcf2x2: the wide kernels' and the filterable maps'
    // code left out of the SPIR-V, which halves what lavapipe compiles when the pipeline is made.)
    return 1.0;
#else
    // Wide kernels: a tap d texels from the point compares against a surface that a plane
    // tilted by θ has moved d·texel·tan(θ) along the light, so each tap's slope term grows
    // with its distance (a per-tap receiver-plane bias; without it wide kernels make acne).
    float kernelTexels = float(light.pcfSize);  // poisson: the diameter given
    const float lightSize = light.lightSize;
    const bool pcss = filterCode == SHADOWLAB_FILTER_PCSS && perspective && lightSize > 0.0;
    const bool wrap = pcss && point;  // PCSS taps of a point light go on into the neighbouring faces
    const vec3 qd = q - light.position;
    if (pcss) {
        // Percentage-closer soft shadows (Fernando, "Percentage-Closer Soft Shadows", SIGGRAPH 2005
        // sketch). 1. Blocker search: a blocker at distance d along the axis, s to the side of the
        // receiver's ray, shadows the receiver (distance dr) from some point of a light of size w
        // when s <= (w/2)(dr − d)/dr; in the map that is s/(d·texelPerDistance) texels, largest at
        // the near plane, so the search covers that, capped at kPcssMaxSearchFraction of the map.
        const float near = light.mapNear, far = light.mapFar;
        const float dr = r.axial;
        const float reach = 0.5 * lightSize * (dr - near) / dr / (near * light.texelWorldSize);
        const float searchRadius = clamp(reach, 1.0, kPcssMaxSearchFraction * size);
        const float angle = 2.0 * kPi * interleavedGradientNoise(gl_FragCoord.xy);
        const mat2 rotation = mat2(cos(angle), sin(angle), -sin(angle), cos(angle));
        float blockerSum = 0.0;
        int blockers = 0;
        for (int k = 0; k < 16; ++k) {
            const vec2 o = rotation * kPoisson[k] * searchRadius;
            vec3 at = vec3(r.uv + o / size, layer);
            float drTap = dr;
            vec2 range = vec2(near, far);
            // How much nearer than the receiver (dr) a stored depth must be to count as a blocker.
            // With the receiver plane, as biasedTap: the tap reads the texel at its center, where the
            // receiver lies at the plane's depth, so its own texels are not blockers (the slope term,
            // which the plane makes unnecessary elsewhere so that it may be 0, and which is capped at
            // tan θ = 10, need not cover them across a wide search); the threshold is the nearer of
            // that and dr (a surface behind the point cannot shadow it, even where the plane lies
            // deeper), less the constant bias (r.biasWorld is that alone with a plane). A tap that
            // wraps into another face (point lights) keeps the slope term: the plane and its texel
            // grid are the receiver's face's.
            float nearerBy = r.biasWorld + r.slopeStep * length(o);
            if (kReceiverPlane && r.plane) {
                const vec2 t = r.uv * size;
                const vec2 center = floor(t + o) + 0.5;
                at.xy = center / size;
                nearerBy = r.biasWorld - min(dot(r.grad, center - t), 0.0);
            }
            if (wrap) {
                at = cubeTap(light, axis, right, up, qd, at.xy, drTap, range);
                if (kReceiverPlane && r.plane && at.z != layer) nearerBy = r.biasWorld + r.slopeStep * length(o);
            }
            // The nearest caster of the texel: the opaque depth or, with semi-transparent casters,
            // the nearest of those when it is nearer, so their shadows are softened too.
            float z = texture(shadowDepths, at).r;
            if (kTransmittance && inTransmitWindow(floor(at.xy * size), at.z)) z = min(z, texture(transparentDepths, at).r);
            if (z >= 1.0) continue;  // nothing drawn there
            // Stored perspective depth back to distance: z = far/(far−near)(1 − near/d).
            const float d = range.x / max(1.0 - z * (range.y - range.x) / range.y, 1e-7);
            if (d < drTap - nearerBy) {
                blockerSum += d;
                ++blockers;
            }
        }
        if (blockers == 0) return 1.0;  // nothing between the point and the light
        // 2. Penumbra width at the receiver: (dr − db)·w/db (similar triangles), in texels of the
        // receiver's distance. 3. Poisson PCF over that diameter, below.
        const float db = blockerSum / float(blockers);
        const float penumbra = (dr - db) * lightSize / db;
        kernelTexels = clamp(penumbra / texel, 1.0, kPcssMaxFilterFraction * size);
    }
    const int taps = clamp(light.pcfSize, 1, 15);
    float sum = 0.0;
    if (filterCode == SHADOWLAB_FILTER_PCF) {
        // taps x taps texels one texel apart, centered on the point.
        const float c = 0.5 * float(taps - 1);
        for (int j = 0; j < taps; ++j)
            for (int i = 0; i < taps; ++i) {
                const vec2 o = vec2(i, j) - c;
                sum += biasedTap(light, r, o, size, layer, blocker);
            }
        return sum / float(taps * taps);
    }
    // Poisson (and PCSS, and pcss where it has no light size): 16 taps on a disk of diameter
    // `taps` (PCSS: the penumbra's) texels, rotated per pixel.
    const float angle = 2.0 * kPi * interleavedGradientNoise(gl_FragCoord.xy);
    const mat2 rotation = mat2(cos(angle), sin(angle), -sin(angle), cos(angle));
    const float radius = 0.5 * (filterCode == SHADOWLAB_FILTER_PCSS ? kernelTexels : float(taps));
    for (int k = 0; k < 16; ++k) {
        const vec2 o = rotation * kPoisson[k] * radius;
        if (wrap) {
            Receiver rt = r;
            LightData lt = light;
            vec2 range;
            const vec3 at = cubeTap(light, axis, right, up, qd, r.uv + o / size, rt.axial, range);
            if (kReceiverPlane && r.plane && at.z == layer) {
                // Still in the receiver's face: the same texel grid and depths as a spot's map, so
                // the tap compares against the receiver plane as biasedTap does (with the slope
                // bias 0 the slope term would take the tilted receiver's own texels for blockers).
                sum += biasedTap(light, r, o, size, layer, blocker);
                continue;
            }
            lt.mapNear = range.x;
            lt.mapFar = range.y;
            sum += tap(at.xy, at.z, reference(lt, rt, r.biasWorld + r.slopeStep * length(o)), blocker);
        } else {
            sum += biasedTap(light, r, o, size, layer, blocker);
        }
    }
    return sum / 16.0;
#endif
}

// Cascade c's map, texel size, depth scale and constant bias in place of the light's; its layer
// follows the light's first one.
LightData withCascade(LightData light, int lightIndex, int c) {
    const CascadeData cascade = cascadeAt(lightIndex, c);
    light.toShadow = cascade.toShadow;
    light.layer += float(c);
    light.depthBiasWorld = cascade.depthBiasWorld;
    light.texelWorldSize = cascade.texelWorldSize;
    light.depthPerWorld = cascade.depthPerWorld;
    return light;
}

// Cascaded shadow maps: a directional light with cascadeCount = kCascades > 1 cascades uses the
// cascade c whose slice holds p's view depth z (the Frame's Z, same expression).
// Blend bands (kCascadeBlend, F = u.cascadeBlendBand): where z lies in the last F of slice c
// (split[c] to split[c+1]) and c is not the last cascade, `next` gets cascade c + 1 and `blend` the position in
// the band, 0 at its start to 1 at the split, so the visibility goes over linearly to the next
// cascade's and is continuous across the split; elsewhere blend = 0.
LightData cascadeOf(LightData light, int lightIndex, vec3 p, out LightData next, out float blend) {
    const int count = min(kCascades, SHADOWLAB_MAX_CASCADES);  // = light.cascadeCount
    const float z = dot(p, viewForward());
    int c = 0;
    [[unroll]] for (int k = 0; k + 1 < count; ++k)
        if (z > cascadeAt(lightIndex, k).sliceFar) c = k + 1;
    blend = 0.0;
    next = light;
    if (kCascadeBlend && c + 1 < count) {
        const float start = c == 0 ? cascadeStart() : cascadeAt(lightIndex, c - 1).sliceFar;  // split[c]
        const float end = cascadeAt(lightIndex, c).sliceFar;                                  // split[c+1]
        const float bandStart = end - cascadeBlendBand() * (end - start);
        if (z > bandStart) {
            blend = clamp((z - bandStart) / (end - bandStart), 0.0, 1.0);
            next = withCascade(light, lightIndex, c + 1);
        }
    }
    LightData chosen = withCascade(light, lightIndex, c);
    // Past the last split (with the slack raster/cascades.h kCascadeSplitSlack gives its receivers)
    // lie only receivers no caster can shade (shadowableDepthRange): lit, with no shadow test.
    const float last = cascadeAt(lightIndex, count - 1).sliceFar;
    if (z > last + 1e-4 * abs(last)) chosen.layer = -1.0;
    return chosen;
}

void main() {
    // The position's screen-space derivatives, here in uniform control flow: vectors in the
    // triangle's plane (the position is linear across it), for its facet normal below and the
    // receiver plane.
    const vec3 ex = dFdx(inPosition), ey = dFdy(inPosition);
    const vec3 dpdx = kReceiverPlane ? ex : vec3(0.0);
    const vec3 dpdy = kReceiverPlane ? ey : vec3(0.0);
#ifdef SHADOWLAB_ALPHA
    if (alphaCameraSkips(inObjectId, inUv)) discard;  // after the derivatives, which need the quad
#endif
    vec3 n = normalize(inNormal);
    // Two-sided surfaces, the ray tracer's rule (raytrace/tracer.cpp, surfacePoint): the facet's
    // normal turned toward the viewer, the shading normal into that normal's half-space. Turning
    // the shading normal toward the viewer by itself flips it across the facet where it leans away
    // from the viewer while the facet faces it (smooth normals near a silhouette, a rough mesh's
    // normals), which negates N·L there. A facet seen edge-on has no normal here: the shading
    // normal decides.
    vec3 facet = cross(ex, ey);
    if (dot(facet, inPosition) > 0.0) facet = -facet;
    const float side = dot(facet, facet) > 0.0 ? dot(n, facet) : -dot(n, inPosition);
    if (side < 0.0) n = -n;

    const vec4 objectAlbedo = inAlbedo;
    const vec3 albedoColor = objectAlbedo.rgb;
    if (kTransmittance) receiverTransmittance = max(objectAlbedo.a, 1e-6);
    vec3 color = ambient() * albedoColor;
    float weightSum = 0.0;
    float weightedVisibility = 0.0;
    uint blocker = 0u;
    const int lightCount = kLightCount;
    float maxNdotL = lightCount > 0 ? -1.0 : 0.0;
#ifdef SHADOWLAB_LIGHT_OUTPUTS
    vec4 lightVisibility[2] = vec4[](vec4(0.0), vec4(0.0));
#endif
    [[unroll]] for (int i = 0; i < lightCount; ++i) {
        LightData light = lightAt(i);
        // A cascaded directional light (cascadeCount; 0 without a shadow test) takes its
        // cascade's map. The code exists only in pipelines made for cascades (kCascades > 1).
        LightData nextCascade;
        float cascadeBlend = 0.0;  // > 0: in a blend band, mix with nextCascade's visibility
        // (kSpecializedCascades: the one light is the cascaded one, its cascadeCount kCascades.)
        if (kCascades > 1 && isKind(light, SHADOWLAB_LIGHT_DIRECTIONAL) && (kSpecializedCascades || light.cascadeCount > 1))
            light = cascadeOf(light, i, inPosition, nextCascade, cascadeBlend);
        vec3 l;
        float irradiance;  // relative to radiance: 1 for directional lights
        bool reaches = true;
        if (isPerspective(light)) {
            // scene/shading.h: intensity / (4π d²); a spot is dark outside its cone and falls off
            // between its inner and outer cone (spotFalloff).
            const vec3 toLight = light.position - inPosition;
            const float d2 = dot(toLight, toLight);
            l = toLight * inversesqrt(d2);
            irradiance = 1.0 / (4.0 * kPi * d2);
            if (isKind(light, SHADOWLAB_LIGHT_SPOT)) {
                const float cosAngle = dot(-l, light.spotDirection);
                reaches = cosAngle >= light.spotCosCone;
                if (light.spotCosInner > light.spotCosCone) {
                    const float t = clamp((cosAngle - light.spotCosCone) / (light.spotCosInner - light.spotCosCone), 0.0, 1.0);
                    irradiance *= t * t;
                }
                if (!reaches) irradiance = 0.0;
            }
        } else {
            l = light.towardLight;
            irradiance = 1.0;
        }
        const float ndotl = dot(n, l);
        // A light that does not reach the point (outside a spot's cone) has no N·L to give: where
        // none reaches, ndotl stays -1 and compare counts the pixel as it counts a back face.
        maxNdotL = max(maxNdotL, reaches ? ndotl : -1.0);
        // No light (N·L <= 0, outside a spot's cone): visibility 0, weight 0. (An if, not a
        // continue, so that the loop unrolls.)
        if (ndotl > 0.0 && reaches) {
            uint lightBlocker = 0u;
            float v = light.layer >= 0.0 ? shadowTest(light, inPosition, n, ndotl, dpdx, dpdy, lightBlocker) : 1.0;
            if (kCascadeBlend && cascadeBlend > 0.0) {
                // (A cascaded light always has a shadow test: cascadeCount > 1 only then.) The blocker
                // id stays the first cascade's when it found one.
                uint nextBlocker = 0u;
                const float vNext = shadowTest(nextCascade, inPosition, n, ndotl, dpdx, dpdy, nextBlocker);
                v = mix(v, vNext, cascadeBlend);
                if (lightBlocker == 0u) lightBlocker = nextBlocker;
            }
            if (blocker == 0u) blocker = lightBlocker;  // the first light that found one, as raytrace/
#ifdef SHADOWLAB_LIGHT_OUTPUTS
            lightVisibility[i / 4][i % 4] = v;
#endif
            // The visibility AOV weighs each light by what it would add unshadowed (as raytrace/).
            const float w = light.visibilityWeight * irradiance * ndotl;
            weightSum += w;
            weightedVisibility += w * v;
            color += albedoColor * light.radiance * (irradiance * ndotl * v);
        }
    }
    const float visibility = !kVisibility ? 1.0 : weightSum > 0.0 ? weightedVisibility / weightSum : 0.0;
    outBeauty = vec4(color, visibility);
#ifndef SHADOWLAB_BEAUTY_ONLY
    outVisibility = visibility;
    outObjectId = float(inObjectId);
    outNdotL = maxNdotL;
    outDepth = dot(inPosition, viewForward());
    outBlockerId = float(blocker);
#endif
#ifdef SHADOWLAB_LIGHT_OUTPUTS
    outLights0 = lightVisibility[0];
    outLights1 = lightVisibility[1];
#endif
}
