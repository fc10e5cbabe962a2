// tests/compare/gates_test.cpp: budgets against hand-set metrics: which break, in which unit,
// at the limit itself, and the cases that cannot be measured.
#include "compare/gates.h"

#include <gtest/gtest.h>

#include "scene/error.h"

namespace shadowlab::compare {
namespace {

using scene::BudgetKind;

// 1000 counted pixels: 30 false shadows (20 of them self acne), 10 missed: mismatch 4%.
Metrics someMetrics() {
    Metrics m;
    m.counted = 1000;
    m.falseShadow = 30;
    m.missedShadow = 10;
    m.falseShadowRate = 0.03;
    m.missedShadowRate = 0.01;
    m.mismatchRate = 0.04;
    m.hasBlockerIds = true;
    m.selfShadowAcne = 20;
    m.selfShadowAcneRate = 0.02;
    m.meanAbsVisibilityError = 0.035;
    m.shadowIoU = 0.9;
    return m;
}

scene::Budgets budgets(std::initializer_list<std::pair<BudgetKind, const char*>> items) {
    scene::Budgets b;
    for (const auto& [k, text] : items) b[k] = scene::parseBudgetLimit(text, k, scene::budgetInfo(k).option);
    return b;
}

TEST(Gates, EachBudgetBreaksAboveItsLimitAndHoldsAtIt) {
    const Metrics m = someMetrics();
    // Exactly at the limit holds; one step beyond breaks.
    const auto at = checkBudgets(m, budgets({{BudgetKind::MaxMismatch, "4%"},
                                             {BudgetKind::MaxFalseShadow, "30px"},
                                             {BudgetKind::MaxMissedShadow, "0.01"},
                                             {BudgetKind::MaxSelfAcne, "20px"},
                                             {BudgetKind::MaxMeanAbsDiff, "0.035"},
                                             {BudgetKind::MinIoU, "0.9"}}));
    ASSERT_EQ(at.size(), 6u);
    EXPECT_FALSE(anyBroken(at));
    const auto beyond = checkBudgets(m, budgets({{BudgetKind::MaxMismatch, "3.9%"},
                                                 {BudgetKind::MaxFalseShadow, "29px"},
                                                 {BudgetKind::MaxMissedShadow, "0.0099"},
                                                 {BudgetKind::MaxSelfAcne, "19px"},
                                                 {BudgetKind::MaxMeanAbsDiff, "0.034"},
                                                 {BudgetKind::MinIoU, "0.91"}}));
    for (const BudgetCheck& c : beyond) EXPECT_TRUE(c.broken) << describe(c);
    EXPECT_EQ(describe(beyond[1]), "--max-false-shadow: 3.00% (30 px) > limit 29px: BROKEN");
    EXPECT_EQ(describe(beyond[5]), "--min-iou: 0.9000 < limit 0.91: BROKEN");
    EXPECT_EQ(beyond[1].measured, 30.0);  // in the limit's unit: pixels
    const nlohmann::json j = toJson(beyond);
    EXPECT_EQ(j[0]["budget"], "max_mismatch");
    EXPECT_EQ(j[0]["limit"], "3.9%");
    EXPECT_EQ(j[0]["broken"], true);
}

TEST(Gates, NoBudgetNoCheckAndNothingCountedBreaks) {
    EXPECT_TRUE(checkBudgets(someMetrics(), {}).empty());
    Metrics empty;  // a comparison of mismatched views counts nothing: all rates 0
    const auto checks = checkBudgets(empty, budgets({{BudgetKind::MaxMismatch, "1%"}}));
    ASSERT_EQ(checks.size(), 2u);
    EXPECT_TRUE(checks[0].nothingCounted);
    EXPECT_TRUE(anyBroken(checks));
    EXPECT_FALSE(checks[1].broken);
}

TEST(Gates, BleedingBudgetNeedsTheBlockerDistancesAndCountsBleeding) {
    Metrics m = someMetrics();
    m.hasBlockerDistance = false;
    EXPECT_THROW(checkBudgets(m, budgets({{BudgetKind::MaxBleeding, "1%"}})), scene::InputError);
    m.hasBlockerDistance = true;
    m.bleeding = 30;
    m.bleedingRate = 30.0 / double(m.counted);
    const auto within = checkBudgets(m, budgets({{BudgetKind::MaxBleeding, "30px"}}));
    ASSERT_EQ(within.size(), 1u);
    EXPECT_FALSE(within[0].broken);
    EXPECT_TRUE(anyBroken(checkBudgets(m, budgets({{BudgetKind::MaxBleeding, "29px"}}))));
    EXPECT_EQ(scene::budgetInfo(BudgetKind::MaxBleeding).jsonKey, std::string("max_bleeding"));
}

TEST(Gates, SelfAcneBudgetWithoutBlockerIdsIsBadInput) {
    Metrics m = someMetrics();
    m.hasBlockerIds = false;
    EXPECT_THROW(checkBudgets(m, budgets({{BudgetKind::MaxSelfAcne, "1%"}})), scene::InputError);
}

}  // namespace
}  // namespace shadowlab::compare
