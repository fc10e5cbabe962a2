// raster/lift_free.h: which triangles the lit pass can draw without the slope bias's lift past its
// cap (docs/raster.md "Grazing light"), so that a pipeline without that path draws them.
#pragma once

#include <cstdint>
#include <span>
#include <vector>

#include <glm/mat4x4.hpp>
#include <glm/vec3.hpp>

#include "raster/shadow_pass.h"

namespace shadowlab::raster {

// The |N·L| from which a fragment of a lift-free triangle is judged free of the lift: the cap's
// cos θ = 1/√(1 + maxTan²) plus kLiftFreeMargin (raster/tolerances.h).
double liftFreeThreshold(double maxSlopeTan);

// Per vertex, for each light l in towardLights (unit directions toward directional lights whose
// shader slope bias is on): bit 2l when N·L/|N| ≥ threshold, bit 2l+1 when N·L/|N| ≤ −threshold;
// the other bits set. At most 16 lights (SHADOWLAB_MAX_LIGHTS is 8). A zero or non-finite normal
// gets neither bit.
std::vector<std::uint32_t> liftFreeVertexBits(std::span<const glm::vec3> normals,
                                              std::span<const glm::vec3> towardLights, double threshold);

// Per triangle of `indices`, its area in pixels as `viewProj` (camera-relative positions to clip
// space) puts it on a width x height image, unclipped; width·height for a triangle with a vertex
// at or behind the camera's plane.
std::vector<float> pixelAreas(std::span<const glm::vec3> positions, std::span<const std::uint32_t> indices,
                              const glm::mat4& viewProj, std::uint32_t width, std::uint32_t height);

// `ranges` (DrawGeometry::litRanges, or one range of every index when empty) cut into runs of
// triangles that are lift-free (IndexRange::liftFree) or not, in index order: a triangle is
// lift-free when for every light its three vertices share bit 2l or share bit 2l+1. A lift-free
// run whose triangles' `weights` (one per triangle, e.g. pixelAreas) add up to less than minWeight
// stays with its neighbours (each run is a draw and a pipeline switch of its own); alpha ranges are
// never lift-free. Runs of one kind next to each other are merged.
std::vector<IndexRange> splitByLift(std::span<const std::uint32_t> vertexBits, std::span<const std::uint32_t> indices,
                                    std::span<const IndexRange> ranges, std::span<const float> weights,
                                    double minWeight);

}  // namespace shadowlab::raster
