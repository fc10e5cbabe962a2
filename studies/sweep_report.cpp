// studies/sweep_report.cpp: renders a sweep's rows as one self-contained HTML page with its
// plots as standalone SVG files beside it, and the summary the run report shows of a sweep.
#include "studies/sweep_report.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <map>
#include <sstream>

#include "compare/pareto.h"
#include "compare/svg_plot.h"
#include "compare/text.h"
#include "scene/frame_io.h"
#include "studies/machine.h"

namespace shadowlab::studies {

namespace {

namespace fs = std::filesystem;
using Json = nlohmann::json;

// A row that rendered and was measured: it is plotted and ranked; the others are listed.
bool usable(const SweepRow& r) {
    return r.error.empty() && std::isfinite(r.rate("mismatch_rate")) && std::isfinite(r.frameMs);
}

// Milliseconds as a bare number with 3 significant digits ("0.412", "87.3", "1234").
std::string ms(double v) {
    if (!std::isfinite(v)) return "n/a";
    char buf[32];
    std::snprintf(buf, sizeof buf, std::fabs(v) >= 100.0 ? "%.0f" : "%.3g", v);
    return buf;
}

// A row's settings without the backend (it has its own column and heading).
std::string settingsOf(const SweepRow& r) { return r.config.settingsText(); }

std::vector<scene::Backend> backendsOf(const std::vector<SweepRow>& rows) {
    std::vector<scene::Backend> b;
    for (const auto& r : rows)
        if (std::find(b.begin(), b.end(), r.config.backend) == b.end()) b.push_back(r.config.backend);
    return b;
}

// The machines the rows were timed on, in first-seen order, and each row's index into them.
// Rows of journals that predate machine records are one "unknown machine".
struct Machines {
    std::vector<MachineInfo> list;
    std::vector<std::size_t> ofRow;
    std::vector<std::size_t> rowCount;
    // The host name when hosts tell the machines apart, else the full description.
    std::string label(std::size_t m) const {
        bool hostsUnique = true;
        for (std::size_t i = 0; i < list.size(); ++i)
            for (std::size_t j = i + 1; j < list.size(); ++j) hostsUnique = hostsUnique && list[i].host != list[j].host;
        if (list[m].host.empty()) return "unknown machine";
        return hostsUnique ? list[m].host : list[m].describe();
    }
};

Machines machinesOf(const std::vector<SweepRow>& rows) {
    Machines m;
    std::vector<std::string> ids;
    for (const SweepRow& r : rows) {
        const MachineInfo mi = machineFromJson(r.machine);
        const auto it = std::find(ids.begin(), ids.end(), mi.id());
        if (it == ids.end()) {
            ids.push_back(mi.id());
            m.list.push_back(mi);
            m.rowCount.push_back(0);
        }
        const std::size_t k = std::size_t(std::find(ids.begin(), ids.end(), mi.id()) - ids.begin());
        m.ofRow.push_back(k);
        ++m.rowCount[k];
    }
    return m;
}

compare::FrameInfo frameOf(const SweepRow& r, const SweepReportInput& in) {
    compare::FrameInfo f;
    f.width = in.width;
    f.height = in.height;
    if (r.metrics.is_object()) {
        f.width = r.metrics.value("width", f.width);
        f.height = r.metrics.value("height", f.height);
    }
    return f;
}

compare::ErrorHotspot hotspotOf(const SweepRow& r) {
    compare::ErrorHotspot h;
    if (!r.metrics.is_object() || !r.metrics.contains("hotspot") || !r.metrics["hotspot"].is_object()) return h;
    const Json& j = r.metrics["hotspot"];
    h.x = j.value("x", 0);
    h.y = j.value("y", 0);
    h.size = j.value("size", 0);
    h.wrongPixels = j.value("wrong_pixels", std::size_t(0));
    return h;
}

std::string backendTitle(scene::Backend backend) {
    const std::string name = scene::toString(backend);
    switch (backend) {
        case scene::Backend::Raster: return "the shadow map (" + name + ")";
        case scene::Backend::Raytrace: return "the ray tracer (" + name + ")";
        case scene::Backend::Reference: break;
    }
    return name;
}

// Best: least mismatch, then faster. Worst: most mismatch, then slower. Indices into rows.
struct Extremes {
    std::ptrdiff_t best = -1, worst = -1;
};

Extremes extremesOf(const std::vector<SweepRow>& rows, scene::Backend backend) {
    Extremes e;
    for (std::size_t i = 0; i < rows.size(); ++i) {
        const SweepRow& r = rows[i];
        if (r.config.backend != backend || !usable(r)) continue;
        const double m = r.rate("mismatch_rate");
        if (e.best < 0 || m < rows[e.best].rate("mismatch_rate") ||
            (m == rows[e.best].rate("mismatch_rate") && r.frameMs < rows[e.best].frameMs))
            e.best = std::ptrdiff_t(i);
        if (e.worst < 0 || m > rows[e.worst].rate("mismatch_rate") ||
            (m == rows[e.worst].rate("mismatch_rate") && r.frameMs > rows[e.worst].frameMs))
            e.worst = std::ptrdiff_t(i);
    }
    return e;
}

// Row indices on each backend's Pareto front of (per-frame time, mismatch).
std::vector<bool> frontRows(const std::vector<SweepRow>& rows) {
    std::vector<bool> on(rows.size(), false);
    for (const scene::Backend backend : backendsOf(rows)) {
        std::vector<compare::TimeErrorPoint> pts;
        std::vector<std::size_t> index;
        for (std::size_t i = 0; i < rows.size(); ++i)
            if (rows[i].config.backend == backend && usable(rows[i])) {
                pts.push_back({rows[i].frameMs, rows[i].rate("mismatch_rate")});
                index.push_back(i);
            }
        for (const std::size_t k : compare::paretoFront(pts)) on[index[k]] = true;
    }
    return on;
}

compare::ScatterPlot biasSeriesPlot(const BiasSeries& s) {
    compare::ScatterPlot p = biasPlot(s.samples, s.window, s.name() + " (" + s.unit() + ")", s.logSpaced);
    if (!s.window.stiff) {
        if (!p.bands.empty()) p.bands.front().label = "window · middle " + compare::formatShort(s.recommended);
        p.markers.push_back({s.recommended, ""});
    } else {
        p.markers.push_back({s.recommended, "best compromise"});
    }
    return p;
}

std::string rowTitle(const SweepRow& r) { return settingsOf(r).empty() ? "defaults" : settingsOf(r); }

std::string ratesNote(const SweepRow& r) {
    return compare::formatPercent(r.rate("false_shadow_rate")) + " false, " +
           compare::formatPercent(r.rate("missed_shadow_rate")) + " missed · " + compare::formatDuration(r.frameMs) +
           " per frame";
}

// One configuration: caption, its image and difference image side by side, and the zooms.
std::string configCard(const SweepRow& r, const std::string& tag, const SweepReportInput& in) {
    const compare::FrameInfo f = frameOf(r, in);
    const compare::ErrorHotspot hot = hotspotOf(r);
    std::ostringstream o;
    o << "<div class=\"cfg\"><div class=\"cfghead\"><span class=\"tag " << tag << "\">" << tag << "</span> <b>"
      << compare::escapeHtml(rowTitle(r)) << "</b><div class=\"small\">" << compare::escapeHtml(ratesNote(r))
      << "</div></div>"
      << "<div class=\"pair\">";
    if (!r.image.empty()) o << compare::html::figure("image", "", r.image, f, nullptr);
    if (!r.diffImage.empty())
        o << compare::html::figure("difference", compare::formatPercent(r.rate("mismatch_rate")) + " wrong",
                                   r.diffImage, f, &hot);
    o << "</div>";
    if (hot.wrongPixels > 0 && hot.size > 0 && f.width > 0 && f.height > 0 && !r.image.empty() &&
        !r.diffImage.empty()) {
        o << "<div class=\"crops\">" << compare::html::zoomCrop(r.image, f, hot, rowTitle(r) + " zoom")
          << compare::html::zoomCrop(r.diffImage, f, hot, rowTitle(r) + " difference zoom")
          << "<div class=\"small\">Zoom into the " << hot.size << "×" << hot.size << " px region at (" << hot.x << ", "
          << hot.y << ") with the most errors (" << compare::formatCount(hot.wrongPixels)
          << " px), marked yellow above: "
          << "the image, then its difference.</div></div>";
    } else if (hot.wrongPixels == 0) {
        o << "<div class=\"small\">No wrong pixel: nothing to zoom into.</div>";
    }
    o << "</div>";
    return o.str();
}

bool hasFlicker(const SweepReportInput& in) {
    return std::any_of(in.rows.begin(), in.rows.end(),
                       [](const SweepRow& r) { return usable(r) && r.temporal.is_object(); });
}

std::string rowsTable(const SweepReportInput& in, const std::vector<bool>& front) {
    std::map<scene::Backend, Extremes> ext;
    for (const auto& b : backendsOf(in.rows)) ext[b] = extremesOf(in.rows, b);
    const Machines machines = machinesOf(in.rows);
    const bool perMachine = machines.list.size() > 1;
    const bool temporal = hasFlicker(in);
    std::ostringstream o;
    o << "<table class=\"rows\"><thead><tr><th>#</th><th>backend</th><th>settings</th><th>setup ms</th>"
         "<th>frame ms, median [min–max]</th>"
      << (perMachine ? "<th>timed on</th>" : "")
      << "<th>false shadow</th><th>missed shadow</th><th>mismatch</th><th>IoU</th>"
      << (temporal ? "<th>flicker</th><th>held-view flicker</th><th>swim px</th>" : "")
      << "<th>images</th></tr></thead><tbody>\n";
    for (std::size_t i = 0; i < in.rows.size(); ++i) {
        const SweepRow& r = in.rows[i];
        if (!usable(r)) continue;
        const Extremes& e = ext[r.config.backend];
        o << "<tr" << (front[i] ? " class=\"front\"" : "") << "><td>" << i + 1 << "</td><td>"
          << scene::toString(r.config.backend) << "</td><td>" << compare::escapeHtml(rowTitle(r));
        if (front[i]) o << " <span class=\"tag front\" title=\"on the Pareto front\">front</span>";
        if (std::ptrdiff_t(i) == e.best) o << " <span class=\"tag best\">best</span>";
        if (std::ptrdiff_t(i) == e.worst && e.worst != e.best) o << " <span class=\"tag worst\">worst</span>";
        o << "</td><td>" << ms(r.setupMs) << "</td><td>" << ms(r.frameMs) << " <span class=\"small\">["
          << ms(r.frameMsMin) << "–" << ms(r.frameMsMax) << "]</span></td><td>";
        if (perMachine) {
            o << compare::escapeHtml(machines.label(machines.ofRow[i])) << " <span class=\"small\">load "
              << compare::formatFixed(machineFromJson(r.machine).load, 1) << "</span></td><td>";
        }
        o << compare::formatPercent(r.rate("false_shadow_rate")) << "</td><td>"
          << compare::formatPercent(r.rate("missed_shadow_rate")) << "</td><td><b>"
          << compare::formatPercent(r.rate("mismatch_rate")) << "</b></td><td>"
          << compare::formatFixed(r.rate("shadow_iou"), 3) << "</td><td>";
        if (temporal) {
            auto cell = [&](double v, bool percent) {
                return std::isfinite(v) ? (percent ? compare::formatPercent(v) : compare::formatFixed(v, 3))
                                        : std::string("–");
            };
            o << cell(r.temporalValue("flicker_rate"), true) << "</td><td>"
              << cell(r.temporalValue("flicker_rate", true), true) << "</td><td>"
              << cell(r.temporalValue("swim_px"), false) << "</td><td>";
        }
        if (!r.image.empty()) o << "<a href=\"" << compare::escapeHtml(r.image) << "\">image</a>";
        if (!r.image.empty() && !r.diffImage.empty()) o << " · ";
        if (!r.diffImage.empty()) o << "<a href=\"" << compare::escapeHtml(r.diffImage) << "\">diff</a>";
        o << "</td></tr>\n";
    }
    o << "</tbody></table>\n";
    return o.str();
}

const char* kSweepCss = R"CSS(
.top { display: grid; grid-template-columns: minmax(0, 1fr) 400px; gap: 16px; align-items: start; margin-top: 16px; }
.top .findings { margin-top: 0; }
.findings ul { margin: 0; padding-left: 18px; }
.findings li { margin-bottom: 4px; }
.backend { display: grid; grid-template-columns: repeat(2, minmax(0, 1fr)); gap: 14px; }
.cfg { background: var(--card); border: 1px solid var(--line); border-radius: 8px; padding: 12px 14px; }
.cfghead { margin-bottom: 8px; }
.pair { display: grid; grid-template-columns: repeat(2, minmax(0, 1fr)); gap: 8px; }
.pair figcaption { font-weight: 500; font-size: 12px; }
.cfg .crops { grid-template-columns: repeat(3, minmax(0, 1fr)); align-items: end; }
.cfg .crops .small { align-self: end; }
.tag { display: inline-block; font-size: 11px; font-weight: 600; padding: 0 6px; border-radius: 9px;
       border: 1px solid #0002; vertical-align: 1px; white-space: nowrap; }
.tag.best { background: #d3f9d8; color: #2b8a3e; }
.tag.worst { background: #ffe8cc; color: #d9480f; }
.tag.front { background: #e5dbff; color: #5f3dc4; }
.plots { display: grid; grid-template-columns: repeat(2, minmax(0, 1fr)); gap: 18px; align-items: start; }
.plots p { margin: 6px 0 0; }
table.rows td:nth-child(2), table.rows td:nth-child(3), table.rows th:nth-child(2),
table.rows th:nth-child(3) { text-align: left; }
table.rows { font-size: 13px; }
table.rows th, table.rows td { padding: 4px 8px; white-space: nowrap; }
table.rows td:nth-child(3) { white-space: normal; }
tr.front td { background: #f8f5ff; }
)CSS";

std::string svgName(const std::string& kind) { return "bias-" + kind + ".svg"; }

}  // namespace

SweepReportInput makeSweepReportInput(const std::string& sceneName, const std::string& scenePath,
                                      const SweepResult& result) {
    SweepReportInput in;
    in.sceneName = sceneName;
    in.scenePath = scenePath;
    in.rows = result.rows;
    in.referencePng = "reference.png";
    in.referenceMs = result.referenceMs;
    in.width = result.reference.width;
    in.height = result.reference.height;
    return in;
}

std::string sweepErrorTimeSvg(const SweepReportInput& in) {
    std::vector<compare::SweepPoint> points;
    const Machines machines = machinesOf(in.rows);
    for (std::size_t i = 0; i < in.rows.size(); ++i) {
        const SweepRow& r = in.rows[i];
        if (usable(r))
            points.push_back({scene::toString(r.config.backend), r.frameMs, r.rate("mismatch_rate"), rowTitle(r),
                              machines.label(machines.ofRow[i])});
    }
    compare::ErrorTimeOptions o;
    o.title = "Shadow error against per-frame time";
    o.errorName = "mismatch rate (false + missed)";
    return compare::renderSvg(compare::errorTimePlot(points, in.referenceMs, o));
}

std::string sweepFlickerSvg(const SweepReportInput& in) {
    compare::ScatterPlot plot;
    std::string path;
    for (const SweepRow& r : in.rows)
        if (usable(r) && r.temporal.is_object())
            path = r.temporal.value("path", "") + " path, " + std::to_string(r.temporal.value("frames", 0)) + " frames";
    plot.title = "Flicker against error (" + path + ")";
    plot.x.title = "mismatch rate (false + missed)";
    plot.x.log = true;
    plot.x.percent = true;
    plot.y.title = "mean flicker rate per frame pair";
    plot.y.percent = true;
    plot.y.min = 0.0;
    // One series per backend (the moving view), and the raster held view where the path has one.
    std::vector<std::string> names;
    std::map<std::string, compare::PlotSeries> series;
    for (const SweepRow& r : in.rows) {
        if (!usable(r) || !r.temporal.is_object()) continue;
        for (bool held : {false, true}) {
            const double f = r.temporalValue("flicker_rate", held);
            if (!std::isfinite(f)) continue;
            const std::string name = std::string(scene::toString(r.config.backend)) + (held ? " held view" : "");
            if (!series.count(name)) {
                names.push_back(name);
                series[name].name = name;
                series[name].color =
                    compare::backendColor(held ? name : scene::toString(r.config.backend), names.size() - 1);
                series[name].shape = held ? 1 : 0;
            }
            series[name].points.push_back({r.rate("mismatch_rate"), f, "",
                                           rowTitle(r) + ": " + compare::formatPercent(f) + " flicker, " +
                                               compare::formatFixed(r.temporalValue("swim_px", held), 3) +
                                               " px swim, " + compare::formatPercent(r.rate("mismatch_rate")) +
                                               " wrong, " + compare::formatDuration(r.frameMs) + " per frame"});
        }
    }
    for (const std::string& n : names) plot.series.push_back(series[n]);
    return compare::renderSvg(plot);
}

// How much more missed shadow (a rate over counted pixels) than the most accurate row a row
// may have and still be named the fastest good one: about a pixel in a thousand, the noise of
// a shadow edge's rounding between settings, far below a crevice's lost shadow.
constexpr double kSweepShadowLossSlack = 0.001;

std::vector<std::string> describeSweep(const SweepReportInput& in, const AutoBias& bias) {
    std::vector<std::string> lines;
    for (const scene::Backend backend : backendsOf(in.rows)) {
        const Extremes e = extremesOf(in.rows, backend);
        // The fastest row under the mismatch bar that loses no more shadow than the most accurate
        // one (within kSweepShadowLossSlack): a constant bias of a tenth of the model erases the
        // shadows in its crevices yet stays under the bar where a lit ground fills the image.
        const SweepRow* fastest = nullptr;
        const double mostMissed =
            e.best >= 0 ? in.rows[e.best].missedBesideTerminatorRate() + kSweepShadowLossSlack : 0.0;
        for (const SweepRow& r : in.rows)
            if (r.config.backend == backend && usable(r) &&
                r.rate("mismatch_rate") <= compare::kSweepGoodMismatchRate &&
                r.missedBesideTerminatorRate() <= mostMissed && (!fastest || r.frameMs < fastest->frameMs))
                fastest = &r;
        std::string s = "For " + backendTitle(backend) + ", ";
        if (e.best < 0) {
            s += "no configuration rendered.";
        } else if (fastest) {
            s += "the fastest configuration under " + compare::formatPercent(compare::kSweepGoodMismatchRate) +
                 " mismatch that misses no more shadow than the most accurate one is " + rowTitle(*fastest) + ": " +
                 compare::formatDuration(fastest->frameMs) + " per frame, " +
                 compare::formatPercent(fastest->rate("mismatch_rate")) + " wrong.";
            const SweepRow& b = in.rows[e.best];
            if (&b != fastest)
                s += " The most accurate, " + rowTitle(b) + ", has " + compare::formatPercent(b.rate("mismatch_rate")) +
                     " at " + compare::formatDuration(b.frameMs) + ".";
        } else {
            const SweepRow& b = in.rows[e.best];
            s += "no configuration stays under " + compare::formatPercent(compare::kSweepGoodMismatchRate) +
                 " mismatch without missing more shadow than the most accurate; the most accurate, " + rowTitle(b) +
                 ", has " + compare::formatPercent(b.rate("mismatch_rate")) + " at " +
                 compare::formatDuration(b.frameMs) + " per frame.";
        }
        lines.push_back(s);
    }
    // The probe slices' picks are the block only when nothing was searched in the configuration
    // the user runs; otherwise that search's notes say what the block holds and why (the slices'
    // windows stay under their plots below), so the findings never name two recommendations.
    if (!in.recommendation)
        for (const std::string& note : bias.notes) lines.push_back(note);
    if (const Machines machines = machinesOf(in.rows); machines.list.size() > 1) {
        std::string s = "The rows were timed on " + std::to_string(machines.list.size()) + " different machines (";
        for (std::size_t m = 0; m < machines.list.size(); ++m)
            s += (m ? "; " : "") + machines.list[m].describe() + ": " + std::to_string(machines.rowCount[m]) + " rows";
        s += "), so run times of rows from different machines are not comparable; the error-time plot gives each "
             "machine its own marker.";
        lines.push_back(s);
    }
    if (in.recommendation)
        for (const std::string& note : in.recommendation->notes) lines.push_back(note);
    else
        // A merge of shards has the rows only: the search renders the scene in the user's
        // configuration, which happens where a sweep runs whole, not where shards are joined.
        lines.push_back(
            "The block below is the probe slice's and was not measured against your defaults: the search "
            "in your configuration renders the scene, which a merge of shards does not; `shadowlab run " +
            (in.scenePath.empty() ? std::string("SCENE") : in.scenePath) + "` with the shards' options searches it.");
    std::size_t failed = 0;
    for (const SweepRow& r : in.rows) failed += usable(r) ? 0 : 1;
    if (failed > 0)
        lines.push_back(std::to_string(failed) + " configuration" + (failed == 1 ? "" : "s") + " failed and " +
                        (failed == 1 ? "is" : "are") + " listed at the end, not plotted.");
    if (in.rows.empty()) lines.push_back("The sweep holds no configuration yet.");
    return lines;
}

// The block the page shows and recommended-shadow.json holds under "shadow".
static nlohmann::json recommendedBlock(const SweepReportInput& in, const AutoBias& bias) {
    return in.recommendation ? in.recommendation->shadowBlock : bias.shadowBlock;
}

std::string renderSweepReportHtml(const SweepReportInput& in) {
    const AutoBias bias = recommendBias(in.rows, in.threshold);
    const std::vector<bool> front = frontRows(in.rows);
    const std::string title = "shadowlab sweep — " + (in.sceneName.empty() ? std::string("scene") : in.sceneName);
    int width = in.width, height = in.height;
    for (const SweepRow& r : in.rows)
        if (width == 0 && r.metrics.is_object()) {
            width = r.metrics.value("width", 0);
            height = r.metrics.value("height", 0);
        }
    std::size_t failed = 0;
    for (const SweepRow& r : in.rows) failed += usable(r) ? 0 : 1;

    std::ostringstream o;
    o << "<!DOCTYPE html>\n<html lang=\"en\">\n<head>\n<meta charset=\"utf-8\">\n"
      << "<meta name=\"viewport\" content=\"width=device-width, initial-scale=1\">\n"
      << "<title>" << compare::escapeHtml(title) << "</title>\n<style>" << compare::html::css() << kSweepCss
      << "</style>\n</head>\n<body>\n<main>\n";
    o << "<header><h1>" << compare::escapeHtml(title) << "</h1><div class=\"sub\">";
    if (!in.scenePath.empty()) o << "<code>" << compare::escapeHtml(in.scenePath) << "</code> · ";
    if (width > 0) o << width << "×" << height << " px · ";
    o << compare::formatCount(in.rows.size()) << " configurations";
    if (failed > 0) o << " (" << compare::formatCount(failed) << " failed)";
    o << " · each timed as the median of its frames after a warm-up, and measured against the "
         "double-precision reference</div></header>\n";

    // Summary in words beside the reference.
    o << "<div class=\"top\"><div class=\"findings\"><ul>";
    for (const std::string& line : describeSweep(in, bias)) o << "<li>" << compare::escapeHtml(line) << "</li>";
    o << "</ul><p style=\"margin-top:10px\">Recommended <code>\"shadow\"</code> block for the scene file "
         "(also in <code>recommended-shadow.json</code>):</p><pre>"
      << compare::escapeHtml(recommendedBlock(in, bias).dump(2)) << "</pre></div>\n<div>";
    if (!in.referencePng.empty()) {
        compare::FrameInfo ref;
        ref.width = width;
        ref.height = height;
        o << compare::html::figure(scene::toString(scene::Backend::Reference),
                                   in.referenceMs > 0.0 ? compare::formatDuration(in.referenceMs) : "", in.referencePng,
                                   ref, nullptr);
    }
    o << "</div></div>\n";

    // Best and worst configuration of each backend.
    for (const scene::Backend backend : backendsOf(in.rows)) {
        const Extremes e = extremesOf(in.rows, backend);
        if (e.best < 0) continue;
        o << "<h2>" << compare::escapeHtml(backendTitle(backend))
          << ": best and worst configuration</h2>\n<div class=\"backend\">" << configCard(in.rows[e.best], "best", in);
        if (e.worst != e.best) o << configCard(in.rows[e.worst], "worst", in);
        o << "</div>\n";
    }
    if (!in.rows.empty())
        o << "<details><summary>Colors of the difference images</summary>" << compare::html::diffLegend()
          << "</details>\n";

    // Plots.
    o << "<h2>Error against run time</h2>\n<div class=\"plots\"><div>" << sweepErrorTimeSvg(in)
      << "</div><div><p>Every configuration that rendered is one point: its median per-frame time (setup "
         "excluded: it is paid once) against the share of counted pixels whose shadow is wrong. The line "
         "through each backend's points is its Pareto front: no other setting of that backend is both faster "
         "and more accurate. Points on the bottom edge have no wrong pixel at all (zero cannot sit on a log "
         "axis). The dashed line is the reference's render time.</p>"
         "<p class=\"small\">Hover a point for its settings. Times come from a shared machine: compare rows "
         "of this sweep with each other, not with other machines.</p></div></div>\n";
    if (hasFlicker(in))
        o << "<h2>Flicker against error</h2>\n<div class=\"plots\"><div>" << sweepFlickerSvg(in)
          << "</div><div><p>Every configuration was also rendered along one short path (the same for all rows) and "
             "measured against the reference at each frame: the flicker rate is the share of pixels, counted in both "
             "frames of a pair, whose lit/shadow state changes while the reference's does not (docs/temporal.md). "
             "Squares are the raster held view: each frame's shadow setup drawn from frame 0's camera, so every "
             "change is the shadow maps' own (zero for a map that holds still). Error is that of the still frame; "
             "hover a point for its run time.</p></div></div>\n";
    bool anyBias = false;
    for (const std::string& kind : seriesKinds()) anyBias = anyBias || bias.primary(kind);
    if (anyBias) {
        o << "<h2>False and missed shadow against bias</h2>\n<div class=\"plots\">";
        for (const std::string& kind : seriesKinds()) {
            const BiasSeries* s = bias.primary(kind);
            if (!s) continue;
            o << "<div>" << compare::renderSvg(biasSeriesPlot(*s)) << "<p>" << compare::escapeHtml(s->describe())
              << "</p></div>";
        }
        o << "</div>\n<p class=\"small\">Too little bias gives false shadow (acne, red); too much gives missed "
             "shadow (peter-panning and light leaks, blue). The green band is the bias window: the sampled "
             "values where both stay at or under "
          << compare::formatPercent(bias.threshold)
          << " of the counted pixels. Without one, the scene is stiff for that "
             "method.</p>\n";
    }

    o << "<h2>All configurations</h2>\n"
      << rowsTable(in, front)
      << "<p class=\"small\">Rates are over counted pixels. <span class=\"tag front\">front</span> marks the "
         "Pareto front of each backend. Setup is the one-time cost (Vulkan device and pipelines, the ray "
         "tracer's BVH).</p>\n";

    if (failed > 0) {
        o << "<h2>Failed configurations</h2>\n";
        for (std::size_t i = 0; i < in.rows.size(); ++i) {
            const SweepRow& r = in.rows[i];
            if (usable(r)) continue;
            o << "<div class=\"failure\"><b>#" << i + 1 << " "
              << compare::escapeHtml(std::string(scene::toString(r.config.backend)) + ": " + rowTitle(r)) << ":</b> "
              << compare::escapeHtml(r.error.empty() ? std::string("no metrics recorded") : r.error) << "</div>\n";
        }
    }
    o << "</main>\n</body>\n</html>\n";
    return o.str();
}

void writeSweepReport(const fs::path& dir, const SweepReportInput& input) {
    const AutoBias bias = recommendBias(input.rows, input.threshold);
    scene::writeTextAtomic(dir / "error-time.svg", sweepErrorTimeSvg(input));
    if (hasFlicker(input)) scene::writeTextAtomic(dir / "flicker-error.svg", sweepFlickerSvg(input));
    for (const std::string& kind : seriesKinds()) {
        const BiasSeries* s = bias.primary(kind);
        if (s) {
            scene::writeTextAtomic(dir / svgName(kind), compare::renderSvg(biasSeriesPlot(*s)));
        } else {
            std::error_code ec;
            fs::remove(dir / svgName(kind), ec);
        }
    }
    const Json file = input.recommendation ? input.recommendation->toJson()
                                           : Json{{"shadow", bias.shadowBlock}, {"measured", nullptr}};
    scene::writeTextAtomic(dir / "recommended-shadow.json", file.dump(2) + "\n");
    scene::writeTextAtomic(dir / "report.html", renderSweepReportHtml(input));
}

compare::SweepSummary summarizeSweep(const SweepReportInput& input, const std::string& href) {
    const AutoBias bias = recommendBias(input.rows, input.threshold);
    compare::SweepSummary s;
    s.href = href;
    s.errorTimeSvg = sweepErrorTimeSvg(input);
    s.lines = describeSweep(input, bias);
    s.shadowBlockJson = recommendedBlock(input, bias).dump(2);
    s.configurations = input.rows.size();
    for (const SweepRow& r : input.rows) s.failed += usable(r) ? 0 : 1;
    int w = input.width, h = input.height;
    for (const SweepRow& r : input.rows)
        if (w == 0 && r.metrics.is_object()) {
            w = r.metrics.value("width", 0);
            h = r.metrics.value("height", 0);
        }
    if (w > 0) s.resolution = std::to_string(w) + "x" + std::to_string(h);
    return s;
}

}  // namespace shadowlab::studies
