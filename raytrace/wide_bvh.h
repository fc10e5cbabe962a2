// raytrace/wide_bvh.h: an N-wide BVH (N = 4 or 8) collapsed from the binary SAH tree (bvh.h):
// nodes hold N child boxes tested four at a time with SSE, traversed nearest child first for
// closest hit with a stack that skips entries beyond the current hit, stored order for any hit.
#pragma once

#include <cmath>
#include <cstdint>
#include <type_traits>
#include <vector>

#if defined(__SSE2__)
#include <emmintrin.h>
#include <xmmintrin.h>
#endif
#if defined(__x86_64__) && defined(__GNUC__)
#include <immintrin.h>
// An AVX 8-wide child-box test behind runtime dispatch (target attributes, no -m flag: the
// program still runs on plain x86-64; see docs/raytrace.md, "AVX").
#define SHADOWLAB_AVX_BOX_TEST 1
#endif

#include "raytrace/bvh.h"
#include "raytrace/tolerances.h"

namespace shadowlab::raytrace {

// N children in structure-of-arrays order: bounds[r][c] is row r (lo x, lo y, lo z, hi x,
// hi y, hi z) of child c, so a row of four children is one 16-byte SSE load. Unused children
// have empty boxes (lo = +inf, hi = −inf) that no ray enters.
template <int N>
struct alignas(64) WideNode {
    float bounds[6][N];
    std::uint32_t ref[N];  // kEmpty, an interior node index, or a leaf (WideBvh::leafRef)
};
static_assert(sizeof(WideNode<4>) == 128, "4-wide node: two cache lines");
static_assert(sizeof(WideNode<8>) == 256, "8-wide node: four cache lines");

// A child reference: node index (< 2^28), or a leaf with its primitive count (1..15) in the top
// four bits and its first slot below, or kEmpty.
struct WideRef {
    static constexpr std::uint32_t kEmpty = 0xFFFFFFFFu;
    static constexpr std::uint32_t kMaxSlots = 1u << 28;
    // Every leaf starts on a multiple of four slots (padding slots hold kEmpty), so the
    // triangles of a leaf fill whole SSE packets (triangle4.h).
    static constexpr std::uint32_t kLeafAlign = 4;
    static constexpr std::uint32_t leafRef(std::uint32_t first, std::uint32_t count) { return (count << 28) | first; }
    static constexpr bool isLeaf(std::uint32_t ref) { return (ref >> 28) != 0; }
    static constexpr std::uint32_t leafCount(std::uint32_t ref) { return ref >> 28; }
    static constexpr std::uint32_t leafFirst(std::uint32_t ref) { return ref & (kMaxSlots - 1); }
};

template <int N>
class WideBvh : public WideRef {
    static_assert(N == 4 || N == 8, "the SSE box test handles four children at a time");

public:
    using Node = WideNode<N>;
    static constexpr int kWidth = N;

    // Builds the binary SAH tree (Bvh::build) and collapses it. Throws std::length_error past
    // 2^26 primitives in one tree.
    static WideBvh build(const std::vector<scene::Bounds>& primitiveBounds);
    // Bvh::buildFast collapsed with smallFirst: the float tracer's tree.
    static WideBvh buildFast(const std::vector<scene::Bounds>& primitiveBounds);
    // Bvh::buildFast with pre-split triangles, collapsed with smallFirst.
    static WideBvh buildFast(const std::vector<scene::Bounds>& primitiveBounds,
                             const std::vector<Vec3T<float>>& positions, const std::vector<std::uint32_t>& indices);
    // Collapses a binary tree: each wide node takes a binary node's children and keeps opening
    // its interior child of largest surface area until it has N (the usual collapse, as
    // Embree's BVHNBuilder does; pbrt-v4 stays binary). The binary leaves are kept as they are.
    // Children are stored in the binary tree's left-to-right order; with smallFirst, a node whose
    // largest child box has over twice the surface area of its smallest stores them by increasing
    // surface area instead (the any-hit walk's order, docs/raytrace.md "Traversal"; closest hit
    // sorts by distance, so only its ties see the order, and those do not change its answers).
    static WideBvh collapse(const Bvh& binary, bool smallFirst = false);

    const std::vector<Node>& nodes() const { return nodes_; }
    // primitives()[slot] = primitive index, or kEmpty for padding; the slots of a leaf are
    // contiguous and start on a multiple of kLeafAlign. Differs from the binary tree's order.
    const std::vector<std::uint32_t>& primitives() const { return primitives_; }
    // The root: a node index, or a leaf when the whole tree is one leaf; kEmpty when empty.
    std::uint32_t root() const { return root_; }
    bool empty() const { return root_ == kEmpty; }
    // Memory held by nodes and the slot → primitive table.
    std::size_t bytes() const {
        return nodes_.capacity() * sizeof(Node) + primitives_.capacity() * sizeof(std::uint32_t);
    }

    // Visits leaves; `leaf(first, count, tMax)` tests slots first … first + count − 1, shortens
    // tMax to a hit and returns true when it hit. Closest hit (anyHit false) visits children
    // nearest entry first; with anyHit the walk stops at the first leaf that reports a hit and
    // children are taken in stored order (sorting cost more than it saved on shadow rays, see
    // docs/raytrace.md). Box tests are intersectBounds' (same widening, same NaN rule).
    template <typename Real, typename LeafFn>
    bool traverse(const Ray<Real>& ray, Real& tMax, bool anyHit, LeafFn&& leaf) const;
    // The same walk with a chosen child-box test (BoxTest(ray), box(node, tMax, tNear) → mask).
    template <typename BoxTest, typename Real, typename LeafFn>
    bool traverseWith(const Ray<Real>& ray, Real& tMax, bool anyHit, LeafFn&& leaf) const;

    // The float tracer's walk (tracer.cpp), the same closest-hit visits as traverseWith's with
    // a leaner loop: closest hit (kAnyHit false) takes one entered child without touching the
    // stack, two by one comparison, three or more by sorting them on the stack; any hit visits
    // the entered children in stored order, pushed with the box test's `pushRefs(node, mask,
    // out)` where it has one (one vector permute and store instead of a loop). `boxes(node,
    // tMax, tNear)` is a child-box test as above; `tNear` is 32-byte aligned.
    template <bool kAnyHit, typename BoxTest, typename LeafFn>
    bool walk(const BoxTest& boxes, float& tMax, LeafFn&& leaf) const;

private:
    std::vector<Node> nodes_;
    std::vector<std::uint32_t> primitives_;
    std::uint32_t root_ = kEmpty;
};

using Bvh4 = WideBvh<4>;
using Bvh8 = WideBvh<8>;
using Bvh4Node = WideNode<4>;
using Bvh8Node = WideNode<8>;

extern template class WideBvh<4>;
extern template class WideBvh<8>;

namespace detail {

// Box test of a node's children, the same arithmetic as intersectBounds per child: near and
// far planes picked by the direction's sign, tFar widened by 1 + 2γ(3), NaN slab values
// ignored. Writes each child's entry distance and returns the mask of children entered.
template <typename Real, int N>
struct ChildBoxTest {
    const Ray<Real>& ray;
    explicit ChildBoxTest(const Ray<Real>& r) : ray(r) {}
    int operator()(const WideNode<N>& n, Real tMax, Real tNear[N]) const {
        constexpr Real kWiden = 1 + 2 * gamma<Real>(3);
        int mask = 0;
        for (int c = 0; c < N; ++c) {
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
template <int N>
struct ChildBoxTest<float, N> {
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
    int operator()(const WideNode<N>& n, float tMax, float tNear[N]) const {
        int mask = 0;
        for (int q = 0; q < N; q += 4) {
            __m128 tn = _mm_setzero_ps(), tf = _mm_set1_ps(tMax);
            for (int i = 0; i < 3; ++i) {
                const __m128 a = _mm_mul_ps(_mm_sub_ps(_mm_load_ps(&n.bounds[nearRow[i]][q]), o[i]), inv[i]);
                const __m128 b =
                    _mm_mul_ps(_mm_mul_ps(_mm_sub_ps(_mm_load_ps(&n.bounds[farRow[i]][q]), o[i]), inv[i]), widen);
                tn = _mm_max_ps(a, tn);
                tf = _mm_min_ps(b, tf);
            }
            _mm_storeu_ps(tNear + q, tn);
            mask |= _mm_movemask_ps(_mm_cmple_ps(tn, tf)) << q;
        }
        return mask;
    }
};
#endif

#if defined(SHADOWLAB_AVX_BOX_TEST)
// All eight children in one AVX pass, the same operations in the same order as the SSE test
// (_mm256_max_ps / _mm256_min_ps have _mm_max_ps' NaN rule; no FMA: the target is "avx" only,
// so nothing can be contracted), hence bit for bit the same masks and entry distances. Usable
// only where the CPU has AVX (hasAvx()) and only from functions compiled for it.
struct ChildBoxTestAvx8 {
    __m256 o[3], inv[3], widen;
    int nearRow[3], farRow[3];
    __attribute__((target("avx"))) explicit ChildBoxTestAvx8(const Ray<float>& r) {
        for (int i = 0; i < 3; ++i) {
            o[i] = _mm256_set1_ps(r.o[i]);
            inv[i] = _mm256_set1_ps(r.invDir[i]);
            nearRow[i] = r.dirIsNeg[i] ? 3 + i : i;
            farRow[i] = r.dirIsNeg[i] ? i : 3 + i;
        }
        widen = _mm256_set1_ps(1 + 2 * gamma<float>(3));
    }
    __attribute__((target("avx"))) int operator()(const WideNode<8>& n, float tMax, float tNear[8]) const {
        __m256 tn = _mm256_setzero_ps(), tf = _mm256_set1_ps(tMax);
        for (int i = 0; i < 3; ++i) {
            const __m256 a = _mm256_mul_ps(_mm256_sub_ps(_mm256_load_ps(n.bounds[nearRow[i]]), o[i]), inv[i]);
            const __m256 b =
                _mm256_mul_ps(_mm256_mul_ps(_mm256_sub_ps(_mm256_load_ps(n.bounds[farRow[i]]), o[i]), inv[i]), widen);
            tn = _mm256_max_ps(a, tn);
            tf = _mm256_min_ps(b, tf);
        }
        _mm256_storeu_ps(tNear, tn);
        return _mm256_movemask_ps(_mm256_cmp_ps(tn, tf, _CMP_LE_OQ));
    }
};

// ChildBoxTestAvx8 for the rays of one octant (kOctant = octantOf(ray)): the near and far rows
// are constants, so the walk keeps no per-ray row indices in registers and loads each row at a
// fixed offset. The same operations in the same order: the same masks and entry distances.
template <int kOctant>
struct ChildBoxTestAvx8Octant {
    __m256 o[3], inv[3], widen;
    __attribute__((target("avx"))) explicit ChildBoxTestAvx8Octant(const Ray<float>& r) {
        for (int i = 0; i < 3; ++i) {
            o[i] = _mm256_set1_ps(r.o[i]);
            inv[i] = _mm256_set1_ps(r.invDir[i]);
        }
        widen = _mm256_set1_ps(1 + 2 * gamma<float>(3));
    }
    static constexpr int nearRow(int i) { return (kOctant >> i) & 1 ? 3 + i : i; }
    static constexpr int farRow(int i) { return (kOctant >> i) & 1 ? i : 3 + i; }
    __attribute__((target("avx"))) int operator()(const WideNode<8>& n, float tMax, float tNear[8]) const {
        __m256 tn = _mm256_setzero_ps(), tf = _mm256_set1_ps(tMax);
        const __m256 ax = _mm256_mul_ps(_mm256_sub_ps(_mm256_load_ps(n.bounds[nearRow(0)]), o[0]), inv[0]);
        const __m256 ay = _mm256_mul_ps(_mm256_sub_ps(_mm256_load_ps(n.bounds[nearRow(1)]), o[1]), inv[1]);
        const __m256 az = _mm256_mul_ps(_mm256_sub_ps(_mm256_load_ps(n.bounds[nearRow(2)]), o[2]), inv[2]);
        const __m256 bx =
            _mm256_mul_ps(_mm256_mul_ps(_mm256_sub_ps(_mm256_load_ps(n.bounds[farRow(0)]), o[0]), inv[0]), widen);
        const __m256 by =
            _mm256_mul_ps(_mm256_mul_ps(_mm256_sub_ps(_mm256_load_ps(n.bounds[farRow(1)]), o[1]), inv[1]), widen);
        const __m256 bz =
            _mm256_mul_ps(_mm256_mul_ps(_mm256_sub_ps(_mm256_load_ps(n.bounds[farRow(2)]), o[2]), inv[2]), widen);
        tn = _mm256_max_ps(ax, tn);
        tf = _mm256_min_ps(bx, tf);
        tn = _mm256_max_ps(ay, tn);
        tf = _mm256_min_ps(by, tf);
        tn = _mm256_max_ps(az, tn);
        tf = _mm256_min_ps(bz, tf);
        _mm256_store_ps(tNear, tn);
        return _mm256_movemask_ps(_mm256_cmp_ps(tn, tf, _CMP_LE_OQ));
    }
};

// The double reference's box test with AVX: four children per 256-bit pass of doubles (the
// float planes widened exactly by _mm256_cvtps_pd), the scalar ChildBoxTest<double, 8>'s
// operations in the same order (_mm256_max_pd / _mm256_min_pd have its NaN rule; target "avx"
// contracts no multiply-add), so the same masks and entry distances bit for bit, the same walk
// order, and the reference's hits (ties included) unchanged.
struct ChildBoxTestAvx8Double {
    __m256d o[3], inv[3], widen;
    int nearRow[3], farRow[3];
    __attribute__((target("avx"))) explicit ChildBoxTestAvx8Double(const Ray<double>& r) {
        for (int i = 0; i < 3; ++i) {
            o[i] = _mm256_set1_pd(r.o[i]);
            inv[i] = _mm256_set1_pd(r.invDir[i]);
            nearRow[i] = r.dirIsNeg[i] ? 3 + i : i;
            farRow[i] = r.dirIsNeg[i] ? i : 3 + i;
        }
        widen = _mm256_set1_pd(1 + 2 * gamma<double>(3));
    }
    __attribute__((target("avx"))) int operator()(const WideNode<8>& n, double tMax, double tNear[8]) const {
        int mask = 0;
        for (int q = 0; q < 8; q += 4) {
            __m256d tn = _mm256_setzero_pd(), tf = _mm256_set1_pd(tMax);
            for (int i = 0; i < 3; ++i) {
                const __m256d a =
                    _mm256_mul_pd(_mm256_sub_pd(_mm256_cvtps_pd(_mm_load_ps(&n.bounds[nearRow[i]][q])), o[i]), inv[i]);
                const __m256d b = _mm256_mul_pd(
                    _mm256_mul_pd(_mm256_sub_pd(_mm256_cvtps_pd(_mm_load_ps(&n.bounds[farRow[i]][q])), o[i]), inv[i]),
                    widen);
                tn = _mm256_max_pd(a, tn);
                tf = _mm256_min_pd(b, tf);
            }
            _mm256_storeu_pd(tNear + q, tn);
            mask |= _mm256_movemask_pd(_mm256_cmp_pd(tn, tf, _CMP_LE_OQ)) << q;
        }
        return mask;
    }
};

// Byte b of kCompressLanes[mask] is the index of mask's b-th set bit counted from the highest
// (bytes past its bit count 0): the permutation that packs a node's entered children to the
// front, last stored child first, so that a stack popping from the top gives them in stored order.
inline constexpr auto kCompressLanes = [] {
    struct Table {
        std::uint64_t lanes[256];
    } t{};
    for (unsigned m = 0; m < 256; ++m) {
        int b = 0;
        for (int c = 7; c >= 0; --c)
            if (m >> c & 1) t.lanes[m] |= std::uint64_t(c) << (8 * b++);
    }
    return t;
}();

// The any-hit walk's push (WideBvh::walk): the refs of the children in `mask`, last stored first,
// written to out[0 .. count) in one permute and one store, no loop or branch per child; the store
// writes eight lanes, so `out` has room for eight. Returns the count.
__attribute__((target("avx2"))) inline unsigned pushRefsAvx2(const WideNode<8>& n, unsigned mask, std::uint32_t* out) {
    const __m256i lanes =
        _mm256_cvtepu8_epi32(_mm_loadl_epi64(reinterpret_cast<const __m128i*>(&kCompressLanes.lanes[mask])));
    const __m256i refs = _mm256_load_si256(reinterpret_cast<const __m256i*>(n.ref));
    _mm256_storeu_si256(reinterpret_cast<__m256i*>(out), _mm256_permutevar8x32_epi32(refs, lanes));
    return unsigned(__builtin_popcount(mask));
}

// The box test of the float walk on CPUs with AVX2, for rays of one octant whose inverse
// direction is finite in all three components, also times the widening factor
// (avx2BoxTestApplies: no slab value can be NaN). The far distances use
// the inverse direction times the widening factor, rounded once per ray (the same four roundings
// as intersectBounds' (b − o)·inv·widen, so the same error bound), and the minimum and maximum
// are taken on the floats' bit patterns as 32-bit integers, one cycle each instead of four:
// the maximum with +0 is exact on floats ≥ 0 and ignores negative ones (as the float max with
// 0 does); the minimum is exact when all far distances are ≥ +0 and negative as soon as one is
// negative or −0, and the comparison is made on the integers too, so such a child is not
// entered: its far plane lies at or behind the origin, where no hit with t > 0 can be.
template <int kOctant>
struct ChildBoxTestAvx2Octant {
    __m256 o[3], inv[3], invFar[3];
    __attribute__((target("avx2"))) explicit ChildBoxTestAvx2Octant(const Ray<float>& r) {
        const float widen = 1 + 2 * gamma<float>(3);
        for (int i = 0; i < 3; ++i) {
            o[i] = _mm256_set1_ps(r.o[i]);
            inv[i] = _mm256_set1_ps(r.invDir[i]);
            invFar[i] = _mm256_set1_ps(r.invDir[i] * widen);
        }
    }
    static constexpr int nearRow(int i) { return (kOctant >> i) & 1 ? 3 + i : i; }
    static constexpr int farRow(int i) { return (kOctant >> i) & 1 ? i : 3 + i; }
    __attribute__((target("avx2"))) int operator()(const WideNode<8>& n, float tMax, float tNear[8]) const {
#define SHADOWLAB_SLAB(row, i, scale) \
    _mm256_castps_si256(_mm256_mul_ps(_mm256_sub_ps(_mm256_load_ps(n.bounds[row]), o[i]), scale))
        const __m256i ax = SHADOWLAB_SLAB(nearRow(0), 0, inv[0]), ay = SHADOWLAB_SLAB(nearRow(1), 1, inv[1]),
                      az = SHADOWLAB_SLAB(nearRow(2), 2, inv[2]);
        const __m256i bx = SHADOWLAB_SLAB(farRow(0), 0, invFar[0]), by = SHADOWLAB_SLAB(farRow(1), 1, invFar[1]),
                      bz = SHADOWLAB_SLAB(farRow(2), 2, invFar[2]);
#undef SHADOWLAB_SLAB
        const __m256i tn = _mm256_max_epi32(_mm256_max_epi32(ax, ay), _mm256_max_epi32(az, _mm256_setzero_si256()));
        const __m256i tf =
            _mm256_min_epi32(_mm256_min_epi32(bx, by), _mm256_min_epi32(bz, _mm256_castps_si256(_mm256_set1_ps(tMax))));
        _mm256_store_si256(reinterpret_cast<__m256i*>(tNear), tn);
        return ~_mm256_movemask_ps(_mm256_castsi256_ps(_mm256_cmpgt_epi32(tn, tf))) & 0xFF;
    }
    __attribute__((target("avx2"))) unsigned pushRefs(const WideNode<8>& n, unsigned mask, std::uint32_t* out) const {
        return pushRefsAvx2(n, mask, out);
    }
};

#endif

// Whether ChildBoxTestAvx2Octant may test this ray: its inverse direction, and that times the
// widening factor, finite in all three components, so that no slab value can be NaN (0·inf).
inline bool avx2BoxTestApplies(const Ray<float>& r) {
    const float widen = 1 + 2 * gamma<float>(3);
    return std::isfinite(r.invDir.x * widen) && std::isfinite(r.invDir.y * widen) && std::isfinite(r.invDir.z * widen);
}

// The octant of a ray's direction: bit i set when its component i is negative (dirIsNeg).
template <typename Real>
inline int octantOf(const Ray<Real>& r) {
    return r.dirIsNeg[0] | r.dirIsNeg[1] << 1 | r.dirIsNeg[2] << 2;
}

// Whether this CPU runs the AVX box test (checked once), and whether the tracer uses it:
// on by default where available; tests and the bench switch it off to compare with SSE.
bool hasAvx();
bool useAvx();
void setUseAvx(bool on);  // no effect (stays off) without AVX
// The same for the AVX2 box test (ChildBoxTestAvx2Octant), used where useAvx() is on too.
bool hasAvx2();
bool useAvx2();
void setUseAvx2(bool on);  // no effect (stays off) without AVX2

// Whether float tracers build their meshes with Bvh::buildFast (on by default) or with the
// double build the reference uses; the bench switches it to measure what the tree is worth.
bool fastFloatBuild();
void setFastFloatBuild(bool on);

}  // namespace detail

template <int N>
template <typename Real, typename LeafFn>
bool WideBvh<N>::traverse(const Ray<Real>& ray, Real& tMax, bool anyHit, LeafFn&& leaf) const {
    return traverseWith<detail::ChildBoxTest<Real, N>>(ray, tMax, anyHit, leaf);
}

template <int N>
template <typename BoxTest, typename Real, typename LeafFn>
bool WideBvh<N>::traverseWith(const Ray<Real>& ray, Real& tMax, bool anyHit, LeafFn&& leaf) const {
    if (root_ == kEmpty) return false;
    // Each node pushes at most N − 1 entries; the binary build caps the depth at 80 levels
    // (tolerances.h) and a wide level consumes at least one binary level: (N − 1)·80 + 1 fits.
    constexpr int kStackSize = 82 * N;
    struct Entry {
        std::uint32_t ref;
        Real tNear;  // entry distance when pushed: a later, nearer hit makes the entry useless
    };
    Entry stack[kStackSize];
    int top = 0;
    const BoxTest boxes(ray);
    std::uint32_t ref = root_;
    bool hit = false;
    for (;;) {
        if (isLeaf(ref)) {
            if (leaf(leafFirst(ref), leafCount(ref), tMax)) {
                hit = true;
                if (anyHit) return true;
            }
        } else {
            const Node& node = nodes_[ref];
            Real tn[N];
            int mask = boxes(node, tMax, tn);
            if (mask != 0) {
                int c = __builtin_ctz(unsigned(mask));
                mask &= mask - 1;
                if (mask == 0) {  // one child: no stack traffic
                    ref = node.ref[c];
                    continue;
                }
                if (anyHit) {
                    // Any hit: the first child in stored order, the others pushed. Their node
                    // lines are prefetched now, as they will be read soon.
                    ref = node.ref[c];
                    while (mask != 0) {
                        c = __builtin_ctz(unsigned(mask));
                        mask &= mask - 1;
                        stack[top++] = Entry{node.ref[c], tn[c]};
#if defined(__SSE2__)
                        if (!isLeaf(node.ref[c])) {
                            const char* p = reinterpret_cast<const char*>(&nodes_[node.ref[c]]);
                            for (std::size_t line = 0; line < sizeof(Node); line += 64)
                                _mm_prefetch(p + line, _MM_HINT_T0);
                        }
#endif
                    }
                    continue;
                }
                // Closest hit: sort the entered children by entry distance (insertion sort of
                // at most N), push all but the nearest farthest first, descend into the nearest.
                Entry e[N];
                e[0] = Entry{node.ref[c], tn[c]};
                int n = 1;
                while (mask != 0) {
                    c = __builtin_ctz(unsigned(mask));
                    mask &= mask - 1;
                    const Entry x{node.ref[c], tn[c]};
                    int k = n++;
                    while (k > 0 && e[k - 1].tNear > x.tNear) {
                        e[k] = e[k - 1];
                        --k;
                    }
                    e[k] = x;
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

template <int N>
template <bool kAnyHit, typename BoxTest, typename LeafFn>
bool WideBvh<N>::walk(const BoxTest& boxes, float& tMax, LeafFn&& leaf) const {
    std::uint32_t ref = root_;
    if (ref == kEmpty) return false;
    const Node* nodes = nodes_.data();
    // As traverseWith: at most N − 1 entries per level of at most 80, plus a node's N at once.
    // (Plus N: a box test's pushRefs stores N lanes at once.)
    constexpr int kStackSize = 82 * N + N;
    std::uint32_t stackRef[kStackSize];
    float stackNear[kStackSize];
    int top = 0;
    bool hit = false;
    // Boxes are culled a little beyond the best hit (tolerances.h, kTieCullSlack): a box whose
    // computed entry rounds just past a hit's computed t may hold a triangle tied with it.
    float cull = tMax * kTieCullSlack;
    for (;;) {
        bool leafReached = true;
        while (!isLeaf(ref)) {
            const Node& node = nodes[ref];
#if defined(__SSE2__)
            // The child refs' line, fetched beside the bounds': the mask picks a ref from it next.
            _mm_prefetch(reinterpret_cast<const char*>(node.ref), _MM_HINT_T0);
#endif
            alignas(32) float tn[N];
            unsigned mask = unsigned(boxes(node, cull, tn));
            if (mask == 0) {
                leafReached = false;
                break;
            }
            int c = __builtin_ctz(mask);
            mask &= mask - 1;
            if (mask == 0) {  // one child: no stack traffic
                ref = node.ref[c];
                continue;
            }
            if constexpr (kAnyHit && requires { boxes.pushRefs(node, mask, stackRef); }) {
                // Any hit with a vector push: the first entered child in stored order next, the
                // others pushed to be popped in stored order, without a loop over them.
                top += int(boxes.pushRefs(node, mask, stackRef + top));
                ref = node.ref[c];
                continue;
            }
            if constexpr (kAnyHit) {
                // The first entered child in stored order next, the others pushed to be popped in
                // stored order; their node lines are prefetched, as they will be read soon.
                ref = node.ref[c];
                do {
                    c = 31 - __builtin_clz(mask);  // last stored first: popped in stored order
                    mask &= ~(1u << c);
                    stackRef[top++] = node.ref[c];
#if defined(__SSE2__)
                    if (!isLeaf(node.ref[c])) {
                        const char* p = reinterpret_cast<const char*>(&nodes[node.ref[c]]);
                        for (std::size_t line = 0; line < sizeof(Node); line += 64) _mm_prefetch(p + line, _MM_HINT_T0);
                    }
#endif
                } while (mask != 0);
                continue;
            } else {
                const int c2 = __builtin_ctz(mask);
                mask &= mask - 1;
                if (mask == 0) {  // two children: the nearer next, the other pushed
                    const bool swap = tn[c2] < tn[c];
                    const int nearC = swap ? c2 : c, farC = swap ? c : c2;
                    stackRef[top] = node.ref[farC];
                    stackNear[top] = tn[farC];
                    ++top;
                    ref = node.ref[nearC];
                    continue;
                }
                // Three or more: pushed, then that part of the stack sorted by entry distance,
                // farthest at the bottom (insertion sort of at most N); the nearest is taken.
                const int base = top;
                stackRef[top] = node.ref[c];
                stackNear[top] = tn[c];
                ++top;
                int k = top++;
                // Insert c2 then the rest, keeping [base, top) in decreasing tNear.
                auto insert = [&](int at, int child) {
                    const float d = tn[child];
                    const std::uint32_t r = node.ref[child];
                    while (at > base && stackNear[at - 1] < d) {
                        stackNear[at] = stackNear[at - 1];
                        stackRef[at] = stackRef[at - 1];
                        --at;
                    }
                    stackNear[at] = d;
                    stackRef[at] = r;
                };
                insert(k, c2);
                do {
                    c = __builtin_ctz(mask);
                    mask &= mask - 1;
                    insert(top++, c);
                } while (mask != 0);
                ref = stackRef[--top];
                continue;
            }
        }
        if (leafReached && leaf(leafFirst(ref), leafCount(ref), tMax)) {
            hit = true;
            if constexpr (kAnyHit) return true;
            cull = tMax * kTieCullSlack;
        }
        if constexpr (kAnyHit) {
            // Any hit stops at its first hit, so the cull distance never shrinks and every
            // pushed child (entered: its entry ≤ its exit ≤ cull) is still to be visited.
            if (top == 0) return false;
            ref = stackRef[--top];
            continue;
        }
        // Pop, skipping entries that begin beyond the nearest hit so far.
        for (;;) {
            if (top == 0) return hit;
            --top;
            if (stackNear[top] <= cull) {
                ref = stackRef[top];
                break;
            }
        }
    }
}

}  // namespace shadowlab::raytrace
