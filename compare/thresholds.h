// compare/thresholds.h: every tolerance compare/ uses, each with the reason for its value.
#pragma once

namespace shadowlab::compare {

// τ: visibilities disagree when they differ by more than half the 0..1 range, so a slightly
// wider or narrower penumbra (soft shadows, PCF) is not counted as a wrong shadow, while a hard
// lit/shadowed flip (|ΔV| = 1) always is. A pixel is "shadowed" when V ≤ τ (IoU, classes).
inline constexpr float kVisibilityTolerance = 0.5f;

// Object ids are integers (index + 1) stored in float channels, exact up to 2^24. Two ids match
// when they round to the same integer: a backend that stores ids through a half-float or a
// normalized format still matches, while a different object (ids differ by ≥ 1) never does.
// Id 0 (background) never counts as a match.
inline constexpr float kObjectIdRounding = 0.5f;

// A pixel counts only where N·L > 0 in BOTH frames. The reference decides whether the pixel
// faces the light; the method must agree, because a method that computed N·L ≤ 0 shades the
// pixel black whatever its shadow test says, so its visibility there is not a shadow answer.
// Zero, not an epsilon: pixels facing the light at grazing angles are exactly where acne lives
// and must stay counted. Pixels where the two disagree on the sign are reported separately
// (Metrics::ndotlSignMismatch) so nothing is hidden.
inline constexpr float kMinNdotL = 0.0f;

// Edge-aware error: a wrong pixel within this many pixels (Chebyshev distance) of a
// reference shadow boundary counts as aliasing (texel-sized stair steps of a shadow map are
// one or two pixels wide at typical map/screen ratios) rather than as bias error.
inline constexpr int kDefaultEdgeRadiusPixels = 2;

// Bias window: a bias is acceptable when both its false- and missed-shadow rates are at most
// this share of the counted pixels. 0.1% is about 500 pixels of a 1280×720 view of a floor:
// scattered that thinly, acne and leak pixels stop being visible at 1:1, while a real acne
// pattern or a detached contact shadow is well above it.
inline constexpr double kBiasWindowMaxRate = 0.001;

// Sweep summary: "good enough" for the fastest-configuration sentence is a mismatch of at most
// 1% of the counted pixels. A typical contact shadow's rim, or a shadow map's stair steps along
// a long edge, stays below it; a visible acne pattern or a detached shadow does not.
inline constexpr double kSweepGoodMismatchRate = 0.01;

// Continuous error: a counted pixel whose visibility is off by more than this, yet not by more
// than τ, is a soft-shadow error the classes cannot see (a penumbra a quarter of the range too
// light or too dark is visible, while PCF's half-texel edge blur stays well under it).
inline constexpr float kSoftErrorTolerance = 0.25f;

// Soft-shadow error is named in the findings ("dominates", "does not match") when it holds more
// than this share of the counted pixels: the bias window's 0.1%, below which scattered pixels are
// not visible at 1:1 (a 16-sample ray tracer's noise leaves a few such pixels in a penumbra).
inline constexpr double kNotableSoftErrorRate = 0.001;

// The reference's penumbra: counted pixels with kPenumbraMargin < V_R < 1 − kPenumbraMargin.
// Not exactly 0 and 1: the reference stores float, and a weighted mean of exact 0/1 answers of
// several lights can round a hair inside the range (float epsilon is 1.2e-7).
inline constexpr float kPenumbraMargin = 1e-6f;

// Light bleeding against bias leaks (docs/compare.md): a missed-shadow pixel whose reference
// blocker lies within the contact distance D of the receiver, along the shadow ray, is a bias
// leak, else bleeding. A shadow map answers a receiver with the depth of the texel it reads,
// minus the bias: the constant bias b and the slope term s·t·tanθ move the receiver that far
// toward the light, and the texel's footprint holds depths up to t·tanθ from the receiver's own,
// widened by the filter to a few texels (pcf2x2: 2, pcf 3×3: 3, the default moment blur: 5,
// whose half-width 2.5 reaches that far). So D = b + (s + kContactTexels)·t·max(1, tanθ), t the
// texel at the pixel (a spot's or cube face's grows with the distance from the light), with
// tanθ capped as the slope bias caps it: a blocker that near can be lost to the bias and the
// texel grid alone; one farther away cannot, and a lit answer there is the filter's (light
// bleeding in the moment maps) or an edge's. Four texels is the middle of those footprints; at
// the default bias (half a texel) D is 4.5 texels. A ray tracer's offset origin skips blockers
// within about its offset: D = kContactRayBiasFactor × ray bias.
inline constexpr double kContactTexels = 4.0;
inline constexpr double kContactMaxTan = 10.0;  // raster/tolerances.h kMaxSlopeTan
inline constexpr double kContactRayBiasFactor = 2.0;

// A smooth-shaded mesh's terminator (docs/compare.md, "The terminator"): a missed-shadow pixel
// whose reference blocker is the receiver's own object, seen at a reference N·L below this, is
// most likely the reference's flat facets shadowing their neighbours where the interpolated
// normal still faces the light. The shading normal strays from a facet's by up to about half the
// angle between neighbouring facets, so only there, at small N·L, can a facet face away from a
// light its shading normal faces; 0.2 (about 12 degrees from grazing) holds 70-97% of the
// self-blocked misses on the sample models' (Suzanne, the Stanford bunny, FlightHelmet,
// SciFiHelmet) default views.
inline constexpr float kTerminatorNdotL = 0.2f;

// Findings paragraph: an object or cause is named as "mostly" responsible when it holds more
// than half of a class, i.e. when it is the majority, not merely the largest share.
inline constexpr double kMostlyShare = 0.5;
// Findings paragraph: a cause short of the majority is still named when it holds a fifth of a
// class (less reads as a footnote).
inline constexpr double kNotableShare = 0.2;
// Findings paragraph: silhouettes are mentioned when they differ on more than 0.2% of the
// image. Below that it is the usual one-pixel rim where rasterization's coverage rule and a
// ray through the pixel center disagree (a sphere 600 px across has a rim of ~1900 pixels).
inline constexpr double kNotableSilhouetteRate = 0.002;

}  // namespace shadowlab::compare
