// scene/gltf_export.h: a Scene as glTF 2.0 (.glb or .gltf) with KHR_lights_punctual, so that any
// engine loads what shadowlab renders: analytic spheres, quads and boxes tessellated, the camera,
// materials and opacity, the image size; a shadowlab load of the file gives back the same lights,
// camera and image size (docs/export.md).
#pragma once

#include <filesystem>

#include "scene/scene.h"

namespace shadowlab::scene {

struct ExportOptions {
    // Largest sagitta of a sphere's tessellation (the distance from the true surface to the
    // flat triangles), as a fraction of its radius.
    double tolerance = 1e-3;
};

// The finest tolerance: a UV sphere then has about π²/(4·1e-5) ≈ 250,000 triangles, and no
// shadow map or pixel of a sane view resolves a sagitta of 1e-5 of the radius. (Below it the
// count grows without bound: 1e-8 took 13 GB before it was stopped.)
inline constexpr double kMinExportTolerance = 1e-5;

// glTF needs a spot's innerConeAngle below its outerConeAngle: an export writes a hard cone's
// inner angle as this fraction of the outer one, and loading a shadowlab export reads an inner
// angle at or above it back as hard, so the round trip keeps the cone's edge hard.
inline constexpr double kExportHardConeInnerRatio = 1.0 - 1e-3;

// Throws InputError for an extension other than .glb or .gltf, or a tolerance outside
// [kMinExportTolerance, 0.5), naming the option and the value.
void checkExportOptions(const std::filesystem::path& file, const ExportOptions& options);

struct ExportResult {
    double achievedTolerance = 0.0;  // the largest measured sagitta / radius over all spheres (0: none)
    std::size_t triangles = 0;
    std::size_t nodes = 0;
};

// The largest distance from a sphere of radius 1 to a UV tessellation with `segments` around and
// `rings` from pole to pole (vertices on the sphere), measured over every triangle: 1 minus the
// least distance from the centre to a triangle.
double uvSphereSagitta(int segments, int rings);

// Writes `scene` to `file` (.glb binary, .gltf with the buffer embedded as a data URI) through a
// temporary name and a rename. Throws InputError for an unknown extension or a file that cannot
// be written (nothing is left behind).
ExportResult exportGltf(const Scene& scene, const std::filesystem::path& file, const ExportOptions& options = {});

}  // namespace shadowlab::scene
