// raytrace/bvh.h: a bounding volume hierarchy over one object's triangles (a BLAS), built with
// binned SAH and stored as compact 32-byte nodes in depth-first order.
#pragma once

#include <cstdint>
#include <vector>

#include "raytrace/intersect.h"
#include "scene/scene.h"

namespace shadowlab::raytrace {

// 32 bytes: two nodes per 64-byte cache line. Bounds are float, rounded outward from the
// double build bounds, so they contain the primitives in both precisions.
struct BvhNode {
    float lo[3];
    float hi[3];
    std::uint32_t offset;  // leaf: first index into Bvh::primitives; interior: second child
    std::uint16_t count;   // primitives in the leaf; 0 for an interior node (first child = next)
    std::uint8_t axis;     // interior: split axis, used to visit the near child first
    std::uint8_t pad;
};
static_assert(sizeof(BvhNode) == 32, "BvhNode must stay 32 bytes");

class Bvh {
public:
    // Binned SAH over primitive bounds (double). Empty input gives an empty tree.
    static Bvh build(const std::vector<scene::Bounds>& primitiveBounds);
    // The same SAH on float bounds (rounded outward), for the float tracer: about half the
    // build time, a slightly different tree (docs/performance.md, "Setup time").
    static Bvh buildFast(const std::vector<scene::Bounds>& primitiveBounds);
    // buildFast over triangles (positions[indices[3i + k]], the float vertices the tracer tests)
    // whose large, mostly empty boxes are first split into several tighter references
    // (pre-splitting, Karras & Aila 2013): a triangle may then sit in several leaves.
    // primitiveBounds[i] must contain triangle i.
    static Bvh buildFast(const std::vector<scene::Bounds>& primitiveBounds, const std::vector<Vec3T<float>>& positions,
                         const std::vector<std::uint32_t>& indices);

    const std::vector<BvhNode>& nodes() const { return nodes_; }
    const std::vector<std::uint32_t>& primitives() const { return primitives_; }
    bool empty() const { return nodes_.empty(); }
    int depth() const { return depth_; }

    // Visits leaves front to back along the ray's direction signs. `leaf(slot, tMax)` tests the
    // primitive primitives()[slot] (callers may keep data in slot order for locality),
    // shortening tMax on a hit and returning true. With anyHit the walk stops at the first hit.
    template <typename Real, typename LeafFn>
    bool traverse(const Ray<Real>& ray, Real& tMax, bool anyHit, LeafFn&& leaf) const;

private:
    friend struct FastBuildAccess;  // bvh.cpp: buildFast's common end
    std::vector<BvhNode> nodes_;
    std::vector<std::uint32_t> primitives_;
    int depth_ = 0;
};

template <typename Real, typename LeafFn>
bool Bvh::traverse(const Ray<Real>& ray, Real& tMax, bool anyHit, LeafFn&& leaf) const {
    if (nodes_.empty()) return false;
    constexpr int kStackSize = 128;  // build caps the depth well below this (see bvh.cpp)
    std::uint32_t stack[kStackSize];
    int top = 0;
    std::uint32_t current = 0;
    bool hit = false;
    for (;;) {
        const BvhNode& node = nodes_[current];
        if (intersectBounds(ray, node.lo, node.hi, tMax)) {
            if (node.count > 0) {
                for (std::uint32_t i = 0; i < node.count; ++i) {
                    if (leaf(node.offset + i, tMax)) {
                        hit = true;
                        if (anyHit) return true;
                    }
                }
                if (top == 0) break;
                current = stack[--top];
            } else if (ray.dirIsNeg[node.axis]) {
                // The second child holds the larger coordinates: visit it first.
                stack[top++] = current + 1;
                current = node.offset;
            } else {
                stack[top++] = node.offset;
                current = current + 1;
            }
        } else {
            if (top == 0) break;
            current = stack[--top];
        }
    }
    return hit;
}

}  // namespace shadowlab::raytrace
