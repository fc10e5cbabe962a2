// shaders/background.frag: the values of a pixel no object covers, written into the lit pass's
// float targets instead of clearing them: lavapipe (Mesa 22.3) clears a texel wider than 4 bytes
// with a memcpy per texel, which cost more than shading the image (docs/performance.md). The
// beauty gets the scene's background color, every AOV 0, as the clears gave them.
// Variants as lit.frag's: SHADOWLAB_BEAUTY_ONLY (the beauty target alone), default (the beauty
// and the five AOV planes), SHADOWLAB_LIGHT_OUTPUTS (also the two per-light visibility targets).
#version 450

layout(constant_id = 0) const float kBackgroundR = 0.0;
layout(constant_id = 1) const float kBackgroundG = 0.0;
layout(constant_id = 2) const float kBackgroundB = 0.0;

layout(location = 0) out vec4 outBeauty;
#ifndef SHADOWLAB_BEAUTY_ONLY
layout(location = 1) out float outVisibility;
layout(location = 2) out float outObjectId;
layout(location = 3) out float outNdotL;
layout(location = 4) out float outDepth;
layout(location = 5) out float outBlockerId;
#endif
#ifdef SHADOWLAB_LIGHT_OUTPUTS
layout(location = 6) out vec4 outLights0;
layout(location = 7) out vec4 outLights1;
#endif

void main() {
    outBeauty = vec4(kBackgroundR, kBackgroundG, kBackgroundB, 0.0);
#ifndef SHADOWLAB_BEAUTY_ONLY
    outVisibility = 0.0;
    outObjectId = 0.0;
    outNdotL = 0.0;
    outDepth = 0.0;
    outBlockerId = 0.0;
#endif
#ifdef SHADOWLAB_LIGHT_OUTPUTS
    outLights0 = vec4(0.0);
    outLights1 = vec4(0.0);
#endif
}
