// shaders/lit_constants.glsl: the lit pass's specialization constants, shared by lit.vert and
// lit.frag (raster/lit_pass.cpp gives both stages the same VkSpecializationInfo; each uses the
// constants it needs). lavapipe (llvmpipe) runs every branch of a fragment shader for all lanes
// under an execution mask instead of jumping over it, so a filter chosen at run time paid for the
// texture taps of every filter and the blocker-id lookups on every pixel. Fixed at pipeline
// creation, the dead paths are gone.
layout(constant_id = 0) const int kFilter = SHADOWLAB_FILTER_PCF2X2;  // the filter of every light
layout(constant_id = 1) const bool kBlockerIds = true;  // look up and write the blocker ids
// The number of lights (u.lightCount holds the same), so the light loop unrolls and each light's
// uniforms are loaded from a constant index; and the light kinds present (bit 1 << kind), so
// the spot and point-light paths are left out of scenes without such lights.
#if defined(SHADOWLAB_ONE_SUN) || defined(SHADOWLAB_ONE_SPOT) || defined(SHADOWLAB_ONE_POINT)
// (The *_sun variants: one directional light, no semi-transparent casters, no receiver plane;
// *_sun_map also one map, no cascades; *_spot and *_point: one spot or one point light, likewise.
// These constants are plain constants there, so spirv-opt drops the code they switch off before
// lavapipe turns the module into NIR.)
const int kLightCount = 1;
#if defined(SHADOWLAB_ONE_SPOT)
const int kLightKinds = 1 << SHADOWLAB_LIGHT_SPOT;
#elif defined(SHADOWLAB_ONE_POINT)
const int kLightKinds = 1 << SHADOWLAB_LIGHT_POINT;
#else
const int kLightKinds = 1 << SHADOWLAB_LIGHT_DIRECTIONAL;
#endif
#if defined(SHADOWLAB_ONE_MAP) || !defined(SHADOWLAB_ONE_SUN)
const int kCascades = 1;
const bool kCascadeBlend = false;
#else
layout(constant_id = 4) const int kCascades = 1;
layout(constant_id = 7) const bool kCascadeBlend = false;
#endif
const bool kTransmittance = false;
const bool kReceiverPlane = false;
#else
layout(constant_id = 2) const int kLightCount = SHADOWLAB_MAX_LIGHTS;
layout(constant_id = 3) const int kLightKinds = 7;
// The cascades of the cascaded directional lights (1: none cascaded; every cascaded light has
// the same count, as the cascades depend on the camera only), so scenes without cascades have
// no cascade selection and the selection loop has a constant length.
layout(constant_id = 4) const int kCascades = 1;
// The scene has semi-transparent casters: every compare tap is multiplied by the transmittance
// map's texel. Scenes without have none of that code.
layout(constant_id = 5) const bool kTransmittance = false;
// Receiver-plane depth bias in every tap (see shadowTest); off, its code is compiled out.
layout(constant_id = 6) const bool kReceiverPlane = false;
// Cascaded lights blend each cascade into the next over a band before the split
// (u.cascadeBlendBand, the band's fraction of the slice; see cascadeOf); off, the second shadow
// test is compiled out.
layout(constant_id = 7) const bool kCascadeBlend = false;
#endif
// The visibility AOV is computed (the AOV variants); off for the beauty-only variants (the float
// beauty and the 8-bit display target), which leaves out the weighting and the division per pixel.
layout(constant_id = 8) const bool kVisibility = true;
// A normal offset is set (LightData::normalOffsetTexels, the same for every light): off (the
// default), the lookup point is the surface point itself, and the offset's arithmetic is left out.
layout(constant_id = 9) const bool kNormalOffset = true;
// One directional light with one map, or one spot light, and no receiver plane (kOneMapLight): the
// one light whose constants lit.vert can pass on flat (kVertexLightConstants) or the pipeline can
// bake in (kSpecializedLightConstants), its map matrix among them.
// (Written without ||: glslang turns || of specialization constants into a branch and an OpPhi
// inside a function, which the constant's uses elsewhere cannot see.)
// The cascaded *_sun modules (SHADOWLAB_ONE_SUN without SHADOWLAB_ONE_MAP): never, fixed here so
// that spirv-opt drops the code.
#if defined(SHADOWLAB_ONE_SUN) && !defined(SHADOWLAB_ONE_MAP)
#ifndef SHADOWLAB_BAKED_LIGHT
#error the cascaded *_sun modules go with SHADOWLAB_BAKED_LIGHT: no lit.vert build passes them flat light values
#endif
const bool kOneSpot = false;
const bool kOneMapSun = false;
#else
const bool kOneSpot = kLightCount == 1 && kLightKinds == (1 << SHADOWLAB_LIGHT_SPOT) && !kReceiverPlane;
const bool kOneMapSun = kLightCount == 1 && kLightKinds == (1 << SHADOWLAB_LIGHT_DIRECTIONAL) && kCascades == 1 &&
                        !kReceiverPlane;
#endif
const bool kOneMapLight = !(!kOneSpot && !kOneMapSun);
const bool kAnyPerspective =
    (kLightKinds & ((1 << SHADOWLAB_LIGHT_SPOT) | (1 << SHADOWLAB_LIGHT_POINT))) != 0;
// The one light's constants that lit.frag reads (the LightData members its kind uses; the kind
// itself is a constant there, as kLightKinds has one bit), LitUniforms' forward, ambient and map
// size, and its toShadow (lit.frag oneMapMatrix) reach lit.frag as flat outputs of lit.vert
// instead of uniform-buffer reads, where that light is kOneMapLight. lavapipe (Mesa 22.3's
// llvmpipe) reads a uniform in a fragment shader lane by lane, with a bounds check, for every
// eight pixels; a flat input is set up once per triangle and then read as a constant
// (docs/performance.md: less CPU per frame on the seed scene and on Sponza, down to half a pixel
// per triangle). The values are the same floats either way (raster::LightConstants).
// SHADOWLAB_BAKED_LIGHT (the modules raster/lit_pass.cpp picks for baked constants, below): never;
// those modules declare no flat light inputs, which llvmpipe would set up per triangle unread.
layout(constant_id = 10) const bool kVertexLightConstantsAsked = false;
#ifdef SHADOWLAB_BAKED_LIGHT
const bool kVertexLightConstants = false;
#else
const bool kVertexLightConstants = kVertexLightConstantsAsked && kOneMapLight;
#endif
// The same values baked into the pipeline (raster::LightConstants::kSpecialization): lit.frag reads
// them as constants 18..49, packed as lit.vert packs outLight[0..5] and outFrame[0..1] (but for the
// matrix's rows, which the lit_vert*_sun builds put in a sun's spare components), and lit.vert
// writes neither. A flat input costs llvmpipe its setup and 48 bytes per triangle in every bin it
// touches; a constant costs nothing per triangle, and folds into the arithmetic that reads it.
// kOneMapLight: also its map matrix, in cascade 0's constants below. One cascaded directional light,
// no receiver plane: the same 32 values, and the cascades' values below.
layout(constant_id = 17) const bool kSpecializedLightConstantsAsked = false;
const bool kOneCascadedSun = kLightCount == 1 && kLightKinds == (1 << SHADOWLAB_LIGHT_DIRECTIONAL) && kCascades > 1 &&
                             !kReceiverPlane;
const bool kSpecializedCascades = kSpecializedLightConstantsAsked && kOneCascadedSun;
const bool kSpecializedLightConstants =
    !(!(kSpecializedLightConstantsAsked && kOneMapLight) && !kSpecializedCascades);
// lightAt() unpacks the 32 values, from lit.vert or baked in.
const bool kLightFromSlots = !(!kVertexLightConstants && !kSpecializedLightConstants);
layout(constant_id = 18) const float kL00 = 0.0;
layout(constant_id = 19) const float kL01 = 0.0;
layout(constant_id = 20) const float kL02 = 0.0;
layout(constant_id = 21) const float kL03 = 0.0;
layout(constant_id = 22) const float kL10 = 0.0;
layout(constant_id = 23) const float kL11 = 0.0;
layout(constant_id = 24) const float kL12 = 0.0;
layout(constant_id = 25) const float kL13 = 0.0;
layout(constant_id = 26) const float kL20 = 0.0;
layout(constant_id = 27) const float kL21 = 0.0;
layout(constant_id = 28) const float kL22 = 0.0;
layout(constant_id = 29) const float kL23 = 0.0;
layout(constant_id = 30) const float kL30 = 0.0;
layout(constant_id = 31) const float kL31 = 0.0;
layout(constant_id = 32) const float kL32 = 0.0;
layout(constant_id = 33) const float kL33 = 0.0;
layout(constant_id = 34) const float kL40 = 0.0;
layout(constant_id = 35) const float kL41 = 0.0;
layout(constant_id = 36) const float kL42 = 0.0;
layout(constant_id = 37) const float kL43 = 0.0;
layout(constant_id = 38) const float kL50 = 0.0;
layout(constant_id = 39) const float kL51 = 0.0;
layout(constant_id = 40) const float kL52 = 0.0;
layout(constant_id = 41) const float kL53 = 0.0;
layout(constant_id = 42) const float kF00 = 0.0;
layout(constant_id = 43) const float kF01 = 0.0;
layout(constant_id = 44) const float kF02 = 0.0;
layout(constant_id = 45) const float kF03 = 0.0;
layout(constant_id = 46) const float kF10 = 0.0;
layout(constant_id = 47) const float kF11 = 0.0;
layout(constant_id = 48) const float kF12 = 0.0;
layout(constant_id = 49) const float kF13 = 0.0;
// kSpecializedCascades: LitUniforms' cascadeStart and cascadeBlendBand, then per cascade c of light 0
// (constants 52 + 16c ..): toShadow's first three rows (an orthographic map's last row is 0 0 0 1),
// then sliceFar, texelWorldSize, depthPerWorld and depthBiasWorld (raster::packLightConstants).
// kOneMapLight with kSpecializedLightConstants: cascade 0's first three rows are its toShadow's
// (lit.frag oneMapMatrix; a spot's last row is in the light slots' spare components).
layout(constant_id = 50) const float kCascadeStart = 0.0;
layout(constant_id = 51) const float kCascadeBlendBand = 0.0;
layout(constant_id = 52) const float kC0_00 = 0.0;
layout(constant_id = 53) const float kC0_01 = 0.0;
layout(constant_id = 54) const float kC0_02 = 0.0;
layout(constant_id = 55) const float kC0_03 = 0.0;
layout(constant_id = 56) const float kC0_04 = 0.0;
layout(constant_id = 57) const float kC0_05 = 0.0;
layout(constant_id = 58) const float kC0_06 = 0.0;
layout(constant_id = 59) const float kC0_07 = 0.0;
layout(constant_id = 60) const float kC0_08 = 0.0;
layout(constant_id = 61) const float kC0_09 = 0.0;
layout(constant_id = 62) const float kC0_10 = 0.0;
layout(constant_id = 63) const float kC0_11 = 0.0;
layout(constant_id = 64) const float kC0_12 = 0.0;
layout(constant_id = 65) const float kC0_13 = 0.0;
layout(constant_id = 66) const float kC0_14 = 0.0;
layout(constant_id = 67) const float kC0_15 = 0.0;
layout(constant_id = 68) const float kC1_00 = 0.0;
layout(constant_id = 69) const float kC1_01 = 0.0;
layout(constant_id = 70) const float kC1_02 = 0.0;
layout(constant_id = 71) const float kC1_03 = 0.0;
layout(constant_id = 72) const float kC1_04 = 0.0;
layout(constant_id = 73) const float kC1_05 = 0.0;
layout(constant_id = 74) const float kC1_06 = 0.0;
layout(constant_id = 75) const float kC1_07 = 0.0;
layout(constant_id = 76) const float kC1_08 = 0.0;
layout(constant_id = 77) const float kC1_09 = 0.0;
layout(constant_id = 78) const float kC1_10 = 0.0;
layout(constant_id = 79) const float kC1_11 = 0.0;
layout(constant_id = 80) const float kC1_12 = 0.0;
layout(constant_id = 81) const float kC1_13 = 0.0;
layout(constant_id = 82) const float kC1_14 = 0.0;
layout(constant_id = 83) const float kC1_15 = 0.0;
layout(constant_id = 84) const float kC2_00 = 0.0;
layout(constant_id = 85) const float kC2_01 = 0.0;
layout(constant_id = 86) const float kC2_02 = 0.0;
layout(constant_id = 87) const float kC2_03 = 0.0;
layout(constant_id = 88) const float kC2_04 = 0.0;
layout(constant_id = 89) const float kC2_05 = 0.0;
layout(constant_id = 90) const float kC2_06 = 0.0;
layout(constant_id = 91) const float kC2_07 = 0.0;
layout(constant_id = 92) const float kC2_08 = 0.0;
layout(constant_id = 93) const float kC2_09 = 0.0;
layout(constant_id = 94) const float kC2_10 = 0.0;
layout(constant_id = 95) const float kC2_11 = 0.0;
layout(constant_id = 96) const float kC2_12 = 0.0;
layout(constant_id = 97) const float kC2_13 = 0.0;
layout(constant_id = 98) const float kC2_14 = 0.0;
layout(constant_id = 99) const float kC2_15 = 0.0;
layout(constant_id = 100) const float kC3_00 = 0.0;
layout(constant_id = 101) const float kC3_01 = 0.0;
layout(constant_id = 102) const float kC3_02 = 0.0;
layout(constant_id = 103) const float kC3_03 = 0.0;
layout(constant_id = 104) const float kC3_04 = 0.0;
layout(constant_id = 105) const float kC3_05 = 0.0;
layout(constant_id = 106) const float kC3_06 = 0.0;
layout(constant_id = 107) const float kC3_07 = 0.0;
layout(constant_id = 108) const float kC3_08 = 0.0;
layout(constant_id = 109) const float kC3_09 = 0.0;
layout(constant_id = 110) const float kC3_10 = 0.0;
layout(constant_id = 111) const float kC3_11 = 0.0;
layout(constant_id = 112) const float kC3_12 = 0.0;
layout(constant_id = 113) const float kC3_13 = 0.0;
layout(constant_id = 114) const float kC3_14 = 0.0;
layout(constant_id = 115) const float kC3_15 = 0.0;

// Every light's constants baked in (kEveryLightBaked), where light 0's alone cannot be: several
// lights, a point light, the receiver-plane bias. The SHADOWLAB_BAKED_LIGHT modules then read the
// LightData members lit.frag uses of light i from constants 116 + 56 i ..: fourteen slots of four,
// packed as raster::packLightConstants packs them, instead of loading them from the uniform buffer
// lane by lane for every eight pixels; each light's kind becomes a constant too, so the code of the
// kinds it is not is left out of its unrolled iteration; and each light's cascades. Only in
// the *_every modules (SHADOWLAB_EVERY_LIGHT), which raster/lit_pass.cpp picks for that case alone:
// glslang cannot fold the switch between the one light's constants and these, and in the other
// modules the code would stay in the SPIR-V lavapipe turns into NIR at every pipeline's creation.
#ifdef SHADOWLAB_EVERY_LIGHT
#ifndef SHADOWLAB_BAKED_LIGHT
#error SHADOWLAB_EVERY_LIGHT goes with SHADOWLAB_BAKED_LIGHT (no flat light inputs)
#endif
#define SHADOWLAB_LIGHT_SLOT(i, s)                                                 \
    layout(constant_id = 116 + 56 * i + 4 * s) const float kB##i##_##s##x = 0.0;     \
    layout(constant_id = 116 + 56 * i + 4 * s + 1) const float kB##i##_##s##y = 0.0; \
    layout(constant_id = 116 + 56 * i + 4 * s + 2) const float kB##i##_##s##z = 0.0; \
    layout(constant_id = 116 + 56 * i + 4 * s + 3) const float kB##i##_##s##w = 0.0;
#define SHADOWLAB_LIGHT_SLOTS(i)                                                                                  \
    SHADOWLAB_LIGHT_SLOT(i, 0) SHADOWLAB_LIGHT_SLOT(i, 1) SHADOWLAB_LIGHT_SLOT(i, 2) SHADOWLAB_LIGHT_SLOT(i, 3)   \
    SHADOWLAB_LIGHT_SLOT(i, 4) SHADOWLAB_LIGHT_SLOT(i, 5) SHADOWLAB_LIGHT_SLOT(i, 6) SHADOWLAB_LIGHT_SLOT(i, 7)   \
    SHADOWLAB_LIGHT_SLOT(i, 8) SHADOWLAB_LIGHT_SLOT(i, 9) SHADOWLAB_LIGHT_SLOT(i, 10) SHADOWLAB_LIGHT_SLOT(i, 11) \
    SHADOWLAB_LIGHT_SLOT(i, 12) SHADOWLAB_LIGHT_SLOT(i, 13)
SHADOWLAB_LIGHT_SLOTS(0)
SHADOWLAB_LIGHT_SLOTS(1)
SHADOWLAB_LIGHT_SLOTS(2)
SHADOWLAB_LIGHT_SLOTS(3)
SHADOWLAB_LIGHT_SLOTS(4)
SHADOWLAB_LIGHT_SLOTS(5)
SHADOWLAB_LIGHT_SLOTS(6)
SHADOWLAB_LIGHT_SLOTS(7)
// Each light's SHADOWLAB_MAX_CASCADES cascades (constants 564 + 64 i + 16 c ..): as kC0_00.. above,
// toShadow's first three rows, then sliceFar, texelWorldSize, depthPerWorld, depthBiasWorld.
#define SHADOWLAB_CASCADE_SLOT(i, c, s)                                                                \
    layout(constant_id = 564 + 64 * i + 16 * c + 4 * s) const float kD##i##_##c##_##s##x = 0.0;     \
    layout(constant_id = 564 + 64 * i + 16 * c + 4 * s + 1) const float kD##i##_##c##_##s##y = 0.0; \
    layout(constant_id = 564 + 64 * i + 16 * c + 4 * s + 2) const float kD##i##_##c##_##s##z = 0.0; \
    layout(constant_id = 564 + 64 * i + 16 * c + 4 * s + 3) const float kD##i##_##c##_##s##w = 0.0;
#define SHADOWLAB_CASCADE_SLOTS(i, c)                                                              \
    SHADOWLAB_CASCADE_SLOT(i, c, 0) SHADOWLAB_CASCADE_SLOT(i, c, 1) SHADOWLAB_CASCADE_SLOT(i, c, 2) \
    SHADOWLAB_CASCADE_SLOT(i, c, 3)
#define SHADOWLAB_LIGHT_CASCADES(i)                                                                \
    SHADOWLAB_CASCADE_SLOTS(i, 0) SHADOWLAB_CASCADE_SLOTS(i, 1) SHADOWLAB_CASCADE_SLOTS(i, 2)      \
    SHADOWLAB_CASCADE_SLOTS(i, 3)
SHADOWLAB_LIGHT_CASCADES(0)
SHADOWLAB_LIGHT_CASCADES(1)
SHADOWLAB_LIGHT_CASCADES(2)
SHADOWLAB_LIGHT_CASCADES(3)
SHADOWLAB_LIGHT_CASCADES(4)
SHADOWLAB_LIGHT_CASCADES(5)
SHADOWLAB_LIGHT_CASCADES(6)
SHADOWLAB_LIGHT_CASCADES(7)
#if SHADOWLAB_MAX_LIGHTS != 8 || SHADOWLAB_MAX_CASCADES != 4
#error one SHADOWLAB_LIGHT_SLOTS and SHADOWLAB_LIGHT_CASCADES line per light, four cascades each
#endif
const bool kEveryLightBaked = kSpecializedLightConstantsAsked && !kSpecializedLightConstants;
#else
const bool kEveryLightBaked = false;
#endif
// LitUniforms' forward, ambient and map size from lit.frag's constant slots kF.. or lit.vert's.
const bool kFrameFromSlots = !(!kLightFromSlots && !kEveryLightBaked);
const bool kFrameBakedIn = !(!kSpecializedLightConstants && !kEveryLightBaked);

// The filterable maps' parameters (scene::MomentSettings, raster/moment_maps.h), read only by
// the vsm, evsm2, evsm4, esm and msm filters.
layout(constant_id = 11) const float kMinVariance = 1e-6;
layout(constant_id = 12) const float kBleedReduction = 0.2;
layout(constant_id = 13) const float kEvsmPositive = 40.0;
layout(constant_id = 14) const float kEvsmNegative = 5.0;
layout(constant_id = 15) const float kEsmExponent = 80.0;
layout(constant_id = 16) const float kMomentBias = 3e-5;
