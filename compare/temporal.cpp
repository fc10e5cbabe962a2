// compare/temporal.cpp: flicker, error variation and edge swimming along a path of frames; the
// definitions and their limits are in docs/temporal.md.
#include "compare/temporal.h"

#include <algorithm>
#include <cmath>
#include <string>

#include "scene/error.h"

namespace shadowlab::compare {

namespace {

constexpr float kTau = kVisibilityTolerance;

bool counts(PixelClass c) { return c != PixelClass::NotCounted && c != PixelClass::Invalid; }

// Where a shadow edge crosses an image row (horizontal) or column: the position along it, in
// pixels from the image's left or top edge, interpolated between the two pixel centers where the
// visibility passes τ; dir +1 when lit comes first (lit -> shadow going right or down), else -1.
struct Crossing {
    double pos = 0.0;
    int dir = 0;
    // The reference's crossings: the matched method offset (pixels, + = method shadow smaller).
    bool matched = false;
    double offset = 0.0;
};
// Crossings per line: rows first (index y), then columns (index height + x).
using Lines = std::vector<std::vector<Crossing>>;

Lines crossings(const std::vector<float>& v, const std::vector<PixelClass>& cls, const std::vector<float>& ids, int w,
                int h) {
    Lines lines(std::size_t(w + h));
    auto scan = [&](std::size_t line, std::size_t a, std::size_t b, double at) {
        if (!counts(cls[a]) || !counts(cls[b]) || ids[a] != ids[b]) return;  // not across silhouettes
        const bool litA = v[a] > kTau, litB = v[b] > kTau;
        if (litA == litB) return;
        const double t = std::clamp((double(kTau) - v[a]) / (double(v[b]) - v[a]), 0.0, 1.0);
        lines[line].push_back({at + 0.5 + t, litA ? 1 : -1});
    };
    for (int y = 0; y < h; ++y)
        for (int x = 0; x + 1 < w; ++x) scan(std::size_t(y), std::size_t(y) * w + x, std::size_t(y) * w + x + 1, x);
    for (int x = 0; x < w; ++x)
        for (int y = 0; y + 1 < h; ++y) scan(std::size_t(h + x), std::size_t(y) * w + x, std::size_t(y + 1) * w + x, y);
    return lines;
}

// The crossing of `line` with direction `dir` nearest to `pos` within `reach`, or nullptr.
template <class C>
C* nearest(std::vector<C>& line, double pos, int dir, double reach) {
    C* best = nullptr;
    double bestDistance = reach;
    for (C& c : line) {
        const double d = std::abs(c.pos - pos);
        if (c.dir == dir && d <= bestDistance) {
            best = &c;
            bestDistance = d;
        }
    }
    return best;
}

void checkFrame(const scene::Frame& f, const scene::Frame& first, const char* what, std::size_t t) {
    const std::size_t n = first.pixelCount();
    if (f.width != first.width || f.height != first.height || f.visibility.size() != n || f.objectId.size() != n)
        throw scene::InputError(std::string("temporal: ") + what + " frame " + std::to_string(t) +
                                " differs in size from frame 0 or lacks visibility/object_id");
}

}  // namespace

TemporalSummary measureTemporal(const std::vector<const scene::Frame*>& method,
                                const std::vector<const scene::Frame*>& reference,
                                const std::vector<const std::vector<PixelClass>*>& classes) {
    if (method.size() != reference.size() || method.size() != classes.size())
        throw scene::InputError("temporal: " + std::to_string(method.size()) + " method frames, " +
                                std::to_string(reference.size()) + " reference frames and " +
                                std::to_string(classes.size()) + " classifications: they must be as many");
    TemporalSummary s;
    s.frames = int(method.size());
    if (method.empty()) return s;
    const scene::Frame& first = *reference[0];
    const int w = first.width, h = first.height;
    const std::size_t n = first.pixelCount();
    for (std::size_t t = 0; t < method.size(); ++t) {
        checkFrame(*method[t], first, "method", t);
        checkFrame(*reference[t], first, "reference", t);
        if (classes[t]->size() != n)
            throw scene::InputError("temporal: the classification of frame " + std::to_string(t) + " has " +
                                    std::to_string(classes[t]->size()) + " pixels, not " + std::to_string(n));
    }

    // Per frame: the reference's crossings, each matched with the method's nearest.
    std::vector<Lines> refLines;
    for (std::size_t t = 0; t < method.size(); ++t) {
        Lines ref = crossings(reference[t]->visibility, *classes[t], reference[t]->objectId, w, h);
        Lines met = crossings(method[t]->visibility, *classes[t], reference[t]->objectId, w, h);
        FrameEdges e;
        double sum = 0.0, sumAbs = 0.0;
        for (std::size_t l = 0; l < ref.size(); ++l)
            for (Crossing& r : ref[l]) {
                ++e.referenceCrossings;
                if (const Crossing* m = nearest(met[l], r.pos, r.dir, kEdgeMatchPixels)) {
                    r.matched = true;
                    r.offset = (m->pos - r.pos) * r.dir;
                    ++e.matched;
                    sum += r.offset;
                    sumAbs += std::abs(r.offset);
                }
            }
        if (e.matched) {
            e.meanOffset = sum / double(e.matched);
            e.meanAbsOffset = sumAbs / double(e.matched);
        }
        s.edges.push_back(e);
        refLines.push_back(std::move(ref));
    }

    double offsetSum = 0.0;
    int offsetFrames = 0;
    for (const FrameEdges& e : s.edges)
        if (e.matched) {
            offsetSum += e.meanOffset;
            ++offsetFrames;
        }
    s.meanEdgeOffset = offsetFrames ? offsetSum / offsetFrames : 0.0;

    double rateSum = 0.0, variationSum = 0.0, swimSum = 0.0;
    int swimPairs = 0;
    for (std::size_t t = 0; t + 1 < method.size(); ++t) {
        PairStability p;
        p.first = int(t);
        const std::vector<float>&vm0 = method[t]->visibility, &vm1 = method[t + 1]->visibility;
        const std::vector<float>&vr0 = reference[t]->visibility, &vr1 = reference[t + 1]->visibility;
        double variation = 0.0;
        for (std::size_t i = 0; i < n; ++i) {
            if (!counts((*classes[t])[i]) || !counts((*classes[t + 1])[i])) continue;
            ++p.comparable;
            const bool m = (vm0[i] > kTau) != (vm1[i] > kTau);
            const bool r = (vr0[i] > kTau) != (vr1[i] > kTau);
            p.methodChanges += m;
            p.referenceChanges += r;
            p.flicker += m && !r;
            p.missedChanges += r && !m;
            const double d = std::abs(std::abs(double(vm1[i]) - vr1[i]) - std::abs(double(vm0[i]) - vr0[i]));
            variation += d;
            p.maxErrorVariation = std::max(p.maxErrorVariation, d);
        }
        if (p.comparable) {
            p.flickerRate = double(p.flicker) / double(p.comparable);
            p.errorVariation = variation / double(p.comparable);
        }
        // Swimming: each matched reference crossing of t, followed to t + 1 on its line.
        double delta = 0.0;
        for (std::size_t l = 0; l < refLines[t].size(); ++l)
            for (const Crossing& r0 : refLines[t][l]) {
                if (!r0.matched) continue;
                const Crossing* r1 = nearest(refLines[t + 1][l], r0.pos, r0.dir, kEdgeTrackPixels);
                if (!r1 || !r1->matched) continue;
                ++p.trackedEdges;
                delta += std::abs(r1->offset - r0.offset);
            }
        if (p.trackedEdges) {
            p.swimPixels = delta / double(p.trackedEdges);
            swimSum += p.swimPixels;
            ++swimPairs;
            s.maxSwimPixels = std::max(s.maxSwimPixels, p.swimPixels);
        }
        s.totalFlicker += p.flicker;
        rateSum += p.flickerRate;
        variationSum += p.errorVariation;
        s.maxFlickerRate = std::max(s.maxFlickerRate, p.flickerRate);
        s.maxErrorVariation = std::max(s.maxErrorVariation, p.maxErrorVariation);
        if (s.worstPair < 0 || p.flicker > s.pairs[std::size_t(s.worstPair)].flicker) s.worstPair = int(t);
        s.pairs.push_back(p);
    }
    if (!s.pairs.empty()) {
        s.meanFlickerRate = rateSum / double(s.pairs.size());
        s.meanErrorVariation = variationSum / double(s.pairs.size());
    }
    s.meanSwimPixels = swimPairs ? swimSum / swimPairs : 0.0;
    return s;
}

TemporalSummary measureTemporal(const std::vector<const scene::Frame*>& method,
                                const std::vector<const scene::Frame*>& reference) {
    if (method.size() != reference.size())
        throw scene::InputError("temporal: " + std::to_string(method.size()) + " method frames and " +
                                std::to_string(reference.size()) + " reference frames");
    std::vector<std::vector<PixelClass>> classes;
    for (std::size_t t = 0; t < method.size(); ++t) classes.push_back(compareFrames(*method[t], *reference[t]).classes);
    std::vector<const std::vector<PixelClass>*> pointers;
    for (const auto& c : classes) pointers.push_back(&c);
    return measureTemporal(method, reference, pointers);
}

std::vector<unsigned char> flickerMask(const scene::Frame& m0, const scene::Frame& m1, const scene::Frame& r0,
                                       const scene::Frame& r1, const std::vector<PixelClass>& c0,
                                       const std::vector<PixelClass>& c1) {
    const std::size_t n = c0.size();
    std::vector<unsigned char> mask(n, 0);
    for (std::size_t i = 0; i < n; ++i) {
        if (!counts(c0[i]) || !counts(c1[i])) continue;
        const bool m = (m0.visibility[i] > kTau) != (m1.visibility[i] > kTau);
        const bool r = (r0.visibility[i] > kTau) != (r1.visibility[i] > kTau);
        mask[i] = m && !r;
    }
    return mask;
}

nlohmann::json toJson(const PairStability& p) {
    return {{"first", p.first},
            {"comparable", p.comparable},
            {"method_changes", p.methodChanges},
            {"reference_changes", p.referenceChanges},
            {"flicker", p.flicker},
            {"missed_changes", p.missedChanges},
            {"flicker_rate", p.flickerRate},
            {"error_variation", p.errorVariation},
            {"max_error_variation", p.maxErrorVariation},
            {"tracked_edges", p.trackedEdges},
            {"swim_px", p.swimPixels}};
}

nlohmann::json toJson(const TemporalSummary& s) {
    nlohmann::json pairs = nlohmann::json::array(), edges = nlohmann::json::array();
    for (const PairStability& p : s.pairs) pairs.push_back(toJson(p));
    for (const FrameEdges& e : s.edges)
        edges.push_back({{"reference_crossings", e.referenceCrossings},
                         {"matched", e.matched},
                         {"mean_offset_px", e.meanOffset},
                         {"mean_abs_offset_px", e.meanAbsOffset}});
    return {{"frames", s.frames},
            {"total_flicker", s.totalFlicker},
            {"mean_flicker_rate", s.meanFlickerRate},
            {"max_flicker_rate", s.maxFlickerRate},
            {"worst_pair", s.worstPair},
            {"mean_error_variation", s.meanErrorVariation},
            {"max_error_variation", s.maxErrorVariation},
            {"mean_swim_px", s.meanSwimPixels},
            {"max_swim_px", s.maxSwimPixels},
            {"mean_edge_offset_px", s.meanEdgeOffset},
            {"pairs", pairs},
            {"edges", edges}};
}

}  // namespace shadowlab::compare
