// studies/check.h: a check suite, the CI gate over many cases: each case (a scene, a backend,
// settings, budgets) is rendered, compared with the reference, held to its budgets and to a
// stored baseline of its metrics. Suites and baselines are JSON (docs/ci.md); the app writes
// JUnit XML, a Markdown table and one JSON per case (check_report.h).
#pragma once

#include <filesystem>
#include <functional>
#include <map>
#include <optional>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "compare/compare.h"
#include "compare/gates.h"
#include "scene/budgets.h"
#include "scene/scene.h"
#include "studies/shard.h"

namespace shadowlab::studies {

// How far a metric may move the wrong way from its baseline before the case fails. Absolute:
// the same program renders the same suite bit for bit on one machine; the slack is for other
// CPUs, compilers and Mesa versions, whose float rounding moves a few pixels along shadow edges.
struct CheckTolerance {
    double rate = 0.002;         // false-, missed-shadow, mismatch and self-acne rates (0.2 points)
    double meanAbsDiff = 0.002;  // mean |V_M − V_R|
    double iou = 0.01;           // shadow IoU
};

struct CheckCase {
    std::string name;  // the case's key: unique in the suite, [A-Za-z0-9._-]
    std::filesystem::path sceneFile;
    scene::Backend backend = scene::Backend::Raster;  // Raster or Raytrace; Raster when the suite names none
    scene::Scene scene;       // loaded, resolution applied, case settings merged into its "shadow"
    std::string resolution;   // "WxH"
    std::string device;       // raster: Vulkan device ("" = the default)
    scene::Budgets budgets;   // scene's, then suite's, then case's
    nlohmann::json settings;  // the case's "settings" block as written (reports)
};

struct CheckSuite {
    std::filesystem::path file;
    std::string name;  // the file's stem
    std::string description;
    std::vector<CheckCase> cases;  // in file order: the order every output lists them in
    CheckTolerance tolerance;
    std::optional<std::filesystem::path> baseline;  // resolved against the suite's folder
};

// Loads and validates the whole suite, every scene included; throws scene::SceneError naming the
// file, the JSON path and what is wrong.
CheckSuite loadSuite(const std::filesystem::path& file);

// The metrics a baseline keeps per case, by their metrics-JSON names.
struct BaselineEntry {
    std::map<std::string, double> metrics;
};
using Baseline = std::map<std::string, BaselineEntry>;  // by case name
// Throws scene::SceneError on a malformed file; a missing file is an error too (the suite names it).
Baseline loadBaseline(const std::filesystem::path& file);
nlohmann::json baselineJson(const std::string& suiteName, const Baseline& baseline);
// The tracked metrics: names, and whether larger is better.
struct TrackedMetric {
    const char* name;
    bool higherIsBetter;
};
const std::vector<TrackedMetric>& trackedMetrics();
BaselineEntry baselineEntry(const compare::Metrics& metrics);

struct MetricDrift {
    std::string metric;
    double baseline = 0.0, current = 0.0, tolerance = 0.0;
    bool regressed = false;  // moved the wrong way by more than the tolerance
    bool improved = false;   // moved the right way by more than the tolerance
};

enum class CaseVerdict { Passed, Failed, Error };
const char* toString(CaseVerdict v);

struct CaseResult {
    std::string name;
    CaseVerdict verdict = CaseVerdict::Passed;
    std::string error;                  // Error: what went wrong
    std::vector<std::string> failures;  // Failed: one line per broken budget or regression
    std::optional<compare::Metrics> metrics;
    std::vector<compare::BudgetCheck> budgets;
    bool hasBaseline = false;
    std::vector<MetricDrift> drift;
    double seconds = 0.0;        // rendering and comparing (the reference excluded)
    std::vector<float> diffRgb;  // the difference image (kept for failing cases only)
    int width = 0, height = 0;
    nlohmann::json attributes;  // the method frame's settings as applied
};

// Renders every case in order, calling `progress` after each; a case that fails to render is an
// Error and the others go on. References are rendered once per scene, resolution and sample count.
// `baseline` may be null (no regression check).
std::vector<CaseResult> runSuite(const CheckSuite& suite, const Baseline* baseline,
                                 const std::function<void(std::size_t done, const CaseResult&)>& progress);

// The cases of `shard` (`check --shard K/N`), in file order: case names are sorted and dealt
// round-robin (assignShards, the rule of sweep shards), so the split depends only on
// the set of names.
CheckSuite shardSuite(const CheckSuite& suite, const Shard& shard);

// The drift of `metrics` from `entry`.
std::vector<MetricDrift> compareWithBaseline(const compare::Metrics& metrics, const BaselineEntry& entry,
                                             const CheckTolerance& tolerance);

}  // namespace shadowlab::studies
