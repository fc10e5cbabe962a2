// compare/bias_window.h: the acne–leak trade-off of one bias parameter. Too little bias gives
// false shadow (acne), too much gives missed shadow (leaks, peter-panning); the bias window is
// the range where both stay under a threshold. A scene with no such range is "stiff".
#pragma once

#include <cstddef>
#include <limits>
#include <string>
#include <vector>

#include "compare/thresholds.h"

namespace shadowlab::compare {

struct BiasSample {
    double bias = 0.0;  // in the parameter's own unit (world units, texels)
    double falseShadowRate = 0.0;
    double missedShadowRate = 0.0;
};

struct BiasWindow {
    bool stiff = true;  // no sampled bias keeps both rates under the threshold
    double threshold = kBiasWindowMaxRate;
    // The sampled acceptable range [lo, hi] (valid when !stiff): the longest run of consecutive
    // acceptable samples in bias order (ties: the run with the lower worst rate).
    double lo = 0.0, hi = 0.0;
    std::size_t acceptableSamples = 0;  // in that run
    // The true window edges lie in (outerLo, lo] and [hi, outerHi): the nearest failing
    // samples around the run, ±infinity when the run reaches the end of the sampled range.
    double outerLo = -std::numeric_limits<double>::infinity();
    double outerHi = std::numeric_limits<double>::infinity();
    // The best compromise over all samples (also when stiff): least max(false, missed).
    double bestBias = 0.0;
    double bestFalseShadowRate = 0.0, bestMissedShadowRate = 0.0;

    // "bias window 0.001 .. 0.004 (rates ≤ 0.1%)" or "stiff: ... best compromise ...".
    std::string describe() const;
};

// Samples may come in any order; non-finite rates count as failing. Throws scene::InputError
// when there is no sample or the threshold is not a finite non-negative number.
BiasWindow findBiasWindow(std::vector<BiasSample> samples, double threshold = kBiasWindowMaxRate);

}  // namespace shadowlab::compare
