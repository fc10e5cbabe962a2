// raster/view_cull.h: which runs of the index buffer the camera cannot see, so that the lit pass
// does not draw them. Exact: only triangles that produce no fragment are left out, and the rest
// keep their order (draw order decides depth ties). The same clusters serve the shadow pass,
// which leaves out those that cannot cast onto what the camera sees (docs/raster.md).
#pragma once

#include <cstdint>
#include <span>
#include <vector>

#include <glm/mat4x4.hpp>
#include <glm/vec3.hpp>

#include "raster/geometry.h"
#include "raster/shadow_pass.h"
#include "scene/scene.h"

namespace shadowlab::raster {

// Consecutive triangles of the index buffer (indices first .. first + count − 1) and the box of
// their vertices, in the vertex buffer's (camera-relative) coordinates.
struct IndexCluster {
    std::uint32_t first = 0;
    std::uint32_t count = 0;
    glm::vec3 lo{0.0f};
    glm::vec3 hi{0.0f};
};

// `pieces` (the objects in index order) cut into clusters of at most maxTriangles consecutive
// triangles each, a cluster never spanning two pieces (one object's box stays its own).
std::vector<IndexCluster> indexClusters(std::span<const Vertex> vertices, std::span<const std::uint32_t> indices,
                                        std::span<const IndexRange> pieces, std::uint32_t maxTriangles);

// True when every point of the box [lo, hi] lies outside one plane of the clip volume of
// `viewProj` (−w ≤ x ≤ w, −w ≤ y ≤ w, 0 ≤ z ≤ w), by a margin of kViewCullMargin of the magnitudes
// summed in that plane's product: then no triangle in the box can give a fragment, whatever the
// float rounding of the vertex shader's product with the same (float) matrix.
bool boxOutsideClipVolume(const glm::vec3& lo, const glm::vec3& hi, const glm::mat4& viewProj);

// The index runs of the clusters not outside the clip volume, adjacent ones merged, in order.
std::vector<IndexRange> visibleIndexRuns(std::span<const IndexCluster> clusters, const glm::mat4& viewProj);

// The index runs of the clusters with keep[i], adjacent ones merged, in order.
std::vector<IndexRange> keptIndexRuns(std::span<const IndexCluster> clusters, const std::vector<bool>& keep);

// The clusters' boxes in world coordinates (the vertex buffer's are relative to `origin`), for the
// shadow pass's culling of clusters that cannot cast onto what the camera sees
// (raster::layerCastingBoxes).
std::vector<scene::Bounds> worldBoxes(std::span<const IndexCluster> clusters, const glm::dvec3& origin);

// `ranges` (sorted, disjoint) cut to the parts inside `visible` (sorted, disjoint), each part
// keeping its range's flags, in order; parts of one range that touch stay one.
std::vector<IndexRange> intersectRanges(std::span<const IndexRange> ranges, std::span<const IndexRange> visible);

}  // namespace shadowlab::raster
