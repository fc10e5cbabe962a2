// scene/budgets.cpp: the budget syntax, shared by the command line, scene files and suites.
#include "scene/budgets.h"

#include <cmath>
#include <cstdlib>

#include <nlohmann/json.hpp>

namespace shadowlab::scene {

namespace {

constexpr BudgetInfo kBudgets[kBudgetKindCount] = {
    {BudgetKind::MaxMismatch, "--max-mismatch", "max_mismatch", true, false},
    {BudgetKind::MaxFalseShadow, "--max-false-shadow", "max_false_shadow", true, false},
    {BudgetKind::MaxMissedShadow, "--max-missed-shadow", "max_missed_shadow", true, false},
    {BudgetKind::MaxSelfAcne, "--max-self-acne", "max_self_acne", true, false},
    {BudgetKind::MaxMeanAbsDiff, "--max-mean-abs-diff", "max_mean_abs_diff", false, false},
    {BudgetKind::MinIoU, "--min-iou", "min_iou", false, true},
    {BudgetKind::MaxBleeding, "--max-bleeding", "max_bleeding", true, false},
};

// A decimal number filling all of `s` (strtod also takes "inf", "nan" and hex: all rejected
// by the range checks or the character check).
bool parseNumber(const std::string& s, double& out) {
    if (s.empty() || s.find_first_not_of("0123456789.eE+-") != std::string::npos) return false;
    char* end = nullptr;
    out = std::strtod(s.c_str(), &end);
    return end == s.c_str() + s.size() && std::isfinite(out);
}

}  // namespace

const BudgetInfo& budgetInfo(BudgetKind kind) { return kBudgets[int(kind)]; }

bool Budgets::empty() const {
    for (const auto& l : limits)
        if (l) return false;
    return true;
}

Budgets Budgets::overriddenBy(const Budgets& over) const {
    Budgets b = *this;
    for (int k = 0; k < kBudgetKindCount; ++k)
        if (over.limits[k]) b.limits[k] = over.limits[k];
    return b;
}

BudgetLimit parseBudgetLimit(const std::string& text, BudgetKind kind, const std::string& where) {
    const BudgetInfo& info = budgetInfo(kind);
    auto fail = [&](const std::string& what) -> BudgetLimit {
        throw InputError(where + ": " + what + ", got '" + text + "'");
    };
    BudgetLimit l;
    l.text = text;
    double v = 0.0;
    if (text.size() > 2 && text.compare(text.size() - 2, 2, "px") == 0) {
        if (!info.allowsPixels)
            return fail(std::string("is not a pixel count; give a ") +
                        (info.isMinimum ? "ratio" : "mean visibility difference") + " in 0..1 or a percentage");
        const std::string digits = text.substr(0, text.size() - 2);
        if (digits.find_first_not_of("0123456789") != std::string::npos || digits.size() > 15)
            return fail("expected a whole number of pixels such as 120px");
        l.unit = BudgetLimit::Unit::Pixels;
        l.value = std::strtod(digits.c_str(), nullptr);
        return l;
    }
    if (!text.empty() && text.back() == '%') {
        if (!parseNumber(text.substr(0, text.size() - 1), v) || v < 0.0 || v > 100.0)
            return fail("expected a percentage in 0..100% such as 0.5%");
        l.value = v / 100.0;
        return l;
    }
    if (!parseNumber(text, v) || v < 0.0 || v > 1.0)
        return fail(info.allowsPixels ? "expected a rate in 0..1 (0.005), a percentage (0.5%) or pixels (120px)"
                                      : "expected a value in 0..1 (0.005) or a percentage (0.5%)");
    l.value = v;
    return l;
}

Budgets readBudgets(const std::filesystem::path& file, const nlohmann::json& node, const JsonPath& path) {
    if (!node.is_object()) throw SceneError(file, path, "expected an object of budgets");
    Budgets b;
    for (const auto& [key, value] : node.items()) {
        const BudgetInfo* info = nullptr;
        for (const BudgetInfo& i : kBudgets)
            if (key == i.jsonKey) info = &i;
        if (!info) {
            std::string allowed;
            for (const BudgetInfo& i : kBudgets) allowed += (allowed.empty() ? "" : ", ") + std::string(i.jsonKey);
            throw SceneError(file, path / key, "unknown budget; allowed here: " + allowed);
        }
        std::string text;
        if (value.is_string()) {
            text = value.get<std::string>();
        } else if (value.is_number()) {
            text = value.dump();
        } else {
            throw SceneError(file, path / key,
                             "expected a number or a string such as \"0.5%\" or \"120px\", got " + value.dump());
        }
        try {
            b[info->kind] = parseBudgetLimit(text, info->kind, "budget");
        } catch (const InputError& e) {
            std::string what = e.what();
            what = what.substr(what.find(": ") + 2);  // "budget: " is said by the JSON path
            throw SceneError(file, path / key, what);
        }
    }
    return b;
}

nlohmann::json toJson(const Budgets& budgets) {
    nlohmann::json j = nlohmann::json::object();
    for (const BudgetInfo& i : kBudgets)
        if (budgets[i.kind]) j[i.jsonKey] = budgets[i.kind]->text;
    return j;
}

}  // namespace shadowlab::scene
