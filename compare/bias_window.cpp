// compare/bias_window.cpp: finds the bias window (or declares the scene stiff) from sampled
// false- and missed-shadow rates.
#include "compare/bias_window.h"

#include <algorithm>
#include <cmath>

#include "compare/text.h"
#include "scene/error.h"

namespace shadowlab::compare {

namespace {

double worst(const BiasSample& s) {
    if (!std::isfinite(s.falseShadowRate) || !std::isfinite(s.missedShadowRate))
        return std::numeric_limits<double>::infinity();
    return std::max(s.falseShadowRate, s.missedShadowRate);
}

}  // namespace

BiasWindow findBiasWindow(std::vector<BiasSample> samples, double threshold) {
    if (samples.empty()) throw scene::InputError("bias window: no bias samples");
    if (!std::isfinite(threshold) || threshold < 0.0)
        throw scene::InputError("bias window: threshold must be a finite rate >= 0, got " + formatShort(threshold));
    std::stable_sort(samples.begin(), samples.end(),
                     [](const BiasSample& a, const BiasSample& b) { return a.bias < b.bias; });
    BiasWindow w;
    w.threshold = threshold;

    const auto best = std::min_element(samples.begin(), samples.end(),
                                       [](const auto& a, const auto& b) { return worst(a) < worst(b); });
    w.bestBias = best->bias;
    w.bestFalseShadowRate = best->falseShadowRate;
    w.bestMissedShadowRate = best->missedShadowRate;

    // Longest run of acceptable samples; on equal length, the one whose worst rate is lower.
    std::size_t bestStart = 0, bestLen = 0;
    double bestRunWorst = std::numeric_limits<double>::infinity();
    for (std::size_t i = 0; i < samples.size();) {
        if (!(worst(samples[i]) <= threshold)) {
            ++i;
            continue;
        }
        std::size_t j = i;
        double runWorst = 0.0;
        while (j < samples.size() && worst(samples[j]) <= threshold) runWorst = std::max(runWorst, worst(samples[j++]));
        const std::size_t len = j - i;
        if (len > bestLen || (len == bestLen && runWorst < bestRunWorst)) {
            bestStart = i;
            bestLen = len;
            bestRunWorst = runWorst;
        }
        i = j;
    }
    if (bestLen == 0) return w;  // stiff
    w.stiff = false;
    w.acceptableSamples = bestLen;
    w.lo = samples[bestStart].bias;
    w.hi = samples[bestStart + bestLen - 1].bias;
    if (bestStart > 0) w.outerLo = samples[bestStart - 1].bias;
    if (bestStart + bestLen < samples.size()) w.outerHi = samples[bestStart + bestLen].bias;
    return w;
}

std::string BiasWindow::describe() const {
    const std::string limit = "rates <= " + formatPercent(threshold);
    const std::string compromise = "best compromise bias " + formatShort(bestBias) + ": " +
                                   formatPercent(bestFalseShadowRate) + " false, " +
                                   formatPercent(bestMissedShadowRate) + " missed";
    if (stiff) return "stiff: no sampled bias keeps both " + limit + "; " + compromise;
    return "bias window " + formatShort(lo) + " .. " + formatShort(hi) + " (" + limit + ", " +
           std::to_string(acceptableSamples) + " sample" + (acceptableSamples == 1 ? "" : "s") + "); " + compromise;
}

}  // namespace shadowlab::compare
