// studies/stability.cpp: runs one extreme case (reference, analytic oracle, both backends at
// defaults, bias search, both backends at best) and writes the suite's HTML/CSV/JSON report.
#include "studies/stability.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <fstream>
#include <map>
#include <sstream>

#include "compare/report.h"
#include "compare/text.h"
#include "scene/error.h"
#include "scene/frame_io.h"
#include "scene/input_file.h"
#include "scene/json_input.h"
#include "scene/loader.h"
#include "scene/settings.h"
#include "studies/auto_bias.h"

namespace shadowlab::studies {
namespace fs = std::filesystem;
using Json = nlohmann::json;

namespace {

double msSince(std::chrono::steady_clock::time_point t0) {
    return std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count();
}

bool isBlack(const scene::Frame& f) {
    float mx = 0.0f;
    for (float v : f.beauty)
        if (std::isfinite(v)) mx = std::max(mx, v);
    return mx < kBlackFrameMax;
}

std::string fmt(double v, int digits = 4) {
    std::ostringstream s;
    s.precision(digits);
    s << v;
    return s.str();
}

// The scene-file "shadow" keys auto_bias writes, as command-line overrides.
scene::SettingsOverrides overridesFromBlock(const Json& block) {
    scene::SettingsOverrides o;
    if (block.contains("shadow_map_size")) o.shadowMapSize = block["shadow_map_size"].get<int>();
    if (block.contains("filter")) o.filter = block["filter"].get<std::string>();
    if (block.contains("depth_bias")) o.depthBias = block["depth_bias"].get<double>();
    if (block.contains("slope_bias")) o.slopeBias = block["slope_bias"].get<double>();
    if (block.contains("ray_bias")) {
        const Json& r = block["ray_bias"];
        o.rayBias = r.is_string() ? r.get<std::string>() : Json(r.get<double>()).dump();
    }
    if (block.contains("precision")) o.precision = block["precision"].get<std::string>();
    if (block.contains("fit_light_frustum")) o.fitLightFrustum = block["fit_light_frustum"].get<bool>();
    if (block.contains("cascades")) o.cascades = block["cascades"].get<int>();
    return o;
}

std::string describeOverrides(const Json& block, scene::Backend backend) {
    std::string s;
    for (const auto& [k, v] : block.items()) {
        const bool rayKey = k == "ray_bias" || k == "precision";
        if (rayKey != (backend == scene::Backend::Raytrace)) continue;
        if (!s.empty()) s += ", ";
        s += k + " " + (v.is_string() ? v.get<std::string>() : v.dump());
    }
    return s.empty() ? "defaults" : s;
}

BackendRun renderRun(const scene::Scene& scene, const scene::Frame& reference,
                     const scene::SettingsOverrides& overrides, const StabilityOptions& options, scene::Backend backend,
                     const std::string& variant, const std::string& label, scene::Frame* keep = nullptr) {
    BackendRun run;
    run.backend = backend;
    run.variant = variant;
    run.settings = label;
    try {
        scene::SettingsOverrides o = overrides;
        o.validate = options.validate;
        if (options.shadowMapSize && !o.shadowMapSize) o.shadowMapSize = options.shadowMapSize;
        const scene::RenderSettings settings = scene::resolveSettings(scene, o);
        const auto t0 = std::chrono::steady_clock::now();
        const scene::Frame frame = options.render(scene, settings, backend);
        run.timeMs = msSince(t0);
        run.ok = true;
        run.health = compare::measureHealth(frame);
        run.blackFrame = isBlack(frame);
        if (auto it = frame.attributes.find("validation_messages"); it != frame.attributes.end())
            run.validationMessages = std::stoi(it->second);
        const compare::Comparison cmp = compare::compareFrames(frame, reference);
        run.counted = cmp.metrics.counted;
        run.falseShadowRate = cmp.metrics.falseShadowRate;
        run.missedShadowRate = cmp.metrics.missedShadowRate;
        run.mismatchRate = cmp.metrics.mismatchRate;
        run.diffRgb = cmp.diffRgb;
        if (keep && !run.failed()) *keep = frame;
    } catch (const std::exception& e) {
        run.ok = false;
        run.error = e.what();
    }
    return run;
}

// The bias search: each grid point rendered once and measured (the sweep's warm-up, repeated
// timing and journal are not needed to find a window), then recommendBias.
AutoBias searchBias(const scene::Scene& scene, const scene::Frame& reference, const StabilityOptions& options) {
    SweepGrid grid = defaultGrid(scene, options.quick);
    std::vector<SweepRow> rows;
    for (SweepConfig config : grid.configs) {
        if (std::find(options.backends.begin(), options.backends.end(), config.backend) == options.backends.end())
            continue;
        const bool isSeries =
            !config.biasKind.empty() || config.overrides.rayBias == std::optional<std::string>("robust");
        if (options.biasSeriesOnly && !isSeries) continue;
        if (options.searchMapSize > 0 && config.backend == scene::Backend::Raster)
            config.overrides.shadowMapSize = options.searchMapSize;
        SweepRow row;
        row.config = config;
        row.key = config.key();
        row.repetitions = 1;
        try {
            scene::SettingsOverrides o = config.overrides;
            o.validate = options.validate;
            const scene::RenderSettings settings = scene::resolveSettings(scene, o);
            const auto t0 = std::chrono::steady_clock::now();
            const scene::Frame frame = options.render(scene, settings, config.backend);
            row.frameMs = msSince(t0);
            // A NaN frame must not look like a good bias: its rates become NaN (failing samples).
            Json m = toJson(compare::compareFrames(frame, reference).metrics);
            if (compare::measureHealth(frame).total() > 0) {
                m["false_shadow_rate"] = nullptr;
                m["missed_shadow_rate"] = nullptr;
                row.error = "non-finite values";
            }
            row.metrics = m;
        } catch (const std::exception& e) {
            row.error = e.what();
        }
        rows.push_back(std::move(row));
    }
    return recommendBias(rows);
}

}  // namespace

const BackendRun* StabilityCase::run(scene::Backend backend, const std::string& variant) const {
    for (const BackendRun& r : runs)
        if (r.backend == backend && r.variant == variant) return &r;
    return nullptr;
}

const MethodBias* StabilityCase::biasOf(scene::Backend backend) const {
    for (const MethodBias& b : bias)
        if (b.backend == backend) return &b;
    return nullptr;
}

std::string readDescription(const fs::path& sceneFile) {
    try {
        const Json doc = scene::parseJsonText(sceneFile, scene::readInputFile(sceneFile, scene::kMaxJsonFileBytes));
        return doc.value("description", std::string());
    } catch (const std::exception&) {
        return {};
    }
}

StabilityCase runStabilityCase(const scene::Scene& sceneIn, const StabilityOptions& options, const std::string& name,
                               const std::string& description) {
    if (options.width < 1 || options.height < 1 || options.width > scene::kMaxResolution ||
        options.height > scene::kMaxResolution)
        throw scene::InputError("stability: resolution " + std::to_string(options.width) + "x" +
                                std::to_string(options.height) + " is out of range");
    scene::Scene scene = sceneIn;
    scene.camera.width = options.width;
    scene.camera.height = options.height;

    StabilityCase c;
    c.name = name.empty() ? scene.file.stem().string() : name;
    c.description = description;
    c.width = options.width;
    c.height = options.height;

    // Reference (timed).
    try {
        const scene::RenderSettings settings = scene::resolveSettings(scene, {});
        const auto t0 = std::chrono::steady_clock::now();
        c.reference = options.render(scene, settings, scene::Backend::Reference);
        c.referenceMs = msSince(t0);
        c.referenceOk = true;
        c.referenceHealth = compare::measureHealth(c.reference);
        c.referenceBlack = isBlack(c.reference);
    } catch (const std::exception& e) {
        c.referenceError = e.what();
    }
    if (!c.referenceOk) {
        c.failures.push_back("reference failed: " + c.referenceError);
        return c;
    }
    if (c.referenceHealth.total() > 0)
        c.failures.push_back("reference has " + std::to_string(c.referenceHealth.total()) + " NaN/Inf values");
    if (c.referenceBlack) c.failures.push_back("reference is a black frame");

    // Analytic oracle.
    c.notAnalytic = whyNotAnalytic(scene);
    if (c.notAnalytic.empty()) {
        if (const auto answer = analyticAnswer(scene)) {
            c.analytic = checkAgainstAnalytic(c.reference, *answer);
            if (!c.analytic->passed()) c.failures.push_back("reference " + c.analytic->summary());
        }
    }

    // Backends at their defaults (kept: the recommendation is checked against them).
    std::map<scene::Backend, scene::Frame> defaultsFrames;
    for (const scene::Backend backend : options.backends)
        c.runs.push_back(
            renderRun(scene, c.reference, {}, options, backend, "defaults", "defaults", &defaultsFrames[backend]));
    auto defaultsOf = [&](scene::Backend backend) -> const scene::Frame* {
        const auto it = defaultsFrames.find(backend);
        return it == defaultsFrames.end() || it->second.pixelCount() == 0 ? nullptr : &it->second;
    };
    auto hasBackend = [&](scene::Backend b) {
        return std::find(options.backends.begin(), options.backends.end(), b) != options.backends.end();
    };

    // Bias search, then each backend at its best settings.
    if (options.search) {
        const AutoBias ab = searchBias(scene, c.reference, options);
        // The best settings: searched in the case's own configuration and never worse than its
        // defaults, at the case's resolution.
        RecommendOptions ro;
        ro.render = options.render;
        ro.user.shadowMapSize = options.shadowMapSize;
        ro.user.validate = options.validate;
        ro.raster = hasBackend(scene::Backend::Raster);
        ro.raytrace = hasBackend(scene::Backend::Raytrace);
        ro.depthSteps = options.bestDepthSteps;
        ro.slopeSteps = options.bestSlopeSteps;
        const Recommendation rec =
            recommendShadow(scene, c.reference, scene, c.reference, defaultsOf(scene::Backend::Raster),
                            defaultsOf(scene::Backend::Raytrace), rayCandidateOf(ab), ro);
        c.bestShadowBlock = rec.shadowBlock;
        c.bestNotes = rec.notes;
        for (const scene::Backend backend : options.backends) {
            MethodBias mb;
            mb.backend = backend;
            const BiasSeries* chosen = nullptr;
            for (const BiasSeries& s : ab.series) {
                if (s.backend != backend) continue;
                if (!mb.text.empty()) mb.text += " ";
                mb.text += s.describe();
                if (!s.window.stiff && (!chosen || chosen->window.stiff)) chosen = &s;
                if (!chosen) chosen = &s;
            }
            if (chosen) {
                mb.stiff = chosen->window.stiff;
                mb.kind = chosen->kind;
                mb.lo = chosen->window.lo;
                mb.hi = chosen->window.hi;
                mb.recommended = chosen->recommended;
                mb.dominant = chosen->dominant;
            } else {
                mb.text = "no bias series rendered";
            }
            if (backend == scene::Backend::Raytrace)
                for (const RobustResult& r : ab.robust)
                    mb.text += " Robust offsets (" + (r.precision.empty() ? std::string("default") : r.precision) +
                               "): false " + fmt(100 * r.falseShadowRate, 3) + "%, missed " +
                               fmt(100 * r.missedShadowRate, 3) + "%" + (r.passes ? " (pass)." : " (fail).");
            c.bias.push_back(mb);
            c.runs.push_back(renderRun(scene, c.reference, overridesFromBlock(rec.shadowBlock), options, backend,
                                       "best", describeOverrides(rec.shadowBlock, backend)));
        }
    }

    for (const BackendRun& r : c.runs) {
        const std::string who = std::string(scene::toString(r.backend)) + " (" + r.variant + ")";
        if (!r.ok)
            c.failures.push_back(who + " failed: " + r.error);
        else {
            if (r.health.total() > 0)
                c.failures.push_back(who + " has " + std::to_string(r.health.total()) + " NaN/Inf values");
            if (r.blackFrame) c.failures.push_back(who + " rendered a black frame");
            if (r.validationMessages > 0)
                c.failures.push_back(who + ": " + std::to_string(r.validationMessages) + " validation messages");
        }
    }
    return c;
}

std::vector<fs::path> extremeSceneFiles() {
    std::vector<fs::path> files;
    std::error_code ec;
    for (const auto& e : fs::directory_iterator(scene::scenesDirectory() / "extreme", ec))
        if (e.path().extension() == ".json") files.push_back(e.path());
    std::sort(files.begin(), files.end());
    return files;
}

std::vector<StabilityCase> runStabilitySuite(const std::vector<fs::path>& files, const StabilityOptions& options,
                                             const std::function<void(const StabilityCase&)>& progress) {
    std::vector<StabilityCase> cases;
    for (const fs::path& file : files) {
        const std::string name = file.stem().string();
        try {
            const scene::Scene scene = scene::loadScene(file);
            cases.push_back(runStabilityCase(scene, options, name, readDescription(file)));
        } catch (const std::exception& e) {
            StabilityCase c;
            c.name = name;
            c.description = readDescription(file);
            c.width = options.width;
            c.height = options.height;
            c.failures.push_back(std::string("scene failed to load: ") + e.what());
            cases.push_back(std::move(c));
        }
        if (progress) progress(cases.back());
    }
    return cases;
}

std::string StabilityCase::referenceVerdict() const {
    if (!referenceOk || referenceHealth.total() > 0 || referenceBlack) return "wrong";
    if (analytic) return analytic->passed() ? "exact" : "wrong";
    return "unchecked";
}

BackendState stateOf(const BackendRun* r, bool atBest) {
    if (!r) return {"not run", "not run"};
    if (r->failed()) {
        std::string why = !r->ok                  ? r->error
                          : r->blackFrame         ? "black frame"
                          : r->health.total() > 0 ? std::to_string(r->health.total()) + " NaN/Inf"
                                                  : std::to_string(r->validationMessages) + " validation messages";
        return {"failed", "failed: " + why};
    }
    const bool acne = r->falseShadowRate > compare::kBiasWindowMaxRate,
               leaks = r->missedShadowRate > compare::kBiasWindowMaxRate;
    if (!acne && !leaks) return {"clean", "clean"};
    std::string text;
    if (acne) text = "acne " + compare::formatPercent(r->falseShadowRate);
    if (leaks) text += std::string(acne ? ", " : "") + "leaks " + compare::formatPercent(r->missedShadowRate);
    if (atBest) return {"stiff", "stiff: " + text};
    return {acne && leaks ? "acne+leaks" : acne ? "acne" : "leaks", text};
}

bool suitePassed(const std::vector<StabilityCase>& cases) {
    return std::none_of(cases.begin(), cases.end(), [](const StabilityCase& c) { return c.failed(); });
}

Json toJson(const StabilityCase& c) {
    Json j;
    j["name"] = c.name;
    j["description"] = c.description;
    // Separate verdicts: whether the case ran cleanly, whether the reference is right, and what
    // each backend's shadows look like at its defaults and at its best bias.
    j["health"] = c.failed() ? "failed" : "ok";
    j["reference_verdict"] = c.referenceVerdict();
    j["states"] = Json::object();
    for (const BackendRun& r : c.runs) {
        const BackendState st = stateOf(&r, r.variant == "best");
        j["states"][scene::toString(r.backend)][r.variant] = {{"state", st.state},
                                                              {"text", st.text},
                                                              {"false_shadow_rate", r.falseShadowRate},
                                                              {"missed_shadow_rate", r.missedShadowRate}};
    }
    j["best_notes"] = c.bestNotes;
    j["failures"] = c.failures;
    j["resolution"] = std::to_string(c.width) + "x" + std::to_string(c.height);
    j[scene::toString(scene::Backend::Reference)] = {{"ok", c.referenceOk},
                                                     {"error", c.referenceError},
                                                     {"time_ms", c.referenceMs},
                                                     {"non_finite", c.referenceHealth.total()}};
    if (c.analytic) {
        const AnalyticCheck& a = *c.analytic;
        j["analytic"] = {{"passed", a.passed()},
                         {"object_id_mismatches", a.objectIdMismatches},
                         {"visibility_mismatches", a.visibilityMismatches},
                         {"visibility_compared", a.visibilityCompared},
                         {"knife_edge_pixels", a.knifeEdgePixels},
                         {"summary", a.summary()}};
    } else {
        j["analytic"] = nullptr;
        j["not_analytic"] = c.notAnalytic;
    }
    j["runs"] = Json::array();
    for (const BackendRun& r : c.runs)
        j["runs"].push_back({{"backend", scene::toString(r.backend)},
                             {"variant", r.variant},
                             {"settings", r.settings},
                             {"ok", r.ok},
                             {"error", r.error},
                             {"black_frame", r.blackFrame},
                             {"nan", r.health.beauty.nan + r.health.visibility.nan + r.health.objectId.nan +
                                         r.health.ndotl.nan + r.health.depth.nan + r.health.blockerId.nan},
                             {"non_finite", r.health.total()},
                             {"validation_messages", r.validationMessages},
                             {"time_ms", r.timeMs},
                             {"counted", r.counted},
                             {"false_shadow_rate", r.falseShadowRate},
                             {"missed_shadow_rate", r.missedShadowRate}});
    j["bias"] = Json::array();
    for (const MethodBias& b : c.bias)
        j["bias"].push_back({{"backend", scene::toString(b.backend)},
                             {"stiff", b.stiff},
                             {"kind", b.kind},
                             {"lo", b.lo},
                             {"hi", b.hi},
                             {"recommended", b.recommended},
                             {"dominant", b.dominant},
                             {"text", b.text}});
    j["best_shadow_block"] = c.bestShadowBlock;
    return j;
}

namespace {
std::string windowText(const MethodBias* b) {
    if (!b) return "not searched";
    if (b->kind.empty()) return b->text;
    if (b->stiff)
        return "stiff (" + b->kind + ", " + (b->dominant == "missed" ? "leaks dominate" : "acne dominates") + ")";
    return b->kind + " " + fmt(b->lo) + " .. " + fmt(b->hi);
}
std::string csvField(std::string s) {
    for (char& ch : s)
        if (ch == '"') ch = '\'';
    return "\"" + s + "\"";
}
}  // namespace

std::string stabilityCsv(const std::vector<StabilityCase>& cases) {
    std::ostringstream s;
    s << "case,health,reference,analytic,reference_ms,backend,variant,state,settings,ok,black,non_finite,"
         "false_shadow_rate,missed_shadow_rate,time_ms,bias_window\n";
    for (const StabilityCase& c : cases) {
        const std::string analytic = c.analytic ? (c.analytic->passed() ? "exact" : "MISSED") : "n/a";
        for (const BackendRun& r : c.runs)
            s << c.name << ',' << (c.failed() ? "failed" : "ok") << ',' << c.referenceVerdict() << ',' << analytic
              << ',' << c.referenceMs << ',' << scene::toString(r.backend) << ',' << r.variant << ','
              << csvField(stateOf(&r, r.variant == "best").text) << ',' << csvField(r.settings) << ',' << r.ok << ','
              << r.blackFrame << ',' << r.health.total() << ',' << r.falseShadowRate << ',' << r.missedShadowRate << ','
              << r.timeMs << ',' << csvField(windowText(c.biasOf(r.backend))) << '\n';
        if (c.runs.empty())
            s << c.name << ',' << (c.failed() ? "failed" : "ok") << ',' << c.referenceVerdict() << ',' << analytic
              << ',' << c.referenceMs << ",,,,,,,,,,,\n";
    }
    return s.str();
}

namespace {

// A cell of the summary table: the state's text on its own color (the page's CSS, st-*).
std::string stateCell(const BackendState& st) {
    std::string cls = st.state;
    std::replace(cls.begin(), cls.end(), '+', '-');
    std::replace(cls.begin(), cls.end(), ' ', '-');
    return "<td class=\"st-" + cls + "\">" + compare::escapeHtml(st.text) + "</td>";
}

std::string referenceCell(const std::string& verdict) {
    return "<td class=\"ref-" + verdict + "\">" + verdict + "</td>";
}

}  // namespace

void writeStabilityReport(const fs::path& dir, const std::vector<StabilityCase>& cases) {
    fs::create_directories(dir / "stability");
    std::ostringstream h;
    std::size_t failedCases = 0, exact = 0, wrong = 0;
    for (const StabilityCase& c : cases) {
        failedCases += c.failed() ? 1 : 0;
        exact += c.referenceVerdict() == "exact" ? 1 : 0;
        wrong += c.referenceVerdict() == "wrong" ? 1 : 0;
    }
    h << "<!doctype html><html><head><meta charset=\"utf-8\"><title>shadowlab stability</title><style>"
      << compare::html::css()
      << " table.st td,table.st th{padding:3px 8px;border-bottom:1px solid #ddd;text-align:left}"
         " .fail{color:#b00;font-weight:bold} .pass{color:#070;font-weight:bold}"
         " .st-clean,.ref-exact{background:#d3f9d8;color:#1b5e20} .st-acne{background:#ffe3e3;color:#a51111}"
         " .st-leaks{background:#dbe4ff;color:#1c3faa} .st-acne-leaks{background:#f3d9fa;color:#6b1e80}"
         " .st-stiff{background:#fff0d4;color:#8a4b00;font-weight:600} "
         ".st-failed,.ref-wrong{background:#c92a2a;color:#fff;font-weight:600}"
         " .st-not-run,.ref-unchecked{background:#f1f3f5;color:#495057} "
         ".figs{display:flex;flex-wrap:wrap;gap:10px;margin:12px 0} .figs "
         "figure{width:320px}</style></head><body><main>"
      << "<h1>Stability suite</h1><p>" << cases.size() << " cases. Reference: <span class=pass>" << exact
      << " exact</span> against the analytic answer, " << (cases.size() - exact - wrong)
      << " unchecked (no analytic answer), " << (wrong ? "<span class=fail>" : "") << wrong << " wrong"
      << (wrong ? "</span>" : "") << ". Runs: "
      << (failedCases
              ? "<span class=fail>" + std::to_string(failedCases) +
                    " with a crash, NaN/Inf, black frame or validation message</span>"
              : std::string(
                    "<span class=pass>none crashed, produced NaN/Inf, a black frame or a validation message</span>"))
      << ".</p><p>Each case runs through the double reference, the analytic oracle (where the scene is"
         " spheres, quads and boxes under directional lights), and each backend at its defaults and at"
         " its best bias (searched in its own configuration over depth × slope, never worse than the defaults)."
         " A backend's state: <span class=st-clean>clean</span> (false and missed shadow both ≤ "
      << compare::formatPercent(compare::kBiasWindowMaxRate)
      << " of the counted pixels), <span class=st-acne>acne x%</span> (false shadow),"
         " <span class=st-leaks>leaks y%</span> (missed shadow: light leaking, peter-panning),"
         " <span class=st-acne-leaks>both</span>, and at the best bias <span class=st-stiff>stiff</span>: no searched"
         " bias makes it clean. <span class=st-failed>failed</span>: crash, NaN/Inf, black frame or validation "
         "messages."
         "</p><table class=st><tr><th>case</th><th>reference</th><th>raster at defaults</th><th>raster at best</th>"
         "<th>raytrace at defaults</th><th>raytrace at best</th><th>raster window</th><th>raytrace window</th></tr>";
    for (const StabilityCase& c : cases) {
        h << "<tr><td><a href=\"#" << compare::escapeHtml(c.name) << "\">" << compare::escapeHtml(c.name) << "</a></td>"
          << referenceCell(c.referenceVerdict());
        for (const scene::Backend backend : {scene::Backend::Raster, scene::Backend::Raytrace})
            for (const char* variant : {"defaults", "best"})
                h << stateCell(stateOf(c.run(backend, variant), std::string(variant) == "best"));
        h << "<td>" << compare::escapeHtml(windowText(c.biasOf(scene::Backend::Raster))) << "</td><td>"
          << compare::escapeHtml(windowText(c.biasOf(scene::Backend::Raytrace))) << "</td></tr>";
    }
    h << "</table>" << compare::html::diffLegend();
    for (const StabilityCase& c : cases) {
        h << "<section id=\"" << compare::escapeHtml(c.name) << "\"><h2>" << compare::escapeHtml(c.name)
          << "</h2><table class=st><tr>"
          << "<th>reference</th><th>raster at defaults</th><th>raster at best</th><th>raytrace at defaults</th>"
             "<th>raytrace at best</th></tr><tr>"
          << referenceCell(c.referenceVerdict());
        for (const scene::Backend backend : {scene::Backend::Raster, scene::Backend::Raytrace})
            for (const char* variant : {"defaults", "best"})
                h << stateCell(stateOf(c.run(backend, variant), std::string(variant) == "best"));
        h << "</tr></table>";
        if (!c.description.empty()) h << "<p>" << compare::escapeHtml(c.description) << "</p>";
        for (const std::string& f : c.failures) h << "<p class=fail>" << compare::escapeHtml(f) << "</p>";
        h << "<p>Reference: " << fmt(c.referenceMs) << " ms, " << c.referenceHealth.total() << " NaN/Inf. Analytic: "
          << compare::escapeHtml(c.analytic ? c.analytic->summary() : "not analytic (" + c.notAnalytic + ")")
          << ".</p>";
        h << "<table class=st><tr><th>backend</th><th>settings</th><th>state</th><th>NaN/Inf</th><th>acne</th>"
             "<th>leak</th><th>time ms</th></tr>";
        for (const BackendRun& r : c.runs)
            h << "<tr><td>" << scene::toString(r.backend) << "</td><td>"
              << compare::escapeHtml(r.variant + ": " + r.settings) << "</td>"
              << stateCell(stateOf(&r, r.variant == "best")) << "<td>" << r.health.total() << "</td><td>"
              << fmt(100 * r.falseShadowRate, 3) << "%</td><td>" << fmt(100 * r.missedShadowRate, 3) << "%</td><td>"
              << fmt(r.timeMs) << "</td></tr>";
        h << "</table>";
        for (const MethodBias& b : c.bias)
            h << "<p><b>" << scene::toString(b.backend) << "</b> (probe slice): " << compare::escapeHtml(windowText(&b))
              << ". " << compare::escapeHtml(b.text) << "</p>";
        for (const std::string& note : c.bestNotes) h << "<p>" << compare::escapeHtml(note) << "</p>";
        h << "<div class=figs>";
        // Every image at one width (figures in a flex row would shrink to their captions), small
        // renders magnified with crisp pixels so their shadows can be seen.
        const std::string size =
            "width=320 height=" + std::to_string(std::max(1, 320 * c.height / std::max(1, c.width)));
        if (c.referenceOk && !c.reference.beauty.empty()) {
            const std::string png = "stability/" + c.name + "-reference.png";
            scene::writePngLinear(dir / png, c.width, c.height, c.reference.beauty);
            h << "<figure><img src=\"" << png << "\" " << size
              << " class=upscale alt=reference><figcaption>reference</figcaption></figure>";
        }
        for (const BackendRun& r : c.runs) {
            if (r.diffRgb.empty()) continue;
            const std::string png = "stability/" + c.name + "-" + scene::toString(r.backend) +
                                    (r.variant == "defaults" ? "" : "-" + r.variant) + "-diff.png";
            scene::writePngDisplay(dir / png, c.width, c.height, r.diffRgb);
            h << "<figure><img src=\"" << png << "\" " << size << " class=upscale alt=\"" << scene::toString(r.backend)
              << " difference\"><figcaption>" << scene::toString(r.backend) << " at " << r.variant
              << " vs reference</figcaption></figure>";
        }
        h << "</div></section>";
    }
    h << "</main></body></html>\n";
    scene::writeTextAtomic(dir / "stability.html", h.str());
    scene::writeTextAtomic(dir / "stability.csv", stabilityCsv(cases));
    Json all = Json::array();
    for (const StabilityCase& c : cases) all.push_back(toJson(c));
    scene::writeTextAtomic(dir / "stability.json", Json{{"passed", suitePassed(cases)}, {"cases", all}}.dump(2) + "\n");
}

}  // namespace shadowlab::studies
