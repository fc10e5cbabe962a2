// studies/check.cpp: suites, baselines and running the cases of `shadowlab check`.
#include "studies/check.h"

#include <chrono>
#include <cmath>
#include <cstdio>
#include <fstream>
#include <set>

#include "scene/backend.h"
#include "scene/error.h"
#include "scene/json_input.h"
#include "scene/loader.h"
#include "scene/settings.h"
#include "studies/sweep.h"

namespace shadowlab::studies {

namespace {

namespace fs = std::filesystem;
using Json = nlohmann::json;
using scene::JsonPath;
using scene::SceneError;

Json parseFile(const fs::path& file) { return scene::readJsonFile(file); }

void checkKeys(const fs::path& file, const Json& node, const JsonPath& path,
               std::initializer_list<const char*> allowed) {
    if (!node.is_object()) throw SceneError(file, path, "expected an object, got " + node.dump().substr(0, 40));
    for (const auto& item : node.items()) {
        bool ok = false;
        std::string list;
        for (const char* a : allowed) {
            ok = ok || item.key() == a;
            list += (list.empty() ? "" : ", ") + std::string(a);
        }
        if (!ok) throw SceneError(file, path / item.key(), "unknown key; allowed here: " + list);
    }
}

std::string stringAt(const fs::path& file, const Json& node, const JsonPath& path) {
    if (!node.is_string() || node.get<std::string>().empty())
        throw SceneError(file, path, "expected a non-empty string, got " + node.dump().substr(0, 40));
    return node.get<std::string>();
}

// "WxH" with sides in 1..kMaxResolution; returns the sides.
std::pair<int, int> parseResolution(const fs::path& file, const Json& node, const JsonPath& path) {
    int w = 0, h = 0;
    char x = 0, extra = 0;
    if (!node.is_string() || std::sscanf(node.get<std::string>().c_str(), "%d%c%d%c", &w, &x, &h, &extra) != 3 ||
        x != 'x' || w < 1 || h < 1 || w > scene::kMaxResolution || h > scene::kMaxResolution ||
        static_cast<long long>(w) * h > scene::kMaxPixels)
        throw SceneError(file, path,
                         "expected \"WxH\" with sides in 1.." + std::to_string(scene::kMaxResolution) + ", got " +
                             node.dump().substr(0, 40));
    return {w, h};
}

double nonNegative(const fs::path& file, const Json& node, const JsonPath& path) {
    if (!node.is_number() || !std::isfinite(node.get<double>()) || node.get<double>() < 0.0)
        throw SceneError(file, path, "expected a number >= 0, got " + node.dump().substr(0, 40));
    return node.get<double>();
}

// Every setting the case names replaces the scene's "shadow" block value.
bool validName(const std::string& s) {
    if (s.empty() || s.size() > 100) return false;
    for (char c : s)
        if (!(std::isalnum(static_cast<unsigned char>(c)) || c == '.' || c == '_' || c == '-')) return false;
    return s != "." && s != "..";
}

}  // namespace

CheckSuite loadSuite(const fs::path& file) {
    const Json doc = parseFile(file);
    const JsonPath root;
    checkKeys(file, doc, root, {"description", "resolution", "baseline", "tolerance", "budgets", "cases"});
    CheckSuite suite;
    suite.file = file;
    suite.name = file.stem().string();
    const fs::path dir = file.has_parent_path() ? file.parent_path() : fs::path(".");
    if (doc.contains("description")) suite.description = stringAt(file, doc["description"], root / "description");
    std::optional<Json> defaultResolution;
    if (doc.contains("resolution")) {
        parseResolution(file, doc["resolution"], root / "resolution");
        defaultResolution = doc["resolution"];
    }
    if (doc.contains("baseline")) suite.baseline = dir / stringAt(file, doc["baseline"], root / "baseline");
    if (doc.contains("tolerance")) {
        const Json& t = doc["tolerance"];
        const JsonPath p = root / "tolerance";
        checkKeys(file, t, p, {"rate", "mean_abs_diff", "iou"});
        if (t.contains("rate")) suite.tolerance.rate = nonNegative(file, t["rate"], p / "rate");
        if (t.contains("mean_abs_diff"))
            suite.tolerance.meanAbsDiff = nonNegative(file, t["mean_abs_diff"], p / "mean_abs_diff");
        if (t.contains("iou")) suite.tolerance.iou = nonNegative(file, t["iou"], p / "iou");
    }
    scene::Budgets suiteBudgets;
    if (doc.contains("budgets")) suiteBudgets = scene::readBudgets(file, doc["budgets"], root / "budgets");
    if (!doc.contains("cases")) throw SceneError(file, root / "cases", "is required");
    const Json& cases = doc["cases"];
    if (!cases.is_array() || cases.empty())
        throw SceneError(file, root / "cases", "expected a non-empty array of cases");
    std::set<std::string> names;
    for (std::size_t i = 0; i < cases.size(); ++i) {
        const Json& c = cases[i];
        const JsonPath p = root / "cases" / i;
        checkKeys(file, c, p, {"name", "scene", "backend", "resolution", "settings", "budgets", "device"});
        CheckCase k;
        if (!c.contains("name")) throw SceneError(file, p / "name", "is required");
        k.name = stringAt(file, c["name"], p / "name");
        if (!validName(k.name))
            throw SceneError(file, p / "name",
                             "'" + k.name + "': use letters, digits, '.', '_' and '-' (it names files)");
        if (!names.insert(k.name).second)
            throw SceneError(file, p / "name", "'" + k.name + "' names an earlier case too");
        if (!c.contains("scene")) throw SceneError(file, p / "scene", "is required");
        const std::string sceneName = stringAt(file, c["scene"], p / "scene");
        // A path beside the suite, or a shipped scene's name.
        std::error_code ec;
        if (fs::is_regular_file(dir / sceneName, ec)) {
            k.sceneFile = dir / sceneName;
        } else {
            try {
                k.sceneFile = scene::findScene(sceneName);
            } catch (const scene::InputError& e) {
                throw SceneError(file, p / "scene", e.what());
            }
        }
        if (c.contains("backend")) {
            const std::string name = stringAt(file, c["backend"], p / "backend");
            const std::optional<scene::Backend> b = scene::parseBackend(name);
            if (b != scene::Backend::Raster && b != scene::Backend::Raytrace)
                throw SceneError(file, p / "backend", "expected raster or raytrace, got '" + name + "'");
            k.backend = *b;
        }
        if (c.contains("device")) {
            k.device = stringAt(file, c["device"], p / "device");
            // A ray-traced case renders on no Vulkan device: a device there is a mistake to name.
            if (k.backend != scene::Backend::Raster)
                throw SceneError(file, p / "device",
                                 "a Vulkan device applies to a raster case; this case's backend is "
                                 "raytrace (remove \"device\", or set \"backend\": \"raster\")");
        }
        k.scene = scene::loadScene(k.sceneFile);
        const Json* res = c.contains("resolution") ? &c["resolution"]
                          : defaultResolution      ? &*defaultResolution
                                                   : nullptr;
        if (res) {
            const auto [w, h] =
                parseResolution(file, *res, c.contains("resolution") ? p / "resolution" : root / "resolution");
            k.scene.camera.width = w;
            k.scene.camera.height = h;
        }
        k.resolution = std::to_string(k.scene.camera.width) + "x" + std::to_string(k.scene.camera.height);
        if (c.contains("settings")) {
            k.settings = c["settings"];
            k.scene.shadow = k.scene.shadow.overriddenBy(scene::readShadowBlock(file, c["settings"], p / "settings"));
        } else {
            k.settings = Json::object();
        }
        scene::Budgets caseBudgets;
        if (c.contains("budgets")) caseBudgets = scene::readBudgets(file, c["budgets"], p / "budgets");
        k.budgets = k.scene.budgets.overriddenBy(suiteBudgets).overriddenBy(caseBudgets);
        // Settings are resolved now so that a bad combination is bad input, not a case error.
        try {
            scene::SettingsOverrides o;
            if (!k.device.empty()) o.device = k.device;
            scene::resolveSettings(k.scene, o);
        } catch (const scene::InputError& e) {
            throw SceneError(file, p / "settings", e.what());
        }
        suite.cases.push_back(std::move(k));
    }
    return suite;
}

const std::vector<TrackedMetric>& trackedMetrics() {
    static const std::vector<TrackedMetric> kMetrics = {
        {"mismatch_rate", false},         {"false_shadow_rate", false},         {"missed_shadow_rate", false},
        {"self_shadow_acne_rate", false}, {"mean_abs_visibility_error", false}, {"shadow_iou", true},
    };
    return kMetrics;
}

BaselineEntry baselineEntry(const compare::Metrics& m) {
    BaselineEntry e;
    e.metrics = {{"mismatch_rate", m.mismatchRate},
                 {"false_shadow_rate", m.falseShadowRate},
                 {"missed_shadow_rate", m.missedShadowRate},
                 {"mean_abs_visibility_error", m.meanAbsVisibilityError},
                 {"shadow_iou", m.shadowIoU}};
    if (m.hasBlockerIds) e.metrics["self_shadow_acne_rate"] = m.selfShadowAcneRate;
    return e;
}

Baseline loadBaseline(const fs::path& file) {
    const Json doc = parseFile(file);
    const JsonPath root;
    checkKeys(file, doc, root, {"shadowlab_check_baseline", "suite", "cases"});
    if (!doc.contains("shadowlab_check_baseline") || doc["shadowlab_check_baseline"] != 1)
        throw SceneError(file, root / "shadowlab_check_baseline", "expected 1 (the baseline format's version)");
    if (!doc.contains("cases") || !doc["cases"].is_object())
        throw SceneError(file, root / "cases", "expected an object of cases by name");
    Baseline b;
    for (const auto& [name, entry] : doc["cases"].items()) {
        const JsonPath p = root / "cases" / name;
        if (!entry.is_object()) throw SceneError(file, p, "expected an object of metrics");
        BaselineEntry e;
        for (const auto& [metric, value] : entry.items()) {
            bool known = false;
            for (const TrackedMetric& t : trackedMetrics()) known = known || metric == t.name;
            if (!known)
                throw SceneError(file, p / metric,
                                 "not a tracked metric (mismatch_rate, false_shadow_rate, "
                                 "missed_shadow_rate, self_shadow_acne_rate, "
                                 "mean_abs_visibility_error, shadow_iou)");
            if (!value.is_number() || !std::isfinite(value.get<double>()) || value.get<double>() < 0.0 ||
                value.get<double>() > 1.0)
                throw SceneError(file, p / metric, "expected a number in 0..1, got " + value.dump().substr(0, 40));
            e.metrics[metric] = value.get<double>();
        }
        b[name] = e;
    }
    return b;
}

Json baselineJson(const std::string& suiteName, const Baseline& baseline) {
    Json cases = Json::object();
    for (const auto& [name, e] : baseline) cases[name] = e.metrics;
    return {{"shadowlab_check_baseline", 1}, {"suite", suiteName}, {"cases", cases}};
}

CheckSuite shardSuite(const CheckSuite& suite, const Shard& shard) {
    std::vector<std::string> names;
    for (const CheckCase& c : suite.cases) names.push_back(c.name);
    const std::vector<int> of = assignShards(names, shard.count);
    CheckSuite s = suite;
    s.cases.clear();
    for (std::size_t i = 0; i < suite.cases.size(); ++i)
        if (of[i] == shard.index) s.cases.push_back(suite.cases[i]);
    return s;
}

std::vector<MetricDrift> compareWithBaseline(const compare::Metrics& m, const BaselineEntry& entry,
                                             const CheckTolerance& t) {
    const BaselineEntry now = baselineEntry(m);
    std::vector<MetricDrift> out;
    for (const TrackedMetric& tm : trackedMetrics()) {
        const auto b = entry.metrics.find(tm.name);
        const auto c = now.metrics.find(tm.name);
        if (b == entry.metrics.end() || c == now.metrics.end()) continue;
        MetricDrift d;
        d.metric = tm.name;
        d.baseline = b->second;
        d.current = c->second;
        d.tolerance = std::string(tm.name) == "shadow_iou"                  ? t.iou
                      : std::string(tm.name) == "mean_abs_visibility_error" ? t.meanAbsDiff
                                                                            : t.rate;
        const double worse = tm.higherIsBetter ? d.baseline - d.current : d.current - d.baseline;
        d.regressed = worse > d.tolerance;
        d.improved = -worse > d.tolerance;
        out.push_back(d);
    }
    return out;
}

const char* toString(CaseVerdict v) {
    switch (v) {
        case CaseVerdict::Passed: return "passed";
        case CaseVerdict::Failed: return "failed";
        case CaseVerdict::Error: return "error";
    }
    return "?";
}

std::vector<CaseResult> runSuite(const CheckSuite& suite, const Baseline* baseline,
                                 const std::function<void(std::size_t, const CaseResult&)>& progress) {
    using Clock = std::chrono::steady_clock;
    std::map<std::string, scene::Frame> references;  // by scene file, resolution and samples
    std::vector<CaseResult> results;
    for (std::size_t i = 0; i < suite.cases.size(); ++i) {
        const CheckCase& k = suite.cases[i];
        CaseResult r;
        r.name = k.name;
        try {
            scene::SettingsOverrides o;
            if (!k.device.empty()) o.device = k.device;
            const scene::RenderSettings settings = scene::resolveSettings(k.scene, o);
            const std::string refKey = fs::absolute(k.sceneFile).string() + "|" + k.resolution + "|" +
                                       std::to_string(settings.raytrace.samples);
            auto ref = references.find(refKey);
            if (ref == references.end())
                ref = references.emplace(refKey, renderWithBackend(k.scene, settings, scene::Backend::Reference)).first;
            const auto start = Clock::now();
            const scene::Frame method = renderWithBackend(k.scene, settings, k.backend);
            compare::Comparison c = compare::compareFrames(method, ref->second);
            r.seconds = std::chrono::duration<double>(Clock::now() - start).count();
            r.budgets = compare::checkBudgets(c.metrics, k.budgets);
            for (const compare::BudgetCheck& b : r.budgets)
                if (b.broken) r.failures.push_back("budget " + describe(b));
            if (baseline) {
                if (const auto e = baseline->find(k.name); e != baseline->end()) {
                    r.hasBaseline = true;
                    r.drift = compareWithBaseline(c.metrics, e->second, suite.tolerance);
                    for (const MetricDrift& d : r.drift) {
                        if (!d.regressed) continue;
                        char line[256];
                        std::snprintf(line, sizeof line, "regression: %s %.6g, baseline %.6g (tolerance %.6g)",
                                      d.metric.c_str(), d.current, d.baseline, d.tolerance);
                        r.failures.push_back(line);
                    }
                }
            }
            r.verdict = r.failures.empty() ? CaseVerdict::Passed : CaseVerdict::Failed;
            r.attributes = method.attributes;
            r.width = c.width;
            r.height = c.height;
            if (r.verdict == CaseVerdict::Failed) r.diffRgb = std::move(c.diffRgb);
            r.metrics = c.metrics;
        } catch (const std::exception& e) {
            r.verdict = CaseVerdict::Error;
            r.error = e.what();
        }
        results.push_back(std::move(r));
        if (progress) progress(i + 1, results.back());
    }
    return results;
}

}  // namespace shadowlab::studies
