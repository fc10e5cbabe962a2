// raytrace/bvh.cpp: binned-SAH BVH construction (Wald, "On fast Construction of SAH-based
// Bounding Volume Hierarchies", RT'07: bin centroids, sweep the bins, split at the cheapest
// boundary; pbrt-v4 BVHAggregate::buildRecursive does the same with 12 buckets).
#include "raytrace/bvh.h"

#include <algorithm>
#include <array>
#include <numeric>

#include "raytrace/tolerances.h"

namespace shadowlab::raytrace {

namespace {

double surfaceArea(const scene::Bounds& b) {
    if (b.empty()) return 0.0;
    const scene::Vec3 e = b.extent();
    return 2.0 * (e.x * e.y + e.y * e.z + e.z * e.x);
}

struct Builder {
    const std::vector<scene::Bounds>& bounds;
    std::vector<scene::Vec3> centroids;
    std::vector<std::uint32_t>& prims;
    std::vector<BvhNode>& nodes;
    int maxDepth = 0;

    std::uint32_t makeLeaf(std::uint32_t node, std::uint32_t begin, std::uint32_t end) {
        nodes[node].offset = begin;
        nodes[node].count = std::uint16_t(end - begin);
        nodes[node].axis = 0;
        return node;
    }

    std::uint32_t build(std::uint32_t begin, std::uint32_t end, int depth) {
        maxDepth = std::max(maxDepth, depth);
        const std::uint32_t node = std::uint32_t(nodes.size());
        nodes.emplace_back();
        scene::Bounds all, cb;
        for (std::uint32_t i = begin; i < end; ++i) {
            all.extend(bounds[prims[i]]);
            cb.extend(centroids[prims[i]]);
        }
        for (int k = 0; k < 3; ++k) {
            // Outward rounding keeps the float box around the double (and float) geometry.
            nodes[node].lo[k] = roundDown<float>(all.min[k]);
            nodes[node].hi[k] = roundUp<float>(all.max[k]);
        }
        const std::uint32_t count = end - begin;
        if (count <= kBvhMinSplitCount) return makeLeaf(node, begin, end);

        int bestAxis = -1;
        int bestBin = -1;
        double bestCost = std::numeric_limits<double>::infinity();
        const scene::Vec3 ext = cb.extent();
        if (depth < kBvhSahMaxDepth) {
            for (int axis = 0; axis < 3; ++axis) {
                if (!(ext[axis] > 0)) continue;
                std::array<scene::Bounds, kBvhBins> binBounds;
                std::array<std::uint32_t, kBvhBins> binCount{};
                for (std::uint32_t i = begin; i < end; ++i) {
                    const int b = binOf(centroids[prims[i]][axis], cb.min[axis], ext[axis]);
                    ++binCount[b];
                    binBounds[b].extend(bounds[prims[i]]);
                }
                // Sweep from the right to get every right-hand side's area and count.
                std::array<double, kBvhBins> rightArea{};
                std::array<std::uint32_t, kBvhBins> rightCount{};
                scene::Bounds acc;
                std::uint32_t n = 0;
                for (int b = kBvhBins - 1; b > 0; --b) {
                    acc.extend(binBounds[b]);
                    n += binCount[b];
                    rightArea[b] = surfaceArea(acc);
                    rightCount[b] = n;
                }
                scene::Bounds left;
                std::uint32_t nl = 0;
                for (int b = 0; b < kBvhBins - 1; ++b) {
                    left.extend(binBounds[b]);
                    nl += binCount[b];
                    if (nl == 0 || rightCount[b + 1] == 0) continue;
                    const double cost =
                        surfaceArea(left) * blocks(nl) + rightArea[b + 1] * blocks(rightCount[b + 1]);
                    if (cost < bestCost) {
                        bestCost = cost;
                        bestAxis = axis;
                        bestBin = b;
                    }
                }
            }
        }
        const double area = surfaceArea(all);
        // SAH in units of one block test; traversal of a node costs kBvhTraversalCost.
        const double splitCost =
            area > 0 ? kBvhTraversalCost + bestCost / area : std::numeric_limits<double>::infinity();
        if (count <= kBvhMaxLeafCount && (bestAxis < 0 || splitCost >= blocks(count)))
            return makeLeaf(node, begin, end);

        std::uint32_t mid;
        int axis;
        if (bestAxis >= 0) {
            axis = bestAxis;
            auto* midPtr = std::partition(
                prims.data() + begin, prims.data() + end, [&](std::uint32_t p) {
                    return binOf(centroids[p][axis], cb.min[axis], ext[axis]) <= bestBin;
                });
            mid = std::uint32_t(midPtr - prims.data());
        } else {
            // No usable SAH split (coincident centroids or too deep): halve by count so the
            // tree stays shallow and leaves stay small.
            axis = ext.x >= ext.y && ext.x >= ext.z ? 0 : (ext.y >= ext.z ? 1 : 2);
            mid = begin + count / 2;
            std::nth_element(prims.data() + begin, prims.data() + mid, prims.data() + end,
                             [&](std::uint32_t a, std::uint32_t b) {
                                 return centroids[a][axis] < centroids[b][axis];
                             });
        }
        build(begin, mid, depth + 1);
        const std::uint32_t second = build(mid, end, depth + 1);
        nodes[node].offset = second;
        nodes[node].count = 0;
        nodes[node].axis = std::uint8_t(axis);
        return node;
    }

    // Leaves are tested kBvhLeafBlock triangles at a time (triangle4.h), so a leaf of n costs
    // ⌈n / block⌉ tests: Embree's SAH counts primitives in blocks the same way.
    static double blocks(std::uint32_t n) {
        return double((n + kBvhLeafBlock - 1) / kBvhLeafBlock);
    }

    static int binOf(double c, double lo, double extent) {
        const int b = int(kBvhBins * ((c - lo) / extent));
        return std::clamp(b, 0, kBvhBins - 1);
    }
};

}  // namespace

Bvh Bvh::build(const std::vector<scene::Bounds>& primitiveBounds) {
    Bvh bvh;
    const std::size_t n = primitiveBounds.size();
    if (n == 0) return bvh;
    bvh.primitives_.resize(n);
    std::iota(bvh.primitives_.begin(), bvh.primitives_.end(), 0u);
    bvh.nodes_.reserve(2 * n);
    Builder b{primitiveBounds, {}, bvh.primitives_, bvh.nodes_};
    b.centroids.reserve(n);
    for (const scene::Bounds& pb : primitiveBounds) b.centroids.push_back(pb.center());
    b.build(0, std::uint32_t(n), 0);
    bvh.depth_ = b.maxDepth;
    bvh.nodes_.shrink_to_fit();
    return bvh;
}

}  // namespace shadowlab::raytrace
