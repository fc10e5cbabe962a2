// raytrace/bvh.cpp: binned-SAH BVH construction (Wald, "On fast Construction of SAH-based
// Bounding Volume Hierarchies", RT'07: bin centroids, sweep the bins, split at the cheapest
// boundary; pbrt-v4 BVHAggregate::buildRecursive does the same with 12 buckets).
#include "raytrace/bvh.h"

#include <algorithm>
#include <array>
#include <numeric>

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>
#include <tbb/parallel_invoke.h>
#include <tbb/parallel_reduce.h>

#include "raytrace/tolerances.h"

namespace shadowlab::raytrace {

namespace {

double surfaceArea(const scene::Bounds& b) {
    if (b.empty()) return 0.0;
    const scene::Vec3 e = b.extent();
    return 2.0 * (e.x * e.y + e.y * e.z + e.z * e.x);
}

// Bins of one range on all three axes; merged with `add` (bounds unions and counts are exact,
// so the merged bins do not depend on how the range was cut: the parallel build makes the
// same tree as the sequential one).
struct Bins {
    std::array<std::array<scene::Bounds, kBvhBins>, 3> bounds;
    std::array<std::array<std::uint32_t, kBvhBins>, 3> count{};
    void add(const Bins& o) {
        for (int a = 0; a < 3; ++a)
            for (int b = 0; b < kBvhBins; ++b) {
                bounds[a][b].extend(o.bounds[a][b]);
                count[a][b] += o.count[a][b];
            }
    }
};

struct RangeBounds {
    scene::Bounds all, centroids;
};

struct Builder {
    const std::vector<scene::Bounds>& bounds;
    std::vector<scene::Vec3> centroids;
    std::vector<std::uint32_t>& prims;

    RangeBounds rangeBounds(std::uint32_t begin, std::uint32_t end) const {
        auto body = [&](std::uint32_t b, std::uint32_t e, RangeBounds r) {
            for (std::uint32_t i = b; i < e; ++i) {
                r.all.extend(bounds[prims[i]]);
                r.centroids.extend(centroids[prims[i]]);
            }
            return r;
        };
        if (end - begin < kBvhParallelCount) return body(begin, end, {});
        return tbb::parallel_reduce(
            tbb::blocked_range<std::uint32_t>(begin, end, kBvhParallelGrain), RangeBounds{},
            [&](const tbb::blocked_range<std::uint32_t>& r, RangeBounds acc) { return body(r.begin(), r.end(), acc); },
            [](RangeBounds x, const RangeBounds& y) {
                x.all.extend(y.all);
                x.centroids.extend(y.centroids);
                return x;
            });
    }

    Bins bin(std::uint32_t begin, std::uint32_t end, const scene::Bounds& cb) const {
        const scene::Vec3 ext = cb.extent();
        auto body = [&](std::uint32_t b, std::uint32_t e, Bins& out) {
            for (std::uint32_t i = b; i < e; ++i) {
                const std::uint32_t p = prims[i];
                for (int axis = 0; axis < 3; ++axis) {
                    if (!(ext[axis] > 0)) continue;
                    const int k = binOf(centroids[p][axis], cb.min[axis], ext[axis]);
                    ++out.count[axis][k];
                    out.bounds[axis][k].extend(bounds[p]);
                }
            }
        };
        if (end - begin < kBvhParallelCount) {
            Bins out;
            body(begin, end, out);
            return out;
        }
        return tbb::parallel_reduce(
            tbb::blocked_range<std::uint32_t>(begin, end, kBvhParallelGrain), Bins{},
            [&](const tbb::blocked_range<std::uint32_t>& r, Bins acc) {
                body(r.begin(), r.end(), acc);
                return acc;
            },
            [](Bins x, const Bins& y) {
                x.add(y);
                return x;
            });
    }

    static std::uint32_t makeLeaf(std::vector<BvhNode>& nodes, std::uint32_t node, std::uint32_t begin,
                                  std::uint32_t end) {
        nodes[node].offset = begin;
        nodes[node].count = std::uint16_t(end - begin);
        nodes[node].axis = 0;
        return node;
    }

    // Appends the subtree over prims[begin, end) to `nodes` in depth-first order; interior
    // nodes' `offset` (second child) is an index into `nodes`. Returns the deepest level.
    int build(std::vector<BvhNode>& nodes, std::uint32_t begin, std::uint32_t end, int depth) {
        const std::uint32_t node = std::uint32_t(nodes.size());
        nodes.emplace_back();
        const RangeBounds rb = rangeBounds(begin, end);
        const scene::Bounds& all = rb.all;
        const scene::Bounds& cb = rb.centroids;
        for (int k = 0; k < 3; ++k) {
            // Outward rounding keeps the float box around the double (and float) geometry.
            nodes[node].lo[k] = roundDown<float>(all.min[k]);
            nodes[node].hi[k] = roundUp<float>(all.max[k]);
        }
        const std::uint32_t count = end - begin;
        if (count <= kBvhMinSplitCount) {
            makeLeaf(nodes, node, begin, end);
            return depth;
        }

        int bestAxis = -1;
        int bestBin = -1;
        double bestCost = std::numeric_limits<double>::infinity();
        const scene::Vec3 ext = cb.extent();
        if (depth < kBvhSahMaxDepth) {
            const Bins bins = bin(begin, end, cb);
            for (int axis = 0; axis < 3; ++axis) {
                if (!(ext[axis] > 0)) continue;
                const auto& binBounds = bins.bounds[axis];
                const auto& binCount = bins.count[axis];
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
        if (count <= kBvhMaxLeafCount && (bestAxis < 0 || splitCost >= blocks(count))) {
            makeLeaf(nodes, node, begin, end);
            return depth;
        }

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
        int deepest;
        std::uint32_t second;
        if (count >= kBvhParallelCount) {
            // Both halves at once: the second into its own vector, appended after the first
            // with its node indices shifted, so the layout is exactly the sequential one.
            std::vector<BvhNode> right;
            int dl = 0, dr = 0;
            tbb::parallel_invoke([&] { dl = build(nodes, begin, mid, depth + 1); },
                                 [&] {
                                     right.reserve(2 * std::size_t(end - mid));
                                     dr = build(right, mid, end, depth + 1);
                                 });
            second = std::uint32_t(nodes.size());
            for (BvhNode& n : right)
                if (n.count == 0) n.offset += second;
            nodes.insert(nodes.end(), right.begin(), right.end());
            deepest = std::max(dl, dr);
        } else {
            const int dl = build(nodes, begin, mid, depth + 1);
            second = std::uint32_t(nodes.size());
            deepest = std::max(dl, build(nodes, mid, end, depth + 1));
        }
        nodes[node].offset = second;
        nodes[node].count = 0;
        nodes[node].axis = std::uint8_t(axis);
        return deepest;
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
    Builder b{primitiveBounds, std::vector<scene::Vec3>(n), bvh.primitives_};
    tbb::parallel_for(tbb::blocked_range<std::size_t>(0, n, kBvhParallelGrain),
                      [&](const tbb::blocked_range<std::size_t>& r) {
                          for (std::size_t i = r.begin(); i != r.end(); ++i)
                              b.centroids[i] = primitiveBounds[i].center();
                      });
    bvh.depth_ = b.build(bvh.nodes_, 0, std::uint32_t(n), 0);
    bvh.nodes_.shrink_to_fit();
    return bvh;
}

}  // namespace shadowlab::raytrace
