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
#ifdef SHADOWLAB_ONE_SUN
// (The *_sun variants: one directional light, no semi-transparent casters, no receiver plane;
// *_sun_map also one map, no cascades. These constants are plain constants there, so spirv-opt
// drops the code they switch off before lavapipe turns the module into NIR.)
const int kLightCount = 1;
const int kLightKinds = 1 << SHADOWLAB_LIGHT_DIRECTIONAL;
#ifdef SHADOWLAB_ONE_MAP
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
// default), the lookup point is the surface point itself, and the vertex path's map-space normal
// is not read (one varying and its arithmetic less per pixel).
layout(constant_id = 9) const bool kNormalOffset = true;
// One directional light with one map, or one spot light, and no receiver plane: its map
// coordinates are interpolated from lit.vert (see shadowTest) instead of a matrix product per
// fragment.
// (Written without ||: glslang turns || of specialization constants into a branch and an OpPhi
// inside a function, which the constant's uses elsewhere cannot see.)
const bool kVertexSpot = kLightCount == 1 && kLightKinds == (1 << SHADOWLAB_LIGHT_SPOT) && !kReceiverPlane;
const bool kVertexDirectional = kLightCount == 1 && kLightKinds == (1 << SHADOWLAB_LIGHT_DIRECTIONAL) &&
                                kCascades == 1 && !kReceiverPlane;
const bool kVertexLightCoordinates = !(!kVertexSpot && !kVertexDirectional);
const bool kAnyPerspective =
    (kLightKinds & ((1 << SHADOWLAB_LIGHT_SPOT) | (1 << SHADOWLAB_LIGHT_POINT))) != 0;
// The one light's constants that lit.frag reads (the LightData members its kind uses, less
// toShadow; the kind itself is a constant there, as kLightKinds has one bit) and LitUniforms'
// forward, ambient and map size reach lit.frag as flat outputs of lit.vert instead of uniform-buffer reads, where lit.frag takes
// that light's map coordinates from lit.vert too (kVertexLightCoordinates). lavapipe (Mesa 22.3's
// llvmpipe) reads a uniform in a fragment shader lane by lane, with a bounds check, for every
// eight pixels; a flat input is set up once per triangle and then read as a constant
// (docs/performance.md: less CPU per frame on the seed scene and on Sponza, down to half a pixel
// per triangle). The values are the same floats either way (raster::LightConstants).
layout(constant_id = 10) const bool kVertexLightConstantsAsked = false;
const bool kVertexLightConstants = kVertexLightConstantsAsked && kVertexLightCoordinates;
// The same values baked into the pipeline (raster::LightConstants::kSpecialization): lit.frag reads
// them as constants 18..49, packed as lit.vert packs outLight[0..5] and outFrame[0..1], and lit.vert
// writes neither. A flat input costs llvmpipe its setup and 48 bytes per triangle in every bin it
// touches; a constant costs nothing per triangle, and folds into the arithmetic that reads it.
layout(constant_id = 17) const bool kSpecializedLightConstantsAsked = false;
const bool kSpecializedLightConstants = kSpecializedLightConstantsAsked && kVertexLightConstants;
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

// The filterable maps' parameters (scene::MomentSettings, raster/moment_maps.h), read only by
// the vsm, evsm2, evsm4, esm and msm filters.
layout(constant_id = 11) const float kMinVariance = 1e-6;
layout(constant_id = 12) const float kBleedReduction = 0.2;
layout(constant_id = 13) const float kEvsmPositive = 40.0;
layout(constant_id = 14) const float kEvsmNegative = 5.0;
layout(constant_id = 15) const float kEsmExponent = 80.0;
layout(constant_id = 16) const float kMomentBias = 3e-5;
