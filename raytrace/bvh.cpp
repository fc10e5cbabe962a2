// raytrace/bvh.cpp: binned-SAH BVH construction (Wald, "On fast Construction of SAH-based
// Bounding Volume Hierarchies", RT'07: bin centroids, sweep the bins, split at the cheapest
// boundary; pbrt-v4 BVHAggregate::buildRecursive does the same with 12 buckets).
#include "raytrace/bvh.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <cstring>
#include <limits>
#include <memory>
#include <numeric>

// SSE2 intrinsics: baseline on x86-64, the only target the builders are written for.
#include <emmintrin.h>
#include <xmmintrin.h>

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

// A primitive's double bounds and its index, 64 bytes, moved by the partitions themselves so
// that every pass over a range reads memory in order (an index into the bounds would gather
// 48 scattered bytes per primitive). Lanes: lo x, y, z, index; hi x, y, z, unused. The bounds
// are extended with SSE2 min/max, which pick exactly what glm::min / glm::max pick (the
// accumulator unless the new value is smaller / larger), so nothing differs from scene::Bounds.
struct alignas(64) PrimRef {
    double lo[4];
    double hi[4];
    std::uint32_t index() const { return std::uint32_t(lo[3]); }
    double centroid(int axis) const { return 0.5 * (lo[axis] + hi[axis]); }  // Bounds::center()
};
static_assert(sizeof(PrimRef) == 64, "PrimRef: one cache line");

// Four-lane double box (lanes 0..2 used), the same min/max rule as scene::Bounds.
struct Box4 {
    __m128d lo01 = _mm_set1_pd(std::numeric_limits<double>::infinity()), lo2 = lo01;
    __m128d hi01 = _mm_set1_pd(-std::numeric_limits<double>::infinity()), hi2 = hi01;
    void extend(const PrimRef& r) {
        // _mm_min_pd(new, acc) = new < acc ? new : acc = glm::min(acc, new); same for max.
        lo01 = _mm_min_pd(_mm_load_pd(r.lo), lo01);
        lo2 = _mm_min_pd(_mm_load_pd(r.lo + 2), lo2);
        hi01 = _mm_max_pd(_mm_load_pd(r.hi), hi01);
        hi2 = _mm_max_pd(_mm_load_pd(r.hi + 2), hi2);
    }
    void extend(const Box4& o) {
        // For an empty o (lo = +inf, hi = −inf) this changes nothing, as Bounds::extend skips it.
        lo01 = _mm_min_pd(o.lo01, lo01);
        lo2 = _mm_min_pd(o.lo2, lo2);
        hi01 = _mm_max_pd(o.hi01, hi01);
        hi2 = _mm_max_pd(o.hi2, hi2);
    }
    // surfaceArea(bounds()), the same arithmetic.
    double area() const {
        alignas(16) double l[4], h[4];
        _mm_store_pd(l, lo01);
        _mm_store_pd(l + 2, lo2);
        _mm_store_pd(h, hi01);
        _mm_store_pd(h + 2, hi2);
        if (!(l[0] <= h[0])) return 0.0;
        const double x = h[0] - l[0], y = h[1] - l[1], z = h[2] - l[2];
        return 2.0 * (x * y + y * z + z * x);
    }
    scene::Bounds bounds() const {
        alignas(16) double l[4], h[4];
        _mm_store_pd(l, lo01);
        _mm_store_pd(l + 2, lo2);
        _mm_store_pd(h, hi01);
        _mm_store_pd(h + 2, hi2);
        scene::Bounds b;
        b.min = scene::Vec3(l[0], l[1], l[2]);
        b.max = scene::Vec3(h[0], h[1], h[2]);
        return b;
    }
};

// Bins of one range on all three axes; merged with `add` (bounds unions and counts are exact,
// so the merged bins do not depend on how the range was cut: the parallel build makes the
// same tree as the sequential one).
struct Bins {
    std::array<std::array<Box4, kBvhBins>, 3> bounds;
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
    std::vector<PrimRef>& refs;

    scene::Bounds centroidBounds(std::uint32_t begin, std::uint32_t end) const {
        auto body = [&](std::uint32_t b, std::uint32_t e, scene::Bounds c) {
            for (std::uint32_t i = b; i < e; ++i)
                c.extend(scene::Vec3(refs[i].centroid(0), refs[i].centroid(1), refs[i].centroid(2)));
            return c;
        };
        if (end - begin < kBvhParallelCount) return body(begin, end, {});
        return tbb::parallel_reduce(
            tbb::blocked_range<std::uint32_t>(begin, end, kBvhParallelGrain), scene::Bounds{},
            [&](const tbb::blocked_range<std::uint32_t>& r, scene::Bounds acc) {
                return body(r.begin(), r.end(), acc);
            },
            [](scene::Bounds x, const scene::Bounds& y) {
                x.extend(y);
                return x;
            });
    }

    RangeBounds rangeBounds(std::uint32_t begin, std::uint32_t end) const {
        auto body = [&](std::uint32_t b, std::uint32_t e, Box4 r) {
            for (std::uint32_t i = b; i < e; ++i) r.extend(refs[i]);
            return r;
        };
        Box4 all;
        if (end - begin < kBvhParallelCount) {
            all = body(begin, end, {});
        } else {
            all = tbb::parallel_reduce(
                tbb::blocked_range<std::uint32_t>(begin, end, kBvhParallelGrain), Box4{},
                [&](const tbb::blocked_range<std::uint32_t>& r, Box4 acc) { return body(r.begin(), r.end(), acc); },
                [](Box4 x, const Box4& y) {
                    x.extend(y);
                    return x;
                });
        }
        return {all.bounds(), centroidBounds(begin, end)};
    }

    void bin(std::uint32_t begin, std::uint32_t end, const scene::Bounds& cb, Bins& result) const {
        const scene::Vec3 ext = cb.extent();
        const __m128d lo01 = _mm_set_pd(cb.min.y, cb.min.x), lo2 = _mm_set_sd(cb.min.z);
        const __m128d ext01 = _mm_set_pd(ext.y, ext.x), ext2 = _mm_set_pd(1.0, ext.z);
        const __m128d half = _mm_set1_pd(0.5), bins = _mm_set1_pd(double(kBvhBins));
        const __m128i zero = _mm_setzero_si128(), last = _mm_set1_epi32(kBvhBins - 1);
        auto body = [&](std::uint32_t b, std::uint32_t e, Bins& out) {
            for (std::uint32_t i = b; i < e; ++i) {
                const PrimRef& r = refs[i];
                // binOf on all three axes at once: the same double operations in the same
                // order (0.5·(lo + hi), − min, ÷ extent, × bins, truncate, clamp). An axis
                // of zero extent gives garbage bins, never read (the sweep skips that axis).
                const __m128d c01 = _mm_mul_pd(half, _mm_add_pd(_mm_load_pd(r.lo), _mm_load_pd(r.hi)));
                const __m128d c2 = _mm_mul_pd(half, _mm_add_pd(_mm_load_pd(r.lo + 2), _mm_load_pd(r.hi + 2)));
                const __m128d f01 = _mm_mul_pd(bins, _mm_div_pd(_mm_sub_pd(c01, lo01), ext01));
                const __m128d f2 = _mm_mul_pd(bins, _mm_div_pd(_mm_sub_pd(c2, lo2), ext2));
                __m128i k = _mm_unpacklo_epi64(_mm_cvttpd_epi32(f01), _mm_cvttpd_epi32(f2));
                // Clamp to [0, bins − 1] (SSE2 has no 32-bit min/max: compare and select).
                k = _mm_andnot_si128(_mm_cmplt_epi32(k, zero), k);
                const __m128i over = _mm_cmpgt_epi32(k, last);
                k = _mm_or_si128(_mm_and_si128(over, last), _mm_andnot_si128(over, k));
                alignas(16) std::int32_t kk[4];
                _mm_store_si128(reinterpret_cast<__m128i*>(kk), k);
                for (int axis = 0; axis < 3; ++axis) {
                    ++out.count[axis][kk[axis]];
                    out.bounds[axis][kk[axis]].extend(r);
                }
            }
        };
        if (end - begin < kBvhParallelCount) {
            body(begin, end, result);
            return;
        }
        result = tbb::parallel_reduce(
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

    // std::partition as libstdc++ implements it for bidirectional iterators (the same
    // predicate calls and swaps, so the same order of primitives as the sequential build has
    // always made), each primitive's centroid added to its side's bounds as it is classified:
    // min and max of the same numbers, so the same bounds as a pass over each side afterwards
    // (the sign of a zero may differ, which moves no centroid to another bin).
    template <typename Pred>
    std::uint32_t partition(std::uint32_t begin, std::uint32_t end, Pred pred, scene::Bounds& left,
                            scene::Bounds& right) {
        PrimRef* first = refs.data() + begin;
        PrimRef* last = refs.data() + end;
        auto centroid = [](const PrimRef& r) { return scene::Vec3(r.centroid(0), r.centroid(1), r.centroid(2)); };
        for (;;) {
            for (;;) {
                if (first == last) return std::uint32_t(first - refs.data());
                if (!pred(*first)) break;
                left.extend(centroid(*first));
                ++first;
            }
            --last;
            for (;;) {
                if (first == last) {
                    right.extend(centroid(*first));  // classified false above
                    return std::uint32_t(first - refs.data());
                }
                if (pred(*last)) break;
                right.extend(centroid(*last));
                --last;
            }
            right.extend(centroid(*first));
            left.extend(centroid(*last));
            std::swap(*first, *last);
            ++first;
        }
    }

    static std::uint32_t makeLeaf(std::vector<BvhNode>& nodes, std::uint32_t node, std::uint32_t begin,
                                  std::uint32_t end) {
        nodes[node].offset = begin;
        nodes[node].count = std::uint16_t(end - begin);
        nodes[node].axis = 0;
        return node;
    }

    // Appends the subtree over refs[begin, end) to `nodes` in depth-first order; interior
    // nodes' `offset` (second child) is an index into `nodes`. Returns the deepest level.
    // `known`: the range's bounds when the parent's bins gave them (the union of the bins on
    // the chosen side is the union of exactly these primitives), else null.
    int build(std::vector<BvhNode>& nodes, std::uint32_t begin, std::uint32_t end, int depth,
              const scene::Bounds* known, const scene::Bounds* knownCentroids) {
        const std::uint32_t node = std::uint32_t(nodes.size());
        nodes.emplace_back();
        RangeBounds rb;
        if (known)
            rb.all = *known;
        else
            rb = rangeBounds(begin, end);
        const scene::Bounds& all = rb.all;
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
        if (known) rb.centroids = *knownCentroids;
        const scene::Bounds& cb = rb.centroids;

        int bestAxis = -1;
        int bestBin = -1;
        double bestCost = std::numeric_limits<double>::infinity();
        const scene::Vec3 ext = cb.extent();
        Bins bins;
        if (depth < kBvhSahMaxDepth) {
            bin(begin, end, cb, bins);
            for (int axis = 0; axis < 3; ++axis) {
                if (!(ext[axis] > 0)) continue;
                const auto& binBounds = bins.bounds[axis];
                const auto& binCount = bins.count[axis];
                // Sweep from the right to get every right-hand side's area and count.
                std::array<double, kBvhBins> rightArea{};
                std::array<std::uint32_t, kBvhBins> rightCount{};
                Box4 acc;
                std::uint32_t n = 0;
                for (int b = kBvhBins - 1; b > 0; --b) {
                    acc.extend(binBounds[b]);
                    n += binCount[b];
                    rightArea[b] = acc.area();
                    rightCount[b] = n;
                }
                Box4 left;
                std::uint32_t nl = 0;
                for (int b = 0; b < kBvhBins - 1; ++b) {
                    left.extend(binBounds[b]);
                    nl += binCount[b];
                    if (nl == 0 || rightCount[b + 1] == 0) continue;
                    const double cost = left.area() * blocks(nl) + rightArea[b + 1] * blocks(rightCount[b + 1]);
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
        scene::Bounds leftAll, rightAll, leftCentroids, rightCentroids;
        bool childBounds = false;
        if (bestAxis >= 0) {
            axis = bestAxis;
            // The same std::partition with the same predicate on the same sequence as over
            // indices: the same swaps, so the same order of primitives.
            mid = partition(
                begin, end,
                [&](const PrimRef& r) { return binOf(r.centroid(axis), cb.min[axis], ext[axis]) <= bestBin; },
                leftCentroids, rightCentroids);
            Box4 l, r;
            for (int b = 0; b <= bestBin; ++b) l.extend(bins.bounds[axis][b]);
            for (int b = bestBin + 1; b < kBvhBins; ++b) r.extend(bins.bounds[axis][b]);
            leftAll = l.bounds();
            rightAll = r.bounds();
            childBounds = true;
        } else {
            // No usable SAH split (coincident centroids or too deep): halve by count so the
            // tree stays shallow and leaves stay small.
            axis = ext.x >= ext.y && ext.x >= ext.z ? 0 : (ext.y >= ext.z ? 1 : 2);
            mid = begin + count / 2;
            std::nth_element(refs.data() + begin, refs.data() + mid, refs.data() + end,
                             [&](const PrimRef& a, const PrimRef& b) { return a.centroid(axis) < b.centroid(axis); });
        }
        int deepest;
        std::uint32_t second;
        if (count >= kBvhParallelCount) {
            // Both halves at once: the second into its own vector, appended after the first
            // with its node indices shifted, so the layout is exactly the sequential one.
            std::vector<BvhNode> right;
            int dl = 0, dr = 0;
            tbb::parallel_invoke(
                [&] { dl = build(nodes, begin, mid, depth + 1, childBounds ? &leftAll : nullptr, &leftCentroids); },
                [&] {
                    right.reserve(2 * std::size_t(end - mid));
                    dr = build(right, mid, end, depth + 1, childBounds ? &rightAll : nullptr, &rightCentroids);
                });
            second = std::uint32_t(nodes.size());
            for (BvhNode& n : right)
                if (n.count == 0) n.offset += second;
            nodes.insert(nodes.end(), right.begin(), right.end());
            deepest = std::max(dl, dr);
        } else {
            const int dl = build(nodes, begin, mid, depth + 1, childBounds ? &leftAll : nullptr, &leftCentroids);
            second = std::uint32_t(nodes.size());
            deepest =
                std::max(dl, build(nodes, mid, end, depth + 1, childBounds ? &rightAll : nullptr, &rightCentroids));
        }
        nodes[node].offset = second;
        nodes[node].count = 0;
        nodes[node].axis = std::uint8_t(axis);
        return deepest;
    }
    // Leaves are tested kBvhLeafBlock triangles at a time (triangle4.h), so a leaf of n costs
    // ⌈n / block⌉ tests: Embree's SAH counts primitives in blocks the same way.
    static double blocks(std::uint32_t n) { return double((n + kBvhLeafBlock - 1) / kBvhLeafBlock); }

    static int binOf(double c, double lo, double extent) {
        const int b = int(kBvhBins * ((c - lo) / extent));
        return std::clamp(b, 0, kBvhBins - 1);
    }
};

// The float builder for the float tracer: the same SAH, leaf rules and layout as Builder, on
// 32-byte float references (the double bounds rounded outward, so every box still contains its
// triangles in both precisions) with one SSE register per box, bins found by a multiply
// instead of a divide. Half the bytes per pass of the double build; a slightly different tree.
struct alignas(32) PrimRefF {
    __m128 lo;  // lane 3: the primitive index's bits
    __m128 hi;
};
static_assert(sizeof(PrimRefF) == 32, "PrimRefF: two per cache line");

struct BoxF {
    __m128 lo = _mm_set1_ps(std::numeric_limits<float>::infinity());
    __m128 hi = _mm_set1_ps(-std::numeric_limits<float>::infinity());
    void extend(__m128 l, __m128 h) {
        lo = _mm_min_ps(lo, l);
        hi = _mm_max_ps(hi, h);
    }
    void extend(const BoxF& o) { extend(o.lo, o.hi); }
    float area() const {
        alignas(16) float l[4], h[4];
        _mm_store_ps(l, lo);
        _mm_store_ps(h, hi);
        if (!(l[0] <= h[0])) return 0.0f;
        const float x = h[0] - l[0], y = h[1] - l[1], z = h[2] - l[2];
        return 2.0f * (x * y + y * z + z * x);
    }
};

struct BinsF {
    std::array<std::array<BoxF, kBvhBins>, 3> bounds;
    std::array<std::array<std::uint32_t, kBvhBins>, 3> count{};
    void add(const BinsF& o) {
        for (int a = 0; a < 3; ++a)
            for (int b = 0; b < kBvhBins; ++b) {
                bounds[a][b].extend(o.bounds[a][b]);
                count[a][b] += o.count[a][b];
            }
    }
};

// Centroids are kept doubled (lo + hi): the same order, one multiply fewer.
inline __m128 centroid2(const PrimRefF& r) { return _mm_add_ps(r.lo, r.hi); }

struct FastBuilder {
    // Ranges of at least this many references are binned with two sets of bins (bin). A second
    // set is 1.7 KB to clear and merge per node; on a few dozen references that is most of the
    // binning. (Not tuned: the gain measured is the large ranges'.)
    static constexpr std::uint32_t kBinPairsFrom = 64;

    // The references, and a second array as large: a range is partitioned from the one that
    // holds it into the other (the same positions), so its children live in the other one.
    // A leaf's references are copied back into `refs`, which ends in the leaves' order.
    std::vector<PrimRefF>& refs;
    PrimRefF* spare;

    PrimRefF* buffer(bool inSpare) const { return inSpare ? spare : refs.data(); }

    // Bin of each axis for doubled centroid c: (c − lo)·scale, clamped to [0, bins − 1].
    struct Binner {
        __m128 lo, scale;
        explicit Binner(const BoxF& cb) {
            lo = cb.lo;
            alignas(16) float e[4], sc[4];
            _mm_store_ps(e, _mm_sub_ps(cb.hi, cb.lo));
            for (int k = 0; k < 4; ++k) sc[k] = k < 3 && e[k] > 0 ? float(kBvhBins) * (1.0f - 0x1.0p-20f) / e[k] : 0.0f;
            scale = _mm_load_ps(sc);
        }
        __m128i operator()(__m128 c) const {
            __m128 f = _mm_mul_ps(_mm_sub_ps(c, lo), scale);
            f = _mm_min_ps(_mm_max_ps(f, _mm_setzero_ps()), _mm_set1_ps(float(kBvhBins - 1)));
            return _mm_cvttps_epi32(f);
        }
    };

    static void bin(const PrimRefF* src, std::uint32_t begin, std::uint32_t end, const Binner& binner, BinsF& result) {
        auto add = [&](const PrimRefF& r, BinsF& out) {
            const __m128i k = binner(centroid2(r));
            const int k0 = _mm_cvtsi128_si32(k), k1 = _mm_cvtsi128_si32(_mm_shuffle_epi32(k, 0x55)),
                      k2 = _mm_cvtsi128_si32(_mm_shuffle_epi32(k, 0xaa));
            ++out.count[0][k0];
            ++out.count[1][k1];
            ++out.count[2][k2];
            out.bounds[0][k0].extend(r.lo, r.hi);
            out.bounds[1][k1].extend(r.lo, r.hi);
            out.bounds[2][k2].extend(r.lo, r.hi);
        };
        auto body = [&](std::uint32_t b, std::uint32_t e, BinsF& out) {
            if (e - b < kBinPairsFrom) {
                for (std::uint32_t i = b; i < e; ++i) add(src[i], out);
                return;
            }
            // Neighbouring references often fall in the same bins: alternating between two
            // sets of bins lets one's update start before the other's store lands. (Unions and
            // counts: the merged bins are the same.)
            BinsF odd;
            std::uint32_t i = b;
            for (; i + 1 < e; i += 2) {
                add(src[i], out);
                add(src[i + 1], odd);
            }
            if (i < e) add(src[i], out);
            out.add(odd);
        };
        if (end - begin < kBvhParallelCount) {
            body(begin, end, result);
            return;
        }
        result = tbb::parallel_reduce(
            tbb::blocked_range<std::uint32_t>(begin, end, kBvhParallelGrain), BinsF{},
            [&](const tbb::blocked_range<std::uint32_t>& r, BinsF acc) {
                body(r.begin(), r.end(), acc);
                return acc;
            },
            [](BinsF x, const BinsF& y) {
                x.add(y);
                return x;
            });
    }

    static void rangeBounds(const PrimRefF* src, std::uint32_t begin, std::uint32_t end, BoxF& all, BoxF& cb) {
        all = BoxF{};
        cb = BoxF{};
        for (std::uint32_t i = begin; i < end; ++i) {
            all.extend(src[i].lo, src[i].hi);
            const __m128 c = centroid2(src[i]);
            cb.extend(c, c);
        }
    }

    // Moves src[begin, end) into dst[begin, end): the references whose centroid's bin on `axis`
    // is at most `lastLeftBin` to the front in their order, the others to the back in reverse
    // order, and finds each side's centroid bounds. Branch-free: which side a reference takes
    // is as good as random to a branch predictor. Returns the first right one's position.
    static std::uint32_t partition(const PrimRefF* src, PrimRefF* dst, std::uint32_t begin, std::uint32_t end,
                                   const Binner& binner, int axis, int lastLeftBin, BoxF& leftC, BoxF& rightC) {
        alignas(16) float lo[4], scale[4];
        _mm_store_ps(lo, binner.lo);
        _mm_store_ps(scale, binner.scale);
        // The bin is ⌊(c − lo)·scale⌋ clamped to [0, bins − 1] (Binner): at most lastLeftBin
        // exactly when the same product is below lastLeftBin + 1.
        const float a = lo[axis], sc = scale[axis], limit = float(lastLeftBin + 1);
        // Added to a centroid before it meets a side's minimum (maximum: subtracted): +inf
        // keeps it out of the side it does not take, 0 lets it in.
        const __m128 away[2] = {_mm_set1_ps(std::numeric_limits<float>::infinity()), _mm_setzero_ps()};
        __m128 lLo = leftC.lo, lHi = leftC.hi, rLo = rightC.lo, rHi = rightC.hi;
        std::uint32_t l = begin, h = end;  // the next left slot; one past the next right slot
        for (std::uint32_t i = begin; i < end; ++i) {
            const __m128 rl = src[i].lo, rh = src[i].hi;
            const __m128 c = _mm_add_ps(rl, rh);
            const float ca =
                _mm_cvtss_f32(axis == 0 ? c : (axis == 1 ? _mm_shuffle_ps(c, c, 1) : _mm_shuffle_ps(c, c, 2)));
            const int left = !((ca - a) * sc >= limit);  // (as Binner's clamp, NaN goes left)
            PrimRefF* out = dst + (left ? l : h - 1);
            out->lo = rl;
            out->hi = rh;
            l += left;
            h -= 1 - left;
            const __m128 toL = away[left], toR = away[1 - left];
            lLo = _mm_min_ps(lLo, _mm_add_ps(c, toL));
            lHi = _mm_max_ps(lHi, _mm_sub_ps(c, toL));
            rLo = _mm_min_ps(rLo, _mm_add_ps(c, toR));
            rHi = _mm_max_ps(rHi, _mm_sub_ps(c, toR));
        }
        leftC = BoxF{lLo, lHi};
        rightC = BoxF{rLo, rHi};
        return l;
    }

    void makeLeaf(BvhNode& leaf, std::uint32_t begin, std::uint32_t end, bool inSpare) const {
        if (inSpare) std::copy(spare + begin, spare + end, refs.data() + begin);
        leaf.offset = begin;
        leaf.count = std::uint16_t(end - begin);
        leaf.axis = 0;
    }

    struct Built {
        int depth = 0;            // the deepest level
        std::uint32_t nodes = 0;  // slots used
    };

    // Writes the subtree over the references [begin, end) at nodes[node], its first child at
    // node + 1 and its second at `offset`, each further node at `next`, counting up. A subtree
    // of m references has at most 2m − 1 nodes, so two built in parallel take disjoint slots
    // if the second starts 2m − 1 after the first; the slots left between are closed up once,
    // at the end (FastBuildAccess::build), not at every parallel level.
    Built build(BvhNode* nodes, std::uint32_t node, std::uint32_t& next, std::uint32_t begin, std::uint32_t end,
                int depth, bool inSpare, const BoxF& all, const BoxF& cb) {
        alignas(16) float l[4], h[4];
        _mm_store_ps(l, all.lo);
        _mm_store_ps(h, all.hi);
        for (int k = 0; k < 3; ++k) {
            nodes[node].lo[k] = l[k];
            nodes[node].hi[k] = h[k];
        }
        nodes[node].pad = 0;
        const std::uint32_t count = end - begin;
        if (count <= kBvhMinSplitCount) {
            makeLeaf(nodes[node], begin, end, inSpare);
            return {depth, 1};
        }
        PrimRefF* src = buffer(inSpare);
        alignas(16) float cl[4], ch[4];
        _mm_store_ps(cl, cb.lo);
        _mm_store_ps(ch, cb.hi);
        int bestAxis = -1, bestBin = -1;
        float bestCost = std::numeric_limits<float>::infinity();
        const Binner binner(cb);
        BinsF bins;
        if (depth < kBvhSahMaxDepth) {
            bin(src, begin, end, binner, bins);
            for (int axis = 0; axis < 3; ++axis) {
                if (!(ch[axis] > cl[axis])) continue;
                const auto& bb = bins.bounds[axis];
                const auto& bc = bins.count[axis];
                std::array<float, kBvhBins> rightArea{};
                std::array<std::uint32_t, kBvhBins> rightCount{};
                BoxF acc;
                std::uint32_t n = 0;
                for (int b = kBvhBins - 1; b > 0; --b) {
                    acc.extend(bb[b]);
                    n += bc[b];
                    rightArea[b] = acc.area();
                    rightCount[b] = n;
                }
                BoxF left;
                std::uint32_t nl = 0;
                for (int b = 0; b < kBvhBins - 1; ++b) {
                    left.extend(bb[b]);
                    nl += bc[b];
                    if (nl == 0 || rightCount[b + 1] == 0) continue;
                    const float cost = left.area() * float(Builder::blocks(nl)) +
                                       rightArea[b + 1] * float(Builder::blocks(rightCount[b + 1]));
                    if (cost < bestCost) {
                        bestCost = cost;
                        bestAxis = axis;
                        bestBin = b;
                    }
                }
            }
        }
        const float area = all.area();
        const double splitCost =
            area > 0 ? kBvhTraversalCost + double(bestCost) / double(area) : std::numeric_limits<double>::infinity();
        if (count <= kBvhMaxLeafCount && (bestAxis < 0 || splitCost >= Builder::blocks(count))) {
            makeLeaf(nodes[node], begin, end, inSpare);
            return {depth, 1};
        }
        std::uint32_t mid;
        int axis;
        bool childInSpare = inSpare;
        BoxF leftAll, rightAll, leftC, rightC;
        if (bestAxis >= 0) {
            axis = bestAxis;
            childInSpare = !inSpare;
            PrimRefF* dst = buffer(childInSpare);
            mid = partition(src, dst, begin, end, binner, axis, bestBin, leftC, rightC);
            for (int b = 0; b <= bestBin; ++b) leftAll.extend(bins.bounds[axis][b]);
            for (int b = bestBin + 1; b < kBvhBins; ++b) rightAll.extend(bins.bounds[axis][b]);
        } else {
            const float ex = ch[0] - cl[0], ey = ch[1] - cl[1], ez = ch[2] - cl[2];
            axis = ex >= ey && ex >= ez ? 0 : (ey >= ez ? 1 : 2);
            mid = begin + count / 2;
            auto key = [axis](const PrimRefF& r) {
                alignas(16) float c[4];
                _mm_store_ps(c, centroid2(r));
                return c[axis];
            };
            std::nth_element(src + begin, src + mid, src + end,
                             [&](const PrimRefF& a, const PrimRefF& b) { return key(a) < key(b); });
            rangeBounds(src, begin, mid, leftAll, leftC);
            rangeBounds(src, mid, end, rightAll, rightC);
        }
        Built left, right;
        std::uint32_t second;
        if (count >= kBvhParallelCount) {
            second = node + 2 * (mid - begin);
            tbb::parallel_invoke(
                [&] {
                    std::uint32_t nextLeft = node + 2;
                    left = build(nodes, node + 1, nextLeft, begin, mid, depth + 1, childInSpare, leftAll, leftC);
                },
                [&] {
                    std::uint32_t nextRight = second + 1;
                    right = build(nodes, second, nextRight, mid, end, depth + 1, childInSpare, rightAll, rightC);
                });
        } else {
            ++next;  // (node + 1)
            left = build(nodes, node + 1, next, begin, mid, depth + 1, childInSpare, leftAll, leftC);
            second = next++;
            right = build(nodes, second, next, mid, end, depth + 1, childInSpare, rightAll, rightC);
        }
        nodes[node].offset = second;
        nodes[node].count = 0;
        nodes[node].axis = std::uint8_t(axis);
        return {std::max(left.depth, right.depth), 1 + left.nodes + right.nodes};
    }
};

}  // namespace

Bvh Bvh::build(const std::vector<scene::Bounds>& primitiveBounds) {
    Bvh bvh;
    const std::size_t n = primitiveBounds.size();
    if (n == 0) return bvh;
    std::vector<PrimRef> refs(n);
    tbb::parallel_for(
        tbb::blocked_range<std::size_t>(0, n, kBvhParallelGrain), [&](const tbb::blocked_range<std::size_t>& r) {
            for (std::size_t i = r.begin(); i != r.end(); ++i) {
                const scene::Bounds& b = primitiveBounds[i];
                refs[i] = PrimRef{{b.min.x, b.min.y, b.min.z, double(i)}, {b.max.x, b.max.y, b.max.z, 0.0}};
            }
        });
    bvh.nodes_.reserve(2 * n);
    Builder b{refs};
    bvh.depth_ = b.build(bvh.nodes_, 0, std::uint32_t(n), 0, nullptr, nullptr);
    bvh.nodes_.shrink_to_fit();
    bvh.primitives_.resize(n);
    for (std::size_t i = 0; i < n; ++i) bvh.primitives_[i] = refs[i].index();
    return bvh;
}

}  // namespace shadowlab::raytrace

namespace shadowlab::raytrace {

namespace {

// roundDown<float> / roundUp<float> (real.h) with the step to the neighbouring float taken on
// the bits instead of by std::nextafter, a library call that was most of a reference's cost,
// and without a branch: whether float(x) rounded up is as good as random. For every non-NaN
// float r, the next float down is bits − 1 above zero and bits + 1 below it (from −0: the
// smallest negative subnormal); the next up mirrors it. float(x) is +0 only for x ≥ 0, never
// above x, and −0 only for x ≤ 0, never below it, so the sign bit picks the step.
float floatDown(double x) {
    const float r = float(x);
    std::uint32_t bits;
    std::memcpy(&bits, &r, sizeof bits);
    bits += std::uint32_t(double(r) > x) * ((bits >> 31) * 2u - 1u);  // sign 1: +1, 0: −1
    float down;
    std::memcpy(&down, &bits, sizeof down);
    return down;
}
float floatUp(double x) {
    const float r = float(x);
    std::uint32_t bits;
    std::memcpy(&bits, &r, sizeof bits);
    bits += std::uint32_t(double(r) < x) * (1u - (bits >> 31) * 2u);  // sign 0: +1, 1: −1
    float up;
    std::memcpy(&up, &bits, sizeof up);
    return up;
}

PrimRefF floatRef(const scene::Bounds& b, std::uint32_t index) {
    float idx;
    std::memcpy(&idx, &index, sizeof idx);
    PrimRefF r;
    r.lo = _mm_setr_ps(floatDown(b.min.x), floatDown(b.min.y), floatDown(b.min.z), idx);
    r.hi = _mm_setr_ps(floatUp(b.max.x), floatUp(b.max.y), floatUp(b.max.z), 0.0f);
    return r;
}

// 2^-k for k in [0, 31], made on the exponent bits (exact).
double levelWeight(int k) {
    const std::uint64_t bits = std::uint64_t(1023 - k) << 52;
    double w;
    std::memcpy(&w, &bits, sizeof w);
    return w;
}

// x^(1/3) within a few per cent for normal floats x > 0, 0 otherwise: the exponent divided by
// three on the bits (Kahan's estimate, the constant re-biases it). A priority needs no more,
// and std::cbrt was a twentieth of the float build.
float cubeRootEstimate(float x) {
    if (!(x >= std::numeric_limits<float>::min())) return 0.0f;
    std::uint32_t bits;
    std::memcpy(&bits, &x, sizeof bits);
    bits = bits / 3 + 0x2a514067u;
    std::memcpy(&x, &bits, sizeof x);
    return x;
}

// Pre-splitting of triangles (Karras & Aila, "Fast Parallel Construction of High-Quality
// Bounding Volume Hierarchies", HPG 2013, section 4.2): a budget of extra references goes to the
// triangles whose box is largest and emptiest, each split recursively across its box's longest
// axis at the coarsest plane of a power-of-two grid over the mesh (the planes the SAH splits
// near the root most likely use). A piece's box is the box of the triangle clipped to one side,
// within its parent's box.
struct Presplitter {
    const std::vector<Vec3T<float>>& positions;
    const std::vector<std::uint32_t>& indices;
    double gridLo[3], gridExtent[3], gridScale[3];  // scale: 2^31 / extent
    double pad;                                     // margin around a piece (see emit)

    struct BoxD {
        double lo[3], hi[3];
        void empty() {
            for (int k = 0; k < 3; ++k) {
                lo[k] = std::numeric_limits<double>::infinity();
                hi[k] = -std::numeric_limits<double>::infinity();
            }
        }
        void extend(const double p[3]) {
            for (int k = 0; k < 3; ++k) {
                lo[k] = std::min(lo[k], p[k]);
                hi[k] = std::max(hi[k], p[k]);
            }
        }
        bool isEmpty() const { return !(lo[0] <= hi[0] && lo[1] <= hi[1] && lo[2] <= hi[2]); }
    };

    void vertices(std::uint32_t tri, double v[3][3]) const {
        for (int k = 0; k < 3; ++k) {
            const Vec3T<float>& p = positions[indices[3 * std::size_t(tri) + k]];
            for (int a = 0; a < 3; ++a) v[k][a] = double(p[a]);
        }
    }

    // The box of the part of the triangle on one side of the plane x[axis] = s (both sides take
    // points on the plane).
    static void clipHalf(const double v[3][3], int axis, double s, bool below, BoxD& out) {
        out.empty();
        for (int i = 0; i < 3; ++i) {
            const double* a = v[i];
            const double* b = v[(i + 1) % 3];
            const double da = a[axis] - s, db = b[axis] - s;
            if (below ? da <= 0 : da >= 0) out.extend(a);
            if ((da < 0 && db > 0) || (da > 0 && db < 0)) {
                const double f = da / (da - db);
                double p[3];
                for (int k = 0; k < 3; ++k) p[k] = a[k] + f * (b[k] - a[k]);
                p[axis] = s;
                out.extend(p);
            }
        }
    }

    // [0, 2^31) fixed point of a coordinate over the mesh box on this axis.
    std::uint32_t fixed(int axis, double x) const {
        return std::uint32_t(std::clamp((x - gridLo[axis]) * gridScale[axis], 0.0, 0x1.0p31 - 2));
    }

    // The level k (1: the middle plane) of the coarsest grid plane the box crosses, over its
    // axes: with the box's ends in fixed point, the highest bit in which they differ.
    int level(const scene::Bounds& b) const {
        int best = 31;
        for (int axis = 0; axis < 3; ++axis) {
            if (!(gridExtent[axis] > 0)) continue;
            const std::uint32_t d = fixed(axis, b.min[axis]) ^ fixed(axis, b.max[axis]);
            if (d != 0) best = std::min(best, __builtin_clz(d));  // bit 30 differs: level 1
        }
        return best;
    }

    // The coarsest grid plane inside (lo, hi) on this axis (the upper end's fixed point with the
    // bits below the highest one that differs from the lower end's cleared), else the middle,
    // as a float strictly inside; NaN if none.
    float plane(int axis, double lo, double hi) const {
        if (!(gridExtent[axis] > 0) || !(hi > lo)) return std::numeric_limits<float>::quiet_NaN();
        const std::uint32_t a = fixed(axis, lo), b = fixed(axis, hi);
        if (a != b) {
            const int h = 31 - __builtin_clz(a ^ b);
            const float s = float(gridLo[axis] + gridExtent[axis] * (double((b >> h) << h) * 0x1.0p-31));
            if (double(s) > lo && double(s) < hi) return s;
        }
        const float s = float(0.5 * (lo + hi));
        return double(s) > lo && double(s) < hi ? s : std::numeric_limits<float>::quiet_NaN();
    }

    // A piece's reference: its box widened by `pad` and rounded outward, but never beyond the
    // whole triangle's box. The margin keeps inside the pieces every point the float triangle
    // test may accept near the triangle (its rounding is far below it), as the whole box did.
    static void emit(const BoxD& box, double pad, const PrimRefF& whole, PrimRefF*& out) {
        alignas(16) float wl[4], wh[4], l[4], h[4];
        _mm_store_ps(wl, whole.lo);
        _mm_store_ps(wh, whole.hi);
        for (int k = 0; k < 3; ++k) {
            l[k] = std::max(wl[k], floatDown(box.lo[k] - pad));
            h[k] = std::min(wh[k], floatUp(box.hi[k] + pad));
        }
        l[3] = wl[3];
        h[3] = 0.0f;
        out->lo = _mm_load_ps(l);
        out->hi = _mm_load_ps(h);
        ++out;
    }

    void split(const double v[3][3], const BoxD& box, int pieces, const PrimRefF& whole, PrimRefF*& out) const {
        int axis = 0;
        for (int k = 1; k < 3; ++k)
            if (box.hi[k] - box.lo[k] > box.hi[axis] - box.lo[axis]) axis = k;
        const float s = pieces > 1 ? plane(axis, box.lo[axis], box.hi[axis]) : 0.0f;
        if (pieces <= 1 || std::isnan(s)) {
            for (int i = 0; i < pieces; ++i) emit(box, pad, whole, out);  // (count kept exact)
            return;
        }
        BoxD left, right;
        clipHalf(v, axis, s, true, left);
        clipHalf(v, axis, s, false, right);
        for (int k = 0; k < 3; ++k) {
            left.lo[k] = std::max(left.lo[k], box.lo[k]);
            left.hi[k] = std::min(left.hi[k], box.hi[k]);
            right.lo[k] = std::max(right.lo[k], box.lo[k]);
            right.hi[k] = std::min(right.hi[k], box.hi[k]);
        }
        left.hi[axis] = std::min(left.hi[axis], double(s));
        right.lo[axis] = std::max(right.lo[axis], double(s));
        if (left.isEmpty() || right.isEmpty()) {
            for (int i = 0; i < pieces; ++i) emit(box, pad, whole, out);
            return;
        }
        const double el = left.hi[axis] - left.lo[axis], er = right.hi[axis] - right.lo[axis];
        int nl = int(std::lround(pieces * (el / (el + er))));
        nl = std::clamp(nl, 1, pieces - 1);
        split(v, left, nl, whole, out);
        split(v, right, pieces - nl, whole, out);
    }
};

}  // namespace

struct FastBuildAccess {
    static Bvh build(std::vector<PrimRefF>& refs);
};

Bvh Bvh::buildFast(const std::vector<scene::Bounds>& primitiveBounds) {
    Bvh bvh;
    const std::size_t n = primitiveBounds.size();
    if (n == 0) return bvh;
    std::vector<PrimRefF> refs(n);
    tbb::parallel_for(tbb::blocked_range<std::size_t>(0, n, kBvhParallelGrain),
                      [&](const tbb::blocked_range<std::size_t>& r) {
                          for (std::size_t i = r.begin(); i != r.end(); ++i)
                              refs[i] = floatRef(primitiveBounds[i], std::uint32_t(i));
                      });
    return FastBuildAccess::build(refs);
}

Bvh Bvh::buildFast(const std::vector<scene::Bounds>& primitiveBounds, const std::vector<Vec3T<float>>& positions,
                   const std::vector<std::uint32_t>& indices) {
    const std::size_t n = primitiveBounds.size();
    if (n == 0) return Bvh{};
    scene::Bounds all;
    for (const scene::Bounds& b : primitiveBounds) all.extend(b);
    Presplitter ps{positions, indices, {}, {}, {}, 0.0};
    for (int k = 0; k < 3; ++k) {
        ps.gridLo[k] = all.min[k];
        ps.gridExtent[k] = all.max[k] - all.min[k];
        ps.gridScale[k] = ps.gridExtent[k] > 0 ? 0x1.0p31 / ps.gridExtent[k] : 0.0;
    }
    ps.pad = kPresplitPad * (all.maxAbsCoordinate() + all.diagonal());
    // Priority: Karras & Aila's, the cube root of the box's empty surface times the importance of
    // the planes it crosses; the budget is shared in proportion.
    std::vector<float> priority(n);
    tbb::parallel_for(
        tbb::blocked_range<std::size_t>(0, n, kBvhParallelGrain), [&](const tbb::blocked_range<std::size_t>& r) {
            for (std::size_t i = r.begin(); i != r.end(); ++i) {
                double v[3][3];
                ps.vertices(std::uint32_t(i), v);
                const double e1[3] = {v[1][0] - v[0][0], v[1][1] - v[0][1], v[1][2] - v[0][2]};
                const double e2[3] = {v[2][0] - v[0][0], v[2][1] - v[0][1], v[2][2] - v[0][2]};
                const double cx = e1[1] * e2[2] - e1[2] * e2[1], cy = e1[2] * e2[0] - e1[0] * e2[2],
                             cz = e1[0] * e2[1] - e1[1] * e2[0];
                // The box's surface not covered by the triangle's two sides, weighted by the
                // coarsest grid plane the box crosses: halved per level below the middle one.
                const double waste = (surfaceArea(primitiveBounds[i]) - std::sqrt(cx * cx + cy * cy + cz * cz)) *
                                     levelWeight(ps.level(primitiveBounds[i]));
                priority[i] = cubeRootEstimate(float(waste));
            }
        });
    // Summed in order, and the extras below are integers: the tree does not depend on the threads.
    double total = 0;
    for (float p : priority) total += p;
    // Triangle i gets floor(scale · priority) extra pieces (at most kPresplitMaxPieces in all),
    // the scale found by bisection so that the extras come to the budget.
    const double budget = kPresplitBudget * double(n);
    auto extras = [&](std::size_t i, double scale) {  // (a truncation: scale · priority ≥ 0)
        return std::uint32_t(std::min(scale * double(priority[i]), double(kPresplitMaxPieces - 1)));
    };
    auto used = [&](double scale) {  // (serial: a fraction of a ns per triangle, less than waking threads)
        std::uint64_t sum = 0;
        for (std::size_t i = 0; i < n; ++i) sum += extras(i, scale);
        return double(sum);
    };
    // Σ⌊s·p⌋ lies in (s·Σp − n, s·Σp]: at budget / total it is within the budget, at
    // (n + budget) / total beyond it. Six halvings find the scale to a fraction of that range.
    double lo = total > 0 ? budget / total : 0.0, hi = total > 0 ? (double(n) + budget) / total : 0.0;
    for (int it = 0; it < 6 && hi > 0; ++it) {
        const double mid = 0.5 * (lo + hi);
        (used(mid) > budget ? hi : lo) = mid;
    }
    std::vector<std::uint32_t> first(n + 1);
    first[0] = 0;
    for (std::size_t i = 0; i < n; ++i) first[i + 1] = first[i] + 1 + extras(i, lo);
    std::vector<PrimRefF> refs(first[n]);
    tbb::parallel_for(tbb::blocked_range<std::size_t>(0, n, kBvhParallelGrain),
                      [&](const tbb::blocked_range<std::size_t>& r) {
                          for (std::size_t i = r.begin(); i != r.end(); ++i) {
                              const PrimRefF whole = floatRef(primitiveBounds[i], std::uint32_t(i));
                              PrimRefF* out = refs.data() + first[i];
                              const int pieces = int(first[i + 1] - first[i]);
                              if (pieces == 1) {
                                  *out = whole;
                                  continue;
                              }
                              double v[3][3];
                              ps.vertices(std::uint32_t(i), v);
                              Presplitter::BoxD box;
                              box.empty();
                              for (int k = 0; k < 3; ++k) box.extend(v[k]);
                              ps.split(v, box, pieces, whole, out);
                          }
                      });
    return FastBuildAccess::build(refs);
}

Bvh FastBuildAccess::build(std::vector<PrimRefF>& refs) {
    Bvh bvh;
    const std::size_t n = refs.size();
    // (Neither is zeroed: a slot is written before it is read, and most node slots never are.)
    const std::unique_ptr<PrimRefF[]> spare(new PrimRefF[n]);
    const std::unique_ptr<BvhNode[]> slots(new BvhNode[2 * n - 1]);
    FastBuilder b{refs, spare.get()};
    BoxF all, cb;
    FastBuilder::rangeBounds(refs.data(), 0, std::uint32_t(n), all, cb);
    std::uint32_t next = 1;
    const FastBuilder::Built built = b.build(slots.get(), 0, next, 0, std::uint32_t(n), 0, false, all, cb);
    bvh.depth_ = built.depth;
    // Pack the used slots in depth-first order (first child next, as Bvh::build lays them out).
    bvh.nodes_.reserve(built.nodes);
    std::vector<std::pair<std::uint32_t, std::uint32_t>> pending;  // (second child's slot, its parent's index)
    std::uint32_t slot = 0;
    for (;;) {
        const std::uint32_t index = std::uint32_t(bvh.nodes_.size());
        bvh.nodes_.push_back(slots[slot]);
        if (bvh.nodes_.back().count == 0) {
            pending.emplace_back(bvh.nodes_.back().offset, index);
            ++slot;
            continue;
        }
        if (pending.empty()) break;
        slot = pending.back().first;
        bvh.nodes_[pending.back().second].offset = std::uint32_t(bvh.nodes_.size());
        pending.pop_back();
    }
    bvh.primitives_.resize(n);
    for (std::size_t i = 0; i < n; ++i) {
        alignas(16) float lo[4];
        _mm_store_ps(lo, refs[i].lo);
        std::memcpy(&bvh.primitives_[i], &lo[3], sizeof(std::uint32_t));
    }
    return bvh;
}

}  // namespace shadowlab::raytrace
