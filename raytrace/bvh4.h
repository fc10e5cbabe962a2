// raytrace/bvh4.h: a 4-wide BVH collapsed from the binary SAH tree (bvh.h): 128-byte nodes whose
// four child boxes are tested at once with SSE, traversed nearest child first with a stack that
// skips entries farther than the current hit.
#pragma once

#include <cstdint>
#include <type_traits>
#include <vector>

#if defined(__SSE2__)
#include <emmintrin.h>
#endif

#include "raytrace/bvh.h"

namespace shadowlab::raytrace {

// Four children in structure-of-arrays order: bounds[r][c] is row r (lo x, lo y, lo z, hi x,
// hi y, hi z) of child c, so one row of the four children is one 16-byte SSE load. Unused
// children have empty boxes (lo = +inf, hi = −inf) that no ray enters.
struct alignas(64) Bvh4Node {
    float bounds[6][4];
    std::uint32_t ref[4];  // Bvh4::kEmpty, an interior node index, or a leaf (Bvh4::leafRef)
};
static_assert(sizeof(Bvh4Node) == 128, "Bvh4Node must stay two cache lines");

class Bvh4 {
public:
    // A child reference: node index (< 2^28), or a leaf with its primitive count (1..15) in the
    // top four bits and its first slot below, or kEmpty.
    static constexpr std::uint32_t kEmpty = 0xFFFFFFFFu;
    static constexpr std::uint32_t kMaxSlots = 1u << 28;
    // Every leaf starts on a multiple of four slots (padding slots hold kEmpty), so the
    // triangles of a leaf fill whole SSE packets (triangle4.h).
    static constexpr std::uint32_t kLeafAlign = 4;
    static constexpr std::uint32_t leafRef(std::uint32_t first, std::uint32_t count) {
        return (count << 28) | first;
    }
    static constexpr bool isLeaf(std::uint32_t ref) { return (ref >> 28) != 0; }
    static constexpr std::uint32_t leafCount(std::uint32_t ref) { return ref >> 28; }
    static constexpr std::uint32_t leafFirst(std::uint32_t ref) { return ref & (kMaxSlots - 1); }

    // Builds the binary SAH tree (Bvh::build) and collapses it. Throws std::length_error past
    // kMaxSlots primitives.
    static Bvh4 build(const std::vector<scene::Bounds>& primitiveBounds);
    // Collapses a binary tree: each 4-wide node takes a binary node's children and keeps
    // opening its interior child of largest surface area until it has four (the usual
    // collapse, e.g. Embree's BVHNBuilder; pbrt-v4 stays binary). The binary leaves are kept.
    static Bvh4 collapse(const Bvh& binary);

    const std::vector<Bvh4Node>& nodes() const { return nodes_; }
    // primitives()[slot] = primitive index, or kEmpty for padding; the slots of a leaf are
    // contiguous and start on a multiple of kLeafAlign. Differs from the binary tree's order.
    const std::vector<std::uint32_t>& primitives() const { return primitives_; }
    // The root: a node index, or a leaf when the whole tree is one leaf; kEmpty when empty.
    std::uint32_t root() const { return root_; }
    bool empty() const { return root_ == kEmpty; }
    // Memory held by nodes and the slot → primitive table.
    std::size_t bytes() const {
        return nodes_.capacity() * sizeof(Bvh4Node) + primitives_.capacity() * sizeof(std::uint32_t);
    }

    // Visits leaves nearest box first. `leaf(first, count, tMax)` tests slots first … first +
    // count − 1, shortens tMax to a hit and returns true when it hit. With anyHit the walk stops
    // at the first leaf that reports a hit. Box tests are those of intersectBounds (same
    // widening, same NaN rule), four at a time in float.
    template <typename Real, typename LeafFn>
    bool traverse(const Ray<Real>& ray, Real& tMax, bool anyHit, LeafFn&& leaf) const;

private:
    std::vector<Bvh4Node> nodes_;
    std::vector<std::uint32_t> primitives_;
    std::uint32_t root_ = kEmpty;
};

namespace detail {

// Box test of a node's four children, the same arithmetic as intersectBounds per child: near
// and far planes picked by the direction's sign, tFar widened by 1 + 2γ(3), NaN slab values
// ignored. Writes each child's entry distance and returns the mask of children entered.
template <typename Real>
struct ChildBoxTest {
    const Ray<Real>& ray;
    explicit ChildBoxTest(const Ray<Real>& r) : ray(r) {}
    int operator()(const Bvh4Node& n, Real tMax, Real tNear[4]) const {
        constexpr Real kWiden = 1 + 2 * gamma<Real>(3);
        int mask = 0;
        for (int c = 0; c < 4; ++c) {
            Real tn = 0, tf = tMax;
            for (int i = 0; i < 3; ++i) {
                const int nearRow = ray.dirIsNeg[i] ? 3 + i : i;
                const int farRow = ray.dirIsNeg[i] ? i : 3 + i;
                const Real a = (Real(n.bounds[nearRow][c]) - ray.o[i]) * ray.invDir[i];
                const Real b = (Real(n.bounds[farRow][c]) - ray.o[i]) * ray.invDir[i] * kWiden;
                tn = a > tn ? a : tn;
                tf = b < tf ? b : tf;
            }
            tNear[c] = tn;
            if (tn <= tf) mask |= 1 << c;
        }
        return mask;
    }
};

#if defined(__SSE2__)
// SSE2 is part of x86-64 itself, so this path needs no -m flag and runs on every x86-64 CPU.
// _mm_max_ps(a, b) is `a > b ? a : b` and _mm_min_ps(a, b) is `a < b ? a : b`, NaN in a giving
// b: exactly the scalar expressions above, so the float results are bit for bit the same.
template <>
struct ChildBoxTest<float> {
    __m128 o[3], inv[3], widen;
    int nearRow[3], farRow[3];
    explicit ChildBoxTest(const Ray<float>& r) {
        for (int i = 0; i < 3; ++i) {
            o[i] = _mm_set1_ps(r.o[i]);
            inv[i] = _mm_set1_ps(r.invDir[i]);
            nearRow[i] = r.dirIsNeg[i] ? 3 + i : i;
            farRow[i] = r.dirIsNeg[i] ? i : 3 + i;
        }
        widen = _mm_set1_ps(1 + 2 * gamma<float>(3));
    }
    int operator()(const Bvh4Node& n, float tMax, float tNear[4]) const {
        __m128 tn = _mm_setzero_ps(), tf = _mm_set1_ps(tMax);
        for (int i = 0; i < 3; ++i) {
            const __m128 a = _mm_mul_ps(_mm_sub_ps(_mm_load_ps(n.bounds[nearRow[i]]), o[i]), inv[i]);
            const __m128 b = _mm_mul_ps(
                _mm_mul_ps(_mm_sub_ps(_mm_load_ps(n.bounds[farRow[i]]), o[i]), inv[i]), widen);
            tn = _mm_max_ps(a, tn);
            tf = _mm_min_ps(b, tf);
        }
        _mm_storeu_ps(tNear, tn);
        return _mm_movemask_ps(_mm_cmple_ps(tn, tf));
    }
};
#endif

}  // namespace detail

#ifndef SL_UNSORTED
#define SL_UNSORTED 0
#endif
#ifdef SL_STATS
inline thread_local std::uint64_t gNodeVisits = 0, gLeafVisits = 0, gRays = 0;
#endif
inline constexpr bool kAnyHitUnsorted = SL_UNSORTED == 1;
template <typename Real, typename LeafFn>
bool Bvh4::traverse(const Ray<Real>& ray, Real& tMax, bool anyHit, LeafFn&& leaf) const {
    if (root_ == kEmpty) return false;
    // Each node pushes at most three entries and the binary build caps the depth at 80 levels
    // (tolerances.h), and a 4-wide level consumes at least one binary level: 3·80 + 1 < 256.
    constexpr int kStackSize = 256;
    struct Entry {
        std::uint32_t ref;
        Real tNear;  // entry distance when pushed: a later, nearer hit makes the entry useless
    };
    Entry stack[kStackSize];
    int top = 0;
    const detail::ChildBoxTest<Real> boxes(ray);
    std::uint32_t ref = root_;
    bool hit = false;
#ifdef SL_STATS
    ++gRays;
#endif
    for (;;) {
#ifdef SL_STATS
        ++(isLeaf(ref) ? gLeafVisits : gNodeVisits);
#endif
        if (isLeaf(ref)) {
            if (leaf(leafFirst(ref), leafCount(ref), tMax)) {
                hit = true;
                if (anyHit) return true;
            }
        } else {
            const Bvh4Node& node = nodes_[ref];
            Real tn[4];
            int mask = boxes(node, tMax, tn);
            if (mask != 0) {
                if ((mask & (mask - 1)) == 0) {  // one child: no stack traffic
                    ref = node.ref[__builtin_ctz(unsigned(mask))];
                    continue;
                }
                if (anyHit && kAnyHitUnsorted) {
                    int c = __builtin_ctz(unsigned(mask));
                    mask &= mask - 1;
                    const std::uint32_t first = node.ref[c];
                    while (mask != 0) {
                        c = __builtin_ctz(unsigned(mask));
                        mask &= mask - 1;
                        stack[top++] = Entry{node.ref[c], tn[c]};
#if defined(__SSE2__) && defined(SL_PREFETCH)
                        if (!isLeaf(node.ref[c])) {
                            const char* p = reinterpret_cast<const char*>(&nodes_[node.ref[c]]);
                            _mm_prefetch(p, _MM_HINT_T0);
                            _mm_prefetch(p + 64, _MM_HINT_T0);
                        }
#endif
                    }
                    ref = first;
                    continue;
                }
                // Sort the entered children by entry distance (at most four: insertion sort),
                // push all but the nearest farthest first, descend into the nearest.
                Entry e[4];
                int n = 0;
                while (mask != 0) {
                    const int c = __builtin_ctz(unsigned(mask));
                    mask &= mask - 1;
                    Entry x{node.ref[c], tn[c]};
                    int k = n++;
                    while (k > 0 && e[k - 1].tNear > x.tNear) {
                        e[k] = e[k - 1];
                        --k;
                    }
                    e[k] = x;
                }
                if (anyHit && SL_UNSORTED == 2) {
                    for (int k = 0; k < n - 1; ++k) stack[top++] = e[k];
                    ref = e[n - 1].ref;
                    continue;
                }
                for (int k = n - 1; k > 0; --k) stack[top++] = e[k];
                ref = e[0].ref;
                continue;
            }
        }
        // Pop, skipping entries that begin beyond the nearest hit so far. The box test would
        // cull them too: its tFar is at most tMax.
        for (;;) {
            if (top == 0) return hit;
            const Entry& e = stack[--top];
            if (e.tNear <= tMax) {
                ref = e.ref;
                break;
            }
        }
    }
}

}  // namespace shadowlab::raytrace
