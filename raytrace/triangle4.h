// raytrace/triangle4.h: four float triangles in structure-of-arrays order and an SSE filter
// that runs the watertight test (intersect.h) on all four at once; the lanes it cannot reject
// are decided by the scalar test, so results are the scalar test's, bit for bit.
#pragma once

#include <cstdint>

#if defined(__SSE2__)
#include <emmintrin.h>
#endif

#include "raytrace/intersect.h"

namespace shadowlab::raytrace {

// v[3·vertex + axis][lane]: one row of four lanes is one 16-byte load, so the per-ray axis
// permutation of the watertight test is a choice of rows, not a shuffle. Unused lanes hold NaN.
struct alignas(16) TrianglePacket {
    float v[9][4];

    Vec3T<float> vertex(int lane, int k) const { return {v[3 * k][lane], v[3 * k + 1][lane], v[3 * k + 2][lane]}; }
};
static_assert(sizeof(TrianglePacket) == 144, "TrianglePacket: 36 bytes per triangle");

// Per-ray constants of the packet test, made once per ray (Woop et al.'s kx, ky, kz and shear).
struct Triangle4Ray {
#if defined(__SSE2__)
    __m128 o[3];  // origin, already permuted: o[0] = o[kx], o[1] = o[ky], o[2] = o[kz]
    __m128 sx, sy, sz;
#endif
    int row[3];  // kx, ky, kz

    explicit Triangle4Ray(const Ray<float>& r) {
        row[0] = r.kx;
        row[1] = r.ky;
        row[2] = r.kz;
#if defined(__SSE2__)
        for (int i = 0; i < 3; ++i) o[i] = _mm_set1_ps(r.o[row[i]]);
        sx = _mm_set1_ps(r.sx);
        sy = _mm_set1_ps(r.sy);
        sz = _mm_set1_ps(r.sz);
#endif
    }
};

// What the packet test found for four lanes. `pass`: lanes that pass the watertight test's edge,
// determinant and t-range checks with the same float operations in the same order as the
// scalar intersectTriangle (no FMA: SSE2 has none, and the compiler contracts nothing without
// -mfma), so for those lanes t = t[l] and bᵢ = e[i][l]·invDet[l] are the scalar test's values bit
// for bit. `zeroEdge`: lanes with an edge function exactly 0, which the scalar test recomputes in
// double, so only it can decide them. Both are masked by `valid`.
struct Triangle4Result {
    int pass = 0;
    int zeroEdge = 0;
    alignas(16) float t[4];
    alignas(16) float e[3][4];
    alignas(16) float invDet[4];
};

inline void triangle4Test(const Triangle4Ray& r, const TrianglePacket& p, float tMax, int valid, Triangle4Result& out) {
#if defined(__SSE2__)
    auto load = [&](int vertex, int k) { return _mm_load_ps(p.v[3 * vertex + r.row[k]]); };
    // a = p0 − o, b = p1 − o, c = p2 − o, permuted, then sheared: x += sx·z, y += sy·z.
    __m128 az = _mm_sub_ps(load(0, 2), r.o[2]);
    __m128 bz = _mm_sub_ps(load(1, 2), r.o[2]);
    __m128 cz = _mm_sub_ps(load(2, 2), r.o[2]);
    const __m128 ax = _mm_add_ps(_mm_sub_ps(load(0, 0), r.o[0]), _mm_mul_ps(r.sx, az));
    const __m128 ay = _mm_add_ps(_mm_sub_ps(load(0, 1), r.o[1]), _mm_mul_ps(r.sy, az));
    const __m128 bx = _mm_add_ps(_mm_sub_ps(load(1, 0), r.o[0]), _mm_mul_ps(r.sx, bz));
    const __m128 by = _mm_add_ps(_mm_sub_ps(load(1, 1), r.o[1]), _mm_mul_ps(r.sy, bz));
    const __m128 cx = _mm_add_ps(_mm_sub_ps(load(2, 0), r.o[0]), _mm_mul_ps(r.sx, cz));
    const __m128 cy = _mm_add_ps(_mm_sub_ps(load(2, 1), r.o[1]), _mm_mul_ps(r.sy, cz));
    const __m128 e0 = _mm_sub_ps(_mm_mul_ps(bx, cy), _mm_mul_ps(by, cx));
    const __m128 e1 = _mm_sub_ps(_mm_mul_ps(cx, ay), _mm_mul_ps(cy, ax));
    const __m128 e2 = _mm_sub_ps(_mm_mul_ps(ax, by), _mm_mul_ps(ay, bx));
    const __m128 zero = _mm_setzero_ps();
    const int zeroEdge =
        _mm_movemask_ps(_mm_or_ps(_mm_or_ps(_mm_cmpeq_ps(e0, zero), _mm_cmpeq_ps(e1, zero)), _mm_cmpeq_ps(e2, zero)));
    const __m128 anyNeg = _mm_or_ps(_mm_or_ps(_mm_cmplt_ps(e0, zero), _mm_cmplt_ps(e1, zero)), _mm_cmplt_ps(e2, zero));
    const __m128 anyPos = _mm_or_ps(_mm_or_ps(_mm_cmpgt_ps(e0, zero), _mm_cmpgt_ps(e1, zero)), _mm_cmpgt_ps(e2, zero));
    const __m128 det = _mm_add_ps(_mm_add_ps(e0, e1), e2);
    az = _mm_mul_ps(az, r.sz);
    bz = _mm_mul_ps(bz, r.sz);
    cz = _mm_mul_ps(cz, r.sz);
    const __m128 tScaled = _mm_add_ps(_mm_add_ps(_mm_mul_ps(e0, az), _mm_mul_ps(e1, bz)), _mm_mul_ps(e2, cz));
    const __m128 tMaxDet = _mm_mul_ps(_mm_set1_ps(tMax), det);
    // det < 0: need tScaled < 0 and tScaled >= tMax·det; det > 0: tScaled > 0, <= tMax·det.
    const __m128 okNeg =
        _mm_and_ps(_mm_cmplt_ps(det, zero), _mm_and_ps(_mm_cmplt_ps(tScaled, zero), _mm_cmpge_ps(tScaled, tMaxDet)));
    const __m128 okPos =
        _mm_and_ps(_mm_cmpgt_ps(det, zero), _mm_and_ps(_mm_cmpgt_ps(tScaled, zero), _mm_cmple_ps(tScaled, tMaxDet)));
    const __m128 inside = _mm_andnot_ps(_mm_and_ps(anyNeg, anyPos), _mm_or_ps(okNeg, okPos));
    out.zeroEdge = zeroEdge & valid;
    out.pass = _mm_movemask_ps(inside) & valid & ~zeroEdge;
    if (out.pass == 0) return;  // most packets: no lane left, no division needed
    const __m128 invDet = _mm_div_ps(_mm_set1_ps(1.0f), det);
    const __m128 t = _mm_mul_ps(tScaled, invDet);
    const __m128 tOk = _mm_and_ps(_mm_cmpgt_ps(t, zero), _mm_cmplt_ps(t, _mm_set1_ps(tMax)));
    out.pass &= _mm_movemask_ps(tOk);
    if (out.pass != 0) {
        _mm_store_ps(out.t, t);
        _mm_store_ps(out.e[0], e0);
        _mm_store_ps(out.e[1], e1);
        _mm_store_ps(out.e[2], e2);
        _mm_store_ps(out.invDet, invDet);
    }
#else
    (void)r;
    (void)p;
    (void)tMax;
    out.pass = 0;
    out.zeroEdge = valid;  // no packet test: the scalar test decides every lane
#endif
}

// Returns the lanes of `valid` the scalar intersectTriangle must still decide: those that pass
// the packet test (triangle4Test) plus those with an edge function exactly 0. Every lane the
// scalar test accepts is therefore returned; most misses are rejected here, four at a time.
inline int triangle4Candidates(const Triangle4Ray& r, const TrianglePacket& p, float tMax, int valid) {
    Triangle4Result res;
    triangle4Test(r, p, tMax, valid, res);
    return res.pass | res.zeroEdge;
}

}  // namespace shadowlab::raytrace
