// scene/budgets.h: error budgets, the limits a CI gate holds a method's shadows to. A budget is
// data (parsed from the command line or a scene's "budgets" block); compare/gates.h checks
// Metrics against it. Syntax (docs/ci.md): a rate as a fraction ("0.005") or a percentage
// ("0.5%"), or a pixel count ("120px") for the budgets that count pixels.
#pragma once

#include <cstddef>
#include <filesystem>
#include <optional>
#include <string>
#include <vector>

#include <nlohmann/json_fwd.hpp>

#include "scene/error.h"

namespace shadowlab::scene {

struct BudgetLimit {
    enum class Unit { Rate, Pixels };
    Unit unit = Unit::Rate;
    double value = 0.0;  // Rate: a fraction in 0..1; Pixels: a whole count >= 0
    std::string text;    // as written, for messages ("0.5%", "120px")
};

// The budgets, by their option and JSON names. Each is absent unless set.
enum class BudgetKind {
    MaxMismatch,
    MaxFalseShadow,
    MaxMissedShadow,
    MaxSelfAcne,
    MaxMeanAbsDiff,
    MinIoU,
    MaxBleeding
};
inline constexpr int kBudgetKindCount = 7;
struct BudgetInfo {
    BudgetKind kind;
    const char* option;   // "--max-mismatch"
    const char* jsonKey;  // "max_mismatch"
    bool allowsPixels;    // false for the mean and the IoU, which are not pixel counts
    bool isMinimum;       // min_iou: broken when the value is below the limit
};
const BudgetInfo& budgetInfo(BudgetKind kind);

struct Budgets {
    std::optional<BudgetLimit> limits[kBudgetKindCount];
    std::optional<BudgetLimit>& operator[](BudgetKind k) { return limits[int(k)]; }
    const std::optional<BudgetLimit>& operator[](BudgetKind k) const { return limits[int(k)]; }
    bool empty() const;
    // Every limit set in `over` replaces this one's.
    Budgets overriddenBy(const Budgets& over) const;
};

// Parses one limit; throws InputError("OPTION: what is wrong") naming `where`.
BudgetLimit parseBudgetLimit(const std::string& text, BudgetKind kind, const std::string& where);
// A JSON "budgets" block (an object of jsonKey: number | "0.5%" | "120px"); throws SceneError
// naming the file and the JSON path of the bad value.
Budgets readBudgets(const std::filesystem::path& file, const nlohmann::json& node, const JsonPath& path);
// Back to JSON, as written (for reports and the per-case JSON of `check`).
nlohmann::json toJson(const Budgets& budgets);

}  // namespace shadowlab::scene
