// compare/report.cpp: renders the `shadowlab run` report as one self-contained HTML page and
// writes the paragraph that says in words what the comparison found.
#include "compare/report.h"

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <set>
#include <sstream>

#include "compare/svg_plot.h"
#include "compare/text.h"
#include "compare/thresholds.h"
#include "scene/frame_io.h"

namespace shadowlab::compare {

namespace {

// Two methods whose wrong-pixel rates lie within this ratio are called about as close to the
// reference, not ranked: a difference that small moves with a texel's rounding or a pixel of
// view, and the images show no winner.
constexpr double kSameErrorRatio = 1.1;
// Mean |ΔV| that overrides the wrong-pixel ranking: at least twice the other's and more than this
// apart (below it both print alike and neither is visibly worse).
constexpr double kMeanDisagreeRatio = 2.0;
constexpr double kMeanDisagreeMin = 0.0005;

std::string methodTitle(const std::string& label) {
    if (label == "raster") return "The shadow map (raster)";
    if (label == "raytrace") return "The ray tracer (raytrace)";
    return "The " + label + " method";
}

std::string shortTitle(const std::string& label) {
    if (label == "raster") return "the shadow map";
    if (label == "raytrace") return "the ray tracer";
    return label;
}

std::string objectName(const ReportInput& in, int id) {
    if (id >= 1 && std::size_t(id) <= in.objectNames.size() && !in.objectNames[id - 1].empty())
        return in.objectNames[id - 1];
    return "object " + std::to_string(id);
}

// The object carrying more than half of a class, or "" when none does.
template <typename Count>
std::string dominantObject(const ReportInput& in, const Metrics& m, std::size_t total, Count count) {
    if (total == 0) return "";
    for (const auto& o : m.perObject)
        if (double(count(o)) > kMostlyShare * double(total)) return objectName(in, o.objectId);
    return "";
}

std::string ratio(double a, double b) {
    // "3.2× faster" style wording of a/b for run times.
    if (!(a > 0.0) || !(b > 0.0)) return "";
    const double r = b / a;
    if (r >= 1.05) return formatFixed(r, r >= 10 ? 0 : 1) + "× faster than";
    if (r <= 1 / 1.05) return formatFixed(1 / r, 1 / r >= 10 ? 0 : 1) + "× slower than";
    return "about as fast as";
}

std::string healthText(const FrameHealth& h) {
    std::vector<std::string> parts;
    auto add = [&](const char* name, const NonFinite& n) {
        if (n.total() == 0) return;
        std::string s = std::string(name) + ": ";
        if (n.nan) s += formatCount(n.nan) + " NaN";
        if (n.nan && n.inf) s += ", ";
        if (n.inf) s += formatCount(n.inf) + " Inf";
        parts.push_back(s);
    };
    add("beauty", h.beauty);
    add("visibility", h.visibility);
    add("object_id", h.objectId);
    add("ndotl", h.ndotl);
    add("Z", h.depth);
    add("blocker_id", h.blockerId);
    std::string out;
    for (std::size_t i = 0; i < parts.size(); ++i) out += (i ? "; " : "") + parts[i];
    return out;
}

// The continuous error in words: the mean, the penumbra's mean, and the soft-shadow error the
// classes hide, named as what dominates when it outnumbers the wrong pixels.
std::string describeContinuous(const Metrics& m) {
    std::string s = "Its visibility is off by " + formatFixed(m.meanAbsVisibilityError, 4) + " on average";
    if (m.penumbraPixels > 0)
        s += " and by " + formatFixed(m.meanAbsVisibilityErrorPenumbra, 3) + " over the reference's penumbra (" +
             formatCount(m.penumbraPixels) + " px where 0 < V < 1)";
    s += ".";
    if (m.softErrorPixels > 0) {
        s += " " + formatCount(m.softErrorPixels) + " px (" + formatPercent(m.softErrorRate) +
             ") are off by more than " + formatShort(kSoftErrorTolerance) + " without crossing τ";
        if (m.softErrorNearEdge > 0)
            s += " (" + formatCount(m.softErrorNearEdge) + " of them within " + std::to_string(m.edgeRadius) +
                 " px of the reference's shadow edges, where a filter blurs a hard edge)";
        const double away = double(softErrorAwayFromEdges(m));
        if (away <= kNotableSoftErrorRate * double(m.counted))
            s += ".";
        else if (softErrorDominates(m))
            s += ": soft-shadow error dominates, and the mismatch rate does not show it.";
        else
            s += m.falseShadow + m.missedShadow > 0 ? ": soft-shadow error beside the wrong pixels." : ".";
    }
    const std::size_t lightWrong = m.perLightWrongPixels;
    if (lightsHideWrongPixels(m))
        s += " Per light, " + formatCount(lightWrong) + " px are wrong outright, more than the " +
             formatCount(m.falseShadow + m.missedShadow) +
             " the combined visibility counts: where one light's shadow is lost or added, another light still "
             "reaches the point and the combined value moves by less than τ, so judge each light by its own "
             "channel.";
    for (const LightError& l : m.perLight)
        if (l.softErrorPixels > 0 || l.falseShadow + l.missedShadow > 0 ||
            l.meanAbsVisibilityErrorPenumbra > kSoftErrorTolerance)
            s += " Light " + std::to_string(l.light) + ": mean |ΔV| " + formatFixed(l.meanAbsVisibilityError, 4) +
                 (l.penumbraPixels ? ", " + formatFixed(l.meanAbsVisibilityErrorPenumbra, 3) + " over its penumbra"
                                   : "") +
                 (l.falseShadow + l.missedShadow > 0 ? ", " + formatCount(l.falseShadow) + " px false shadow and " +
                                                           formatCount(l.missedShadow) + " px missed in its own channel"
                                                     : "") +
                 (l.softErrorPixels > 0 ? ", " + formatCount(l.softErrorPixels) + " px off by more than " +
                                              formatShort(kSoftErrorTolerance) + " within τ"
                                        : "") +
                 ".";
    return s;
}

// Where the default map size was capped below what the receivers and casters ask for (the raster
// frame's shadow_map_size_needed against shadow_map_size), the words that say so; else "".
std::string cappedMapText(const FrameInfo& frame) {
    auto number = [&](const char* key) {
        const auto it = frame.attributes.find(key);
        return it == frame.attributes.end() ? 0.0 : std::atof(it->second.c_str());
    };
    const double needed = number("shadow_map_size_needed"), size = number("shadow_map_size");
    if (!(size > 0.0) || !(needed > size)) return "";
    return " (the receivers and casters ask for " + formatCount(std::size_t(needed)) + " texels across the map, the " +
           "default caps it at " + formatCount(std::size_t(size)) +
           ": a larger --shadow-map-size shrinks the texels and the contact distance with them)";
}

std::string describeMethod(const ReportInput& in, const ReportMethod& rm) {
    const Metrics& m = rm.metrics;
    const std::string who = methodTitle(rm.label);
    std::string s;
    if (m.counted == 0) {
        s = who +
            " has no pixel to compare: no visible point faces the light in both frames "
            "on the same object.";
    } else if (m.falseShadow + m.missedShadow == 0 && !lightsHideWrongPixels(m) &&
               double(softErrorAwayFromEdges(m)) <= kNotableSoftErrorRate * double(m.counted)) {
        s = who + " matches the reference on all " + formatCount(m.counted) + " counted pixels (mean |ΔV| " +
            formatFixed(m.meanAbsVisibilityError, 4) + ")";
        s += m.softErrorNearEdge > 0
                 ? " but for its filter's blur along the shadow edges (" + formatCount(m.softErrorNearEdge) +
                       " px off by more than " + formatShort(kSoftErrorTolerance) + " there, within τ)."
                 : ".";
    } else if (m.falseShadow + m.missedShadow == 0) {
        s = who + " has no pixel wrong by more than τ = " + formatShort(kVisibilityTolerance) + " among the " +
            formatCount(m.counted) + " counted pixels, so the classes call it agreement, but it does not match" +
            (lightsHideWrongPixels(m)
                 ? ": one light's shadow is wrong outright where another light still reaches the point."
                 : ".");
    } else {
        s = softErrorDominates(m)
                // Lead with what a viewer sees: partial darkening under τ outnumbers the wrong pixels.
                ? who + " is partly wrong on " + formatPercent(double(softErrorAwayFromEdges(m)) / double(m.counted)) +
                      " of the " + formatCount(m.counted) +
                      " counted pixels away from the shadow edges (off by more than " +
                      formatShort(kSoftErrorTolerance) + " without crossing τ: " +
                      (lightsHideWrongPixels(m)
                           ? "one light's shadow wrong outright where another light still reaches the point"
                           : "filtered acne, or a penumbra of the wrong width") +
                      "), which the mismatch rate does not count; outright it disagrees with the reference on " +
                      formatPercent(m.mismatchRate) + ": "
                : who + " disagrees with the reference on " + formatPercent(m.mismatchRate) + " of the " +
                      formatCount(m.counted) + " counted pixels: ";
        // Missed shadow's causes, each pixel named once: the terminator's pixels are bias leaks too
        // (a facet's neighbour is within any contact distance), so peter-panning leaves them out.
        const bool terminatorMost = double(m.terminatorMissed) > kMostlyShare * double(m.missedShadow);
        const std::size_t leak = m.biasLeakBesideTerminator();
        const bool mapLeaks = m.hasBlockerDistance && !m.pointSampled && !terminatorMost;
        const bool leakMost = mapLeaks && double(leak) > kMostlyShare * double(m.missedShadow);
        const bool leakNotable =
            mapLeaks && !leakMost && leak > 0 && double(leak) >= kNotableShare * double(m.missedShadow);
        std::vector<std::string> parts;
        if (m.falseShadow > 0) {
            std::string f = formatPercent(m.falseShadowRate) + " false shadow";
            if (m.hasBlockerIds && double(m.selfShadowAcne) > kMostlyShare * double(m.falseShadow)) {
                f += ", mostly self-shadow acne";
                const std::string on =
                    dominantObject(in, m, m.selfShadowAcne, [](const ObjectErrors& o) { return o.selfShadowAcne; });
                if (!on.empty()) f += " on " + on;
                if (double(m.selfShadowAcneGrazing) > kMostlyShare * double(m.selfShadowAcne))
                    f += " (" + formatPercent(double(m.selfShadowAcneGrazing) / double(m.selfShadowAcne)) +
                         " of it lit near grazing, N·L below " + formatShort(kTerminatorNdotL) +
                         ", where a curved surface bends away from its own map texels faster than the slope "
                         "bias follows; a normal offset of a fraction of a texel clears it without the contact "
                         "shadows a larger bias loses)";
            } else {
                if (m.hasBlockerIds && m.selfShadowAcne > 0)
                    f += " (" + formatPercent(double(m.selfShadowAcne) / double(m.falseShadow)) +
                         " of it self-shadow acne)";
                const std::string on =
                    dominantObject(in, m, m.falseShadow, [](const ObjectErrors& o) { return o.falseShadow; });
                if (!on.empty()) f += ", mostly on " + on;
            }
            parts.push_back(f);
        } else {
            parts.push_back("no false shadow");
        }
        if (m.missedShadow > 0 && terminatorMost) {
            // The reference's own faceting, not a leak a viewer of the method's image would see.
            std::string f = formatPercent(m.missedShadowRate) + " missed shadow, " +
                            formatPercent(double(m.terminatorMissed) / double(m.missedShadow)) +
                            " of it at a smooth-shaded mesh's terminator";
            const std::string on =
                dominantObject(in, m, m.terminatorMissed, [](const ObjectErrors& o) { return o.terminatorMissed; });
            if (!on.empty()) f += " on " + on;
            f += " (N·L below " + formatShort(kTerminatorNdotL) +
                 ", the receiver shadowed by its own surface): there the reference's flat facets shadow their "
                 "neighbours while the interpolated normal still faces the light, and " +
                 std::string(m.pointSampled ? "the ray's offset along that normal lifts the point out of it"
                                            : "the map's bias reaches past the neighbouring facet") +
                 ", as renderers mean to; a tessellation effect rather than a leak";
            parts.push_back(f);
        } else if (m.missedShadow > 0) {
            std::string f = formatPercent(m.missedShadowRate) + " missed shadow (light leaking or peter-panning";
            const std::string on =
                dominantObject(in, m, m.missedShadow, [](const ObjectErrors& o) { return o.missedShadow; });
            f += on.empty() ? ")" : ", mostly on " + on + ")";
            // Near its blocker, a missed shadow is the bias's and the texel grid's; far from it, the
            // filter's (light bleeding).
            if (leakMost)
                f += ", " + formatPercent(double(leak) / double(m.missedShadow)) +
                     " of it within the contact distance of its blocker (" + formatShort(m.contactDistance) +
                     " with the light head-on, more at grazing light): a caster that close to its receiver is lost "
                     "to the bias and the map's texels" +
                     cappedMapText(rm.frame);
            else {
                // A minority by count can still be what a viewer sees first: a shadow detached from
                // where a thin caster meets the ground is a few pixels against long aliased edges.
                if (leakNotable)
                    f += ", " + formatPercent(double(leak) / double(m.missedShadow)) + " of it (" + formatCount(leak) +
                         " px) within the contact distance of its blocker (" + formatShort(m.contactDistance) +
                         " with the light head-on, more at grazing light): peter-panning, the shadow cut "
                         "off where its caster meets the receiver, lost to the bias and the map's texels" +
                         cappedMapText(rm.frame);
                if (m.hasBlockerDistance && m.bleeding > 0)
                    f += double(m.bleeding) > kMostlyShare * double(m.missedShadow)
                             ? ", mostly light bleeding (" +
                                   formatPercent(double(m.bleeding) / double(m.missedShadow)) + " of it farther than " +
                                   formatShort(m.contactDistance) + " from its blocker)"
                             : " (" + formatPercent(double(m.bleeding) / double(m.missedShadow)) +
                                   " of it light bleeding, farther than " + formatShort(m.contactDistance) +
                                   " from its blocker)";
            }
            if (m.terminatorMissed > 0 && double(m.terminatorMissed) >= kNotableShare * double(m.missedShadow))
                f += "; " + formatPercent(double(m.terminatorMissed) / double(m.missedShadow)) +
                     " of it lies at a smooth-shaded mesh's terminator (the receiver shadowed by its own surface at "
                     "N·L below " +
                     formatShort(kTerminatorNdotL) + "), where the reference's flat facets shadow their neighbours";
            parts.push_back(f);
        } else {
            parts.push_back("no missed shadow");
        }
        s += parts[0] + " and " + parts[1] + ".";
        const std::size_t wrong = m.falseShadow + m.missedShadow;
        const std::string within = " within " + std::to_string(m.edgeRadius) + " px of a reference shadow edge";
        if (m.pointSampled) {
            // A ray tracer tests the very point the reference tests: where it disagrees, its origin
            // offset or its arithmetic put the ray on the other side of a blocker's edge.
            const double nearShare = double(m.falseShadowNearEdge + m.missedShadowNearEdge) / double(wrong);
            s += " It tests each pixel's own point, as the reference does, so none of this is aliasing: it is its "
                 "ray offset and precision";
            s += nearShare > kMostlyShare ? " (" + formatPercent(nearShare) + " of the wrong pixels lie" + within +
                                                ", where a ray started off its surface passes a blocker's edge on the "
                                                "other side)."
                                          : ".";
        } else {
            const double nearShare = double(m.aliasingPixels) / double(wrong);
            if (nearShare > kMostlyShare)
                s += " Most wrong pixels (" + formatPercent(nearShare) + ") lie" + within +
                     (leakNotable ? ": edge aliasing, beside the bias's peter-panning above."
                                  : ": edge aliasing rather than bias.");
            else if (m.aliasingPixels > 0)
                s += " " + formatPercent(1.0 - nearShare) +
                     " of the wrong pixels are bias error (away from shadow edges" +
                     (m.biasLeakNearEdge > 0 ? ", or missed within the contact distance of their blocker" : "") +
                     "), the rest lie" + within + " (aliasing).";
        }
        s += " Its shadowed area overlaps the reference's with IoU " + formatFixed(m.shadowIoU, 3) + ".";
    }
    if (m.counted > 0) s += " " + describeContinuous(m);
    if (m.silhouetteMismatchRate > kNotableSilhouetteRate)
        s += " Silhouettes differ on " + formatPercent(m.silhouetteMismatchRate) + " of the image (not counted).";
    const double t = m.methodTiming.totalMs, tr = m.referenceTiming.totalMs;
    if (t > 0.0) {
        s += " It took " + formatDuration(t);
        const std::string r = ratio(t, tr);
        s += r.empty() ? "." : ", " + r + " the reference.";
    }
    if (m.methodHealth.total() > 0)
        s += " Warning: it produced non-finite values (" + healthText(m.methodHealth) + ").";
    return s;
}

// ---- HTML pieces ----------------------------------------------------------------------

const char* kCss = R"CSS(
:root { --ink:#1f2933; --muted:#616e7c; --line:#e4e7eb; --bg:#f5f7fa; --card:#fff;
        --false:#ff140d; --missed:#1a66ff; }
* { box-sizing: border-box; }
body { margin: 0; background: var(--bg); color: var(--ink);
       font: 14px/1.5 system-ui, -apple-system, "Segoe UI", Roboto, sans-serif; }
main { max-width: 1360px; margin: 0 auto; padding: 24px 28px 48px; }
header h1 { margin: 0; font-size: 24px; font-weight: 650; }
header .sub { color: var(--muted); margin-top: 2px; }
h2 { font-size: 17px; margin: 28px 0 10px; font-weight: 650; }
section.card, .findings { background: var(--card); border: 1px solid var(--line); border-radius: 8px;
       padding: 16px 18px; }
.findings { margin-top: 16px; border-left: 4px solid #3e4c59; font-size: 15px; }
.findings p { margin: 0 0 6px; }
.failure { background: #fff5f5; border: 1px solid #ffc9c9; color: #a51111; border-radius: 8px;
       padding: 10px 14px; margin-top: 12px; }
.grid { display: grid; gap: 14px; }
figure { margin: 0; }
figure img { width: 100%; height: auto; display: block; border-radius: 4px; background: #222; }
figure figcaption { font-weight: 600; margin-bottom: 6px; }
figure figcaption span { font-weight: 400; color: var(--muted); }
img.upscale, .crop img { image-rendering: pixelated; }
.imgwrap { position: relative; }
.hot { position: absolute; border: 2px solid #ffd43b; box-shadow: 0 0 0 1px #000; pointer-events: none; }
.crops { display: grid; grid-template-columns: 1fr 1fr; gap: 6px; margin-top: 8px; }
.crop { position: relative; width: 100%; aspect-ratio: 1 / 1; overflow: hidden; border-radius: 4px;
        background: #222; }
.crop img { position: absolute; max-width: none; }
.small { color: var(--muted); font-size: 12px; }
.settings { margin-top: 4px; font-family: ui-monospace, "SFMono-Regular", Menlo, monospace; }
.legend { list-style: none; padding: 0; margin: 0; }
.legend li { display: flex; align-items: flex-start; gap: 8px; margin: 0 0 8px; }
.sw { flex: none; width: 16px; height: 16px; border-radius: 3px; border: 1px solid #0003; margin-top: 2px; }
table { border-collapse: collapse; width: 100%; background: var(--card); }
th, td { padding: 6px 10px; border-bottom: 1px solid var(--line); text-align: right;
         font-variant-numeric: tabular-nums; }
th:first-child, td:first-child { text-align: left; }
thead th { background: #f0f4f8; font-weight: 600; }
td .rate { color: var(--muted); margin-left: 6px; }
tr.key td { font-weight: 600; }
.plotrow { display: grid; grid-template-columns: minmax(0, 660px) minmax(0, 1fr); gap: 18px; align-items: start; }
svg.plot { max-width: 100%; height: auto; border: 1px solid var(--line); border-radius: 8px; }
details { margin-top: 10px; }
summary { cursor: pointer; font-weight: 600; }
ul.sweeplines { margin: 0 0 8px; padding-left: 18px; }
ul.sweeplines li { margin-bottom: 6px; }
pre { background: #f0f4f8; padding: 10px 12px; border-radius: 6px; overflow-x: auto; font-size: 12px; }
a { color: #1864ab; }
.heatbar { height: 14px; border-radius: 3px; border: 1px solid #0003; }
.heatticks { display: flex; justify-content: space-between; font-size: 12px; color: var(--muted); }
.warning { background: #fff9db; border: 1px solid #ffe066; color: #5c3c00; border-radius: 8px;
       padding: 10px 14px; margin-top: 12px; }
)CSS";

std::string swatch(const std::array<float, 3>& c) {
    char buf[64];
    std::snprintf(buf, sizeof buf, "#%02x%02x%02x", int(std::lround(c[0] * 255)), int(std::lround(c[1] * 255)),
                  int(std::lround(c[2] * 255)));
    return buf;
}

std::string swatchGradient(float base, float scale) {
    const float lo = base, hi = base + scale;
    return "background: linear-gradient(90deg," + swatch({lo, lo, lo}) + "," + swatch({hi, hi, hi}) + ")";
}

std::string figure(const std::string& caption, const std::string& note, const std::string& png, const FrameInfo& f,
                   const ErrorHotspot* hot) {
    std::ostringstream o;
    // Small frames are magnified with hard pixel edges; large ones scale down smoothly so a
    // single red pixel still tints its neighbourhood instead of vanishing.
    const bool upscale = f.width > 0 && f.width <= 440;
    o << "<figure><figcaption>" << escapeHtml(caption);
    if (!note.empty()) o << " <span>" << escapeHtml(note) << "</span>";
    o << "</figcaption><div class=\"imgwrap\"><a href=\"" << escapeHtml(png) << "\"><img src=\"" << escapeHtml(png)
      << "\" alt=\"" << escapeHtml(caption) << "\"" << (upscale ? " class=\"upscale\"" : "");
    if (f.width > 0) o << " width=\"" << f.width << "\" height=\"" << f.height << "\"";
    o << "></a>";
    if (hot && hot->wrongPixels > 0 && f.width > 0 && f.height > 0) {
        o << "<div class=\"hot\" title=\"zoomed below\" style=\"left:" << formatFixed(100.0 * hot->x / f.width, 3)
          << "%;top:" << formatFixed(100.0 * hot->y / f.height, 3)
          << "%;width:" << formatFixed(100.0 * hot->size / f.width, 3)
          << "%;height:" << formatFixed(100.0 * hot->size / f.height, 3) << "%\"></div>";
    }
    o << "</div></figure>\n";
    return o.str();
}

// The settings that decide a frame's shadows, on one line under its image, fractions to three
// digits; every attribute, in full, is in the Settings section at the end.
std::string settingsLine(const FrameInfo& f) {
    static const char* const kKeys[] = {"shadow_map_size", "filter",   "depth_bias", "slope_bias", "normal_offset",
                                        "shadow_maps",     "ray_bias", "precision",  "samples"};
    std::string line;
    for (const char* key : kKeys) {
        const auto it = f.attributes.find(key);
        if (it == f.attributes.end()) continue;
        std::string v = it->second;
        char* end = nullptr;
        const double number = std::strtod(v.c_str(), &end);
        if (!v.empty() && end == v.c_str() + v.size() && std::isfinite(number) && number != std::floor(number))
            v = formatShort(number);  // (whole numbers, a map size, stay as they are)
        line += (line.empty() ? "" : " · ") + std::string(key) + " " + v;
    }
    return line.empty() ? "" : "<div class=\"small settings\">" + escapeHtml(line) + "</div>";
}

// Why the scene is seen and lit as it is (the view, sun, lights and ground the program chose,
// the reference frame's choice.* attributes), in full.
std::string choicesHtml(const FrameInfo& f) {
    std::string items;
    for (const auto& [key, value] : f.attributes)
        if (key.rfind("choice.", 0) == 0)
            items += "<li><b>" + escapeHtml(key.substr(7)) + "</b>: " + escapeHtml(value) + "</li>";
    return items.empty() ? "" : "<ul class=\"small choices\">" + items + "</ul>\n";
}

// A square crop of `png` showing the hotspot window, scaled up with hard pixel edges. Pure CSS:
// the container is square, so percentages of its width also work for the vertical offset.
std::string crop(const std::string& png, const FrameInfo& f, const ErrorHotspot& hot, const std::string& alt) {
    std::ostringstream o;
    const double s = hot.size;
    o << "<div class=\"crop\"><img src=\"" << escapeHtml(png) << "\" alt=\"" << escapeHtml(alt)
      << "\" style=\"width:" << formatFixed(100.0 * f.width / s, 3) << "%;left:" << formatFixed(-100.0 * hot.x / s, 3)
      << "%;top:" << formatFixed(-100.0 * hot.y / s, 3) << "%\"></div>";
    return o.str();
}

std::string countCell(std::size_t n, double r, bool showRate = true) {
    std::string s = "<td>" + formatCount(n);
    if (showRate) s += "<span class=\"rate\">" + formatPercent(r) + "</span>";
    return s + "</td>";
}

std::string legendHtml() {
    using C = DiffColors;
    std::ostringstream o;
    o << "<ul class=\"legend\">"
      << "<li><span class=\"sw\" style=\"background:" << swatch(C::kFalseShadow)
      << "\"></span><span><b>False shadow</b>: the method is dark where the reference is lit "
         "(acne, over-darkening). Red speckles on a lit surface are acne.</span></li>"
      << "<li><span class=\"sw\" style=\"background:" << swatch(C::kMissedShadow)
      << "\"></span><span><b>Missed shadow</b>: the method is lit where the reference is dark "
         "(light leaking, peter-panning). Blue areas along a contact are a detached shadow.</span></li>"
      << "<li><span class=\"sw\" style=\"" << swatchGradient(C::kLitBase, C::kLitScale)
      << "\"></span><span><b>Agree, lit</b>: the reference image, gray and dimmed.</span></li>"
      << "<li><span class=\"sw\" style=\"" << swatchGradient(C::kShadowBase, C::kShadowScale)
      << "\"></span><span><b>Agree, shadow</b>: darker.</span></li>"
      << "<li><span class=\"sw\" style=\"background:" << swatch(C::kNotCounted)
      << "\"></span><span><b>Not counted</b>: background, surfaces facing away from the light, "
         "or a different object in the two frames (silhouettes).</span></li>"
      << "<li><span class=\"sw\" style=\"background:" << swatch(C::kInvalid)
      << "\"></span><span><b>Invalid</b>: NaN or infinity in either frame.</span></li>"
      << "</ul><p class=\"small\">A pixel counts when both frames see the same object there and "
         "it faces the light (N·L &gt; 0) in both. Visibilities V disagree when |V<sub>method</sub> − "
         "V<sub>reference</sub>| &gt; "
      << formatShort(kVisibilityTolerance)
      << ". The yellow square marks the region with the most "
         "errors, zoomed under each difference image.</p>";
    return o.str();
}

std::string heatLegendHtml() {
    std::ostringstream stops;
    for (std::size_t k = 0; k < HeatScale::kStops.size(); ++k)
        stops << ',' << swatch(HeatScale::kStops[k]) << ' ' << formatShort(100.0 * double(k) / 4.0) << '%';
    std::ostringstream o;
    o << "<div class=\"heatbar\" style=\"background:linear-gradient(90deg" << stops.str() << ")\"></div>"
      << "<div class=\"heatticks\"><span>0</span><span>0.25</span><span>0.5 "
         "(τ)</span><span>0.75</span><span>1</span></div>"
      << "<p class=\"small\">|V<sub>method</sub> − V<sub>reference</sub>| per counted pixel: dark where the two agree, "
         "brighter the further apart. Between 0.25 and 0.5 (purple to red) a pixel is wrong but still agrees in class; "
         "above 0.5 it is a false or missed shadow. <span class=\"sw\" "
         "style=\"display:inline-block;vertical-align:middle;background:"
      << swatch(DiffColors::kNotCounted)
      << "\"></span> not counted, <span class=\"sw\" style=\"display:inline-block;"
         "vertical-align:middle;background:"
      << swatch(DiffColors::kInvalid) << "\"></span> invalid.</p>";
    return o.str();
}

std::string metricsTable(const ReportInput& in) {
    std::ostringstream o;
    o << "<table class=\"metrics\"><thead><tr><th>metric</th>";
    for (const auto& m : in.methods) o << "<th>" << escapeHtml(m.label) << "</th>";
    o << "</tr></thead><tbody>\n";
    auto row = [&](const std::string& name, auto cell, const char* cls = "") {
        o << "<tr" << (*cls ? std::string(" class=\"") + cls + "\"" : std::string()) << "><td>" << name << "</td>";
        for (const auto& rm : in.methods) o << cell(rm.metrics);
        o << "</tr>\n";
    };
    auto plain = [](const std::string& s) { return "<td>" + s + "</td>"; };
    row("counted pixels",
        [&](const Metrics& m) { return countCell(m.counted, double(m.counted) / std::max<double>(1, m.totalPixels)); });
    row(
        "mismatch", [&](const Metrics& m) { return countCell(m.falseShadow + m.missedShadow, m.mismatchRate); }, "key");
    row("<span style=\"color:var(--false)\">■</span> false shadow",
        [&](const Metrics& m) { return countCell(m.falseShadow, m.falseShadowRate); });
    row("&nbsp;&nbsp;of which self-shadow acne", [&](const Metrics& m) {
        return m.hasBlockerIds ? countCell(m.selfShadowAcne, m.selfShadowAcneRate) : plain("n/a");
    });
    row("<span style=\"color:var(--missed)\">■</span> missed shadow",
        [&](const Metrics& m) { return countCell(m.missedShadow, m.missedShadowRate); });
    row("&nbsp;&nbsp;of which light bleeding (blocker far)",
        [&](const Metrics& m) { return m.hasBlockerDistance ? countCell(m.bleeding, m.bleedingRate) : plain("n/a"); });
    row("&nbsp;&nbsp;of which at a smooth mesh's terminator <span class=\"small\">(a tessellation effect)</span>",
        [&](const Metrics& m) {
            return m.hasReferenceBlockerIds ? countCell(m.terminatorMissed, m.terminatorMissedRate) : plain("n/a");
        });
    // A facet's neighbour is always within the contact distance: the terminator's missed shadow is
    // counted apart, not as leaks.
    row("&nbsp;&nbsp;of which bias leak (blocker within the contact distance, terminators aside)",
        [&](const Metrics& m) {
            if (!m.hasBlockerDistance) return plain("n/a");
            const std::size_t leaks = m.biasLeakBesideTerminator();
            return countCell(leaks, double(leaks) / std::max<double>(1, m.counted));
        });
    row("agree, lit",
        [&](const Metrics& m) { return countCell(m.agreeLit, double(m.agreeLit) / std::max<double>(1, m.counted)); });
    row("agree, shadow", [&](const Metrics& m) {
        return countCell(m.agreeShadow, double(m.agreeShadow) / std::max<double>(1, m.counted));
    });
    row("mean |V<sub>M</sub> − V<sub>R</sub>|",
        [&](const Metrics& m) { return plain(formatFixed(m.meanAbsVisibilityError, 4)); });
    row(
        "mean |V<sub>M</sub> − V<sub>R</sub>| over the reference's penumbra",
        [&](const Metrics& m) {
            return m.penumbraPixels ? "<td>" + formatFixed(m.meanAbsVisibilityErrorPenumbra, 4) +
                                          "<span class=\"rate\">" + formatCount(m.penumbraPixels) + " px</span></td>"
                                    : plain("no penumbra");
        },
        "key");
    row("off by &gt; " + formatShort(kSoftErrorTolerance) + ", ≤ τ (soft error)",
        [&](const Metrics& m) { return countCell(m.softErrorPixels, m.softErrorRate); });
    row("max |V<sub>M</sub> − V<sub>R</sub>|",
        [&](const Metrics& m) { return plain(formatFixed(m.maxAbsVisibilityError, 3)); });
    std::size_t lights = 0;
    for (const auto& rm : in.methods) lights = std::max(lights, rm.metrics.perLight.size());
    for (std::size_t l = 0; l < lights; ++l)
        row("light " + std::to_string(l) + ": mean |ΔV| / over its penumbra", [&](const Metrics& m) {
            if (l >= m.perLight.size()) return plain("–");
            const LightError& e = m.perLight[l];
            return plain(formatFixed(e.meanAbsVisibilityError, 4) + " / " +
                         (e.penumbraPixels ? formatFixed(e.meanAbsVisibilityErrorPenumbra, 4) : std::string("–")));
        });
    row(
        "IoU of shadowed areas", [&](const Metrics& m) { return plain(formatFixed(m.shadowIoU, 4)); }, "key");
    // A ray tracer samples each pixel's own point: it has no aliasing, and every wrong pixel, near
    // an edge or not, is its offset's and precision's (the summary gives the share near edges).
    row("aliasing <span class=\"small\">(wrong near a shadow edge, from the map's texels)</span>",
        [&](const Metrics& m) {
            return m.pointSampled ? plain("none <span class=\"small\">(point-sampled)</span>")
                                  : countCell(m.aliasingPixels, m.aliasingRate);
        });
    row("bias error <span class=\"small\">(the other wrong pixels)</span>",
        [&](const Metrics& m) { return countCell(m.biasErrorPixels, m.biasErrorRate); });
    row("silhouette mismatch <span class=\"small\">(of all pixels)</span>",
        [&](const Metrics& m) { return countCell(m.silhouetteMismatch, m.silhouetteMismatchRate); });
    row("N·L sign differs", [&](const Metrics& m) { return countCell(m.ndotlSignMismatch, 0, false); });
    row("non-finite values", [&](const Metrics& m) {
        const std::string t = healthText(m.methodHealth);
        return plain(t.empty() ? "0" : "<b style=\"color:#c92a2a\">" + escapeHtml(t) + "</b>");
    });
    row(
        "run time", [&](const Metrics& m) { return plain(formatRunTime(m.methodTiming.totalMs)); }, "key");
    o << "</tbody></table>\n";
    return o.str();
}

std::string timingTable(const ReportInput& in) {
    std::vector<std::pair<std::string, const FrameInfo*>> cols;
    cols.push_back({in.reference.label.empty() ? "reference" : in.reference.label, &in.reference.frame});
    for (const auto& m : in.methods) cols.push_back({m.label, &m.frame});
    std::vector<std::string> stages;  // union, in first-seen order
    for (const auto& [label, f] : cols)
        for (const auto& [stage, ms] : f->timingsMs)
            if (std::find(stages.begin(), stages.end(), stage) == stages.end()) stages.push_back(stage);
    std::ostringstream o;
    o << "<table class=\"timings\"><thead><tr><th>stage</th>";
    for (const auto& c : cols) o << "<th>" << escapeHtml(c.first) << "</th>";
    o << "</tr></thead><tbody>\n";
    for (const auto& stage : stages) {
        o << "<tr><td>" << escapeHtml(stage) << "</td>";
        for (const auto& c : cols) {
            const auto it = std::find_if(c.second->timingsMs.begin(), c.second->timingsMs.end(),
                                         [&](const auto& t) { return t.first == stage; });
            o << "<td>" << (it == c.second->timingsMs.end() ? "–" : formatDuration(it->second)) << "</td>";
        }
        o << "</tr>\n";
    }
    o << "<tr class=\"key\"><td>total</td>";
    for (const auto& c : cols) o << "<td>" << formatRunTime(c.second->totalTimeMs()) << "</td>";
    o << "</tr></tbody></table>\n";
    return o.str();
}

std::string errorTimeSvg(const ReportInput& in) {
    std::vector<SweepPoint> points;
    for (const auto& rm : in.methods)
        points.push_back({rm.label, rm.metrics.methodTiming.totalMs, rm.metrics.mismatchRate, rm.label});
    ErrorTimeOptions o;
    o.errorName = "mismatch rate (false + missed)";
    o.logError = false;  // two points, one of them often at zero error
    o.fronts = false;
    o.labels = true;
    return renderSvg(errorTimePlot(points, in.reference.frame.totalTimeMs(), o));
}

// The quick sweep `run` includes: its error-time plot beside its findings and the recommended
// shadow block, and a link to its own report for the images and the table.
std::string sweepSection(const SweepSummary& sw) {
    std::ostringstream o;
    o << "<h2>Quick sweep</h2>\n<p class=\"small\">" << formatCount(sw.configurations) << " configurations";
    if (!sw.resolution.empty()) o << " at " << escapeHtml(sw.resolution);
    if (sw.failed > 0) o << ", " << formatCount(sw.failed) << " failed";
    o << "; each point is one setting, the lines are each backend's Pareto front (nothing is both faster and "
         "more accurate).</p>\n<div class=\"plotrow\"><div>"
      << sw.errorTimeSvg << "</div><div><ul class=\"sweeplines\">";
    for (const auto& line : sw.lines) o << "<li>" << escapeHtml(line) << "</li>";
    o << "</ul>";
    if (!sw.shadowBlockJson.empty())
        o << "<p>Recommended <code>\"shadow\"</code> block for the scene file:</p><pre>"
          << escapeHtml(sw.shadowBlockJson) << "</pre>";
    if (!sw.href.empty())
        o << "<p><a href=\"" << escapeHtml(sw.href)
          << "\">The sweep's own report</a>: every configuration, "
             "best and worst images, bias plots.</p>";
    o << "</div></div>\n";
    return o.str();
}

std::string perObjectTable(const ReportInput& in) {
    std::set<int> ids;
    for (const auto& rm : in.methods)
        for (const auto& o : rm.metrics.perObject) ids.insert(o.objectId);
    if (ids.empty()) return "";
    std::ostringstream o;
    o << "<table class=\"objects\"><thead><tr><th>receiver</th>";
    for (const auto& rm : in.methods)
        o << "<th>" << escapeHtml(rm.label) << " counted</th><th>false</th><th>self acne</th><th>missed</th>";
    o << "</tr></thead><tbody>\n";
    for (const int id : ids) {
        o << "<tr><td>" << escapeHtml(objectName(in, id)) << "</td>";
        for (const auto& rm : in.methods) {
            const auto it = std::find_if(rm.metrics.perObject.begin(), rm.metrics.perObject.end(),
                                         [&](const ObjectErrors& e) { return e.objectId == id; });
            if (it == rm.metrics.perObject.end()) {
                o << "<td>–</td><td>–</td><td>–</td><td>–</td>";
                continue;
            }
            o << "<td>" << formatCount(it->counted) << "</td><td>" << formatCount(it->falseShadow) << "</td><td>"
              << (rm.metrics.hasBlockerIds ? formatCount(it->selfShadowAcne) : "n/a") << "</td><td>"
              << formatCount(it->missedShadow) << "</td>";
        }
        o << "</tr>\n";
    }
    o << "</tbody></table>\n";
    return o.str();
}

std::string attributesHtml(const std::string& label, const FrameInfo& f) {
    std::ostringstream o;
    o << "<h3 style=\"font-size:14px;margin:12px 0 4px\">" << escapeHtml(label) << "</h3><table><tbody>";
    for (const auto& [k, v] : f.attributes)
        o << "<tr><td>" << escapeHtml(k) << "</td><td style=\"text-align:left\"><code>" << escapeHtml(v)
          << "</code></td></tr>";
    if (f.attributes.empty()) o << "<tr><td class=\"small\">no metadata</td><td></td></tr>";
    o << "</tbody></table>";
    return o.str();
}

}  // namespace

FrameInfo::FrameInfo(const scene::Frame& frame)
    : width(frame.width), height(frame.height), attributes(frame.attributes), timingsMs(frame.timingsMs) {}

double FrameInfo::totalTimeMs() const {
    double total = 0.0;
    for (const auto& [stage, ms] : timingsMs) total += ms;
    return total;
}

std::string describeFindings(const ReportInput& in) {
    std::vector<std::string> lines;
    for (const auto& rm : in.methods) lines.push_back(describeMethod(in, rm));
    // Which method is closer, when there are several to rank.
    if (in.methods.size() >= 2) {
        const auto best = std::min_element(in.methods.begin(), in.methods.end(), [](const auto& a, const auto& b) {
            return a.metrics.mismatchRate < b.metrics.mismatchRate;
        });
        const auto worst = std::max_element(in.methods.begin(), in.methods.end(), [](const auto& a, const auto& b) {
            return a.metrics.mismatchRate < b.metrics.mismatchRate;
        });
        const double b = best->metrics.mismatchRate, w = worst->metrics.mismatchRate;
        const auto [bt, wt] = formatPercentsApart(b, w);
        // Mean |ΔV| clearly the other way (twice, and by more than 0.0005): the wrong-pixel count
        // alone would name, or tie, the method a viewer sees as the worse one.
        const double mb = best->metrics.meanAbsVisibilityError, mw = worst->metrics.meanAbsVisibilityError;
        if (w > b && mb >= kMeanDisagreeRatio * mw && mb - mw > kMeanDisagreeMin) {
            int d = 4;
            while (d < 8 && formatFixed(mb, d) == formatFixed(mw, d)) ++d;
            lines.push_back(
                "Overall, " + shortTitle(best->label) + " gets fewer pixels wrong outright (" + bt + " against " + wt +
                "), but " + shortTitle(worst->label) + " is closer to the reference by mean |ΔV| (" +
                formatFixed(mw, d) + " against " + formatFixed(mb, d) + "): " +
                (softErrorDominates(best->metrics)
                     ? "most of " + shortTitle(best->label) + "'s error is partial shadow that the count misses."
                     : shortTitle(best->label) + "'s visibility is off over more of the image by less than "
                                                 "τ, which the count does not see."));
        } else if (w > b && w <= kSameErrorRatio * b) {
            lines.push_back("Overall, " + shortTitle(best->label) + " and " + shortTitle(worst->label) +
                            " are about as close to the reference as each other (" + bt + " and " + wt +
                            " wrong, within a tenth of each other).");
        } else if (w > b) {
            std::string t = "Overall, " + shortTitle(best->label) + " is closer to the reference (" + bt + " against " +
                            wt + " wrong)";
            const std::string r = ratio(best->metrics.methodTiming.totalMs, worst->metrics.methodTiming.totalMs);
            if (!r.empty()) t += " and " + r + " " + shortTitle(worst->label);
            lines.push_back(t + ".");
        }
    }
    for (const auto& f : in.failures) lines.push_back("The " + f.label + " backend failed: " + f.message);
    for (const auto& w : in.warnings) lines.push_back("Warning: " + w);
    if (in.reference.frame.width > 0) {
        // Reference health is checked once here rather than per method.
        for (const auto& rm : in.methods)
            if (rm.metrics.referenceHealth.total() > 0) {
                lines.push_back("Warning: the reference itself has non-finite values (" +
                                healthText(rm.metrics.referenceHealth) + "); its verdicts there are void.");
                break;
            }
    }
    if (lines.empty()) return "Nothing to compare: no method produced a frame.";
    std::string s;
    for (const auto& line : lines) {
        if (!s.empty()) s += '\n';
        s += line;
    }
    return s;
}

std::string renderReportHtml(const ReportInput& in) {
    const std::string title = "shadowlab — " + (in.sceneName.empty() ? std::string("report") : in.sceneName);
    std::ostringstream o;
    o << "<!DOCTYPE html>\n<html lang=\"en\">\n<head>\n<meta charset=\"utf-8\">\n"
      << "<meta name=\"viewport\" content=\"width=device-width, initial-scale=1\">\n"
      << "<title>" << escapeHtml(title) << "</title>\n<style>" << kCss << "</style>\n</head>\n<body>\n<main>\n";

    // Header.
    const FrameInfo& ref = in.reference.frame;
    o << "<header><h1>" << escapeHtml(title) << "</h1><div class=\"sub\">";
    if (!in.scenePath.empty()) o << "<code>" << escapeHtml(in.scenePath) << "</code> · ";
    if (ref.width > 0) o << ref.width << "×" << ref.height << " px · ";
    const auto version = ref.attributes.find("version");
    if (version != ref.attributes.end()) o << "shadowlab " << escapeHtml(version->second) << " · ";
    o << "shadow error of each method against a double-precision ray-traced reference</div></header>\n";

    // Findings in words.
    o << "<div class=\"findings\">";
    std::istringstream lines(describeFindings(in));
    for (std::string line; std::getline(lines, line);) o << "<p>" << escapeHtml(line) << "</p>";
    o << "</div>\n";
    for (const auto& f : in.failures)
        o << "<div class=\"failure\"><b>" << escapeHtml(f.label) << " failed:</b> " << escapeHtml(f.message)
          << "</div>\n";
    for (const auto& w : in.warnings) o << "<div class=\"warning\"><b>Warning:</b> " << escapeHtml(w) << "</div>\n";

    // Images over difference images, one column per frame.
    const std::size_t cols = 1 + in.methods.size();
    const std::string gridStyle = "grid-template-columns: repeat(" + std::to_string(cols) + ", minmax(0, 1fr))";
    o << "<h2>Images</h2>\n<div class=\"grid\" style=\"" << gridStyle << "\">\n";
    o << "<div>"
      << figure(in.reference.label.empty() ? "reference" : in.reference.label, formatDuration(ref.totalTimeMs()),
                in.reference.png, ref, nullptr)
      << settingsLine(ref) << "</div>\n";
    for (const auto& rm : in.methods)
        o << "<div>" << figure(rm.label, formatDuration(rm.frame.totalTimeMs()), rm.png, rm.frame, nullptr)
          << settingsLine(rm.frame) << "</div>\n";
    o << "</div>\n" << choicesHtml(ref);
    if (in.displayExposure != 1.0)
        o << "<p>The images are scaled by " << formatShort(in.displayExposure)
          << " for display: at full value more than 1% of the reference's visible surface would be white. The "
             "EXR frames keep the rendered values.</p>\n";

    o << "<h2>Difference to the reference</h2>\n<div class=\"grid\" style=\"" << gridStyle << "\">\n";
    o << "<div>" << legendHtml() << "</div>\n";
    for (const auto& rm : in.methods) {
        const Metrics& m = rm.metrics;
        o << "<div>"
          << figure(rm.label + " vs reference",
                    formatPercent(m.falseShadowRate) + " false, " + formatPercent(m.missedShadowRate) + " missed",
                    rm.diffPng, rm.frame, &m.hotspot);
        if (m.hotspot.wrongPixels > 0 && m.hotspot.size > 0 && rm.frame.width > 0) {
            o << "<div class=\"crops\">" << crop(rm.png, rm.frame, m.hotspot, rm.label + " zoom")
              << crop(rm.diffPng, rm.frame, m.hotspot, rm.label + " difference zoom") << "</div>"
              << "<div class=\"small\">Zoom into the " << m.hotspot.size << "×" << m.hotspot.size << " px region at ("
              << m.hotspot.x << ", " << m.hotspot.y << ") with the most errors (" << formatCount(m.hotspot.wrongPixels)
              << " px): " << escapeHtml(rm.label) << " image, then its difference.</div>";
        }
        o << "</div>\n";
    }
    o << "</div>\n";

    const bool anyHeat =
        std::any_of(in.methods.begin(), in.methods.end(), [](const ReportMethod& rm) { return !rm.heatPng.empty(); });
    if (anyHeat) {
        o << "<h2>Continuous error |V<sub>method</sub> − V<sub>reference</sub>|</h2>\n<div class=\"grid\" style=\""
          << gridStyle << "\">\n<div>" << heatLegendHtml() << "</div>\n";
        for (const auto& rm : in.methods) {
            const Metrics& m = rm.metrics;
            o << "<div>";
            if (!rm.heatPng.empty()) {
                std::string note = "mean " + formatFixed(m.meanAbsVisibilityError, 4);
                if (m.penumbraPixels) note += ", penumbra " + formatFixed(m.meanAbsVisibilityErrorPenumbra, 3);
                note += ", " + formatCount(m.softErrorPixels) + " px soft error";
                o << figure(rm.label + " |ΔV|", note, rm.heatPng, rm.frame, nullptr);
            }
            for (std::size_t l = 0; l < rm.lightHeatPngs.size() && l < m.perLight.size(); ++l) {
                const LightError& e = m.perLight[l];
                std::string note = "mean " + formatFixed(e.meanAbsVisibilityError, 4);
                if (e.penumbraPixels) note += ", penumbra " + formatFixed(e.meanAbsVisibilityErrorPenumbra, 3);
                o << figure(rm.label + ", light " + std::to_string(l), note, rm.lightHeatPngs[l], rm.frame, nullptr);
            }
            o << "</div>\n";
        }
        o << "</div>\n";
    }

    if (!in.shadowMapViews.empty()) {
        o << "<h2>Inside the shadow maps (raster)</h2>\n<div class=\"grid\" style=\"grid-template-columns: repeat("
          << std::min<std::size_t>(in.shadowMapViews.size(), 3) << ", minmax(0, 1fr))\">\n";
        for (const ReportView& v : in.shadowMapViews) {
            FrameInfo size;
            size.width = v.width;
            size.height = v.height;
            o << "<div>" << figure(v.title, "", v.png, size, nullptr) << "<div class=\"small\">"
              << escapeHtml(v.caption) << "</div></div>\n";
        }
        o << "</div>\n";
    }

    if (!in.methods.empty()) {
        o << "<h2>Metrics</h2>\n" << metricsTable(in);
        o << "<p class=\"small\">Rates are over counted pixels unless noted. Aliasing counts a shadow map's wrong "
             "pixels within "
          << in.methods.front().metrics.edgeRadius
          << " px of a shadow edge in the reference, but for missed shadow whose blocker lies within the contact "
             "distance (a bias leak, lost whole to the bias); bias error counts the rest. A ray tracer tests each "
             "pixel's own point, so all of its wrong pixels are bias error, near an edge or not.</p>\n";
    }

    o << "<h2>Error against run time</h2>\n<div class=\"plotrow\"><div>" << errorTimeSvg(in) << "</div><div>"
      << timingTable(in)
      << "<p class=\"small\">Stage timings in milliseconds as each backend recorded them.</p></div></div>\n";

    if (in.sweep) o << sweepSection(*in.sweep);

    const std::string objects = perObjectTable(in);
    if (!objects.empty()) o << "<h2>Errors per receiving object</h2>\n" << objects;

    o << "<h2>Settings</h2>\n<details><summary>Frame metadata (backend, settings, versions)</summary>"
      << attributesHtml(in.reference.label.empty() ? "reference" : in.reference.label, ref);
    for (const auto& rm : in.methods) o << attributesHtml(rm.label, rm.frame);
    o << "</details>\n";
    if (!in.planText.empty())
        o << "<details><summary>Render plan</summary><pre>" << escapeHtml(in.planText) << "</pre></details>\n";

    o << "</main>\n</body>\n</html>\n";
    return o.str();
}

void writeReport(const std::filesystem::path& dir, const ReportInput& input) {
    scene::writeTextAtomic(dir / "report.html", renderReportHtml(input));
}

namespace html {

const char* css() { return kCss; }

std::string figure(const std::string& caption, const std::string& note, const std::string& png, const FrameInfo& frame,
                   const ErrorHotspot* hotspot) {
    return compare::figure(caption, note, png, frame, hotspot);
}

std::string zoomCrop(const std::string& png, const FrameInfo& frame, const ErrorHotspot& hotspot,
                     const std::string& alt) {
    return compare::crop(png, frame, hotspot, alt);
}

std::string diffLegend() { return legendHtml(); }

std::string heatLegend() { return heatLegendHtml(); }

}  // namespace html

}  // namespace shadowlab::compare
