// raster/alpha_casters.h: what the depth and transmittance passes need for alpha-tested (MASK)
// and textured BLEND casters: a second vertex buffer of texture coordinates, one alpha record
// per object id and every alpha texture's texels, in two storage buffers read by
// shaders/alpha.glsl (set 0 in the depth pass and the first transmittance pass, set 1 in the
// second). Made only where some object's alpha test can cut (scene::Material::alphaCanFallBelow)
// or the transmittance passes read alpha (planAlpha).
#pragma once

#include "raster/geometry.h"
#include "raster/pipeline.h"
#include "raster/resources.h"
#include "scene/scene.h"

#include <vector>

namespace shadowlab::raster {

// Which passes test a material's alpha: the depth pass a MASK caster's, the lit pass (the
// camera's) a MASK or BLEND surface's.
struct AlphaTests {
    bool depth = false;
    bool camera = false;
};

// What a Renderer makes and runs for the scene's alpha; the memory estimate reads the same.
struct AlphaPlan {
    std::vector<AlphaTests> byMaterial;  // per scene material (those no object uses: none)
    bool transmittanceReads = false;     // the transmittance passes take their alpha shaders
    bool data = false;                   // UVs and alpha records are made (AlphaCasters)
};

// `transmittance`: the scene has the transmittance passes (RenderPlan::needsTransmittanceMap), which
// draw the semi-transparent casters: they read a textured BLEND caster's alpha and test a MASK
// one's (opacity under 1), in one pipeline for all of them. `idleTestsLeftOut`
// (RendererOptions::idleAlphaTestsLeftOut): a test whose alpha can never fall below its cutoff is
// left out; false tests every MASK and BLEND material.
AlphaPlan planAlpha(const scene::Scene& scene, bool transmittance, bool idleTestsLeftOut = true);

struct AlphaCasters {
    Buffer uvs;                 // vertex binding 1, one vec2 per vertex of SceneGeometry
    Buffer records;             // std430 AlphaRecord per object id (0: unused)
    Buffer texels;              // every texture's alpha, one float a texel
    DescriptorSet descriptors;  // records and texels, bound as set 1 of the passes that test alpha
    std::size_t textureTexels = 0;
};

// `geometry` must have been tessellated with UVs.
AlphaCasters createAlphaCasters(const Context& ctx, const scene::Scene& scene, const SceneGeometry& geometry);

}  // namespace shadowlab::raster
