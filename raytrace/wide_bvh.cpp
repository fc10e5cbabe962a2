// raytrace/wide_bvh.cpp: collapse of the binary SAH tree into N-wide nodes.
#include "raytrace/wide_bvh.h"

#include <algorithm>
#include <array>
#include <atomic>
#include <limits>
#include <stdexcept>

#include "raytrace/tolerances.h"

namespace shadowlab::raytrace {

static_assert(kBvhMaxLeafCount < 16, "a leaf ref keeps its count in four bits");

namespace {

float surfaceArea(const BvhNode& n) {
    const float x = n.hi[0] - n.lo[0], y = n.hi[1] - n.lo[1], z = n.hi[2] - n.lo[2];
    return 2 * (x * y + y * z + z * x);
}

template <int N>
struct Collapser {
    const std::vector<BvhNode>& bin;
    const std::vector<std::uint32_t>& binPrims;
    std::vector<WideNode<N>>& out;
    std::vector<std::uint32_t>& prims;
    bool smallFirst;  // order each node's children by surface area where they differ (collapse)

    std::uint32_t refOf(std::uint32_t b) {
        const BvhNode& n = bin[b];
        if (n.count == 0) return collapse(b);
        // Leaves are laid out in traversal order, each starting on a multiple of kLeafAlign
        // slots, so a leaf is whole packets of four triangles.
        // A pre-split triangle (Bvh::buildFast) may have several pieces in one leaf: it is kept once.
        const std::uint32_t first = std::uint32_t(prims.size());
        for (std::uint32_t i = n.offset; i < n.offset + n.count; ++i)
            if (std::find(prims.begin() + first, prims.end(), binPrims[i]) == prims.end()) prims.push_back(binPrims[i]);
        const std::uint32_t count = std::uint32_t(prims.size()) - first;
        while (prims.size() % WideRef::kLeafAlign != 0) prims.push_back(WideRef::kEmpty);
        return WideRef::leafRef(first, count);
    }

    // Makes the wide node for binary interior node b and returns its index.
    std::uint32_t collapse(std::uint32_t b) {
        std::array<std::uint32_t, N> kids{};
        int n = 2;
        kids[0] = b + 1;
        kids[1] = bin[b].offset;
        while (n < N) {
            // Open the interior child with the largest surface area: it is the one a ray
            // enters most often, so flattening it saves the most node visits (SAH argument).
            int best = -1;
            float bestArea = -1;
            for (int i = 0; i < n; ++i) {
                if (bin[kids[i]].count > 0) continue;
                const float a = surfaceArea(bin[kids[i]]);
                if (a > bestArea) {
                    bestArea = a;
                    best = i;
                }
            }
            if (best < 0) break;
            const std::uint32_t k = kids[best];
            // Its two children take its place, in order, so siblings stay spatially sorted.
            for (int i = n; i > best + 1; --i) kids[i] = kids[i - 1];
            kids[best] = k + 1;
            kids[best + 1] = bin[k].offset;
            ++n;
        }
        if (smallFirst) {
            // The any-hit walk's order: on Sponza's shadow rays smaller boxes first found blockers
            // sooner (large boxes hold the big floor and wall triangles the rays leave), while on
            // uniform meshes (the terrain) the spatial order was faster, hence only where sizes differ.
            float lo = std::numeric_limits<float>::infinity(), hi = 0;
            for (int i = 0; i < n; ++i) {
                lo = std::min(lo, surfaceArea(bin[kids[i]]));
                hi = std::max(hi, surfaceArea(bin[kids[i]]));
            }
            if (hi > 2 * lo)  // insertion sort: stable, and no allocation per node
                for (int i = 1; i < n; ++i) {
                    const std::uint32_t k = kids[i];
                    const float a = surfaceArea(bin[k]);
                    int j = i;
                    for (; j > 0 && surfaceArea(bin[kids[j - 1]]) > a; --j) kids[j] = kids[j - 1];
                    kids[j] = k;
                }
        }
        const std::uint32_t index = std::uint32_t(out.size());
        out.emplace_back();
        WideNode<N>& node = out[index];
        for (int c = 0; c < N; ++c) {
            for (int k = 0; k < 3; ++k) {
                node.bounds[k][c] = c < n ? bin[kids[c]].lo[k] : std::numeric_limits<float>::infinity();
                node.bounds[3 + k][c] = c < n ? bin[kids[c]].hi[k] : -std::numeric_limits<float>::infinity();
            }
            node.ref[c] = WideRef::kEmpty;
        }
        for (int c = 0; c < n; ++c) {
            const std::uint32_t r = refOf(kids[c]);  // may grow `out`: index, not reference
            out[index].ref[c] = r;
        }
        return index;
    }
};

}  // namespace

template <int N>
WideBvh<N> WideBvh<N>::collapse(const Bvh& binary, bool smallFirst) {
    WideBvh bvh;
    if (binary.empty()) return bvh;
    // Padding adds at most kLeafAlign − 1 slots per leaf, and a leaf holds at least one.
    if (binary.primitives().size() >= kMaxSlots / kLeafAlign)
        throw std::length_error("WideBvh: more than 2^26 primitives in one mesh");
    const std::vector<BvhNode>& bin = binary.nodes();
    bvh.nodes_.reserve(bin.size() / (N - 1) + 1);
    bvh.primitives_.reserve(binary.primitives().size() * 3 / 2);
    Collapser<N> c{bin, binary.primitives(), bvh.nodes_, bvh.primitives_, smallFirst};
    bvh.root_ = c.refOf(0);
    bvh.nodes_.shrink_to_fit();
    bvh.primitives_.shrink_to_fit();
    return bvh;
}

template <int N>
WideBvh<N> WideBvh<N>::build(const std::vector<scene::Bounds>& primitiveBounds) {
    return collapse(Bvh::build(primitiveBounds));
}

template <int N>
WideBvh<N> WideBvh<N>::buildFast(const std::vector<scene::Bounds>& primitiveBounds) {
    return collapse(Bvh::buildFast(primitiveBounds), true);
}

template <int N>
WideBvh<N> WideBvh<N>::buildFast(const std::vector<scene::Bounds>& primitiveBounds,
                                 const std::vector<Vec3T<float>>& positions,
                                 const std::vector<std::uint32_t>& indices) {
    // Pre-split references count against the slot limit: a mesh near it is built unsplit.
    if (double(primitiveBounds.size()) * (1 + kPresplitBudget) >= double(kMaxSlots / kLeafAlign))
        return buildFast(primitiveBounds);
    return collapse(Bvh::buildFast(primitiveBounds, positions, indices), true);
}

template class WideBvh<4>;
template class WideBvh<8>;

namespace detail {

namespace {
std::atomic<bool>& avxSwitch() {
    static std::atomic<bool> on{hasAvx()};
    return on;
}
}  // namespace

bool hasAvx() {
#if defined(SHADOWLAB_AVX_BOX_TEST)
    static const bool has = __builtin_cpu_supports("avx");
    return has;
#else
    return false;
#endif
}
bool hasAvx2() {
#if defined(SHADOWLAB_AVX_BOX_TEST)
    static const bool has = __builtin_cpu_supports("avx2");
    return has;
#else
    return false;
#endif
}
namespace {
std::atomic<bool> fastFloatBuildOn{true};
}  // namespace
bool fastFloatBuild() { return fastFloatBuildOn.load(std::memory_order_relaxed); }
void setFastFloatBuild(bool on) { fastFloatBuildOn.store(on, std::memory_order_relaxed); }

bool useAvx() { return avxSwitch().load(std::memory_order_relaxed); }
void setUseAvx(bool on) { avxSwitch().store(on && hasAvx(), std::memory_order_relaxed); }

namespace {
std::atomic<bool>& avx2Switch() {
    static std::atomic<bool> on{hasAvx2()};
    return on;
}
}  // namespace
bool useAvx2() { return avx2Switch().load(std::memory_order_relaxed); }
void setUseAvx2(bool on) { avx2Switch().store(on && hasAvx2(), std::memory_order_relaxed); }

}  // namespace detail

}  // namespace shadowlab::raytrace
