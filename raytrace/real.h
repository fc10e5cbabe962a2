// raytrace/real.h: numeric building blocks of the Real-templated tracer (float for the method,
// double for the reference): vectors, the γ(n) rounding-error bound, outward rounding and a
// small interval type used by the conservative (robust) intersection tests.
#pragma once

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <limits>

#include <glm/glm.hpp>

namespace shadowlab::raytrace {

template <typename Real>
using Vec3T = glm::vec<3, Real, glm::defaultp>;

// Unit roundoff u = ε/2: the largest relative error of one correctly rounded operation.
template <typename Real>
constexpr Real unitRoundoff() {
    return std::numeric_limits<Real>::epsilon() * Real(0.5);
}

// γ(n) = n·u / (1 − n·u) bounds the relative error of a value that went through n roundings
// (Higham, "Accuracy and Stability of Numerical Algorithms", 2nd ed., lemma 3.1; pbrt-v4 uses
// the same function, src/pbrt/util/float.h `gamma`). Evaluated in double and nudged up by two
// ulps of Real so the bound itself is never too small; constexpr so it folds away.
template <typename Real>
constexpr Real gamma(int n) {
    const double nu = n * double(unitRoundoff<Real>());
    const double g = nu / (1.0 - nu);
    return Real(g) * (Real(1) + 2 * std::numeric_limits<Real>::epsilon());
}

template <typename Real>
inline Real nextUp(Real x) {
    return std::nextafter(x, std::numeric_limits<Real>::infinity());
}
template <typename Real>
inline Real nextDown(Real x) {
    return std::nextafter(x, -std::numeric_limits<Real>::infinity());
}

// Converts a double to float (or double) rounding toward -inf / +inf, so that converted
// bounds still contain everything the double bounds contained.
template <typename Real>
inline Real roundDown(double x) {
    Real r = Real(x);
    if (double(r) > x) r = nextDown(r);
    return r;
}
template <typename Real>
inline Real roundUp(double x) {
    Real r = Real(x);
    if (double(r) < x) r = nextUp(r);
    return r;
}

template <typename Real>
inline Real maxComponent(const Vec3T<Real>& v) {
    return std::max({v.x, v.y, v.z});
}
template <typename Real>
inline int maxDimension(const Vec3T<Real>& v) {
    return (v.x > v.y) ? (v.x > v.z ? 0 : 2) : (v.y > v.z ? 1 : 2);
}

// A closed interval [lo, hi] that contains the exact result of the operations that produced
// it: every operation rounds its bounds one ulp outward (pbrt-v4's Interval does the same,
// src/pbrt/util/float.h). Only the robust mode's sphere test uses it, so speed is secondary.
template <typename Real>
struct Interval {
    Real lo = 0;
    Real hi = 0;

    Interval() = default;
    explicit Interval(Real v) : lo(v), hi(v) {}
    Interval(Real l, Real h) : lo(l), hi(h) {}

    Real mid() const { return (lo + hi) / 2; }
    Real lower() const { return lo; }
    Real upper() const { return hi; }

    friend Interval operator+(Interval a, Interval b) { return {nextDown(a.lo + b.lo), nextUp(a.hi + b.hi)}; }
    friend Interval operator-(Interval a, Interval b) { return {nextDown(a.lo - b.hi), nextUp(a.hi - b.lo)}; }
    friend Interval operator-(Interval a) { return {-a.hi, -a.lo}; }
    friend Interval operator*(Interval a, Interval b) {
        const Real p[4] = {a.lo * b.lo, a.lo * b.hi, a.hi * b.lo, a.hi * b.hi};
        return {nextDown(std::min({p[0], p[1], p[2], p[3]})), nextUp(std::max({p[0], p[1], p[2], p[3]}))};
    }
    friend Interval operator/(Interval a, Interval b) {
        if (b.lo <= 0 && b.hi >= 0)
            return {-std::numeric_limits<Real>::infinity(), std::numeric_limits<Real>::infinity()};
        const Real q[4] = {a.lo / b.lo, a.lo / b.hi, a.hi / b.lo, a.hi / b.hi};
        return {nextDown(std::min({q[0], q[1], q[2], q[3]})), nextUp(std::max({q[0], q[1], q[2], q[3]}))};
    }
};

template <typename Real>
inline Interval<Real> sqrOf(Interval<Real> a) {
    const Real l2 = a.lo * a.lo, h2 = a.hi * a.hi;
    if (a.lo >= 0) return {nextDown(l2), nextUp(h2)};
    if (a.hi <= 0) return {nextDown(h2), nextUp(l2)};
    return {Real(0), nextUp(std::max(l2, h2))};
}
template <typename Real>
inline Interval<Real> sqrtOf(Interval<Real> a) {
    return {std::max(Real(0), nextDown(std::sqrt(std::max(Real(0), a.lo)))),
            nextUp(std::sqrt(std::max(Real(0), a.hi)))};
}

// Plain numbers behave as zero-width intervals, so one template serves both test modes.
inline float sqrOf(float v) { return v * v; }
inline double sqrOf(double v) { return v * v; }
inline float sqrtOf(float v) { return std::sqrt(v); }
inline double sqrtOf(double v) { return std::sqrt(v); }
inline float lowerOf(float v) { return v; }
inline double lowerOf(double v) { return v; }
inline float upperOf(float v) { return v; }
inline double upperOf(double v) { return v; }
inline float midOf(float v) { return v; }
inline double midOf(double v) { return v; }
template <typename Real>
inline Real lowerOf(const Interval<Real>& v) {
    return v.lo;
}
template <typename Real>
inline Real upperOf(const Interval<Real>& v) {
    return v.hi;
}
template <typename Real>
inline Real midOf(const Interval<Real>& v) {
    return v.mid();
}

// Deterministic per-pixel random numbers (SplitMix64, Steele et al. 2014): renders are
// reproducible and independent of the thread schedule.
struct Rng {
    std::uint64_t state;
    explicit Rng(std::uint64_t seed) : state(seed) {}
    std::uint64_t next() {
        std::uint64_t z = (state += 0x9E3779B97F4A7C15ull);
        z = (z ^ (z >> 30)) * 0xBF58476D1CE4E5B9ull;
        z = (z ^ (z >> 27)) * 0x94D049BB133111EBull;
        return z ^ (z >> 31);
    }
    double uniform() { return double(next() >> 11) * 0x1.0p-53; }  // [0, 1)
};

}  // namespace shadowlab::raytrace
