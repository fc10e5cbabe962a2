// compare/gates.cpp: budgets against metrics.
#include "compare/gates.h"

#include "compare/text.h"
#include "scene/error.h"

namespace shadowlab::compare {

namespace {

using scene::BudgetKind;
using scene::BudgetLimit;

struct Measured {
    double rate = 0.0;
    std::size_t pixels = 0;
    bool isRate = true;  // false: a mean or a ratio that is not a share of pixels
};

Measured measure(const Metrics& m, BudgetKind kind) {
    switch (kind) {
        case BudgetKind::MaxMismatch: return {m.mismatchRate, m.falseShadow + m.missedShadow};
        case BudgetKind::MaxFalseShadow: return {m.falseShadowRate, m.falseShadow};
        case BudgetKind::MaxMissedShadow: return {m.missedShadowRate, m.missedShadow};
        case BudgetKind::MaxSelfAcne: return {m.selfShadowAcneRate, m.selfShadowAcne};
        case BudgetKind::MaxMeanAbsDiff: return {m.meanAbsVisibilityError, 0, false};
        case BudgetKind::MinIoU: return {m.shadowIoU, 0, false};
        case BudgetKind::MaxBleeding: return {m.bleedingRate, m.bleeding};
    }
    return {};
}

}  // namespace

std::vector<BudgetCheck> checkBudgets(const Metrics& m, const scene::Budgets& budgets) {
    std::vector<BudgetCheck> out;
    if (budgets.empty()) return out;
    if (budgets[BudgetKind::MaxSelfAcne] && !m.hasBlockerIds)
        throw scene::InputError(
            "--max-self-acne: the method frame has no blocker_id channel, so its self-shadow "
            "acne cannot be told from other false shadows (use --max-false-shadow)");
    if (budgets[BudgetKind::MaxBleeding] && !m.hasBlockerDistance)
        throw scene::InputError(
            "--max-bleeding: the reference frame has no blocker_distance channel (rendered before "
            "it was written?) or the method frame no bias and texel size, so light bleeding cannot "
            "be told from bias leaks (render the reference again, or use --max-missed-shadow)");
    if (m.counted == 0) {
        BudgetCheck c;
        c.kind = BudgetKind::MaxMismatch;
        c.limit = {BudgetLimit::Unit::Pixels, 1.0, "at least 1 counted pixel"};
        c.nothingCounted = true;
        c.measuredText = "no counted pixel (different scene or camera?)";
        c.broken = true;
        out.push_back(c);
    }
    for (int k = 0; k < scene::kBudgetKindCount; ++k) {
        const auto kind = BudgetKind(k);
        if (!budgets[kind]) continue;
        const Measured v = measure(m, kind);
        BudgetCheck c;
        c.kind = kind;
        c.limit = *budgets[kind];
        const bool pixels = c.limit.unit == BudgetLimit::Unit::Pixels;
        c.measured = pixels ? double(v.pixels) : v.rate;
        c.broken = scene::budgetInfo(kind).isMinimum ? c.measured < c.limit.value : c.measured > c.limit.value;
        c.measuredText =
            v.isRate ? formatPercent(v.rate) + " (" + formatCount(v.pixels) + " px)" : formatFixed(v.rate, 4);
        out.push_back(c);
    }
    return out;
}

bool anyBroken(const std::vector<BudgetCheck>& checks) {
    for (const BudgetCheck& c : checks)
        if (c.broken) return true;
    return false;
}

std::string describe(const BudgetCheck& c) {
    if (c.nothingCounted) return "counted: " + c.measuredText + ": BROKEN";
    const bool minimum = scene::budgetInfo(c.kind).isMinimum;
    const char* relation = c.broken ? (minimum ? " < " : " > ") : (minimum ? " >= " : " <= ");
    return std::string(scene::budgetInfo(c.kind).option) + ": " + c.measuredText + relation + "limit " + c.limit.text +
           (c.broken ? ": BROKEN" : ": ok");
}

nlohmann::json toJson(const std::vector<BudgetCheck>& checks) {
    nlohmann::json a = nlohmann::json::array();
    for (const BudgetCheck& c : checks) {
        a.push_back({{"budget", c.nothingCounted ? "counted" : scene::budgetInfo(c.kind).jsonKey},
                     {"limit", c.limit.text},
                     {"unit", c.limit.unit == BudgetLimit::Unit::Pixels ? "px" : "rate"},
                     {"measured", c.measured},
                     {"measured_text", c.measuredText},
                     {"broken", c.broken}});
    }
    return a;
}

}  // namespace shadowlab::compare
