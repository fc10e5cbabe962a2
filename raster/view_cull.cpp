// raster/view_cull.cpp: clusters of the index buffer and their test against the camera's clip volume.
#include "raster/view_cull.h"

#include <algorithm>
#include <cmath>

#include <glm/glm.hpp>

#include "raster/tolerances.h"

namespace shadowlab::raster {

std::vector<IndexCluster> indexClusters(std::span<const Vertex> vertices, std::span<const std::uint32_t> indices,
                                        std::span<const IndexRange> pieces, std::uint32_t maxTriangles) {
    std::vector<IndexCluster> clusters;
    const std::uint32_t step = std::max<std::uint32_t>(maxTriangles, 1) * 3;
    for (const IndexRange& piece : pieces)
        for (std::uint32_t first = piece.first; first < piece.first + piece.count; first += step) {
            IndexCluster c{first, std::min(step, piece.first + piece.count - first), glm::vec3(INFINITY),
                           glm::vec3(-INFINITY)};
            for (std::uint32_t i = c.first; i < c.first + c.count; ++i) {
                c.lo = glm::min(c.lo, vertices[indices[i]].position);
                c.hi = glm::max(c.hi, vertices[indices[i]].position);
            }
            clusters.push_back(c);
        }
    return clusters;
}

bool boxOutsideClipVolume(const glm::vec3& lo, const glm::vec3& hi, const glm::mat4& viewProj) {
    if (!(lo.x <= hi.x && lo.y <= hi.y && lo.z <= hi.z)) return false;  // empty or NaN: never culled
    // Rows of clip = M·p (in double, from the float matrix the vertex shader uses).
    glm::dvec4 row[4];
    for (int r = 0; r < 4; ++r) row[r] = glm::dvec4(viewProj[0][r], viewProj[1][r], viewProj[2][r], viewProj[3][r]);
    // Inside: w + x ≥ 0, w − x ≥ 0, w + y ≥ 0, w − y ≥ 0, z ≥ 0 (far, reversed Z), w − z ≥ 0 (near).
    const glm::dvec4 planes[6] = {row[3] + row[0], row[3] - row[0], row[3] + row[1],
                                  row[3] - row[1], row[2],          row[3] - row[2]};
    const glm::dvec3 dlo(lo), dhi(hi);
    const glm::dvec3 magnitude = glm::max(glm::abs(dlo), glm::abs(dhi));
    for (const glm::dvec4& plane : planes) {
        // The plane's largest value over the box is at the corner its normal points to.
        const glm::dvec3 n(plane);
        const glm::dvec3 corner(n.x > 0 ? dhi.x : dlo.x, n.y > 0 ? dhi.y : dlo.y, n.z > 0 ? dhi.z : dlo.z);
        const double value = glm::dot(n, corner) + plane.w;
        // The float product's rounding scales with its terms' magnitudes, those of both rows in it.
        const glm::dvec4 terms = glm::abs(row[3]) + glm::abs(row[0]) + glm::abs(row[1]) + glm::abs(row[2]);
        const double slack = kViewCullMargin * (glm::dot(glm::dvec3(terms), magnitude) + terms.w);
        if (value < -slack) return true;
    }
    return false;
}

std::vector<IndexRange> visibleIndexRuns(std::span<const IndexCluster> clusters, const glm::mat4& viewProj) {
    std::vector<bool> keep(clusters.size());
    for (std::size_t i = 0; i < clusters.size(); ++i)
        keep[i] = !boxOutsideClipVolume(clusters[i].lo, clusters[i].hi, viewProj);
    return keptIndexRuns(clusters, keep);
}

std::vector<IndexRange> keptIndexRuns(std::span<const IndexCluster> clusters, const std::vector<bool>& keep) {
    std::vector<IndexRange> runs;
    for (std::size_t i = 0; i < clusters.size(); ++i) {
        const IndexCluster& c = clusters[i];
        if (c.count == 0 || !keep[i]) continue;
        if (!runs.empty() && runs.back().first + runs.back().count == c.first)
            runs.back().count += c.count;
        else
            runs.push_back(IndexRange{c.first, c.count});
    }
    return runs;
}

std::vector<scene::Bounds> worldBoxes(std::span<const IndexCluster> clusters, const glm::dvec3& origin) {
    std::vector<scene::Bounds> boxes;
    boxes.reserve(clusters.size());
    for (const IndexCluster& c : clusters) {
        // The float box holds the float vertices exactly; in double, origin + a float is within an
        // ulp of the double sum, which the culling margin (texels) dwarfs.
        scene::Bounds b;
        b.extend(origin + glm::dvec3(c.lo));
        b.extend(origin + glm::dvec3(c.hi));
        boxes.push_back(b);
    }
    return boxes;
}

std::vector<IndexRange> intersectRanges(std::span<const IndexRange> ranges, std::span<const IndexRange> visible) {
    std::vector<IndexRange> out;
    std::size_t v = 0;
    for (const IndexRange& r : ranges) {
        const std::uint32_t end = r.first + r.count;
        while (v < visible.size() && visible[v].first + visible[v].count <= r.first) ++v;
        for (std::size_t k = v; k < visible.size() && visible[k].first < end; ++k) {
            const std::uint32_t a = std::max(r.first, visible[k].first);
            const std::uint32_t b = std::min(end, visible[k].first + visible[k].count);
            if (a >= b) continue;
            IndexRange part = r;
            part.first = a;
            part.count = b - a;
            out.push_back(part);
        }
    }
    return out;
}

}  // namespace shadowlab::raster
