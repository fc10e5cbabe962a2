// compare/gates.h: holds a comparison's Metrics to error budgets (scene/budgets.h), the check a
// CI gate makes. Each budget set gives one BudgetCheck with the measured value and the limit.
#pragma once

#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "compare/compare.h"
#include "scene/budgets.h"

namespace shadowlab::compare {

struct BudgetCheck {
    scene::BudgetKind kind = scene::BudgetKind::MaxMismatch;
    scene::BudgetLimit limit;
    double measured = 0.0;     // a rate, a pixel count or a ratio, in the limit's unit
    std::string measuredText;  // "38.2% (12,034 px)", "0.981"
    bool broken = false;
    bool nothingCounted = false;  // the "counted" check: no pixel counted at all
};

// Every budget set in `budgets`, in BudgetKind order. Throws scene::InputError when a budget
// cannot be measured (a self-acne budget on a method frame without blocker ids). With any budget
// set, a comparison with no counted pixel breaks the gate: an empty measurement proves nothing
// (a wrong camera or scene counts no pixel), reported as a "counted" check.
std::vector<BudgetCheck> checkBudgets(const Metrics& metrics, const scene::Budgets& budgets);
bool anyBroken(const std::vector<BudgetCheck>& checks);
// "--max-mismatch: 38.2% (12,034 px) > limit 0.5%: BROKEN" or "... <= limit ...: ok".
std::string describe(const BudgetCheck& check);
nlohmann::json toJson(const std::vector<BudgetCheck>& checks);

}  // namespace shadowlab::compare
