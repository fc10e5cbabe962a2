// studies/analytic.h: a closed-form oracle for scenes of spheres, quads and boxes under
// directional lights: per pixel the primary hit and the hard-shadow visibility, computed in
// long double relative to the camera, independent of raytrace/. The stability suite checks the
// reference against it (docs/stability.md).
#pragma once

#include <cstddef>
#include <cstdint>
#include <optional>
#include <string>
#include <vector>

#include "scene/frame.h"
#include "scene/scene.h"

namespace shadowlab::studies {

// Knife-edge margins of the oracle. A pixel whose answer would flip if a length moved by less
// than this is not judged: the double reference may round either way there.
// Relative to the scene's bounding-box diagonal: 1e-7 is ~1e9 double ulps of the scene's size,
// far above any rounding a double tracer makes, and far below a pixel's footprint at the
// resolutions we run (a pixel of a 20-unit scene at 1280 wide is ~1e-2).
inline constexpr long double kKnifeRelative = 1e-7L;
// Absolute positions are rounded to double before anyone sees them: a margin of 64 double ulps
// of the largest coordinate covers the far-from-origin cases (1e7 → 1.5e-7).
inline constexpr long double kKnifeCoordinateUlps = 64.0L * 2.220446049250313e-16L;
// |N·L| below this is a terminator pixel: the sign of N·L is not decided reliably.
inline constexpr long double kKnifeNdotL = 1e-9L;

struct AnalyticFrame {
    int width = 0, height = 0;
    std::vector<int> objectId;  // 0 = background, else object index + 1
    // Weighted visibility as raytrace/ defines the AOV: Σ w·v / Σ w with w = irradiance·N·L
    // over the lights with N·L > 0; 0 where no light faces the point. Exactly 0 or 1 for one light.
    std::vector<float> visibility;
    std::vector<float> ndotl;  // max over lights, 0 on background
    // True where the visibility is meaningful (a hit with N·L > kKnifeNdotL for some light).
    std::vector<std::uint8_t> lit;
    // True where the primary hit or a shadow test is within the margin of flipping.
    std::vector<std::uint8_t> knifeEdge;
    std::size_t pixelCount() const { return std::size_t(width) * std::size_t(height); }
};

// Why a scene has no analytic answer ("mesh 'slivers'", "point light 0", ...); empty when it
// has one.
std::string whyNotAnalytic(const scene::Scene& scene);

// The oracle at the scene camera's resolution, or nullopt when the scene is not analytic
// (meshes, point or spot lights, area lights, semi-transparent materials, no lights).
std::optional<AnalyticFrame> analyticAnswer(const scene::Scene& scene);

struct AnalyticCheck {
    std::size_t pixels = 0;
    std::size_t knifeEdgePixels = 0;
    std::size_t objectIdMismatches = 0;    // outside knife edges
    std::size_t visibilityCompared = 0;    // lit pixels with matching ids outside knife edges
    std::size_t visibilityMismatches = 0;  // (V_ref > 0.5) != (V_analytic > 0.5) there
    std::size_t nonFinite = 0;             // reference NaN/Inf where the oracle judges
    int firstX = -1, firstY = -1;          // the first mismatching pixel, -1 when none
    bool passed() const { return objectIdMismatches == 0 && visibilityMismatches == 0 && nonFinite == 0; }
    std::string summary() const;
};

// Throws scene::InputError when the reference's size differs from the oracle's or a channel is
// missing.
AnalyticCheck checkAgainstAnalytic(const scene::Frame& reference, const AnalyticFrame& answer);

}  // namespace shadowlab::studies
