// raster/lift_free.cpp: the lift-free triangles (raster/lift_free.h).
//
// Why a triangle whose vertices all pass the threshold has no fragment that moves: lit.frag's
// normal is the interpolated one, m = Σ bₖ nₖ with bₖ ≥ 0 and Σ bₖ = 1, normalized, possibly
// negated (two-sided shading). If nₖ·l ≥ t·|nₖ| for every vertex, m·l = Σ bₖ nₖ·l ≥ t Σ bₖ|nₖ| ≥
// t|m|, so N·L ≥ t; with nₖ·l ≤ −t|nₖ| the same bound holds for −N·L. A fragment either has
// N·L ≤ −t (no light, no shadow test) or N·L ≥ t > 1/√(1 + maxTan²), where sin θ − maxTan·cos θ < 0
// and the lift is exactly 0: with no normal offset asked for, the offset is 0·texel = 0 and the
// lookup point p + 0·n is the one the pipeline without the lift uses, bit for bit. Tests render both.
#include "raster/lift_free.h"

#include <cmath>
#include <stdexcept>

#include <glm/geometric.hpp>
#include <glm/vec2.hpp>
#include <glm/vec4.hpp>

#include "raster/tolerances.h"

namespace shadowlab::raster {

double liftFreeThreshold(double maxSlopeTan) {
    return 1.0 / std::sqrt(1.0 + maxSlopeTan * maxSlopeTan) + kLiftFreeMargin;
}

std::vector<std::uint32_t> liftFreeVertexBits(std::span<const glm::vec3> normals,
                                              std::span<const glm::vec3> towardLights, double threshold) {
    if (towardLights.size() > 16) throw std::logic_error("liftFreeVertexBits: more than 16 lights");
    std::uint32_t unused = ~0u;
    for (std::size_t l = 0; l < towardLights.size(); ++l) unused &= ~(3u << (2 * l));
    std::vector<std::uint32_t> bits(normals.size(), unused);
    for (std::size_t v = 0; v < normals.size(); ++v) {
        const glm::dvec3 n(normals[v]);
        const double length = std::sqrt(n.x * n.x + n.y * n.y + n.z * n.z);
        if (!(length > 0.0) || !std::isfinite(length)) continue;
        for (std::size_t l = 0; l < towardLights.size(); ++l) {
            const double ndotl = glm::dot(n, glm::dvec3(towardLights[l])) / length;
            if (ndotl >= threshold) bits[v] |= 1u << (2 * l);
            if (ndotl <= -threshold) bits[v] |= 2u << (2 * l);
        }
    }
    return bits;
}

namespace {
// Every light's pair of bits (2l, 2l+1) has at least one bit set.
bool liftFree(std::uint32_t shared) { return ((shared | (shared >> 1)) & 0x55555555u) == 0x55555555u; }
}  // namespace

std::vector<float> pixelAreas(std::span<const glm::vec3> positions, std::span<const std::uint32_t> indices,
                              const glm::mat4& viewProj, std::uint32_t width, std::uint32_t height) {
    const float whole = float(width) * float(height);
    // Each vertex projected once (NDC x, y; NaN at or behind the camera's plane).
    std::vector<glm::vec2> ndc(positions.size());
    for (std::size_t v = 0; v < positions.size(); ++v) {
        const glm::vec4 c = viewProj * glm::vec4(positions[v], 1.0f);
        ndc[v] = c.w > 0.0f ? glm::vec2(c) / c.w : glm::vec2(NAN);
    }
    std::vector<float> areas(indices.size() / 3);
    for (std::size_t t = 0; t < areas.size(); ++t) {
        const glm::vec2 p0 = ndc[indices[3 * t]];
        const glm::vec2 a = ndc[indices[3 * t + 1]] - p0, b = ndc[indices[3 * t + 2]] - p0;
        const float area = 0.125f * std::fabs(a.x * b.y - a.y * b.x) * whole;  // NDC spans 2 x 2
        areas[t] = std::isnan(area) ? whole : area;
    }
    return areas;
}

std::vector<IndexRange> splitByLift(std::span<const std::uint32_t> vertexBits, std::span<const std::uint32_t> indices,
                                    std::span<const IndexRange> ranges, std::span<const float> weights,
                                    double minWeight) {
    const IndexRange all{0, std::uint32_t(indices.size()), false};
    if (ranges.empty()) ranges = std::span<const IndexRange>(&all, 1);
    std::vector<IndexRange> out;
    auto append = [&](IndexRange r) {
        if (r.count == 0) return;
        IndexRange* last = out.empty() ? nullptr : &out.back();
        if (last && last->alpha == r.alpha && last->liftFree == r.liftFree && last->first + last->count == r.first)
            last->count += r.count;
        else
            out.push_back(r);
    };
    for (const IndexRange& range : ranges) {
        if (range.alpha) {
            append(range);
            continue;
        }
        // Runs of lift-free triangles long enough to be a draw of their own; the rest stays with the lift.
        std::uint32_t cursor = range.first;  // first index not yet appended
        std::uint32_t runStart = range.first;
        double runWeight = 0.0;
        bool inRun = false;
        const std::uint32_t end = range.first + range.count;
        auto closeRun = [&](std::uint32_t runEnd) {
            if (runWeight >= minWeight) {
                append(IndexRange{cursor, runStart - cursor, false, false});
                append(IndexRange{runStart, runEnd - runStart, false, true});
                cursor = runEnd;
            }
        };
        for (std::uint32_t t = range.first; t + 3 <= end; t += 3) {
            const bool free =
                liftFree(vertexBits[indices[t]] & vertexBits[indices[t + 1]] & vertexBits[indices[t + 2]]);
            if (free && !inRun) {
                runStart = t;
                runWeight = 0.0;
            }
            if (free) runWeight += double(weights[t / 3]);
            if (!free && inRun) closeRun(t);
            inRun = free;
        }
        if (inRun) closeRun(end);
        append(IndexRange{cursor, end - cursor, false, false});
    }
    return out;
}

}  // namespace shadowlab::raster
