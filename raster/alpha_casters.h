// raster/alpha_casters.h: what the depth and transmittance passes need for alpha-tested (MASK)
// and textured BLEND casters: a second vertex buffer of texture coordinates, one alpha record
// per object id and every alpha texture's texels, in two storage buffers read by
// shaders/alpha.glsl (set 0 in the depth pass and the first transmittance pass, set 1 in the
// second). Made only where some object's alpha test can cut (scene::Material::alphaCanFallBelow)
// or the transmittance passes read alpha (raster/renderer.cpp).
#pragma once

#include "raster/geometry.h"
#include "raster/pipeline.h"
#include "raster/resources.h"
#include "scene/scene.h"

namespace shadowlab::raster {

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
