// studies/auto_bias.cpp: groups sweep rows into bias series, finds each series' bias window and
// writes the recommended scene-file "shadow" block with the sentences that justify it.
#include "studies/auto_bias.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <map>

#include "compare/text.h"
#include "scene/error.h"

namespace shadowlab::studies {

namespace {

using Json = nlohmann::json;

// The filterable maps' parameter series, in the order their notes appear, with the scene-file
// "shadow" key each sets (docs/scene-format.md) and the sweep axis that samples it.
struct MomentKind {
    const char* kind;  // the sweep axis and SweepConfig::biasKind
    const char* key;   // the scene-file key
    const char* name;  // for sentences
    const char* unit;
};
constexpr MomentKind kMomentKinds[] = {
    {"min_variance", "min_variance", "min variance", "normalized depth squared"},
    {"bleeding_reduction", "light_bleeding_reduction", "light-bleeding reduction", "fraction"},
    {"evsm_positive", "evsm_positive_exponent", "EVSM positive exponent", "exponent"},
    {"evsm_negative", "evsm_negative_exponent", "EVSM negative exponent", "exponent"},
    {"esm_exponent", "esm_exponent", "ESM exponent", "exponent"},
    {"moment_bias", "moment_bias", "moment bias", "fraction"},
};

const MomentKind* momentKind(const std::string& kind) {
    for (const MomentKind& m : kMomentKinds)
        if (kind == m.kind) return &m;
    return nullptr;
}

// The scene-file key a bias kind sets.
const char* kindKey(const std::string& kind) {
    if (kind == "depth") return "depth_bias";
    if (kind == "slope") return "slope_bias";
    if (const MomentKind* m = momentKind(kind)) return m->key;
    return "ray_bias";
}

// The overrides a backend reads, as scene-file "shadow" keys, leaving out `skipKey`. Keys the
// backend ignores (the app copies --ray-bias into raster rows too) are left out, so they do not
// split one series into several.
Json contextOf(const SweepConfig& c, const std::string& skipKey) {
    const auto& o = c.overrides;
    Json j = Json::object();
    if (c.backend == scene::Backend::Raster) {
        if (o.shadowMapSize) j["shadow_map_size"] = *o.shadowMapSize;
        if (o.filter) j["filter"] = *o.filter;
        if (o.depthBias) j["depth_bias"] = *o.depthBias;
        if (o.slopeBias) j["slope_bias"] = *o.slopeBias;
        // The map a bias was found on: a recommended block carries it, so the bias is used on it.
        if (o.fitLightFrustum) j["fit_light_frustum"] = *o.fitLightFrustum;
        if (o.cascades) j["cascades"] = *o.cascades;
        // A filterable map's parameters, so a series of one holds the others fixed.
        for (const MomentKind& m : kMomentKinds)
            if (const std::optional<double> v = momentOverride(o, m.kind)) j[m.key] = *v;
        if (o.blurWidth) j["blur_width"] = *o.blurWidth;
    } else {
        if (o.rayBias) {
            // Scene files take a number or "robust"; the overrides keep the command-line text.
            if (*o.rayBias == "robust") {
                j["ray_bias"] = "robust";
            } else {
                char* end = nullptr;
                const double v = std::strtod(o.rayBias->c_str(), &end);
                if (end && *end == '\0' && std::isfinite(v)) j["ray_bias"] = v;
            }
        }
        if (o.precision) j["precision"] = *o.precision;
        if (o.samples) j["samples"] = *o.samples;
    }
    j.erase(skipKey);
    return j;
}

// The value a configuration sets for a bias kind, if it sets one (a numeric ray bias only).
std::optional<double> biasOf(const SweepConfig& c, const std::string& kind) {
    const auto& o = c.overrides;
    const bool raster = c.backend == scene::Backend::Raster;
    if (kind == "depth" && raster) return o.depthBias;
    if (kind == "slope" && raster) return o.slopeBias;
    if (momentKind(kind) && raster) return momentOverride(o, kind);
    if (kind == "ray" && c.backend == scene::Backend::Raytrace && o.rayBias && *o.rayBias != "robust") {
        char* end = nullptr;
        const double v = std::strtod(o.rayBias->c_str(), &end);
        if (end && *end == '\0' && std::isfinite(v)) return v;
    }
    return std::nullopt;
}

// A setting's value for sentences: integers as integers ("1024"), others with 3 digits.
std::string valueText(const Json& value) {
    if (value.is_number_integer()) return std::to_string(value.get<long long>());
    if (value.is_number()) return compare::formatShort(value.get<double>());
    if (value.is_string()) return value.get<std::string>();
    return value.dump();
}

std::string contextLabel(const Json& context) {
    std::vector<std::string> parts;
    for (const auto& [key, value] : context.items()) {
        std::string k = key;
        std::replace(k.begin(), k.end(), '_', ' ');
        if (k == "shadow map size") k = "map";
        parts.push_back(k + " " + valueText(value));
    }
    std::string s;
    for (std::size_t i = 0; i < parts.size(); ++i) s += (i ? ", " : "") + parts[i];
    return s;
}

// A value for a scene file: 3 significant digits, unless rounding would leave [lo, hi], the
// range of values the sweep showed to be acceptable.
double tidy(double v, double lo, double hi) {
    if (!std::isfinite(v) || v == 0.0) return v;
    char buf[32];
    std::snprintf(buf, sizeof buf, "%.3g", v);
    const double r = std::strtod(buf, nullptr);
    return r >= lo && r <= hi ? r : v;
}

double worstOf(double a, double b) {
    if (!std::isfinite(a) || !std::isfinite(b)) return std::numeric_limits<double>::infinity();
    return std::max(a, b);
}

std::string artifactName(const std::string& dominant, const std::string& kind) {
    if (momentKind(kind))
        return dominant == "false" ? "over-darkening (false shadow)" : "light bleeding and leaks (missed shadow)";
    if (dominant == "false") return "acne (false shadow)";
    return kind == "ray" ? "light leaks (missed shadow)" : "peter-panning and light leaks (missed shadow)";
}

std::string precisionText(const std::string& p) { return p.empty() ? "" : " (" + p + ")"; }

}  // namespace

const std::vector<std::string>& seriesKinds() {
    static const std::vector<std::string> kinds = [] {
        std::vector<std::string> k{"depth", "slope", "ray"};
        for (const MomentKind& m : kMomentKinds) k.push_back(m.kind);
        return k;
    }();
    return kinds;
}

double windowMiddle(double lo, double hi, bool logSpaced) {
    if (logSpaced && lo > 0.0 && hi > 0.0) return std::sqrt(lo * hi);
    return 0.5 * (lo + hi);
}

bool isLogSpaced(std::vector<double> values) {
    values.erase(std::remove_if(values.begin(), values.end(), [](double v) { return !(v > 0.0) || !std::isfinite(v); }),
                 values.end());
    std::sort(values.begin(), values.end());
    values.erase(std::unique(values.begin(), values.end()), values.end());
    if (values.size() < 2) return false;
    if (values.size() == 2) return values[1] >= 10.0 * values[0];
    // Coefficient of variation of the steps: 0 for a perfect series of that kind.
    auto variation = [](const std::vector<double>& steps) {
        double mean = 0.0;
        for (double s : steps) mean += s;
        mean /= double(steps.size());
        double var = 0.0;
        for (double s : steps) var += (s - mean) * (s - mean);
        return std::sqrt(var / double(steps.size())) / mean;
    };
    std::vector<double> linear, ratio;
    for (std::size_t i = 1; i < values.size(); ++i) {
        linear.push_back(values[i] - values[i - 1]);
        ratio.push_back(std::log(values[i] / values[i - 1]));
    }
    return variation(ratio) < variation(linear);
}

std::string BiasSeries::name() const {
    if (const MomentKind* m = momentKind(kind)) return m->name;
    return kind + " bias";
}

std::string BiasSeries::unit() const {
    if (const MomentKind* m = momentKind(kind)) return m->unit;
    return kind == "slope" ? "texels" : "world units";
}

std::string BiasSeries::describe() const {
    std::string s = name() + " (" + unit();
    const std::string ctx = contextLabel(context);
    if (!ctx.empty()) s += "; " + ctx;
    s += "): ";
    const std::string limit = "both rates <= " + compare::formatPercent(window.threshold);
    if (!window.stiff) {
        s += std::string(momentKind(kind) ? "parameter window " : "bias window ") + compare::formatShort(window.lo) +
             " .. " + compare::formatShort(window.hi) + " (" + limit + ", " + std::to_string(window.acceptableSamples) +
             " sample" + (window.acceptableSamples == 1 ? "" : "s") + "); ";
        if (window.lo == window.hi) return s + "one sampled value, " + compare::formatShort(recommended) + ".";
        return s + "its " + (logSpaced && window.lo > 0.0 ? "geometric" : "arithmetic") + " middle, " +
               compare::formatShort(recommended) + ", leaves the most room either way on this slice.";
    }
    return s + "stiff: no sampled value keeps " + limit + ". At the best compromise, " +
           compare::formatShort(window.bestBias) + ", " + artifactName(dominant, kind) + " dominates (" +
           compare::formatPercent(window.bestFalseShadowRate) + " false, " +
           compare::formatPercent(window.bestMissedShadowRate) + " missed).";
}

const BiasSeries* AutoBias::primary(const std::string& kind) const {
    const BiasSeries* best = nullptr;
    for (const BiasSeries& s : series)
        if (s.kind == kind && (!best || s.samples.size() > best->samples.size())) best = &s;
    return best;
}

const RobustResult* AutoBias::robustPick() const {
    // By precision, not by measured time: float is the tracer's own and the cheaper walk, and the
    // two precisions' sweep rows often time within the noise, so a pick by time changed between
    // two runs of the same scene. Double only where float does not pass.
    auto rank = [](const std::string& precision) { return precision == "float" ? 0 : precision.empty() ? 1 : 2; };
    const RobustResult* best = nullptr;
    for (const RobustResult& r : robust)
        if (r.passes && (!best || rank(r.precision) < rank(best->precision))) best = &r;
    return best;
}

AutoBias recommendBias(const std::vector<SweepRow>& rows, double threshold) {
    if (!std::isfinite(threshold) || threshold < 0.0)
        throw scene::InputError("automatic bias: threshold must be a finite rate >= 0, got " +
                                compare::formatShort(threshold));
    AutoBias out;
    out.threshold = threshold;

    // Group the usable rows by kind and shared settings, in first-seen order per kind.
    for (const std::string& kind : seriesKinds()) {
        std::vector<BiasSeries> found;
        std::map<std::pair<scene::Backend, std::string>, std::size_t> index;  // by backend and context
        for (const SweepRow& r : rows) {
            if (r.config.biasKind != kind || !r.error.empty() || !std::isfinite(r.config.biasValue)) continue;
            const double f = r.rate("false_shadow_rate"), m = r.missedBesideTerminatorRate();
            if (!std::isfinite(f) || !std::isfinite(m)) continue;
            const Json context = contextOf(r.config, kindKey(kind));
            const std::pair<scene::Backend, std::string> groupKey{r.config.backend, context.dump()};
            auto it = index.find(groupKey);
            if (it == index.end()) {
                BiasSeries s;
                s.kind = kind;
                s.backend = r.config.backend;
                s.context = context;
                it = index.emplace(groupKey, found.size()).first;
                found.push_back(s);
            }
            found[it->second].samples.push_back({r.config.biasValue, f, m});
        }
        // A row of another kind, or of none, that sets this kind's bias and otherwise matches a
        // series is a sample of it too: defaultGrid's slope series starts at slope 0 with the
        // depth series' first row (depth 0, slope 0) rather than rendering it twice.
        for (const SweepRow& r : rows) {
            if (r.config.biasKind == kind || !r.error.empty()) continue;
            const std::optional<double> bias = biasOf(r.config, kind);
            const double f = r.rate("false_shadow_rate"), m = r.missedBesideTerminatorRate();
            if (!bias || !std::isfinite(f) || !std::isfinite(m)) continue;
            const auto it = index.find({r.config.backend, contextOf(r.config, kindKey(kind)).dump()});
            if (it == index.end()) continue;
            auto& samples = found[it->second].samples;
            if (std::none_of(samples.begin(), samples.end(),
                             [&](const compare::BiasSample& b) { return b.bias == *bias; }))
                samples.push_back({*bias, f, m});
        }
        for (BiasSeries& s : found) {
            std::stable_sort(
                s.samples.begin(), s.samples.end(),
                [](const compare::BiasSample& a, const compare::BiasSample& b) { return a.bias < b.bias; });
            s.window = compare::findBiasWindow(s.samples, threshold);
            std::vector<double> biases;
            for (const auto& b : s.samples) biases.push_back(b.bias);
            s.logSpaced = isLogSpaced(biases);
            if (!s.window.stiff) {
                s.recommended = tidy(windowMiddle(s.window.lo, s.window.hi, s.logSpaced), s.window.lo, s.window.hi);
            } else {
                s.recommended = s.window.bestBias;
                s.dominant = s.window.bestFalseShadowRate >= s.window.bestMissedShadowRate ? "false" : "missed";
            }
            out.series.push_back(std::move(s));
        }
    }

    for (const SweepRow& r : rows) {
        if (r.config.backend != scene::Backend::Raytrace ||
            r.config.overrides.rayBias != std::optional<std::string>("robust") || !r.error.empty())
            continue;
        // Judged as the bias windows are: the terminator's faceted shadow left out.
        const double f = r.rate("false_shadow_rate"), m = r.missedBesideTerminatorRate();
        if (!std::isfinite(f) || !std::isfinite(m)) continue;
        out.robust.push_back(
            {r.config.overrides.precision.value_or(""), f, m, r.frameMs, f <= threshold && m <= threshold});
    }

    // One sentence per primary series; others (the same kind at other settings) are mentioned.
    for (const std::string& kind : seriesKinds()) {
        const BiasSeries* p = out.primary(kind);
        if (!p) continue;
        out.notes.push_back(p->describe());
        const auto others = std::count_if(out.series.begin(), out.series.end(),
                                          [&](const BiasSeries& s) { return s.kind == kind && &s != p; });
        if (others > 0)
            out.notes.push_back("The sweep also holds " + std::to_string(others) + " other " + p->name() +
                                " series at other settings; the recommendation uses the longest one.");
    }

    // The raster: one bias kind, as measured (its series held the other kind fixed).
    const BiasSeries* depth = out.primary("depth");
    const BiasSeries* slope = out.primary("slope");
    const BiasSeries* raster = nullptr;
    if (depth && slope) {
        const bool depthOpen = !depth->window.stiff, slopeOpen = !slope->window.stiff;
        if (depthOpen && slopeOpen)
            raster = slope->window.acceptableSamples > depth->window.acceptableSamples ? slope : depth;
        else if (depthOpen || slopeOpen)
            raster = depthOpen ? depth : slope;
        else
            raster = worstOf(slope->window.bestFalseShadowRate, slope->window.bestMissedShadowRate) <
                             worstOf(depth->window.bestFalseShadowRate, depth->window.bestMissedShadowRate)
                         ? slope
                         : depth;
    } else {
        raster = depth ? depth : slope;
    }
    if (raster) {
        for (const auto& [key, value] : raster->context.items()) out.shadowBlock[key] = value;
        out.shadowBlock[kindKey(raster->kind)] = raster->recommended;
        const BiasSeries* other = raster == depth ? slope : depth;
        std::string why;
        if (raster->window.stiff) {
            why = "On the probe slice the shadow map is stiff for this scene: no " +
                  std::string(other ? "depth or slope bias" : raster->name()) +
                  " keeps both rates <= " + compare::formatPercent(threshold) + ". Its best compromise is " +
                  raster->name() + " " + compare::formatShort(raster->recommended) + ", where " +
                  artifactName(raster->dominant, raster->kind) + " dominates.";
        } else if (other) {
            why = "On the probe slice the " + raster->name() + " is the pick (" +
                  compare::formatShort(raster->recommended) + " " + raster->unit() + "): ";
            why += other->window.stiff
                       ? "the " + other->name() + " has no window."
                       : "its window holds " + std::to_string(raster->window.acceptableSamples) +
                             " sampled values against " + std::to_string(other->window.acceptableSamples) +
                             " for the " + other->name() + ".";
            why += " Each was measured with the other held fixed.";
        } else {
            why = "On the probe slice: " + raster->name() + " " + compare::formatShort(raster->recommended) + " " +
                  raster->unit() + ".";
        }
        out.notes.push_back(why);
    }

    // The filterable maps' own parameters: into the block when it holds the filter they were
    // measured with (each series held the others fixed), else a sentence says why not.
    for (const MomentKind& m : kMomentKinds) {
        const BiasSeries* p = out.primary(m.kind);
        if (!p || p->window.stiff) continue;
        const std::string filter = p->context.value("filter", std::string());
        if (out.shadowBlock.value("filter", std::string()) == filter) {
            out.shadowBlock[m.key] = p->recommended;
        } else {
            out.notes.push_back(
                std::string("The ") + m.name + " window was measured with filter " +
                (filter.empty() ? std::string("(scene default)") : filter) + "; the block's shadow map uses " +
                out.shadowBlock.value("filter", std::string("its default")) + ", so it does not carry \"" + m.key +
                "\": " + m.key + " " + compare::formatShort(p->recommended) + " goes with that filter.");
        }
    }

    // The ray tracer: robust offsets when they pass, else the ray-bias series.
    const BiasSeries* ray = out.primary("ray");
    const RobustResult* pick = out.robustPick();
    if (pick) {
        out.shadowBlock["ray_bias"] = "robust";
        if (!pick->precision.empty()) out.shadowBlock["precision"] = pick->precision;
        out.notes.push_back("Robust ray offsets" + precisionText(pick->precision) + " keep both rates <= " +
                            compare::formatPercent(threshold) + " (" + compare::formatPercent(pick->falseShadowRate) +
                            " false, " + compare::formatPercent(pick->missedShadowRate) +
                            " missed) with no bias to tune: the ray tracer "
                            "should use \"ray_bias\": \"robust\".");
    } else {
        for (const RobustResult& r : out.robust)
            out.notes.push_back("Robust ray offsets" + precisionText(r.precision) +
                                " do not pass: " + compare::formatPercent(r.falseShadowRate) + " false, " +
                                compare::formatPercent(r.missedShadowRate) + " missed.");
        if (ray) {
            for (const auto& [key, value] : ray->context.items()) out.shadowBlock[key] = value;
            out.shadowBlock["ray_bias"] = ray->recommended;
            if (ray->window.stiff)
                out.notes.push_back(
                    "The ray tracer is stiff for this scene with a constant ray bias; the block uses the "
                    "best compromise, " +
                    compare::formatShort(ray->recommended) + " world units, where " +
                    artifactName(ray->dominant, "ray") + " dominates.");
        } else if (!out.robust.empty()) {
            const auto best = std::min_element(out.robust.begin(), out.robust.end(), [](const auto& a, const auto& b) {
                return worstOf(a.falseShadowRate, a.missedShadowRate) < worstOf(b.falseShadowRate, b.missedShadowRate);
            });
            out.shadowBlock["ray_bias"] = "robust";
            if (!best->precision.empty()) out.shadowBlock["precision"] = best->precision;
        }
    }
    return out;
}

}  // namespace shadowlab::studies
